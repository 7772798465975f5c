#pragma once
// Every output file is written through AtomicFile: the bytes go to a fresh temporary file in the same
// folder (created exclusively, never through a symlink), which is flushed, fsynced, closed and then
// renamed over the final name. A reader sees the old file or the complete new one, never half a file;
// a symlink planted at the final name is replaced, not followed; a failed write leaves nothing behind.
#include <filesystem>
#include <functional>
#include <memory>
#include <ostream>
#include <string_view>

namespace rigcal {

class AtomicFile {
 public:
  /// Creates the temporary file next to `path`. Throws std::runtime_error "<path>: cannot create (...)".
  explicit AtomicFile(std::filesystem::path path);
  /// Removes the temporary file unless commit() succeeded.
  ~AtomicFile();
  AtomicFile(const AtomicFile&) = delete;
  AtomicFile& operator=(const AtomicFile&) = delete;

  /// Where to write the contents (binary; buffered).
  std::ostream& stream();
  /// Flushes, checks every write, fsyncs, closes and renames onto the final name (then fsyncs the
  /// folder). Throws std::runtime_error "<path>: write failed (<reason>)"; the final name is untouched.
  void commit();
  [[nodiscard]] const std::filesystem::path& path() const { return path_; }

 private:
  class Buffer;
  std::filesystem::path path_;
  std::filesystem::path temporary_;
  std::unique_ptr<Buffer> buffer_;
  std::unique_ptr<std::ostream> stream_;
  bool committed_ = false;
};

/// Writes `path` atomically with whatever `fill` puts into the stream.
void writeFileAtomically(const std::filesystem::path& path, const std::function<void(std::ostream&)>& fill);
/// Writes `text` to `path` atomically.
void writeFileAtomically(const std::filesystem::path& path, std::string_view text);

}  // namespace rigcal
