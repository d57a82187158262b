#include "autonomy/slam/voxel_map.h"

#include <algorithm>
#include <cmath>
#include <utility>

namespace paddock::slam {

namespace {

// box tests are conservative by this much (m): a point's voxel comes from
// its leaf number, floor(x / leaf), and a voxel's faces from key * voxel,
// each rounded once; 1 um is far above either rounding at any coordinate
// the map accepts (|x| < 2^30 leaves)
constexpr double kBoxMargin = 1e-6;

// a below b in (distance, x, y, z) order
bool before(double d2, const Eigen::Vector3d& p, const VoxelMap::Neighbour& b) {
  if (d2 != b.distance2) return d2 < b.distance2;
  if (p.x() != b.point.x()) return p.x() < b.point.x();
  if (p.y() != b.point.y()) return p.y() < b.point.y();
  return p.z() < b.point.z();
}

// floor(x) for |x| < 2^62, inline (std::floor is a call into libm on x86-64
// without SSE4.1): truncation, one down for a negative non-integer
std::int64_t floor_int(double x) {
  const std::int64_t t = static_cast<std::int64_t>(x);
  return x < static_cast<double>(t) ? t - 1 : t;
}

}  // namespace

std::string VoxelMapParams::check() const {
  const double ratio = voxel_size / leaf_size;
  const double n = std::round(ratio);
  if (n < 1.0 || std::abs(ratio - n) > 1e-6 * n)
    return "voxel_size must be a whole multiple of leaf_size (got " + params::number(voxel_size) + " and " +
           params::number(leaf_size) + ")";
  // a leaf's number inside its voxel, n^3, fits 32 bits
  if (n > 1000.0) return "voxel_size must be at most 1000 leaf_size (got " + params::number(ratio) + ")";
  return "";
}

std::size_t VoxelMap::Table::home(const Key& k) const {
  // each coordinate times an odd 64-bit constant, summed, then
  // murmur3's 64-bit finaliser spreads every bit over the low ones
  std::uint64_t h = static_cast<std::uint64_t>(static_cast<std::uint32_t>(k.x)) * 0x9E3779B97F4A7C15ull +
                    static_cast<std::uint64_t>(static_cast<std::uint32_t>(k.y)) * 0xC2B2AE3D27D4EB4Full +
                    static_cast<std::uint64_t>(static_cast<std::uint32_t>(k.z)) * 0x165667B19E3779F9ull;
  h ^= h >> 33;
  h *= 0xFF51AFD7ED558CCDull;
  h ^= h >> 33;
  return static_cast<std::size_t>(h) & mask_;
}

std::uint32_t VoxelMap::Table::find(const Key& k) const {
  if (slots_.empty()) return kNone;
  for (std::size_t i = home(k);; i = (i + 1) & mask_) {
    const Entry& e = slots_[i];
    if (e.v == kNone || e.key == k) return e.v;
  }
}

void VoxelMap::Table::insert(const Key& k, std::uint32_t v) {
  if (2 * (size_ + 1) > slots_.size()) grow();
  std::size_t i = home(k);
  while (slots_[i].v != kNone) i = (i + 1) & mask_;
  slots_[i] = {k, v};
  ++size_;
}

void VoxelMap::Table::erase(const Key& k) {
  std::size_t i = home(k);
  // present: met before any empty entry
  while (slots_[i].v == kNone || !(slots_[i].key == k)) i = (i + 1) & mask_;
  // backward shift: each later entry of the run moves into the hole unless
  // its home lies cyclically in (hole, entry]
  for (std::size_t j = (i + 1) & mask_; slots_[j].v != kNone; j = (j + 1) & mask_) {
    const std::size_t h = home(slots_[j].key);
    const bool stays = i <= j ? (i < h && h <= j) : (i < h || h <= j);
    if (stays) continue;
    slots_[i] = slots_[j];
    i = j;
  }
  slots_[i].v = kNone;
  --size_;
}

void VoxelMap::Table::grow() {
  std::vector<Entry> old;
  old.swap(slots_);
  slots_.assign(std::max<std::size_t>(64, 2 * old.size()), Entry{});
  mask_ = slots_.size() - 1;
  size_ = 0;
  for (const Entry& e : old)
    if (e.v != kNone) insert(e.key, e.v);
}

void VoxelMap::Table::clear() {
  slots_.clear();
  mask_ = 0;
  size_ = 0;
}

VoxelMap::VoxelMap(const VoxelMapParams& p) : params_(params::require_valid(p, "VoxelMapParams")) {
  leaves_per_voxel_ = static_cast<std::int64_t>(std::round(params_.voxel_size / params_.leaf_size));
  per_voxel_ = static_cast<double>(leaves_per_voxel_);
  voxel_ = per_voxel_ * params_.leaf_size;
  max_coord_ = params_.leaf_size * 1073741824.0;  // 2^30 leaves
  // the query's voxel, then the faces, the edges, the corners: nearest boxes first
  int n = 0;
  for (int nonzero = 0; nonzero <= 3; ++nonzero)
    for (int dx = -1; dx <= 1; ++dx)
      for (int dy = -1; dy <= 1; ++dy)
        for (int dz = -1; dz <= 1; ++dz)
          if ((dx != 0) + (dy != 0) + (dz != 0) == nonzero) offsets_[static_cast<std::size_t>(n++)] = {dx, dy, dz};
  searched_ = params_.nearby == VoxelMapParams::Nearby6 ? 7 : params_.nearby == VoxelMapParams::Nearby18 ? 19 : 27;
}

bool VoxelMap::locate(const double p[3], std::int64_t leaf[3], Key& voxel) const {
  std::int32_t key[3];
  for (int a = 0; a < 3; ++a) {
    if (!(std::abs(p[a]) < max_coord_)) return false;  // NaN too
    leaf[a] = floor_int(p[a] / params_.leaf_size);
    // floor(leaf / n) in doubles: exact, as |leaf| < 2^30 and n <= 1000 (an
    // integer quotient stays one, any other lies at least 1/n below the
    // next integer, far more than a rounding at 2^30), and cheaper than a
    // 64-bit integer division
    key[a] = static_cast<std::int32_t>(floor_int(static_cast<double>(leaf[a]) / per_voxel_));
  }
  voxel = {key[0], key[1], key[2]};
  return true;
}

void VoxelMap::unlink(std::uint32_t v) {
  Voxel& x = pool_[v];
  if (x.prev != kNone) pool_[x.prev].next = x.next;
  else head_ = x.next;
  if (x.next != kNone) pool_[x.next].prev = x.prev;
  else tail_ = x.prev;
  x.prev = x.next = kNone;
}

void VoxelMap::push_front(std::uint32_t v) {
  Voxel& x = pool_[v];
  x.prev = kNone;
  x.next = head_;
  if (head_ != kNone) pool_[head_].prev = v;
  head_ = v;
  if (tail_ == kNone) tail_ = v;
}

std::uint32_t VoxelMap::add_voxel(const Key& key) {
  std::uint32_t v;
  if (!free_.empty()) {
    v = free_.back();
    free_.pop_back();
  } else {
    v = static_cast<std::uint32_t>(pool_.size());
    pool_.emplace_back();
  }
  Voxel& x = pool_[v];
  x.key = key;
  x.live = true;
  if (index_.size() == 0) {
    lo_ = hi_ = key;
  } else {
    lo_ = {std::min(lo_.x, key.x), std::min(lo_.y, key.y), std::min(lo_.z, key.z)};
    hi_ = {std::max(hi_.x, key.x), std::max(hi_.y, key.y), std::max(hi_.z, key.z)};
  }
  index_.insert(key, v);
  push_front(v);
  return v;
}

void VoxelMap::drop_voxel(std::uint32_t v) {
  Voxel& x = pool_[v];
  points_ -= x.points.size();
  index_.erase(x.key);
  unlink(v);
  x.points.clear();  // keeps its capacity for the slot's next voxel
  x.live = false;
  free_.push_back(v);
}

VoxelMap::InsertResult VoxelMap::insert(const std::vector<Eigen::Vector3d>& points) {
  InsertResult r;
  const double leaf = params_.leaf_size;
  const std::size_t cap = static_cast<std::size_t>(params_.max_points_per_voxel);
  const std::int64_t n = leaves_per_voxel_;
  for (const Eigen::Vector3d& in : points) {
    // the point as the map stores it: rounded to float (in range first, or
    // the conversion is undefined)
    if (!(std::abs(in.x()) < max_coord_ && std::abs(in.y()) < max_coord_ && std::abs(in.z()) < max_coord_)) {
      ++r.rejected;
      continue;
    }
    const float f[3] = {static_cast<float>(in.x()), static_cast<float>(in.y()), static_cast<float>(in.z())};
    const double p[3] = {f[0], f[1], f[2]};
    std::int64_t leaf_of[3];
    Key key;
    if (!locate(p, leaf_of, key)) {
      ++r.rejected;
      continue;
    }
    // its leaf's number inside the voxel and its squared distance to the leaf's centre
    std::uint32_t number = 0;
    double d2 = 0.0;
    for (int a = 0; a < 3; ++a) {
      const std::int64_t local = leaf_of[a] - static_cast<std::int64_t>(a == 0 ? key.x : a == 1 ? key.y : key.z) * n;
      number = static_cast<std::uint32_t>(number * static_cast<std::uint64_t>(n) + static_cast<std::uint64_t>(local));
      const double d = p[a] - (static_cast<double>(leaf_of[a]) + 0.5) * leaf;
      d2 += d * d;
    }
    const Slot slot{f[0], f[1], f[2], number};

    const std::uint32_t v = index_.find(key);
    if (v == kNone) {
      if (index_.size() >= static_cast<std::size_t>(params_.max_voxels)) {
        drop_voxel(tail_);
        ++r.evicted_voxels;
      }
      pool_[add_voxel(key)].points.push_back(slot);
      ++points_;
      ++r.added;
      continue;
    }
    if (v != head_) {
      unlink(v);
      push_front(v);
    }
    std::vector<Slot>& pts = pool_[v].points;
    auto same = std::find_if(pts.begin(), pts.end(), [number](const Slot& s) { return s.leaf == number; });
    if (same != pts.end()) {
      // without replacement the leaf's first point stays, however near
      double old2 = 0.0;
      if (params_.replace) {
        const double q[3] = {same->x, same->y, same->z};
        for (int a = 0; a < 3; ++a) {
          const double d = q[a] - (static_cast<double>(leaf_of[a]) + 0.5) * leaf;
          old2 += d * d;
        }
      }
      if (params_.replace && d2 < old2) {
        *same = slot;
        ++r.replaced;
      } else {
        ++r.skipped;
      }
    } else if (pts.size() >= cap) {
      ++r.full;
    } else {
      pts.push_back(slot);
      ++points_;
      ++r.added;
    }
  }
  rejected_ += static_cast<std::size_t>(r.rejected);
  return r;
}

int VoxelMap::knn(const Eigen::Vector3d& query, int k, double max_distance, std::vector<Neighbour>& out) const {
  out.clear();
  if (k <= 0 || !(max_distance >= 0.0) || points_ == 0) return 0;
  const double q[3] = {query.x(), query.y(), query.z()};
  std::int64_t leaf_of[3];
  Key qk;
  if (!locate(q, leaf_of, qk)) return 0;
  const std::size_t kk = static_cast<std::size_t>(k);
  const double limit = max_distance * max_distance;

  // squared distance from the query to the neighbour boxes' near faces, per
  // axis and offset (-1, 0, +1), a little short (kBoxMargin)
  double gap2[3][3];
  const std::int32_t qkey[3] = {qk.x, qk.y, qk.z};
  for (int a = 0; a < 3; ++a) {
    const double lo = static_cast<double>(qkey[a]) * voxel_;
    const double below = std::max(0.0, q[a] - lo - kBoxMargin);
    const double above = std::max(0.0, lo + voxel_ - q[a] - kBoxMargin);
    gap2[a][0] = below * below;
    gap2[a][1] = 0.0;
    gap2[a][2] = above * above;
  }

  // the farthest a point may lie and still enter the list: max_distance,
  // and once the list is full its last
  double bound = limit;
  const auto search = [&](const std::vector<Slot>& points) {
    for (const Slot& s : points) {
      const double dx = static_cast<double>(s.x) - q[0];
      const double dy = static_cast<double>(s.y) - q[1];
      const double dz = static_cast<double>(s.z) - q[2];
      const double d2 = (dx * dx + dy * dy) + dz * dz;
      if (d2 > bound) continue;
      const Eigen::Vector3d p(s.x, s.y, s.z);
      if (out.size() == kk) {
        if (!before(d2, p, out.back())) continue;
        out.back() = {p, d2};
      } else {
        out.push_back({p, d2});
      }
      // insertion into the sorted list
      for (std::size_t j = out.size() - 1; j > 0 && before(out[j].distance2, out[j].point, out[j - 1]); --j)
        std::swap(out[j], out[j - 1]);
      if (out.size() == kk) bound = std::min(limit, out.back().distance2);
    }
  };
  // the query's own voxel first: its points set the bound
  if (const std::uint32_t v = index_.find(qk); v != kNone) search(pool_[v].points);
  // then the neighbours still within it, looked up together (their table
  // probes and points are fetched from memory side by side, not one after
  // the other), searched in order; a neighbour the bound has since passed
  // is skipped
  const std::vector<Slot>* found[26];
  double found_box2[26];
  int n = 0;
  for (int i = 1; i < searched_; ++i) {
    const Key& o = offsets_[static_cast<std::size_t>(i)];
    const double box2 = gap2[0][o.x + 1] + gap2[1][o.y + 1] + gap2[2][o.z + 1];
    if (box2 > bound) continue;
    const std::uint32_t v = index_.find({qk.x + o.x, qk.y + o.y, qk.z + o.z});
    if (v == kNone) continue;
    found[n] = &pool_[v].points;
    __builtin_prefetch(found[n]->data());
    found_box2[n++] = box2;
  }
  for (int i = 0; i < n; ++i)
    if (!(found_box2[i] > bound)) search(*found[i]);
  return static_cast<int>(out.size());
}

std::size_t VoxelMap::remove_outside(const Eigen::Vector3d& centre, double reach) {
  if (!centre.allFinite() || !(reach >= 0.0)) return 0;
  const double c[3] = {centre.x(), centre.y(), centre.z()};
  const double r2 = reach * reach;
  const double inner = reach - kBoxMargin;
  const double outer = reach + kBoxMargin;
  std::size_t removed = 0;
  if (index_.size() == 0) return 0;
  // every voxel ever added lies in [lo_, hi_]: when that box is wholly
  // inside, so is each voxel (the box's faces are its extreme voxels' faces,
  // computed alike), and none need be looked at
  if (inner > 0.0) {
    const std::int32_t lo[3] = {lo_.x, lo_.y, lo_.z}, hi[3] = {hi_.x, hi_.y, hi_.z};
    double far2 = 0.0;
    for (int a = 0; a < 3; ++a) {
      const double low = static_cast<double>(lo[a]) * voxel_;
      const double high = static_cast<double>(hi[a]) * voxel_ + voxel_;
      const double far = std::max(c[a] - low, high - c[a]);
      far2 += far * far;
    }
    if (far2 <= inner * inner) return 0;
  }
  // slot order, never the hash table's
  for (std::uint32_t v = 0; v < pool_.size(); ++v) {
    Voxel& x = pool_[v];
    if (!x.live) continue;
    const std::int32_t key[3] = {x.key.x, x.key.y, x.key.z};
    double near2 = 0.0, far2 = 0.0;
    for (int a = 0; a < 3; ++a) {
      const double lo = static_cast<double>(key[a]) * voxel_;
      const double hi = lo + voxel_;
      const double near = c[a] < lo ? lo - c[a] : c[a] > hi ? c[a] - hi : 0.0;
      const double far = std::max(c[a] - lo, hi - c[a]);
      near2 += near * near;
      far2 += far * far;
    }
    // wholly inside, wholly outside, or point by point
    if (inner > 0.0 && far2 <= inner * inner) continue;
    if (near2 > outer * outer) {
      removed += x.points.size();
      drop_voxel(v);
      continue;
    }
    const auto out = std::remove_if(x.points.begin(), x.points.end(), [&](const Slot& s) {
      const double dx = static_cast<double>(s.x) - c[0];
      const double dy = static_cast<double>(s.y) - c[1];
      const double dz = static_cast<double>(s.z) - c[2];
      return (dx * dx + dy * dy) + dz * dz > r2;
    });
    const std::size_t gone = static_cast<std::size_t>(x.points.end() - out);
    x.points.erase(out, x.points.end());
    points_ -= gone;
    removed += gone;
    if (x.points.empty()) {
      // drop_voxel subtracts what is left: nothing
      drop_voxel(v);
    }
  }
  return removed;
}

std::vector<Eigen::Vector3d> VoxelMap::points() const {
  std::vector<Eigen::Vector3d> all;
  all.reserve(points_);
  for (const Voxel& x : pool_)
    if (x.live)
      for (const Slot& s : x.points) all.emplace_back(s.x, s.y, s.z);
  return all;
}

void VoxelMap::clear() {
  index_.clear();
  pool_.clear();
  free_.clear();
  head_ = tail_ = kNone;
  points_ = 0;
  rejected_ = 0;
}

}  // namespace paddock::slam
