// The pinhole and thin-lens camera of core/camera.h: framing (centre ray,
// field of view at the corners, film axes), pinhole origins, and the thin
// lens (rays meet on the plane in focus, leave from the aperture disk, fill
// it uniformly, and reduce to the pinhole with aperture 0).
//
// Expected values come from an independent double-precision model: the
// camera basis forward = normalize(look_at - position), right =
// normalize(forward x up), up' = right x forward, and the film point (x, y)
// in pixels on the image plane at distance 1 along forward at
//   ((2x/w - 1) * aspect * tan(fov_y/2), (1 - 2y/h) * tan(fov_y/2)).
// The CameraPlantedBugs suite runs the same checks on cameras with
// deliberately planted bugs (wrappers around the real one) and expects them
// to fail: it shows each check has the power to catch the bug it is there for.
#include "core/camera.h"

#include "core/sampling.h"
#include "tests/stat_util.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <functional>
#include <numbers>
#include <random>
#include <sstream>
#include <vector>

namespace pathlab {
namespace {

// --- statistics (for the one statistical test: the lens is filled uniformly) -

using test::chi2_critical;
using test::chi2_equal;

constexpr double kAlpha = 1e-3;

// --- cameras under test --------------------------------------------------------

struct Shot {
  CameraDesc desc;
  int width, height;
};

CameraDesc make_desc(vec3 position, vec3 look_at, vec3 up, float fov_y, float aperture = 0.0f,
                     float focus = 5.0f) {
  CameraDesc d;
  d.position = position;
  d.look_at = look_at;
  d.up = up;
  d.fov_y_degrees = fov_y;
  d.aperture_radius = aperture;
  d.focus_distance = focus;
  return d;
}

// Looking down -z from +z: right is +x, up is +y.
const Shot kLandscape{make_desc({0, 0, 5}, {0, 0, 0}, {0, 1, 0}, 40.0f), 640, 480};
// Off-axis, with an `up` neither unit length nor perpendicular to the view.
const Shot kTilted{make_desc({1, 2, 3}, {-2, 0.5f, -4}, {0.3f, 2, 0.1f}, 65.0f), 640, 480};
// Portrait, wide angle, z up.
const Shot kPortrait{make_desc({-3, 1, 0}, {2, -1, 1}, {0, 0, 1}, 90.0f), 300, 600};
const Shot kFramings[] = {kLandscape, kTilted, kPortrait};

Shot with_lens(Shot s, float aperture, float focus) {
  s.desc.aperture_radius = aperture;
  s.desc.focus_distance = focus;
  return s;
}
// Thin-lens versions: focus nearer and farther than look_at.
const Shot kLenses[] = {with_lens(kLandscape, 0.25f, 3.7f), with_lens(kTilted, 0.5f, 12.0f),
                         with_lens(kPortrait, 0.1f, 2.0f)};

using RayFn = std::function<Ray(vec2 film, vec2 u_lens)>;

RayFn real_camera(const Shot& s) {
  return [camera = Camera(s.desc, s.width, s.height)](vec2 film, vec2 u_lens) {
    return camera.generate_ray(film, u_lens);
  };
}

// --- the independent model ---------------------------------------------------------

struct Model {
  dvec3 position, forward, right, up;
  double tan_half, aspect;
  int width, height;

  explicit Model(const Shot& s)
      : position(s.desc.position),
        forward(glm::normalize(dvec3(s.desc.look_at) - dvec3(s.desc.position))),
        right(glm::normalize(glm::cross(forward, dvec3(s.desc.up)))),
        up(glm::cross(right, forward)),
        tan_half(std::tan(s.desc.fov_y_degrees * std::numbers::pi / 360.0)),
        aspect(double(s.width) / s.height),
        width(s.width),
        height(s.height) {}

