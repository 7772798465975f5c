#include "rigcal/calib/outputs/summary_table.hpp"

#include <cstdio>
#include <sstream>

namespace rigcal::calib {
namespace {

std::string row(const std::string& pair, const std::string& result, const Pose& T, const Pose& initial,
                const std::string& score, const std::string& frames) {
  const XyzRpy v = toXyzRpy(T);
  const Pose change = initial.inverse() * T;
  char line[320];
  std::snprintf(line, sizeof line, "%-26s %-10s %8.3f %8.3f %8.3f %9.3f %9.3f %8.3f  %7.3f %7.3f  %-22s %s\n",
                pair.c_str(), result.c_str(), v.x, v.y, v.z, rad2deg(v.roll), rad2deg(v.pitch), rad2deg(v.yaw),
                change.translation().norm(), rad2deg(rotationAngle(change)), score.c_str(), frames.c_str());
  return line;
}

}  // namespace

std::string summaryTable(const CalibrationOutcome& o) {
  std::ostringstream out;
  char head[320];
  std::snprintf(head, sizeof head, "%-26s %-10s %8s %8s %8s %9s %9s %8s  %7s %7s  %-22s %s\n", "parent -> child",
                "result", "x m", "y m", "z m", "roll deg", "pitch deg", "yaw deg", "dt m", "dr deg", "score (rms m, inl.)",
                "frames");
  out << head;
  const auto initial_base = o.initial_T_base_sensor.count(o.mapping_sensor) != 0
                                ? o.initial_T_base_sensor.at(o.mapping_sensor)
                                : Pose::Identity();
  if (o.base) {
    char score[64];
    std::snprintf(score, sizeof score, "plane %zu inliers", o.base->plane.inliers);
    out << row(o.base_frame + " -> " + o.mapping_sensor, o.base->ok ? "ok" : "FAILED", o.T_base_mapping(),
               initial_base, o.base->ok ? score : o.base->failure, "-");
  }
  for (const auto& d : o.datasets) {
    const LidarLidarResult* r = o.lidar(d.calibration_sensor);
    const std::string pair = d.mapping_sensor + " -> " + d.calibration_sensor;
    if (r == nullptr) {
      out << row(pair, "not run", d.T_mapping_calib_guess, d.T_mapping_calib_guess, "-",
                 std::to_string(d.frames.size()) + " selected");
      continue;
    }
    char score[96];
    std::snprintf(score, sizeof score, "%.4f, %.2f", r->final_score.rmse, r->final_score.inlier_ratio);
    const std::string result = r->verdict == Verdict::kFailed       ? "FAILED"
                               : r->verdict == Verdict::kUnverified ? "unverified"
                               : r->deadline_reached                ? "ok (dl)"
                                                                    : "ok";
    out << row(pair, result, r->ok ? r->T_mapping_calib : r->T_mapping_calib_guess, r->T_mapping_calib_guess, score,
               std::to_string(r->frames_used.size()) + "/" + std::to_string(d.frames.size()));
  }
  for (const auto& r : o.lidars) {
    if (!r.ok) out << "  " << r.calibration_sensor << ": " << r.failure << "\n";
    else if (r.verdict == Verdict::kUnverified)
      out << "  " << r.calibration_sensor << ": unverified (not called ok): " << r.doubt << "\n";
    else if (r.deadline_reached && r.deadline_share_s >= 0) {
      char line[160];
      std::snprintf(line, sizeof line, "  %s: ran out of time (its share %.1f s of the %.0f s deadline); best result so far\n",
                    r.calibration_sensor.c_str(), r.deadline_share_s, o.deadline_s);
      out << line;
    }
  }
  for (const auto& r : o.lidars) {
    // The residual clock offset each result was judged with (after any time_offset_ns the rig applied).
    const LidarLidarEvidence& e = r.evidence;
    if (!e.clock_measured) continue;
    char line[256];
    std::snprintf(line, sizeof line, "  %s: clock %+.1f ms (± %.2f) against %s", r.calibration_sensor.c_str(),
                  e.clock_offset_ms, e.clock_offset_uncertainty_ms, r.mapping_sensor.c_str());
    out << line;
    if (e.time_offset_applied_ms != 0.0) {
      std::snprintf(line, sizeof line, " after its time_offset_ns (%+.1f ms)", e.time_offset_applied_ms);
      out << line;
    }
    out << "\n";
  }
  for (const auto& r : o.lidars) {
    // The residual clock offset against the mapping trajectory (no capture time needed), or why there is none.
    const TrajectoryClockEstimate& c = r.trajectory_clock;
    if (c.status == TrajectoryClockEstimate::Status::kNotRun) continue;
    char line[320];
    if (c.status == TrajectoryClockEstimate::Status::kEstimated)
      std::snprintf(line, sizeof line, "  %s: clock %+.1f ms (± %.1f) against %s's trajectory\n",
                    r.calibration_sensor.c_str(), c.offset_ms, c.uncertainty_ms, r.mapping_sensor.c_str());
    else {
      out << "  " << r.calibration_sensor << ": clock against " << r.mapping_sensor << "'s trajectory: "
          << toString(c.status) << " (" << c.note << ")\n";
      continue;
    }
    out << line;
  }
  for (const auto& w : o.warnings) out << "  warning: " << w << "\n";
  if (o.base && !o.base->ok) out << "  " << o.mapping_sensor << " (base): " << o.base->failure << "\n";
  if (o.base && o.base->ok) {
    // Which parts of base_link -> mapping lidar came from where.
    out << "  " << o.base_frame << " -> " << o.mapping_sensor << ": z, roll, pitch from the ground; ";
    if (o.base_motion) out << describeBaseFromMotion(*o.base_motion) << "\n";
    else out << "x, y, yaw from the guess (base_link_from_motion: off)\n";
  }
  if (!o.base && !o.base_skipped.empty())
    out << "  " << o.base_frame << " -> " << o.mapping_sensor << ": not calibrated (" << o.base_skipped
        << "); calibration.yaml keeps its initial extrinsic\n";
  out << "  ok (dl) = best result when the deadline (" << o.deadline_s << " s) was reached, confirmed by its frames and"
         " registrators; unverified = beats the guess but not confirmed; dt, dr = change from the initial guess\n";
  return out.str();
}

}  // namespace rigcal::calib
