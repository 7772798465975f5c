#include "rigcal/drivers/ipv4_reassembler.hpp"

#include <algorithm>
#include <cstring>

namespace rigcal::drivers {

namespace {
constexpr std::size_t kMaxDatagram = 65535;
}

std::span<const std::uint8_t> Ipv4Reassembler::add(const Ipv4Header& f) {
  const std::size_t begin = f.fragment_offset;
  const std::size_t end = begin + f.payload.size();
  // Every fragment but the last carries a multiple of 8 bytes.
  if (end > kMaxDatagram || (f.more_fragments && f.payload.size() % 8 != 0)) {
    ++dropped_;
    return {};
  }

  auto it = std::find_if(pending_.begin(), pending_.end(), [&](const Pending& p) {
    return p.identification == f.identification && p.source == f.source &&
           p.destination == f.destination && p.protocol == f.protocol;
  });
  if (it == pending_.end()) {
    if (pending_.size() >= max_pending_) {
      pending_.pop_front();
      ++dropped_;
    }
    pending_.push_back(Pending{f.source, f.destination, f.identification, f.protocol, {}, {}, 0, 0});
    it = std::prev(pending_.end());
  }
  Pending& p = *it;
  if (p.data.size() < end) {
    p.data.resize(end);
    p.have.resize((end + 7) / 8, false);
  }
  // An empty fragment is legal on the wire; memcpy with a null pointer is not, even for 0 bytes.
  if (!f.payload.empty()) std::memcpy(p.data.data() + begin, f.payload.data(), f.payload.size());
  for (std::size_t block = begin / 8; block < (end + 7) / 8; ++block) {
    if (!p.have[block]) {
      p.have[block] = true;
      p.received += std::min<std::size_t>(8, end - block * 8);
    }
  }
  if (!f.more_fragments) p.total = end;

  if (p.total == 0 || p.received < p.total) return {};
  done_ = std::move(p.data);
  done_.resize(p.total);
  pending_.erase(it);
  return done_;
}

}  // namespace rigcal::drivers
