// A recorded path as geometry: one polyline for the path (camera -> each
// vertex -> the escape or termination point) and a two-point line per shadow
// ray, each point carrying what happened there. The VTK export
// (vtk_export.h) writes these lines; the GUI projects their points over the
// image. Arrays and flags are documented in docs/path-vtk.md.
#pragma once

#include "core/math.h"
#include "debugtools/path_recorder.h"

#include <cstdint>
#include <vector>

namespace pathlab {

// Bits of PathPoint::flags.
enum PathPointFlag : std::uint32_t {
  kPointImpulse = 1u << 0,     // the vertex scattered by an impulse (mirror)
  kPointNeeVisible = 1u << 1,  // a shadow ray from this vertex reached its light (on a shadow
                               // line: this shadow ray did)
  kPointRoulette = 1u << 2,    // Russian roulette ended the path here
  kPointCamera = 1u << 3,      // the ray origin on the camera
  kPointEscape = 1u << 4,      // the end of an escaping ray, drawn at a finite length
  kPointLight = 1u << 5,       // the light end of a shadow ray
};

struct PathPoint {
  vec3 p{0.0f};
  int depth = 0;               // 0 = camera, k = vertex k (an escape point: the vertex it would have been)
  Spectrum throughput{1.0f};   // arriving at the point
  Spectrum added{0.0f};        // radiance added here (emission found + NEE of this vertex)
  float pdf = 0.0f;            // of the direction that left the point (scatter or light sample); 0 = none
  int lobe = -1;               // Lobe that scattered here, -1 = none
  std::uint32_t flags = 0;
};

struct PathLine {
  enum class Kind : std::uint8_t { Path = 0, Shadow = 1 };
  Kind kind = Kind::Path;
  std::uint32_t sample = 0;
  std::vector<PathPoint> points;
};

// The lines of one recorded path: the path polyline first, then one line per
// `light` event in event order. Escaping rays and shadow rays to the
// environment end `escape_length` from where they start.
std::vector<PathLine> path_lines(const PathRecorder& path, std::uint32_t sample, float escape_length);

}  // namespace pathlab
