#pragma once
// RIGCAL_SANITIZED is 1 in ASan/UBSan/TSan builds with either GCC (__SANITIZE_*__) or clang
// (__has_feature), so tests can size their data for instrumented code, which runs 10-50x slower.
#if defined(__SANITIZE_THREAD__) || defined(__SANITIZE_ADDRESS__)
#define RIGCAL_SANITIZED 1
#elif defined(__has_feature)
#if __has_feature(thread_sanitizer) || __has_feature(address_sanitizer)
#define RIGCAL_SANITIZED 1
#endif
#endif
#ifndef RIGCAL_SANITIZED
#define RIGCAL_SANITIZED 0
#endif

// RIGCAL_TSAN is 1 under ThreadSanitizer only.
#if defined(__SANITIZE_THREAD__)
#define RIGCAL_TSAN 1
#elif defined(__has_feature)
#if __has_feature(thread_sanitizer)
#define RIGCAL_TSAN 1
#endif
#endif
#ifndef RIGCAL_TSAN
#define RIGCAL_TSAN 0
#endif

namespace rigcal::test {
/// RIGCAL_SANITIZED as a constant for `if constexpr` / ternaries that size a test's workload.
inline constexpr bool kSanitized = RIGCAL_SANITIZED != 0;
/// Wall-clock bounds are asserted only in optimised, uninstrumented builds: instrumented code runs 10-50x
/// slower and a loaded CI machine deschedules it, so under sanitizers a test asserts behaviour, not speed.
inline constexpr bool kWallClockAsserted = !kSanitized;
}  // namespace rigcal::test
