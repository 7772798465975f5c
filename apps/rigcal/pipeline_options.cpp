#include "pipeline_options.hpp"

#include <filesystem>
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
  auto* bag = cmd.add_option("--bag", o.bag, "Read the sensors' packets or PointCloud2 scans from a ROS 2 bag");
  live->excludes(pcap);
  shm->excludes(pcap);
  shm->excludes(live);
  for (auto* other : {pcap, live, shm}) bag->excludes(other);
  cmd.add_option("--topic", o.topics,
                 "With --bag: SENSOR=TOPIC per sensor (or TOPIC for a one-sensor rig); default: each sensor's source.topic")
      ->needs(bag);
  // Checked in toPipelineOptions: CLI11's needs() cannot say "--pcap or --bag".
  cmd.add_option("--rate", o.rate, "With --pcap or --bag: 1.0 = recorded timing (real time); default: as fast as possible");
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
  if (!o.rate.empty() && o.pcap.empty() && o.bag.empty())
    throw CommandFailed(kExitUsage, "--rate needs --pcap or --bag");
  if (!o.pcap.empty() || !o.bag.empty()) {
    if (!o.pcap.empty()) {
      requireInputFile(o.pcap, "capture");  // exit 4, as every command's missing input
      p.input = pipeline::InputKind::kPcap;
      p.pcap = o.pcap;
    } else {
      if (!std::filesystem::exists(o.bag)) throw CommandFailed(kExitInput, o.bag + ": bag not found");
      p.input = pipeline::InputKind::kBag;
      p.bag = o.bag;
      for (const auto& t : o.topics) {
        const auto eq = t.find('=');
        const std::string sensor = eq == std::string::npos ? std::string() : t.substr(0, eq);
        const std::string topic = eq == std::string::npos ? t : t.substr(eq + 1);
        if (topic.empty() || !p.bag_topics.emplace(sensor, topic).second)
          throw CommandFailed(kExitUsage, "--topic '" + t + "': give SENSOR=TOPIC once per sensor (or one TOPIC)");
      }
    }
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
    throw CommandFailed(kExitUsage, "needs an input: --pcap FILE, --bag BAG, --live or --shm");
  }
  const bool paced = pipeline::isRecording(p.input) && p.rate > 0;
  p.mode = (o.realtime || paced || !pipeline::isRecording(p.input)) ? pipeline::PipelineMode::kRealtime
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
