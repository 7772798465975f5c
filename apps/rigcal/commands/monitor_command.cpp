// `rigcal monitor [--config rig.yaml] [--once] [--interval S]`: a live table of the shared-memory scan rings
// (scans/s, points/s, last stamp, lag, overruns, torn reads, writer alive). Rates are measured between two
// looks `interval` apart; `--once` prints one table and exits. Read-only: it never changes a ring.
#include <unistd.h>

#include <algorithm>
#include <cstdio>
#include <ctime>
#include <iomanip>
#include <iostream>
#include <map>
#include <memory>
#include <sstream>

#include "../commands.hpp"
#include "../exit_codes.hpp"
#include "../stop_signals.hpp"
#include "rigcal/config/rig_config.hpp"
#include "rigcal/shm/liveness.hpp"
#include "rigcal/shm/ring_inspect.hpp"
#include "rigcal/shm/ring_segment.hpp"
#include "rigcal/core/text_format.hpp"

namespace rigcal::app {

namespace {

struct MonitorOptions {
  std::string config;
  bool once = false;
  double interval = 1.0;
};

std::string human(double v) {
  if (v >= 1e6) return fixed(v / 1e6, 2) + "M";
  if (v >= 1e3) return fixed(v / 1e3, 1) + "k";
  return fixed(v, 1);
}

std::vector<std::string> ringNames(const std::vector<std::string>& sensors, const std::string& prefix) {
  if (sensors.empty()) return shm::listSegments(prefix);
  std::vector<std::string> names;
  for (const auto& s : sensors) names.push_back(shm::segmentName(s, prefix));
  return names;
}

void printTable(const std::vector<std::string>& names, const std::map<std::string, shm::RingInfo>& before,
                const std::map<std::string, shm::RingInfo>& now, const std::string& prefix) {
  // Cells first, then widths: columns fit their widest cell (a pcap replay's lag can have nine digits).
  std::vector<std::vector<std::string>> rows = {{"RING", "WRITER", "PID", "EPOCH", "SCANS/S", "POINTS/S",
                                                 "LAST STAMP (s)", "LAG (s)", "AGE (ms)", "READERS",
                                                 "OVERRUNS", "TORN", "BACKLOG"}};
  std::vector<std::string> errors;
  const std::int64_t now_real = shm::realtimeNs();
  for (const auto& name : names) {
    const shm::RingInfo& r = now.at(name);
    const auto prev = before.find(name);
    std::string status = r.present ? shm::toString(r.writer) : "absent";
    if (!r.error.empty()) {
      status = "error";
      errors.push_back(r.error);
    }
    std::string scans_s = "-", points_s = "-";
    if (prev != before.end() && r.error.empty() && r.epoch > 0 && r.epoch == prev->second.epoch &&
        r.write_index >= prev->second.write_index && r.sampled_ns > prev->second.sampled_ns) {
      const double dt = static_cast<double>(r.sampled_ns - prev->second.sampled_ns) * 1e-9;
      scans_s = fixed(static_cast<double>(r.write_index - prev->second.write_index) / dt, 1);
      points_s = human(static_cast<double>(r.total_points - prev->second.total_points) / dt);
    }
    const bool any = r.write_index > 0;
    const bool readable = r.present && r.error.empty() && r.epoch > 0;
    rows.push_back({name, status, r.writer_pid > 0 ? std::to_string(r.writer_pid) : "-",
                    r.epoch > 0 ? std::to_string(r.epoch) : "-", scans_s, points_s,
                    any ? fixed(static_cast<double>(r.last_stamp_ns) * 1e-9, 3) : "-",
                    any ? fixed(static_cast<double>(now_real - r.last_stamp_ns) * 1e-9, 3) : "-",
                    any ? std::to_string((r.sampled_ns - r.last_publish_ns) / 1'000'000) : "-",
                    readable ? std::to_string(r.readers) : "-", readable ? std::to_string(r.overruns) : "-",
                    readable ? std::to_string(r.torn_reads) : "-", readable ? std::to_string(r.max_backlog) : "-"});
  }
  std::vector<std::size_t> width(rows[0].size(), 0);
  for (const auto& row : rows) {
    for (std::size_t c = 0; c < row.size(); ++c) width[c] = std::max(width[c], row[c].size());
  }
  std::ostringstream out;
  for (const auto& row : rows) {
    for (std::size_t c = 0; c < row.size(); ++c) {
      if (c > 0) out << "  ";
      // Names and states left-aligned, numbers right-aligned.
      out << (c < 2 ? std::left : std::right) << std::setw(static_cast<int>(width[c])) << row[c];
    }
    out << '\n';
  }
  if (names.empty()) out << "(no rings under " << shm::segmentPath(prefix).string() << "*)\n";
  for (const auto& e : errors) out << "error: " << e << '\n';
  std::cout << out.str() << std::flush;
}

void runMonitor(const MonitorOptions& o) {
  std::vector<std::string> sensors;
  if (!o.config.empty()) {
    try {
      for (const auto& s : config::loadRigConfig(o.config).sensors) sensors.push_back(s.name);
    } catch (const config::ConfigError& e) {
      throw CommandFailed(kExitConfig, e.what());
    }
  }
  const std::string prefix = shm::defaultNamePrefix();
  const bool tty = ::isatty(STDOUT_FILENO) != 0;
  const StopSignals stop_signals;
  const auto interval_ns = static_cast<std::int64_t>(o.interval * 1e9);
  std::map<std::string, shm::RingInfo> before;
  for (const auto& n : ringNames(sensors, prefix)) before[n] = shm::inspectRing(n);
  while (!StopSignals::requested()) {
    timespec ts{static_cast<time_t>(interval_ns / 1'000'000'000), static_cast<long>(interval_ns % 1'000'000'000)};
    ::nanosleep(&ts, nullptr);  // a signal cuts it short
    if (StopSignals::requested() && !o.once) break;
    const std::vector<std::string> names = ringNames(sensors, prefix);
    std::map<std::string, shm::RingInfo> now;
    for (const auto& n : names) now[n] = shm::inspectRing(n);
    if (tty && !o.once) std::cout << "\x1b[H\x1b[2J";
    printTable(names, before, now, prefix);
    if (o.once) break;
    before = std::move(now);
  }
}

}  // namespace

void addMonitorCommand(CLI::App& app) {
  auto* cmd = app.add_subcommand("monitor", "Live table of the shared-memory scan rings");
  auto o = std::make_shared<MonitorOptions>();
  cmd->add_option("--config", o->config, "Rig file: show its sensors' rings (default: every ring found)");
  cmd->add_flag("--once", o->once, "Print one table (rates over --interval) and exit");
  cmd->add_option("--interval", o->interval, "Seconds between tables")->check(CLI::PositiveNumber);
  cmd->footer(std::string("Rings are /dev/shm/<prefix><sensor>, prefix $RIGCAL_SHM_PREFIX or \"") +
              shm::kDefaultNamePrefix + "\". " + kExitCodesHelp);
  cmd->callback([o] { runMonitor(*o); });
}

}  // namespace rigcal::app
