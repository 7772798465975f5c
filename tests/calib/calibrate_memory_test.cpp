// Issue #18 (resource bounds): the peak memory of `rigcal calibrate` through the real binary, read from the
// kernel (wait4's ru_maxrss of that one child, not of the `rigcal sim` before it).
//
// Measured on the 12 s parking-lot drive below (Release, 2 shared cores at load ~15): 440 MB before
// issue #18's fixes (the deskew stage held every calibration scan to the end of input), 320 MB after.
// Then (load 4-9): 287-303 MB with targets that kept 4x4 covariances, 231-240 MB with compact ones; 238 MB
// before targets were built from keyframes' clouds only (shared by neighbouring candidates), 199 MB since
// (192-215 MB at load 6-8).
#include <gtest/gtest.h>

#include <fcntl.h>
#include <spawn.h>
#include <sys/resource.h>
#include <sys/wait.h>

#include <filesystem>
#include <string>
#include <vector>

#include "calibrate_chain.hpp"
#include "sanitizers.hpp"
#include "test_data.hpp"

extern char** environ;

namespace rigcal::test {
namespace {

struct ChildUsage {
  int exit_code = -1;
  long peak_rss_kb = 0;
};

/// Runs the rigcal binary with `args` (output to files in `dir`) and returns its exit code and peak RSS.
ChildUsage runMeasured(const std::vector<std::string>& args, const std::filesystem::path& dir) {
  std::vector<std::string> storage{rigcalBinary().string()};
  storage.insert(storage.end(), args.begin(), args.end());
  std::vector<char*> argv;
  for (auto& a : storage) argv.push_back(a.data());
  argv.push_back(nullptr);
  posix_spawn_file_actions_t actions;
  posix_spawn_file_actions_init(&actions);
  posix_spawn_file_actions_addopen(&actions, 1, (dir / "calibrate.out").c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
  posix_spawn_file_actions_addopen(&actions, 2, (dir / "calibrate.err").c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
  pid_t pid = 0;
  const int rc = posix_spawn(&pid, storage.front().c_str(), &actions, nullptr, argv.data(), environ);
  posix_spawn_file_actions_destroy(&actions);
  ChildUsage u;
  if (rc != 0) return u;
  int status = 0;
  rusage usage{};
  if (wait4(pid, &status, 0, &usage) != pid) return u;
  u.exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
  u.peak_rss_kb = usage.ru_maxrss;  // Linux: kilobytes
  return u;
}

/// `rigcal sim` of the parking-lot demo (with `sim_args`) into dir/sim, then `rigcal calibrate` of it into
/// dir/out (with `calibrate_args`), measured. Asserts only that the simulation worked.
ChildUsage calibrateParkingLot(const TempDir& dir, const std::vector<std::string>& sim_args,
                               const std::vector<std::string>& calibrate_args) {
  const auto sim = dir / "sim";
  std::vector<std::string> args{"sim", "--scenario", "parking-lot", "--out", sim.string()};
  args.insert(args.end(), sim_args.begin(), sim_args.end());
  const auto simulated = runRigcal(args);
  EXPECT_EQ(simulated.exit_code, 0) << simulated.err;
  if (simulated.exit_code != 0) return {};
  return runMeasured(calibrateArgs(sim, dir / "out", calibrate_args), dir.path());
}

// A 12 s drive of the demo's scenario (two VLP-16 calibration lidars, a 64-beam mapping lidar): its peak
// RSS stays under a bound that catches the regression keyframe-only target clouds fixed (+39 MB: 238 MB
// against 199 MB, quiet). Since the next frame's crop is prepared beside the current target's build (one
// more crop and voxel map alive at once) it measures 202-230 MB quiet (median 211 in 13 runs; main before
// it 195-218, median 205), so the bound is 250 MB. Release only: sanitizers and debug builds allocate
// differently.
TEST(CalibrateMemory, PeakRssOfAShortDriveStaysBounded) {
#ifndef NDEBUG
  GTEST_SKIP() << "peak memory is asserted in optimised builds only";
#endif
  if (kSanitized) GTEST_SKIP() << "peak memory is asserted in uninstrumented builds only";
  constexpr long kBoundKb = 250 * 1024;
  TempDir dir;
  // A short deadline: the calibration's targets are part of the peak, and the test stays short. 4 s: with
  // 2 s (a 1 s share a lidar) beside the shared-memory driver processes' test under ctest -j 2, front_left's
  // first registration did not finish (exit 1: nothing beat the guess).
  const ChildUsage u = calibrateParkingLot(dir, {"--duration", "12"}, {"--deadline", "4"});
  // 0 ok, 6 unverified (a short deadline on a loaded machine): either way it calibrated and wrote its outputs.
  ASSERT_TRUE(u.exit_code == 0 || u.exit_code == 6)
      << "exit " << u.exit_code << ": " << fileContents(dir / "calibrate.err");
  EXPECT_TRUE(std::filesystem::exists(dir / "out" / "calibration.yaml"));
  EXPECT_GT(u.peak_rss_kb, 0);
  EXPECT_LT(u.peak_rss_kb, kBoundKb) << "peak RSS " << u.peak_rss_kb / 1024 << " MB";
}

// Issue #18's goal on the demo itself: the whole parking-lot drive, default deadline, under 500 MB (0.7-1.1
// GB when the issue was filed; 516-528 MB before targets were built from keyframes' clouds only, which
// neighbouring candidates share: 404-428 MB since, quiet and at load 5). ~2 min: RIGCAL_LONG_TESTS=1.
TEST(CalibrateMemoryLong, TheParkingLotDemoStaysUnder500Mb) {
  if (!longTests()) GTEST_SKIP() << "long test: set RIGCAL_LONG_TESTS=1 (Release only)";
#ifndef NDEBUG
  GTEST_SKIP() << "peak memory is asserted in optimised builds only";
#endif
  if (kSanitized) GTEST_SKIP() << "peak memory is asserted in uninstrumented builds only";
  TempDir dir;
  const ChildUsage u = calibrateParkingLot(dir, {}, {});
  ASSERT_TRUE(u.exit_code == 0 || u.exit_code == 6)
      << "exit " << u.exit_code << ": " << fileContents(dir / "calibrate.err");
  EXPECT_LT(u.peak_rss_kb, 500L * 1024) << "peak RSS " << u.peak_rss_kb / 1024 << " MB";
  RecordProperty("peak_rss_mb", static_cast<int>(u.peak_rss_kb / 1024));
}

}  // namespace
}  // namespace rigcal::test
