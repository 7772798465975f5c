#include "rigcal/bag/point_cloud2_encoder.hpp"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <span>

#include "rigcal/bag/cdr_writer.hpp"

namespace rigcal::bag {

namespace {

// sensor_msgs/PointField datatypes.
enum Datatype : std::uint8_t { kUint8 = 2, kUint16 = 4, kUint32 = 6, kFloat32 = 7, kFloat64 = 8 };

// What a field carries, taken from the scan.
enum class Source {
  kX, kY, kZ, kIntensity, kIntensityU8, kRing, kReturn, kRelativeNs, kRelativeSeconds, kAbsoluteSeconds,
  kRange, kAzimuth, kElevation, kZero
};

struct FieldSpec {
  const char* name;
  std::uint32_t offset;
  std::uint8_t datatype;
  Source source;
};

struct LayoutSpec {
  std::uint32_t point_step;
  std::vector<FieldSpec> fields;
};

LayoutSpec layoutSpec(PointCloud2Layout layout) {
  using S = Source;
  switch (layout) {
    case PointCloud2Layout::kVelodyne:
      return {32, {{"x", 0, kFloat32, S::kX}, {"y", 4, kFloat32, S::kY}, {"z", 8, kFloat32, S::kZ},
                   {"intensity", 16, kFloat32, S::kIntensity}, {"ring", 20, kUint16, S::kRing},
                   {"time", 24, kFloat32, S::kRelativeSeconds}}};
    case PointCloud2Layout::kOuster:
      return {48, {{"x", 0, kFloat32, S::kX}, {"y", 4, kFloat32, S::kY}, {"z", 8, kFloat32, S::kZ},
                   {"intensity", 16, kFloat32, S::kIntensity}, {"t", 20, kUint32, S::kRelativeNs},
                   {"reflectivity", 24, kUint16, S::kZero}, {"ring", 26, kUint16, S::kRing},
                   {"ambient", 28, kUint16, S::kZero}, {"range", 32, kUint32, S::kRange}}};
    case PointCloud2Layout::kHesai:
      return {48, {{"x", 0, kFloat32, S::kX}, {"y", 4, kFloat32, S::kY}, {"z", 8, kFloat32, S::kZ},
                   {"intensity", 16, kFloat32, S::kIntensity}, {"timestamp", 24, kFloat64, S::kAbsoluteSeconds},
                   {"ring", 32, kUint16, S::kRing}}};
    case PointCloud2Layout::kLivox:
      return {20, {{"x", 0, kFloat32, S::kX}, {"y", 4, kFloat32, S::kY}, {"z", 8, kFloat32, S::kZ},
                   {"intensity", 12, kFloat32, S::kIntensity}, {"offset_time", 16, kUint32, S::kRelativeNs}}};
    case PointCloud2Layout::kNebula:
      return {32, {{"x", 0, kFloat32, S::kX}, {"y", 4, kFloat32, S::kY}, {"z", 8, kFloat32, S::kZ},
                   {"intensity", 12, kUint8, S::kIntensityU8}, {"return_type", 13, kUint8, S::kReturn},
                   {"channel", 14, kUint16, S::kRing}, {"azimuth", 16, kFloat32, S::kAzimuth},
                   {"elevation", 20, kFloat32, S::kElevation}, {"distance", 24, kFloat32, S::kRange},
                   {"time_stamp", 28, kUint32, S::kRelativeNs}}};
    case PointCloud2Layout::kRigcal:
      return {24, {{"x", 0, kFloat32, S::kX}, {"y", 4, kFloat32, S::kY}, {"z", 8, kFloat32, S::kZ},
                   {"intensity", 12, kFloat32, S::kIntensity}, {"t", 16, kUint32, S::kRelativeNs},
                   {"ring", 20, kUint16, S::kRing}, {"return_type", 22, kUint8, S::kReturn}}};
  }
  return {};
}

template <class T>
void store(std::uint8_t* p, T v) {
  std::memcpy(p, &v, sizeof v);
}

}  // namespace

std::string_view pointCloud2LayoutName(PointCloud2Layout layout) {
  switch (layout) {
    case PointCloud2Layout::kVelodyne: return "velodyne";
    case PointCloud2Layout::kOuster: return "ouster";
    case PointCloud2Layout::kHesai: return "hesai";
    case PointCloud2Layout::kLivox: return "livox";
    case PointCloud2Layout::kNebula: return "nebula";
    case PointCloud2Layout::kRigcal: return "rigcal";
  }
  return {};
}

std::vector<std::uint8_t> encodePointCloud2(const Scan& scan, std::string_view frame_id, PointCloud2Layout layout) {
  const LayoutSpec spec = layoutSpec(layout);
  const std::size_t n = scan.size();
  CdrWriter cdr;
  cdr.reserve(128 + frame_id.size() + spec.fields.size() * 32 + n * spec.point_step);
  cdr.putHeader(scan.stamp_ns, frame_id);
  cdr.put(std::uint32_t(1));  // height: unorganised
  cdr.put(std::uint32_t(n));  // width
  cdr.put(std::uint32_t(spec.fields.size()));
  for (const auto& f : spec.fields) {
    cdr.putString(f.name);
    cdr.put(f.offset);
    cdr.put(f.datatype);
    cdr.put(std::uint32_t(1));  // count
  }
  cdr.put(std::uint8_t(0));  // is_bigendian
  cdr.put(spec.point_step);
  cdr.put(std::uint32_t(n * spec.point_step));  // row_step
  cdr.put(std::uint32_t(n * spec.point_step));  // data length
  std::vector<std::uint8_t> data(n * spec.point_step, 0);
  for (std::size_t i = 0; i < n; ++i) {
    std::uint8_t* point = data.data() + i * spec.point_step;
    const double range = std::sqrt(double(scan.x[i]) * scan.x[i] + double(scan.y[i]) * scan.y[i] +
                                   double(scan.z[i]) * scan.z[i]);
    for (const auto& f : spec.fields) {
      std::uint8_t* p = point + f.offset;
      switch (f.source) {
        case Source::kX: store(p, scan.x[i]); break;
        case Source::kY: store(p, scan.y[i]); break;
        case Source::kZ: store(p, scan.z[i]); break;
        case Source::kIntensity: store(p, scan.intensity[i]); break;
        case Source::kIntensityU8:
          store(p, std::uint8_t(std::clamp(std::lround(scan.intensity[i]), 0L, 255L)));
          break;
        case Source::kRing: store(p, scan.ring[i]); break;
        case Source::kReturn: store(p, scan.return_index[i]); break;
        case Source::kRelativeNs: store(p, scan.offset_ns[i]); break;
        case Source::kRelativeSeconds: store(p, float(double(scan.offset_ns[i]) * 1e-9)); break;
        case Source::kAbsoluteSeconds: store(p, toSeconds(scan.pointTime(i))); break;
        case Source::kRange:
          if (f.datatype == kUint32)
            store(p, std::uint32_t(std::lround(range * 1000.0)));  // ouster-ros: millimetres
          else
            store(p, float(range));
          break;
        case Source::kAzimuth: store(p, float(std::atan2(scan.y[i], scan.x[i]))); break;
        case Source::kElevation: store(p, float(range > 0 ? std::asin(scan.z[i] / range) : 0.0)); break;
        case Source::kZero: break;
      }
    }
  }
  cdr.putBytes(data);
  cdr.put(std::uint8_t(1));  // is_dense
  return cdr.take();
}

}  // namespace rigcal::bag
