#pragma once
// a global-shutter RGB camera on the main hoop, ray-cast with Embree 3 against
// the LiDAR's scene (LidarWorld: the same cone meshes with their stripe
// materials, the same ground), with the simulation's annotation: a per-pixel
// label (the cone index) and one instance per visible cone. The frame is what
// a camera driver gives (hal::CameraFrame); the annotation is the
// simulation's alone (CameraAnnotation) and never crosses the HAL: the
// annotation detector (annotation_detector.h) turns the two into the boxes a
// detector node on the car would post.
//
// Model (CameraParams) + a small class holding its random stream and reusable
// buffers (Camera). No I/O, no clock, no global state: render() is a pure
// function of the world, the base pose and the stream's state.
//
// Pinhole model, no distortion (the paper's camera driver undistorts before
// the detector sees a frame). Image coordinates (u, v) in px: u right, v down,
// pixel (i, j) (column i, row j, row 0 at the top) covers [i, i+1) x [j, j+1),
// its centre is (i + 0.5, j + 0.5) and its ray goes through that centre. A
// point p_cam of the optical frame (z forward, x right, y down) lands at
//   u = fx x / z + cx,  v = fy y / z + cy,
// fx = fy = (width / 2) / tan(hfov / 2), cx = width / 2, cy = height / 2; the
// optical axis meets the image at (cx, cy), the corner between the 4 middle
// pixels. calibration() gives exactly these K and T_camera_base.
//
// Mounting: the optical centre at (mount_x, mount_y, mount_z) in the base
// frame; the optical axis along base +x pitched down by mount_pitch about base
// y (no roll, no yaw offset), so each image row is all ground or all sky on
// flat ground. As the LiDAR (lidar.h), the camera keeps mount_z above the
// ground under its mounting point: it stands at world z = ground_z(mount point)
// + mount_z, and the body is not tilted by the ground.
//
// Shading: a material's colour (CameraParams: the cone stripes of lidar.h's
// cone_material, the asphalt) times ambient + (1 - ambient) max(0, n . sun),
// n the hit facet's geometric normal turned towards the camera, sun a fixed
// world direction (sun_azimuth, sun_elevation); the sky a flat colour. No
// shadows, no fog. Rounded to 8 bits, then optional Gaussian pixel noise.
//
// What is cast (the cost): cones are small, so on flat ground only pixels
// inside the projected bounding boxes of the cones (their 3D axis-aligned
// boxes' projections, clipped to the image, plus 1 px) are ray-cast; every
// other pixel is filled analytically, row by row: ground (the plane z = 0
// taken as unbounded, so rows just below the horizon show ground where the
// scene's finite ground quad, 500 m past the cones, would show sky) below the
// horizon, sky above. The flat ground's shading is one colour (normal up),
// the same the cast pixels get.
//
// A cone covers about half its box, and a far cone's box is mostly its 1 px
// margin, so on flat ground with no barrier blocks a box's pixel is cast
// only if its ray meets the cone's bounding frustum (ConeFrustum,
// bounding_frustum): a truncated circular cone about the cone's axis (world
// +z standing, +x knocked, as cone_class tells them apart) built from the
// mesh's vertices as read back: its ends the vertices' extent along the
// axis, its radii there the farthest vertex from the axis in each half, kept
// only if every vertex then lies within the radius at its height (else a
// cylinder), grown by 1 mm plus 64 float epsilons of the coordinates'
// magnitudes. It is convex and holds every vertex, so every triangle; the
// margin is far more than Embree's float arithmetic can put a hit outside
// its triangle, or the test's ray (the pixel's direction before it is
// normalised and rounded to float) can stray from the ray cast. A pixel left
// out is one whose ray would meet no cone, and on flat ground with no blocks
// such a ray finds the ground or the sky: the background's colour, no label.
// And a ray that hits a cone first is carried on (see Annotation) only if it
// meets two or more frustums, as far as the farthest of their cones: the
// cones whose frustums it misses it could not hit further on either. So the
// frame is, bit for bit, the one casting every pixel of the boxes gives
// (Camera::set_culling(false); tests/sensors/camera_test.cc compares the two
// along FSG 2023 and near knocked, big and cut-off cones). The one thing
// assumed of Embree is that a ray's hit does not depend on the other rays of
// its packet, which change (LidarCast::Exploit assumes the same). Along FSG
// 2023 (bench/camera_bench.cc) 4.3k rays a frame are cast instead of 11.2k.
//
// On a non-flat ground (a height field) every pixel of the boxes is cast
// (their rays give their ground's shading), and the rest of the image in
// 4 x 4 px tiles: one ray through a tile's middle pixel gives the colour of
// the tile's pixels outside the boxes (sky, or the ground's facet shaded; so
// the horizon and the ground's shading are 4 px coarse there, the cones and
// their surroundings exact). That costs W H / 16 more rays on a large grid:
// about 5 ms a frame at 800 x 500 (FSG 2023, 0.1 m bumps).
//
// The venue's barrier blocks are opaque and grey (the unknown cone's albedo):
// where a ray meets one first, the cones behind it are hidden. They are drawn
// only where rays are cast (in the cones' boxes, every pixel of them: no
// culling; on non-flat ground also the ground tiles'): elsewhere the image
// shows the analytic ground and sky.
//
// Annotation (CameraAnnotation). labels[p] = LidarWorld::cone_of of the first hit, -1 for ground
// and sky. One CameraInstance per cone with >= 1 labelled pixel, in ascending
// cone index: id = the cone index, color = its colour class (from the scene:
// body material, big or small mesh), range = from the optical centre to the
// middle of the cone's axis (standing: h / 2 above its position),
// visible_fraction = visible pixels / unoccluded pixels. The unoccluded count
// is exact w.r.t. the meshes: a pixel counts for a cone when its ray, carried
// on through whatever it meets first, hits that cone. Only rays that hit a
// cone first where two or more boxes overlap (with the culling: where the
// ray meets two or more frustums; and, on non-flat ground, rays that hit the
// ground inside a box nearer than a cone whose box it is: a hill can hide a
// cone) are carried on, one rtcIntersect1 per further surface, up to the
// farthest corner of those cones' boxes; on flat ground nothing behind a
// ground hit can be seen, so those stop there.
//
// The cones' geometry (boxes, colour, axis) is read back from the scene's
// Embree buffers each frame (vertex and index buffers of the cone geometry,
// grouped by LidarWorld::cone_of): the scene stays the one LidarWorld built,
// and nothing but its public interface is assumed beyond lidar.h's documented
// mesh layout (a standing cone's axis is world +z, a knocked cone's +x).
#include <array>
#include <cstdint>
#include <random>
#include <string>
#include <vector>

