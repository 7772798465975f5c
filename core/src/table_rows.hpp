#pragma once
// Row-wise (de)serialisation of a PointTable body, shared by the PCD and PLY codecs.
// Binary rows are packed little-endian (x86 and ARM hosts are little-endian).
#include <filesystem>
#include <iosfwd>

#include "rigcal/core/point_table.hpp"

namespace rigcal::detail {

/// Appends `rows` rows to the table's (already declared) fields; `unit` names a row in errors.
void readAsciiRows(std::istream& in, PointTable& table, std::size_t rows, const char* unit,
                   const std::filesystem::path& path);
void readBinaryRows(std::istream& in, PointTable& table, std::size_t rows, const char* unit,
                    const std::filesystem::path& path);
void writeAsciiRows(std::ostream& out, const PointTable& table);
void writeBinaryRows(std::ostream& out, const PointTable& table);

/// One little-endian value of type t at p, widened to double.
double readValue(const void* p, FieldType t);

[[noreturn]] void failFile(const std::filesystem::path& path, const std::string& what);

}  // namespace rigcal::detail
