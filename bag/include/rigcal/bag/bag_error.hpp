#pragma once
// The one exception the bag readers throw: a one-line message naming the file and the record offset,
// topic or field that is wrong.
#include <stdexcept>
#include <string>

namespace rigcal::bag {

struct BagError : std::runtime_error {
  using std::runtime_error::runtime_error;
};

}  // namespace rigcal::bag
