#pragma once
// base_link x and yaw of the mapping lidar from the drive itself. A car-like vehicle without side slip
// moves along its own x axis at the rear axle (base_link's origin, Autoware's convention):
//  - yaw: on straight stretches the lidar's motion, seen in its own frame levelled by the ground's roll
//    and pitch, points along base_link's x axis;
//  - x:   while turning, the lidar origin's lateral motion is ω·x (x = lidar x − rear axle x), so turns
//    give x; turns both ways also separate x from yaw (one turn direction alone trades one for the other).
//  - y:   not observable (any point on the axle line moves the same way): kept from the guess.
//
// Measurements are chords of the trajectory, each ~chord_m of travel in one direction: the displacement
// seen in the frame halfway (in rotation) between the chord's ends is exactly the tangent of a circular
// arc, and its lateral part equals 2·sin(Δθ/2)·x, so the model is exact on arcs and needs no timing.
// Chords do not overlap (independent noise, an honest standard deviation). Reversing flips both sides
// of the equation; stops and slow creeping are skipped by the speed threshold; a chord spanning a
// direction change (cusp) or a lost frame is dropped.
#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "rigcal/core/pose.hpp"
#include "rigcal/core/time.hpp"

namespace rigcal::calib {

enum class BaseFromMotionMode : std::uint8_t { kOff, kYaw, kYawX };

/// "off" | "yaw" | "yaw_x" (the rig parameter base_link_from_motion); throws std::invalid_argument.
BaseFromMotionMode parseBaseFromMotionMode(const std::string& text);

struct BaseFromMotionSettings {
  double chord_m = 1.0;                   // travel per measurement chord
  double min_speed_mps = 0.5;             // a chord slower than this on average is not used (stops, creeping)
  double max_chord_s = 4.0;               // nor one taking longer (with a gap or a stop inside)
  double straight_max_curvature = 0.01;   // 1/m: a chord this straight counts as straight driving
  double turn_min_curvature = 0.02;       // 1/m: a chord this curved counts as turning (left > 0, right < 0)
  double min_straight_m = 5.0;            // straight driving needed for yaw alone
  double min_turn_deg = 20.0;             // heading change needed in each direction for x
  double outlier_sigmas = 3.0;            // residuals beyond this many robust σ are rejected
};

/// One estimated quantity: its value, its standard deviation from the data's residuals, or why it was
/// kept from the guess.
struct MotionComponent {
  bool estimated = false;
  double value = 0.0;   // the estimate, else the guess (yaw in rad, x in m)
  double stddev = 0.0;  // from the residuals' scatter (0 when not estimated)
  std::string note;     // "not observable: ...; kept the guess" when not estimated
};

struct BaseFromMotionResult {
  MotionComponent yaw, x;
  /// The guess with yaw and x replaced where estimated (z, roll, pitch and y as given).
  Pose T_base_lidar = Pose::Identity();
  double moving_m = 0.0;         // travel in usable chords (above the speed threshold)
  double straight_m = 0.0;       // of which straight
  double left_turn_deg = 0.0;    // heading change in left-turning chords
  double right_turn_deg = 0.0;   // and in right-turning ones (positive)
  double reversing_m = 0.0;      // usable travel driven backwards
  std::size_t chords = 0;        // usable chords
  std::size_t chords_used = 0;   // of which in the final fit
  std::size_t outliers = 0;      // rejected by the robust fit
  double residual_rms_m = 0.0;   // of the final fit's lateral residuals
};

/// Estimates yaw (mode kYaw) or yaw and x (kYawX) of T_base_lidar from the lidar's trajectory
/// `T_map_lidar` at `stamps` (strictly increasing; `usable[i] == false` marks a lost frame, which no
/// chord spans; empty = all usable). `guess` is T_base_lidar with z, roll and pitch already right (the
/// ground's); its x, y and yaw are the starting point and what is kept when not observable.
BaseFromMotionResult estimateBaseFromMotion(const std::vector<TimeNs>& stamps, const std::vector<Pose>& T_map_lidar,
                                            const std::vector<bool>& usable, const Pose& guess,
                                            BaseFromMotionMode mode, const BaseFromMotionSettings& settings = {});

/// One line for the summary: which parts of T_base_lidar came from where and how well.
std::string describeBaseFromMotion(const BaseFromMotionResult& r);

}  // namespace rigcal::calib
