#pragma once
// a rotating multi-channel LiDAR, ray-cast with Embree 3 against cone meshes of
// their real size standing on the ground: a flat plane z = 0 or a height field
// (GroundParams: a slope plus sinusoidal bumps); and the venue's barrier
// blocks (world::Block, boxes of their own material), when there are any.
//
// Model (LidarParams) + the scene (LidarWorld: the Embree device and scene,
// built once from the cones) + a small class holding only its random stream
// (Lidar). No I/O, no clock, no global state: scan() is a pure function of the
// world, the pose trajectory, the start time and the stream's state.
//
// The sensor frame `lidar`: origin at the optical centre, x forward, y left,
// z up (REP-103), mounted in the base frame at (mount_x, mount_y, mount_z) with
// the yaw of the base and a pitch mount_pitch about its y axis (> 0 tilts the
// nose down). The head spins counter-clockwise seen from above, column c
// looking at azimuth -pi + 2 pi c / columns in the sensor frame, or, with
// `clockwise` (an Ouster's metadata file), at pi - 2 pi c / columns (column 0
// looks backwards, column columns/2 straight ahead, so the seam of a rotation
// lies behind the car, where its body hides the view anyway). The channels'
// elevations are the layout's (hal::ring_elevation: an even fan, or a metadata
// file's beams); ranges and intensities are reported in the sensor's units
// when the layout has them (range_resolution, intensity_full_scale).
//
// Intensity: a material model. Each hit has a material (ConeMaterial: the cone's
// stripes by height along its axis, or the asphalt ground) with a reflectivity
// rho (LidarParams), and
//   I = rho * cos(incidence) * min(1, (intensity_range_ref / r)^2) + N(0, intensity_noise)
// clamped to [0, 1]; r is the true range, the incidence is taken against the
// hit facet's geometric normal. The 1/r^2 law is the received power of an
// extended Lambertian target that fills the beam (a cone face or the ground at
// these ranges); below intensity_range_ref the receiver is taken as saturated.
//
// Noise: the range and intensity noise N(0, sigma^2) are table draws
// (gaussian_table.h: 4096 quantiles of N(0, 1), cut at 3.67 sigma, std
// within 0.02 % of 1) from a splitmix64 stream seeded once a scan from the
// sensor's own std::mt19937_64; the dropout draws come from the latter.
//
// Knocked cones lie on their side (LidarWorld's `knocked`).
//
// Ground (GroundParams): z = ground_height(g, x, y) in the world frame. Flat
// (the default) it is two triangles at z = 0; otherwise a triangle grid whose
// vertices lie on ground_height (see LidarWorld). The sensor keeps its mount_z
// above the ground under the mounting point: the rays start at world z =
// ground_height(mount point) + mount_z. The car's body is not tilted by the
// slope (no roll or pitch from the ground): the sensor frame stays level, only
// mount_pitch tilts it, and the points' z is relative to the optical centre.
#include <cstddef>
#include <cstdint>
#include <functional>
#include <random>
#include <stdexcept>
#include <string>
#include <vector>

#include <embree3/rtcore.h>

#include "autonomy/common/cone.h"
#include "autonomy/common/geometry.h"
#include "autonomy/common/time.h"
#include "autonomy/hal/lidar_layout.h"
#include "sim/world/venue.h"

namespace paddock::sensors {

// the rotating LiDAR: its layout and mounting (hal::LidarLayout, the same
// struct the stack is told as its calibration), rate, range, noise and the
// intensity model of the cones' materials
struct LidarParams : hal::LidarLayout {
  // DESIGN.md's LiDAR rate
  double rate = 10.0;
  // a 0.5 m blind zone as common FS LiDARs have; 50 m is far beyond where a
  // cone still gets more than a point or two
  double range_min = 0.5;
  double range_max = 50.0;
  // the paper quotes 2-3 cm
  double range_noise = 0.02;
  double dropout = 0.0;
  // the materials' reflectivities (diffuse, 905 nm)
  double reflect_white = 0.9;    // white stripe (retro-ish white foil / paint)
  double reflect_yellow = 0.6;   // yellow cone body
  double reflect_orange = 0.5;   // orange cone body
  double reflect_blue = 0.25;    // blue cone body
  double reflect_black = 0.05;   // black stripe
  double reflect_grey = 0.4;     // cones of unknown colour: plain grey
  double reflect_ground = 0.15;  // asphalt
  double reflect_barrier = 0.35;  // the venue's barrier blocks (grey concrete, white plastic ~0.5)
  double intensity_range_ref = 5.0;
  double intensity_noise = 0.01;

