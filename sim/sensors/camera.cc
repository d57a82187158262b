#include "sim/sensors/camera.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>
#include <stdexcept>

#include "sim/sensors/embree_ray.h"
#include "sim/sensors/gaussian_table.h"

namespace paddock::sensors {

namespace {

std::uint8_t to_byte(double v) {
  return static_cast<std::uint8_t>(std::lround(255.0 * std::clamp(v, 0.0, 1.0)));
}

const Rgb& albedo(const CameraParams& p, LidarMaterial m) {
  switch (m) {
    case LidarMaterial::White: return p.white;
    case LidarMaterial::Yellow: return p.yellow;
    case LidarMaterial::Orange: return p.orange;
    case LidarMaterial::Blue: return p.blue;
    case LidarMaterial::Black: return p.black;
    case LidarMaterial::Grey: return p.grey;
    case LidarMaterial::Ground: return p.ground;
    case LidarMaterial::Barrier: return p.grey;  // grey concrete, as a cone of no colour
  }
  return p.grey;
}

constexpr float kNear = 1e-3f;          // m, near plane for the boxes' projection
constexpr double kCarryStep = 1e-4;     // m, past a hit before casting on
constexpr int kMaxCarry = 64;           // surfaces a carried-on ray may pass
constexpr std::uint8_t kMaxCover = 255;
constexpr int kGroundTile = 4;          // px, non-flat ground outside the boxes
// the cones' bounding frustums are grown by 1 mm plus 64 float epsilons of
// the scene's scale (the coordinates' magnitudes): far more than Embree's
// float arithmetic can put a hit outside its triangle, or the frustum test's
// rays (the pixel's direction before it is normalised and rounded to float)
// can differ from the rays cast
constexpr double kFrustumMargin = 1e-3;  // m
constexpr double kFrustumRelMargin = 64.0 * std::numeric_limits<float>::epsilon();
// r0 + (r1 - r0) a / length at a vertex's a may round a little below its
// distance from the axis even where the vertex defines r0 or r1
constexpr double kFrustumTolerance = 1e-9;  // m

// the rays from one origin against one frustum: the terms that depend only
// on the two, then one ray at a time (ray_meets_frustum)
class FrustumRays {
 public:
  FrustumRays(const ConeFrustum& f, const double o[3])
      : ax_(f.axis), p_((f.axis + 1) % 3), q_((f.axis + 2) % 3), length_(f.length) {
    // the ray in the frustum's terms: a(t) = alpha + beta t along the axis,
    // (ep + t fp, eq + t fq) across it; the radius there r0 + k a(t) =
    // rho + k beta t
    degenerate_ = !(f.length > 0.0);
    k_ = degenerate_ ? 0.0 : (f.r1 - f.r0) / f.length;
    alpha_ = o[ax_] - f.centre[ax_];
    ep_ = o[p_] - f.centre[p_];
    eq_ = o[q_] - f.centre[q_];
    rho_ = f.r0 + k_ * alpha_;
  }

  bool meets(const double d[3]) const {
    if (degenerate_) return true;  // no slope to take: say it may meet
    const double beta = d[ax_], fp = d[p_], fq = d[q_];
    // the t >= 0 with 0 <= a(t) <= length: [t0, t1]
    double t0 = 0.0, t1 = std::numeric_limits<double>::infinity();
    if (beta != 0.0) {
      const double ta = -alpha_ / beta, tb = (length_ - alpha_) / beta;
      t0 = std::max(t0, std::min(ta, tb));
      t1 = std::max(ta, tb);
      if (!(t0 <= t1)) return false;
    } else if (!(alpha_ >= 0.0 && alpha_ <= length_)) {
      return false;
    }
    // over [t0, t1] the radius is >= 0, so the ray is inside where
    // g(t) = |across(t)|^2 - radius(t)^2 <= 0; g is a quadratic
    // A t^2 + 2 B t + C, least over the interval at an end or, when A > 0,
    // at -B / A
    const double kb = k_ * beta;
    const auto g = [&](double t) {
      const double x = ep_ + t * fp, y = eq_ + t * fq, r = rho_ + kb * t;
      return x * x + y * y - r * r;
    };
    if (g(t0) <= 0.0) return true;
    if (t1 < std::numeric_limits<double>::infinity() && g(t1) <= 0.0) return true;
    const double A = fp * fp + fq * fq - kb * kb;
    if (!(A > 0.0)) return false;  // concave or linear: least at an end
    const double tv = -(ep_ * fp + eq_ * fq - rho_ * kb) / A;
    return tv > t0 && tv < t1 && g(tv) <= 0.0;
  }

