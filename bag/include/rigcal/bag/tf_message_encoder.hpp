#pragma once
// tf2_msgs/TFMessage serialised as CDR (layout in tf_message.hpp): what /tf_static carries.
#include <cstdint>
#include <span>
#include <vector>

#include "rigcal/bag/tf_message.hpp"

namespace rigcal::bag {

std::vector<std::uint8_t> encodeTfMessage(std::span<const StampedTransform> transforms);

}  // namespace rigcal::bag
