// Human and machine views of the pipeline's progress and stats.
#include <iomanip>
#include <sstream>

#include "rigcal/pipeline/pipeline.hpp"

namespace rigcal::pipeline {

namespace {
double ms(std::int64_t ns) { return double(ns) * 1e-6; }

std::string jsonString(const std::string& s) {
  std::ostringstream o;
  o << '"';
  for (const char c : s) {
    if (c == '"' || c == '\\') o << '\\' << c;
    else if (static_cast<unsigned char>(c) < 0x20) o << "\\u" << std::hex << std::setw(4) << std::setfill('0') << int(c) << std::dec;
    else o << c;
  }
  o << '"';
  return o.str();
}
}  // namespace

double PipelineProgress::budgetFill() const {
  if (lidars.empty()) return 0.0;
  double sum = 0;
  for (const auto& l : lidars)
    sum += l.handed_over ? 1.0 : (l.budget > 0 ? std::min(1.0, double(l.selected) / l.budget) : 0.0);
  return sum / double(lidars.size());
}

std::string PipelineProgress::line() const {
  std::ostringstream o;
  o << "scans " << mapping_scans << " | kf " << keyframes << " stopped " << stopped_frames << " lost " << lost_frames;
  if (mapping_done) o << " (map full)";
  // Packets lost show as they happen, not only in the final report.
  if (mapping_lost_packets > 0) o << " | " << mapping_sensor << " lost " << mapping_lost_packets << " pkts";
  if (mapping_malformed_packets > 0)
    o << (mapping_lost_packets > 0 ? ", " : " | " + mapping_sensor + ' ') << mapping_malformed_packets << " malformed";
  for (const auto& l : lidars) {
    o << " | " << l.sensor << ' ' << l.selected << '/' << l.budget << " (cand " << l.candidates << ')';
    if (l.lost_packets > 0) o << " (lost " << l.lost_packets << " pkts)";
    if (l.malformed_packets > 0) o << " (" << l.malformed_packets << " malformed)";
    if (l.handed_over) o << " done";
  }
  return o.str();
}

std::string PipelineStats::table() const {
  std::ostringstream o;
  o << std::fixed << std::setprecision(2);
  o << std::left << std::setw(18) << "stage" << std::right << std::setw(8) << "count" << std::setw(10) << "p50 ms"
    << std::setw(10) << "p99 ms" << std::setw(10) << "max ms" << std::setw(9) << "cpu s" << '\n';
  for (const auto& s : stages) {
    o << std::left << std::setw(18) << s.name << std::right << std::setw(8) << s.latency.count();
    if (s.latency.count() > 0)
      o << std::setw(10) << ms(s.latency.quantile(0.5)) << std::setw(10) << ms(s.latency.quantile(0.99))
        << std::setw(10) << ms(s.latency.max());
    else
      o << std::setw(10) << "-" << std::setw(10) << "-" << std::setw(10) << "-";
    o << std::setw(9) << s.cpu_seconds << '\n';
  }
  o << std::left << std::setw(18) << "queue" << std::right << std::setw(8) << "cap" << std::setw(10) << "depth"
    << std::setw(10) << "max" << std::setw(10) << "dropped" << '\n';
  for (const auto& q : queues)
    o << std::left << std::setw(20) << q.name << std::right << std::setw(6) << q.capacity << std::setw(10) << q.depth
      << std::setw(10) << q.max_depth << std::setw(10) << q.dropped << '\n';
  o << "input scans lost before the pipeline: " << input_dropped_scans << "; wall " << wall_seconds << " s\n";
  return o.str();
}

std::string PipelineStats::json() const {
  std::ostringstream o;
  o << std::setprecision(6);
  o << "{\"wall_seconds\": " << wall_seconds << ", \"input_dropped_scans\": " << input_dropped_scans
    << ", \"stages\": [";
  for (std::size_t i = 0; i < stages.size(); ++i) {
    const auto& s = stages[i];
    o << (i ? ", " : "") << "{\"name\": " << jsonString(s.name) << ", \"count\": " << s.latency.count()
      << ", \"processed\": " << s.processed << ", \"p50_ms\": " << ms(s.latency.quantile(0.5))
      << ", \"p99_ms\": " << ms(s.latency.quantile(0.99)) << ", \"max_ms\": " << ms(s.latency.max())
      << ", \"cpu_seconds\": " << s.cpu_seconds << '}';
  }
  o << "], \"queues\": [";
  for (std::size_t i = 0; i < queues.size(); ++i) {
    const auto& q = queues[i];
    o << (i ? ", " : "") << "{\"name\": " << jsonString(q.name) << ", \"capacity\": " << q.capacity
      << ", \"depth\": " << q.depth << ", \"max_depth\": " << q.max_depth << ", \"dropped\": " << q.dropped << '}';
  }
  o << "]}";
  return o.str();
}

}  // namespace rigcal::pipeline
