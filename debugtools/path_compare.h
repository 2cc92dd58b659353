// Comparing two recorded paths of the same pixel sample (the reference's and
// the wavefront's), event by event, to find where they part.
#pragma once

#include "debugtools/path_recorder.h"

#include <string>
#include <vector>

namespace pathlab {

struct PathDivergence {
  bool identical = true;  // every event agrees within the tolerance
  // The paths are the same path up to their parting, which a floating-point
  // difference explains: they part on a discrete outcome (a visibility, a
  // roulette draw, a hit against an escape, an end by roulette or by a
  // sample with no density) or on values that still agree to 1e-2, never on
  // an unrelated path (different camera ray, direction, surface) or a
  // change of the algorithm (a light sample one path skips, an end by the
  // depth cap, events past a path's end).
  bool rounding = true;
  std::size_t event = 0;  // index of the first event that differs
  int vertex = 0;         // its vertex
  std::string reason;     // what differs, for people
};

// Events agree if they are of the same kind at the same vertex, their
// discrete outcomes and indices are equal, and every other field (positions,
// normals, directions, rays, pdfs, weights, radiance, contributions) agrees
// within `tolerance` relative (absolute below 1). Every field of every event
// kind is compared; `reason` names the first that differs, in parentheses
// ("event 3 (vertex 1): light visibility (visible) differs").
PathDivergence first_divergence(const std::vector<PathEvent>& a, const std::vector<PathEvent>& b, float tolerance);

}  // namespace pathlab
