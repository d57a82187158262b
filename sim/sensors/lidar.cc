#include "sim/sensors/lidar.h"

#include <algorithm>
#include <atomic>
#include <cassert>
#include <cmath>
#include <cstring>
#include <limits>

#include <immintrin.h>

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
constexpr int kBlockVertices = 8;                      // the footprint's corners at the base, then at the top
constexpr int kBlockTriangles = 10;                    // four sides (2 each), the top

// Embree's reciprocal 1 / a as its kernels take it (common/simd/vfloat{4,8,16}_*.h,
// Embree 3.13): an estimate r refined by one Newton step r + r (1 - a r). Which
// estimate and whether the step is fused depends on the ISA Embree picks at
// run time: rcp14 and fused with AVX-512, rcp and fused with AVX2, rcp and
// unfused below. Each candidate below is one of these; LidarWorld keeps the
// one that reproduces Embree's own hits (probe_quad_rcp). n: a multiple of 4.
using RcpFn = void (*)(const float* a, float* out, std::size_t n);

__attribute__((target("avx512f,avx512vl,fma"))) void rcp_avx512(const float* a, float* out,
                                                                 std::size_t n) {
  const __m128 one = _mm_set1_ps(1.0f);
  for (std::size_t i = 0; i < n; i += 4) {
    const __m128 x = _mm_loadu_ps(a + i);
    const __m128 r = _mm_rcp14_ps(x);
    _mm_storeu_ps(out + i, _mm_fmadd_ps(r, _mm_fnmadd_ps(x, r, one), r));
  }
}

__attribute__((target("avx2,fma"))) void rcp_avx2(const float* a, float* out, std::size_t n) {
  const __m128 one = _mm_set1_ps(1.0f);
  for (std::size_t i = 0; i < n; i += 4) {
    const __m128 x = _mm_loadu_ps(a + i);
    const __m128 r = _mm_rcp_ps(x);
    _mm_storeu_ps(out + i, _mm_fmadd_ps(r, _mm_fnmadd_ps(x, r, one), r));
  }
}

void rcp_sse(const float* a, float* out, std::size_t n) {
  const __m128 one = _mm_set1_ps(1.0f);
  for (std::size_t i = 0; i < n; i += 4) {
    const __m128 x = _mm_loadu_ps(a + i);
    const __m128 r = _mm_rcp_ps(x);
    _mm_storeu_ps(out + i, _mm_add_ps(r, _mm_mul_ps(r, _mm_sub_ps(one, _mm_mul_ps(x, r)))));
  }
}

// the flat ground in closed form: Embree's Moeller-Trumbore test
// (kernels/geometry/triangle_intersector_moeller.h, Embree 3.13) of a ray
// (org, dir in float) against a quad triangle, v0 = (x0, y0, 0), whose
// geometric normal is Ng = (0, 0, ng) (LidarWorld::quad_ng_). With C = v0 -
// org, C.z = 0 - oz exactly:
//   den = dot(Ng, dir) = ng dz,   T = dot(Ng, C) ^ sign(den) = (ng C.z) ^ sign(den)
// (dot's other terms are exact zeros, fused or not, so each is one rounded
// product), and the ray hits when den != 0 and 0 = |den| tnear < T <= |den| tfar,
// at t = T rcp(|den|). The edge tests pass wherever the hit lies inside the
// quad (on the diagonal one triangle's U is the other's -V, so one passes);
// the callers keep to hits well inside. num[j] = T, den[j] = |den|; hit when
// den[j] != 0 and 0 < num[j] <= den[j] tfar.
void quad_terms(float ng, float oz, const float* dz, float* num, float* den, std::size_t n) {
  const float p = ng * (0.0f - oz);
  for (std::size_t j = 0; j < n; ++j) {
    const float d = ng * dz[j];
    den[j] = std::fabs(d);
    num[j] = std::signbit(d) ? -p : p;
  }
}

