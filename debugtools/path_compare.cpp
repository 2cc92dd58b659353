#include "debugtools/path_compare.h"

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
          check(near(a.film, b.film, tol) && near(a.origin, b.origin, tol) && near(a.dir, b.dir, tol), "camera ray");
        } else if constexpr (std::is_same_v<T, HitEvent>) {
          check(a.shape == b.shape && a.instance == b.instance && a.material == b.material, "surface hit");
          check(near(a.p, b.p, tol), "hit position");
          check(near(a.added, b.added, tol) && near(a.emission_weight, b.emission_weight, tol), "emission added");
        } else if constexpr (std::is_same_v<T, EscapeEvent>) {
          check(near(a.added, b.added, tol), "environment added");
        } else if constexpr (std::is_same_v<T, LightEvent>) {
          check(a.delta == b.delta && a.light == b.light, "light chosen");
          check(near(a.wi, b.wi, tol) && near(a.pdf, b.pdf, tol), "light direction or pdf");
          check(near(a.ray, b.ray, tol), "shadow ray");
          outcome(a.rejected == b.rejected, "light sample rejected (below the surface, black BSDF, no sample)");
          outcome(a.visible == b.visible, "light visibility");
          check(near(a.added, b.added, tol), "light added");
        } else if constexpr (std::is_same_v<T, ScatterEvent>) {
          check(a.lobe == b.lobe && a.impulse == b.impulse, "lobe");
          check(near(a.wi, b.wi, tol) && near(a.pdf, b.pdf, tol), "scattered direction or pdf");
          check(near(a.throughput, b.throughput, tol), "throughput");
          check(near(a.next, b.next, tol), "continuation ray");
        } else if constexpr (std::is_same_v<T, EndEvent>) {
          outcome(a.reason == b.reason, "why the path ended");
        }
      },
      ea);
  return d;
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
      // A different kind of event after an agreeing prefix: one path went on
      // where the other ended, or took another branch - a flipped outcome.
      d.rounding = i > 0;
      why << "event " << i << ": different events at vertex " << vertex_of(a[i]) << " and " << vertex_of(b[i]);
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
    d.rounding = n > 0;
    d.reason = "one path has more events";
  }
  return d;
}

}  // namespace pathlab
