#pragma once
// The command-line options of every command that runs the Pipeline (`rigcal map`, `rigcal calibrate`):
// the input (--pcap F [--rate R] | --live | --shm), real time or offline, pinning, and the stats output.
#include <CLI/CLI.hpp>
#include <string>
#include <vector>

#include "rigcal/pipeline/pipeline.hpp"

namespace rigcal::app {

struct PipelineCliOptions {
  std::string pcap;
  std::string bag;                  // a ROS 2 bag (folder, .mcap or .db3) instead of a pcap
  std::vector<std::string> topics;  // with --bag: SENSOR=TOPIC (or TOPIC for a one-sensor rig)
  std::string rate;       // empty: as fast as possible (offline); "1" = recorded timing (real time)
  bool live = false;
  bool shm = false;
  std::string shm_prefix;
  bool wait_for_writers = false;
  bool realtime = false;  // force real-time mode (drop oldest) for a pcap read as fast as possible
  bool pin = false;
  std::string cores;      // e.g. "0,1"; implies --pin
  std::string stats_file;
};

/// Adds --pcap --bag --topic --rate --live --shm --shm-prefix --realtime --pin --cores --stats to `cmd`.
void addPipelineOptions(CLI::App& cmd, PipelineCliOptions& o);

/// Throws CommandFailed(kExitUsage) on a bad combination or value (one line, naming the option).
pipeline::PipelineOptions toPipelineOptions(const PipelineCliOptions& o);

/// Prints the stats table on stdout and, with --stats FILE, writes them as JSON (CommandFailed on error).
void reportStats(const PipelineCliOptions& o, const pipeline::PipelineStats& stats);

}  // namespace rigcal::app