// which candidate reciprocal reproduces Embree's hits on the flat ground of
// `scene` (the quad x0 .. x1, y0 .. y1 with normal ng): 64 probe rays cast
// down onto the margin of the quad, 250 m in from its corner (500 m from the
// cones, which they cannot reach), at several heights and slopes
RcpFn probe_quad_rcp(RTCScene scene, float x0, float y0, float ng) {
  std::vector<RcpFn> candidates;
  __builtin_cpu_init();
  if (__builtin_cpu_supports("avx512f") && __builtin_cpu_supports("avx512vl") &&
      __builtin_cpu_supports("fma")) {
    candidates.push_back(rcp_avx512);
  }
  if (__builtin_cpu_supports("avx2") && __builtin_cpu_supports("fma")) {
    candidates.push_back(rcp_avx2);
  }
  candidates.push_back(rcp_sse);

  constexpr int kProbes = 64;
  const float tfar = 1000.0f;
  float oz[kProbes], dz[kProbes], t[kProbes];
  bool hit[kProbes];
  RTCIntersectContext context;
  rtcInitIntersectContext(&context);
  std::uint64_t state = 0x5eed;
  for (int p0 = 0; p0 < kProbes; p0 += 16) {
    alignas(64) int valid[16];
    alignas(64) RTCRayHit16 rh;
    for (int j = 0; j < 16; ++j) {
      const int k = p0 + j;
      // heights 0.05 .. 3 m, depressions with |dz| 0.1 .. 1 of varied mantissas
      const double u = static_cast<double>(splitmix64(state) >> 11) * 0x1.0p-53;
      const double v = static_cast<double>(splitmix64(state) >> 11) * 0x1.0p-53;
      const double el = 0.1 + 1.4 * u, az = 6.283185307179586 * v;
      const double org[3] = {static_cast<double>(x0) + 250.0, static_cast<double>(y0) + 250.0,
                             0.05 + 2.95 * static_cast<double>(k) / kProbes};
      const double dir[3] = {std::cos(el) * std::cos(az), std::cos(el) * std::sin(az),
                             -std::sin(el)};
      valid[j] = -1;
      set_ray(rh, j, org, dir, 0.0f, tfar);
      oz[k] = rh.ray.org_z[j];
      dz[k] = rh.ray.dir_z[j];
    }
    rtcIntersect16(valid, scene, &context, &rh);
    for (int j = 0; j < 16; ++j) {
      hit[p0 + j] = rh.hit.geomID[j] != RTC_INVALID_GEOMETRY_ID;
      t[p0 + j] = rh.ray.tfar[j];
    }
  }
  for (const RcpFn f : candidates) {
    bool same = true;
    for (int k = 0; k < kProbes && same; ++k) {
      alignas(16) float num[4], den[4], r[4];
      quad_terms(ng, oz[k], &dz[k], num, den, 1);
      den[1] = den[2] = den[3] = 1.0f;
      f(den, r, 4);
      const bool h = den[0] != 0.0f && 0.0f < num[0] && num[0] <= den[0] * tfar;
      const float tk = num[0] * r[0];
      same = h == hit[k] && (!h || std::memcmp(&tk, &t[k], sizeof tk) == 0);
    }
    if (same) return f;
  }
  return nullptr;
}

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
    case LidarMaterial::Barrier: return p.reflect_barrier;
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
                       const GroundParams& ground, const std::vector<world::Block>& blocks)
    : ground_(ground) {
  static std::atomic<std::uint64_t> built{0};
  serial_ = ++built;
  if (!knocked.empty() && knocked.size() != cones.size()) {
    throw std::invalid_argument("LidarWorld: knocked must be empty or of the size of cones");
  }
  params::require_valid(ground_, "LidarWorld: GroundParams");
  // one worker thread: many simulations may run side by side in one process.
  // Embree picks its kernels by the CPU, and they round differently (the
  // default run's log differs between SSE/AVX, AVX2 and AVX-512 machines):
  // capped at AVX2, every machine with AVX2 and FMA gives the same result
  device_ = rtcNewDevice("threads=1,max_isa=avx2");
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
    // the blocks with a finite footprint grow the box too
    std::vector<const world::Block*> solid;
    for (const world::Block& b : blocks) {
      if (!finite(b.centre) || !finite(b.yaw) || !(b.length > 0.0) || !(b.width > 0.0) || !(b.height > 0.0)) continue;
      solid.push_back(&b);
      for (const Vec2 q : world::block_corners(b)) {
        if (!any) {
          lo_x = hi_x = q.x;
          lo_y = hi_y = q.y;
          any = true;
        }
        lo_x = std::min(lo_x, q.x);
        hi_x = std::max(hi_x, q.x);
        lo_y = std::min(lo_y, q.y);
        hi_y = std::max(hi_y, q.y);
      }
    }
    block_count_ = solid.size();

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
      quad_x0_ = x0;
      quad_x1_ = x1;
      quad_y0_ = y0;
      quad_y1_ = y1;
      // Embree's Ng = cross(e2, e1) of triangle (0, 1, 2), e1 = v0 - v1 = (x0 - x1, 0, 0),
      // e2 = v2 - v0 = (x1 - x0, y1 - y0, 0): z = e2.x e1.y - e2.y e1.x = (y1 - y0)(x1 - x0)
      // (e2.x e1.y is an exact 0, fused or not); triangle (0, 2, 3) gives the same
      const float ax = x1 - x0, ay = y1 - y0;
      quad_ng_ = ay * ax;
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
        // its bounds, from the float vertices
        bounds_.push_back(bounds_of(vk, kConeVertices));
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

    // blocks: one triangle mesh, kBlockTriangles per block (its four sides
    // and its top; the base stands on the ground), in `solid` order
    if (!solid.empty()) {
      const std::size_t n = solid.size();
      RTCGeometry g = rtcNewGeometry(device_, RTC_GEOMETRY_TYPE_TRIANGLE);
      check(device_, "rtcNewGeometry(blocks)");
      auto* v = static_cast<float*>(rtcSetNewGeometryBuffer(
          g, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3, 3 * sizeof(float), n * kBlockVertices));
      auto* idx = static_cast<unsigned*>(rtcSetNewGeometryBuffer(
          g, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3, 3 * sizeof(unsigned), n * kBlockTriangles));
      check(device_, "rtcSetNewGeometryBuffer(blocks)");
      for (std::size_t k = 0; k < n; ++k) {
        const world::Block& blk = *solid[k];
        const std::vector<Vec2> corners = world::block_corners(blk);
        // the base at the lowest ground under the corners (on a slope the
        // block's uphill foot sinks into the ground: it stands level)
        double z0 = std::numeric_limits<double>::infinity(), z1 = -z0;
        for (const Vec2 q : corners) {
          z0 = std::min(z0, ground_height(ground_, q.x, q.y));
          z1 = std::max(z1, ground_height(ground_, q.x, q.y));
        }
        const double top = z1 + blk.height;
        float* vk = v + 3 * kBlockVertices * k;
        for (int q = 0; q < 4; ++q) {
          const Vec2 c = corners[static_cast<std::size_t>(q)];
          float* lo = vk + 3 * q;
          float* hi = vk + 3 * (4 + q);
          lo[0] = hi[0] = static_cast<float>(c.x);
          lo[1] = hi[1] = static_cast<float>(c.y);
          lo[2] = static_cast<float>(z0);
          hi[2] = static_cast<float>(top);
        }
        bounds_.push_back(bounds_of(vk, kBlockVertices));
        const auto base = static_cast<unsigned>(kBlockVertices * k);
        unsigned* ik = idx + 3 * kBlockTriangles * k;
        for (unsigned s = 0; s < 4; ++s) {
          const unsigned s1 = (s + 1) % 4;
          unsigned* q = ik + 6 * s;
          q[0] = base + s; q[1] = base + s1; q[2] = base + 4 + s1;  // side, lower
          q[3] = base + s; q[4] = base + 4 + s1; q[5] = base + 4 + s;  // side, upper
        }
        unsigned* t = ik + 24;
        t[0] = base + 4; t[1] = base + 5; t[2] = base + 6;  // top
        t[3] = base + 4; t[4] = base + 6; t[5] = base + 7;
      }
      rtcCommitGeometry(g);
      block_geom_ = rtcAttachGeometry(scene_, g);
      rtcReleaseGeometry(g);
      check(device_, "block geometry");
    }

    rtcCommitScene(scene_);
    check(device_, "rtcCommitScene");
    if (flat(ground_)) quad_rcp_ = probe_quad_rcp(scene_, quad_x0_, quad_y0_, quad_ng_);
  } catch (...) {
    if (scene_ != nullptr) rtcReleaseScene(scene_);
    rtcReleaseDevice(device_);
    throw;
  }
}

