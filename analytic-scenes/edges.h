// Where a model's radiance may jump, as the camera sees it, so that
// expected_image() can refine there instead of hoping two coarse grids
// notice (a silhouette or a plane's far edge a hair inside a pixel falls
// between the midpoints of every coarse grid, and two grids that both miss
// it agree).
//
// An edge is a set of view directions from the eye: (1 - t) a + t b for t in
// [0, 1], a and b points relative to the eye (the image of a straight world
// segment) or directions (points at infinity: an arc of a great circle of
// less than 180 degrees), or a mix (a ray's image). Curves (a sphere's
// silhouette, a sun's disk, a row of an environment map) are chains of such
// chords, each with the curve's own point halfway along it, from which the
// integrator bounds how far the curve strays from its chord.
#pragma once

#include "core/math.h"
#include "core/scene.h"

#include <functional>
#include <optional>
#include <string>
#include <vector>

namespace pathlab {

struct EdgeArc {
  dvec3 a{0.0}, b{0.0};
  std::optional<dvec3> mid;  // for a chord of a curve: the curve's point halfway (same convention)
};

class EdgeList {
 public:
  explicit EdgeList(const dvec3& eye) : eye_(eye) {}
  const dvec3& eye() const { return eye_; }
  const std::vector<EdgeArc>& arcs() const { return arcs_; }
  // Discontinuities the model knows of but cannot list (empty if none):
  // expected_image() falls back to its two-grid rule there, and says so.
  const std::string& unlisted() const { return unlisted_; }

  // A straight world segment.
  void segment(const dvec3& p0, const dvec3& p1);
  // Every edge of a mesh's triangles (its outline, its silhouette from any
  // eye, its creases) except those inside one flat face: shared, by vertex
  // index, by exactly two triangles of the same plane, side and material
  // (a quad's diagonal), across which nothing jumps.
  void mesh_edges(const Shape& shape);
  // The silhouette of a sphere seen from the eye (nothing from inside).
  void sphere_silhouette(const dvec3& centre, double radius);
  // The cone of directions at angle acos(cos_alpha) about `axis` (a sun's
  // disk), at infinity.
  void cone(const dvec3& axis, double cos_alpha);
  // A curve of directions at infinity, dir(s) for s in [s0, s1], in
  // `pieces` chords.
  void direction_curve(const std::function<dvec3(double)>& dir, double s0, double s1, int pieces);
  // A curve of world points, p(s) for s in [s0, s1], in `pieces` chords.
  void point_curve(const std::function<dvec3(double)>& p, double s0, double s1, int pieces);
  void note_unlisted(const std::string& what) { unlisted_ += (unlisted_.empty() ? "" : "; ") + what; }

 private:
  dvec3 eye_;
  std::vector<EdgeArc> arcs_;
  std::string unlisted_;
};

}  // namespace pathlab