#include "autonomy/common/geometry.h"
#include "autonomy/common/params.h"
#include "autonomy/common/time.h"
#include "autonomy/hal/messages.h"
#include "autonomy/perception/types.h"
#include "sim/sensors/lidar.h"

namespace paddock::sensors {

// a linear RGB colour, each channel in [0, 1] (1 = 255 in the image)
struct Rgb {
  double r = 0.0, g = 0.0, b = 0.0;

  template <class V>
  void visit(V& v) {
    v(PADDOCK_PARAM(r), {"", params::fraction(), "red"});
    v(PADDOCK_PARAM(g), {"", params::fraction(), "green"});
    v(PADDOCK_PARAM(b), {"", params::fraction(), "blue"});
  }
};

struct CameraParams {
  // 800 x 500 (0.4 MP, 16:10): a frame stays cheap (1.2 MB of RGB), and with
  // the lens below a small cone (0.325 m) is still 8.7 px tall at 15 m, where
  // the fusion stops trusting the detector (fusion.h).
  int width = 800;
  int height = 500;
  // a wide lens: fx = fy = (width / 2) / tan(hfov / 2) = 400 px at 90 deg;
  // the vertical field of view follows (64 deg at 800 x 500)
  double hfov = 90.0 * kPi / 180.0;
  // mounting (chosen): on top of the main hoop as in the paper. The hoop of a
  // 1.53 m wheelbase car stands a little ahead of mid-wheelbase: 0.95 m ahead
  // of the rear axle; 1.20 m above the ground (a hoop top about 1.15 m plus
  // the camera housing). Pitched 5 deg down: the horizon sits 35 px above the
  // image centre, the ground shows from 1.6 m ahead of the camera, and a cone
  // at 20 m (3.4 deg below the horizontal) is still well inside the image.
  double mount_x = 0.95;
  double mount_y = 0.0;
  double mount_z = 1.20;
  double mount_pitch = 5.0 * kPi / 180.0;
  // the LiDAR triggers the camera once a rotation (trigger_time)
  double trigger_azimuth = 0.0;
  // lighting: a sun 50 deg high from the south-west of the map frame, and
  // 35 % ambient so faces turned away from it keep their colour
  double sun_azimuth = -2.4;
  double sun_elevation = 50.0 * kPi / 180.0;
  double ambient = 0.35;
  // materials' colours (albedo; the sky's is its colour as seen)
  Rgb sky{0.55, 0.72, 0.92};
  Rgb ground{0.32, 0.32, 0.34};
  Rgb blue{0.05, 0.22, 0.80};
  Rgb yellow{0.98, 0.82, 0.05};
  Rgb orange{0.98, 0.42, 0.05};
  Rgb white{0.95, 0.95, 0.95};
  Rgb black{0.06, 0.06, 0.06};
  Rgb grey{0.50, 0.50, 0.50};
  // per channel, drawn from the table of 4096 quantiles of gaussian_table.h
  // (so cut at 3.67 sigma), rounded to whole levels; 0 = off (the default:
  // the annotation detector does not look at the pixels, and noise costs
  // about 2 ms a frame at 800 x 500)
  double pixel_noise = 0.0;

