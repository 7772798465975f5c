// A Target build (tree, k-NN covariances, NDT grid) under a deadline: on a busy machine it can take several
// times its estimate, and a calibration's deadline is a hard bound, so the build stops once the deadline
// expires and says so; a deadline that does not expire changes nothing in what is built.
#include <gtest/gtest.h>

#include <chrono>
#include <cstring>

#include "rigcal/registration/target.hpp"
#include "sanitizers.hpp"
#include "scenes.hpp"

namespace rigcal::registration {
namespace {

using Clock = std::chrono::steady_clock;

TargetOptions fullOptions() {
  TargetOptions o;
  o.normals_and_covariances = true;
  o.ndt_resolutions = {1.0};
  o.num_threads = 2;
  return o;
}

TEST(TargetDeadline, AnExpiredDeadlineStopsTheBuildAndSaysSo) {
  TargetOptions o = fullOptions();
  o.deadline = Deadline::after(Clock::duration::zero());
  const Target t(test::room(0.1), o);
  EXPECT_TRUE(t.stopped());
  EXPECT_EQ(t.ndtGrid(1.0), nullptr) << "nothing is built after the deadline";
}

TEST(TargetDeadline, ADeadlineThatDoesNotExpireBuildsTheSameTarget) {
  TargetOptions with = fullOptions();
  with.deadline = Deadline::after(std::chrono::hours(1));
  const Target a(test::room(0.1), fullOptions()), b(test::room(0.1), with);
  ASSERT_FALSE(b.stopped());
  ASSERT_EQ(a.size(), b.size());
  ASSERT_TRUE(b.hasCovariances());
  ASSERT_EQ(a.covarianceUpperFloat().size(), b.covarianceUpperFloat().size());
  EXPECT_EQ(std::memcmp(a.covarianceUpperFloat().data(), b.covarianceUpperFloat().data(),
                        a.covarianceUpperFloat().size_bytes()),
            0)
      << "bit-identical covariances";
  ASSERT_NE(b.ndtGrid(1.0), nullptr);
  EXPECT_EQ(a.neighborGraph().offsets, b.neighborGraph().offsets);
}

// Cancelled part-way (another thread, as Ctrl-C or a calibration deadline would): the build returns soon
// after, well before a whole build's time.
TEST(TargetDeadline, ACancelDuringTheBuildStopsItSoonAfter) {
  const PointCloud cloud = test::room(rigcal::test::kSanitized ? 0.05 : 0.02);
  auto t0 = Clock::now();
  const Target whole(cloud, fullOptions());
  const double whole_s = std::chrono::duration<double>(Clock::now() - t0).count();
  ASSERT_FALSE(whole.stopped());
  TargetOptions o = fullOptions();
  const auto cut = std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(whole_s / 5));
  o.deadline = Deadline::after(cut);
  t0 = Clock::now();
  const Target part(cloud, o);
  const double part_s = std::chrono::duration<double>(Clock::now() - t0).count();
  std::printf("%zu points: whole build %.3f s, stopped at %.3f s (deadline %.3f s)\n", whole.size(), whole_s, part_s,
              whole_s / 5);
  EXPECT_TRUE(part.stopped());
  if (!rigcal::test::kSanitized) {
    EXPECT_LT(part_s, 0.8 * whole_s) << "stopped well before a whole build";
  }
}

}  // namespace
}  // namespace rigcal::registration
