// makeDecoder: picks the vendor decoder for a model name. Each vendor lists its own models.
#include <algorithm>
#include <stdexcept>

#include "rigcal/drivers/hesai/hesai_decoder.hpp"
#include "rigcal/drivers/ouster/ouster_decoder.hpp"
#include "rigcal/drivers/packet_decoder.hpp"
#include "rigcal/drivers/robosense/robosense_decoder.hpp"
#include "rigcal/drivers/velodyne/velodyne_decoder.hpp"

namespace rigcal::drivers {

namespace {
struct Vendor {
  std::vector<std::string> (*models)();
  std::unique_ptr<PacketDecoder> (*make)(const DecoderConfig&);
};

const std::vector<Vendor>& vendors() {
  static const std::vector<Vendor> table = {
      {velodyneModels, [](const DecoderConfig& c) { return makeVelodyneDecoder(c); }},
      {ousterModels, makeOusterDecoder},
      {hesaiModels, makeHesaiDecoder},
      {robosenseModels, makeRobosenseDecoder},
  };
  return table;
}
}  // namespace

std::vector<std::string> supportedModels() {
  std::vector<std::string> all;
  for (const Vendor& v : vendors())
    for (auto& m : v.models()) all.push_back(std::move(m));
  return all;
}

std::unique_ptr<PacketDecoder> makeDecoder(const DecoderConfig& config) {
  for (const Vendor& v : vendors()) {
    const auto models = v.models();
    if (std::find(models.begin(), models.end(), config.model) != models.end()) return v.make(config);
  }
  std::string list;
  for (const auto& m : supportedModels()) list += (list.empty() ? "" : ", ") + m;
  throw std::runtime_error("unknown lidar model '" + config.model + "' (supported: " + list + ")");
}

}  // namespace rigcal::drivers
