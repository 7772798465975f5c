#include "rigcal/core/point_table.hpp"

#include <stdexcept>

namespace rigcal {

std::size_t fieldSize(FieldType t) {
  switch (t) {
    case FieldType::kI8:
    case FieldType::kU8: return 1;
    case FieldType::kI16:
    case FieldType::kU16: return 2;
    case FieldType::kI32:
    case FieldType::kU32:
    case FieldType::kF32: return 4;
    case FieldType::kI64:
    case FieldType::kU64:
    case FieldType::kF64: return 8;
  }
  return 0;
}

const std::vector<double>& PointTable::column(std::string_view name) const {
  if (const PointField* f = find(name)) return f->values;
  throw std::out_of_range("point table has no field '" + std::string(name) + "'");
}

PointField& PointTable::add(std::string name, FieldType type, std::vector<double> values) {
  fields_.push_back(PointField{std::move(name), type, std::move(values)});
  return fields_.back();
}

const PointField* PointTable::find(std::string_view name) const {
  for (const auto& f : fields_)
    if (f.name == name) return &f;
  return nullptr;
}

namespace {
template <class T>
std::vector<double> widen(const std::vector<T>& v) {
  return std::vector<double>(v.begin(), v.end());
}
template <class T>
void narrow(const std::vector<double>& in, std::vector<T>& out) {
  out.resize(in.size());
  for (std::size_t i = 0; i < in.size(); ++i) out[i] = static_cast<T>(in[i]);
}
}  // namespace

PointTable toTable(const Scan& scan) {
  PointTable t;
  t.add("x", FieldType::kF32, widen(scan.x));
  t.add("y", FieldType::kF32, widen(scan.y));
  t.add("z", FieldType::kF32, widen(scan.z));
  t.add("intensity", FieldType::kF32, widen(scan.intensity));
  t.add("ring", FieldType::kU16, widen(scan.ring));
  t.add("offset_ns", FieldType::kU32, widen(scan.offset_ns));
  t.add("return", FieldType::kU8, widen(scan.return_index));
  return t;
}

Scan toScan(const PointTable& table) {
  Scan s;
  const std::size_t n = table.size();
  narrow(table.column("x"), s.x);
  narrow(table.column("y"), s.y);
  narrow(table.column("z"), s.z);
  const auto optional = [&](std::string_view name, auto& out) {
    if (table.has(name))
      narrow(table.column(name), out);
    else
      out.assign(n, 0);
  };
  optional("intensity", s.intensity);
  optional("ring", s.ring);
  optional("offset_ns", s.offset_ns);
  optional("return", s.return_index);
  return s;
}

}  // namespace rigcal
