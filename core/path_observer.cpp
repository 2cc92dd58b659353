#include "core/path_observer.h"

namespace pathlab {

const char* path_end_name(PathEnd end) {
  switch (end) {
    case PathEnd::Escaped: return "escaped";
    case PathEnd::MaxDepth: return "max_depth";
    case PathEnd::Absorbed: return "absorbed";
    case PathEnd::Roulette: return "roulette";
    case PathEnd::NoSample: return "no_sample";
  }
  return "?";
}

const char* light_rejection_name(LightRejection r) {
  switch (r) {
    case LightRejection::None: return "none";
    case LightRejection::NoSample: return "no_sample";
    case LightRejection::BelowSurface: return "below_surface";
    case LightRejection::BlackBsdf: return "black_bsdf";
  }
  return "?";
}

}  // namespace pathlab
