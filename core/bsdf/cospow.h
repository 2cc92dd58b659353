// The cosine-power (Phong) lobe about an axis r: the analytic approximation
// of a microfacet lobe from the course notes. Density in solid angle
//   p(wi) = (n + 1) / (2 pi) cos^n(angle between wi and r),  on the half of
// the sphere around r (directions more than 90 degrees from r: 0).
// The exponent comes from the microfacet alpha by Walter et al.'s
// Beckmann-Phong correspondence n = 2 / alpha^2 - 2. Sampling and density
// are written once over vectors in core/bsdf/cospow-inl.h (the Disney
// model's glossy lobes under `bsdf_sampling: cospow`, disney-inl.h's
// CospowLobes).
#pragma once

namespace pathlab::cospow {

// Capped at 1e6 (alpha ~ 1.4e-3): far narrower lobes only lose float
// precision in the direction (cos = 1 - 5e-7 is 8 ulps from 1).
inline constexpr float kMaxExponent = 1e6f;
// n = 2 / alpha^2 - 2 in [0, kMaxExponent] (cospow-inl.h's cospow_exponent
// at width 1; core/bsdf/disney.cpp).
float exponent_from_alpha(float alpha);

}  // namespace pathlab::cospow
