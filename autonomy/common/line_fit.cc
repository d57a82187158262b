#include "autonomy/common/line_fit.h"

#include <algorithm>
#include <cmath>

namespace paddock {

LineFit fit_line(const std::vector<Vec2>& points) {
  LineFit fit;
  if (points.size() < 2) {
    fit.reason = "line fit: fewer than 2 points";
    return fit;
  }
  // centroid and covariance
  Vec2 c{0.0, 0.0};
  for (const Vec2& p : points) {
    if (!(std::isfinite(p.x) && std::isfinite(p.y))) {
      fit.reason = "line fit: a point is not finite";
      return fit;
    }
    c += p;
  }
  const double n = static_cast<double>(points.size());
  c = c / n;
  double sxx = 0.0, sxy = 0.0, syy = 0.0;
  for (const Vec2& p : points) {
    const Vec2 d = p - c;
    sxx += d.x * d.x;
    sxy += d.x * d.y;
    syy += d.y * d.y;
  }
  sxx /= n;
  sxy /= n;
  syy /= n;
  if (!(sxx + syy > 0.0)) {
    fit.reason = "line fit: all points coincide";
    return fit;
  }
  // the principal axis of [[sxx, sxy], [sxy, syy]] is at angle
  // 0.5 atan2(2 sxy, sxx - syy); the smaller eigenvalue is the mean squared
  // distance from the line: (sxx + syy)/2 - sqrt(((sxx - syy)/2)^2 + sxy^2)
  const double angle = 0.5 * std::atan2(2.0 * sxy, sxx - syy);
  const double half = 0.5 * (sxx - syy);
  const double lambda_min = 0.5 * (sxx + syy) - std::sqrt(half * half + sxy * sxy);
  fit.point = c;
  fit.direction = unit_from_angle(angle);
  fit.rms = std::sqrt(std::max(0.0, lambda_min));
  return fit;
}

}  // namespace paddock