  // The film point on the image plane at distance 1, in (right, up) units.
  glm::dvec2 plane(vec2 film) const {
    return {(2.0 * film.x / width - 1.0) * aspect * tan_half, (1.0 - 2.0 * film.y / height) * tan_half};
  }
  dvec3 pinhole_dir(vec2 film) const {
    const glm::dvec2 p = plane(film);
    return glm::normalize(forward + p.x * right + p.y * up);
  }
  // A world direction in the camera frame (right, up, forward).
  dvec3 local(const vec3& d) const {
    const dvec3 v(d);
    return {glm::dot(v, right), glm::dot(v, up), glm::dot(v, forward)};
  }
};

std::string str(const vec3& v) {
  std::ostringstream s;
  s << "(" << v.x << ", " << v.y << ", " << v.z << ")";
  return s.str();
}

// Float rounding in building a direction (a sum, a normalisation) perturbs
// it by a few 2^-24 units; 2e-6 bounds that with margin, while a framing bug
// moves rays by a sizeable fraction of the field of view.
constexpr double kDirTolerance = 2e-6;

// --- framing ---------------------------------------------------------------------

testing::AssertionResult centre_ray_points_at_look_at(const Shot& s, const RayFn& ray) {
  const Model m(s);
  const Ray r = ray(vec2(0.5f * s.width, 0.5f * s.height), vec2(0.5f));
  const double err = glm::length(dvec3(r.dir) - m.forward);
  if (!(err <= kDirTolerance))
    return testing::AssertionFailure() << "centre ray " << str(r.dir) << " is " << err << " from look_at - position";
  return testing::AssertionSuccess();
}

// Through each corner the ray makes the vertical half-angle fov_y / 2 with the
// view axis and the horizontal half-angle atan(aspect * tan(fov_y / 2)), on
// the side of the corner: (0, 0), the top left, looks up and to the left.
testing::AssertionResult corner_rays_make_half_angles(const Shot& s, const RayFn& ray) {
  const Model m(s);
  const double vertical = 0.5 * s.desc.fov_y_degrees * std::numbers::pi / 180.0;
  const double horizontal = std::atan(m.aspect * m.tan_half);
  const float w = static_cast<float>(s.width), h = static_cast<float>(s.height);
  const struct {
    vec2 film;
    double sign_x, sign_y;
  } corners[] = {{{0, 0}, -1, 1}, {{w, 0}, 1, 1}, {{0, h}, -1, -1}, {{w, h}, 1, -1}};
  for (const auto& c : corners) {
    const dvec3 l = m.local(ray(c.film, vec2(0.5f)).dir);
    const double ay = std::atan2(l.y, l.z), ax = std::atan2(l.x, l.z);
    if (!(std::abs(ay - c.sign_y * vertical) <= kDirTolerance && std::abs(ax - c.sign_x * horizontal) <= kDirTolerance))
      return testing::AssertionFailure() << "corner (" << c.film.x << ", " << c.film.y << "): angles (horizontal "
                                         << ax << ", vertical " << ay << "), expected (" << c.sign_x * horizontal
                                         << ", " << c.sign_y * vertical << ")";
  }
  return testing::AssertionSuccess();
}

// Down a column, the ray's vertical tangent falls linearly from +tan(fov/2)
// at y = 0 (the top row looks up) to -tan(fov/2) at y = height.
testing::AssertionResult film_y_grows_downward(const Shot& s, const RayFn& ray) {
  const Model m(s);
  for (int k = 0; k <= 16; ++k) {
    const vec2 film(0.3f * s.width, s.height * (k / 16.0f));
    const dvec3 l = m.local(ray(film, vec2(0.5f)).dir);
    const double expected = m.plane(film).y;
    if (!(std::abs(l.y / l.z - expected) <= kDirTolerance * (1.0 + m.tan_half)))
      return testing::AssertionFailure() << "film y = " << film.y << ": vertical tangent " << l.y / l.z
                                         << ", expected " << expected;
  }
  return testing::AssertionSuccess();
}

// Along a row, the horizontal tangent rises linearly from -aspect tan(fov/2)
// at x = 0 to +aspect tan(fov/2) at x = width.
testing::AssertionResult film_x_grows_rightward(const Shot& s, const RayFn& ray) {
  const Model m(s);
  for (int k = 0; k <= 16; ++k) {
    const vec2 film(s.width * (k / 16.0f), 0.7f * s.height);
    const dvec3 l = m.local(ray(film, vec2(0.5f)).dir);
    const double expected = m.plane(film).x;
    if (!(std::abs(l.x / l.z - expected) <= kDirTolerance * (1.0 + m.aspect * m.tan_half)))
      return testing::AssertionFailure() << "film x = " << film.x << ": horizontal tangent " << l.x / l.z
                                         << ", expected " << expected;
  }
  return testing::AssertionSuccess();
}

// Every film point: the pinhole ray starts exactly at the position, is unit
// length, ignores the lens sample, and points through its image-plane point.
testing::AssertionResult pinhole_rays(const Shot& s, const RayFn& ray) {
  const Model m(s);
  std::mt19937_64 rng(3);
  auto unit = [&] { return static_cast<float>(rng() >> 40) * 0x1p-24f; };
  for (int i = 0; i <= 8; ++i)
    for (int j = 0; j <= 8; ++j) {
      const vec2 film(s.width * (i / 8.0f), s.height * (j / 8.0f));
      const Ray first = ray(film, vec2(0.5f));
      for (int k = 0; k < 8; ++k) {
        const vec2 u_lens = k == 0 ? vec2(0.0f) : vec2(unit(), unit());
        const Ray r = ray(film, u_lens);
        if (r.origin != s.desc.position)
          return testing::AssertionFailure() << "origin " << str(r.origin) << " is not the position";
        if (r.dir != first.dir)
          return testing::AssertionFailure() << "direction depends on the lens sample at film (" << film.x << ", "
                                             << film.y << ")";
        const double err = glm::length(dvec3(r.dir) - m.pinhole_dir(film));
        if (!(err <= kDirTolerance))
          return testing::AssertionFailure() << "film (" << film.x << ", " << film.y << "): direction " << str(r.dir)
                                             << " is " << err << " from the model's";
      }
    }
  return testing::AssertionSuccess();
}

TEST(CameraFraming, CentreRayPointsAlongLookAtMinusPosition) {
  for (const Shot& s : kFramings) EXPECT_TRUE(centre_ray_points_at_look_at(s, real_camera(s)));
}
TEST(CameraFraming, CornerRaysMakeTheHalfFieldOfView) {
  for (const Shot& s : kFramings) EXPECT_TRUE(corner_rays_make_half_angles(s, real_camera(s)));
}
TEST(CameraFraming, FilmYGrowsDownward) {
  for (const Shot& s : kFramings) EXPECT_TRUE(film_y_grows_downward(s, real_camera(s)));
  // In the world: the default camera's top row looks towards +y.
  EXPECT_GT(real_camera(kLandscape)(vec2(320.0f, 0.0f), vec2(0.5f)).dir.y, 0.0f);
  EXPECT_LT(real_camera(kLandscape)(vec2(320.0f, 480.0f), vec2(0.5f)).dir.y, 0.0f);
}
TEST(CameraFraming, FilmXGrowsRightward) {
  for (const Shot& s : kFramings) EXPECT_TRUE(film_x_grows_rightward(s, real_camera(s)));
  // Right-handed: looking down -z with +y up, the right edge looks towards +x.
  EXPECT_GT(real_camera(kLandscape)(vec2(640.0f, 240.0f), vec2(0.5f)).dir.x, 0.0f);
  EXPECT_LT(real_camera(kLandscape)(vec2(0.0f, 240.0f), vec2(0.5f)).dir.x, 0.0f);
}
TEST(CameraPinhole, RaysStartAtThePositionAndIgnoreTheLens) {
  for (const Shot& s : kFramings) EXPECT_TRUE(pinhole_rays(s, real_camera(s)));
}

// --- thin lens ---------------------------------------------------------------------

// For film points over the whole image (corners included) and lens samples
// (random, and the corners of the unit square): each ray is unit length,
// leaves from the aperture disk (radius aperture_radius about the position,
// in the plane perpendicular to forward), and meets the plane in focus
// (distance focus_distance along forward) where the pinhole ray through the
// same film point does, within 1e-4 of that point's distance from the
// position. Float rounding of origin and direction is ~1e-7 relative.
testing::AssertionResult thin_lens_rays_meet_on_focus_plane(const Shot& s, const RayFn& ray) {
  const Model m(s);
  const double radius = s.desc.aperture_radius, focus = s.desc.focus_distance;
  const double scale = glm::length(m.position) + radius;
  std::mt19937_64 rng(4);
  auto unit = [&] { return static_cast<float>(rng() >> 40) * 0x1p-24f; };
  std::vector<vec2> lens = {{0, 0}, {1.0f - 0x1p-24f, 0}, {0, 1.0f - 0x1p-24f}, {1.0f - 0x1p-24f, 1.0f - 0x1p-24f},
                            {0.5f, 0.5f}};
  for (int k = 0; k < 59; ++k) lens.emplace_back(unit(), unit());
  for (int i = 0; i <= 4; ++i)
    for (int j = 0; j <= 4; ++j) {
      const vec2 film(s.width * (i / 4.0f), s.height * (j / 4.0f));
      const glm::dvec2 p = m.plane(film);
      const dvec3 target = m.position + focus * (m.forward + p.x * m.right + p.y * m.up);
      const double tolerance = 1e-4 * glm::length(target - m.position);
      for (const vec2 u : lens) {
        const Ray r = ray(film, u);
        const dvec3 o(r.origin), d(r.dir);
        const dvec3 offset = o - m.position;
        if (!(std::abs(glm::length(d) - 1.0) <= 1e-6))
          return testing::AssertionFailure() << "direction " << str(r.dir) << " not unit length";
        if (!(glm::length(offset) <= radius + 1e-6 * scale))
          return testing::AssertionFailure() << "origin " << str(r.origin) << " is " << glm::length(offset)
                                             << " from the position, aperture radius " << radius;
        if (!(std::abs(glm::dot(offset, m.forward)) <= 1e-6 * scale))
          return testing::AssertionFailure() << "origin " << str(r.origin) << " is " << glm::dot(offset, m.forward)
                                             << " off the lens plane";
        const double t = (focus - glm::dot(offset, m.forward)) / glm::dot(d, m.forward);
        const dvec3 hit = o + t * d;
        const double err = glm::length(hit - target);
        if (!(t > 0.0 && err <= tolerance))
          return testing::AssertionFailure() << "film (" << film.x << ", " << film.y << "), lens (" << u.x << ", "
                                             << u.y << "): meets the focus plane " << err << " from the pinhole "
                                             << "ray's point (tolerance " << tolerance << ")";
      }
    }
  return testing::AssertionSuccess();
}

// Origins of rays through one film point, for uniform lens samples, are
// uniform over the aperture disk: chi-square on 8 equal-area annuli x 16
// sectors (angles in the camera's right/up frame).
testing::AssertionResult thin_lens_fills_aperture_uniformly(const Shot& s, const RayFn& ray) {
  const Model m(s);
  constexpr int kN = 20000, kRings = 8, kSectors = 16;
  std::vector<double> counts(kRings * kSectors, 0.0);
  std::mt19937_64 rng(5);
  auto unit = [&] { return static_cast<float>(rng() >> 40) * 0x1p-24f; };
  const vec2 film(0.3f * s.width, 0.6f * s.height);
  for (int i = 0; i < kN; ++i) {
    const float ux = unit();
    const dvec3 offset = dvec3(ray(film, vec2(ux, unit())).origin) - m.position;
    const double x = glm::dot(offset, m.right) / s.desc.aperture_radius;
    const double y = glm::dot(offset, m.up) / s.desc.aperture_radius;
    const int ring = std::min(static_cast<int>((x * x + y * y) * kRings), kRings - 1);
    double phi = std::atan2(y, x);
    if (phi < 0.0) phi += 2.0 * std::numbers::pi;
    const int sector = std::min(static_cast<int>(phi / (2.0 * std::numbers::pi) * kSectors), kSectors - 1);
    counts[ring * kSectors + sector] += 1.0;
  }
  const double stat = chi2_equal(counts, kN);
  const double crit = chi2_critical(static_cast<double>(counts.size()) - 1.0, kAlpha);
  if (stat > crit) return testing::AssertionFailure() << "chi2(127) = " << stat << " > " << crit;
  return testing::AssertionSuccess();
}

TEST(CameraThinLens, RaysThroughAFilmPointMeetOnTheFocusPlane) {
  for (const Shot& s : kLenses) EXPECT_TRUE(thin_lens_rays_meet_on_focus_plane(s, real_camera(s)));
}
TEST(CameraThinLens, OriginsFillTheApertureDiskUniformly) {
  for (const Shot& s : kLenses) EXPECT_TRUE(thin_lens_fills_aperture_uniformly(s, real_camera(s)));
}

TEST(CameraThinLens, ZeroApertureIsThePinhole) {
  for (const Shot& lens : kLenses) {
    const Shot pinhole = with_lens(lens, 0.0f, lens.desc.focus_distance);
    const Shot other_focus = with_lens(lens, 0.0f, 2.0f * lens.desc.focus_distance);
    const RayFn a = real_camera(pinhole), b = real_camera(other_focus), thin = real_camera(lens);
    for (int i = 0; i <= 4; ++i)
      for (int j = 0; j <= 4; ++j) {
        const vec2 film(lens.width * (i / 4.0f), lens.height * (j / 4.0f));
        const Ray r = a(film, vec2(0.5f));
        // Exactly the pinhole ray, whatever the lens sample and focus distance.
        EXPECT_EQ(r.origin, lens.desc.position);
        for (const vec2 u : {vec2(0.0f), vec2(0.9f, 0.1f), vec2(0.3f, 0.7f)}) {
          EXPECT_EQ(a(film, u).origin, r.origin);
          EXPECT_EQ(a(film, u).dir, r.dir);
          EXPECT_EQ(b(film, u).dir, r.dir);
        }
        // The same direction as the thin lens's ray through its centre.
        const Ray c = thin(film, vec2(0.5f));
        EXPECT_EQ(c.origin, lens.desc.position);
        EXPECT_LE(glm::length(dvec3(c.dir) - dvec3(r.dir)), kDirTolerance) << film.x << ", " << film.y;
      }
  }
  EXPECT_TRUE(pinhole_rays(with_lens(kTilted, 0.0f, 1.0f), real_camera(with_lens(kTilted, 0.0f, 1.0f))));
}

// --- planted bugs: each check above must catch the bugs it is there for ----------

// Film y taken as growing upward.
RayFn y_up(const Shot& s) {
  return [ray = real_camera(s), h = float(s.height)](vec2 f, vec2 l) { return ray(vec2(f.x, h - f.y), l); };
}
// Looking away from look_at (forward = position - look_at).
RayFn backwards(const Shot& s) {
  return [ray = real_camera(s)](vec2 f, vec2 l) {
    Ray r = ray(f, l);
    r.dir = -r.dir;
    return r;
  };
}
// Mirror image (right = up x forward).
RayFn mirrored(const Shot& s) {
  return [ray = real_camera(s), w = float(s.width)](vec2 f, vec2 l) { return ray(vec2(w - f.x, f.y), l); };
}
// Aspect ratio ignored (a square image plane stretched over the film).
RayFn square_aspect(const Shot& s) {
  return [ray = real_camera({s.desc, s.height, s.height}), k = float(s.height) / float(s.width)](vec2 f, vec2 l) {
    return ray(vec2(f.x * k, f.y), l);
  };
}
// tan(fov_y) for tan(fov_y / 2) (only for fov_y < 90 degrees).
RayFn full_angle_tangent(Shot s) {
  const double t = std::tan(s.desc.fov_y_degrees * std::numbers::pi / 180.0);
  s.desc.fov_y_degrees = static_cast<float>(2.0 * std::atan(t) * 180.0 / std::numbers::pi);
  return real_camera(s);
}
// Pinhole origin jittered by the lens sample.
RayFn jittered_pinhole(const Shot& s) {
  return [ray = real_camera(s)](vec2 f, vec2 l) {
    Ray r = ray(f, l);
    r.origin += 1e-3f * vec3(l.x - 0.5f, l.y - 0.5f, 0.0f);
    return r;
  };
}
// Rewrites each thin-lens ray to leave from `move(offset)` (offset = origin -
// position) towards `aim(ray)`, a point it should pass through.
RayFn rewritten_lens(const Shot& s, std::function<vec3(vec3)> move, std::function<vec3(const Ray&)> aim) {
  return [ray = real_camera(s), p = s.desc.position, move, aim](vec2 f, vec2 l) {
    const Ray r = ray(f, l);
    const vec3 target = aim(r);
    Ray out = r;
    out.origin = p + move(r.origin - p);
    out.dir = glm::normalize(target - out.origin);
    return out;
  };
}
// Where the real ray meets the plane in focus.
std::function<vec3(const Ray&)> true_focus(const Shot& s) {
  const vec3 fwd = glm::normalize(s.desc.look_at - s.desc.position);
  return [=](const Ray& r) {
    const float t = (s.desc.focus_distance - glm::dot(r.origin - s.desc.position, fwd)) / glm::dot(r.dir, fwd);
    return r.origin + t * r.dir;
  };
}
// Focus on a sphere: the pinhole ray's point at distance focus_distance.
RayFn sphere_of_focus(const Shot& s) {
  const RayFn pinhole = real_camera(with_lens(s, 0.0f, s.desc.focus_distance));
  return [ray = real_camera(s), pinhole, s](vec2 f, vec2 l) {
    Ray r = ray(f, l);
    r.dir = glm::normalize(s.desc.position + pinhole(f, l).dir * s.desc.focus_distance - r.origin);
    return r;
  };
}

TEST(CameraPlantedBugs, FramingBugsAreCaught) {
  EXPECT_FALSE(centre_ray_points_at_look_at(kTilted, backwards(kTilted)));
  EXPECT_FALSE(film_y_grows_downward(kTilted, y_up(kTilted)));
  EXPECT_FALSE(corner_rays_make_half_angles(kTilted, y_up(kTilted)));
  EXPECT_FALSE(film_x_grows_rightward(kPortrait, mirrored(kPortrait)));
  EXPECT_FALSE(corner_rays_make_half_angles(kPortrait, mirrored(kPortrait)));
  EXPECT_FALSE(corner_rays_make_half_angles(kLandscape, square_aspect(kLandscape)));
  EXPECT_FALSE(film_x_grows_rightward(kLandscape, square_aspect(kLandscape)));
  EXPECT_FALSE(corner_rays_make_half_angles(kTilted, full_angle_tangent(kTilted)));
  EXPECT_FALSE(film_y_grows_downward(kTilted, full_angle_tangent(kTilted)));
  EXPECT_FALSE(pinhole_rays(kLandscape, jittered_pinhole(kLandscape)));
}

TEST(CameraPlantedBugs, ThinLensBugsAreCaught) {
  const Shot& s = kLenses[1];
  const vec3 fwd = glm::normalize(s.desc.look_at - s.desc.position);
  const float radius = s.desc.aperture_radius;
  // Focus on a sphere instead of a plane: misses off-axis.
  EXPECT_FALSE(thin_lens_rays_meet_on_focus_plane(s, sphere_of_focus(s)));
  // Aperture radius used as a diameter.
  EXPECT_FALSE(
      thin_lens_rays_meet_on_focus_plane(s, rewritten_lens(s, [](vec3 o) { return 2.0f * o; }, true_focus(s))));
  // Lens tilted out of the plane perpendicular to forward (same radius).
  EXPECT_FALSE(thin_lens_rays_meet_on_focus_plane(
      s, rewritten_lens(s, [fwd](vec3 o) { return 0.8f * o + 0.6f * glm::length(o) * fwd; }, true_focus(s))));
  // Lens sample ignored: all rays from the centre of the lens.
  EXPECT_FALSE(
      thin_lens_fills_aperture_uniformly(s, rewritten_lens(s, [](vec3) { return vec3(0.0f); }, true_focus(s))));
  // Radius r / R taken to (r / R)^2: not uniform over the disk.
  EXPECT_FALSE(thin_lens_fills_aperture_uniformly(
      s, rewritten_lens(s, [radius](vec3 o) { return o * (glm::length(o) / radius); }, true_focus(s))));
}

}  // namespace
}  // namespace pathlab
