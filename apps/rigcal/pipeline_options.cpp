#include "pipeline_options.hpp"

#include <fstream>
#include <iostream>
#include <thread>

#include "commands.hpp"
#include "exit_codes.hpp"
#include "rig_loading.hpp"
#include "rigcal/core/atomic_file.hpp"
#include "rigcal/pipeline/stage_thread.hpp"

namespace rigcal::app {

void addPipelineOptions(CLI::App& cmd, PipelineCliOptions& o) {
  auto* pcap = cmd.add_option("--pcap", o.pcap, "Read the sensors' packets from a capture");
  auto* live = cmd.add_flag("--live", o.live, "Read the sensors' UDP ports (real time)");
  auto* shm = cmd.add_flag("--shm", o.shm, "Read the shared-memory rings of `rigcal driver` processes (real time)");
  live->excludes(pcap);
  shm->excludes(pcap);
  shm->excludes(live);
  cmd.add_option("--rate", o.rate, "With --pcap: 1.0 = recorded timing (real time); default: as fast as possible")
      ->needs(pcap);
  cmd.add_option("--shm-prefix", o.shm_prefix, "With --shm: ring name prefix (default $RIGCAL_SHM_PREFIX or rigcal.)")
      ->needs(shm);
  cmd.add_flag("--wait-for-writers", o.wait_for_writers,
               "With --shm: when every ring writer is gone, wait for new ones (default: the input ends)")
      ->needs(shm);
  cmd.add_flag("--realtime", o.realtime, "Never wait for a slow stage: drop the oldest work (default with --live, --shm, --rate)");
  cmd.add_flag("--pin", o.pin, "Pin the pipeline's threads to the machine's cores (or --cores)");
  cmd.add_option("--cores", o.cores, "Cores to pin the threads to, e.g. 0,1 or 0-1 (implies --pin)");
  cmd.add_option("--stats", o.stats_file, "Write the stage latencies, queue depths, drops and CPU as JSON");
}

pipeline::PipelineOptions toPipelineOptions(const PipelineCliOptions& o) {
  pipeline::PipelineOptions p;
  if (!o.pcap.empty()) {
    requireInputFile(o.pcap, "capture");  // exit 4, as every command's missing input
    p.input = pipeline::InputKind::kPcap;
    p.pcap = o.pcap;
    if (!o.rate.empty()) {
      try {
        std::size_t used = 0;
        p.rate = o.rate == "max" ? 0.0 : std::stod(o.rate, &used);
        if (o.rate != "max" && (used != o.rate.size() || !(p.rate > 0)))
          throw std::invalid_argument(o.rate);
      } catch (const std::exception&) {
        throw CommandFailed(kExitUsage, "--rate must be a positive number or 'max', got '" + o.rate + "'");
      }
    }
  } else if (o.live) {
    p.input = pipeline::InputKind::kLive;
  } else if (o.shm) {
    p.input = pipeline::InputKind::kShm;
    if (!o.shm_prefix.empty()) p.shm_prefix = o.shm_prefix;
    p.wait_for_writers = o.wait_for_writers;
  } else {
    throw CommandFailed(kExitUsage, "needs an input: --pcap FILE, --live or --shm");
  }
  const bool paced = p.input == pipeline::InputKind::kPcap && p.rate > 0;
  p.mode = (o.realtime || paced || p.input != pipeline::InputKind::kPcap) ? pipeline::PipelineMode::kRealtime
                                                                          : pipeline::PipelineMode::kOffline;
  if (!o.cores.empty()) {
    try {
      p.cores = pipeline::parseCoreList(o.cores);
    } catch (const std::exception& e) {
      throw CommandFailed(kExitUsage, std::string("--cores: ") + e.what());
    }
  } else if (o.pin) {
    for (unsigned c = 0; c < std::max(1u, std::thread::hardware_concurrency()); ++c) p.cores.push_back(int(c));
  }
  return p;
}

void reportStats(const PipelineCliOptions& o, const pipeline::PipelineStats& stats) {
  std::cout << stats.table();
  if (o.stats_file.empty()) return;
  try {
    writeFileAtomically(o.stats_file, [&](std::ostream& out) { out << stats.json() << '\n'; });
  } catch (const std::runtime_error& e) {
    throw CommandFailed(kExitFailure, std::string("--stats: ") + e.what());
  }
}

}  // namespace rigcal::app
