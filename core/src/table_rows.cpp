#include "table_rows.hpp"

#include <cstdlib>
#include <cstring>
#include <string>
#include <iomanip>
#include <istream>
#include <limits>
#include <ostream>
#include <stdexcept>

namespace rigcal::detail {
namespace {

template <class T>
double load(const void* p) {
  T v;
  std::memcpy(&v, p, sizeof v);
  return static_cast<double>(v);
}

template <class T>
void store(char* p, double value) {
  const T v = static_cast<T>(value);
  std::memcpy(p, &v, sizeof v);
}

}  // namespace

double readValue(const void* p, FieldType t) {
  switch (t) {
    case FieldType::kI8: return load<std::int8_t>(p);
    case FieldType::kU8: return load<std::uint8_t>(p);
    case FieldType::kI16: return load<std::int16_t>(p);
    case FieldType::kU16: return load<std::uint16_t>(p);
    case FieldType::kI32: return load<std::int32_t>(p);
    case FieldType::kU32: return load<std::uint32_t>(p);
    case FieldType::kI64: return load<std::int64_t>(p);
    case FieldType::kU64: return load<std::uint64_t>(p);
    case FieldType::kF32: return load<float>(p);
    case FieldType::kF64: return load<double>(p);
  }
  return 0.0;
}

namespace {

void writeValue(char* p, FieldType t, double v) {
  switch (t) {
    case FieldType::kI8: return store<std::int8_t>(p, v);
    case FieldType::kU8: return store<std::uint8_t>(p, v);
    case FieldType::kI16: return store<std::int16_t>(p, v);
    case FieldType::kU16: return store<std::uint16_t>(p, v);
    case FieldType::kI32: return store<std::int32_t>(p, v);
    case FieldType::kU32: return store<std::uint32_t>(p, v);
    case FieldType::kI64: return store<std::int64_t>(p, v);
    case FieldType::kU64: return store<std::uint64_t>(p, v);
    case FieldType::kF32: return store<float>(p, v);
    case FieldType::kF64: return store<double>(p, v);
  }
}

bool isInteger(FieldType t) { return t != FieldType::kF32 && t != FieldType::kF64; }

std::size_t rowBytes(const PointTable& table) {
  std::size_t stride = 0;
  for (const auto& f : table.fields()) stride += fieldSize(f.type);
  return stride;
}

}  // namespace

void failFile(const std::filesystem::path& path, const std::string& what) {
  throw std::runtime_error(path.string() + ": " + what);
}

void readAsciiRows(std::istream& in, PointTable& table, std::size_t rows, const char* unit,
                   const std::filesystem::path& path) {
  for (std::size_t i = 0; i < rows; ++i)
    for (auto& f : table.fields()) {
      // Token then strtod: PCL writes invalid points as "nan", which operator>> does not parse.
      std::string token;
      if (!(in >> token))
        failFile(path, "truncated ascii data at " + std::string(unit) + " " + std::to_string(i) +
                           " of " + std::to_string(rows));
      char* end = nullptr;
      const double v = std::strtod(token.c_str(), &end);
      if (end == token.c_str() || *end != '\0')
        failFile(path, "'" + token + "' is not a number at " + std::string(unit) + " " + std::to_string(i) +
                           " field " + f.name);
      f.values.push_back(v);
    }
}

void readBinaryRows(std::istream& in, PointTable& table, std::size_t rows, const char* unit,
                    const std::filesystem::path& path) {
  std::vector<char> row(rowBytes(table));
  for (std::size_t i = 0; i < rows; ++i) {
    if (!in.read(row.data(), static_cast<std::streamsize>(row.size())))
      failFile(path, "truncated binary data at " + std::string(unit) + " " + std::to_string(i) +
                         " of " + std::to_string(rows));
    std::size_t off = 0;
    for (auto& f : table.fields()) {
      f.values.push_back(readValue(row.data() + off, f.type));
      off += fieldSize(f.type);
    }
  }
}

void writeAsciiRows(std::ostream& out, const PointTable& table) {
  const auto& fields = table.fields();
  for (std::size_t i = 0; i < table.size(); ++i) {
    for (std::size_t f = 0; f < fields.size(); ++f) {
      if (f) out << ' ';
      const double v = fields[f].values[i];
      if (isInteger(fields[f].type))
        out << static_cast<long long>(v);
      else if (fields[f].type == FieldType::kF32)
        out << std::setprecision(std::numeric_limits<float>::max_digits10) << static_cast<float>(v);
      else
        out << std::setprecision(std::numeric_limits<double>::max_digits10) << v;
    }
    out << '\n';
  }
}

void writeBinaryRows(std::ostream& out, const PointTable& table) {
  std::vector<char> buffer(rowBytes(table) * table.size());
  char* p = buffer.data();
  for (std::size_t i = 0; i < table.size(); ++i)
    for (const auto& f : table.fields()) {
      writeValue(p, f.type, f.values[i]);
      p += fieldSize(f.type);
    }
  out.write(buffer.data(), static_cast<std::streamsize>(buffer.size()));
}

}  // namespace rigcal::detail
