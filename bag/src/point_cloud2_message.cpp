#include "rigcal/bag/point_cloud2_message.hpp"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>
#include <optional>
#include <vector>

#include "rigcal/bag/cdr_reader.hpp"

namespace rigcal::bag {

namespace {

// sensor_msgs/PointField datatypes.
enum Datatype : std::uint8_t { kInt8 = 1, kUint8, kInt16, kUint16, kInt32, kUint32, kFloat32, kFloat64 };

std::size_t datatypeSize(std::uint8_t t) {
  switch (t) {
    case kInt8: case kUint8: return 1;
    case kInt16: case kUint16: return 2;
    case kInt32: case kUint32: case kFloat32: return 4;
    case kFloat64: return 8;
    default: return 0;
  }
}

struct Field {
  std::uint32_t offset = 0;
  std::uint8_t datatype = 0;
};

double readAs(const std::uint8_t* p, std::uint8_t datatype) {
  auto get = [p]<class T>(T) {
    T v;
    std::memcpy(&v, p, sizeof v);
    return double(v);
  };
  switch (datatype) {
    case kInt8: return get(std::int8_t{});
    case kUint8: return get(std::uint8_t{});
    case kInt16: return get(std::int16_t{});
    case kUint16: return get(std::uint16_t{});
    case kInt32: return get(std::int32_t{});
    case kUint32: return get(std::uint32_t{});
    case kFloat32: return get(float{});
    default: return get(double{});
  }
}

enum class TimeKind { kRelativeNs, kRelativeSeconds, kAbsoluteSecondsOrRelative };

struct TimeField {
  const char* name;
  TimeKind kind;
};
constexpr TimeField kTimeFields[] = {{"t", TimeKind::kRelativeNs},
                                     {"time_stamp", TimeKind::kRelativeNs},
                                     {"offset_time", TimeKind::kRelativeNs},
                                     {"time", TimeKind::kRelativeSeconds},
                                     {"timestamp", TimeKind::kAbsoluteSecondsOrRelative}};

}  // namespace

DecodedCloud decodePointCloud2(std::span<const std::uint8_t> message, const std::string& what) {
  CdrReader cdr(message, what);
  DecodedCloud out;
  const RosHeader header = cdr.readHeader();
  out.header_stamp_ns = header.stamp_ns;
  out.frame_id = header.frame_id;
  const auto height = cdr.read<std::uint32_t>("height");
  const auto width = cdr.read<std::uint32_t>("width");
  const auto field_count = cdr.readCount("fields", 4 + 4 + 1 + 4);
  std::optional<Field> x, y, z, intensity, ring, time;
  TimeKind time_kind = TimeKind::kRelativeNs;
  std::size_t time_rank = std::size(kTimeFields);
  std::vector<std::pair<Field, std::string>> fields;
  for (std::uint32_t i = 0; i < field_count; ++i) {
    const std::string name(cdr.readString("fields[].name"));
    Field f;
    f.offset = cdr.read<std::uint32_t>("fields[].offset");
    f.datatype = cdr.read<std::uint8_t>("fields[].datatype");
    cdr.read<std::uint32_t>("fields[].count");
    if (datatypeSize(f.datatype) == 0)
      throw BagError(what + ": field " + name + " has unknown datatype " + std::to_string(f.datatype));
    fields.emplace_back(f, name);
    if (name == "x") x = f;
    if (name == "y") y = f;
    if (name == "z") z = f;
    if (name == "intensity" || (name == "reflectivity" && !intensity)) intensity = f;
    if (name == "ring" || (name == "channel" && !ring)) ring = f;
    for (std::size_t r = 0; r < std::size(kTimeFields); ++r)
      if (name == kTimeFields[r].name && r < time_rank) {
        time = f;
        time_kind = kTimeFields[r].kind;
        time_rank = r;
        out.time_field = name;
      }
  }
  if (cdr.read<std::uint8_t>("is_bigendian") != 0) throw BagError(what + ": big-endian point data is not supported");
  const auto point_step = cdr.read<std::uint32_t>("point_step");
  const auto row_step = cdr.read<std::uint32_t>("row_step");
  const auto data_size = cdr.readCount("data", 1);
  const auto data = cdr.take(data_size, "data");
  if (!x || !y || !z) throw BagError(what + ": PointCloud2 without x, y and z fields");
  for (const auto& [f, name] : fields)
    if (std::uint64_t(f.offset) + datatypeSize(f.datatype) > point_step)
      throw BagError(what + ": field " + name + " at offset " + std::to_string(f.offset) + " lies outside point_step " +
                     std::to_string(point_step));
  if (std::uint64_t(point_step) * width > row_step)
    throw BagError(what + ": row_step " + std::to_string(row_step) + " is less than width " + std::to_string(width) +
                   " x point_step " + std::to_string(point_step));
  if (std::uint64_t(row_step) * height > data.size())
    throw BagError(what + ": message shorter than its layout: data holds " + std::to_string(data.size()) +
                   " bytes, height " + std::to_string(height) + " x row_step " + std::to_string(row_step) + " needs " +
                   std::to_string(std::uint64_t(row_step) * height));

  const std::size_t n = std::size_t(height) * width;
  std::vector<Point> points;
  points.reserve(n);
  for (std::uint32_t row = 0; row < height; ++row) {
    const std::uint8_t* row_data = data.data() + std::size_t(row) * row_step;
    for (std::uint32_t col = 0; col < width; ++col) {
      const std::uint8_t* p = row_data + std::size_t(col) * point_step;
      Point pt;
      pt.x = float(readAs(p + x->offset, x->datatype));
      pt.y = float(readAs(p + y->offset, y->datatype));
      pt.z = float(readAs(p + z->offset, z->datatype));
      if (!std::isfinite(pt.x) || !std::isfinite(pt.y) || !std::isfinite(pt.z)) {
        ++out.dropped_nan;
        continue;
      }
      if (intensity) pt.intensity = float(readAs(p + intensity->offset, intensity->datatype));
      if (ring) pt.ring = std::uint16_t(readAs(p + ring->offset, ring->datatype));
      pt.time_ns = header.stamp_ns;
      if (time) {
        const double v = readAs(p + time->offset, time->datatype);
        if (time_kind == TimeKind::kRelativeNs)
          pt.time_ns += TimeNs(v);
        else if (time_kind == TimeKind::kRelativeSeconds || v < 1e6)
          pt.time_ns += fromSeconds(v);
        else
          pt.time_ns = fromSeconds(v);
      }
      points.push_back(pt);
    }
  }
  TimeNs earliest = points.empty() ? header.stamp_ns : points.front().time_ns;
  TimeNs latest = earliest;
  for (const Point& p : points) {
    earliest = std::min(earliest, p.time_ns);
    latest = std::max(latest, p.time_ns);
  }
  if (latest - earliest > TimeNs(std::numeric_limits<std::uint32_t>::max()))
    throw BagError(what + ": per-point " + out.time_field + " spans " + std::to_string(toSeconds(latest - earliest)) +
                   " s, more than one sweep can");
  out.scan.stamp_ns = earliest;
  out.scan.reserve(points.size());
  for (const Point& p : points) out.scan.push_back(p);
  return out;
}

}  // namespace rigcal::bag