LidarWorld::Bounds LidarWorld::bounds_of(const float* v, int n) {
  double lo[3] = {v[0], v[1], v[2]}, hi[3] = {v[0], v[1], v[2]};
  for (int q = 1; q < n; ++q) {
    for (int a = 0; a < 3; ++a) {
      lo[a] = std::min(lo[a], static_cast<double>(v[3 * q + a]));
      hi[a] = std::max(hi[a], static_cast<double>(v[3 * q + a]));
    }
  }
  Bounds b{0.5 * (lo[0] + hi[0]), 0.5 * (lo[1] + hi[1]), 0.5 * (lo[2] + hi[2]),
           0.5 * (hi[0] - lo[0]), 0.5 * (hi[1] - lo[1]), 0.5 * (hi[2] - lo[2]), 0.0};
  for (int q = 0; q < n; ++q) {
    const double dx = v[3 * q] - b.x, dy = v[3 * q + 1] - b.y, dz = v[3 * q + 2] - b.z;
    b.r = std::max(b.r, std::sqrt(dx * dx + dy * dy + dz * dz));
  }
  return b;
}

LidarWorld::~LidarWorld() {
  if (scene_ != nullptr) rtcReleaseScene(scene_);
  if (device_ != nullptr) rtcReleaseDevice(device_);
}

std::int32_t LidarWorld::cone_of(unsigned geom_id, unsigned prim_id) const {
  if (geom_id == RTC_INVALID_GEOMETRY_ID) return kHitNothing;
  if (geom_id == ground_geom_) return kHitGround;
  if (geom_id == cone_geom_) {
    const std::size_t k = prim_id / static_cast<unsigned>(kConeTriangles);
    if (k < cone_of_mesh_.size()) return cone_of_mesh_[k];
  }
  if (geom_id == block_geom_) return kHitStructure;
  return kHitNothing;
}