  template <class V>
  void visit(V& v) {
    v(PADDOCK_PARAM(width), {"px", params::in(16, 8192), "image width"});
    v(PADDOCK_PARAM(height), {"px", params::in(16, 8192), "image height"});
    v(PADDOCK_PARAM(hfov), {"rad", params::in(10.0 * kPi / 180.0, 170.0 * kPi / 180.0), "horizontal field of view"});
    v(PADDOCK_PARAM(mount_x), {"m", params::in(-10.0, 10.0), "optical centre ahead of the rear axle"});
    v(PADDOCK_PARAM(mount_y), {"m", params::in(-5.0, 5.0), "optical centre left of the centre"});
    v(PADDOCK_PARAM(mount_z), {"m", params::in(0.01, 5.0), "optical centre above the ground"});
    v(PADDOCK_PARAM(mount_pitch), {"rad", params::in(-1.5, 1.5), "pitch, > 0 nose down"});
    v(PADDOCK_PARAM(trigger_azimuth), {"rad", params::in(-kPi, kPi), "the LiDAR azimuth (lidar frame, 0 ahead) whose column's firing triggers the exposure"});
    v(PADDOCK_PARAM(sun_azimuth), {"rad", params::in(-kPi, kPi), "sun direction from map +x, counter-clockwise"});
    v(PADDOCK_PARAM(sun_elevation), {"rad", params::in(0.0, kPi / 2), "sun height"});
    v(PADDOCK_PARAM(ambient), {"", params::fraction(), "ambient light share"});
    v.section(PADDOCK_PARAM(sky), "the sky's colour");
    v.section(PADDOCK_PARAM(ground), "the asphalt's albedo");
    v.section(PADDOCK_PARAM(blue), "a blue cone body's albedo");
    v.section(PADDOCK_PARAM(yellow), "a yellow cone body's albedo");
    v.section(PADDOCK_PARAM(orange), "an orange cone body's albedo");
    v.section(PADDOCK_PARAM(white), "a white stripe's albedo");
    v.section(PADDOCK_PARAM(black), "a black stripe's albedo");
    v.section(PADDOCK_PARAM(grey), "the albedo of a cone of unknown colour");
    v(PADDOCK_PARAM(pixel_noise), {"", params::in(0.0, 64.0), "Gaussian pixel noise std in 8-bit levels (0: off)"});
  }
};

// the simulation's annotation of one cone seen by the camera (a labelled data
// set's box label); a hardware camera gives none
struct CameraInstance {
  std::int32_t id = -1;                  // the value of its pixels in CameraAnnotation::labels
  ConeColor color = ConeColor::Unknown;  // its class
  double range = 0.0;                    // m, from the camera's optical centre to the cone
  double visible_fraction = 1.0;         // -, visible pixels / pixels it would cover unoccluded
};

// the simulation's annotation of one frame: per pixel (row-major, as the
// frame's rgb) the id of the cone instance it shows, -1 for none; and the instances
struct CameraAnnotation {
  std::vector<std::int32_t> labels;
  std::vector<CameraInstance> instances;
  // when listed: the pixels whose label is >= 0, each once, in no set order
  // (the camera lists what it labelled, so a reader need not scan the
  // frame's mostly empty labels); not listed: read the labels
  bool listed = false;
  std::vector<std::uint32_t> labelled;
};

// one rendered frame: what the camera gives, and what only the simulation knows of it
struct AnnotatedFrame {
  hal::CameraFrame frame;
  CameraAnnotation annotation;
};

// the LiDAR column nearest to azimuth (rad, lidar frame): column c looks at
// -pi + 2 pi c / columns (lidar.h), so c = round((azimuth + pi) columns / 2 pi)
// mod columns; a clockwise head's at pi - 2 pi c / columns, so
// c = round((pi - azimuth) columns / 2 pi) mod columns
int trigger_column(const LidarParams& lidar, double azimuth);
// when a LiDAR rotation starting at scan_start fires that column (as
// Lidar::column_time: scan_start + period c / columns, period = 1 / rate in
// integer ns): the camera's exposure time for that rotation
TimeNs trigger_time(const LidarParams& lidar, double azimuth, TimeNs scan_start);

// the pinhole intrinsics and T_camera_base of a camera with these parameters
// (what Camera::calibration() returns)
perception::CameraCalibration camera_calibration(const CameraParams& p);

// a solid truncated circular cone (frustum) about a world axis, the bound
// Camera::render tests a pixel's ray against before casting it: the points
// whose coordinate along `axis` (0 = world x, 2 = world z) lies in
// [centre[axis], centre[axis] + length] and whose distance from the axis line
// through centre is at most r0 + (r1 - r0) a / length, a the coordinate less
// centre[axis] (r0 at the base end, r1 at the other)
struct ConeFrustum {
  int axis = 2;
  double centre[3] = {0.0, 0.0, 0.0};  // m, the base end's centre
  double length = 0.0;                 // m, > 0
  double r0 = 0.0, r1 = 0.0;           // m, >= 0
};

// whether the ray o + t d, t >= 0, meets f (a point of it lies in f); d need
// not be a unit vector. Exact but for double rounding (far below a micron
// at a camera's ranges); true when f.length is not > 0
bool ray_meets_frustum(const ConeFrustum& f, const double o[3], const double d[3]);

// a frustum about world axis `axis` (0 or 2) holding every vertex of the
// triangles prim0 .. prim1 - 1 of an Embree triangle mesh (v: its vertex
// buffer, 3 floats a vertex; idx: its index buffer, 3 a triangle), hence the
// triangles, grown by `margin` (m) so it also holds every point within
// `margin` of them. The vertices taken are those numbered from the
// triangles' least index to their greatest (theirs, and any between). Its
// axis passes through the middle of their box across `axis`; its ends are
// the box's along it; r0 and r1 are the largest distances from the axis of
// the vertices in the base and the top half, kept only if then every vertex
// lies within r0 + (r1 - r0) a / length (else a cylinder: r0 = r1 = the
// largest distance). False, and f untouched, when a vertex is not finite or
// there is no triangle.
bool bounding_frustum(const float* v, const unsigned* idx, unsigned prim0, unsigned prim1, int axis, double margin,
                      ConeFrustum& f);

class Camera {
 public:
  // throws std::invalid_argument when params::validate(params) fails. The seed starts
  // this sensor's own random stream (std::mt19937_64; drawn from only when
  // pixel_noise > 0).
  Camera(const CameraParams& params, std::uint64_t seed);

