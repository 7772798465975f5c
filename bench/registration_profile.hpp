#pragma once
// `registration_bench --profile CASE [N]`: one case N times with callgrind's instrumentation on only
// around the measured calls (see registration_profile.cpp for the cases).
#include <string>

namespace rigcal::bench {

int registrationProfile(const std::string& which, int runs);

}  // namespace rigcal::bench
