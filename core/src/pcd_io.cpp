#include "rigcal/core/pcd_io.hpp"

#include <cstdint>
#include <cstring>
#include <fstream>
#include <limits>
#include <sstream>
#include <stdexcept>

#include "rigcal/core/atomic_file.hpp"
#include "rigcal/core/lzf.hpp"
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
  for (const int c : h.counts)
    if (c < 1 || c > 65536) failFile(path, "PCD header COUNT " + std::to_string(c) + " out of range 1..65536");
  if (!have_points) h.points = width * height;
  return h;
}

std::uint32_t readU32(std::istream& in, const char* what, const std::filesystem::path& path) {
  unsigned char b[4];
  if (!in.read(reinterpret_cast<char*>(b), 4))
    failFile(path, std::string("binary_compressed data truncated before its ") + what);
  return std::uint32_t(b[0]) | std::uint32_t(b[1]) << 8 | std::uint32_t(b[2]) << 16 | std::uint32_t(b[3]) << 24;
}

// PCL's binary_compressed body: u32 compressed size, u32 uncompressed size, then LZF data that expands to
// the fields one after another (all points' x, then all points' y, ...), not row by row.
void readCompressedColumns(std::istream& in, PointTable& table, std::size_t points, const std::vector<int>& counts,
                           const std::filesystem::path& path) {
  const std::uint32_t compressed = readU32(in, "compressed size", path);
  const std::uint32_t uncompressed = readU32(in, "uncompressed size", path);
  std::size_t row = 0;
  for (const auto& f : table.fields()) row += fieldSize(f.type);
  if (row != 0 && points > std::numeric_limits<std::uint32_t>::max() / row)
    failFile(path, "binary_compressed: " + std::to_string(points) + " points cannot fit in one file");
  if (uncompressed != points * row)
    failFile(path, "binary_compressed: uncompressed size " + std::to_string(uncompressed) + " bytes, but " +
                       std::to_string(points) + " points of " + std::to_string(row) + " bytes need " +
                       std::to_string(points * row));
  if (points == 0) return;
  // Both sizes are bounded before anything is allocated: the compressed bytes by what the file holds, the
  // uncompressed by LZF's largest expansion (a 3-byte back-reference yields at most 264 bytes).
  const auto here = in.tellg();
  in.seekg(0, std::ios::end);
  const auto left = std::uint64_t(in.tellg() - here);
  in.seekg(here);
  if (compressed > left)
    failFile(path, "binary_compressed data truncated: " + std::to_string(left) + " of " + std::to_string(compressed) +
                       " compressed bytes");
  if (uncompressed > 100ULL * compressed + 64)
    failFile(path, "binary_compressed: " + std::to_string(compressed) + " compressed bytes cannot expand to " +
                       std::to_string(uncompressed));
  std::vector<std::uint8_t> packed(compressed);
  if (!in.read(reinterpret_cast<char*>(packed.data()), std::streamsize(compressed)))
    failFile(path, "binary_compressed data truncated: " + std::to_string(in.gcount()) + " of " +
                       std::to_string(compressed) + " compressed bytes");
  std::vector<std::uint8_t> bytes;
  try {
    bytes = lzfDecompress(packed, uncompressed);
  } catch (const std::runtime_error& e) {
    failFile(path, std::string("binary_compressed: ") + e.what());
  }
  // A field of COUNT n was expanded into n consecutive columns; in the file it is one block of
  // points * n values, point-major.
  const std::uint8_t* p = bytes.data();
  auto& columns = table.fields();
  std::size_t column = 0;
  for (std::size_t f = 0; f < counts.size(); ++f) {
    const auto n = std::size_t(counts[f]);
    const FieldType type = columns[column].type;
    for (std::size_t i = 0; i < points; ++i)
      for (std::size_t k = 0; k < n; ++k, p += fieldSize(type))
        columns[column + k].values.push_back(detail::readValue(p, type));
    column += n;
  }
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
  else if (h.data == "binary_compressed")
    readCompressedColumns(in, table, h.points, h.counts, path);
  else
    failFile(path, "unsupported PCD DATA encoding '" + h.data + "' (ascii, binary and binary_compressed are read)");
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
