#include "rigcal/calib/lidar_pose_objective.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <condition_variable>
#include <functional>
#include <limits>
#include <mutex>
#include <stdexcept>
#include <string>
#include <thread>
#include <utility>

namespace rigcal::calib {

// n − 1 helper threads that sleep on a condition variable between jobs (no spinning on a 2-core
// target); the caller runs part 0 itself.
class LidarPoseObjective::Workers {
 public:
  explicit Workers(int threads) {
    for (int part = 1; part < threads; ++part) threads_.emplace_back([this, part] { loop(part); });
  }
  ~Workers() {
    {
      std::lock_guard lock(mutex_);
      stop_ = true;
    }
    wake_.notify_all();
    for (auto& t : threads_) t.join();
  }

  void run(const std::function<void(int)>& task) {
    if (threads_.empty()) {
      task(0);
      return;
    }
    {
      std::lock_guard lock(mutex_);
      task_ = &task;
      pending_ = threads_.size();
      ++generation_;
    }
    wake_.notify_all();
    task(0);
    std::unique_lock lock(mutex_);
    done_.wait(lock, [this] { return pending_ == 0; });
    task_ = nullptr;
  }

 private:
  void loop(int part) {
    std::uint64_t seen = 0;
    while (true) {
      const std::function<void(int)>* task = nullptr;
      {
        std::unique_lock lock(mutex_);
        wake_.wait(lock, [&] { return stop_ || generation_ != seen; });
        if (stop_) return;
        seen = generation_;
        task = task_;
      }
      (*task)(part);
      std::lock_guard lock(mutex_);
      if (--pending_ == 0) done_.notify_one();
    }
  }

