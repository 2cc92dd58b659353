#include "debugtools/path_compare.h"

#include <iterator>
#include <sstream>
#include <type_traits>

namespace pathlab {
namespace {

bool near(float a, float b, float tol) {
  return std::abs(a - b) <= tol * std::max(1.0f, std::max(std::abs(a), std::abs(b))) || (std::isinf(a) && a == b);
}
bool near(const vec3& a, const vec3& b, float tol) {
  return near(a.x, b.x, tol) && near(a.y, b.y, tol) && near(a.z, b.z, tol);
}
bool near(const vec2& a, const vec2& b, float tol) { return near(a.x, b.x, tol) && near(a.y, b.y, tol); }
bool near(const Ray& a, const Ray& b, float tol) {
  return near(a.origin, b.origin, tol) && near(a.dir, b.dir, tol) && near(a.tmax, b.tmax, tol);
}

int vertex_of(const PathEvent& e) {
  return std::visit(
      [](const auto& ev) {
        if constexpr (requires { ev.vertex; }) return ev.vertex;
        else return 0;
      },
      e);
}

// What differs between two events of the same kind: "" if nothing
// continuous differs beyond `tol`; `discrete` is set if an outcome differs.
struct Difference {
  std::string what;
  bool discrete = false;
};

Difference compare(const PathEvent& ea, const PathEvent& eb, float tol) {
  Difference d;
  // Every field of every event kind is compared; the first that differs is
  // named as "<what it is> (<field>)", e.g. "light visibility (visible)".
  auto check = [&](bool ok, const char* what) {
    if (!ok && d.what.empty()) d.what = what;
  };
  auto outcome = [&](bool ok, const char* what) {
    if (!ok && d.what.empty()) {
      d.what = what;
      d.discrete = true;
    }
  };
  std::visit(
      [&](const auto& a) {
        using T = std::decay_t<decltype(a)>;
        const T& b = std::get<T>(eb);
        if constexpr (std::is_same_v<T, CameraEvent>) {
          check(a.x == b.x && a.y == b.y, "camera ray (pixel x, y)");
          check(a.sample == b.sample, "camera ray (sample)");
          check(near(a.film, b.film, tol), "camera ray (film)");
          check(near(a.origin, b.origin, tol), "camera ray (origin)");
          check(near(a.dir, b.dir, tol), "camera ray (dir)");
        } else if constexpr (std::is_same_v<T, HitEvent>) {
          check(a.shape == b.shape, "surface hit (shape)");
          check(a.prim == b.prim, "surface hit (prim)");
          check(a.instance == b.instance, "surface hit (instance)");
          check(a.material == b.material, "surface hit (material)");
          check(a.front == b.front, "surface hit (front)");
          check(near(a.p, b.p, tol), "hit position (p)");
          check(near(a.n, b.n, tol), "hit normal (n)");
          check(near(a.throughput, b.throughput, tol), "throughput at the hit (throughput)");
          check(near(a.emitted, b.emitted, tol), "emission added (emitted)");
          check(near(a.emission_weight, b.emission_weight, tol), "emission added (emission_weight)");
          check(near(a.added, b.added, tol), "emission added (added)");
        } else if constexpr (std::is_same_v<T, EscapeEvent>) {
          check(near(a.emitted, b.emitted, tol), "environment added (emitted)");
          check(near(a.emission_weight, b.emission_weight, tol), "environment added (emission_weight)");
          check(near(a.added, b.added, tol), "environment added (added)");
        } else if constexpr (std::is_same_v<T, LightEvent>) {
          check(a.delta == b.delta, "light chosen (delta)");
          check(a.infinite == b.infinite, "light chosen (infinite)");
          check(a.light == b.light, "light chosen (light)");
          // The point is undefined for a light at infinity (LightEvent).
          check(a.infinite || b.infinite || near(a.point, b.point, tol), "light point (point)");
          check(near(a.wi, b.wi, tol), "light direction or pdf (wi)");
          check(near(a.dist, b.dist, tol), "light direction or pdf (dist)");
          check(near(a.pdf, b.pdf, tol), "light direction or pdf (pdf)");
          check(near(a.Le, b.Le, tol), "light radiance (Le)");
          // Before the ray: a sample rejected on one side only has no ray there.
          outcome(a.rejected == b.rejected, "light sample rejected (rejected: below the surface, black BSDF, no sample)");
          check(near(a.ray, b.ray, tol), "shadow ray (ray)");
          outcome(a.visible == b.visible, "light visibility (visible)");
          check(near(a.mis_weight, b.mis_weight, tol), "light MIS weight (mis_weight)");
          check(near(a.added, b.added, tol), "light added (added)");
        } else if constexpr (std::is_same_v<T, ScatterEvent>) {
          // Cosine sampling (strategy cosine) replaces the lobe: named first.
          check(a.cosine == b.cosine, "lobe (cosine)");
          check(a.lobe == b.lobe, "lobe (lobe)");
          check(a.impulse == b.impulse, "lobe (impulse)");
          check(near(a.wi, b.wi, tol), "scattered direction or pdf (wi)");
          check(near(a.pdf, b.pdf, tol), "scattered direction or pdf (pdf)");
          check(near(a.weight, b.weight, tol), "scattering weight (weight)");
          check(near(a.survival, b.survival, tol), "roulette survival (survival)");
          check(near(a.throughput, b.throughput, tol), "throughput (throughput)");
          check(near(a.next, b.next, tol), "continuation ray (next)");
        } else if constexpr (std::is_same_v<T, EndEvent>) {
          outcome(a.reason == b.reason, "why the path ended (reason)");
        }
      },
      ea);
  return d;
}

const char* kind_name(const PathEvent& e) {
  static constexpr const char* kNames[] = {"camera ray", "hit", "escape", "light sample", "scatter", "end"};
  static_assert(std::size(kNames) == std::variant_size_v<PathEvent>);
  return kNames[e.index()];
}

// Whether a floating-point difference can explain two paths that agree up to
// here and then record different kinds of event `a` and `b`: only through a decision taken by
// comparing computed values with a threshold, i.e.
//  - a ray that hits a surface in one path and escapes in the other (a
//    grazing or edge hit): a hit against an escape;
//  - a path that ends in one and goes on in the other by roulette, or by a
//    sampled direction with no density or weight (grazing): an end for
//    Roulette, Absorbed or NoSample (or Escaped: see the first case).
// A depth cap is an integer comparison, and a light sample missing from one
// path (next-event estimation skipped), an event of another vertex or extra
// events after a path's end are changes of the algorithm, not rounding.
bool flip_explains(const PathEvent& a, const PathEvent& b) {
  const auto ends_by_comparison = [](const PathEvent& e) {
    const auto* end = std::get_if<EndEvent>(&e);
    return end != nullptr && end->reason != PathEnd::MaxDepth;
  };
  const auto hit_or_escape = [](const PathEvent& e) {
    return std::holds_alternative<HitEvent>(e) || std::holds_alternative<EscapeEvent>(e);
  };
  if (vertex_of(a) != vertex_of(b)) return false;
  if (hit_or_escape(a) && hit_or_escape(b)) return true;
  return ends_by_comparison(a) || ends_by_comparison(b);
}

// Loose agreement of the geometric content of two events of one kind.
bool still_close(const PathEvent& ea, const PathEvent& eb) {
  const Difference loose = compare(ea, eb, 1e-2f);
  return loose.what.empty() || loose.discrete;
}

}  // namespace

PathDivergence first_divergence(const std::vector<PathEvent>& a, const std::vector<PathEvent>& b, float tolerance) {
  PathDivergence d;
  const std::size_t n = std::min(a.size(), b.size());
  for (std::size_t i = 0; i < n; ++i) {
    std::ostringstream why;
    if (a[i].index() != b[i].index() || vertex_of(a[i]) != vertex_of(b[i])) {
      d.identical = false;
      d.event = i;
      d.vertex = vertex_of(a[i]);
      // After an agreeing prefix: a flipped outcome if a threshold decision
      // explains the different kinds (flip_explains), else a real change.
      d.rounding = i > 0 && flip_explains(a[i], b[i]);
      why << "event " << i << ": different events, a " << kind_name(a[i]) << " at vertex " << vertex_of(a[i])
          << " and a " << kind_name(b[i]) << " at vertex " << vertex_of(b[i]);
      d.reason = why.str();
      return d;
    }
    const Difference diff = compare(a[i], b[i], tolerance);
    if (!diff.what.empty()) {
      d.identical = false;
      d.event = i;
      d.vertex = vertex_of(a[i]);
      d.rounding = diff.discrete || still_close(a[i], b[i]);
      why << "event " << i << " (vertex " << d.vertex << "): " << diff.what << " differs";
      d.reason = why.str();
      return d;
    }
  }
  if (a.size() != b.size()) {
    d.identical = false;
    d.event = n;
    d.vertex = n > 0 ? vertex_of(a[n - 1]) : 0;
    // Recorded paths end with their EndEvent, so a longer one went on past
    // an end the other agreed on: not a rounding difference.
    d.rounding = false;
    d.reason = "one path has more events";
  }
  return d;
}

}  // namespace pathlab
