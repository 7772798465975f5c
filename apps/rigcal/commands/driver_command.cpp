// `rigcal driver --config RIG --sensor NAME (--live | --pcap F [--rate R] | --bag B [--topic T] [--rate R])`: one sensor's driver in its
// own process, writing every finished scan into the shared-memory ring /rigcal.<sensor>.
#include <algorithm>
#include <iomanip>
#include <filesystem>
#include <limits>
#include <iostream>
#include <optional>
#include <sstream>

#include "../commands.hpp"
#include "../exit_codes.hpp"
#include "../rig_loading.hpp"
#include "../stop_signals.hpp"
#include "rigcal/config/rig_config.hpp"
#include "rigcal/core/cpu_latency_request.hpp"
#include "rigcal/pipeline/sensor_driver.hpp"
#include "rigcal/shm/ring_error.hpp"
#include "rigcal/shm/driver_tally.hpp"
#include "rigcal/shm/ring_layout.hpp"
#include "rigcal/shm/scan_ring_writer.hpp"

namespace rigcal::app {

namespace {

struct DriverOptions {
  std::string config, sensor, pcap, bag, topic, rate = "1.0", shm_prefix;
  bool live = false, low_latency = false;
  unsigned slots = 8;
};

double parseRate(const std::string& text) {
  if (text == "max") return 0.0;
  try {
    const double r = std::stod(text);
    if (r > 0) return r;
  } catch (const std::exception&) {
  }
  throw CommandFailed(kExitUsage, "--rate must be a positive number or 'max', got '" + text + "'");
}

// The ring is allocated in full up front (every slot holds the sensor's largest scan): bound it in bytes.
constexpr std::uint64_t kMaxRingBytes = std::uint64_t(512) << 20;

std::string mebibytes(std::uint64_t bytes) {
  std::ostringstream o;
  o << std::fixed << std::setprecision(1) << double(bytes) / double(1 << 20);
  return o.str();
}

void checkRingSize(unsigned slots, std::uint32_t max_points) {
  const std::uint64_t bytes = shm::ringBytes(slots, max_points);
  if (bytes <= kMaxRingBytes) return;
  unsigned fits = slots;
  while (fits > shm::kMinSlots && shm::ringBytes(fits, max_points) > kMaxRingBytes) --fits;
  throw CommandFailed(kExitUsage, "--slots " + std::to_string(slots) + ": the ring would take " + mebibytes(bytes) +
                                      " MiB (" + std::to_string(max_points) + " points per slot); the limit is " +
                                      mebibytes(kMaxRingBytes) + " MiB, at most " + std::to_string(fits) +
                                      " slots for this sensor");
}

std::uint32_t saturated(std::uint64_t n) {
  return std::uint32_t(std::min<std::uint64_t>(n, std::numeric_limits<std::uint32_t>::max()));
}

// What the driver has counted so far, for the ring's readers (read on the driver's thread, which owns it).
shm::DriverTally tallyOf(const pipeline::SensorDriver& driver) {
  const auto& a = driver.assemblerStats();
  shm::DriverTally t;
  t.packets = a.packets;
  t.malformed = saturated(a.malformed + driver.sourceStats().malformed);
  t.late_dropped = saturated(a.late_dropped);
  t.reordered = saturated(a.reordered);
  t.foreign = saturated(driver.foreignPackets().packets);
  return t;
}

void run(const DriverOptions& o) {
  config::RigConfig rig;
  config::SensorConfig sensor;
  rig = loadRig(o.config);
  try {
    sensor = rig.sensor(o.sensor);
  } catch (const config::ConfigError& e) {
    throw CommandFailed(kExitConfig, e.what());
  }
  pipeline::DriverInput input;
  if (!o.bag.empty()) {
    if (!std::filesystem::exists(o.bag)) throw CommandFailed(kExitInput, o.bag + ": bag not found");
    input.bag = o.bag;
    input.topic = o.topic;
    input.rate = parseRate(o.rate);
  } else if (!o.live) {
    requireInputFile(o.pcap, "capture");
    input.pcap = o.pcap;
    input.rate = parseRate(o.rate);
  }

  StopSignals signals;
  std::optional<CpuLatencyRequest> low_latency;
  if (o.low_latency) {
    low_latency.emplace(0);
    if (!low_latency->active()) std::cerr << "warning: --low-latency not in effect: " << low_latency->error() << '\n';
  }
  std::unique_ptr<shm::ScanRingWriter> ring;
  std::uint64_t published = 0, dropped = 0;
  std::unique_ptr<pipeline::SensorDriver> driver;
  try {
    driver = std::make_unique<pipeline::SensorDriver>(sensor, input, StopSignals::flag(), [&](Scan&& scan) {
      ring->publish(scan, tallyOf(*driver)) ? ++published : ++dropped;
    });
    shm::WriterOptions w;
    w.sensor = sensor.name;
    w.max_points = std::uint32_t(driver->maxPointsPerScan());
    w.slot_count = o.slots;
    checkRingSize(o.slots, w.max_points);
    if (!o.shm_prefix.empty()) w.name_prefix = o.shm_prefix;
    ring = std::make_unique<shm::ScanRingWriter>(w);
  } catch (const shm::RingError& e) {
    throw CommandFailed(kExitFailure, e.what());
  } catch (const CommandFailed&) {
    throw;
  } catch (const std::exception& e) {
    throw CommandFailed(kExitInput, e.what());
  }
  std::cout << "driver '" << sensor.name << "' (" << sensor.model << ") writing " << ring->segmentName() << " ("
            << o.slots << " slots, " << mebibytes(shm::ringBytes(o.slots, std::uint32_t(driver->maxPointsPerScan())))
            << " MiB)"
            << (ring->tookOver() ? " (took over a stale ring)" : "") << std::endl;
  if (!driver->bagTopic().empty()) std::cout << "reading bag topic " << driver->bagTopic() << std::endl;

  driver->run([&] { ring->heartbeat(); });

  const auto& a = driver->assemblerStats();
  std::cout << "driver '" << sensor.name << "': " << published << " scans published, " << dropped
            << " too large for a slot; " << a.packets << " packets, " << a.malformed + driver->sourceStats().malformed
            << " malformed, "
            << a.lost_packets << " lost" << std::endl;
  if (!driver->warning().empty()) std::cerr << "warning: " << driver->warning() << '\n';
  if (driver->foreignPackets().packets > 0)
    std::cerr << "warning: sensor '" << sensor.name << "': "
              << driver->foreignPackets().describe(sensor.model, sensor.source.port) << '\n';
  if (const auto& s = driver->sourceStats(); o.live && s.filtered > 0)
    std::cerr << "warning: " << s.filtered << " datagrams on port " << sensor.source.port
              << " dropped by the source-address filter (sensor address " << sensor.source.address.value_or("?")
              << "), the last from " << drivers::formatIpv4(s.last_filtered.address) << ':' << s.last_filtered.port
              << (s.last_filtered.address >> 24 == 127 ? "; a replay on this host? give the sensor 'bind: 127.0.0.1'" : "")
              << '\n';
  if (StopSignals::requested() && !o.live) throw CommandFailed(kExitInterrupted, "driver interrupted");
}

}  // namespace

void addDriverCommand(CLI::App& app) {
  auto o = std::make_shared<DriverOptions>();
  auto* cmd = app.add_subcommand("driver", "Run one sensor's driver, writing scans into its shared-memory ring");
  cmd->add_option("--config", o->config, "Rig YAML file")->required();
  cmd->add_option("--sensor", o->sensor, "Sensor name in the rig file")->required();
  auto* live = cmd->add_flag("--live", o->live, "Read the sensor's UDP port");
  auto* pcap = cmd->add_option("--pcap", o->pcap, "Read a capture instead");
  auto* bag = cmd->add_option("--bag", o->bag, "Read a ROS 2 bag's packet or PointCloud2 topic instead");
  live->excludes(pcap);
  bag->excludes(pcap);
  bag->excludes(live);
  cmd->add_option("--topic", o->topic, "With --bag: the sensor's topic (default: its source.topic, else the only lidar topic)")
      ->needs(bag);
  cmd->add_option("--rate", o->rate, "With --pcap or --bag: 1.0 = recorded timing, 2 = twice as fast, max = no pacing");
  cmd->add_option("--slots", o->slots, "Scans the ring keeps for slow readers")->check(CLI::Range(2u, 1024u));
  cmd->add_flag("--low-latency", o->low_latency,
               "Hold the CPU wake-up latency limit at 0 while running (/dev/cpu_dma_latency, needs root): "
               "readers on other cores wake in ~10 us instead of ~50-100 us, at the cost of power");
  cmd->add_option("--shm-prefix", o->shm_prefix, "Ring name prefix (default $RIGCAL_SHM_PREFIX or rigcal.)");
  cmd->footer(std::string("Stops at the end of the capture, or on Ctrl-C (live). ") + kExitCodesHelp);
  cmd->callback([o] {
    if (!o->live && o->pcap.empty() && o->bag.empty())
      throw CommandFailed(kExitUsage, "driver needs --live, --pcap FILE or --bag BAG");
    run(*o);
  });
}

}  // namespace rigcal::app
