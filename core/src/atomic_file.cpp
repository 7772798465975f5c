#include "rigcal/core/atomic_file.hpp"

#include <fcntl.h>
#include <unistd.h>

#include <array>
#include <atomic>
#include <cerrno>
#include <cstring>
#include <random>
#include <sstream>
#include <stdexcept>
#include <streambuf>
#include <string>

namespace rigcal {

namespace {
std::runtime_error failure(const std::filesystem::path& path, const std::string& what, int error) {
  std::ostringstream message;
  message << path.string() << ": " << what << " (" << std::strerror(error) << ')';
  return std::runtime_error(message.str());
}

/// ".<name>.tmp.<pid>.<counter>.<random>": a name no other writer picks. (std::ostringstream: GCC 12
/// warns falsely on chains of std::string operator+.)
std::string temporaryName(const std::filesystem::path& path) {
  static std::atomic<unsigned> counter{0};
  thread_local std::mt19937_64 random{std::random_device{}()};
  std::ostringstream name;
  name << '.' << path.filename().string() << ".tmp." << ::getpid() << '.' << counter.fetch_add(1) << '.'
       << random() % 1000000007ULL;
  return name.str();
}
}  // namespace

/// A write-only stream buffer on a file descriptor that remembers the first error.
class AtomicFile::Buffer : public std::streambuf {
 public:
  explicit Buffer(int fd) : fd_(fd) { setp(data_.data(), data_.data() + data_.size()); }
  ~Buffer() override { closeFd(); }
  Buffer(const Buffer&) = delete;
  Buffer& operator=(const Buffer&) = delete;

  /// Writes out what is buffered; false (and error()) on the first failure.
  bool drain() {
    const char* p = pbase();
    while (p < pptr() && error_ == 0) {
      const ssize_t n = ::write(fd_, p, std::size_t(pptr() - p));
      if (n < 0) {
        if (errno != EINTR) error_ = errno;
        continue;
      }
      p += n;
    }
    setp(data_.data(), data_.data() + data_.size());
    return error_ == 0;
  }
  int closeFd() {
    if (fd_ < 0) return 0;
    const int r = ::close(fd_);
    fd_ = -1;
    return r == 0 ? 0 : errno;
  }
  [[nodiscard]] int fd() const { return fd_; }
  [[nodiscard]] int error() const { return error_; }

 protected:
  int_type overflow(int_type c) override {
    if (!drain()) return traits_type::eof();
    if (!traits_type::eq_int_type(c, traits_type::eof())) {
      *pptr() = traits_type::to_char_type(c);
      pbump(1);
    }
    return traits_type::not_eof(c);
  }
  int sync() override { return drain() ? 0 : -1; }

 private:
  int fd_;
  int error_ = 0;
  std::array<char, 1 << 16> data_{};
};

AtomicFile::AtomicFile(std::filesystem::path path) : path_(std::move(path)) {
  const std::filesystem::path folder = path_.has_parent_path() ? path_.parent_path() : ".";
  int fd = -1;
  for (int attempt = 0; attempt < 100 && fd < 0; ++attempt) {
    temporary_ = folder / temporaryName(path_);
    // O_EXCL: never opens an existing file or follows a symlink planted at the temporary name.
    fd = ::open(temporary_.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_NOFOLLOW | O_CLOEXEC, 0666);
    if (fd < 0 && errno != EEXIST) throw failure(path_, "cannot create", errno);
  }
  if (fd < 0) throw failure(path_, "cannot create a temporary file", EEXIST);
  buffer_ = std::make_unique<Buffer>(fd);
  stream_ = std::make_unique<std::ostream>(buffer_.get());
}

AtomicFile::~AtomicFile() {
  if (committed_) return;
  buffer_->closeFd();
  ::unlink(temporary_.c_str());
}

std::ostream& AtomicFile::stream() { return *stream_; }

void AtomicFile::commit() {
  if (committed_) return;
  stream_->flush();
  if (!buffer_->drain() || !*stream_)
    throw failure(path_, "write failed", buffer_->error() != 0 ? buffer_->error() : EIO);
  if (::fsync(buffer_->fd()) != 0) throw failure(path_, "write failed", errno);
  if (const int e = buffer_->closeFd(); e != 0) throw failure(path_, "write failed", e);
  // rename() replaces whatever is at the final name (a symlink included) without following it.
  if (::rename(temporary_.c_str(), path_.c_str()) != 0) throw failure(path_, "cannot replace", errno);
  committed_ = true;
  const std::filesystem::path folder = path_.has_parent_path() ? path_.parent_path() : ".";
  if (const int dir = ::open(folder.c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC); dir >= 0) {
    ::fsync(dir);  // the rename itself durable; best effort (some filesystems refuse)
    ::close(dir);
  }
}

void writeFileAtomically(const std::filesystem::path& path, const std::function<void(std::ostream&)>& fill) {
  AtomicFile file(path);
  fill(file.stream());
  file.commit();
}

void writeFileAtomically(const std::filesystem::path& path, std::string_view text) {
  writeFileAtomically(path, [&](std::ostream& out) { out.write(text.data(), std::streamsize(text.size())); });
}

}  // namespace rigcal
