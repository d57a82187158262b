#include "sim/sensors/lidar.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "sim/sensors/embree_ray.h"
#include "sim/sensors/gaussian_table.h"

namespace paddock::sensors {

namespace {

const char* error_name(RTCError e) {
  switch (e) {
    case RTC_ERROR_NONE: return "none";
    case RTC_ERROR_UNKNOWN: return "unknown";
    case RTC_ERROR_INVALID_ARGUMENT: return "invalid argument";
    case RTC_ERROR_INVALID_OPERATION: return "invalid operation";
    case RTC_ERROR_OUT_OF_MEMORY: return "out of memory";
    case RTC_ERROR_UNSUPPORTED_CPU: return "unsupported CPU";
    case RTC_ERROR_CANCELLED: return "cancelled";
  }
  return "?";
}

void check(RTCDevice device, const char* what) {
  const RTCError e = rtcGetDeviceError(device);
  if (e != RTC_ERROR_NONE) {
    throw LidarError(std::string("LidarWorld: Embree error in ") + what + ": " + error_name(e));
  }
}

constexpr int kConeVertices = 2 * kConeSegments + 1;  // base ring, top ring, top centre
constexpr int kConeTriangles = 3 * kConeSegments;     // lateral quads (2 each), top fan


}  // namespace

LidarMaterial cone_material(ConeColor color, double f) {
  const auto in = [f](double lo, double hi) { return f >= lo && f < hi; };
  switch (color) {
    case ConeColor::Blue:
      return in(kSmallStripeLo, kSmallStripeHi) ? LidarMaterial::White : LidarMaterial::Blue;
    case ConeColor::Yellow:
      return in(kSmallStripeLo, kSmallStripeHi) ? LidarMaterial::Black : LidarMaterial::Yellow;
    case ConeColor::SmallOrange:
      return in(kSmallStripeLo, kSmallStripeHi) ? LidarMaterial::White : LidarMaterial::Orange;
    case ConeColor::BigOrange:
      return in(kBigStripe1Lo, kBigStripe1Hi) || in(kBigStripe2Lo, kBigStripe2Hi)
                 ? LidarMaterial::White
                 : LidarMaterial::Orange;
    case ConeColor::Unknown: return LidarMaterial::Grey;
  }
  return LidarMaterial::Grey;
}

double reflectivity(const LidarParams& p, LidarMaterial m) {
  switch (m) {
    case LidarMaterial::White: return p.reflect_white;
    case LidarMaterial::Yellow: return p.reflect_yellow;
    case LidarMaterial::Orange: return p.reflect_orange;
    case LidarMaterial::Blue: return p.reflect_blue;
    case LidarMaterial::Black: return p.reflect_black;
    case LidarMaterial::Grey: return p.reflect_grey;
    case LidarMaterial::Ground: return p.reflect_ground;
  }
  return 0.0;
}

bool flat(const GroundParams& g) {
  return g.slope_x == 0.0 && g.slope_y == 0.0 && g.bump_height == 0.0;
}

double ground_height(const GroundParams& g, double x, double y) {
  double z = g.slope_x * x + g.slope_y * y;
  if (g.bump_height != 0.0) {
    const double k = 2.0 * kPi / g.bump_wavelength;
    z += g.bump_height * std::sin(k * x) * std::sin(k * y);
  }
  return z;
}

GroundShape ground_shape(const GroundParams& g, double x, double y) {
  GroundShape d{g.slope_x, g.slope_y, 0.0, 0.0, 0.0};
  if (g.bump_height != 0.0) {
    // A sin(kx) sin(ky)
    const double k = 2.0 * kPi / g.bump_wavelength;
    const double sx = std::sin(k * x), cx = std::cos(k * x), sy = std::sin(k * y), cy = std::cos(k * y);
    const double a = g.bump_height;
    d.dx += a * k * cx * sy;
    d.dy += a * k * sx * cy;
    d.dxx = -a * k * k * sx * sy;
    d.dyy = d.dxx;
    d.dxy = a * k * k * cx * cy;
  }
  return d;
}

// ---------------------------------------------------------------- LidarWorld

LidarWorld::LidarWorld(const std::vector<Cone>& cones, const std::vector<bool>& knocked,
                       const GroundParams& ground)
    : ground_(ground) {
  if (!knocked.empty() && knocked.size() != cones.size()) {
    throw std::invalid_argument("LidarWorld: knocked must be empty or of the size of cones");
  }
  params::require_valid(ground_, "LidarWorld: GroundParams");
  // one worker thread: many simulations may run side by side in one process
  device_ = rtcNewDevice("threads=1");
  if (device_ == nullptr) {
    throw LidarError(std::string("LidarWorld: rtcNewDevice failed: ") +
                     error_name(rtcGetDeviceError(nullptr)));
  }
  try {
    scene_ = rtcNewScene(device_);
    check(device_, "rtcNewScene");
    rtcSetSceneBuildQuality(scene_, RTC_BUILD_QUALITY_HIGH);

    // the cones' bounding box, for the ground quad
    double lo_x = 0.0, lo_y = 0.0, hi_x = 0.0, hi_y = 0.0;
    bool any = false;
    for (std::size_t i = 0; i < cones.size(); ++i) {
      const Vec2 p = cones[i].position;
      if (!finite(p.x) || !finite(p.y)) continue;
      if (!any) {
        lo_x = hi_x = p.x;
        lo_y = hi_y = p.y;
        any = true;
      }
      lo_x = std::min(lo_x, p.x);
      hi_x = std::max(hi_x, p.x);
      lo_y = std::min(lo_y, p.y);
      hi_y = std::max(hi_y, p.y);
      cone_of_mesh_.push_back(static_cast<std::int32_t>(i));
    }
    cone_count_ = cones.size();

    // ground: two triangles at z = 0 when flat, else a height-field grid
    if (flat(ground_)) {
      RTCGeometry g = rtcNewGeometry(device_, RTC_GEOMETRY_TYPE_TRIANGLE);
      check(device_, "rtcNewGeometry(ground)");
      auto* v = static_cast<float*>(rtcSetNewGeometryBuffer(
          g, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3, 3 * sizeof(float), 4));
      auto* idx = static_cast<unsigned*>(rtcSetNewGeometryBuffer(
          g, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3, 3 * sizeof(unsigned), 2));
      check(device_, "rtcSetNewGeometryBuffer(ground)");
      const double m = kGroundMargin;
      const float x0 = static_cast<float>(lo_x - m), x1 = static_cast<float>(hi_x + m);
      const float y0 = static_cast<float>(lo_y - m), y1 = static_cast<float>(hi_y + m);
      const float quad[12] = {x0, y0, 0.0f, x1, y0, 0.0f, x1, y1, 0.0f, x0, y1, 0.0f};
      std::copy(quad, quad + 12, v);
      const unsigned tris[6] = {0, 1, 2, 0, 2, 3};
      std::copy(tris, tris + 6, idx);
      rtcCommitGeometry(g);
      ground_geom_ = rtcAttachGeometry(scene_, g);
      rtcReleaseGeometry(g);
      check(device_, "ground geometry");
      ground_triangles_ = 2;
    } else {
      const double m = kGridMargin;
      const double x0 = lo_x - m, y0 = lo_y - m;
      const double wx = hi_x - lo_x + 2.0 * m, wy = hi_y - lo_y + 2.0 * m;
      // the cell: at least ground.cell, and large enough for kMaxGridCells
      double cell = std::max(ground_.cell, std::sqrt(wx * wy / kMaxGridCells));
      auto nx = static_cast<std::size_t>(std::ceil(wx / cell));
      auto ny = static_cast<std::size_t>(std::ceil(wy / cell));
      while (static_cast<double>(nx) * static_cast<double>(ny) > kMaxGridCells) {
        cell *= 1.01;
        nx = static_cast<std::size_t>(std::ceil(wx / cell));
        ny = static_cast<std::size_t>(std::ceil(wy / cell));
      }
      nx = std::max<std::size_t>(nx, 1);
      ny = std::max<std::size_t>(ny, 1);
      ground_cell_ = cell;
      ground_triangles_ = 2 * nx * ny;
      RTCGeometry g = rtcNewGeometry(device_, RTC_GEOMETRY_TYPE_TRIANGLE);
      check(device_, "rtcNewGeometry(ground)");
      auto* v = static_cast<float*>(rtcSetNewGeometryBuffer(
          g, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3, 3 * sizeof(float),
          (nx + 1) * (ny + 1)));
      auto* idx = static_cast<unsigned*>(rtcSetNewGeometryBuffer(
          g, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3, 3 * sizeof(unsigned),
          ground_triangles_));
      check(device_, "rtcSetNewGeometryBuffer(ground)");
      for (std::size_t j = 0; j <= ny; ++j) {
        const double y = y0 + cell * static_cast<double>(j);
        for (std::size_t i = 0; i <= nx; ++i) {
          const double x = x0 + cell * static_cast<double>(i);
          float* p = v + 3 * (j * (nx + 1) + i);
          p[0] = static_cast<float>(x);
          p[1] = static_cast<float>(y);
          p[2] = static_cast<float>(ground_height(ground_, x, y));
        }
      }
      for (std::size_t j = 0; j < ny; ++j) {
        for (std::size_t i = 0; i < nx; ++i) {
          const auto a = static_cast<unsigned>(j * (nx + 1) + i);
          const auto b = a + 1;
          const auto d = static_cast<unsigned>((j + 1) * (nx + 1) + i);
          const auto c = d + 1;
          unsigned* q = idx + 6 * (j * nx + i);
          q[0] = a; q[1] = b; q[2] = c;
          q[3] = a; q[4] = c; q[5] = d;
        }
      }
      rtcCommitGeometry(g);
      ground_geom_ = rtcAttachGeometry(scene_, g);
      rtcReleaseGeometry(g);
      check(device_, "ground geometry");
    }

    // cones: one triangle mesh, kConeTriangles per cone, in cone_of_mesh_ order
    if (!cone_of_mesh_.empty()) {
      const std::size_t n = cone_of_mesh_.size();
      RTCGeometry g = rtcNewGeometry(device_, RTC_GEOMETRY_TYPE_TRIANGLE);
      check(device_, "rtcNewGeometry(cones)");
      auto* v = static_cast<float*>(rtcSetNewGeometryBuffer(
          g, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3, 3 * sizeof(float),
          n * kConeVertices));
      auto* idx = static_cast<unsigned*>(rtcSetNewGeometryBuffer(
          g, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3, 3 * sizeof(unsigned),
          n * kConeTriangles));
      check(device_, "rtcSetNewGeometryBuffer(cones)");
      for (std::size_t k = 0; k < n; ++k) {
        const Cone& c = cones[static_cast<std::size_t>(cone_of_mesh_[k])];
        const bool big = c.color == ConeColor::BigOrange;
        const double r0 = 0.5 * (big ? kBigConeBaseWidth : kSmallConeBaseWidth);
        const double h = big ? kBigConeHeight : kSmallConeHeight;
        const bool down = !knocked.empty() && knocked[static_cast<std::size_t>(cone_of_mesh_[k])];
        // the cone's local frame (x, y across, z along the axis from the base
        // centre) to the world: standing, a translation; knocked, first a
        // 90 deg rotation about y, (lx, ly, lz) -> (lz, ly, -lx), then the base
        // centre to (px - h/2, py, r0)
        const double gz = ground_height(ground_, c.position.x, c.position.y);
        const double ox = down ? c.position.x - 0.5 * h : c.position.x;
        const double oz = gz + (down ? r0 : 0.0);
        const auto put = [&](float* out, double lx, double ly, double lz) {
          out[0] = static_cast<float>(ox + (down ? lz : lx));
          out[1] = static_cast<float>(c.position.y + ly);
          out[2] = static_cast<float>(oz + (down ? -lx : lz));
        };
        mesh_info_.push_back({c.color, h, ox, c.position.y, oz, down ? 1.0 : 0.0, 0.0,
                              down ? 0.0 : 1.0});
        float* vk = v + 3 * kConeVertices * k;
        for (int s = 0; s < kConeSegments; ++s) {
          const double a = 2.0 * kPi * s / kConeSegments;
          const double ca = std::cos(a), sa = std::sin(a);
          put(vk + 3 * s, r0 * ca, r0 * sa, 0.0);
          put(vk + 3 * (kConeSegments + s), kConeApexRadius * ca, kConeApexRadius * sa, h);
        }
        put(vk + 3 * (2 * kConeSegments), 0.0, 0.0, h);
        const auto base = static_cast<unsigned>(kConeVertices * k);
        unsigned* ik = idx + 3 * kConeTriangles * k;
        const auto segs = static_cast<unsigned>(kConeSegments);
        for (unsigned s = 0; s < segs; ++s) {
          const unsigned s1 = (s + 1) % segs;
          const unsigned b0 = base + s, b1 = base + s1;
          const unsigned t0 = base + segs + s, t1 = base + segs + s1;
          const unsigned ctr = base + 2 * segs;
          unsigned* q = ik + 9 * s;
          q[0] = b0; q[1] = b1; q[2] = t1;   // lateral, lower
          q[3] = b0; q[4] = t1; q[5] = t0;   // lateral, upper
          q[6] = t0; q[7] = t1; q[8] = ctr;  // top fan
        }
      }
      rtcCommitGeometry(g);
      cone_geom_ = rtcAttachGeometry(scene_, g);
      rtcReleaseGeometry(g);
      check(device_, "cone geometry");
    }

    rtcCommitScene(scene_);
    check(device_, "rtcCommitScene");
  } catch (...) {
    if (scene_ != nullptr) rtcReleaseScene(scene_);
    rtcReleaseDevice(device_);
    throw;
  }
}

LidarWorld::~LidarWorld() {
  if (scene_ != nullptr) rtcReleaseScene(scene_);
  if (device_ != nullptr) rtcReleaseDevice(device_);
}

std::int32_t LidarWorld::cone_of(unsigned geom_id, unsigned prim_id) const {
  if (geom_id == RTC_INVALID_GEOMETRY_ID) return -2;
  if (geom_id == ground_geom_) return -1;
  if (geom_id == cone_geom_) {
    const std::size_t k = prim_id / static_cast<unsigned>(kConeTriangles);
    if (k < cone_of_mesh_.size()) return cone_of_mesh_[k];
  }
  return -2;
}

LidarMaterial LidarWorld::material_of(unsigned geom_id, unsigned prim_id, double x, double y,
                                      double z) const {
  if (geom_id == cone_geom_) {
    const std::size_t k = prim_id / static_cast<unsigned>(kConeTriangles);
    if (k < mesh_info_.size()) {
      const MeshInfo& m = mesh_info_[k];
      const double along = (x - m.ox) * m.ax + (y - m.oy) * m.ay + (z - m.oz) * m.az;
      return cone_material(m.color, along / m.height);
    }
  }
  return LidarMaterial::Ground;
}

// --------------------------------------------------------------------- Lidar

Lidar::Lidar(const LidarParams& params, std::uint64_t seed) : params_(params), rng_(seed) {
  params::require_valid(params_, "LidarParams");
  const auto nch = static_cast<std::size_t>(params_.channels);
  const auto ncol = static_cast<std::size_t>(params_.columns);
  cos_el_.resize(nch);
  sin_el_.resize(nch);
  for (std::size_t i = 0; i < nch; ++i) {
    const double e = params_.elevation_min + static_cast<double>(i) * vertical_resolution();
    cos_el_[i] = std::cos(e);
    sin_el_[i] = std::sin(e);
  }
  cos_az_.resize(ncol);
  sin_az_.resize(ncol);
  for (std::size_t c = 0; c < ncol; ++c) {
    const double a = -kPi + static_cast<double>(c) * horizontal_resolution();
    cos_az_[c] = std::cos(a);
    sin_az_[c] = std::sin(a);
  }
}

double Lidar::vertical_resolution() const {
  return params_.channels > 1
             ? (params_.elevation_max - params_.elevation_min) / (params_.channels - 1)
             : 0.0;
}

double Lidar::horizontal_resolution() const { return 2.0 * kPi / params_.columns; }

TimeNs Lidar::column_time(TimeNs start, int c) const {
  return start + period_ns() * c / params_.columns;
}

std::vector<LidarPoint> Lidar::scan(const LidarWorld& world,
                                    const std::function<Pose2(TimeNs)>& base_pose_at,
                                    TimeNs start) {
  std::vector<LidarPoint> out;
  const int nch = params_.channels;
  out.reserve(static_cast<std::size_t>(nch) * static_cast<std::size_t>(params_.columns) / 2);
  const double cp = std::cos(params_.mount_pitch), sp = std::sin(params_.mount_pitch);
  const float tfar = static_cast<float>(params_.range_max + 6.0 * params_.range_noise + 0.01);
  const bool noisy = params_.range_noise > 0.0;
  const bool drops = params_.dropout > 0.0;
  const bool inoisy = params_.intensity_noise > 0.0;

  RTCIntersectContext context;
  rtcInitIntersectContext(&context);
  // the range and intensity noise's N(0, 1) draws (see the header)
  GaussianStream normal(rng_());

  for (int c = 0; c < params_.columns; ++c) {
    const TimeNs t = column_time(start, c);
    const Pose2 pose = base_pose_at(t);
    if (!finite(pose.x) || !finite(pose.y) || !finite(pose.yaw)) continue;
    const double cy = std::cos(pose.yaw), sy = std::sin(pose.yaw);
    const Vec2 origin = pose.transform({params_.mount_x, params_.mount_y});
    const double oz = world.ground_z(origin.x, origin.y) + params_.mount_z;
    const double org[3] = {origin.x, origin.y, oz};
    const auto cu = static_cast<std::size_t>(c);
    const double ca = cos_az_[cu], sa = sin_az_[cu];
    // the column's channels in packets of 16 rays (coherent: one origin, one azimuth)
    for (int ch0 = 0; ch0 < nch; ch0 += 16) {
      const int n = std::min(16, nch - ch0);
      alignas(64) int valid[16];
      alignas(64) RTCRayHit16 rh;
      double dirs[16][3];
      for (int j = 0; j < 16; ++j) {
        valid[j] = j < n ? -1 : 0;
        const auto chu = static_cast<std::size_t>(ch0 + std::min(j, n - 1));
        // direction in the sensor frame
        const double dx = cos_el_[chu] * ca, dy = cos_el_[chu] * sa, dz = sin_el_[chu];
        dirs[j][0] = dx;
        dirs[j][1] = dy;
        dirs[j][2] = dz;
        // pitch about the sensor's y, then the base's yaw
        const double px = cp * dx + sp * dz, pz = -sp * dx + cp * dz;
        const double dir[3] = {cy * px - sy * dy, sy * px + cy * dy, pz};
        set_ray(rh, j, org, dir, 0.0f, tfar);
      }
      rtcIntersect16(valid, world.scene(), &context, &rh);

      for (int j = 0; j < n; ++j) {
        if (rh.hit.geomID[j] == RTC_INVALID_GEOMETRY_ID) continue;
        const std::int32_t cone = world.cone_of(rh.hit.geomID[j], rh.hit.primID[j]);
        if (cone < -1) continue;

        if (drops && uniform_(rng_) < params_.dropout) continue;
        const double r_true = static_cast<double>(rh.ray.tfar[j]);  // |dir| = 1: tfar is the range
        double r = r_true;
        if (noisy) r += params_.range_noise * normal();
        if (r < params_.range_min || r > params_.range_max) continue;

        // intensity: material at the true hit point, incidence on the facet
        const double wx = rh.ray.org_x[j] + r_true * rh.ray.dir_x[j];
        const double wy = rh.ray.org_y[j] + r_true * rh.ray.dir_y[j];
        const double wz = rh.ray.org_z[j] + r_true * rh.ray.dir_z[j];
        const double rho = reflectivity(
            params_, world.material_of(rh.hit.geomID[j], rh.hit.primID[j], wx, wy, wz));
        const double nx = rh.hit.Ng_x[j], ny = rh.hit.Ng_y[j], nz = rh.hit.Ng_z[j];
        const double nn = std::sqrt(nx * nx + ny * ny + nz * nz);
        const double cos_inc =
            nn > 0.0 ? std::abs(nx * rh.ray.dir_x[j] + ny * rh.ray.dir_y[j] +
                                nz * rh.ray.dir_z[j]) / nn
                     : 0.0;
        const double q = params_.intensity_range_ref / std::max(r_true, 1e-9);
        double intensity = rho * cos_inc * std::min(1.0, q * q);
        if (inoisy) intensity += params_.intensity_noise * normal();
        intensity = std::clamp(intensity, 0.0, 1.0);

        LidarPoint p;
        p.x = static_cast<float>(r * dirs[j][0]);
        p.y = static_cast<float>(r * dirs[j][1]);
        p.z = static_cast<float>(r * dirs[j][2]);
        p.intensity = static_cast<float>(intensity);
        p.ring = static_cast<std::uint16_t>(ch0 + j);
        p.t = t;
        p.cone = cone;
        out.push_back(p);
      }
    }
  }
  return out;
}

}  // namespace paddock::sensors