  std::vector<std::thread> threads_;
  std::mutex mutex_;
  std::condition_variable wake_, done_;
  const std::function<void(int)>* task_ = nullptr;
  std::size_t pending_ = 0;
  std::uint64_t generation_ = 0;
  bool stop_ = false;
};

LidarPoseObjective::LidarPoseObjective(const LidarPoints& points, const PoseTrajectory& trajectory,
                                       int threads)
    : points_(points), trajectory_(trajectory), n_(points.size()), threads_(std::max(1, threads)) {
  if (n_ < 2) throw std::invalid_argument("LidarPoseObjective: needs at least 2 points");
  if (n_ > std::numeric_limits<std::uint32_t>::max())
    throw std::invalid_argument("LidarPoseObjective: too many points");
  workers_ = std::make_unique<Workers>(threads_);
  pose_cache_.resize(12 * n_);
  pose_missing_.resize(threads_);
  wx_.resize(n_);
  wy_.resize(n_);
  wz_.resize(n_);
  part_min_.resize(3 * threads_);
  part_max_.resize(3 * threads_);
  keys_.resize(n_);
  keys_tmp_.resize(n_);
  order_.resize(n_);
  order_tmp_.resize(n_);
  sx_.resize(n_);
  sy_.resize(n_);
  sz_.resize(n_);
  sweep_split_.resize(threads_ + 1);
  cost_.resize(n_);
}

LidarPoseObjective::~LidarPoseObjective() = default;

std::pair<std::size_t, std::size_t> LidarPoseObjective::pointRange(int part) const {
  const std::size_t p = static_cast<std::size_t>(part), t = static_cast<std::size_t>(threads_);
  return {n_ * p / t, n_ * (p + 1) / t};
}

void LidarPoseObjective::updatePoses(double time_offset_s) {
  if (poses_valid_ && time_offset_s == pose_offset_) return;
  std::fill(pose_missing_.begin(), pose_missing_.end(), 0);
  workers_->run([&](int part) {
    const auto [begin, end] = pointRange(part);
    std::size_t hint = 0;
    for (std::size_t i = begin; i < end; ++i) {
      const auto T = trajectory_.at(points_.time_ns[i], time_offset_s, &hint);
      if (!T) {
        pose_missing_[part] = 1;
        return;
      }
      double* c = &pose_cache_[12 * i];
      const Eigen::Matrix3d& R = T->linear();
      for (int r = 0; r < 3; ++r)
        for (int k = 0; k < 3; ++k) c[3 * r + k] = R(r, k);
      c[9] = T->translation().x();
      c[10] = T->translation().y();
      c[11] = T->translation().z();
    }
  });
  poses_valid_ = false;
  for (auto missing : pose_missing_)
    if (missing)
      throw std::out_of_range("LidarPoseObjective: a point has no pose at time offset " +
                              std::to_string(time_offset_s) + " s");
  pose_offset_ = time_offset_s;
  poses_valid_ = true;
}

void LidarPoseObjective::transform(int part, const Pose& T_pose_lidar) {
  const auto [begin, end] = pointRange(part);
  const Eigen::Matrix3d& A = T_pose_lidar.linear();
  const Eigen::Vector3d& b = T_pose_lidar.translation();
  float lo[3] = {std::numeric_limits<float>::max(), std::numeric_limits<float>::max(),
                 std::numeric_limits<float>::max()};
  float hi[3] = {std::numeric_limits<float>::lowest(), std::numeric_limits<float>::lowest(),
                 std::numeric_limits<float>::lowest()};
  for (std::size_t i = begin; i < end; ++i) {
    const double px = points_.x[i], py = points_.y[i], pz = points_.z[i];
    const double q0 = A(0, 0) * px + A(0, 1) * py + A(0, 2) * pz + b.x();
    const double q1 = A(1, 0) * px + A(1, 1) * py + A(1, 2) * pz + b.y();
    const double q2 = A(2, 0) * px + A(2, 1) * py + A(2, 2) * pz + b.z();
    const double* c = &pose_cache_[12 * i];
    const float w[3] = {static_cast<float>(c[0] * q0 + c[1] * q1 + c[2] * q2 + c[9]),
                        static_cast<float>(c[3] * q0 + c[4] * q1 + c[5] * q2 + c[10]),
                        static_cast<float>(c[6] * q0 + c[7] * q1 + c[8] * q2 + c[11])};
    wx_[i] = w[0];
    wy_[i] = w[1];
    wz_[i] = w[2];
    for (int a = 0; a < 3; ++a) {
      lo[a] = std::min(lo[a], w[a]);
      hi[a] = std::max(hi[a], w[a]);
    }
  }
  for (int a = 0; a < 3; ++a) {
    part_min_[3 * part + a] = lo[a];
    part_max_[3 * part + a] = hi[a];
  }
}

void LidarPoseObjective::sortByCell() {
  // Cell keys packed x-fastest, so the cells (ix−1, ix, ix+1) of one (iy, iz) row are contiguous after
  // sorting. A 1-cell margin keeps every neighbour key non-negative.
  std::int64_t count[3];
  for (int a = 0; a < 3; ++a) {
    float lo = std::numeric_limits<float>::max(), hi = std::numeric_limits<float>::lowest();
    for (int p = 0; p < threads_; ++p) {
      lo = std::min(lo, part_min_[3 * p + a]);
      hi = std::max(hi, part_max_[3 * p + a]);
    }
    origin_[a] = static_cast<std::int64_t>(std::floor(lo * inv_cell_)) - 1;
    count[a] = static_cast<std::int64_t>(std::floor(hi * inv_cell_)) - origin_[a] + 2;
  }
  const double cells = static_cast<double>(count[0]) * static_cast<double>(count[1]) *
                       static_cast<double>(count[2]);
  if (cells > 0x1.0p62)
    throw std::runtime_error("LidarPoseObjective: fused cloud too large for its cell grid");
  nx_ = static_cast<std::uint64_t>(count[0]);
  nxy_ = nx_ * static_cast<std::uint64_t>(count[1]);
  int bits = 1;
  while (bits < 64 && (std::uint64_t{1} << bits) < static_cast<std::uint64_t>(cells)) ++bits;

  workers_->run([&](int part) {
    const auto [begin, end] = pointRange(part);
    for (std::size_t i = begin; i < end; ++i) {
      const auto ix = static_cast<std::int64_t>(std::floor(wx_[i] * inv_cell_)) - origin_[0];
      const auto iy = static_cast<std::int64_t>(std::floor(wy_[i] * inv_cell_)) - origin_[1];
      const auto iz = static_cast<std::int64_t>(std::floor(wz_[i] * inv_cell_)) - origin_[2];
      keys_[i] = static_cast<std::uint64_t>(iz) * nxy_ + static_cast<std::uint64_t>(iy) * nx_ +
                 static_cast<std::uint64_t>(ix);
      order_[i] = static_cast<std::uint32_t>(i);
    }
  });

  // LSD radix sort, 11-bit digits: stable, so equal keys stay in point order (deterministic).
  constexpr int kDigit = 11;
  constexpr std::size_t kBuckets = std::size_t{1} << kDigit;
  std::array<std::size_t, kBuckets> histogram;
  for (int shift = 0; shift < bits; shift += kDigit) {
    histogram.fill(0);
    for (std::size_t i = 0; i < n_; ++i) ++histogram[(keys_[i] >> shift) & (kBuckets - 1)];
    std::size_t sum = 0;
    for (auto& h : histogram) sum += std::exchange(h, sum);
    for (std::size_t i = 0; i < n_; ++i) {
      const std::size_t dst = histogram[(keys_[i] >> shift) & (kBuckets - 1)]++;
      keys_tmp_[dst] = keys_[i];
      order_tmp_[dst] = order_[i];
    }
    keys_.swap(keys_tmp_);
    order_.swap(order_tmp_);
  }
  for (std::size_t k = 0; k < n_; ++k) {
    sx_[k] = wx_[order_[k]];
    sy_[k] = wy_[order_[k]];
    sz_[k] = wz_[order_[k]];
  }
  // Sweep parts start on cell boundaries so each part owns whole cells.
  sweep_split_.front() = 0;
  sweep_split_.back() = n_;
  for (int p = 1; p < threads_; ++p) {
    std::size_t k = std::max(sweep_split_[p - 1], n_ * static_cast<std::size_t>(p) / threads_);
    while (k > sweep_split_[p - 1] && k < n_ && keys_[k] == keys_[k - 1]) ++k;
    sweep_split_[p] = k;
  }
}

void LidarPoseObjective::sweep(int part) {
  const std::size_t begin = sweep_split_[part], end = sweep_split_[part + 1];
  if (begin >= end) return;
  const float max_sq = max_sq_;
  // The 9 (dy, dz) rows around a cell, own row first so the nearest neighbour is usually found early
  // and the other rows are skipped by their distance bound.
  struct Row {
    int dy, dz;
    std::int64_t offset;
    std::size_t lo, hi;  // sorted positions of the cells (ix−1 .. ix+1) of this row
  };
  std::array<Row, 9> rows;
  {
    int r = 0;
    for (int dz : {0, -1, 1})
      for (int dy : {0, -1, 1})
        rows[r++] = Row{dy, dz,
                        static_cast<std::int64_t>(dz) * static_cast<std::int64_t>(nxy_) +
                            static_cast<std::int64_t>(dy) * static_cast<std::int64_t>(nx_),
                        0, 0};
  }
  const std::uint64_t first_key = keys_[begin];
  for (Row& row : rows) {
    const auto lo_key = static_cast<std::uint64_t>(static_cast<std::int64_t>(first_key) + row.offset - 1);
    row.lo = static_cast<std::size_t>(std::lower_bound(keys_.begin(), keys_.end(), lo_key) - keys_.begin());
    row.hi = row.lo;
  }
  for (std::size_t k = begin; k < end;) {
    const std::uint64_t key = keys_[k];
    std::size_t cell_end = k + 1;
    while (cell_end < end && keys_[cell_end] == key) ++cell_end;
    for (Row& row : rows) {  // keys only grow: every cursor moves forward
      const auto centre = static_cast<std::uint64_t>(static_cast<std::int64_t>(key) + row.offset);
      while (row.lo < n_ && keys_[row.lo] < centre - 1) ++row.lo;
      row.hi = std::max(row.hi, row.lo);
      while (row.hi < n_ && keys_[row.hi] <= centre + 1) ++row.hi;
    }
    for (std::size_t i = k; i < cell_end; ++i) {
      const float x = sx_[i], y = sy_[i], z = sz_[i];
      const float fy = y * inv_cell_ - std::floor(y * inv_cell_);
      const float fz = z * inv_cell_ - std::floor(z * inv_cell_);
      // Smallest possible |Δy|, |Δz| to a neighbouring row: to this cell's lower or upper face.
      const float gap_y[3] = {fy * cell_, 0.0f, (1.0f - fy) * cell_};
      const float gap_z[3] = {fz * cell_, 0.0f, (1.0f - fz) * cell_};
      float best = max_sq;
      for (const Row& row : rows) {
        const float gy = gap_y[row.dy + 1], gz = gap_z[row.dz + 1];
        if (gy * gy + gz * gz >= best) continue;
        for (std::size_t j = row.lo; j < row.hi; ++j) {
          const float dx = sx_[j] - x, dy = sy_[j] - y, dz = sz_[j] - z;
          const float d2 = dx * dx + dy * dy + dz * dz;
          if (d2 < best && j != i) best = d2;
        }
      }
      cost_[i] = best;
    }
    k = cell_end;
  }
}

double LidarPoseObjective::evaluate(const Pose& T_pose_lidar, double time_offset_s, double max_dist_sq) {
  if (!(max_dist_sq > 0.0)) throw std::invalid_argument("LidarPoseObjective: max_dist_sq must be > 0");
  ++evaluations_;
  updatePoses(time_offset_s);
  max_sq_ = static_cast<float>(max_dist_sq);
  cell_ = static_cast<float>(std::sqrt(max_dist_sq));
  inv_cell_ = 1.0f / cell_;
  workers_->run([&](int part) { transform(part, T_pose_lidar); });
  sortByCell();
  workers_->run([&](int part) { sweep(part); });
  // Fixed-order reduction: the same sum for any thread count.
  double total = 0.0;
  for (const float c : cost_) total += static_cast<double>(c);
  return total;
}

}  // namespace rigcal::calib