  template <class V>
  void visit(V& v) {
    hal::LidarLayout::visit(v);
    v(PADDOCK_PARAM(rate), {"Hz", params::in(0.1, 1000.0), "rotations per second"});
    v(PADDOCK_PARAM(range_min), {"m", params::in(0.0, 1000.0), "nearest return (the blind zone)"});
    v(PADDOCK_PARAM(range_max), {"m", params::in(0.1, 1000.0), "farthest return"});
    v(PADDOCK_PARAM(range_noise), {"m", params::in(0.0, 10.0), "range noise std along the ray"});
    v(PADDOCK_PARAM(dropout), {"", params::in(0.0, 0.99), "chance that a ray returns nothing"});
    v(PADDOCK_PARAM(reflect_white), {"", params::fraction(), "reflectivity of the white stripes"});
    v(PADDOCK_PARAM(reflect_yellow), {"", params::fraction(), "reflectivity of a yellow cone's body"});
    v(PADDOCK_PARAM(reflect_orange), {"", params::fraction(), "reflectivity of an orange cone's body"});
    v(PADDOCK_PARAM(reflect_blue), {"", params::fraction(), "reflectivity of a blue cone's body"});
    v(PADDOCK_PARAM(reflect_black), {"", params::fraction(), "reflectivity of the black stripes"});
    v(PADDOCK_PARAM(reflect_grey), {"", params::fraction(), "reflectivity of a cone of unknown colour"});
    v(PADDOCK_PARAM(reflect_ground), {"", params::fraction(), "reflectivity of the ground"});
    v(PADDOCK_PARAM(reflect_barrier), {"", params::fraction(), "reflectivity of the venue's barrier blocks ([venue])"});
    v(PADDOCK_PARAM(intensity_range_ref), {"m", params::above(0.0), "the intensity falls off as min(1, (ref / r)^2)"});
    v(PADDOCK_PARAM(intensity_noise), {"", params::fraction(), "intensity noise std (before clamping to [0, 1])"});
  }
  std::string check() const {
    if (const std::string why = hal::LidarLayout::check(); !why.empty()) return why;
    return range_max > range_min ? "" : "range_max must be > range_min";
  }
};

// an Embree failure (device creation, buffer allocation, scene commit)
class LidarError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// the ground's height field, world frame
struct GroundParams {
  double slope_x = 0.0, slope_y = 0.0;
  double bump_height = 0.0;
  double bump_wavelength = 10.0;
  double cell = 0.5;

