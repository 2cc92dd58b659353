#include "analytic-scenes/polygon_irradiance.h"

#include <algorithm>
#include <cmath>
#include <cstddef>

namespace pathlab::analytic {
namespace {

using glm::dvec2;

// A point closer to the polygon's plane than this fraction of its distance
// to the farthest vertex counts as lying in the plane. A point meant to lie
// in the plane (computed from the vertices) misses it by rounding, ~1e-16 of
// that scale, a few orders of magnitude more for the plane of a thin
// sliver; and at the plane the answer jumps between the two sides' limits
// (up to π on one side, 0 on the other), so closer than this the data
// cannot say which side x is on. Points farther off are computed accurately
// (the tests go down to 1e-9 of the scale).
constexpr double kInPlaneTolerance = 1e-12;

// --- 3-D: the polygon's plane --------------------------------------------------

// Twice the vector area of the polygon: the sum of the cross products of its
// fan triangles around vertex 0 (Newell's normal, taken relative to a vertex
// to keep the products small). For a planar polygon it is 2·area·N̂, with N̂
// the normal around which the vertices wind counter-clockwise (right-hand
// rule); it vanishes for collinear vertices.
dvec3 twice_vector_area(std::span<const dvec3> polygon) {
  dvec3 sum(0.0);
  for (std::size_t i = 1; i + 1 < polygon.size(); ++i)
    sum += glm::cross(polygon[i] - polygon[0], polygon[i + 1] - polygon[0]);
  return sum;
}

// True if x lies in the plane through the polygon with unit normal
// `unit_normal` (up to kInPlaneTolerance). The distance is averaged over the
// vertices so that a slightly non-planar polygon is judged by its mean plane.
bool lies_in_plane(std::span<const dvec3> polygon, const dvec3& unit_normal, const dvec3& x) {
  double distance_sum = 0.0;
  double scale = 0.0;
  for (const dvec3& v : polygon) {
    distance_sum += glm::dot(unit_normal, v - x);
    scale = std::max(scale, glm::length(v - x));
  }
  const double mean_distance = distance_sum / static_cast<double>(polygon.size());
  return std::abs(mean_distance) <= kInPlaneTolerance * scale;
}

// --- Sutherland–Hodgman: one pass against a half-space ------------------------

// The part of the polygon where the signed distance h (affine in p) is
// ≥ 0: walk the edges prev → cur, keep every vertex with h ≥ 0, and insert
// the point where an edge strictly crosses h = 0, p = prev + t (cur − prev)
// with t = h(prev) / (h(prev) − h(cur)) ∈ (0, 1). A vertex exactly on the
// boundary is kept and creates no crossing, so no duplicate vertices appear.
// The winding is preserved. For a concave polygon the result can contain
// "bridge" edges along the boundary traversed once in each direction.
template <typename P, typename SignedDistance>
std::vector<P> clip_to_half_space(std::span<const P> polygon, SignedDistance h) {
  std::vector<P> clipped;
  if (polygon.empty()) return clipped;
  clipped.reserve(polygon.size() + 2);
  P prev = polygon.back();
  double h_prev = h(prev);
  for (const P& cur : polygon) {
    const double h_cur = h(cur);
    if ((h_prev < 0.0 && h_cur > 0.0) || (h_prev > 0.0 && h_cur < 0.0))
      clipped.push_back(prev + (cur - prev) * (h_prev / (h_prev - h_cur)));
    if (h_cur >= 0.0) clipped.push_back(cur);
    prev = cur;
    h_prev = h_cur;
  }
  return clipped;
}

// The part of the polygon above x's horizon, {p : n·(p − x) ≥ 0}. The bridge
// edges a concave polygon may gain contribute to Lambert's sum once in each
// direction and cancel exactly, since it is a sum over the boundary.
std::vector<dvec3> clip_to_upper_half_space(std::span<const dvec3> polygon, const dvec3& x, const dvec3& n) {
  return clip_to_half_space(polygon, [&](const dvec3& p) { return glm::dot(n, p - x); });
}

// --- 3-D: Lambert's formula -----------------------------------------------------

// One edge's term θ (n·γ) of Lambert's sum, for the edge from vertex p to
// vertex q: θ is the angle at x between d = p − x and d' = q − x, and γ the
// unit normal of the plane through x and the edge, along d × d'.
//
// Accuracy. The cross product is taken as d × (q − p), equal to d × d' since
// d' = d + (q − p), but computed from the edge vector itself: for a small,
// distant polygon d and d' are nearly parallel, and their own cross product
// (or that of their normalized directions) would cancel catastrophically,
// losing a factor distance/size of relative accuracy in γ; in n·γ, which is
// itself small when n looks at the polygon, the loss is squared. θ comes
// from atan2(|d × d'|, d·d'), accurate for all angles (acos of the cosine
// loses half the digits near 0 and π) and indifferent to the lengths of d
// and d'. An edge seen end-on (d × d' = 0 with d·d' > 0, e.g. a repeated
// vertex) subtends no angle and contributes nothing; d·d' < 0 there would
// put x on the edge, hence in the polygon's plane, which the caller
// excludes.
double lambert_edge_term(const dvec3& d, const dvec3& d_next, const dvec3& edge, const dvec3& n) {
  const dvec3 c = glm::cross(d, edge);
  const double c_length = glm::length(c);
  if (c_length == 0.0) return 0.0;
  const double theta = std::atan2(c_length, glm::dot(d, d_next));
  return theta * glm::dot(n, c) / c_length;
}

// Σ_i θ_i (n·γ_i) over the edges v_i → v_{i+1} (cyclically).
//
// Why this is twice the signed cosine-weighted solid angle: let Ω be the
// polygon's central projection from x onto the unit sphere and K the cone
// {x + t ω : ω ∈ Ω, 0 ≤ t ≤ 1}. The constant field n has zero divergence, so
// its flux out of K vanishes. K's boundary is the spherical cap Ω (outward
// normal ω) and one planar circular sector per edge (radius 1, angle θ_i,
// area θ_i / 2, normal ±γ_i). Hence
//     ∫_Ω n·ω dω = ½ Σ_i θ_i n·γ_i
// when every γ_i, along (v_i − x) × (v_{i+1} − x), points into K, which is
// the case when the vertices run counter-clockwise seen from outside the
// sphere (from beyond the polygon looking back at x), i.e. clockwise as seen
// from x, i.e. counter-clockwise around the polygon's normal N when N
// points away from x. The other winding flips every γ_i and negates the sum.
double lambert_sum(std::span<const dvec3> polygon, const dvec3& x, const dvec3& n) {
  double sum = 0.0;
  for (std::size_t i = 0; i < polygon.size(); ++i) {
    const dvec3& p = polygon[i];
    const dvec3& q = polygon[(i + 1) % polygon.size()];
    sum += lambert_edge_term(p - x, q - x, q - p, n);
  }
  return sum;
}

// --- 2-D helpers --------------------------------------------------------------

// z component of (a − o) × (b − o): positive when o → a → b turns left
// (counter-clockwise), zero when the three points are collinear.
double turn(const dvec2& o, const dvec2& a, const dvec2& b) {
  return (a.x - o.x) * (b.y - o.y) - (a.y - o.y) * (b.x - o.x);
}

}  // namespace

double signed_area(std::span<const dvec2> polygon) {
  double twice_area = 0.0;
  for (std::size_t i = 0; i < polygon.size(); ++i) {
    const dvec2& p = polygon[i];
    const dvec2& q = polygon[(i + 1) % polygon.size()];
    twice_area += p.x * q.y - p.y * q.x;
  }
  return 0.5 * twice_area;
}

namespace {

// Appends `p` to the chain being built in `hull`, first popping every vertex
// that would no longer be a strict left turn (a right turn or collinear).
// Vertices at index < `floor` belong to the finished lower chain and stay.
void push_left_turn(std::vector<dvec2>& hull, const dvec2& p, std::size_t floor) {
  while (hull.size() >= floor + 2 && turn(hull[hull.size() - 2], hull.back(), p) <= 0.0) hull.pop_back();
  hull.push_back(p);
}

// The part of `polygon` left of (or on) the directed line a → b, the inside
// of a counter-clockwise polygon's edge, by the signed distance (times
// |b − a|) s(p) = (b − a) × (p − a).
std::vector<dvec2> clip_by_half_plane(const std::vector<dvec2>& polygon, const dvec2& a, const dvec2& b) {
  return clip_to_half_space(std::span<const dvec2>(polygon), [&](const dvec2& p) { return turn(a, b, p); });
}

// Drops repeated consecutive vertices and vertices collinear with their
// neighbours (exactly: these arise when a subject vertex lies on a clip
// edge), cyclically.
std::vector<dvec2> drop_redundant_vertices(const std::vector<dvec2>& polygon) {
  std::vector<dvec2> kept;
  for (const dvec2& p : polygon)
    if (kept.empty() || p != kept.back()) kept.push_back(p);
  while (kept.size() > 1 && kept.front() == kept.back()) kept.pop_back();
  // Remove collinear vertices until none is left (each removal can make a
  // neighbour collinear only if the polygon is degenerate, so this ends fast).
  bool removed = true;
  while (removed && kept.size() >= 3) {
    removed = false;
    for (std::size_t i = 0; i < kept.size() && kept.size() >= 3; ++i) {
      const dvec2& prev = kept[(i + kept.size() - 1) % kept.size()];
      const dvec2& next = kept[(i + 1) % kept.size()];
      if (turn(prev, kept[i], next) == 0.0) {
        kept.erase(kept.begin() + static_cast<std::ptrdiff_t>(i));
        removed = true;
      }
    }
  }
  return kept;
}

}  // namespace

double polygon_form_factor(std::span<const dvec3> polygon, const dvec3& x, const dvec3& n) {
  if (polygon.size() < 3) return 0.0;
  const dvec3 area_vector = twice_vector_area(polygon);
  const double twice_area = glm::length(area_vector);
  if (twice_area == 0.0 || !std::isfinite(twice_area)) return 0.0;
  if (lies_in_plane(polygon, area_vector / twice_area, x)) return 0.0;

  // Below the horizon n·ω < 0: that part of the polygon sends no light to x.
  const std::vector<dvec3> upper = clip_to_upper_half_space(polygon, x, n);
  if (upper.size() < 3) return 0.0;

  // The central projection from x of a plane not through x is one-to-one,
  // so the projected simple polygon bounds a single region Ω, its boundary
  // traversed once in one direction: lambert_sum is +2∫ or −2∫ according
  // to the winding. After the clip Ω lies in the upper hemisphere, where
  // n·ω ≥ 0, so the integral is ≥ 0 and the absolute value recovers it for
  // either winding.
  return 0.5 * std::abs(lambert_sum(upper, x, n));
}

std::vector<dvec2> convex_hull(std::vector<dvec2> points) {
  std::sort(points.begin(), points.end(),
            [](const dvec2& a, const dvec2& b) { return a.x < b.x || (a.x == b.x && a.y < b.y); });
  points.erase(std::unique(points.begin(), points.end()), points.end());
  if (points.size() < 3) return points;

  // Lower chain left to right, then upper chain right to left, each keeping
  // only strict left turns; together they go around counter-clockwise.
  std::vector<dvec2> hull;
  hull.reserve(points.size() + 1);
  for (const dvec2& p : points) push_left_turn(hull, p, 0);
  const std::size_t lower_end = hull.size() - 1;  // the rightmost point starts the upper chain
  for (std::size_t i = points.size() - 1; i-- > 0;) push_left_turn(hull, points[i], lower_end);
  hull.pop_back();  // the upper chain ends where the lower one began
  return hull;
}

std::vector<dvec2> clip_convex(std::span<const dvec2> subject, std::span<const dvec2> clip) {
  if (subject.size() < 3 || clip.size() < 3) return {};
  std::vector<dvec2> result(subject.begin(), subject.end());
  for (std::size_t i = 0; i < clip.size() && !result.empty(); ++i)
    result = clip_by_half_plane(result, clip[i], clip[(i + 1) % clip.size()]);
  result = drop_redundant_vertices(result);
  if (result.size() < 3 || signed_area(result) <= 0.0) return {};
  return result;
}

}  // namespace pathlab::analytic
