#include "autonomy/perception/intensity_colour.h"

#include <algorithm>
#include <cmath>

#include <Eigen/Dense>

namespace paddock::perception {

IntensityColourClassifier::IntensityColourClassifier(const IntensityColourParams& params)
    : params_(params) {
  params::require_valid(params_, "IntensityColourParams");
}

ConeColor IntensityColourClassifier::classify(const Cloud& cloud, const std::uint32_t* members,
                                              std::size_t n, double top, IntensityProfile* profile) {
  if (profile != nullptr) *profile = IntensityProfile{};
  if (top >= params_.big_cone_height) return ConeColor::BigOrange;
  if (n < static_cast<std::size_t>(params_.min_points)) return ConeColor::Unknown;

  // (layer, intensity), sorted: each layer's run gives its median
  samples_.clear();
  for (std::size_t k = 0; k < n; ++k) {
    const CloudPoint& p = cloud.points[members[k]];
    if (!(p.height >= params_.min_height)) continue;
    const double layer = std::floor(static_cast<double>(p.height) / params_.layer_height);
    if (!(std::abs(layer) < 1e6)) continue;
    samples_.emplace_back(static_cast<int>(layer), p.intensity);
  }
  std::sort(samples_.begin(), samples_.end());
  layer_z_.clear();
  layer_i_.clear();
  for (std::size_t b = 0; b < samples_.size();) {
    std::size_t e = b;
    while (e < samples_.size() && samples_[e].first == samples_[b].first) ++e;
    const std::size_t m = e - b;
    // the median of the sorted run (mean of the middle two when even)
    const double med = m % 2 == 1 ? samples_[b + m / 2].second
                                  : 0.5 * (static_cast<double>(samples_[b + m / 2 - 1].second) +
                                           samples_[b + m / 2].second);
    layer_z_.push_back((samples_[b].first + 0.5) * params_.layer_height);
    layer_i_.push_back(med);
    b = e;
  }
  const int layers = static_cast<int>(layer_z_.size());
  if (profile != nullptr) profile->layers = layers;
  if (layers < params_.min_layers) return ConeColor::Unknown;
  if (layer_z_.back() - layer_z_.front() < params_.min_span) return ConeColor::Unknown;
  const double peak = *std::max_element(layer_i_.begin(), layer_i_.end());
  if (!(peak > 0.0)) return ConeColor::Unknown;

  // least squares I(z) = a z^2 + b z + c in z centred on the layers' mean
  // (the centring changes b and c, not a)
  double zm = 0.0;
  for (double z : layer_z_) zm += z;
  zm /= layers;
  Eigen::Matrix3d ata = Eigen::Matrix3d::Zero();
  Eigen::Vector3d atb = Eigen::Vector3d::Zero();
  for (int l = 0; l < layers; ++l) {
    const double z = layer_z_[static_cast<std::size_t>(l)] - zm;
    const Eigen::Vector3d row(z * z, z, 1.0);
    ata += row * row.transpose();
    atb += row * (layer_i_[static_cast<std::size_t>(l)] / peak);
  }
  const Eigen::Vector3d coef = ata.ldlt().solve(atb);
  const double a = coef[0];
  if (!std::isfinite(a)) return ConeColor::Unknown;
  if (profile != nullptr) profile->curvature = a;
  if (a < -params_.min_curvature) return ConeColor::Blue;
  if (a > params_.min_curvature) return ConeColor::Yellow;
  return ConeColor::Unknown;
}

}  // namespace paddock::perception
