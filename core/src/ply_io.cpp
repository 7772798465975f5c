#include "rigcal/core/ply_io.hpp"

#include <array>
#include <fstream>
#include <sstream>
#include <stdexcept>

#include "rigcal/core/atomic_file.hpp"
#include "table_rows.hpp"

namespace rigcal {
using detail::failFile;

namespace {


struct PlyTypeName {
  FieldType type;
  const char* name;
  const char* alias;
};
constexpr std::array<PlyTypeName, 10> kTypes{{
    {FieldType::kI8, "char", "int8"},
    {FieldType::kU8, "uchar", "uint8"},
    {FieldType::kI16, "short", "int16"},
    {FieldType::kU16, "ushort", "uint16"},
    {FieldType::kI32, "int", "int32"},
    {FieldType::kU32, "uint", "uint32"},
    {FieldType::kI64, "int64", "int64"},
    {FieldType::kU64, "uint64", "uint64"},
    {FieldType::kF32, "float", "float32"},
    {FieldType::kF64, "double", "float64"},
}};

FieldType plyType(const std::string& name, const std::filesystem::path& path) {
  for (const auto& t : kTypes)
    if (name == t.name || name == t.alias) return t.type;
  failFile(path, "unsupported PLY property type '" + name + "'");
}

const char* plyName(FieldType type) {
  for (const auto& t : kTypes)
    if (t.type == type) return t.name;
  return "double";
}

}  // namespace

PointTable readPly(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) failFile(path, "cannot open");
  std::string line;
  if (!std::getline(in, line) || line.rfind("ply", 0) != 0) failFile(path, "not a PLY file");

  PointTable table;
  std::string format;
  std::size_t vertices = 0;
  bool in_vertex = false, seen_vertex = false;
  while (std::getline(in, line)) {
    if (!line.empty() && line.back() == '\r') line.pop_back();
    std::istringstream ls(line);
    std::string key;
    ls >> key;
    if (key == "format") {
      ls >> format;
    } else if (key == "element") {
      std::string name;
      std::size_t count = 0;
      ls >> name >> count;
      // Elements after the vertices (a mesh's faces) are ignored: their data follows the vertex block.
      if (seen_vertex && name == "vertex") failFile(path, "more than one 'vertex' element");
      in_vertex = name == "vertex";
      if (seen_vertex && !in_vertex) continue;
      if (in_vertex) {
        vertices = count;
        seen_vertex = true;
      } else {
        failFile(path, "element '" + name + "' before 'vertex' is not supported");
      }
    } else if (key == "property") {
      std::string type, name;
      ls >> type >> name;
      if (!in_vertex) continue;  // a property of an ignored element
      if (type == "list") failFile(path, "list properties are not supported in the vertex element");
      if (in_vertex) table.add(name, plyType(type, path)).values.reserve(vertices);
    } else if (key == "end_header") {
      break;
    } else if (key != "comment" && key != "obj_info") {
      failFile(path, "unknown PLY header line '" + key + "'");
    }
  }
  if (!seen_vertex) failFile(path, "PLY header has no vertex element");

  if (format == "ascii")
    detail::readAsciiRows(in, table, vertices, "vertex", path);
  else if (format == "binary_little_endian")
    detail::readBinaryRows(in, table, vertices, "vertex", path);
  else
    failFile(path, "unsupported PLY format '" + format + "'");
  return table;
}

void writePly(const std::filesystem::path& path, const PointTable& table, PlyEncoding encoding) {
  AtomicFile file(path);
  std::ostream& out = file.stream();
  const auto& fields = table.fields();
  out << "ply\nformat "
      << (encoding == PlyEncoding::kAscii ? "ascii" : "binary_little_endian") << " 1.0\n"
      << "comment written by rigcal\nelement vertex " << table.size() << '\n';
  for (const auto& f : fields) out << "property " << plyName(f.type) << ' ' << f.name << '\n';
  out << "end_header\n";

  if (encoding == PlyEncoding::kAscii)
    detail::writeAsciiRows(out, table);
  else
    detail::writeBinaryRows(out, table);
  file.commit();
}

}  // namespace rigcal