  // one frame of the scene seen from base_pose (the base frame in the map
  // frame at the exposure), stamped `stamp`, and its annotation. A non-finite
  // pose gives a black frame with no labelled pixel and no instance.
  AnnotatedFrame render(const LidarWorld& world, const Pose2& base_pose, TimeNs stamp);
  // the same into `out` and `annotation`, reusing their buffers (no
  // allocation once sized). When annotation.labels is the buffer of this
  // camera's last call, unchanged since, only the pixels it labelled then
  // are reset; when out.rgb is, and that frame was flat ground's without
  // noise, only the pixels its rays drew are (anything else must not write
  // into either).
  // pixels = false: the annotation alone, for a detector node that reads
  // nothing else (AnnotationDetector): the same labels and instances, out's
  // stamp and size, and out.rgb sized but left as it was (no background, no
  // shading, no ground tiles on non-flat ground, no noise added; the random
  // stream moves on as it would); the next call with pixels paints them all
  void render(const LidarWorld& world, const Pose2& base_pose, TimeNs stamp, hal::CameraFrame& out,
              CameraAnnotation& annotation, bool pixels = true);

  const CameraParams& params() const { return params_; }
  // K and T_camera_base, exactly those render() uses
  perception::CameraCalibration calibration() const { return calibration_; }