  template <class V>
  void visit(V& v) {
    v(PADDOCK_PARAM(slope_x), {"", params::in(-1.0, 1.0), "dz/dx of the ground plane (map frame)"});
    v(PADDOCK_PARAM(slope_y), {"", params::in(-1.0, 1.0), "dz/dy of the ground plane (map frame)"});
    v(PADDOCK_PARAM(bump_height), {"m", params::in(0.0, 1.0), "amplitude of the sinusoidal bumps"});
    v(PADDOCK_PARAM(bump_wavelength), {"m", params::in(0.1, 1000.0), "wavelength of the bumps"});
    v(PADDOCK_PARAM(cell), {"m", params::in(0.01, 100.0), "height-field grid cell (a lower bound, see LidarWorld)"});
  }
};

// true when g is the plane z = 0 (no slope, no bumps)
bool flat(const GroundParams& g);

// z = slope_x x + slope_y y + bump_height sin(2 pi x / L) sin(2 pi y / L),
// L = bump_wavelength
double ground_height(const GroundParams& g, double x, double y);

// ground_height's first and second derivatives at (x, y), exact: what a point
// keeping its height above the ground feels vertically (z'' = grad . a +
// v^T H v for a horizontal velocity v and acceleration a)
struct GroundShape {
  double dx = 0.0, dy = 0.0;              // gradient
  double dxx = 0.0, dxy = 0.0, dyy = 0.0;  // Hessian
};
GroundShape ground_shape(const GroundParams& g, double x, double y);

// the real FS cone sizes (ORACLES.md): a cone mesh is a truncated cone of
// kConeSegments facets standing on its base, vertices on the true circles
inline constexpr double kSmallConeBaseWidth = 0.228;  // m
inline constexpr double kSmallConeHeight = 0.325;     // m
inline constexpr double kBigConeBaseWidth = 0.285;    // m
inline constexpr double kBigConeHeight = 0.505;       // m
inline constexpr double kConeApexRadius = 0.03;       // m, the flat top
inline constexpr int kConeSegments = 16;

// the stripes, as fractions of the cone's height along its axis from the base,
// after pictures of the FS cones: a small cone (325 mm) has one middle stripe
// over 40 .. 60 % of its height (z = 130 .. 195 mm, a 65 mm band); a big orange
// cone (505 mm) has two white stripes, 28 .. 42 % and 58 .. 72 % (141 .. 212 mm
// and 293 .. 364 mm). The flat top has the body's colour.
inline constexpr double kSmallStripeLo = 0.40;
inline constexpr double kSmallStripeHi = 0.60;
inline constexpr double kBigStripe1Lo = 0.28;
inline constexpr double kBigStripe1Hi = 0.42;
inline constexpr double kBigStripe2Lo = 0.58;
inline constexpr double kBigStripe2Hi = 0.72;

enum class LidarMaterial { White, Yellow, Orange, Blue, Black, Grey, Ground, Barrier };

// what LidarWorld::cone_of (and LidarPoint::cone) gives for a hit that is
// not a cone: the ground, nothing, a venue structure (a barrier block)
inline constexpr std::int32_t kHitGround = -1;
inline constexpr std::int32_t kHitNothing = -2;
inline constexpr std::int32_t kHitStructure = -3;

// the material of a cone of colour `color` at `height_fraction` (0 = base,
// 1 = top) of its height: blue with a white middle stripe, yellow with a black
// one, small orange with a white one, big orange with two white ones, unknown
// plain grey
LidarMaterial cone_material(ConeColor color, double height_fraction);

// the reflectivity p assigns to material m
double reflectivity(const LidarParams& p, LidarMaterial m);

// how Lidar::scan finds each beam's first hit. All three give the same hits
// (the same beams return, from the same cone or the ground) and ranges within
// float rounding; see Lidar::scan.
enum class LidarCast {
  // the default. Over flat ground: the beams that can meet a cone (their
  // column and ring lie in some cone's window) through the whole scene in
  // packets of 16, the others only against the ground, in closed form. Over
  // a height field (or a flat ground the closed form cannot serve, see
  // LidarWorld::ground_closed_form): as Packets.
  Exploit,
  // every beam through the whole scene, a column's channels in packets of 16
  // (the path before Exploit)
  Packets,
  // every beam through the whole scene, one rtcIntersect1 at a time: the
  // plain reference
  Single,
};

// the static scene: cones (BigOrange big, every other colour small), the
// venue's barrier blocks (world::Block: boxes standing on the ground, their
// base at the lowest ground under their footprint's corners) and the ground. Flat ground is one quad at z = 0 that extends kGroundMargin past the
// cones' bounding box. Any other ground is a grid of right-triangle pairs over
// the cones' bounding box plus kGridMargin, vertices on ground_height; its cell
// is ground.cell, enlarged (if need be) so the grid has at most kMaxGridCells
// cells (2 triangles each). Inside a triangle the grid interpolates linearly:
// for a right isosceles triangle with legs h (circumradius h / sqrt 2) the
// vertical error is at most M R^2 / 2 = M h^2 / 4, M the largest |eigenvalue|
// of ground_height's Hessian = bump_height (2 pi / L)^2 (the plane adds none):
// 2.5 mm for 0.1 m bumps, L = 10 m, h = 0.5 m. Rays that leave the grid find
// no ground.
// Owns the Embree device and scene; non-copyable, non-movable.
//
// A standing cone stands on its base centred on its position, the base (kept
// horizontal) at ground_height there. A knocked cone
// (knocked[i] true) lies on its side: its mesh is rotated 90 deg about the
// world y axis, so its axis is horizontal along the world +x axis (base at
// -x, top at +x), at the height of its base radius (0.114 m small, 0.1425 m
// big) above ground_height at its position (flat ground: the base rim touches
// the ground, the top end floats a little), the middle of its axis above its
// position. It reaches up to its base width
// (0.228 m small, 0.285 m big).
//
// Besides the scene (scene(), the camera's too) it keeps what
// LidarCast::Exploit needs: each cone mesh's bounds, and for flat ground the
// quad as Embree holds it and Embree's reciprocal on this CPU.
class LidarWorld {
 public:
  static constexpr double kGroundMargin = 500.0;     // m, flat ground
  static constexpr double kGridMargin = 60.0;        // m, height-field ground
  static constexpr double kMaxGridCells = 200000.0;  // -, height-field ground
  // throws LidarError on an Embree failure, std::invalid_argument when knocked
  // is neither empty (no cone knocked) nor of the size of cones, or when
  // params::validate(ground) fails. Cones with a non-finite position are left out (and
  // are never reported as hit).
  explicit LidarWorld(const std::vector<Cone>& cones, const std::vector<bool>& knocked = {},
                      const GroundParams& ground = {}, const std::vector<world::Block>& blocks = {});
  ~LidarWorld();
  LidarWorld(const LidarWorld&) = delete;
  LidarWorld& operator=(const LidarWorld&) = delete;

