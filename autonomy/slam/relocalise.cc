#include "autonomy/slam/relocalise.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace paddock::slam {

namespace {

// cells marked within the match radius of a mapped cone
class NearGrid {
 public:
  NearGrid(const std::vector<Vec2>& map, double radius, double cell) : cell_(cell) {
    double x0 = std::numeric_limits<double>::infinity(), y0 = x0, x1 = -x0, y1 = -x0;
    for (const Vec2& m : map) {
      x0 = std::min(x0, m.x);
      y0 = std::min(y0, m.y);
      x1 = std::max(x1, m.x);
      y1 = std::max(y1, m.y);
    }
    x0_ = x0 - radius - cell;
    y0_ = y0 - radius - cell;
    nx_ = static_cast<int>((x1 + radius + cell - x0_) / cell) + 1;
    ny_ = static_cast<int>((y1 + radius + cell - y0_) / cell) + 1;
    near_.assign(static_cast<std::size_t>(nx_) * static_cast<std::size_t>(ny_), 0);
    const int reach = static_cast<int>(std::ceil(radius / cell));
    for (const Vec2& m : map) {
      const int cx = static_cast<int>((m.x - x0_) / cell), cy = static_cast<int>((m.y - y0_) / cell);
      for (int j = cy - reach; j <= cy + reach; ++j)
        for (int i = cx - reach; i <= cx + reach; ++i) {
          if (i < 0 || j < 0 || i >= nx_ || j >= ny_) continue;
          const Vec2 centre{x0_ + (i + 0.5) * cell, y0_ + (j + 0.5) * cell};
          if (distance(centre, m) <= radius) near_[static_cast<std::size_t>(j) * nx_ + i] = 1;
        }
    }
  }
  bool near(Vec2 p) const {
    const double fx = (p.x - x0_) / cell_, fy = (p.y - y0_) / cell_;
    if (!(fx >= 0.0 && fy >= 0.0 && fx < nx_ && fy < ny_)) return false;
    return near_[static_cast<std::size_t>(fy) * nx_ + static_cast<std::size_t>(fx)] != 0;
  }

 private:
  double cell_, x0_ = 0.0, y0_ = 0.0;
  int nx_ = 0, ny_ = 0;
  std::vector<unsigned char> near_;
};

// the nearest mapped cone to p within r, if any
const Vec2* nearest(const std::vector<Vec2>& map, Vec2 p, double r) {
  const Vec2* best = nullptr;
  double best_d = r;
  for (const Vec2& m : map) {
    const double d = distance(m, p);
    if (d <= best_d) {
      best_d = d;
      best = &m;
    }
  }
  return best;
}

// a few rounds of the closed-form rigid fit of the inliers onto their cones
Relocalisation refine(const std::vector<Vec2>& map, const std::vector<Vec2>& obs, Pose2 pose, double radius) {
  Relocalisation out{pose, 0};
  for (int round = 0; round < 5; ++round) {
    std::vector<std::pair<Vec2, Vec2>> pairs;  // (base frame, map)
    for (const Vec2& o : obs)
      if (const Vec2* m = nearest(map, pose.transform(o), radius)) pairs.emplace_back(o, *m);
    out = {pose, static_cast<int>(pairs.size())};
    if (pairs.size() < 2) return out;
    Vec2 ca{0.0, 0.0}, cb{0.0, 0.0};
    for (const auto& [a, b] : pairs) {
      ca = ca + a;
      cb = cb + b;
    }
    ca = ca * (1.0 / static_cast<double>(pairs.size()));
    cb = cb * (1.0 / static_cast<double>(pairs.size()));
    double sxx = 0.0, sxy = 0.0;  // the cross terms of the 2-D rotation's fit
    for (const auto& [a, b] : pairs) {
      const Vec2 da = a - ca, db = b - cb;
      sxx += da.x * db.x + da.y * db.y;
      sxy += da.x * db.y - da.y * db.x;
    }
    const double yaw = std::atan2(sxy, sxx);
    const Vec2 t = cb - rotate(ca, yaw);
    pose = {t.x, t.y, wrap_angle(yaw)};
  }
  return out;
}

Relocalisation relocalise_search(const std::vector<Vec2>& map, const std::vector<Vec2>& observations, const Pose2& guess,
                                 const RelocaliseParams& p) {
  Relocalisation best{guess, -1};
  if (map.empty() || observations.empty()) return {guess, 0};
  const NearGrid grid(map, p.match_radius, std::min(p.match_radius, p.step_xy) * 0.5);
  const int nxy = static_cast<int>(std::floor(p.search_xy / p.step_xy));
  const int nyaw = static_cast<int>(std::floor(p.search_yaw / p.step_yaw));
  // nearest the guess first, so a tie keeps the pose least far from it
  for (int k = 0; k <= 2 * nyaw; ++k) {
    const int a = (k + 1) / 2 * (k % 2 ? 1 : -1);
    const double yaw = guess.yaw + a * p.step_yaw;
    const double c = std::cos(yaw), s = std::sin(yaw);
    for (int j = -nxy; j <= nxy; ++j)
      for (int i = -nxy; i <= nxy; ++i) {
        const double x = guess.x + i * p.step_xy, y = guess.y + j * p.step_xy;
        int score = 0;
        for (const Vec2& o : observations) score += grid.near({x + c * o.x - s * o.y, y + s * o.x + c * o.y}) ? 1 : 0;
        const double d2 = static_cast<double>(i * i + j * j + a * a);
        const double b2 = std::pow((best.pose.x - guess.x) / p.step_xy, 2) + std::pow((best.pose.y - guess.y) / p.step_xy, 2) +
                          std::pow(wrap_angle(best.pose.yaw - guess.yaw) / p.step_yaw, 2);
        if (score > best.inliers || (score == best.inliers && d2 < b2)) best = {{x, y, wrap_angle(yaw)}, score};
      }
  }
  return best;
}

}  // namespace

std::optional<Relocalisation> relocalise(const std::vector<Vec2>& map, const std::vector<Vec2>& observations,
                                         const Pose2& guess, const RelocaliseParams& p) {
  const Relocalisation coarse = relocalise_search(map, observations, guess, p);
  if (coarse.inliers <= 0) return std::nullopt;
  const Relocalisation fine = refine(map, observations, coarse.pose, p.match_radius);
  const double need = std::max(static_cast<double>(p.min_inliers), p.min_inlier_ratio * static_cast<double>(observations.size()));
  if (static_cast<double>(fine.inliers) < need) return std::nullopt;
  return fine;
}

}  // namespace paddock::slam