  // the last frame's work: rays cast (first hits) and rays carried on past
  // an occluder (for the bench and the tests)
  std::size_t last_primary_rays() const { return last_primary_rays_; }
  std::size_t last_continued_rays() const { return last_continued_rays_; }

  // for the tests and the benches: whether render() skips, where it provably
  // changes nothing, the rays of the boxes' pixels that miss every cone's
  // bounding frustum (see the top; on by default). Off, every pixel of a box
  // is cast, as before the culling: the frames must be the same bit for bit
  void set_culling(bool on) { culling_ = on; }
  bool culling() const { return culling_; }

 private:
  // one cone of the scene, read back from its Embree buffers
  struct ConeGeom {
    std::int32_t id = -1;                        // cone index
    unsigned prim = 0;                           // its first triangle
    unsigned prim_end = 0;                       // one past its last
    bool split = false;                          // its triangles are not contiguous
    float lo[3] = {0, 0, 0}, hi[3] = {0, 0, 0};  // world AABB
  };
  void read_cones(const LidarWorld& world);
  // whether c stands (its axis world +z) or lies knocked (+x), from its box
  static bool is_standing(const ConeGeom& c);
  ConeColor cone_class(const LidarWorld& world, const ConeGeom& c, double mid[3]) const;
  std::array<std::uint8_t, 3> shade(const Rgb& albedo, double lambert) const;

  CameraParams params_;
  perception::CameraCalibration calibration_;
  std::mt19937_64 rng_;
  // per column / row: the pixel centre's normalised image coordinate
  std::vector<double> ax_, by_;
  // sun direction (world), analytic ground colour (flat), sky colour
  double sun_[3] = {0, 0, 1};
  std::array<std::uint8_t, 3> sky_rgb_{}, ground_rgb_{};
  std::vector<std::uint8_t> sky_row_, ground_row_;  // a row of each, RGB
  std::vector<std::int16_t> noise_;    // pixel noise quantiles (empty: no noise)
  // buffers reused between frames
  std::vector<ConeGeom> cones_;        // cones of the scene
  std::uint64_t cones_world_ = 0;      // read from the world of this serial (0: none yet)
  unsigned cone_geom_id_ = RTC_INVALID_GEOMETRY_ID;
  const float* cone_v_ = nullptr;      // its vertex and index buffers (this frame)
  const unsigned* cone_idx_ = nullptr;
  bool culling_ = true;
  std::vector<std::int32_t> geom_of_;  // cone index -> cones_ slot (-1: none)
  std::vector<std::uint32_t> stamp_;   // per pixel: frame_ when cast this frame (in a box)
  std::vector<std::uint8_t> cover_;    // per pixel: cones that may cover it (saturating)
  std::vector<float> reach_;           // per pixel: farthest box corner of those cones (m)
  std::vector<std::uint32_t> cast_;    // pixels to cast
  std::vector<std::uint32_t> tiles_;   // non-flat ground: the tiles' middle pixels
  std::vector<std::uint32_t> carry_;   // pixels whose ray is carried on
  std::vector<float> carry_t_;         // and the distance of their first hit
  std::vector<std::int32_t> visible_, unoccluded_;  // per cone index
  std::vector<std::int32_t> boxed_;    // cones with a box in the image this frame
  std::uint32_t frame_ = 0;
  const std::int32_t* labels_buffer_ = nullptr;  // the labels buffer of the last frame
  std::vector<std::uint32_t> labelled_;          // and its pixels >= 0
  const std::uint8_t* rgb_buffer_ = nullptr;     // the image buffer of the last frame
  bool flat_background_ = false;                 // it was the flat background with painted_ drawn on
  std::vector<std::uint32_t> painted_;           // the pixels cast rays drew last frame
  std::size_t last_primary_rays_ = 0, last_continued_rays_ = 0;
};

}  // namespace paddock::sensors
