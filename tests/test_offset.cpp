// Rays leaving a surface must not hit it again, however far from the world
// origin the surface lies (floats there are 0.0078 apart at 1e5).
#include "core/compiled_scene.h"
#include "core/film.h"
#include "core/geometry.h"
#include "core/render.h"
#include "core/rng.h"
#include "core/sampling.h"
#include "reference/reference_tracer.h"

#include <gtest/gtest.h>

#include <bit>
#include <cmath>
#include <limits>

namespace pathlab {
namespace {

Scene box_and_sphere_at(const vec3& offset) {
  Scene scene;
  scene.name = "offset";
  scene.materials.push_back(Material{"white", MaterialType::Diffuse, Spectrum(0.5f), Spectrum(0.0f), false});
  scene.camera.position = offset + vec3(0, 0, 50);
  scene.camera.look_at = offset;
  Shape box;
  box.description = "box";
  box.mesh = {{{-1, -1, -1}, {1, -1, -1}, {1, 1, -1}, {-1, 1, -1}, {-1, -1, 1}, {1, -1, 1}, {1, 1, 1}, {-1, 1, 1}},
              {{0, 2, 1}, {0, 3, 2}, {4, 5, 6}, {4, 6, 7}, {0, 1, 5}, {0, 5, 4},
               {3, 6, 2}, {3, 7, 6}, {0, 4, 7}, {0, 7, 3}, {1, 2, 6}, {1, 6, 5}}};
  for (vec3& p : box.mesh.positions) p = offset + 3.0f * p + vec3(-8, 0, 0);
  scene.shapes.push_back(box);
  Shape sphere;
  sphere.kind = Shape::Kind::Sphere;
  sphere.description = "sphere";
  sphere.center = offset + vec3(8, 0, 0);
  sphere.radius = 3.0f;
  scene.shapes.push_back(sphere);
  return scene;
}

// One grey mesh named "quad", seen from `camera`.
Scene one_quad_scene(const std::string& name, const vec3& camera, TriangleMesh mesh) {
  Scene scene;
  scene.name = name;
  scene.materials.push_back(diffuse_material(Spectrum(0.5f)));
  scene.camera.position = camera;
  Shape quad;
  quad.description = "quad";
  quad.mesh = std::move(mesh);
  scene.shapes.push_back(quad);
  return scene;
}

// A ray leaving the point `sp` in a cosine-distributed direction of its
// front (every fourth one grazing, cos theta ~ 1e-3), drawn from stream
// (seed, a, i), offset as a surfel spawns it.
Ray leaving(const SurfacePoint& sp, std::uint64_t seed, std::uint32_t a, std::uint32_t i) {
  Surfel surfel;
  surfel.p = sp.p;
  surfel.p_error = sp.p_error;
  surfel.n = sp.n;
  vec3 w = square_to_cosine_hemisphere(vec2(sample_u(seed, a, i, 0, Dim::DirectionX), sample_u(seed, a, i, 0, Dim::DirectionY)));
  if (i % 4 == 0) w = glm::normalize(vec3(w.x, w.y, 1e-3f));
  return surfel.spawn(Frame(sp.n).to_world(w));
}

// Both shapes are convex: a ray leaving either surface outwards can hit
// neither itself nor (the two being far apart and the directions drawn in
// the outward hemisphere) anything nearby on the same shape.
void expect_no_self_hits(const vec3& offset) {
  const CompiledScene scene(box_and_sphere_at(offset));
  int self_hits = 0, rays = 0;
  for (std::uint32_t shape = 0; shape < 2; ++shape) {
    const Shape& s = scene.scene().shapes[shape];
    const std::uint32_t prims = s.kind == Shape::Kind::Sphere ? 1 : static_cast<std::uint32_t>(s.mesh.triangles.size());
    for (std::uint32_t i = 0; i < 20000; ++i) {
      const std::uint32_t prim = i % prims;
      const vec2 u(sample_u(1, shape, i, 0, Dim::LightX), sample_u(1, shape, i, 0, Dim::LightY));
      const SurfacePoint sp = s.kind == Shape::Kind::Sphere ? sample_sphere(s, u) : sample_triangle(s, prim, u);
      Surfel hit;
      ++rays;
      if (scene.intersect(leaving(sp, 2, shape, i), &hit) && hit.shape == shape) ++self_hits;
    }
  }
  EXPECT_EQ(self_hits, 0) << "of " << rays << " rays at offset (" << offset.x << ", " << offset.y << ", " << offset.z << ")";
}

// The inline float steps equal std::nextafter, bit for bit, on every kind
// of float: zeros, denormals, normals, the largest finite, infinities.
TEST(RayOffset, NextFloatEqualsNextafter) {
  std::vector<float> values{0.0f, -0.0f, 1.0f, -1.0f, 1e-40f, -1e-40f, std::numeric_limits<float>::denorm_min(),
                            -std::numeric_limits<float>::denorm_min(), std::numeric_limits<float>::min(),
                            -std::numeric_limits<float>::min(), std::numeric_limits<float>::max(),
                            -std::numeric_limits<float>::max(), kInfinity, -kInfinity, 3.14159f, -2.5e7f};
  for (std::uint32_t i = 0; i < 100000; ++i) values.push_back(std::bit_cast<float>(i * 2654435761u) * 1.0f);
  for (float v : values) {
    if (std::isnan(v)) continue;
    EXPECT_EQ(std::bit_cast<std::uint32_t>(next_float_up(v)), std::bit_cast<std::uint32_t>(std::nextafter(v, kInfinity))) << v;
    EXPECT_EQ(std::bit_cast<std::uint32_t>(next_float_down(v)), std::bit_cast<std::uint32_t>(std::nextafter(v, -kInfinity))) << v;
  }
  EXPECT_TRUE(std::isnan(next_float_up(std::numeric_limits<float>::quiet_NaN())));
  EXPECT_TRUE(std::isnan(next_float_down(std::numeric_limits<float>::quiet_NaN())));
}

TEST(RayOffset, NoSelfIntersectionAtTheOrigin) { expect_no_self_hits(vec3(0.0f)); }

// A quad lying exactly in a coordinate plane through the origin (a PLY or
// glTF ground at y = 0): its points have no rounding error across the plane,
// so the error bound gives no offset; rays leaving either side must still
// not find it again. Quads of size 2 and 2e-3 (small edge cross products).
TEST(RayOffset, NoSelfIntersectionOnACoordinatePlaneThroughTheOrigin) {
  for (const float size : {1.0f, 1e-3f}) {
    for (int axis = 0; axis < 3; ++axis) {
      const auto corner = [&](float a, float b) {
        vec3 p(0.0f);
        p[(axis + 1) % 3] = a * size;
        p[(axis + 2) % 3] = b * size;
        return p;
      };
      const CompiledScene compiled(one_quad_scene(
          "plane", vec3(0, 5, 5), {{corner(-1, -1), corner(1, -1), corner(1, 1), corner(-1, 1)}, {{0, 1, 2}, {0, 2, 3}}}));
      int self_hits = 0;
      for (std::uint32_t i = 0; i < 4000; ++i) {
        const vec2 u(sample_u(3, axis, i, 0, Dim::LightX), sample_u(3, axis, i, 0, Dim::LightY));
        const SurfacePoint sp = sample_triangle(compiled.scene().shapes[0], i % 2, u);
        ASSERT_EQ(sp.p[axis], 0.0f);
        ASSERT_EQ(sp.p_error[axis], 0.0f);
        // Every other ray leaves the back.
        const SurfacePoint side{sp.p, sp.p_error, i % 2 == 1 ? -sp.n : sp.n};
        Surfel hit;
        self_hits += compiled.intersect(leaving(side, 4, static_cast<std::uint32_t>(axis), i), &hit);
      }
      EXPECT_EQ(self_hits, 0) << "of 4000 rays, quad of size " << size << " across axis " << axis;
    }
  }
}
// A quad turned 36 degrees about y whose middle edge lies on the y axis:
// near that edge a point's coordinates across the quad are tiny, and so is
// its own rounding error, but Embree tells an origin from the plane only
// within a few ulps of its distance to the vertices (about 1e-8 here).
// Rays leaving points within 1e-3 of the edge must not find their quad
// again (before the bound held Embree's error too, a review measured shadow
// rays hitting it: the image 0.8 % dark, z -36).
TEST(RayOffset, EdgeOnACoordinateAxis) {
  const float c = 0.809016994f, s = 0.587785252f;
  const CompiledScene compiled(one_quad_scene("axis-edge", vec3(2, 0.3, 2.5),
                                              {{{-c, -1, s}, {0, -1, 0}, {c, -1, -s}, {-c, 1, s}, {0, 1, 0}, {c, 1, -s}},
                                               {{0, 1, 4}, {0, 4, 3}, {1, 2, 5}, {1, 5, 4}}}));
  // Triangles 0 and 3 have the edge; their corner off it is p0 and p1.
  // Barycentrics (b1, b2) of a point a fraction `along` up the edge and
  // `off` (below 1e-3) towards that corner.
  const auto near_edge = [](std::uint32_t tri, float along, float off) {
    return tri == 0 ? vec2(along * (1.0f - off), (1.0f - along) * (1.0f - off)) : vec2(off, along * (1.0f - off));
  };
  int self_hits = 0, old_self_hits = 0;
  for (std::uint32_t i = 0; i < 40000; ++i) {
    const std::uint32_t tri = (i / 2) % 2 == 0 ? 0u : 3u;
    const vec2 b = near_edge(tri, sample_u(5, tri, i, 0, Dim::LightX), 1e-3f * sample_u(5, tri, i, 0, Dim::LightY));
    const Triangle tr = make_triangle(compiled.scene().shapes[0], tri);
    const SurfacePoint sp = triangle_point(tr, b);
    const SurfacePoint side{sp.p, sp.p_error, i % 2 == 1 ? -sp.n : sp.n};  // both sides of both triangles
    Surfel hit;
    self_hits += compiled.intersect(leaving(side, 6, tri, i), &hit);
    // The point's rounding error alone, the bound before: the test's rays
    // must find the failure it guards against.
    const float b0 = 1.0f - b.x - b.y;
    const vec3 rounding = gamma_bound(7) * ((glm::abs(b0 * tr.p0) + glm::abs(b.x * tr.p1)) + glm::abs(b.y * tr.p2));
    old_self_hits += compiled.intersect(leaving({sp.p, rounding, side.n}, 6, tri, i), &hit);
  }
  EXPECT_EQ(self_hits, 0) << "of 40000 rays leaving points near the edge on the y axis";
  EXPECT_GT(old_self_hits, 0) << "the rounding error alone no longer lets rays hit their quad: the test sees nothing";
}

TEST(RayOffset, NoSelfIntersectionAt1e5) { expect_no_self_hits(vec3(1e5f, -1e5f, 1e5f)); }
TEST(RayOffset, NoSelfIntersectionAt1e6) { expect_no_self_hits(vec3(-1e6f, 3e5f, 1e6f)); }

// Rays leaving a sphere inwards must cross it and hit its far side, never
// the point they leave from: their first hit lies a chord away.
TEST(RayOffset, InwardRaysCrossTheSphereAt1e5) {
  const CompiledScene scene(box_and_sphere_at(vec3(1e5f, 1e5f, -1e5f)));
  const Shape& sphere = scene.scene().shapes[1];
  int short_hits = 0, misses = 0;
  for (std::uint32_t i = 0; i < 20000; ++i) {
    const SurfacePoint sp =
        sample_sphere(sphere, vec2(sample_u(3, 0, i, 0, Dim::LightX), sample_u(3, 0, i, 0, Dim::LightY)));
    Surfel surfel;
    surfel.p = sp.p;
    surfel.p_error = sp.p_error;
    surfel.n = sp.n;
    vec3 w = square_to_cosine_hemisphere(vec2(sample_u(4, 0, i, 0, Dim::DirectionX), sample_u(4, 0, i, 0, Dim::DirectionY)));
    const vec3 dir = -Frame(sp.n).to_world(w);  // into the sphere
    Surfel hit;
    if (!scene.intersect(surfel.spawn(dir), &hit)) {
      ++misses;
      continue;
    }
    // The chord from p along dir has length 2 r cos(theta) = 2 r w.z.
    if (glm::length(hit.p - sp.p) < 0.5f * 2.0f * sphere.radius * w.z) ++short_hits;
  }
  EXPECT_EQ(short_hits, 0);
  EXPECT_EQ(misses, 0);
}

// Shadow rays between two surfaces far from the origin, with nothing in
// between, must all be unoccluded: both ends are offset off their surfaces.
TEST(RayOffset, ShadowRaysBetweenSurfacesAt1e5AreUnoccluded) {
  const vec3 o(-1e5f, 1e5f, 1e5f);
  Scene s;
  s.name = "far-shadow";
  s.materials.push_back(Material{"white", MaterialType::Diffuse, Spectrum(0.5f), Spectrum(0.0f), false});
  Shape floor, lamp;
  floor.description = "floor";
  floor.mesh = {{o + vec3(-5, 0, -5), o + vec3(5, 0, -5), o + vec3(5, 0, 5), o + vec3(-5, 0, 5)}, {{0, 2, 1}, {0, 3, 2}}};
  lamp.description = "lamp";
  lamp.mesh = {{o + vec3(-1, 2, -1), o + vec3(1, 2, -1), o + vec3(1, 2, 1), o + vec3(-1, 2, 1)}, {{0, 1, 2}, {0, 2, 3}}};
  s.shapes = {floor, lamp};
  const CompiledScene scene(std::move(s));
  int blocked = 0;
  for (std::uint32_t i = 0; i < 20000; ++i) {
    const vec2 u0(sample_u(5, 0, i, 0, Dim::LightX), sample_u(5, 0, i, 0, Dim::LightY));
    const vec2 u1(sample_u(6, 0, i, 0, Dim::LightX), sample_u(6, 0, i, 0, Dim::LightY));
    const SurfacePoint a = sample_triangle(scene.scene().shapes[0], i % 2, u0);
    const SurfacePoint b = sample_triangle(scene.scene().shapes[1], i % 2, u1);
    Surfel from;
    from.p = a.p;
    from.p_error = a.p_error;
    from.n = a.n;
    blocked += scene.occluded(from.spawn_to(b.p, b.p_error, b.n));
  }
  EXPECT_EQ(blocked, 0);
}

// The same check through a whole render: a Lambert plane far from the origin
// lit by a point light. Self-shadowing would show as black speckle; every
// pixel must instead get the direct light rho/pi * I cos(theta) / d^2 of
// its visible point (within the variation over the pixel's footprint).
TEST(RayOffset, NoShadowSpeckleOnAPlaneAt1e5) {
  const vec3 o(1e5f, 1e5f, -1e5f);
  Scene scene;
  scene.name = "far-plane";
  scene.materials.push_back(Material{"white", MaterialType::Diffuse, Spectrum(0.8f), Spectrum(0.0f), false});
  Shape plane;
  plane.description = "plane";
  plane.mesh = {{o + vec3(-40, 0, -40), o + vec3(40, 0, -40), o + vec3(40, 0, 40), o + vec3(-40, 0, 40)},
                {{0, 2, 1}, {0, 3, 2}}};
  scene.shapes.push_back(plane);
  scene.delta_lights.push_back({o + vec3(0, 20, 0), Spectrum(400.0f)});
  scene.camera.position = o + vec3(0, 30, 10);
  scene.camera.look_at = o;
  scene.film = {32, 32, FilterKind::Box};
  scene.render.spp = 4;
  scene.render.max_depth = 1;
  const RenderSettings settings = scene.render;
  const CompiledScene compiled(std::move(scene));
  const ReferenceTracer tracer(compiled, settings);
  Film film(32, 32, FilterKind::Box);
  render(tracer, film);
  int dark = 0;
  for (int y = 0; y < 32; ++y)
    for (int x = 0; x < 32; ++x) {
      const Ray r = compiled.camera().generate_ray(vec2(x + 0.5f, y + 0.5f), vec2(0.5f));
      Surfel s;
      ASSERT_TRUE(compiled.intersect(r, &s));
      const vec3 to_light = compiled.scene().delta_lights[0].position - s.p;
      const float d2 = glm::dot(to_light, to_light);
      const float expected = 0.8f * kInvPi * 400.0f * glm::dot(s.n, to_light) / std::sqrt(d2) / d2;
      if (film.mean(x, y).x < 0.5f * expected) ++dark;
    }
  EXPECT_EQ(dark, 0);
}

}  // namespace
}  // namespace pathlab