  // the whole scene: the ground, the cones and the blocks
  RTCScene scene() const { return scene_; }
  // this world's number, unique among the worlds the process built (a
  // scene rebuilt may sit at the old one's address: this tells them apart)
  std::uint64_t serial() const { return serial_; }
  std::size_t cone_count() const { return cone_count_; }
  std::size_t block_count() const { return block_count_; }
  const GroundParams& ground() const { return ground_; }
  // ground_height(ground(), x, y)
  double ground_z(double x, double y) const { return ground_height(ground_, x, y); }
  // the grid's cell actually used (0 for flat ground) and its triangle count
  double ground_cell() const { return ground_cell_; }
  std::size_t ground_triangles() const { return ground_triangles_; }
  // whether LidarCast::Exploit takes this ground in closed form: flat, and one
  // of the candidates for Embree's reciprocal reproduced Embree's own hits on
  // probe rays when the world was built (lidar.cc)
  bool ground_closed_form() const { return quad_rcp_ != nullptr; }
  // the cone index hit by (geomID, primID), kHitGround (-1) for the ground,
  // kHitStructure (-3) for a block, kHitNothing (-2) for nothing
  std::int32_t cone_of(unsigned geom_id, unsigned prim_id) const;
  // the material at the hit (geomID, primID) at world point (x, y, z): the
  // ground's, a block's, or the cone's stripe at the point's height along the
  // cone's axis. Only meaningful when cone_of(geom_id, prim_id) != kHitNothing.
  LidarMaterial material_of(unsigned geom_id, unsigned prim_id, double x, double y,
                            double z) const;

 private:
  RTCDevice device_ = nullptr;
  RTCScene scene_ = nullptr;
  std::uint64_t serial_ = 0;
  std::size_t cone_count_ = 0;
  std::size_t block_count_ = 0;
  GroundParams ground_;
  double ground_cell_ = 0.0;
  std::size_t ground_triangles_ = 0;
  unsigned ground_geom_ = RTC_INVALID_GEOMETRY_ID;
  unsigned cone_geom_ = RTC_INVALID_GEOMETRY_ID;
  unsigned block_geom_ = RTC_INVALID_GEOMETRY_ID;
  std::vector<std::int32_t> cone_of_mesh_;  // mesh k (in the cone geometry) -> cone index
  // mesh k: colour, height, the base centre and the unit axis (base -> top)
  struct MeshInfo {
    ConeColor color;
    double height;
    double ox, oy, oz;
    double ax, ay, az;
  };
  std::vector<MeshInfo> mesh_info_;
  // LidarCast::Exploit. Mesh k's bounds (the cones' meshes, then the
  // blocks'), from the float vertices Embree holds
  // (so every triangle lies inside): the box of its vertices (centre x, y, z,
  // half-extents ex, ey, ez) and the ball about the box's centre through its
  // farthest vertex (radius r)
  struct Bounds {
    double x, y, z;
    double ex, ey, ez;
    double r;
  };
  std::vector<Bounds> bounds_;
  // the bounds of the n float vertices at v (x, y, z each)
  static Bounds bounds_of(const float* v, int n);
  // flat ground: the quad's corners as Embree holds them, and the z of its
  // triangles' geometric normal Ng = cross(e2, e1) (both triangles have
  // Ng = (0, 0, (x1 - x0)(y1 - y0)) in float)
  float quad_x0_ = 0.0f, quad_x1_ = 0.0f, quad_y0_ = 0.0f, quad_y1_ = 0.0f;
  float quad_ng_ = 0.0f;
  // flat ground: Embree's reciprocal on this CPU (lidar.cc: the candidate that
  // reproduced Embree's own hits on probe rays), nullptr if none did (then
  // Exploit casts every beam through Embree)
  void (*quad_rcp_)(const float* a, float* out, std::size_t n) = nullptr;

  friend class Lidar;
};

struct LidarPoint {
  float x, y, z;        // m, sensor frame at the point's own time (x forward, y left, z up)
  float intensity;      // -, [0, 1]; the material model (see the top)
  std::uint16_t ring;   // channel, 0 = lowest elevation
  std::uint16_t column;  // the column (firing) of the rotation, 0 = the first
  std::int64_t t;       // ns, the time of the point's column
  std::int32_t cone;    // ground truth: cone index hit, kHitGround, kHitStructure
};

class Lidar {
 public:
  // throws std::invalid_argument when params::validate(params) fails. The seed starts
  // this sensor's own random stream (std::mt19937_64).
  Lidar(const LidarParams& params, std::uint64_t seed);

