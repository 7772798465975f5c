#include "registration_profile.hpp"

#include <valgrind/callgrind.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <ctime>
#include <vector>

#include "registration_bench_data.hpp"
#include "rigcal/registration/covariance.hpp"
#include "rigcal/registration/gicp.hpp"

namespace rigcal::bench {

using namespace rigcal::registration;

// `registration_bench --profile CASE [N]`: runs one case N times (default 5) with callgrind's
// instrumentation on only around the alignments, so `valgrind --tool=callgrind --instr-atstart=no` counts
// exactly their instructions (machine-independent, unlike times on this shared machine). CASE is
// s2s-gicp-cov, s2s-gicp, s2m-gicp-cov, s2m-gicp or cov (source covariances alone).
int registrationProfile(const std::string& which, int runs) {
  const Scenario* s = which.rfind("s2m", 0) == 0 ? &data().map : &data().scan;
  // s2s-target / s2m-target: a Target from positions only (tree, covariances, neighbour graph; no NDT
  // grid), 1 thread: what the mapper's local-map build does at each keyframe.
  if (which.find("-target") != std::string::npos) {
    PointCloud positions;
    positions.points = s->target->cloud().points;
    TargetOptions target_options;
    target_options.normals_and_covariances = true;
    std::vector<double> target_ms;
    std::size_t graph_size = 0;
    for (int i = 0; i < runs; ++i) {
      PointCloud copy = positions;
      const auto start = std::chrono::steady_clock::now();
      CALLGRIND_START_INSTRUMENTATION;
      const Target t(std::move(copy), target_options);
      CALLGRIND_STOP_INSTRUMENTATION;
      target_ms.push_back(std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count());
      graph_size = t.neighborGraph().offsets.size();
    }
    std::sort(target_ms.begin(), target_ms.end());
    std::printf("%s: %zu points, %d runs, median %.2f ms, min %.2f ms (graph entries %zu)\n", which.c_str(),
                positions.size(), runs, target_ms[target_ms.size() / 2], target_ms[0], graph_size);
    return 0;
  }
  const bool with_cov = which == "cov" || which.find("-cov") != std::string::npos;
  GicpParams params = commonParams<GicpParams>(1);
  params.max_correspondence_distance = 1.0;
  RegistrationResult r;
  std::vector<double> ms, cpu_ms;
  const auto thread_cpu_ms = [] {
    timespec ts{};
    clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
    return static_cast<double>(ts.tv_sec) * 1e3 + static_cast<double>(ts.tv_nsec) * 1e-6;
  };
  for (int i = 0; i < runs; ++i) {
    const auto start = std::chrono::steady_clock::now();
    const double cpu_start = thread_cpu_ms();
    CALLGRIND_START_INSTRUMENTATION;
    if (with_cov) {
      PointCloud src = data().source;
      estimateCovariances(src);
      if (which != "cov") r = alignGicp(*s->target, src, Pose::Identity(), params);
    } else {
      r = alignGicp(*s->target, data().source_cov, Pose::Identity(), params);
    }
    CALLGRIND_STOP_INSTRUMENTATION;
    ms.push_back(std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count());
    cpu_ms.push_back(thread_cpu_ms() - cpu_start);
  }
  std::sort(ms.begin(), ms.end());
  std::sort(cpu_ms.begin(), cpu_ms.end());
  const Pose e = data().truth.inverse() * r.T_target_source;
  std::printf("%s: %d runs, median %.2f ms (CPU %.2f), min %.2f ms (CPU %.2f); %d iterations, error %.3f mm / %.5f deg\n",
              which.c_str(), runs, ms[ms.size() / 2], cpu_ms[cpu_ms.size() / 2], ms[0], cpu_ms[0], r.iterations, e.translation().norm() * 1e3, rad2deg(rotationAngle(e)));
  return 0;
}

}  // namespace rigcal::bench
