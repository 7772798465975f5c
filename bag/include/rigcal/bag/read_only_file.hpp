#pragma once
// A file read by offset (pread): the MCAP reader jumps between the footer, the summary and chunks.
#include <cstdint>
#include <filesystem>
#include <span>

namespace rigcal::bag {

class ReadOnlyFile {
 public:
  /// Throws BagError "<file>: cannot open: <reason>".
  explicit ReadOnlyFile(const std::filesystem::path& path);
  ~ReadOnlyFile();
  ReadOnlyFile(const ReadOnlyFile&) = delete;
  ReadOnlyFile& operator=(const ReadOnlyFile&) = delete;

  [[nodiscard]] std::uint64_t size() const { return size_; }
  /// Reads out.size() bytes at `offset`; returns how many were read (fewer only at end of file).
  std::size_t readAt(std::uint64_t offset, std::span<std::uint8_t> out) const;

 private:
  std::filesystem::path path_;
  int fd_ = -1;
  std::uint64_t size_ = 0;
};

}  // namespace rigcal::bag
