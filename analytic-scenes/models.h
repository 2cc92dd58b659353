// The models, one file each; make_analytic_model() picks by name.
#pragma once

#include "analytic-scenes/analytic_model.h"

namespace pathlab::analytic {

std::unique_ptr<AnalyticModel> make_furnace(const Scene& scene);
std::unique_ptr<AnalyticModel> make_sphere_in_uniform_light(const Scene& scene);
std::unique_ptr<AnalyticModel> make_penumbra(const Scene& scene);
std::unique_ptr<AnalyticModel> make_rough_sphere_in_environment(const Scene& scene);
std::unique_ptr<AnalyticModel> make_glass_sphere_in_environment(const Scene& scene);
std::unique_ptr<AnalyticModel> make_textured_room(const Scene& scene);

// Radiance reaching the eye inside a closed Lambert room of albedo rho that
// emits Le everywhere, counting paths of at most `max_depth` bounces
// (-1 = any): Le (1 + rho + ... + rho^D) per channel.
Spectrum furnace_radiance(const Spectrum& Le, const Spectrum& rho, int max_depth);

}  // namespace pathlab::analytic
