// A bounding volume hierarchy over the emitters, for picking one light out of
// many in proportion to an estimate of what it sends to a shading point
// (`render.light_sampler: bvh`; Conty Estevez & Kulla 2018, "Importance
// sampling of many lights with adaptive tree splitting"; the design of
// pbrt-v4's BVHLightSampler).
//
// Every node bounds its lights by a box, a cone of normals (axis, half-angle
// theta_o; "two-sided" when some light emits on both faces) and the
// emission's spread about a normal (theta_e = pi/2 for Lambertian emitters),
// and carries their summed power. importance() turns a node and a shading
// point into a weight that bounds from above, up to the constant, how much
// of that power can reach the point (LightBounds below gives the formula).
//
// Picking is exact on the grid of the random numbers: a LightChoice number
// is a multiple of 2^-24 (core/rng.h), so it is an integer k in [0, 2^24).
// The tree receives a range of `count` grid points; at each node the range
// is cut in two, the first child getting round(count * I0 / (I0 + I1)) of
// them (split() below), and k goes down to the child whose part holds it,
// re-based to that part (the uniform number re-scaled). The probability of a
// light is then exactly its leaf's share / 2^24, and share() computes that
// share by walking the same cuts from the root to the light's leaf along its
// bit trail, with the same arithmetic, so the pdf is the probability the
// traversal used. A light whose share rounds to 0 is never picked and has
// probability 0; both children of importance 0 (the node's bounds let light
// through, neither child's does) end the walk with no light, for sample and
// share alike.
#pragma once

#include "core/math.h"

#include <cstdint>
#include <optional>
#include <vector>

namespace pathlab {

// A shading point as light selection sees it: the position, and the unit
// normal of the side of the surface that receives light (every reflection
// pathlab models stays on one side of the geometric surface; transmission is
// an impulse, never connected to a light). n = 0: no side, every direction
// counts (a bare point, as the tests and trace tools use).
struct LightQuery {
  vec3 p{0.0f};
  vec3 n{0.0f};
};

// What a node knows of the lights below it.
struct LightBounds {
  vec3 lo{0.0f}, hi{0.0f};  // box
  vec3 axis{0.0f, 0.0f, 1.0f};
  float cos_o = 1.0f;      // every normal lies within theta_o of axis
  float cos_e = 0.0f;      // emission leaves within theta_e of the normal
  double phi = 0.0;        // summed power (the LightSampler's weights)
  bool two_sided = false;  // some light emits on both faces: normals are +-axis
};

// The union of two bounds: box, the smallest cone holding both cones, the
// wider emission, powers summed in double.
LightBounds merge(const LightBounds& a, const LightBounds& b);

// The importance of bounds `b` for shading point `q` (>= 0, finite):
//   phi * cos(theta') * cos(theta'_i) / d^2
// with, for c the box's centre and r the radius of its bounding sphere,
//   d^2 = max(|q.p - c|^2, r^2 / 4) (a point near the centre of a big node
//     still tells its nearer child from the other; a tiny light's weight stays finite);
//   theta_b the half-angle the sphere subtends at q.p (pi inside it);
//   theta_w the angle between axis and c -> q.p (|cos| when two-sided);
//   theta' = max(0, theta_w - theta_o - theta_b): 0 if theta' >= theta_e
//     (no light in the node can face the point);
//   theta_i the angle between q.n and q.p -> c, theta'_i = max(0, theta_i - theta_b):
//     0 if theta'_i >= pi/2 (the node lies wholly behind the surface); no
//     factor when q.n = 0.
// Computed in double, with cosines and sines of differences (no acos).
double importance(const LightBounds& b, const LightQuery& q);

// The layout of LightBvh::node_table(): per node, its bounds, its index and
// whether it is a leaf, as doubles (core/simd/light_bvh-inl.h reads it).
enum BvhField : int {
  kBvhLo = 0, kBvhHi = 3, kBvhAxis = 6, kBvhCosO = 9, kBvhCosE = 10, kBvhPhi = 11, kBvhTwoSided = 12,
  kBvhIndex = 13, kBvhLeaf = 14, kBvhFields = 16,
};

class LightBvh {
 public:
  // Lights 0 .. n-1 with their bounds (each phi > 0). Empty: no tree.
  explicit LightBvh(std::vector<LightBounds> lights);

  bool empty() const { return nodes_.empty(); }
  std::size_t node_count() const { return nodes_.size(); }
  int depth() const { return depth_; }

  struct Pick {
    std::uint32_t light;
    std::uint32_t share;  // grid points of the range that lead to it
  };
  // The light that grid point k (0 <= k < count) of a range of `count`
  // points leads to, and its share of them; nothing when the walk ends at
  // a node whose children both have importance 0 (or the root has none).
  std::optional<Pick> pick(const LightQuery& q, std::uint32_t k, std::uint32_t count) const;
  // The share of light `light` among `count` points: what pick() gives it.
  std::uint32_t share(const LightQuery& q, std::uint32_t light, std::uint32_t count) const;

  // How a range of `count` points is cut between children of importance
  // i0 and i1: the first child's part, or nothing when both are 0.
  static std::optional<std::uint32_t> split(double i0, double i1, std::uint32_t count);

  // The tree as pick() and share() walk it (core/simd/light_bvh-inl.h, at
  // width 1 here and in the wavefront's vectorised stages' lanes): the
  // nodes as a table of kBvhFields doubles each (BvhField), in order, and
  // per light the trail share() follows.
  const std::vector<double>& node_table() const { return table_; }
  const std::vector<std::uint64_t>& trails() const { return trail_; }

 private:
  struct Node {
    LightBounds bounds;
    std::uint32_t index = 0;  // leaf: the light; interior: the second child (the first is next)
    bool leaf = false;
  };
  LightBounds build(std::vector<std::uint32_t>& order, std::vector<LightBounds>& lights, std::size_t begin,
                    std::size_t end, std::uint64_t trail, int depth);
  std::vector<double> make_table() const;
  struct Nodes;  // the tree as the generic walks read it at width 1 (light_bvh.cpp)

  std::vector<Node> nodes_;
  std::vector<double> table_;  // node_table()
  std::vector<std::uint64_t> trail_;  // per light: bit d set = child 1 at depth d
  int depth_ = 0;
};

}  // namespace pathlab
