#include "rigcal/calib/outputs/report_json_writer.hpp"
#include "rigcal/core/atomic_file.hpp"

#include <fstream>
#include <map>
#include <stdexcept>

namespace rigcal::calib {
namespace {

using nlohmann::json;

json xyzRpy(const Pose& T) {
  const XyzRpy v = toXyzRpy(T);
  return {{"x", v.x}, {"y", v.y}, {"z", v.z}, {"roll", v.roll}, {"pitch", v.pitch}, {"yaw", v.yaw}};
}

json scoreJson(const CalibrationScore& s) {
  return {{"value_m2", s.value}, {"rmse_m", s.rmse}, {"inlier_ratio", s.inlier_ratio}, {"points", s.points},
          {"inliers", s.inliers}};
}

json pairingJson(const pipeline::Pairing& p) {
  return {{"keyframe_frame", p.keyframe_frame},
          {"scan_sequence", p.scan_sequence},
          {"scan_stamp_ns", p.scan_stamp_ns},
          {"stopped", p.stopped},
          {"interpolation",
           {{"time_s", p.stats.time_s},
            {"distance_m", p.stats.distance_m},
            {"angle_deg", p.stats.angle_deg},
            {"speed_mps", p.stats.speed},
            {"accel_mps2", p.stats.accel}}}};
}

json lidarJson(const pipeline::CalibrationDataset& d, const LidarLidarResult* r) {
  json j;
  j["sensor"] = d.calibration_sensor;
  j["parent"] = d.mapping_sensor;
  j["budget_full"] = d.budget_full;
  j["initial"] = xyzRpy(d.T_mapping_calib_guess);
  json selected = json::array();
  for (std::size_t i = 0; i < d.frames.size(); ++i) {
    json f = pairingJson(d.frames[i].pairing);
    f["index"] = i;
    f["information"] = d.frames[i].information;
    f["points"] = d.frames[i].raw ? d.frames[i].raw->size() : 0;
    bool used = false;
    if (r != nullptr)
      for (const auto u : r->frames_used) used = used || u == i;
    f["used"] = used;
    selected.push_back(f);
  }
  j["selected_frames"] = selected;
  json rejected = json::array();
  for (const auto& rej : d.rejected) {
    json x = {{"candidate", rej.id}, {"reason", rej.reason}};
    if (rej.id < d.candidates.size()) x["pairing"] = pairingJson(d.candidates[rej.id]);
    rejected.push_back(x);
  }
  // Candidates the pairing rules already turned down carry their own reason.
  for (std::size_t i = 0; i < d.candidates.size(); ++i)
    if (!d.candidates[i].accepted && !d.candidates[i].rejection.empty())
      rejected.push_back({{"candidate", i}, {"reason", d.candidates[i].rejection}, {"pairing", pairingJson(d.candidates[i])}});
  j["rejections"] = rejected;
  if (r == nullptr) {
    j["calibrated"] = false;
    return j;
  }
  j["calibrated"] = true;
  j["ok"] = r->ok;  // beats the guess's score (the verdict says whether the evidence confirms it)
  if (!r->ok) j["failure"] = r->failure;
  j["verdict"] = toString(r->verdict);
  if (r->verdict == Verdict::kUnverified) j["doubt"] = r->doubt;
  const LidarLidarEvidence& e = r->evidence;
  j["evidence"] = {{"improvement", e.improvement},
                   {"frames_selected", e.frames_selected},
                   {"frames_registered", e.frames_registered},
                   {"frames_agreeing", e.frames_agreeing},
                   {"frame_spread_m", e.frame_spread_m},
                   {"frame_spread_deg", e.frame_spread_deg},
                   {"frame_uncertainty_m", e.frame_uncertainty_m},
                   {"frame_uncertainty_deg", e.frame_uncertainty_deg},
                   {"frame_uncertainty_weighted", e.frame_uncertainty_weighted},
                   {"registrators_agreeing", e.registrators_agreeing},
                   {"inlier_ratio", e.inlier_ratio},
                   {"clock_offset_ms", e.clock_offset_ms}};
  if (e.clock_measured) {
    j["evidence"]["clock_offset_uncertainty_ms"] = e.clock_offset_uncertainty_ms;
    j["evidence"]["time_offset_applied_ms"] = e.time_offset_applied_ms;
  }
  if (e.suggested_deadline_s > 0) j["evidence"]["suggested_deadline_s"] = e.suggested_deadline_s;
  const TrajectoryClockEstimate& tc = r->trajectory_clock;
  if (tc.status != TrajectoryClockEstimate::Status::kNotRun) {
    j["evidence"]["trajectory_clock_status"] = toString(tc.status);
    j["evidence"]["trajectory_clock_note"] = tc.note;
    j["evidence"]["trajectory_clock_seconds"] = tc.seconds;
    if (tc.status == TrajectoryClockEstimate::Status::kEstimated) {
      j["evidence"]["trajectory_clock_offset_ms"] = tc.offset_ms;
      j["evidence"]["trajectory_clock_uncertainty_ms"] = tc.uncertainty_ms;
    }
    json profile = json::array();
    for (const auto& [ms, cost] : tc.profile) profile.push_back({ms, cost});
    j["evidence"]["trajectory_clock_profile"] = profile;  // (trial offset ms, cost m² per point)
  }
  j["deadline_reached"] = r->deadline_reached;  // this lidar ran out of time (its result is the best so far)
  if (r->deadline_share_s >= 0) j["deadline_share_s"] = r->deadline_share_s;
  j["result"] = xyzRpy(r->T_mapping_calib);
  const Pose change = r->T_mapping_calib_guess.inverse() * r->T_mapping_calib;
  j["change_from_initial"] = {{"translation_m", change.translation().norm()},
                              {"rotation_deg", rad2deg(rotationAngle(change))}};
  j["initial_score"] = scoreJson(r->initial_score);
  j["final_score"] = scoreJson(r->final_score);
  j["seconds"] = r->seconds;
  json stages = json::object();
  for (const auto& [name, s] : r->stage_seconds) stages[name] = s;
  j["stage_seconds"] = stages;
  j["frames_skipped"] = r->frames_skipped;
  j["frames_set_aside"] = r->frames_set_aside;
  json runs = json::array();
  std::map<std::string, json> totals;
  for (const auto& run : r->runs) {
    json x = {{"registrator", run.registrator}, {"frame", run.frame},       {"start_candidate", run.start},
              {"seconds", run.seconds},         {"iterations", run.iterations}, {"status", run.status}};
    if (run.max_distance > 0) x["max_distance_m"] = run.max_distance;
    if (run.frame_score >= 0) x["frame_score_m2"] = run.frame_score;
    if (run.score >= 0) x["score_m2"] = run.score;
    if (run.redeskewed) x["redeskewed"] = true;
    runs.push_back(x);
    json& t = totals[run.registrator];
    if (t.is_null()) t = {{"runs", 0}, {"seconds", 0.0}};
    t["runs"] = t["runs"].get<int>() + 1;
    t["seconds"] = t["seconds"].get<double>() + run.seconds;
    if (run.score >= 0 && (!t.contains("best_score_m2") || run.score < t["best_score_m2"].get<double>()))
      t["best_score_m2"] = run.score;
  }
  j["registrations"] = runs;
  json per = json::object();
  for (auto& [name, t] : totals) per[name] = t;
  j["per_registrator"] = per;
  return j;
}

}  // namespace

json reportJson(const CalibrationOutcome& o) {
  json j;
  j["version"] = o.version;
  j["rig"] = o.rig_name;
  j["base_frame"] = o.base_frame;
  j["mapping_sensor"] = o.mapping_sensor;
  j["deadline_s"] = o.deadline_s;
  j["status"] = o.status();
  if (!o.failure.empty()) j["failure"] = o.failure;
  json stages = json::object();
  for (const auto& [name, s] : o.stage_seconds) stages[name] = s;
  j["stage_seconds"] = stages;
  json input = json::object();
  for (const auto& [k, v] : o.input_summary) input[k] = v;
  j["input"] = input;
  j["warnings"] = o.warnings;
  if (o.base) {
    json b = {{"ok", o.base->ok}, {"cropped_points", o.base->cropped_points}};
    if (!o.base->ok) b["failure"] = o.base->failure;
    if (o.base->keyframes_tried > 0)
      b["keyframes"] = {{"tried", o.base->keyframes_tried},
                        {"used", o.base->keyframes_used},
                        {"spread_z_m", o.base->spread_z},
                        {"spread_roll_deg", o.base->spread_roll_deg},
                        {"spread_pitch_deg", o.base->spread_pitch_deg}};
    b["result"] = xyzRpy(o.base->T_base_lidar);
    b["plane"] = {{"normal", {o.base->plane.normal.x(), o.base->plane.normal.y(), o.base->plane.normal.z()}},
                  {"d", o.base->plane.d},
                  {"inliers", o.base->plane.inliers},
                  {"inlier_percentage", o.base->plane.inlier_percentage}};
    // Where each component of the result came from, and the motion estimate's support and spread.
    const auto& m = o.base_motion;
    const auto from = [&](const MotionComponent* c) { return c != nullptr && c->estimated ? "motion" : "guess"; };
    b["sources"] = {{"x", from(m ? &m->x : nullptr)}, {"y", "guess"}, {"z", "ground"}, {"roll", "ground"},
                    {"pitch", "ground"}, {"yaw", from(m ? &m->yaw : nullptr)}};
    if (m) {
      const auto component = [](const MotionComponent& c, double scale) {
        json e = {{"estimated", c.estimated}, {"value", c.value * scale}, {"stddev", c.stddev * scale}};
        if (!c.estimated) e["note"] = c.note;
        return e;
      };
      b["motion"] = {{"yaw_deg", component(m->yaw, rad2deg(1.0))},
                     {"x_m", component(m->x, 1.0)},
                     {"y", "not observable from motion; kept the guess"},
                     {"moving_m", m->moving_m},
                     {"straight_m", m->straight_m},
                     {"left_turn_deg", m->left_turn_deg},
                     {"right_turn_deg", m->right_turn_deg},
                     {"reversing_m", m->reversing_m},
                     {"chords", m->chords},
                     {"chords_used", m->chords_used},
                     {"outliers", m->outliers},
                     {"residual_rms_m", m->residual_rms_m}};
    }
    j["base_lidar"] = b;
  } else if (!o.base_skipped.empty()) {
    j["base_lidar_skipped"] = o.base_skipped;
  }
  const auto it = o.initial_T_base_sensor.find(o.mapping_sensor);
  if (it != o.initial_T_base_sensor.end()) j["base_lidar_initial"] = xyzRpy(it->second);
  json lidars = json::array();
  for (const auto& d : o.datasets) lidars.push_back(lidarJson(d, o.lidar(d.calibration_sensor)));
  j["lidars"] = lidars;
  json all = json::object();
  for (const auto& [name, T] : o.T_base_sensor()) all[name] = xyzRpy(T);
  j["T_base_sensor"] = all;
  return j;
}

void writeReportJson(const std::filesystem::path& path, const CalibrationOutcome& outcome) {
  writeFileAtomically(path, [&](std::ostream& out) { out << reportJson(outcome).dump(2) << "\n"; });
}

}  // namespace rigcal::calib