LidarMaterial LidarWorld::material_of(unsigned geom_id, unsigned prim_id, double x, double y,
                                      double z) const {
  if (geom_id == block_geom_) return LidarMaterial::Barrier;
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
  cos_pitch_ = std::cos(params_.mount_pitch);
  sin_pitch_ = std::sin(params_.mount_pitch);
  const auto nch = static_cast<std::size_t>(params_.channels);
  const auto ncol = static_cast<std::size_t>(params_.columns);
  // every channel of a column is cast in one vertical half-plane from the
  // rotation axis (find_windows relies on it): no per-beam azimuth offsets,
  // no beam origin off the axis (hal::LidarLayout; a metadata file that has
  // them can be decoded but not simulated)
  for (const double a : params_.beam_azimuth) {
    if (a != 0.0) throw std::invalid_argument("LidarParams: the simulated LiDAR casts every channel of a column at its azimuth: beam_azimuth must be 0");
  }
  if (params_.beam_origin != 0.0)
    throw std::invalid_argument("LidarParams: the simulated LiDAR casts from the rotation axis: beam_origin must be 0");
  cos_el_.resize(nch);
  sin_el_.resize(nch);
  for (std::size_t i = 0; i < nch; ++i) {
    const double e = hal::ring_elevation(params_, static_cast<int>(i));
    cos_el_[i] = std::cos(e);
    sin_el_[i] = std::sin(e);
  }
  cos_az_.resize(ncol);
  sin_az_.resize(ncol);
  for (std::size_t c = 0; c < ncol; ++c) {
    const double a = hal::column_azimuth(params_, static_cast<int>(c));
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

// --------------------------------------------------------------------- scan
//
// A scan in three steps. (1) The columns' poses and the rays' origins. (2)
// LidarCast::Exploit over flat ground: the beams that may meet a cone
// (find_windows), cast through the whole scene (cast_windows). (3) Column by
// column: each beam's return (true range, object, intensity before the
// noise): through the whole scene for Packets and Single, and for Exploit
// where the closed form does not serve; else the ground's in closed form and
// the window beams' from (2). Then the column's points with their draws, ring
// by ring, so that the draws are the same however the beams were cast.

namespace {

// a beam's direction: in the sensor frame (elevation cos ce, sin ce; azimuth
// cos ca, sin ca), and in the world as Embree gets it (float): the pitch
// (cos cp, sin cp) about the sensor's y, then the base's yaw (cos cy, sin cy)
inline void beam_dir(double ce, double se, double ca, double sa, double cp, double sp, double cy,
                     double sy, double sensor[3], float world[3]) {
  const double dx = ce * ca, dy = ce * sa, dz = se;
  sensor[0] = dx;
  sensor[1] = dy;
  sensor[2] = dz;
  const double px = cp * dx + sp * dz, pz = -sp * dx + cp * dz;
  world[0] = static_cast<float>(cy * px - sy * dy);
  world[1] = static_cast<float>(sy * px + cy * dy);
  world[2] = static_cast<float>(pz);
}

// beam_dir's world[2] alone (the yaw leaves z alone)
inline float beam_dir_z(double ce, double se, double ca, double cp, double sp) {
  const double dx = ce * ca, dz = se;
  return static_cast<float>(-sp * dx + cp * dz);
}

constexpr unsigned kNoGeom = RTC_INVALID_GEOMETRY_ID;

}  // namespace

void Lidar::beam_directions(int c, const ColumnPose& pose) {
  const auto cu = static_cast<std::size_t>(c);
  ColumnBeams& b = beams_;
  for (std::size_t j = 0; j < static_cast<std::size_t>(params_.channels); ++j) {
    double s[3];
    float w[3];
    beam_dir(cos_el_[j], sin_el_[j], cos_az_[cu], sin_az_[cu], cos_pitch_, sin_pitch_, pose.cy,
             pose.sy, s, w);
    b.wx[j] = w[0];
    b.wy[j] = w[1];
    b.wz[j] = w[2];
  }
}

namespace {

// the padding of a cone's bounds: Embree's float rays and hits stray from
// the exact ones by a few float ulps of the coordinates (the origin's, the
// range's)
double box_pad(const double o[3], double tfar) {
  return 1e-3 + 1e-6 * (std::abs(o[0]) + std::abs(o[1]) + std::abs(o[2]) + tfar);
}

// v (world) in the sensor frame of a column whose yaw has cos cy, sin sy and
// whose pitch has cos cp, sin sp: undo the yaw, then the pitch
void to_sensor(const double v[3], double cy, double sy, double cp, double sp, double s[3]) {
  const double h1 = cy * v[0] + sy * v[1], h2 = -sy * v[0] + cy * v[1];
  s[0] = cp * h1 - sp * v[2];
  s[1] = h2;
  s[2] = sp * h1 + cp * v[2];
}

}  // namespace

// The beams that may meet a cone. Column c's beams lie in the half-plane
// {u m + w z : u >= 0} of its sensor frame, m = (cos az_c, sin az_c, 0), z the
// up axis, and beam (c, e) is the ray of slope w / u = tan e in it. Where it
// meets cone k's mesh, it is inside the mesh's box (padded by box_pad): so
// the box's coordinates h (along the plane's normal n = (-sin az_c, cos
// az_c, 0)), u and w span h = 0, and the point's w / u lies between the
// smallest and largest w / u of the box's corners (the box projects along n
// to the hull of its corners' (u, w), and w / u is extreme over a convex
// polygon in u > 0 at a vertex). The rings whose tan e lies there are the
// column's window of cone k; every ring when a corner has u <= 0 (the box
// reaches over the sensor).
//
// Not every cone is tried in every column. The columns go in chunks of at
// most pi/8 of azimuth; in the chunk's first column's frame, every column's
// view of the cone's ball (radius r) lies within D + Y |s| of this one's (D:
// how far the origin moves within the chunk, Y: the chord of the yaw's
// turn), so a ball grown by that must meet the chunk's wedge of azimuths, and
// the columns tried are those within its azimuth window asin(R' / |s_xy|),
// one more each side.
void Lidar::find_windows(const LidarWorld& world, float tfar) {
  const int nch = params_.channels, ncol = params_.columns;
  const auto nchu = static_cast<std::size_t>(nch);
  window_.assign(nchu * static_cast<std::size_t>(ncol), 0);
  marked_.assign(static_cast<std::size_t>(ncol), 0);
  window_rays_.clear();
  near_.clear();
  const auto& bounds = world.bounds_;
  if (bounds.empty()) return;
  const double cp = cos_pitch_, sp = sin_pitch_;
  const double el0 = params_.elevation_min, del = vertical_resolution();
  const double daz = horizontal_resolution();
  const double spin = params_.clockwise ? -1.0 : 1.0;
  const double reach = static_cast<double>(tfar);
  const auto pose = [this](int c) -> const ColumnPose& {
    return poses_[static_cast<std::size_t>(c)];
  };
  const auto live = [&pose](int c) { return pose(c).ok && !pose(c).whole; };
  const auto dist = [](const double a[3], const double b[3]) {
    return std::sqrt((a[0] - b[0]) * (a[0] - b[0]) + (a[1] - b[1]) * (a[1] - b[1]) +
                     (a[2] - b[2]) * (a[2] - b[2]));
  };

  // the cones within reach of some column: of the first live column's origin,
  // grown by how far the origin moves in the scan
  int first = 0;
  while (first < ncol && !live(first)) ++first;
  if (first == ncol) return;
  const double* o0 = pose(first).o;
  double moved = 0.0;
  for (int c = first; c < ncol; ++c) {
    if (live(c)) moved = std::max(moved, dist(pose(c).o, o0));
  }
  for (std::size_t k = 0; k < bounds.size(); ++k) {
    const double b[3] = {bounds[k].x, bounds[k].y, bounds[k].z};
    if (dist(b, o0) <= reach + bounds[k].r + box_pad(o0, reach) + moved) {
      near_.push_back(static_cast<int>(k));
    }
  }

  // column c's window of cone k: mark its rings
  const auto mark = [&](int c, int k) {
    const ColumnPose& q = pose(c);
    const LidarWorld::Bounds& b = bounds[static_cast<std::size_t>(k)];
    const double pad = box_pad(q.o, reach);
    const double e[3] = {b.ex + pad, b.ey + pad, b.ez + pad};
    const double v[3] = {b.x - q.o[0], b.y - q.o[1], b.z - q.o[2]};
    // the column's n, m and z in the world (beam_dir's pitch and yaw)
    const auto cu = static_cast<std::size_t>(c);
    const double ca = cos_az_[cu], sa = sin_az_[cu];
    const auto world_of = [&](double x, double y, double z, double out[3]) {
      const double px = cp * x + sp * z, pz = -sp * x + cp * z;
      out[0] = q.cy * px - q.sy * y;
      out[1] = q.sy * px + q.cy * y;
      out[2] = pz;
    };
    double n[3], m[3], z[3];
    world_of(-sa, ca, 0.0, n);
    world_of(ca, sa, 0.0, m);
    world_of(0.0, 0.0, 1.0, z);
    const auto dot = [](const double a[3], const double x[3]) {
      return a[0] * x[0] + a[1] * x[1] + a[2] * x[2];
    };
    const auto spread = [&e](const double a[3]) {
      return std::abs(a[0]) * e[0] + std::abs(a[1]) * e[1] + std::abs(a[2]) * e[2];
    };
    if (std::abs(dot(n, v)) > spread(n)) return;  // the box misses the plane
    const double uc = dot(m, v), us = spread(m);
    if (uc + us < 0.0) return;  // behind the sensor
    if (std::sqrt(dot(v, v)) - std::sqrt(e[0] * e[0] + e[1] * e[1] + e[2] * e[2]) > reach) return;
    int lo = 0, hi = nch - 1;
    if (uc - us > 0.0) {
      // the corners' slopes w / u
      const double wc = dot(z, v);
      double lo_t = std::numeric_limits<double>::infinity(), hi_t = -lo_t;
      for (int corner = 0; corner < 8; ++corner) {
        double u = uc, w = wc;
        for (int a = 0; a < 3; ++a) {
          const double sgn = (corner >> a) & 1 ? e[a] : -e[a];
          u += m[a] * sgn;
          w += z[a] * sgn;
        }
        lo_t = std::min(lo_t, w / u);
        hi_t = std::max(hi_t, w / u);
      }
      const double elo = std::atan(lo_t), ehi = std::atan(hi_t);
      if (nch == 1) {
        if (el0 < elo || el0 > ehi) return;
      } else if (!params_.beam_elevation.empty()) {
        // a metadata file's elevations: the rings within [elo, ehi], a
        // little wider
        const std::vector<double>& el = params_.beam_elevation;
        const double tol = 1e-9 * std::max(1.0, std::abs(el.back() - el.front()));
        lo = static_cast<int>(std::lower_bound(el.begin(), el.end(), elo - tol) - el.begin());
        hi = static_cast<int>(std::upper_bound(el.begin(), el.end(), ehi + tol) - el.begin()) - 1;
      } else {
        const double flo = std::clamp((elo - el0) / del, -2.0, nch + 1.0);
        const double fhi = std::clamp((ehi - el0) / del, -2.0, nch + 1.0);
        lo = std::max(lo, static_cast<int>(std::ceil(flo - 1e-9)));
        hi = std::min(hi, static_cast<int>(std::floor(fhi + 1e-9)));
      }
    }
    if (lo > hi) return;
    std::uint8_t* win = window_.data() + cu * nchu;
    for (int j = lo; j <= hi; ++j) win[j] = 1;
    marked_[cu] = 1;
  };

  // chunks of columns
  const int chunk = std::clamp(static_cast<int>(kPi / 8.0 / daz), 1, ncol);
  for (int c0 = 0; c0 < ncol; c0 += chunk) {
    const int c1 = std::min(ncol, c0 + chunk);
    int ref = c0;
    while (ref < c1 && !live(ref)) ++ref;
    if (ref == c1) continue;
    const ColumnPose& qr = pose(ref);
    double D = 0.0, Y = 0.0;
    for (int c = ref; c < c1; ++c) {
      if (!live(c)) continue;
      D = std::max(D, dist(pose(c).o, qr.o));
      // |R(yaw_c) - R(yaw_ref)| = 2 |sin((yaw_c - yaw_ref) / 2)|, the chord
      Y = std::max(Y, std::hypot(pose(c).cy - qr.cy, pose(c).sy - qr.sy));
    }
    // the wedge's edges' normals: n_a . x >= 0 and n_b . x <= 0 inside (a
    // clockwise head sweeps the chunk from its last column's azimuth to its
    // first's, counter-clockwise)
    auto ua = static_cast<std::size_t>(c0), ub = static_cast<std::size_t>(c1 - 1);
    if (params_.clockwise) std::swap(ua, ub);
    const double na[2] = {-sin_az_[ua], cos_az_[ua]}, nb[2] = {-sin_az_[ub], cos_az_[ub]};
    for (const int k : near_) {
      const LidarWorld::Bounds& b = bounds[static_cast<std::size_t>(k)];
      const double v[3] = {b.x - qr.o[0], b.y - qr.o[1], b.z - qr.o[2]};
      const double d = std::sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
      const double R = b.r + box_pad(qr.o, reach) + 1e-6 + D + Y * d;
      if (d - R > reach) continue;
      double s[3];
      to_sensor(v, qr.cy, qr.sy, cp, sp, s);
      if (na[0] * s[0] + na[1] * s[1] < -R || nb[0] * s[0] + nb[1] * s[1] > R) continue;
      // the columns of the ball's azimuth window, in column units [a0, a1]
      const double rho = std::hypot(s[0], s[1]);
      if (rho <= R || 2.0 * std::asin(R / rho) >= kPi / 2.0) {
        for (int c = c0; c < c1; ++c) {
          if (live(c)) mark(c, k);
        }
        continue;
      }
      // column c looks at -pi + c daz, or (clockwise) pi - c daz: the mirror
      // image, so a clockwise head finds its columns at the mirrored azimuth
      const double phi = spin * std::atan2(s[1], s[0]), beta = std::asin(R / rho);
      const double a0 = (phi - beta + kPi) / daz - 1.0, a1 = (phi + beta + kPi) / daz + 1.0;
      // (a1 - a0 < ncol / 4: the window meets the chunk once, maybe a turn away)
      for (const double turn : {-1.0, 0.0, 1.0}) {
        const double lo = std::max(static_cast<double>(c0), std::ceil(a0 + turn * ncol));
        const double hi = std::min(static_cast<double>(c1 - 1), std::floor(a1 + turn * ncol));
        for (int c = static_cast<int>(lo); c <= static_cast<int>(hi); ++c) {
          if (live(c)) mark(c, k);
        }
      }
    }
  }

  // the marked beams, column by column
  for (int c = 0; c < ncol; ++c) {
    if (marked_[static_cast<std::size_t>(c)] == 0) continue;
    const std::uint8_t* win = window_.data() + static_cast<std::size_t>(c) * nchu;
    for (int j = 0; j < nch; ++j) {
      if (win[j] != 0) window_rays_.push_back({c, j, {0.0f, kNoGeom, 0u, {0.0f, 0.0f, 0.0f}}});
    }
  }
}

// the window beams' hits through the whole scene, in packets of 16 in their
// order (column by column, rings ascending)
void Lidar::cast_windows(const LidarWorld& world, float tfar) {
  // a packet's beams are neighbours aimed at one cone: telling Embree they
  // are coherent takes a third off its time here (the hits stay the same)
  RTCIntersectContext context;
  rtcInitIntersectContext(&context);
  context.flags = RTC_INTERSECT_CONTEXT_FLAG_COHERENT;
  for (std::size_t i0 = 0; i0 < window_rays_.size(); i0 += 16) {
    const std::size_t n = std::min<std::size_t>(16, window_rays_.size() - i0);
    alignas(64) int valid[16];
    alignas(64) RTCRayHit16 rh;
    for (std::size_t j = 0; j < 16; ++j) {
      const WindowRay& w = window_rays_[i0 + std::min(j, n - 1)];
      const ColumnPose& q = poses_[static_cast<std::size_t>(w.column)];
      const auto cu = static_cast<std::size_t>(w.column), ju = static_cast<std::size_t>(w.ring);
      double sensor[3];
      float wd[3];
      beam_dir(cos_el_[ju], sin_el_[ju], cos_az_[cu], sin_az_[cu], cos_pitch_, sin_pitch_, q.cy,
               q.sy, sensor, wd);
      const double dir[3] = {wd[0], wd[1], wd[2]};
      valid[j] = j < n ? -1 : 0;
      set_ray(rh, static_cast<int>(j), q.o, dir, 0.0f, tfar);
    }
    rtcIntersect16(valid, world.scene(), &context, &rh);
    for (std::size_t j = 0; j < n; ++j) {
      window_rays_[i0 + j].hit = {rh.ray.tfar[j], rh.hit.geomID[j], rh.hit.primID[j],
                                  {rh.hit.Ng_x[j], rh.hit.Ng_y[j], rh.hit.Ng_z[j]}};
    }
  }
}

std::vector<LidarPoint> Lidar::scan(const LidarWorld& world,
                                    const std::function<Pose2(TimeNs)>& base_pose_at,
                                    TimeNs start, LidarCast cast) {
  std::vector<LidarPoint> out;
  scan(world, base_pose_at, start, out, cast);
  return out;
}

void Lidar::scan(const LidarWorld& world, const std::function<Pose2(TimeNs)>& base_pose_at, TimeNs start,
                 std::vector<LidarPoint>& out, LidarCast cast) {
  out.clear();
  const int nch = params_.channels, ncol = params_.columns;
  const auto nchu = static_cast<std::size_t>(nch);
  const float tfar = static_cast<float>(params_.range_max + 6.0 * params_.range_noise + 0.01);
  const bool noisy = params_.range_noise > 0.0;
  const bool drops = params_.dropout > 0.0;
  const bool inoisy = params_.intensity_noise > 0.0;
  const bool quantised = params_.range_resolution > 0.0 || params_.intensity_full_scale > 0.0;
  const double range_noise = params_.range_noise, intensity_noise = params_.intensity_noise;
  const double range_min = params_.range_min, range_max = params_.range_max;
  const double cp = cos_pitch_, sp = sin_pitch_;

  RTCIntersectContext context;
  rtcInitIntersectContext(&context);
  // the range and intensity noise's N(0, 1) draws (see the header), taken
  // from a buffer the stream fills in blocks
  GaussianStream normal(rng_());
  constexpr std::size_t kDraws = 320;
  double draws[kDraws];
  std::size_t next_draw = kDraws;
  const auto draw = [&]() {
    if (next_draw == kDraws) {
      normal.fill(draws, kDraws);
      next_draw = 0;
    }
    return draws[next_draw++];
  };

  // (1) the columns' poses and the rays' origins. Exploit takes flat ground
  // in closed form when a candidate reciprocal matched Embree's (LidarWorld),
  // except for a column whose ground hits could come within 1 m of the
  // quad's edge (they lie within tfar of the origin): that one, and every
  // column over a height field, goes through the whole scene.
  const bool closed = cast == LidarCast::Exploit && world.ground_closed_form();
  poses_.resize(static_cast<std::size_t>(ncol));
  for (int c = 0; c < ncol; ++c) {
    ColumnPose& q = poses_[static_cast<std::size_t>(c)];
    q.t = column_time(start, c);
    const Pose2 pose = base_pose_at(q.t);
    q.ok = finite(pose.x) && finite(pose.y) && finite(pose.yaw);
    if (!q.ok) continue;
    q.cy = std::cos(pose.yaw);
    q.sy = std::sin(pose.yaw);
    // pose.transform({mount_x, mount_y}) with these cos and sin
    q.o[0] = pose.x + (q.cy * params_.mount_x - q.sy * params_.mount_y);
    q.o[1] = pose.y + (q.sy * params_.mount_x + q.cy * params_.mount_y);
    q.o[2] = world.ground_z(q.o[0], q.o[1]) + params_.mount_z;
    const double m = static_cast<double>(tfar) + 1.0;
    q.whole = !closed || !(q.o[0] - m > world.quad_x0_ && q.o[0] + m < world.quad_x1_ &&
                           q.o[1] - m > world.quad_y0_ && q.o[1] + m < world.quad_y1_);
  }

  // (2) the beams that may meet a cone, and their hits
  window_rays_.clear();
  if (closed) {
    find_windows(world, tfar);
    cast_windows(world, tfar);
  }

  // (3) column by column: each beam's return, then the points
  ColumnBeams& b = beams_;
  const std::size_t padded = (nchu + 15) / 16 * 16;
  b.wx.assign(padded, 0.0f);
  b.wy.assign(padded, 0.0f);
  b.wz.assign(padded, 0.0f);
  b.den.assign(padded, 1.0f);
  b.num.assign(padded, 0.0f);
  b.rcp.resize(padded);
  b.ground.assign(padded, 0);
  b.ground_range.resize(padded);
  b.ground_bright.resize(padded);
  b.oz = std::numeric_limits<float>::quiet_NaN();  // no column's yet
  b.ok.assign(padded, 0);
  b.range.resize(padded);
  b.bright.resize(padded);
  b.cone.resize(padded);
  b.points.resize(padded);
  out.reserve(nchu * static_cast<std::size_t>(ncol) / 2 + nchu * 64);
  const double rho_ground = reflectivity(params_, LidarMaterial::Ground);

  // the intensity before its noise, from reflectivity rho, incidence cos_inc
  // and true range r_true (the header's model)
  const double ref = params_.intensity_range_ref;
  const auto lambert = [ref](double rho, double cos_inc, double r_true) {
    const double qr = ref / std::max(r_true, 1e-9);
    return rho * cos_inc * std::min(1.0, qr * qr);
  };
  // beam j of column c's return from its hit as Embree reports it: the
  // material at the true hit point, the incidence on the hit facet
  const auto resolve = [&](int c, std::size_t j, const float org[3], const BeamHit& h) {
    b.ok[j] = 0;
    if (h.geom == kNoGeom) return;
    const std::int32_t cone = world.cone_of(h.geom, h.prim);
    if (cone == kHitNothing) return;
    const auto cu = static_cast<std::size_t>(c);
    const ColumnPose& q = poses_[cu];
    double sensor[3];
    float dir[3];
    beam_dir(cos_el_[j], sin_el_[j], cos_az_[cu], sin_az_[cu], cp, sp, q.cy, q.sy, sensor, dir);
    const double r_true = static_cast<double>(h.t);  // |dir| = 1: tfar is the range
    const double dx = dir[0], dy = dir[1], dz = dir[2];
    const double rho =
        cone == kHitGround ? rho_ground
                           : reflectivity(params_, world.material_of(h.geom, h.prim, org[0] + r_true * dx,
                                                           org[1] + r_true * dy,
                                                           org[2] + r_true * dz));
    const double nx = h.ng[0], ny = h.ng[1], nz = h.ng[2];
    const double nn = std::sqrt(nx * nx + ny * ny + nz * nz);
    const double cos_inc = nn > 0.0 ? std::abs(nx * dx + ny * dy + nz * dz) / nn : 0.0;
    b.ok[j] = 1;
    b.range[j] = r_true;
    b.cone[j] = cone;
    b.bright[j] = lambert(rho, cos_inc, r_true);
  };

  std::size_t next_window = 0;  // window_rays_ are in column, ring order
  for (int c = 0; c < ncol; ++c) {
    const ColumnPose& q = poses_[static_cast<std::size_t>(c)];
    if (!q.ok) continue;
    const auto cu = static_cast<std::size_t>(c);
    const float org[3] = {static_cast<float>(q.o[0]), static_cast<float>(q.o[1]),
                          static_cast<float>(q.o[2])};

    // the returns
    if (cast == LidarCast::Single) {
      beam_directions(c, q);
      for (std::size_t j = 0; j < nchu; ++j) {
        RTCRayHit rh;
        const double dir[3] = {b.wx[j], b.wy[j], b.wz[j]};
        set_ray(rh, q.o, dir, 0.0f, tfar);
        rtcIntersect1(world.scene(), &context, &rh);
        const BeamHit h{rh.ray.tfar, rh.hit.geomID, rh.hit.primID,
                        {rh.hit.Ng_x, rh.hit.Ng_y, rh.hit.Ng_z}};
        resolve(c, j, org, h);
      }
    } else if (q.whole) {
      // the channels in packets of 16 (coherent: one origin, one azimuth)
      beam_directions(c, q);
      for (int ch0 = 0; ch0 < nch; ch0 += 16) {
        const int n = std::min(16, nch - ch0);
        alignas(64) int valid[16];
        alignas(64) RTCRayHit16 rh;
        for (int j = 0; j < 16; ++j) {
          const auto ju = static_cast<std::size_t>(ch0 + std::min(j, n - 1));
          const double dir[3] = {b.wx[ju], b.wy[ju], b.wz[ju]};
          valid[j] = j < n ? -1 : 0;
          set_ray(rh, j, q.o, dir, 0.0f, tfar);
        }
        rtcIntersect16(valid, world.scene(), &context, &rh);
        for (int j = 0; j < n; ++j) {
          resolve(c, static_cast<std::size_t>(ch0 + j), org,
                  {rh.ray.tfar[j], rh.hit.geomID[j], rh.hit.primID[j],
                   {rh.hit.Ng_x[j], rh.hit.Ng_y[j], rh.hit.Ng_z[j]}});
        }
      }
    } else {
      // the ground in closed form (quad_terms): only the directions' z matter
      // there, and the incidence on Ng = (0, 0, ng) is resolve's
      // |ng dz| / |ng| = |dz| exactly (ng dz and ng^2 are exact in double).
      // So the ground's returns depend on the origin's z and the directions'
      // z alone: a column that repeats the last one's (a level sensor at a
      // steady height) repeats its returns.
      bool same = std::memcmp(&org[2], &b.oz, sizeof b.oz) == 0;
      if (sp != 0.0 || !same) {
        // (with no pitch the z are every column's: -0 dx only adds a zero to dz)
        for (std::size_t j = 0; j < nchu; ++j) {
          const float wz = beam_dir_z(cos_el_[j], sin_el_[j], cos_az_[cu], cp, sp);
          same = same && std::memcmp(&wz, &b.wz[j], sizeof wz) == 0;
          b.wz[j] = wz;
        }
      }
      if (!same) {
        b.oz = org[2];
        quad_terms(world.quad_ng_, org[2], b.wz.data(), b.num.data(), b.den.data(), nchu);
        world.quad_rcp_(b.den.data(), b.rcp.data(), padded);
        for (std::size_t j = 0; j < nchu; ++j) {
          const float num = b.num[j], den = b.den[j];
          b.ground[j] = den != 0.0f && 0.0f < num && num <= den * tfar;
          b.ground_range[j] = static_cast<double>(num * b.rcp[j]);
          b.ground_bright[j] =
              lambert(rho_ground, std::abs(static_cast<double>(b.wz[j])), b.ground_range[j]);
        }
      }
      std::copy(b.ground.begin(), b.ground.begin() + padded, b.ok.begin());
      std::copy(b.ground_range.begin(), b.ground_range.begin() + padded, b.range.begin());
      std::copy(b.ground_bright.begin(), b.ground_bright.begin() + padded, b.bright.begin());
      std::fill(b.cone.begin(), b.cone.end(), -1);
      // the window beams' returns (cast_windows)
      const std::uint8_t* win = window_.data() + cu * nchu;
      if (marked_[cu] != 0) {
        for (std::size_t j = 0; j < nchu; ++j) {
          if (win[j] == 0) continue;
          const WindowRay& w = window_rays_[next_window++];
          assert(w.column == c && static_cast<std::size_t>(w.ring) == j);
          resolve(c, j, org, w.hit);
        }
      }
    }

    // the points, ring by ring: dropout, range noise, intensity noise;
    // written in place into the column's scratch (a point built aside and
    // copied in stalls on the store forwarding of its narrow fields), then
    // appended
    LidarPoint* dst = b.points.data();
    const double ca = cos_az_[cu], sa = sin_az_[cu];
    for (std::size_t j = 0; j < nchu; ++j) {
      if (b.ok[j] == 0) continue;
      if (drops && uniform_(rng_) < params_.dropout) continue;
      double r = b.range[j];
      if (noisy) r += range_noise * draw();
      // as the sensor reports it (its range unit, hal::reported_range)
      if (quantised) r = hal::reported_range(params_, r);
      if (r < range_min || r > range_max) continue;
      double intensity = b.bright[j];
      if (inoisy) intensity += intensity_noise * draw();
      // clamped to [0, 1] (std::clamp's result, without its branches)
      intensity = std::min(std::max(intensity, 0.0), 1.0);
      if (quantised) intensity = hal::reported_intensity(params_, intensity);
      // the direction in the sensor frame as beam_dir's
      const double ce = cos_el_[j];
      dst->x = static_cast<float>(r * (ce * ca));
      dst->y = static_cast<float>(r * (ce * sa));
      dst->z = static_cast<float>(r * sin_el_[j]);
      dst->intensity = static_cast<float>(intensity);
      dst->ring = static_cast<std::uint16_t>(j);
      dst->column = static_cast<std::uint16_t>(c);
      dst->t = q.t;
      dst->cone = b.cone[j];
      ++dst;
    }
    out.insert(out.end(), b.points.data(), dst);
  }
}

}  // namespace paddock::sensors
