// `rigcal register --target T.pcd --source S.pcd [--initial x y z roll pitch yaw | --initial-matrix FILE]
// [--out DIR]`: one pair of clouds from files (PCD in any layout, or PLY), registered with the lidar-lidar
// calibration's global stage, ensemble and score. Prints T_target_source, the overlap and which directions
// the scene leaves poorly constrained; --out gets registration.yaml, the before/after clouds and overlay.png.
#include <cmath>
#include <filesystem>
#include <fstream>
#include <iomanip>
#include <iostream>
#include <sstream>

#include "../commands.hpp"
#include "../exit_codes.hpp"
#include "../output_folder.hpp"
#include "rigcal/calib/lidar_lidar/cloud_pair_registration.hpp"
#include "rigcal/core/point_cloud_file.hpp"

namespace rigcal::app {
namespace {

namespace fs = std::filesystem;

struct RegisterArgs {
  std::string target, source, initial_matrix, out;
  std::vector<double> initial;  // x y z (m) roll pitch yaw (deg)
  double deadline = -1.0;       // < 0: calibration_deadline_s
  bool local = false, exhaustive = false;
  int threads = 2;
};

template <typename... Parts>
std::string cat(const Parts&... parts) {
  std::ostringstream o;
  (o << ... << parts);
  return o.str();
}

Scan readCloud(const std::string& path) {
  std::error_code ec;
  if (!fs::exists(path, ec)) throw CommandFailed(kExitInput, cat(path, ": not found"));
  PointTable table;
  try {
    table = readPointCloudFile(path);
  } catch (const std::exception& e) {
    throw CommandFailed(kExitInput, e.what());
  }
  if (!table.has("x") || !table.has("y") || !table.has("z"))
    throw CommandFailed(kExitInput, cat(path, ": no x, y, z fields"));
  Scan s = toScan(table);
  std::size_t finite = 0;
  for (std::size_t i = 0; i < s.size(); ++i)
    finite += std::isfinite(s.x[i]) && std::isfinite(s.y[i]) && std::isfinite(s.z[i]) ? 1 : 0;
  if (finite == 0) throw CommandFailed(kExitInput, cat(path, ": empty cloud (", s.size(), " points, none finite)"));
  return s;
}

// 16 numbers, row by row; brackets, commas and '#' comments (as registration.yaml writes them) are skipped.
Pose readMatrix(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw CommandFailed(kExitInput, cat(path, ": cannot open"));
  std::vector<double> v;
  for (std::string line; std::getline(in, line);) {
    line = line.substr(0, line.find('#'));
    for (char& c : line)
      if (c == '[' || c == ']' || c == ',') c = ' ';
    std::istringstream ls(line);
    for (std::string tok; ls >> tok;) {
      char* end = nullptr;
      const double d = std::strtod(tok.c_str(), &end);
      if (end != tok.c_str() && *end == '\0') v.push_back(d);
    }
  }
  if (v.size() != 16) throw CommandFailed(kExitInput, cat(path, ": ", v.size(), " numbers, a 4x4 matrix needs 16"));
  Eigen::Matrix4d M;
  for (int i = 0; i < 16; ++i) M(i / 4, i % 4) = v[std::size_t(i)];
  const Eigen::Matrix3d R = M.topLeftCorner<3, 3>();
  if (!M.allFinite() || (R.transpose() * R - Eigen::Matrix3d::Identity()).norm() > 1e-3 ||
      std::abs(R.determinant() - 1.0) > 1e-3 || (M.row(3) - Eigen::RowVector4d(0, 0, 0, 1)).norm() > 1e-9)
    throw CommandFailed(kExitInput, cat(path, ": not a rigid transform (rotation not orthonormal or last row not 0 0 0 1)"));
  Pose T = Pose::Identity();
  T.linear() = Eigen::Quaterniond(R).normalized().toRotationMatrix();
  T.translation() = M.topRightCorner<3, 1>();
  return T;
}

std::string formatPose(const Pose& T) {
  const XyzRpy v = toXyzRpy(T);
  std::ostringstream s;
  s << std::fixed << std::setprecision(4) << v.x << " " << v.y << " " << v.z << " m  " << std::setprecision(3)
    << rad2deg(v.roll) << " " << rad2deg(v.pitch) << " " << rad2deg(v.yaw) << " deg";
  return s.str();
}

int run(const RegisterArgs& a) {
  if (!a.initial.empty() && !a.initial_matrix.empty())
    throw CommandFailed(kExitUsage, "register: give --initial or --initial-matrix, not both");
  calib::CloudPairOptions opt;
  if (!a.initial.empty())
    opt.T_target_source_guess = fromXyzRpy({a.initial[0], a.initial[1], a.initial[2], deg2rad(a.initial[3]),
                                            deg2rad(a.initial[4]), deg2rad(a.initial[5])});
  if (!a.initial_matrix.empty()) opt.T_target_source_guess = readMatrix(a.initial_matrix);
  if (!a.out.empty()) prepareOutputFolder(a.out);
  const Scan target = readCloud(a.target);
  const Scan source = readCloud(a.source);
  config::Parameters params;
  opt.deadline_s = a.deadline >= 0 ? a.deadline : params.calibration_deadline_s;
  opt.global_search = !a.local;
  opt.exhaustive = a.exhaustive;
  opt.num_threads = a.threads;
  const auto r = calib::registerCloudPair(target, source, params, opt);

  if (!a.out.empty()) {
    try {
      calib::writeRegistrationYaml(fs::path(a.out) / "registration.yaml", r, a.target, a.source);
      if (r.ok) calib::writeRegistrationClouds(a.out, target, source, r);
    } catch (const std::exception& e) {
      throw CommandFailed(kExitFailure, e.what());
    }
  }
  if (!r.ok) throw CommandFailed(r.not_enough_data ? kExitNotEnoughData : kExitFailure, cat("register: ", r.failure));

  std::cout << std::setprecision(6) << "T_target_source: " << formatPose(r.T_target_source) << "\n"
            << "initial guess:   " << formatPose(r.T_target_source_guess) << "\n"
            << "score (m^2): initial " << r.guess_score.value << " (inliers " << r.guess_score.inlier_ratio
            << "), final " << r.final_score.value << " (inliers " << r.final_score.inlier_ratio
            << ", rmse " << r.final_score.rmse << " m)\n";
  if (r.global) {
    std::cout << "global search: " << (r.global->ground_used ? "ground planes fixed roll, pitch, height; " : "")
              << r.global->poses_scored << " poses in " << std::setprecision(3) << r.global->seconds << " s, best "
              << r.global->best_score;
    if (r.global->second_score)
      std::cout << ", second basin " << *r.global->second_score << " (x" << *r.global->second_score / std::max(r.global->best_score, 1e-12)
                << ")";
    std::cout << "\n";
    if (!r.global->ground_note.empty()) std::cout << "global search: " << r.global->ground_note << "\n";
  }
  std::cout << std::setprecision(3) << "overlap: " << 100 * r.source_overlap << " % of the source, "
            << 100 * r.target_overlap << " % of the target in the source's reach\n"
            << "information (share per direction, target frame):";
  for (const auto* block : {&r.information.translation, &r.information.rotation})
    for (const auto& d : *block) std::cout << " " << d.name << " " << std::setprecision(3) << d.share;
  std::cout << "\n";
  const auto weak = r.information.weakDirections();
  if (!weak.empty()) {
    std::cerr << "warning: poorly constrained by these clouds:";
    for (const auto& w : weak) std::cerr << " " << w;
    std::cerr << " (their values come from the start, not the data)\n";
  }
  if (!a.out.empty()) std::cout << "wrote " << (fs::path(a.out) / "registration.yaml").string() << "\n";
  return kExitOk;
}

}  // namespace

void addRegisterCommand(CLI::App& app) {
  auto a = std::make_shared<RegisterArgs>();
  auto* cmd = app.add_subcommand("register", "Register one pair of point clouds (PCD or PLY) with the calibration ensemble");
  cmd->add_option("--target", a->target, "Target cloud (PCD ascii/binary/binary_compressed, or PLY)")->required();
  cmd->add_option("--source", a->source, "Source cloud, registered into the target's frame")->required();
  cmd->add_option("--initial", a->initial, "Initial T_target_source: x y z (m) roll pitch yaw (deg)")->expected(6);
  cmd->add_option("--initial-matrix", a->initial_matrix, "Initial T_target_source as a 4x4 matrix file (16 numbers)");
  cmd->add_option("--out", a->out, "Write registration.yaml, target.pcd, source_before/after.pcd and overlay.png here");
  cmd->add_option("--deadline", a->deadline, "Seconds for the ensemble (default calibration_deadline_s, 10)")
      ->check(CLI::Range(0.0, 3600.0));
  cmd->add_flag("--local", a->local, "Skip the global stage (ground planes + coarse search): start from --initial");
  cmd->add_flag("--exhaustive", a->exhaustive, "Spend the time left on upstream's exhaustive ensemble");
  cmd->add_option("--threads", a->threads, "Threads")->check(CLI::Range(1, 64))->capture_default_str();
  cmd->footer(kExitCodesHelp);
  cmd->callback([a] { run(*a); });
}

}  // namespace rigcal::app
