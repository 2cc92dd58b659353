// Sphere hits in closed form: sphere_crossing (core/geometry.h), which
// decides every ray's sphere hit in every Embree API, against the roots of
// the ray-sphere quadratic in long double from the same float inputs; and
// the hit a tracer resolves from it (CompiledScene::intersect) against the
// exact point and normal: the normal within what float coordinates allow,
// the point within its own error bound (p_error) of the sphere.
#include "core/compiled_scene.h"
#include "core/geometry.h"
#include "core/sampling.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <vector>

namespace pathlab {
namespace {

using ld = long double;

// The two crossings of origin + t dir with the sphere, in long double from
// the float inputs (exact there): the discriminant from the distance l of
// the centre to the line, as (r - l)(r + l), and the roots as q/a and c/q.
// `gap` = (r - l) / r: > 0 crosses, < 0 misses.
struct Exact {
  ld gap = 0, t0 = 0, t1 = 0;
};
Exact exact_crossings(const vec3& o, const vec3& d, const vec3& center, float radius) {
  const ld fx = ld(o.x) - ld(center.x), fy = ld(o.y) - ld(center.y), fz = ld(o.z) - ld(center.z);
  const ld dx = d.x, dy = d.y, dz = d.z, r = radius;
  const ld a = dx * dx + dy * dy + dz * dz, b = fx * dx + fy * dy + fz * dz, c = fx * fx + fy * fy + fz * fz - r * r;
  const ld gx = fx - b / a * dx, gy = fy - b / a * dy, gz = fz - b / a * dz;
  const ld l = std::sqrt(gx * gx + gy * gy + gz * gz);
  Exact e;
  e.gap = (r - l) / r;
  if (e.gap <= 0) return e;
  const ld root = std::sqrt(a * (r - l) * (r + l));
  const ld q = -(b + (b < 0 ? -root : root));
  e.t0 = std::min(q / a, c / q);
  e.t1 = std::max(q / a, c / q);
  return e;
}

// The spacing of floats at |x|.
ld ulp_at(ld x) {
  const auto f = static_cast<float>(std::abs(x));
  return ld(std::nextafter(f, std::numeric_limits<float>::infinity())) - ld(f);
}

struct SphereCase {
  const char* name;
  vec3 center;
  float radius;
  float distance;  // of the ray origins from the centre
};

// Unit and unequal radii, near and far (1e6 radii), off the origin (1e5),
// the smallest radius a scene may hold (1e-18), a tiny sphere at a unit
// distance.
const SphereCase kCases[] = {
    {"unit at 2", vec3(0.0f), 1.0f, 2.0f},
    {"unit at 10", vec3(0.3f, -0.2f, 0.1f), 1.0f, 10.0f},
    {"unit at 1e3", vec3(0.0f), 1.0f, 1e3f},
    {"unit at 1e6", vec3(0.0f), 1.0f, 1e6f},
    {"bulb", vec3(0.3f, 0.5f, 0.2f), 0.1f, 1.3f},
    {"large, off the origin", vec3(1e5f, -1e5f, 1e5f), 1e4f, 3e4f},
    {"tiny at unit distance", vec3(0.25f, 0.5f, -0.75f), 1e-4f, 1.0f},
    {"smallest radius", vec3(0.0f), 1e-18f, 5e-18f},
};

// Impact parameters, in radii: through the centre, across, near the rim,
// grazing from inside by 1e-4 .. 1e-7 (the float direction's own rounding
// moves the line by ~1e-7 radii, so the exact gap decides), and misses.
constexpr float kImpacts[] = {0.0f, 0.3f, 0.9f, 0.999f, 1.0f - 1e-4f, 1.0f - 1e-6f, 1.0f - 1e-7f,
                              1.0f + 1e-7f, 1.0f + 1e-5f, 1.5f};

struct AimedRay {
  Ray ray;
  Exact exact;
};

// Rays from points at `c.distance` from the centre over the sphere of
// directions, aimed at each impact parameter in a direction about the axis.
std::vector<AimedRay> aimed_rays(const SphereCase& c) {
  std::vector<AimedRay> rays;
  for (int i = 0; i < 60; ++i) {
    const vec2 u((static_cast<float>(i) + 0.5f) / 60.0f, std::fmod(0.618034f * static_cast<float>(i), 1.0f));
    const vec3 w = square_to_uniform_sphere(u);
    const vec3 origin = c.center + c.distance * w;
    const Frame frame(-w);
    const float phi = 6.2831853f * std::fmod(0.7548777f * static_cast<float>(i), 1.0f);
    for (const float k : kImpacts) {
      const vec3 aim = c.center + c.radius * k * (std::cos(phi) * frame.s + std::sin(phi) * frame.t);
      const vec3 dir = glm::normalize(aim - origin);
      rays.push_back({Ray{origin, dir, kInfinity}, exact_crossings(origin, dir, c.center, c.radius)});
    }
  }
  return rays;
}

// t within one float of the exact first crossing (rounding to nearest takes
// half of that; the double arithmetic before it ~1e-9 of a float), every
// clear crossing found and every clear miss missed; only rays whose exact
// gap is within 1e-12 of the rim may go either way.
TEST(SphereCrossing, TIsTheExactFirstCrossingWithinOneFloat) {
  for (const SphereCase& c : kCases) {
    SCOPED_TRACE(c.name);
    int crossings = 0, misses = 0;
    for (const AimedRay& a : aimed_rays(c)) {
      const float t = sphere_crossing(a.ray.origin, a.ray.dir, 0.0f, kInfinity, c.center, c.radius);
      if (std::abs(a.exact.gap) < 1e-12L) continue;
      if (a.exact.gap < 0) {
        ++misses;
        EXPECT_TRUE(std::isnan(t)) << "gap " << static_cast<double>(a.exact.gap) << ", t " << t;
        continue;
      }
      ++crossings;
      ASSERT_FALSE(std::isnan(t)) << "gap " << static_cast<double>(a.exact.gap);
      EXPECT_LE(std::abs(ld(t) - a.exact.t0), ulp_at(a.exact.t0))
          << "t " << t << ", exact " << static_cast<double>(a.exact.t0) << ", gap " << static_cast<double>(a.exact.gap);
    }
    EXPECT_GT(crossings, 150) << "too few rays cross: the test would check nothing";
    EXPECT_GT(misses, 50);
  }
}

// A sphere far away along an axis (no direction rounding): t = D - r to
// within one float at 1e15.
TEST(SphereCrossing, HugeDistanceAlongAnAxis) {
  for (const float d : {1e6f, 1e10f, 1e15f}) {
    const float t = sphere_crossing(vec3(d, 0.0f, 0.0f), vec3(-1.0f, 0.0f, 0.0f), 0.0f, kInfinity, vec3(0.0f), 1.0f);
    EXPECT_LE(std::abs(ld(t) - (ld(d) - 1)), ulp_at(ld(d) - 1)) << d;
  }
}

// From inside (the far crossing; the near one lies behind), with a
// non-unit direction (t in its units), and tnear / tfar as open bounds: a
// crossing at tfar, or rounding to it, does not count.
TEST(SphereCrossing, InsideScaledDirectionsAndOpenBounds) {
  const vec3 center(0.3f, -0.2f, 0.1f);
  for (int i = 0; i < 100; ++i) {
    const vec2 u((static_cast<float>(i) + 0.5f) / 100.0f, std::fmod(0.618034f * static_cast<float>(i), 1.0f));
    const vec3 w = square_to_uniform_sphere(u), d = square_to_uniform_sphere(vec2(u.y, u.x));
    const vec3 inside = center + 0.5f * w;
    const Exact e = exact_crossings(inside, d, center, 1.0f);
    ASSERT_GT(e.gap, 0);
    const float t = sphere_crossing(inside, d, 0.0f, kInfinity, center, 1.0f);
    EXPECT_LE(std::abs(ld(t) - e.t1), ulp_at(e.t1));
    for (const float scale : {3.0f, 1e-3f}) {
      const Exact es = exact_crossings(inside, scale * d, center, 1.0f);
      const float ts = sphere_crossing(inside, scale * d, 0.0f, kInfinity, center, 1.0f);
      EXPECT_LE(std::abs(ld(ts) - es.t1), ulp_at(es.t1)) << scale;
    }
    EXPECT_TRUE(std::isnan(sphere_crossing(inside, d, 0.0f, t, center, 1.0f)));
    EXPECT_EQ(sphere_crossing(inside, d, 0.0f, std::nextafter(t, kInfinity), center, 1.0f), t);
    EXPECT_TRUE(std::isnan(sphere_crossing(inside, d, t, kInfinity, center, 1.0f)));
  }
}

// A ray leaving the sphere's surface (spawned off it by its error bound,
// core/ray.h) never finds the crossing it leaves: outwards nothing, inwards
// the far side (the exact far crossing within one float), the near one
// lying behind the origin.
TEST(SphereCrossing, SpawnedRaysDoNotFindTheirOwnCrossing) {
  Shape sphere;
  sphere.kind = Shape::Kind::Sphere;
  for (const vec3 center : {vec3(0.0f), vec3(1e5f, -1e5f, 1e5f)}) {
    sphere.center = center;
    sphere.radius = 3.0f;
    for (int i = 0; i < 2000; ++i) {
      const vec2 u((static_cast<float>(i) + 0.5f) / 2000.0f, std::fmod(0.618034f * static_cast<float>(i), 1.0f));
      const SurfacePoint sp = sample_sphere(sphere, u);
      const vec3 w = square_to_cosine_hemisphere(vec2(u.y, u.x));
      const vec3 out = Frame(sp.n).to_world(w);
      const vec3 o_out = offset_ray_origin(sp.p, sp.p_error, sp.n), o_in = offset_ray_origin(sp.p, sp.p_error, -sp.n);
      EXPECT_TRUE(std::isnan(sphere_crossing(o_out, out, 0.0f, kInfinity, center, 3.0f)));
      const float t = sphere_crossing(o_in, -out, 0.0f, kInfinity, center, 3.0f);
      const Exact e = exact_crossings(o_in, -out, center, 3.0f);
      ASSERT_FALSE(std::isnan(t));
      ASSERT_LT(e.t0, 0) << "the offset left the origin outside";
      EXPECT_LE(std::abs(ld(t) - e.t1), ulp_at(e.t1)) << "cos " << w.z;
    }
  }
}

// The hit a tracer resolves (CompiledScene::intersect: t from
// sphere_crossing, the point reprojected onto the sphere): its normal within
// the float spacing of the coordinates involved, over the radius, of the
// exact normal at the exact crossing; its point within its error bound of
// the sphere.
TEST(SphereCrossing, ResolvedHitHasTheExactNormalAndABoundedPoint) {
  for (const SphereCase& c : kCases) {
    SCOPED_TRACE(c.name);
    Scene scene;
    scene.name = "sphere";
    scene.materials.push_back(Material{"white", MaterialType::Diffuse, Spectrum(0.5f), Spectrum(0.0f), false});
    Shape sphere;
    sphere.description = "sphere";
    sphere.kind = Shape::Kind::Sphere;
    sphere.center = c.center;
    sphere.radius = c.radius;
    scene.shapes.push_back(sphere);
    const CompiledScene compiled(std::move(scene));
    int checked = 0;
    for (const AimedRay& a : aimed_rays(c)) {
      if (a.exact.gap < 1e-12L) continue;
      Surfel s;
      ASSERT_TRUE(compiled.intersect(a.ray, &s));
      const vec3& o = a.ray.origin;
      const vec3& d = a.ray.dir;
      const ld t = a.exact.t0;
      ld n_err = 0, dist = 0, p_err = 0;
      const ld p[3] = {ld(o.x) + t * ld(d.x), ld(o.y) + t * ld(d.y), ld(o.z) + t * ld(d.z)};
      for (int k = 0; k < 3; ++k) {
        const ld n_exact = (p[k] - ld(c.center[k])) / ld(c.radius);
        n_err = std::max(n_err, std::abs(ld(s.n[k]) - n_exact));
        dist += (ld(s.p[k]) - ld(c.center[k])) * (ld(s.p[k]) - ld(c.center[k]));
        p_err += ld(s.p_error[k]) * ld(s.p_error[k]);
      }
      // o + t d in float: a few floats of |o| and of t |d|, plus t's own
      // float; moving the point by e turns the normal by e / r.
      const ld largest = std::max({std::abs(ld(o.x)), std::abs(ld(o.y)), std::abs(ld(o.z))}) + t;
      const ld bound = (4 * largest * 0x1p-23L + ulp_at(t)) / ld(c.radius) + 8 * 0x1p-24L;
      EXPECT_LE(n_err, bound) << "gap " << static_cast<double>(a.exact.gap);
      EXPECT_LE(std::abs(std::sqrt(dist) - ld(c.radius)), std::sqrt(p_err));
      ++checked;
    }
    EXPECT_GT(checked, 150);
  }
}

}  // namespace
}  // namespace pathlab
