#include "rigcal/bag/tf_tree.hpp"

#include <set>

#include "rigcal/bag/bag.hpp"
#include "rigcal/bag/bag_error.hpp"

namespace rigcal::bag {

TfTree TfTree::fromBag(const std::filesystem::path& path) {
  Bag bag(path);
  TfTree tree;
  const auto statics = bag.findTopic("/tf_static");
  const auto dynamics = bag.findTopic("/tf");
  // /tf_static wins over /tf for the same child, whatever their order in the bag.
  std::vector<StampedTransform> from_tf;
  while (const auto m = bag.next()) {
    const bool is_static = statics && m->topic == *statics;
    if (!is_static && !(dynamics && m->topic == *dynamics)) continue;
    try {
      auto transforms = decodeTfMessage(m->data, path.string() + ": " + bag.topics()[m->topic].name +
                                                     " message at log time " + std::to_string(m->log_time_ns));
      for (auto& t : transforms) {
        if (is_static) tree.add(t);
        else from_tf.push_back(std::move(t));
      }
    } catch (const BagError&) {
      ++tree.malformed_;
    }
  }
  for (const auto& t : from_tf) tree.add(t);
  return tree;
}

void TfTree::add(const StampedTransform& t) {
  if (t.child_frame.empty() || t.child_frame == t.parent_frame) return;
  parent_of_.emplace(t.child_frame, Edge{t.parent_frame, t.T_parent_child});
}

std::vector<std::pair<std::string, Pose>> TfTree::ancestors(const std::string& frame) const {
  std::vector<std::pair<std::string, Pose>> out{{frame, Pose::Identity()}};
  std::set<std::string> seen{frame};
  for (auto it = parent_of_.find(frame); it != parent_of_.end(); it = parent_of_.find(it->second.parent)) {
    if (!seen.insert(it->second.parent).second) break;  // a loop in a hostile bag: stop at the repeat
    out.emplace_back(it->second.parent, it->second.T_parent_child * out.back().second);
  }
  return out;
}

Pose TfTree::lookup(const std::string& target, const std::string& source, std::vector<std::string>* path) const {
  const auto up_source = ancestors(source);
  const auto up_target = ancestors(target);
  for (std::size_t i = 0; i < up_source.size(); ++i)
    for (std::size_t j = 0; j < up_target.size(); ++j) {
      if (up_source[i].first != up_target[j].first) continue;
      if (path) {
        path->clear();
        for (std::size_t k = 0; k <= j; ++k) path->push_back(up_target[k].first);
        for (std::size_t k = i; k-- > 0;) path->push_back(up_source[k].first);
      }
      // T_target_source = T_common_target⁻¹ · T_common_source.
      return up_target[j].second.inverse() * up_source[i].second;
    }
  std::set<std::string> frames;
  for (const auto& [child, edge] : parent_of_) frames.insert({child, edge.parent});
  const bool has_target = frames.count(target) != 0, has_source = frames.count(source) != 0;
  const std::string why = !has_target && !has_source ? "neither " + target + " nor " + source + " is in the tf tree"
                          : !has_target             ? "frame " + target + " is not in the tf tree"
                          : !has_source             ? "frame " + source + " is not in the tf tree"
                                                    : target + " and " + source + " are not connected in the tf tree";
  throw BagError(why + "; its frames: " + frameList());
}

std::string TfTree::frameList() const {
  std::set<std::string> frames;
  for (const auto& [child, edge] : parent_of_) frames.insert({child, edge.parent});
  std::string out;
  for (const auto& f : frames) out += (out.empty() ? "" : ", ") + f;
  return out.empty() ? "(no transforms)" : out;
}

}  // namespace rigcal::bag
