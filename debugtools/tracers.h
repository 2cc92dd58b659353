// The tracers by name, for every tool that lets a user choose one (the CLI's
// --tracer, pathlab-debug's tracer menu, converge's --tracers).
#pragma once

#include "core/tracer.h"

#include <memory>
#include <string>

namespace pathlab {

// "reference" or "wavefront"; anything else is an InputError naming both.
std::unique_ptr<Tracer> make_tracer(const std::string& name, const CompiledScene& scene, const RenderSettings& settings);

}  // namespace pathlab