  // one rotation. Column c is cast at t_c = start + c * period / columns (integer
  // ns) from the base pose base_pose_at(t_c), all channels at once; the rays
  // start at the mounting point, mount_z above world.ground_z there. Returns
  // the hits whose measured range (true
  // range + N(0, range_noise)) lies in [range_min, range_max], less the
  // dropouts, column by column, rings ascending within a column, each in the
  // sensor frame at its column's time. A column whose pose is not finite gives
  // no points (an all-NaN trajectory gives an empty scan).
  //
  // `cast` picks how the beams are cast (LidarCast); every choice draws the
  // same random numbers for the same hits, so the scans agree point by point
  // within float rounding. Exploit's ground in closed form repeats Embree's
  // own float arithmetic (its Moeller-Trumbore test and reciprocal), so over
  // flat ground its scan is Packets' to the bit (tests/sensors/lidar_cast_test.cc).
  std::vector<LidarPoint> scan(const LidarWorld& world,
                               const std::function<Pose2(TimeNs)>& base_pose_at, TimeNs start,
                               LidarCast cast = LidarCast::Exploit);
  // the same scan into `out` (its contents replaced, its capacity kept: a
  // caller that scans every rotation into one buffer allocates nothing)
  void scan(const LidarWorld& world, const std::function<Pose2(TimeNs)>& base_pose_at, TimeNs start,
            std::vector<LidarPoint>& out, LidarCast cast = LidarCast::Exploit);

  const LidarParams& params() const { return params_; }
  TimeNs period_ns() const { return from_seconds(1.0 / params_.rate); }
  // the time of column c of a scan starting at `start`
  TimeNs column_time(TimeNs start, int c) const;
  // the angular resolutions: vertical (channel spacing) and horizontal
  double vertical_resolution() const;    // rad
  double horizontal_resolution() const;  // rad
  // the beams the last LidarCast::Exploit scan cast through the whole scene
  // (those in some cone's or block's window)
  std::size_t window_beams() const { return window_rays_.size(); }

 private:
  LidarParams params_;
  std::mt19937_64 rng_;
  std::uniform_real_distribution<double> uniform_{0.0, 1.0};
  // per channel: cos and sin of the elevation; per column: of the azimuth
  std::vector<double> cos_el_, sin_el_, cos_az_, sin_az_;
  double cos_pitch_ = 1.0, sin_pitch_ = 0.0;  // of mount_pitch

  // the scratch of a scan (kept to save its allocations), see lidar.cc
  struct ColumnPose {
    bool ok;        // a finite pose
    bool whole;     // cast all its beams through the whole scene
    TimeNs t;       // ns
    double cy, sy;  // cos, sin of the yaw
    double o[3];    // m, the rays' origin (world)
  };
  struct BeamHit {
    float t;         // m, Embree's tfar
    unsigned geom;   // RTC_INVALID_GEOMETRY_ID: no hit
    unsigned prim;
    float ng[3];     // the geometric normal as Embree reports it
  };
  struct WindowRay {
    int column, ring;
    BeamHit hit;
  };
  // a column's beams: directions in the world (as cast, float)
  struct ColumnBeams {
    std::vector<float> wx, wy, wz;
    // the closed-form ground: its terms, hits, ranges and intensities before
    // the noise, for the origin's z oz
    std::vector<float> den, num, rcp;
    std::vector<std::uint8_t> ground;
    std::vector<double> ground_range, ground_bright;
    float oz;
    // the returns: whether there is one, its true range, cone (-1 the
    // ground) and intensity before the noise
    std::vector<std::uint8_t> ok;
    std::vector<double> range, bright;
    std::vector<std::int32_t> cone;
    std::vector<LidarPoint> points;
  };
  std::vector<ColumnPose> poses_;
  std::vector<std::uint8_t> window_;  // per beam (column by column): 1 if it may meet a cone
  std::vector<std::uint8_t> marked_;  // per column: 1 if some beam is in window_
  std::vector<WindowRay> window_rays_;
  std::vector<int> near_;             // the cones in reach this scan
  ColumnBeams beams_;
  void beam_directions(int c, const ColumnPose& pose);
  void find_windows(const LidarWorld& world, float tfar);
  void cast_windows(const LidarWorld& world, float tfar);
};

}  // namespace paddock::sensors
