#pragma once
// A bag's static transform tree: every transform on /tf_static, then the first of each parent -> child
// pair on /tf (a frame's parent never changes once known), composed along the tree between two frames:
// the initial extrinsics of `initial_extrinsics: from_bag`.
#include <filesystem>
#include <map>
#include <string>
#include <vector>

#include "rigcal/bag/tf_message.hpp"

namespace rigcal::bag {

class TfTree {
 public:
  /// Reads /tf_static and /tf of the bag (both may be missing: then the tree is empty). Malformed tf
  /// messages are skipped (counted in malformed()).
  static TfTree fromBag(const std::filesystem::path& bag);

  /// Keeps the first transform seen for each child frame.
  void add(const StampedTransform& t);

  /// T_target_source (maps points in `source` into `target`), composed through their common ancestor;
  /// `path` gets the frames walked from target to source. Throws BagError naming both frames and listing
  /// the tree's frames when either is missing or they are not connected.
  [[nodiscard]] Pose lookup(const std::string& target, const std::string& source,
                            std::vector<std::string>* path = nullptr) const;
  /// "a, b, c" (every frame, sorted), or "(no transforms)".
  [[nodiscard]] std::string frameList() const;
  [[nodiscard]] std::size_t malformed() const { return malformed_; }

 private:
  struct Edge {
    std::string parent;
    Pose T_parent_child;
  };
  /// T_frame_root... from `frame` up: each ancestor with T_ancestor_frame.
  [[nodiscard]] std::vector<std::pair<std::string, Pose>> ancestors(const std::string& frame) const;
  std::map<std::string, Edge> parent_of_;  // child -> edge to its parent
  std::size_t malformed_ = 0;
};

}  // namespace rigcal::bag
