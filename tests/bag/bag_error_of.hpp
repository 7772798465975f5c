#pragma once
// The message of the BagError a call throws, checked to be one line; a test failure when it throws none.
#include <gtest/gtest.h>

#include <functional>
#include <string>

#include "rigcal/bag/bag_error.hpp"

namespace rigcal::bag::test {

inline std::string bagErrorOf(const std::function<void()>& call) {
  try {
    call();
  } catch (const BagError& e) {
    EXPECT_EQ(std::string(e.what()).find('\n'), std::string::npos) << e.what();
    return e.what();
  }
  ADD_FAILURE() << "expected a BagError";
  return {};
}

}  // namespace rigcal::bag::test
