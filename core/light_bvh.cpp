#include "core/light_bvh.h"

#include "core/simd/width1.h"

#include <algorithm>
#include <cfloat>
#include <cmath>
#include <numeric>

namespace pathlab {
namespace {

constexpr double kPiD = 3.14159265358979323846;

// A float no greater than c: a cone's cosine stored in a node must not make
// the cone narrower than the one computed.
float cos_down(double c) {
  c = std::clamp(c, -1.0, 1.0);
  float f = static_cast<float>(c);
  if (static_cast<double>(f) > c) f = std::nextafter(f, -2.0f);
  return std::max(f, -1.0f);
}

// The angle between unit vectors, accurate near 0 and pi.
double angle_between(const dvec3& a, const dvec3& b) {
  return 2.0 * std::atan2(glm::length(a - b), glm::length(a + b));
}

struct Cone {
  dvec3 axis;
  double theta;  // half-angle in [0, pi]
};

// The smallest cone holding cones a and b (pi: the whole sphere), widened by
// a hair for the rounding of the axis and the cosine stored in float.
Cone cone_union(const Cone& a, const Cone& b) {
  if (a.theta >= kPiD) return a;
  if (b.theta >= kPiD) return b;
  const double theta_d = angle_between(a.axis, b.axis);
  if (std::min(theta_d + b.theta, kPiD) <= a.theta) return a;
  if (std::min(theta_d + a.theta, kPiD) <= b.theta) return b;
  const double theta_o = 0.5 * (a.theta + theta_d + b.theta) + 1e-6;
  if (theta_o >= kPiD) return {a.axis, kPiD};
  const dvec3 w = glm::cross(a.axis, b.axis);
  const double len = glm::length(w);
  if (!(len > 1e-12)) return {a.axis, kPiD};  // opposite axes
  // Rotate a's axis towards b's by theta_o - theta_a (Rodrigues; k is
  // perpendicular to a.axis).
  const dvec3 k = w / len;
  const double r = theta_o - a.theta;
  const dvec3 axis = a.axis * std::cos(r) + glm::cross(k, a.axis) * std::sin(r);
  return {glm::normalize(axis), theta_o};
}

dvec3 centroid(const LightBounds& b) { return 0.5 * (dvec3(b.lo) + dvec3(b.hi)); }

double surface_area(const LightBounds& b) {
  const dvec3 d = dvec3(b.hi) - dvec3(b.lo);
  return 2.0 * (d.x * d.y + d.y * d.z + d.z * d.x);
}

// Conty Estevez & Kulla's orientation measure times power times area (the
// surface area orientation heuristic), stretched by `kr` against thin splits.
double saoh_cost(const LightBounds& b, double kr) {
  const double theta_o = std::acos(std::clamp(double(b.cos_o), -1.0, 1.0));
  const double theta_e = std::acos(std::clamp(double(b.cos_e), -1.0, 1.0));
  const double theta_w = std::min(theta_o + theta_e, kPiD);
  const double sin_o = std::sin(theta_o);
  const double m_omega = 2.0 * kPiD * (1.0 - std::cos(theta_o)) +
                         0.5 * kPiD *
                             (2.0 * theta_w * sin_o - std::cos(theta_o - 2.0 * theta_w) - 2.0 * theta_o * sin_o +
                              std::cos(theta_o));
  return b.phi * m_omega * surface_area(b) * kr;
}

}  // namespace

LightBounds merge(const LightBounds& a, const LightBounds& b) {
  LightBounds out;
  out.lo = glm::min(a.lo, b.lo);
  out.hi = glm::max(a.hi, b.hi);
  const Cone c = cone_union({glm::normalize(dvec3(a.axis)), std::acos(std::clamp(double(a.cos_o), -1.0, 1.0))},
                            {glm::normalize(dvec3(b.axis)), std::acos(std::clamp(double(b.cos_o), -1.0, 1.0))});
  out.axis = vec3(c.axis);
  out.cos_o = c.theta >= kPiD ? -1.0f : cos_down(std::cos(c.theta));
  out.cos_e = std::min(a.cos_e, b.cos_e);
  out.phi = a.phi + b.phi;
  out.two_sided = a.two_sided || b.two_sided;
  return out;
}

namespace {
constexpr lane1::One<std::uint64_t> kTrail{};    // a light's trail

width1::generic::BvhBounds<width1::D1, lane1::M> bounds_of(const LightBounds& b) {
  using namespace width1;
  return {lanes(dvec3(b.lo)), lanes(dvec3(b.hi)), lanes(dvec3(b.axis)), D1{b.cos_o}, D1{b.cos_e}, D1{b.phi},
          lane1::M{b.two_sided}};
}
}  // namespace

// importance, split, pick and share are core/simd/light_bvh-inl.h's generic
// code at width 1: the wavefront's vectorised stages walk the same source
// in double lanes.

double importance(const LightBounds& b, const LightQuery& q) {
  using namespace width1;
  return generic::bvh_importance(kScalarD, bounds_of(b), lanes(dvec3(q.p)), lanes(dvec3(q.n))).raw;
}

std::optional<std::uint32_t> LightBvh::split(double i0, double i1, std::uint32_t count) {
  using namespace width1;
  lane1::M valid;
  const D1 first = generic::bvh_split(kScalarD, D1{i0}, D1{i1}, D1{double(count)}, valid);
  if (!valid.raw) return std::nullopt;
  return static_cast<std::uint32_t>(first.raw);
}

LightBvh::LightBvh(std::vector<LightBounds> lights) {
  if (lights.empty()) return;
  trail_.assign(lights.size(), 0);
  std::vector<std::uint32_t> order(lights.size());
  std::iota(order.begin(), order.end(), 0u);
  nodes_.reserve(2 * lights.size() - 1);
  build(order, lights, 0, lights.size(), 0, 0);
  table_ = make_table();
}

LightBounds LightBvh::build(std::vector<std::uint32_t>& order, std::vector<LightBounds>& lights, std::size_t begin,
                            std::size_t end, std::uint64_t trail, int depth) {
  depth_ = std::max(depth_, depth);
  const std::size_t at = nodes_.size();
  nodes_.emplace_back();
  if (end - begin == 1) {
    const std::uint32_t l = order[begin];
    nodes_[at] = Node{lights[l], l, true};
    trail_[l] = trail;
    return lights[l];
  }
  dvec3 box_lo(DBL_MAX), box_hi(-DBL_MAX), c_lo(DBL_MAX), c_hi(-DBL_MAX);
  for (std::size_t i = begin; i < end; ++i) {
    const LightBounds& lb = lights[order[i]];
    box_lo = glm::min(box_lo, dvec3(lb.lo));
    box_hi = glm::max(box_hi, dvec3(lb.hi));
    c_lo = glm::min(c_lo, centroid(lb));
    c_hi = glm::max(c_hi, centroid(lb));
  }
  // Binned SAOH split (Conty Estevez & Kulla 2018, section 4.2), 12 buckets
  // per axis; past depth 32 (or when no split separates anything) the median
  // by centroid along the widest axis, so depth stays below 64 (the trail's
  // bits) for up to 2^32 lights.
  constexpr int kBuckets = 12;
  std::size_t mid = begin;
  if (depth < 32) {
    double best = DBL_MAX;
    int best_dim = -1, best_bucket = -1;
    const dvec3 extent = box_hi - box_lo;
    const double max_extent = std::max({extent.x, extent.y, extent.z});
    for (int dim = 0; dim < 3; ++dim) {
      if (!(c_hi[dim] > c_lo[dim])) continue;
      auto bucket_of = [&](const LightBounds& lb) {
        const int b = static_cast<int>(kBuckets * ((centroid(lb)[dim] - c_lo[dim]) / (c_hi[dim] - c_lo[dim])));
        return std::clamp(b, 0, kBuckets - 1);
      };
      LightBounds bucket[kBuckets];
      bool used[kBuckets] = {};
      for (std::size_t i = begin; i < end; ++i) {
        const LightBounds& lb = lights[order[i]];
        const int b = bucket_of(lb);
        bucket[b] = used[b] ? merge(bucket[b], lb) : lb;
        used[b] = true;
      }
      const double kr = extent[dim] > 0.0 ? max_extent / extent[dim] : 1.0;
      for (int s = 0; s + 1 < kBuckets; ++s) {
        LightBounds below, above;
        bool any_below = false, any_above = false;
        for (int b = 0; b < kBuckets; ++b) {
          if (!used[b]) continue;
          LightBounds& side = b <= s ? below : above;
          bool& any = b <= s ? any_below : any_above;
          side = any ? merge(side, bucket[b]) : bucket[b];
          any = true;
        }
        if (!any_below || !any_above) continue;
        const double cost = saoh_cost(below, kr) + saoh_cost(above, kr);
        if (cost < best) best = cost, best_dim = dim, best_bucket = s;
      }
    }
    if (best_dim >= 0) {
      const int dim = best_dim;
      const auto it = std::partition(order.begin() + std::ptrdiff_t(begin), order.begin() + std::ptrdiff_t(end),
                                     [&](std::uint32_t l) {
                                       const int b = static_cast<int>(
                                           kBuckets * ((centroid(lights[l])[dim] - c_lo[dim]) / (c_hi[dim] - c_lo[dim])));
                                       return std::clamp(b, 0, kBuckets - 1) <= best_bucket;
                                     });
      mid = static_cast<std::size_t>(it - order.begin());
    }
  }
  if (mid == begin || mid == end) {
    const dvec3 e = c_hi - c_lo;
    const int dim = e.x >= e.y && e.x >= e.z ? 0 : e.y >= e.z ? 1 : 2;
    mid = begin + (end - begin) / 2;
    std::nth_element(order.begin() + std::ptrdiff_t(begin), order.begin() + std::ptrdiff_t(mid),
                     order.begin() + std::ptrdiff_t(end), [&](std::uint32_t a, std::uint32_t b) {
                       const double ca = centroid(lights[a])[dim], cb = centroid(lights[b])[dim];
                       return ca < cb || (ca == cb && a < b);
                     });
  }
  const LightBounds first = build(order, lights, begin, mid, trail, depth + 1);
  const std::uint32_t second = static_cast<std::uint32_t>(nodes_.size());
  const LightBounds other = build(order, lights, mid, end, trail | (std::uint64_t{1} << depth), depth + 1);
  const LightBounds both = merge(first, other);
  nodes_[at] = Node{both, second, false};
  return both;
}

// The walks' Tree (core/simd/light_bvh-inl.h's BvhTable reads the same from
// node_table() in the lanes): the nodes themselves, whose floats the table
// holds as doubles.
struct LightBvh::Nodes {
  const std::vector<Node>& nodes;
  width1::D1 importance(lane1::I64 node, const width1::D3& p, const width1::D3& n) const {
    return width1::generic::bvh_importance(width1::kScalarD, bounds_of(nodes[static_cast<std::size_t>(node.raw)].bounds),
                                           p, n);
  }
  width1::D1 leaf(lane1::I64 node) const { return {nodes[static_cast<std::size_t>(node.raw)].leaf ? 1.0 : 0.0}; }
  width1::D1 index(lane1::I64 node) const { return {double(nodes[static_cast<std::size_t>(node.raw)].index)}; }
};

std::optional<LightBvh::Pick> LightBvh::pick(const LightQuery& q, std::uint32_t k, std::uint32_t count) const {
  if (nodes_.empty() || k >= count) return std::nullopt;
  using namespace width1;
  D1 light, share;
  generic::bvh_pick(kScalarD, kIndex, Nodes{nodes_}, lanes(dvec3(q.p)), lanes(dvec3(q.n)), D1{double(k)},
                    D1{double(count)}, lane1::M{true}, light, share);
  if (!(share.raw > 0.0)) return std::nullopt;
  return Pick{static_cast<std::uint32_t>(light.raw), static_cast<std::uint32_t>(share.raw)};
}

std::uint32_t LightBvh::share(const LightQuery& q, std::uint32_t light, std::uint32_t count) const {
  if (nodes_.empty() || light >= trail_.size() || count == 0) return 0;
  using namespace width1;
  const D1 share = generic::bvh_share(kScalarD, kIndex, kTrail, Nodes{nodes_}, trail_.data(), lanes(dvec3(q.p)),
                                      lanes(dvec3(q.n)), D1{double(light)}, D1{double(count)}, lane1::M{true});
  return static_cast<std::uint32_t>(share.raw);
}

std::vector<double> LightBvh::make_table() const {
  std::vector<double> table;
  table.reserve(nodes_.size() * kBvhFields);
  for (const Node& node : nodes_) {
    const LightBounds& b = node.bounds;
    double f[kBvhFields] = {};
    for (int c = 0; c < 3; ++c) {
      f[kBvhLo + c] = b.lo[c];
      f[kBvhHi + c] = b.hi[c];
      f[kBvhAxis + c] = b.axis[c];
    }
    f[kBvhCosO] = b.cos_o;
    f[kBvhCosE] = b.cos_e;
    f[kBvhPhi] = b.phi;
    f[kBvhTwoSided] = b.two_sided ? 1.0 : 0.0;
    f[kBvhIndex] = node.index;
    f[kBvhLeaf] = node.leaf ? 1.0 : 0.0;
    table.insert(table.end(), std::begin(f), std::end(f));
  }
  return table;
}

}  // namespace pathlab
