#include "rigcal/bag/bag.hpp"

#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <array>
#include <cstring>
#include <fstream>

#include "rigcal/bag/bag_error.hpp"
#include "rigcal/bag/mcap_file.hpp"
#include "rigcal/bag/mcap_records.hpp"
#include "rigcal/bag/sqlite_file.hpp"

namespace rigcal::bag {

namespace {

constexpr char kSqliteMagic[] = "SQLite format 3";  // 16 bytes with its NUL

bool isStorageFile(const std::filesystem::path& p) {
  return std::filesystem::is_regular_file(p) && (p.extension() == ".mcap" || p.extension() == ".db3");
}

// The split files metadata.yaml lists, in order. Old rosbag2 versions wrote them prefixed with the bag
// folder's name: fall back to the file name inside the folder.
std::vector<std::filesystem::path> filesFromMetadata(const std::filesystem::path& folder) {
  const auto metadata = folder / "metadata.yaml";
  std::vector<std::filesystem::path> files;
  try {
    const YAML::Node info = YAML::LoadFile(metadata.string())["rosbag2_bagfile_information"];
    if (!info) throw BagError(metadata.string() + ": no rosbag2_bagfile_information");
    if (info["compression_mode"] && info["compression_mode"].as<std::string>() == "FILE")
      throw BagError(metadata.string() + ": whole-file compression (" +
                     info["compression_format"].as<std::string>("?") + ") is not supported: decompress the split files first");
    for (const auto& node : info["relative_file_paths"]) {
      std::filesystem::path p = folder / node.as<std::string>();
      if (!std::filesystem::exists(p)) p = folder / std::filesystem::path(node.as<std::string>()).filename();
      if (!std::filesystem::exists(p))
        throw BagError(metadata.string() + ": listed file " + node.as<std::string>() + " is missing");
      files.push_back(p);
    }
  } catch (const YAML::Exception& e) {
    throw BagError(metadata.string() + ": " + e.what());
  }
  return files;
}

}  // namespace

std::unique_ptr<StorageReader> openStorageFile(const std::filesystem::path& file) {
  std::array<char, 16> head{};
  std::ifstream in(file, std::ios::binary);
  if (!in) throw BagError(file.string() + ": cannot open");
  in.read(head.data(), head.size());
  if (std::size_t(in.gcount()) >= mcap::kMagic.size() && std::memcmp(head.data(), mcap::kMagic.data(), 8) == 0)
    return std::make_unique<McapFile>(file);
  if (std::size_t(in.gcount()) == head.size() && std::memcmp(head.data(), kSqliteMagic, 16) == 0)
    return std::make_unique<SqliteFile>(file);
  if (in.gcount() == 0) throw BagError(file.string() + ": empty file, not a bag");
  throw BagError(file.string() + ": neither MCAP nor sqlite3 (unknown first bytes)");
}

Bag::Bag(const std::filesystem::path& path) : path_(path) {
  if (std::filesystem::is_directory(path)) {
    if (std::filesystem::exists(path / "metadata.yaml")) {
      files_ = filesFromMetadata(path);
    } else {
      for (const auto& entry : std::filesystem::directory_iterator(path))
        if (isStorageFile(entry.path())) files_.push_back(entry.path());
      std::sort(files_.begin(), files_.end());
    }
    if (files_.empty()) throw BagError(path.string() + ": empty bag (no .mcap or .db3 storage files)");
  } else if (std::filesystem::exists(path)) {
    files_.push_back(path);
  } else {
    throw BagError(path.string() + ": no such bag file or folder");
  }
  for (std::size_t f = 0; f < files_.size(); ++f) {
    readers_.push_back(openStorageFile(files_[f]));
    topic_map_.emplace_back();
    for (std::size_t t = 0; t < readers_[f]->topics().size(); ++t) globalTopic(f, t);
  }
  current_.resize(readers_.size());
  for (std::size_t f = 0; f < readers_.size(); ++f) advance(f);
}

Bag::~Bag() = default;

std::size_t Bag::globalTopic(std::size_t file, std::size_t local) {
  auto& map = topic_map_[file];
  while (map.size() <= local) {
    const TopicInfo& info = readers_[file]->topics()[map.size()];
    auto it = std::find_if(topics_.begin(), topics_.end(), [&](const TopicInfo& t) { return t.name == info.name; });
    if (it == topics_.end()) {
      topics_.push_back(info);
      it = topics_.end() - 1;
    }
    map.push_back(std::size_t(it - topics_.begin()));
  }
  return map[local];
}

void Bag::advance(std::size_t file) {
  current_[file] = readers_[file]->next();
  if (current_[file]) heads_.push({current_[file]->log_time_ns, file});
}

std::optional<std::size_t> Bag::findTopic(const std::string& name) const {
  for (std::size_t i = 0; i < topics_.size(); ++i)
    if (topics_[i].name == name) return i;
  return std::nullopt;
}

std::string Bag::topicList() const {
  std::string out;
  for (const auto& t : topics_) out += (out.empty() ? "" : ", ") + t.name;
  return out.empty() ? "(none)" : out;
}

std::optional<BagMessage> Bag::next() {
  if (last_file_) advance(*last_file_);  // only now may the previous message's bytes go
  last_file_.reset();
  if (heads_.empty()) return std::nullopt;
  const Head head = heads_.top();
  heads_.pop();
  last_file_ = head.file;
  const StoredMessage& m = *current_[head.file];
  return BagMessage{globalTopic(head.file, m.topic), m.log_time_ns, m.data};
}

std::vector<std::string> Bag::warnings() const {
  std::vector<std::string> out;
  for (const auto& r : readers_)
    if (!r->warning().empty()) out.push_back(r->warning());
  return out;
}

std::string bagSourceWarning(const std::string& stream_error, const Bag& bag, std::uint64_t malformed,
                             const std::string& last_malformed) {
  std::string out = stream_error;
  for (const auto& w : bag.warnings()) out += (out.empty() ? "" : "; ") + w;
  if (!last_malformed.empty())
    out += (out.empty() ? "" : "; ") + std::to_string(malformed) + " malformed messages dropped, last: " +
           last_malformed;
  return out;
}

}  // namespace rigcal::bag
