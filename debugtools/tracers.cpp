#include "debugtools/tracers.h"

#include "core/error.h"
#include "reference/reference_tracer.h"
#include "wavefront/wavefront_tracer.h"

namespace pathlab {

std::unique_ptr<Tracer> make_tracer(const std::string& name, const CompiledScene& scene, const RenderSettings& settings) {
  if (name == "reference") return std::make_unique<ReferenceTracer>(scene, settings);
  if (name == "wavefront") return std::make_unique<WavefrontTracer>(scene, settings);
  throw InputError("unknown tracer '" + name + "' (expected reference or wavefront)");
}

}  // namespace pathlab