 private:
  int ax_, p_, q_;
  double length_;
  bool degenerate_ = false;
  double k_ = 0.0, alpha_ = 0.0, ep_ = 0.0, eq_ = 0.0, rho_ = 0.0;
};

}  // namespace

bool ray_meets_frustum(const ConeFrustum& f, const double o[3], const double d[3]) {
  return FrustumRays(f, o).meets(d);
}

bool bounding_frustum(const float* v, const unsigned* idx, unsigned prim0, unsigned prim1, int axis, double margin,
                      ConeFrustum& f) {
  if (prim1 <= prim0) return false;
  // the vertices numbered from the triangles' least index to their greatest:
  // theirs and maybe others, which could only make the frustum larger (a
  // LidarWorld cone's 33 vertices are numbered together, and its 48
  // triangles name each about 4 times)
  unsigned first = idx[3 * prim0], last = first;
  for (unsigned k = 3 * prim0; k < 3 * prim1; ++k) {
    first = std::min(first, idx[k]);
    last = std::max(last, idx[k]);
  }
  const float* const begin = v + 3 * static_cast<std::size_t>(first);
  const float* const end = v + 3 * (static_cast<std::size_t>(last) + 1);
  const int p = (axis + 1) % 3, q = (axis + 2) % 3;
  // their box
  double lo[3], hi[3];
  for (int e = 0; e < 3; ++e) lo[e] = hi[e] = begin[e];
  for (const float* x = begin; x != end; x += 3) {
    for (int e = 0; e < 3; ++e) {
      if (!std::isfinite(x[e])) return false;
      lo[e] = std::min(lo[e], static_cast<double>(x[e]));
      hi[e] = std::max(hi[e], static_cast<double>(x[e]));
    }
  }
  const double cp = 0.5 * (lo[p] + hi[p]), cq = 0.5 * (lo[q] + hi[q]), length = hi[axis] - lo[axis];
  // squared distances from the axis (float coordinates, double arithmetic:
  // no rounding that matters)
  const auto radial2 = [&](const float* x) {
    const double dp = x[p] - cp, dq = x[q] - cq;
    return dp * dp + dq * dq;
  };
  // the radii at the ends: the farthest vertex of each half
  double r0 = 0.0, r1 = 0.0;
  for (const float* x = begin; x != end; x += 3) {
    double& r = x[axis] - lo[axis] <= 0.5 * length ? r0 : r1;
    r = std::max(r, radial2(x));
  }
  r0 = std::sqrt(r0);
  r1 = std::sqrt(r1);
  // verified: every vertex within the radius at its height; else the cylinder
  bool holds = length > 0.0;
  for (const float* x = begin; x != end && holds; x += 3) {
    const double r = r0 + (r1 - r0) * ((x[axis] - lo[axis]) / length) + kFrustumTolerance;
    holds = radial2(x) <= r * r;
  }
  if (!holds) r0 = r1 = std::max(r0, r1);
  // grown by margin: each end moved out by margin along the axis, the radius
  // r(a) (carried on linearly past the ends) by margin (1 + |slope|). That
  // holds every point within margin of the frustum: its lateral surface moved
  // out by margin along its normal is margin sqrt(1 + slope^2) further from
  // the axis, and at the narrow end, moved margin out, the radius still
  // exceeds the rim's by margin
  const double slope = length > 0.0 ? (r1 - r0) / length : 0.0;
  const double grow = margin * (1.0 + std::abs(slope));
  f.axis = axis;
  f.centre[axis] = lo[axis] - margin;
  f.centre[p] = cp;
  f.centre[q] = cq;
  f.length = length + 2.0 * margin;
  f.r0 = r0 - slope * margin + grow;
  f.r1 = r1 + slope * margin + grow;
  return true;
}

int trigger_column(const LidarParams& lidar, double azimuth) {
  const int n = std::max(lidar.columns, 1);
  const double a = wrap_angle(azimuth);  // [-pi, pi)
  // the turn since the seam at which the head looks there (hal::column_azimuth)
  const double turn = lidar.clockwise ? kPi - a : a + kPi;
  const long c = std::lround(turn * n / (2.0 * kPi));
  return static_cast<int>(((c % n) + n) % n);
}

TimeNs trigger_time(const LidarParams& lidar, double azimuth, TimeNs scan_start) {
  const TimeNs period = from_seconds(1.0 / lidar.rate);
  return scan_start + period * trigger_column(lidar, azimuth) / std::max(lidar.columns, 1);
}

perception::CameraCalibration camera_calibration(const CameraParams& p) {
  perception::CameraCalibration c;
  c.width = p.width;
  c.height = p.height;
  c.fx = c.fy = 0.5 * p.width / std::tan(0.5 * p.hfov);
  c.cx = 0.5 * p.width;
  c.cy = 0.5 * p.height;
  // the optical axes in the base frame: x right = -y_base; y down and z
  // forward are -z_base and +x_base pitched nose down by mount_pitch about y_base
  // (R_y(theta) takes x_base to (cos, 0, -sin))
  const double ct = std::cos(p.mount_pitch), st = std::sin(p.mount_pitch);
  Eigen::Matrix3d R_base_camera;
  R_base_camera.col(0) = Eigen::Vector3d(0.0, -1.0, 0.0);
  R_base_camera.col(1) = Eigen::Vector3d(-st, 0.0, -ct);
  R_base_camera.col(2) = Eigen::Vector3d(ct, 0.0, -st);
  Eigen::Isometry3d T_base_camera = Eigen::Isometry3d::Identity();
  T_base_camera.linear() = R_base_camera;
  T_base_camera.translation() = Eigen::Vector3d(p.mount_x, p.mount_y, p.mount_z);
  c.T_camera_base = T_base_camera.inverse();
  return c;
}

Camera::Camera(const CameraParams& params, std::uint64_t seed)
    : params_(params), rng_(seed) {
  params::require_valid(params_, "CameraParams");
  calibration_ = camera_calibration(params_);
  const auto w = static_cast<std::size_t>(params_.width);
  const auto h = static_cast<std::size_t>(params_.height);
  ax_.resize(w);
  by_.resize(h);
  for (std::size_t i = 0; i < w; ++i) {
    ax_[i] = (static_cast<double>(i) + 0.5 - calibration_.cx) / calibration_.fx;
  }
  for (std::size_t j = 0; j < h; ++j) {
    by_[j] = (static_cast<double>(j) + 0.5 - calibration_.cy) / calibration_.fy;
  }
  const double ce = std::cos(params_.sun_elevation);
  sun_[0] = ce * std::cos(params_.sun_azimuth);
  sun_[1] = ce * std::sin(params_.sun_azimuth);
  sun_[2] = std::sin(params_.sun_elevation);
  sky_rgb_ = {to_byte(params_.sky.r), to_byte(params_.sky.g), to_byte(params_.sky.b)};
  ground_rgb_ = shade(params_.ground, std::max(0.0, sun_[2]));
  // a row of sky and a row of flat ground, copied into each frame's rows
  sky_row_.resize(3 * w);
  ground_row_.resize(3 * w);
  for (std::size_t i = 0; i < w; ++i) {
    std::copy(sky_rgb_.begin(), sky_rgb_.end(), sky_row_.begin() + 3 * static_cast<std::ptrdiff_t>(i));
    std::copy(ground_rgb_.begin(), ground_rgb_.end(), ground_row_.begin() + 3 * static_cast<std::ptrdiff_t>(i));
  }
  stamp_.assign(w * h, 0);
  cover_.assign(w * h, 0);
  reach_.assign(w * h, 0.0f);
  // the noise table: the quantiles of N(0, 1) (gaussian_table.h) times
  // pixel_noise, rounded to levels
  if (params_.pixel_noise > 0.0) {
    const auto& q = gaussian_quantiles();
    noise_.resize(q.size());
    for (std::size_t k = 0; k < q.size(); ++k) {
      noise_[k] = static_cast<std::int16_t>(std::lround(params_.pixel_noise * q[k]));
    }
  }
}

std::array<std::uint8_t, 3> Camera::shade(const Rgb& a, double lambert) const {
  const double k = params_.ambient + (1.0 - params_.ambient) * lambert;
  return {to_byte(a.r * k), to_byte(a.g * k), to_byte(a.b * k)};
}

void Camera::read_cones(const LidarWorld& world) {
  // a world's cones never move: read once per world
  if (world.serial() == cones_world_) return;
  cones_world_ = world.serial();
  cones_.clear();
  cone_geom_id_ = RTC_INVALID_GEOMETRY_ID;
  cone_v_ = nullptr;
  cone_idx_ = nullptr;
  geom_of_.assign(world.cone_count(), -1);
  // the cone geometry: the one whose primitive 0 belongs to a cone (LidarWorld
  // attaches the ground, then the cones)
  for (unsigned g = 0; g < 4; ++g) {
    if (world.cone_of(g, 0) >= 0) {
      cone_geom_id_ = g;
      break;
    }
  }
  if (cone_geom_id_ == RTC_INVALID_GEOMETRY_ID) return;
  RTCGeometry geom = rtcGetGeometryThreadSafe(world.scene(), cone_geom_id_);
  if (geom == nullptr) return;
  const auto* v = static_cast<const float*>(rtcGetGeometryBufferData(geom, RTC_BUFFER_TYPE_VERTEX, 0));
  const auto* idx = static_cast<const unsigned*>(rtcGetGeometryBufferData(geom, RTC_BUFFER_TYPE_INDEX, 0));
  if (v == nullptr || idx == nullptr) return;
  cone_v_ = v;
  cone_idx_ = idx;
  // every triangle grows the box of its cone; a cone's triangles are
  // contiguous (lidar.cc; one that is not gets no frustum)
  std::int32_t prev = -1;
  ConeGeom* cur = nullptr;
  for (unsigned prim = 0;; ++prim) {
    const std::int32_t c = world.cone_of(cone_geom_id_, prim);
    if (c < 0) break;
    if (c != prev) {
      const auto cu = static_cast<std::size_t>(c);
      if (geom_of_[cu] < 0) {
        geom_of_[cu] = static_cast<std::int32_t>(cones_.size());
        ConeGeom cg;
        cg.id = c;
        cg.prim = prim;
        const float* p = v + 3 * idx[3 * prim];
        std::copy(p, p + 3, cg.lo);
        std::copy(p, p + 3, cg.hi);
        cones_.push_back(cg);
      } else {
        cones_[static_cast<std::size_t>(geom_of_[cu])].split = true;
      }
      cur = &cones_[static_cast<std::size_t>(geom_of_[cu])];
      prev = c;
    }
    cur->prim_end = prim + 1;
    for (int k = 0; k < 3; ++k) {
      const float* p = v + 3 * idx[3 * prim + static_cast<unsigned>(k)];
      for (int a = 0; a < 3; ++a) {
        cur->lo[a] = std::min(cur->lo[a], p[a]);
        cur->hi[a] = std::max(cur->hi[a], p[a]);
      }
    }
  }
}

bool Camera::is_standing(const ConeGeom& c) {
  // lidar.h: a standing cone's axis is world +z from its base centre, a knocked
  // cone's world +x (base at -x); standing cones are taller than wide, knocked
  // ones longer along x than high
  return c.hi[2] - c.lo[2] > c.hi[0] - c.lo[0];
}

ConeColor Camera::cone_class(const LidarWorld& world, const ConeGeom& c, double mid[3]) const {
  const double ex = c.hi[0] - c.lo[0], ez = c.hi[2] - c.lo[2];
  const bool standing = is_standing(c);
  const double base[3] = {standing ? 0.5 * (c.lo[0] + c.hi[0]) : c.lo[0], 0.5 * (c.lo[1] + c.hi[1]),
                          standing ? c.lo[2] : 0.5 * (c.lo[2] + c.hi[2])};
  const double axis[3] = {standing ? 0.0 : 1.0, 0.0, standing ? 1.0 : 0.0};
  const double h = standing ? ez : ex;
  for (int a = 0; a < 3; ++a) mid[a] = base[a] + 0.5 * h * axis[a];
  // the body's material 10 % up the axis (below every stripe), the size from the height
  const LidarMaterial m = world.material_of(cone_geom_id_, c.prim, base[0] + 0.1 * h * axis[0],
                                            base[1], base[2] + 0.1 * h * axis[2]);
  switch (m) {
    case LidarMaterial::Blue: return ConeColor::Blue;
    case LidarMaterial::Yellow: return ConeColor::Yellow;
    case LidarMaterial::Orange:
      return h > 0.5 * (kSmallConeHeight + kBigConeHeight) ? ConeColor::BigOrange : ConeColor::SmallOrange;
    default: return ConeColor::Unknown;
  }
}

AnnotatedFrame Camera::render(const LidarWorld& world, const Pose2& base_pose, TimeNs stamp) {
  AnnotatedFrame f;
  render(world, base_pose, stamp, f.frame, f.annotation);
  return f;
}

void Camera::render(const LidarWorld& world, const Pose2& base_pose, TimeNs stamp, hal::CameraFrame& out,
                    CameraAnnotation& annotation, bool pixels) {
  const int W = params_.width, H = params_.height;
  const std::size_t n_px = static_cast<std::size_t>(W) * static_cast<std::size_t>(H);
  out.stamp = stamp;
  out.width = W;
  out.height = H;
  const bool same_image = pixels && out.rgb.size() == 3 * n_px && out.rgb.data() == rgb_buffer_;
  out.rgb.resize(3 * n_px);
  // the labels: -1 everywhere; when the buffer is the one this camera wrote
  // last frame (as the runner passes it), only the pixels it labelled then
  // differ from that
  if (annotation.labels.size() == n_px && annotation.labels.data() == labels_buffer_) {
    for (std::uint32_t p : labelled_) annotation.labels[p] = -1;
  } else {
    annotation.labels.assign(n_px, -1);
  }
  labels_buffer_ = annotation.labels.data();
  labelled_.clear();
  // the image likewise: when the buffer is the one this camera wrote last
  // frame and that frame was the flat ground's background (the same every
  // frame: it depends on the mount's pitch alone) with painted_ drawn on it,
  // only those pixels differ from the background
  // (without pixels nothing is painted: the next image is painted whole)
  const bool background_kept = same_image && flat_background_;
  rgb_buffer_ = pixels ? out.rgb.data() : nullptr;
  flat_background_ = false;
  annotation.instances.clear();
  last_primary_rays_ = last_continued_rays_ = 0;
  annotation.listed = true;  // (the list is labelled_, copied at the end)
  annotation.labelled.clear();
  if (!finite(base_pose.x) || !finite(base_pose.y) || !finite(base_pose.yaw)) {
    if (pixels) std::fill(out.rgb.begin(), out.rgb.end(), std::uint8_t{0});
    return;
  }
  // a new stamp for "inside a box this frame"; on wrap-around, clear the stamps
  if (++frame_ == 0) {
    std::fill(stamp_.begin(), stamp_.end(), 0u);
    frame_ = 1;
  }

  // the optical centre and axes in the world: the base's yaw on top of the mount
  const Vec2 o2 = base_pose.transform({params_.mount_x, params_.mount_y});
  const double o[3] = {o2.x, o2.y, world.ground_z(o2.x, o2.y) + params_.mount_z};
  const Eigen::Matrix3d Rbc = calibration_.T_camera_base.linear().transpose();
  const double cyaw = std::cos(base_pose.yaw), syaw = std::sin(base_pose.yaw);
  double col[3][3];  // col[k]: optical axis k in the world
  for (int k = 0; k < 3; ++k) {
    const double bx = Rbc(0, k), by = Rbc(1, k), bz = Rbc(2, k);
    col[k][0] = cyaw * bx - syaw * by;
    col[k][1] = syaw * bx + cyaw * by;
    col[k][2] = bz;
  }
  const bool flat_ground = flat(world.ground());

  // background, row by row: with no roll the x axis is level, so a row's rays
  // all point up (sky) or all down (flat ground)
  const auto ground_row = [&](std::size_t j) { return flat_ground && by_[j] * col[1][2] + col[2][2] < 0.0; };
  // (without pixels background_kept is false, and nothing is painted)
  if (background_kept && flat_ground) {
    for (std::uint32_t p : painted_) {
      const std::array<std::uint8_t, 3>& rgb = ground_row(p / static_cast<std::uint32_t>(W)) ? ground_rgb_ : sky_rgb_;
      std::copy(rgb.begin(), rgb.end(), out.rgb.begin() + 3 * static_cast<std::ptrdiff_t>(p));
    }
  } else if (pixels) {
    for (int j = 0; j < H; ++j) {
      const std::vector<std::uint8_t>& row = ground_row(static_cast<std::size_t>(j)) ? ground_row_ : sky_row_;
      std::copy(row.begin(), row.end(), out.rgb.begin() + 3 * static_cast<std::ptrdiff_t>(j) * W);
    }
  }
  painted_.clear();

  // the cones' boxes: project each cone's 3D box (clipped at the near plane),
  // mark the pixels whose centres it may cover (plus 1 px). With the culling,
  // only those whose rays meet the cone's bounding frustum: the others cannot
  // hit the cone. Only where leaving a ray out changes nothing: on flat
  // ground (a ray that meets no cone finds the ground or the sky, which the
  // background already shows) and with no blocks (drawn only where rays are
  // cast)
  const bool cull = culling_ && flat_ground && world.block_count() == 0;
  // the rays' origin as cast (float)
  const double of[3] = {static_cast<float>(o[0]), static_cast<float>(o[1]), static_cast<float>(o[2])};
  const double o_scale = std::max({std::abs(of[0]), std::abs(of[1]), std::abs(of[2])});
  read_cones(world);
  visible_.assign(world.cone_count(), 0);
  unoccluded_.assign(world.cone_count(), 0);
  boxed_.clear();
  cast_.clear();
  for (std::size_t s = 0; s < cones_.size(); ++s) {
    const ConeGeom& c = cones_[s];
    float pc[8][3];
    for (int k = 0; k < 8; ++k) {
      const double w[3] = {(k & 1) ? c.hi[0] : c.lo[0], (k & 2) ? c.hi[1] : c.lo[1], (k & 4) ? c.hi[2] : c.lo[2]};
      const double d[3] = {w[0] - o[0], w[1] - o[1], w[2] - o[2]};
      for (int a = 0; a < 3; ++a) {
        pc[k][a] = static_cast<float>(col[a][0] * d[0] + col[a][1] * d[1] + col[a][2] * d[2]);
      }
    }
    float u0 = 1e30f, u1 = -1e30f, v0 = 1e30f, v1 = -1e30f;
    bool any = false;
    float reach = 0.0f;  // m, to the box's farthest corner
    for (int k = 0; k < 8; ++k) {
      reach = std::max(reach, std::sqrt(pc[k][0] * pc[k][0] + pc[k][1] * pc[k][1] + pc[k][2] * pc[k][2]));
    }
    const auto add = [&](float x, float y, float z) {
      const float u = static_cast<float>(calibration_.fx) * x / z + static_cast<float>(calibration_.cx);
      const float v = static_cast<float>(calibration_.fy) * y / z + static_cast<float>(calibration_.cy);
      u0 = std::min(u0, u);
      u1 = std::max(u1, u);
      v0 = std::min(v0, v);
      v1 = std::max(v1, v);
      any = true;
    };
    for (int k = 0; k < 8; ++k) {
      if (pc[k][2] >= kNear) add(pc[k][0], pc[k][1], pc[k][2]);
      // the box's edges (corners one bit apart) that cross the near plane
      for (int b = 1; b < 8; b <<= 1) {
        const int m = k | b;
        if (m == k) continue;
        const float za = pc[k][2], zb = pc[m][2];
        if ((za < kNear) == (zb < kNear)) continue;
        const float t = (kNear - za) / (zb - za);
        add(pc[k][0] + t * (pc[m][0] - pc[k][0]), pc[k][1] + t * (pc[m][1] - pc[k][1]), kNear);
      }
    }
    if (!any) continue;
    // pixel i's centre i + 0.5 lies in [u0, u1] for i in [u0 - 0.5, u1 - 0.5]; +-1 px
    const float lim_u = static_cast<float>(W), lim_v = static_cast<float>(H);
    if (u1 < -1.0f || v1 < -1.0f || u0 > lim_u + 1.0f || v0 > lim_v + 1.0f) continue;
    const int i0 = std::max(0, static_cast<int>(std::ceil(std::max(u0, -2.0f) - 0.5f)) - 1);
    const int i1 = std::min(W - 1, static_cast<int>(std::floor(std::min(u1, lim_u + 2.0f) - 0.5f)) + 1);
    const int j0 = std::max(0, static_cast<int>(std::ceil(std::max(v0, -2.0f) - 0.5f)) - 1);
    const int j1 = std::min(H - 1, static_cast<int>(std::floor(std::min(v1, lim_v + 2.0f) - 0.5f)) + 1);
    if (i0 > i1 || j0 > j1) continue;
    boxed_.push_back(static_cast<std::int32_t>(s));
    // its frustum, grown by a margin from the magnitudes of the coordinates in play
    float c_scale = 0.0f;
    for (int a = 0; a < 3; ++a) c_scale = std::max({c_scale, std::abs(c.lo[a]), std::abs(c.hi[a])});
    const double margin = kFrustumMargin + kFrustumRelMargin * (o_scale + c_scale);
    ConeFrustum fr;
    const bool test = cull && !c.split && cone_v_ != nullptr &&
                      bounding_frustum(cone_v_, cone_idx_, c.prim, c.prim_end, is_standing(c) ? 2 : 0, margin, fr);
    const FrustumRays rays(fr, of);
    for (int j = j0; j <= j1; ++j) {
      const std::size_t row = static_cast<std::size_t>(j) * static_cast<std::size_t>(W);
      int a = i0, b = i1;
      if (test) {
        // the row's pixels whose rays meet the frustum are one run (the rays
        // from o that meet a convex body fill a convex cone, whose cut with
        // the plane of the row's rays is a wedge): from each end of the box's
        // run inwards to the first pixel whose ray meets it. The ray is the
        // pixel's before it is normalised and rounded to float, as ray_dir
        // casts it
        const double by = by_[static_cast<std::size_t>(j)];
        const double dj[3] = {by * col[1][0] + col[2][0], by * col[1][1] + col[2][1], by * col[1][2] + col[2][2]};
        const auto meets = [&](int i) {
          const double ai = ax_[static_cast<std::size_t>(i)];
          const double d[3] = {ai * col[0][0] + dj[0], ai * col[0][1] + dj[1], ai * col[0][2] + dj[2]};
          return rays.meets(d);
        };
        while (a <= b && !meets(a)) ++a;
        while (b > a && !meets(b)) --b;
      }
      for (int i = a; i <= b; ++i) {
        const std::size_t p = row + static_cast<std::size_t>(i);
        if (stamp_[p] != frame_) {
          stamp_[p] = frame_;
          cover_[p] = 1;
          reach_[p] = reach;
          cast_.push_back(static_cast<std::uint32_t>(p));
        } else {
          if (cover_[p] < kMaxCover) ++cover_[p];
          reach_[p] = std::max(reach_[p], reach);
        }
      }
    }
  }
  RTCIntersectContext context;
  rtcInitIntersectContext(&context);
  // neighbouring pixels: coherent packets (Embree traverses them together)
  context.flags = RTC_INTERSECT_CONTEXT_FLAG_COHERENT;
  // the unit ray through the centre of pixel p
  const auto ray_dir = [&](std::uint32_t p, double d[3]) {
    const double a = ax_[p % static_cast<std::uint32_t>(W)], c = by_[p / static_cast<std::uint32_t>(W)];
    for (int e = 0; e < 3; ++e) d[e] = a * col[0][e] + c * col[1][e] + col[2][e];
    const double inv = 1.0 / std::sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
    for (int e = 0; e < 3; ++e) d[e] *= inv;
  };
  // cast the pixels of `list` in packets of 16 (neighbours in a row: coherent)
  // and hand each hit to on_hit(pixel, rayhit, lane)
  const auto cast = [&](const std::vector<std::uint32_t>& list, auto&& on_hit) {
    for (std::size_t b = 0; b < list.size(); b += 16) {
      const int n = static_cast<int>(std::min<std::size_t>(16, list.size() - b));
      alignas(64) int valid[16];
      alignas(64) RTCRayHit16 rh;
      for (int k = 0; k < 16; ++k) {
        valid[k] = k < n ? -1 : 0;
        double d[3];
        ray_dir(list[b + static_cast<std::size_t>(std::min(k, n - 1))], d);
        set_ray(rh, k, o, d, 0.0f, std::numeric_limits<float>::infinity());
      }
      rtcIntersect16(valid, world.scene(), &context, &rh);
      last_primary_rays_ += static_cast<std::size_t>(n);
      for (int k = 0; k < n; ++k) {
        if (rh.hit.geomID[k] == RTC_INVALID_GEOMETRY_ID) continue;  // sky: already filled
        on_hit(list[b + static_cast<std::size_t>(k)], rh, k);
      }
    }
  };
  // the Lambert term of hit k: the facet's normal turned towards the camera
  const auto lambert_of = [&](const RTCRayHit16& rh, int k) {
    const double nx = rh.hit.Ng_x[k], ny = rh.hit.Ng_y[k], nz = rh.hit.Ng_z[k];
    const double nn = std::sqrt(nx * nx + ny * ny + nz * nz);
    if (!(nn > 0.0)) return 0.0;
    const double facing = nx * rh.ray.dir_x[k] + ny * rh.ray.dir_y[k] + nz * rh.ray.dir_z[k];
    const double sgn = facing > 0.0 ? -1.0 / nn : 1.0 / nn;
    return std::max(0.0, sgn * (nx * sun_[0] + ny * sun_[1] + nz * sun_[2]));
  };

  // non-flat ground outside the boxes: one ray a kGroundTile x kGroundTile
  // tile (through its middle pixel) colours the tile's pixels that no box
  // holds; a tile whose ray meets a cone takes the ground's colour under the
  // hit from the height field's own normal
  if (!flat_ground && pixels) {
    tiles_.clear();
    for (int tj = 0; tj < H; tj += kGroundTile) {
      const int j = std::min(H - 1, tj + kGroundTile / 2);
      for (int ti = 0; ti < W; ti += kGroundTile) {
        const int i = std::min(W - 1, ti + kGroundTile / 2);
        tiles_.push_back(static_cast<std::uint32_t>(j * W + i));
      }
    }
    cast(tiles_, [&](std::uint32_t p, const RTCRayHit16& rh, int k) {
      const std::int32_t cone = world.cone_of(rh.hit.geomID[k], rh.hit.primID[k]);
      if (cone == kHitNothing) return;
      double lambert = 0.0;
      const Rgb* colour = &params_.ground;
      if (cone == kHitStructure) {
        colour = &albedo(params_, LidarMaterial::Barrier);
        lambert = lambert_of(rh, k);
      } else if (cone == kHitGround) {
        lambert = lambert_of(rh, k);
      } else {
        const double t = rh.ray.tfar[k];
        const double x = o[0] + t * rh.ray.dir_x[k], y = o[1] + t * rh.ray.dir_y[k];
        const double e = 0.05;  // m, central differences of the height field
        const double gx = (world.ground_z(x + e, y) - world.ground_z(x - e, y)) / (2.0 * e);
        const double gy = (world.ground_z(x, y + e) - world.ground_z(x, y - e)) / (2.0 * e);
        lambert = std::max(0.0, (-gx * sun_[0] - gy * sun_[1] + sun_[2]) / std::sqrt(gx * gx + gy * gy + 1.0));
      }
      const std::array<std::uint8_t, 3> rgb = shade(*colour, lambert);
      const int i = static_cast<int>(p % static_cast<std::uint32_t>(W));
      const int j = static_cast<int>(p / static_cast<std::uint32_t>(W));
      const int i0 = i - kGroundTile / 2, j0 = j - kGroundTile / 2;
      for (int jj = std::max(0, j0); jj < std::min(H, j0 + kGroundTile); ++jj) {
        for (int ii = std::max(0, i0); ii < std::min(W, i0 + kGroundTile); ++ii) {
          const std::size_t q = static_cast<std::size_t>(jj) * static_cast<std::size_t>(W) + static_cast<std::size_t>(ii);
          if (stamp_[q] == frame_) continue;
          std::copy(rgb.begin(), rgb.end(), out.rgb.begin() + 3 * static_cast<std::ptrdiff_t>(q));
        }
      }
    });
  }

  // the boxes' pixels, each its own ray
  carry_.clear();
  carry_t_.clear();
  cast(cast_, [&](std::uint32_t p, const RTCRayHit16& rh, int k) {
    const std::int32_t cone = world.cone_of(rh.hit.geomID[k], rh.hit.primID[k]);
    if (cone == kHitNothing) return;
    if (cone == kHitGround && flat_ground) return;  // the analytic ground is the same
    const double t = rh.ray.tfar[k];
    if (cone == kHitStructure) {  // a barrier block: opaque, nothing behind it counts
      if (!pixels) return;
      const std::array<std::uint8_t, 3> rgb = shade(albedo(params_, LidarMaterial::Barrier), lambert_of(rh, k));
      std::copy(rgb.begin(), rgb.end(), out.rgb.begin() + 3 * static_cast<std::ptrdiff_t>(p));
      painted_.push_back(p);
      return;
    }
    if (pixels) {
      const LidarMaterial m =
          cone < 0 ? LidarMaterial::Ground
                   : world.material_of(rh.hit.geomID[k], rh.hit.primID[k], o[0] + t * rh.ray.dir_x[k],
                                       o[1] + t * rh.ray.dir_y[k], o[2] + t * rh.ray.dir_z[k]);
      const std::array<std::uint8_t, 3> rgb = shade(albedo(params_, m), lambert_of(rh, k));
      std::copy(rgb.begin(), rgb.end(), out.rgb.begin() + 3 * static_cast<std::ptrdiff_t>(p));
      painted_.push_back(p);
    }
    if (cone >= 0) {
      annotation.labels[p] = cone;
      labelled_.push_back(p);
      ++visible_[static_cast<std::size_t>(cone)];
      ++unoccluded_[static_cast<std::size_t>(cone)];
      // no other cone's box (culling: frustum): nothing behind to count
      if (cover_[p] < 2) return;
    }
    // carried on: a cone hit where boxes (culling: frustums) overlap, or
    // (non-flat) a ground hit in a box, which a hill may have put in front of
    // the cone (not when the hit lies beyond every cone whose box holds the
    // pixel)
    if (cone < 0 && t >= reach_[p]) return;
    carry_.push_back(p);
    carry_t_.push_back(static_cast<float>(t));
  });

  // rays carried on past their first hit: every cone they meet would be seen
  // there but for the occluder in front; each counts once per pixel
  for (std::size_t q = 0; q < carry_.size(); ++q) {
    const std::uint32_t p = carry_[q];
    double d[3];
    ray_dir(p, d);
    std::int32_t seen[8];
    int n_seen = 0;
    if (annotation.labels[p] >= 0) seen[n_seen++] = annotation.labels[p];
    float tnear = carry_t_[q];
    for (int it = 0; it < kMaxCarry; ++it) {
      RTCRayHit rh;
      // nothing beyond the boxes' cones matters
      set_ray(rh, o, d, tnear + static_cast<float>(kCarryStep), reach_[p]);
      rtcIntersect1(world.scene(), &context, &rh);
      ++last_continued_rays_;
      if (rh.hit.geomID == RTC_INVALID_GEOMETRY_ID) break;
      const std::int32_t cone = world.cone_of(rh.hit.geomID, rh.hit.primID);
      if (cone == kHitNothing || cone == kHitStructure) break;  // a block is opaque
      tnear = rh.ray.tfar;
      if (cone == -1) {
        if (flat_ground) break;  // below the plane from here on
        continue;
      }
      if (std::find(seen, seen + n_seen, cone) != seen + n_seen) continue;
      ++unoccluded_[static_cast<std::size_t>(cone)];
      if (n_seen < 8) seen[n_seen++] = cone;
    }
  }

  // instances, by cone index
  std::sort(boxed_.begin(), boxed_.end(),
            [this](std::int32_t a, std::int32_t b) { return cones_[static_cast<std::size_t>(a)].id < cones_[static_cast<std::size_t>(b)].id; });
  for (std::int32_t s : boxed_) {
    const ConeGeom& c = cones_[static_cast<std::size_t>(s)];
    const auto id = static_cast<std::size_t>(c.id);
    if (visible_[id] == 0) continue;
    CameraInstance inst;
    inst.id = c.id;
    double mid[3];
    inst.color = cone_class(world, c, mid);
    inst.range = std::sqrt((mid[0] - o[0]) * (mid[0] - o[0]) + (mid[1] - o[1]) * (mid[1] - o[1]) +
                           (mid[2] - o[2]) * (mid[2] - o[2]));
    inst.visible_fraction =
        std::min(1.0, static_cast<double>(visible_[id]) / static_cast<double>(std::max(unoccluded_[id], 1)));
    annotation.instances.push_back(inst);
  }

  // pixel noise: per channel a 12-bit uniform draw picks one of the 4096
  // quantiles of N(0, pixel_noise^2) (noise_ table; a GaussianStream seeded
  // from rng_ once a frame: five draws per 64-bit word)
  if (!noise_.empty()) {
    GaussianStream draws(rng_());
    if (pixels) {
      for (std::uint8_t& byte : out.rgb) {
        const int v = byte + noise_[draws.index()];
        byte = static_cast<std::uint8_t>(std::clamp(v, 0, 255));
      }
    }
  }
  // (flat ground: the tiles paint no pixel; noise touches every one)
  flat_background_ = pixels && flat_ground && noise_.empty();
  annotation.labelled.assign(labelled_.begin(), labelled_.end());
}

}  // namespace paddock::sensors
