#pragma once
// A point cloud as named, typed columns: the neutral form our PCD and PLY readers and writers exchange,
// and what tests compare against vendors' reference files. Values are held as double (exact for every
// field type we write up to 2^53).
#include <cstddef>
#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

#include "rigcal/core/scan.hpp"

namespace rigcal {

enum class FieldType : std::uint8_t { kI8, kU8, kI16, kU16, kI32, kU32, kI64, kU64, kF32, kF64 };

std::size_t fieldSize(FieldType t);

struct PointField {
  std::string name;
  FieldType type = FieldType::kF32;
  std::vector<double> values;
};

class PointTable {
 public:
  [[nodiscard]] std::size_t size() const { return fields_.empty() ? 0 : fields_.front().values.size(); }
  [[nodiscard]] const std::vector<PointField>& fields() const { return fields_; }
  [[nodiscard]] std::vector<PointField>& fields() { return fields_; }
  [[nodiscard]] bool has(std::string_view name) const { return find(name) != nullptr; }
  /// The column called `name`; throws std::out_of_range naming it when absent.
  [[nodiscard]] const std::vector<double>& column(std::string_view name) const;
  PointField& add(std::string name, FieldType type, std::vector<double> values = {});

 private:
  [[nodiscard]] const PointField* find(std::string_view name) const;
  std::vector<PointField> fields_;
};

/// Columns x y z intensity ring offset_ns return (the `rigcal decode` layout); stamp and ids are lost.
PointTable toTable(const Scan& scan);
/// Needs x, y, z; intensity, ring, offset_ns and return are read when present.
Scan toScan(const PointTable& table);

}  // namespace rigcal
