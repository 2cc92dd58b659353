// Points on shapes: positions with rounding-error bounds and front-facing
// normals, for ray hits and for light samples alike.
#pragma once

#include "core/scene.h"

#include <cstddef>
#include <cstdint>

namespace pathlab {

struct SurfacePoint {
  vec3 p;
  vec3 p_error;  // per-axis bound on |p - true point|
  vec3 n;        // unit normal of the front side
};

// An axis-aligned box, empty until something is added to it.
struct Box {
  vec3 lo{kInfinity}, hi{-kInfinity};
  bool empty() const { return !(lo.x <= hi.x); }
  void add(const vec3& p) {
    lo = glm::min(lo, p);
    hi = glm::max(hi, p);
  }
  void add(const Box& b) {
    if (!b.empty()) add(b.lo), add(b.hi);
  }
  vec3 corner(int c) const { return {(c & 1) ? hi.x : lo.x, (c & 2) ? hi.y : lo.y, (c & 4) ? hi.z : lo.z}; }
};
// The box around a shape (a sphere's, or a mesh's vertices).
Box bounds(const Shape& shape);
// The box around the eight corners of `box` placed by `to_world`.
Box placed(const Box& box, const mat4& to_world);
// True if every corner of `box` placed by `to_world` is finite.
bool placed_finite(const Box& box, const mat4& to_world);
// True if `to_world` can place an instance: finite, with a non-zero
// determinant, and an inverse that is finite too (Embree and the normals'
// inverse transpose need it).
bool invertible_placement(const mat4& to_world);

// The angle at corner `a` of the triangle (a, b, c), from atan2 (accurate
// for slivers, unlike acos).
double corner_angle(const dvec3& a, const dvec3& b, const dvec3& c);

float triangle_area(const TriangleMesh& mesh, std::uint32_t tri);
// Applies `xf` to a mesh (positions; normals by the inverse transpose;
// tangents by `xf`, their handedness flipped with the winding of a mirroring
// transform) and drops the triangles it made degenerate; returns how many.
std::size_t transform_mesh(TriangleMesh* mesh, const mat4& xf);
// Front normal of a triangle: counter-clockwise winding, unless flipped.
vec3 triangle_normal(const Shape& shape, std::uint32_t tri);

// One triangle as hits and light samples need it: its vertices and front
// normal side by side (one or two cache lines instead of four scattered
// reads, and no normal to recompute). CompiledScene keeps one per triangle.
struct Triangle {
  vec3 p0, p1, p2;
  vec3 n;  // unit front normal, as triangle_normal()
};
Triangle make_triangle(const Shape& shape, std::uint32_t tri);

// The point with barycentrics (b1, b2) of a triangle, recomputed from the
// vertices (more accurate than origin + t * dir far from the origin). Its
// p_error also holds Embree's error in telling a ray origin from the
// triangle (core/simd/lanes-inl.h, triangle_point).
SurfacePoint triangle_point(const Triangle& t, vec2 b);
SurfacePoint triangle_point(const Shape& shape, std::uint32_t tri, vec2 b);
// A point near `p_approx` projected back onto the sphere.
SurfacePoint sphere_point(const Shape& shape, const vec3& p_approx);

// The first crossing of the ray origin + t dir with the sphere (center,
// radius) with tnear < t < tfar, or NaN if there is none. `dir` need not be
// of unit length (an instance's space scales it); t is in its units.
// Every ray query decides its sphere hits here: EmbreeAccel registers
// spheres as Embree user geometry that calls this function for each ray,
// whatever API (one ray, 16-wide packet, stream) and batch it came in, so a
// ray's hit - whether, where, and which of the two crossings - is a function
// of the ray alone. (Embree's own sphere kernels are not: its one-ray and
// 16-wide kernels round t differently, by a few ulps, which moves hits across
// a shadow ray's tmax; docs/ARCHITECTURE.md, Ray offsets, Sphere hits.)
// Computed in double from the float inputs, which are exact there: the
// discriminant from the ray's perpendicular offset from the centre, as
// (r - l)(r + l) (PBR 4th ed. 6.8.4; Haines et al., Ray Tracing Gems ch. 7),
// and the two roots as q / a and c / q, so neither root is a difference of
// near-equal numbers. Each root is then rounded to float once, and tested
// against tnear and tfar as a float, as Embree stores t: a crossing at or
// beyond tfar never counts (rounding is monotonic), nor one within half a
// float below it (it rounds to tfar), so the sphere a shadow ray ends just
// before does not stop it. Its error before that rounding is a
// few double ulps of the distances involved, below the float offsets of
// core/ray.h by ~2^29, so the crossing a ray just left (its origin offset off
// the sphere) is never found again. A ray that touches the sphere (one
// double root) crosses it nowhere and finds nothing.
float sphere_crossing(const vec3& origin, const vec3& dir, float tnear, float tfar, const vec3& center, float radius);

// The shading normal at a point with geometric normal `ng` from the
// interpolated vertex normals `sum` (not normalised): unit length, turned to
// ng's side of the surface (so flip_normals and the file's winding decide the
// front, not the file's normals). It is ng itself when `sum` vanishes or is
// not finite (opposite vertex normals) and when it lies within about 0.08
// degrees of ng (1 - cos < 1e-6), so that a mesh whose normals are its face
// normals shades exactly as the flat mesh.
// (The generic shading_normal of core/simd/lanes-inl.h at width 1, which
// core/simd/shading_frame-inl.h's surface_frame applies to the vertex
// normals' blend.)
vec3 shading_normal(const vec3& ng, const vec3& sum);

SurfacePoint sample_triangle(const Triangle& t, vec2 u);
SurfacePoint sample_triangle(const Shape& shape, std::uint32_t tri, vec2 u);
SurfacePoint sample_sphere(const Shape& shape, vec2 u);

}  // namespace pathlab
