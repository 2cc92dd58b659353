// Closed-form irradiance from polygonal Lambertian emitters, and the small
// 2-D polygon toolkit (convex hull, convex clipping) that goes with it.
//
// polygon_form_factor gives the exact irradiance at a point from a uniformly
// emitting planar polygon, E = L * polygon_form_factor(...), by Lambert's
// edge formula (Lambert 1760; Arvo 1995, "Applications of Irradiance
// Tensors to the Simulation of Non-Lambertian Phenomena"), after clipping
// the polygon to the point's upper hemisphere. It is the reference for
// direct lighting from area lights in the analytic scenes.
//
// Everything is in double precision.
#pragma once

#include "core/math.h"

#include <glm/glm.hpp>

#include <span>
#include <vector>

namespace pathlab::analytic {

// The cosine-weighted solid angle  ∫ max(0, n·ω) dω  subtended at the point
// `x` by the planar polygon `polygon` (vertices in order, either winding),
// for the unit normal `n` at x. This is the irradiance at x per unit radiance
// of a uniform Lambertian emitter covering the polygon (π times the
// differential-area-to-polygon form factor); it lies in [0, π].
//
// The polygon must be planar and simple (not self-intersecting); it may be
// concave. Returns 0 for fewer than three vertices, for a polygon of zero
// area (collinear vertices), for one lying wholly below x's horizon
// (n·(p − x) < 0), and when x lies in the polygon's plane (there the
// polygon has no solid angle; the formula would be 0/0 on its edges).
// `n` is assumed unit length: the result scales with |n|.
double polygon_form_factor(std::span<const dvec3> polygon, const dvec3& x, const dvec3& n);

// The signed area of a simple 2-D polygon by the shoelace formula,
// positive when its vertices run counter-clockwise.
double signed_area(std::span<const glm::dvec2> polygon);

// The convex hull of `points` by Andrew's monotone chain, counter-clockwise,
// starting at the lexicographically smallest point (smallest x, then y),
// without repeated points or collinear (180°) vertices. Degenerate inputs
// give the degenerate hull: no points → empty, all points equal → that
// point, all points collinear → the two extreme points.
std::vector<glm::dvec2> convex_hull(std::vector<glm::dvec2> points);

// The intersection of the convex polygons `subject` and `clip`, both
// counter-clockwise (a precondition, not checked), by Sutherland–Hodgman:
// `subject` is cut by the inner half-plane of each edge of `clip` in turn.
// Returns a counter-clockwise convex polygon, or an empty vector when the
// intersection has no area (disjoint polygons, polygons that only touch,
// or either input with fewer than three vertices).
std::vector<glm::dvec2> clip_convex(std::span<const glm::dvec2> subject, std::span<const glm::dvec2> clip);

}  // namespace pathlab::analytic
