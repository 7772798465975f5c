#include "rigcal/core/pcd_io.hpp"

#include <fstream>
#include <sstream>
#include <stdexcept>

#include "rigcal/core/atomic_file.hpp"
#include "table_rows.hpp"

namespace rigcal {
using detail::failFile;

namespace {


FieldType pcdType(char type, int size, const std::filesystem::path& path) {
  const std::string key = std::string(1, type) + std::to_string(size);
  if (key == "I1") return FieldType::kI8;
  if (key == "U1") return FieldType::kU8;
  if (key == "I2") return FieldType::kI16;
  if (key == "U2") return FieldType::kU16;
  if (key == "I4") return FieldType::kI32;
  if (key == "U4") return FieldType::kU32;
  if (key == "I8") return FieldType::kI64;
  if (key == "U8") return FieldType::kU64;
  if (key == "F4") return FieldType::kF32;
  if (key == "F8") return FieldType::kF64;
  failFile(path, "unsupported PCD field TYPE " + std::string(1, type) + " SIZE " + std::to_string(size));
}

char pcdTypeChar(FieldType t) {
  if (t == FieldType::kF32 || t == FieldType::kF64) return 'F';
  if (t == FieldType::kI8 || t == FieldType::kI16 || t == FieldType::kI32 || t == FieldType::kI64)
    return 'I';
  return 'U';
}

struct Header {
  std::vector<std::string> names;
  std::vector<int> sizes, counts;
  std::vector<char> types;
  std::size_t points = 0;
  std::string data;
};

Header readHeader(std::istream& in, const std::filesystem::path& path) {
  Header h;
  std::size_t width = 0, height = 1;
  bool have_points = false;
  std::string line;
  while (std::getline(in, line)) {
    if (line.empty() || line[0] == '#') continue;
    std::istringstream ls(line);
    std::string key;
    ls >> key;
    if (key == "FIELDS") {
      for (std::string s; ls >> s;) h.names.push_back(s);
    } else if (key == "SIZE") {
      for (int s; ls >> s;) h.sizes.push_back(s);
    } else if (key == "TYPE") {
      for (char c; ls >> c;) h.types.push_back(c);
    } else if (key == "COUNT") {
      for (int c; ls >> c;) h.counts.push_back(c);
    } else if (key == "WIDTH") {
      ls >> width;
    } else if (key == "HEIGHT") {
      ls >> height;
    } else if (key == "POINTS") {
      ls >> h.points;
      have_points = true;
    } else if (key == "DATA") {
      ls >> h.data;
      break;
    } else if (key != "VERSION" && key != "VIEWPOINT") {
      failFile(path, "unknown PCD header line '" + key + "'");
    }
  }
  if (h.data.empty()) failFile(path, "not a PCD file (no DATA line)");
  if (h.names.empty()) failFile(path, "PCD header has no FIELDS");
  if (h.counts.empty()) h.counts.assign(h.names.size(), 1);
  if (h.sizes.size() != h.names.size() || h.types.size() != h.names.size() ||
      h.counts.size() != h.names.size())
    failFile(path, "PCD header FIELDS, SIZE, TYPE and COUNT have different lengths");
  if (!have_points) h.points = width * height;
  return h;
}

}  // namespace

PointTable readPcd(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) failFile(path, "cannot open");
  const Header h = readHeader(in, path);

  // Multi-count fields (e.g. FPFH histograms) are expanded to name_0, name_1, ...
  PointTable table;
  for (std::size_t f = 0; f < h.names.size(); ++f) {
    const FieldType t = pcdType(h.types[f], h.sizes[f], path);
    for (int c = 0; c < h.counts[f]; ++c)
      table.add(h.counts[f] == 1 ? h.names[f] : h.names[f] + "_" + std::to_string(c), t)
          .values.reserve(h.points);
  }
  if (h.data == "ascii")
    detail::readAsciiRows(in, table, h.points, "point", path);
  else if (h.data == "binary")
    detail::readBinaryRows(in, table, h.points, "point", path);
  else
    failFile(path, "unsupported PCD DATA encoding '" + h.data + "' (ascii and binary are read)");
  return table;
}

void writePcd(const std::filesystem::path& path, const PointTable& table, PcdEncoding encoding) {
  AtomicFile file(path);
  std::ostream& out = file.stream();
  const auto& fields = table.fields();
  out << "# .PCD v0.7 - Point Cloud Data file format\nVERSION 0.7\nFIELDS";
  for (const auto& f : fields) out << ' ' << f.name;
  out << "\nSIZE";
  for (const auto& f : fields) out << ' ' << fieldSize(f.type);
  out << "\nTYPE";
  for (const auto& f : fields) out << ' ' << pcdTypeChar(f.type);
  out << "\nCOUNT";
  for (std::size_t i = 0; i < fields.size(); ++i) out << " 1";
  out << "\nWIDTH " << table.size() << "\nHEIGHT 1\nVIEWPOINT 0 0 0 1 0 0 0\nPOINTS " << table.size()
      << "\nDATA " << (encoding == PcdEncoding::kAscii ? "ascii" : "binary") << '\n';

  if (encoding == PcdEncoding::kAscii)
    detail::writeAsciiRows(out, table);
  else
    detail::writeBinaryRows(out, table);
  file.commit();
}

}  // namespace rigcal
