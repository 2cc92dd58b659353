#include "core/bsdf/energy.h"

#include "core/bsdf/closure.h"
#include "core/bsdf/disney.h"
#include "core/bsdf/disney-inl.h"
#include "core/bsdf/quadrature.h"
#include "core/simd/width1.h"

#include <map>
#include <mutex>
#include <vector>

namespace pathlab::disney {

namespace {

// The specular and clearcoat albedos: a kGrid x kGrid midpoint rule over
// the square of the lobe's own (vndf) sampler, with u.x = 1 - (1 - s)^3 so
// that the rule resolves the lobe's tail, which the sampler packs into
// u.x -> 1. The diffuse family's largest albedo: adaptive quadrature at
// kDiffuseViews (its retro-reflection at grazing views is a feature the
// midpoint rule resolves only to 1e-2).
constexpr int kGrid = 64;
// Table points per interval between entries (the envelope's resolution).
constexpr int kSub = 4;
// The first entry stands for view cosines in (0, m_1]: measured at 1e-4,
// since exactly at 0 nothing is reflected (the view is in the surface).
constexpr float kSmallestMu = 1e-4f;
constexpr float kDiffuseViews[] = {1e-4f, 1e-3f, 0.01f, 0.05f, 0.1f, 0.25f, 0.5f, 0.75f, 1.0f};

vec3 view(float mu, float azimuth) {
  const float s = std::sqrt(std::max(0.0f, 1.0f - mu * mu));
  return vec3(s * std::cos(azimuth), s * std::sin(azimuth), mu);
}

// Directional albedo of one family seen from wo: the mean of f cos / pdf
// over the substituted midpoint grid of its vndf sampler (every weight is
// bounded).
Spectrum family_albedo(const Closure& c, SampledLobe lobe, const vec3& wo) {
  dvec3 sum(0.0);
  for (int i = 0; i < kGrid; ++i) {
    const double s = (i + 0.5) / kGrid;
    const double jacobian = 3.0 * (1.0 - s) * (1.0 - s);
    const float ux = static_cast<float>(1.0 - (1.0 - s) * (1.0 - s) * (1.0 - s));
    for (int j = 0; j < kGrid; ++j) {
      const vec2 u(ux, (static_cast<float>(j) + 0.5f) / kGrid);
      const auto wi = lobe_sample(c, lobe, wo, u, BsdfSampling::Vndf);
      if (!wi) continue;  // below the surface: reflects nothing
      const float pdf = lobe_pdf(c, lobe, wo, *wi, BsdfSampling::Vndf);
      if (!(pdf > 0.0f)) continue;
      sum += jacobian * dvec3(lobe_eval(c, lobe, wo, *wi)) / static_cast<double>(pdf);
    }
  }
  return Spectrum(sum / static_cast<double>(kGrid * kGrid));
}

// The diffuse family's albedo seen from view cosine mu, by quadrature.
Spectrum diffuse_albedo(const Closure& c, float mu) {
  const vec3 wo = view(mu, 0.0f);
  return Spectrum(quadrature::integrate_directions(
      [&](const vec3& wi) { return dvec3(lobe_eval(c, SampledLobe::Diffuse, wo, wi)); }, {}, 1e-5));
}

// The largest albedo over the view azimuths that matter: one for an
// isotropic lobe; along, across and between the tangents otherwise.
Spectrum worst_albedo(const Closure& c, SampledLobe lobe, float mu) {
  const bool isotropic = c.ax == c.ay || lobe != SampledLobe::Specular;
  Spectrum worst(0.0f);
  for (const float azimuth : {0.0f, 0.25f * kPi, 0.5f * kPi}) {
    worst = glm::max(worst, family_albedo(c, lobe, view(std::max(mu, kSmallestMu), azimuth)));
    if (isotropic) break;
  }
  return worst;
}

EnergyTables compute(const Closure& compensated) {
  Closure c = compensated;
  c.energy = EnergyTables{};  // the lobes as Burley defines them
  constexpr int kPoints = (kEnergyTableSize - 1) * kSub + 1;
  std::vector<Spectrum> es(kPoints);
  std::vector<float> ec(kPoints, 0.0f);  // the clearcoat is white: one channel
  Spectrum diffuse_max(0.0f);
  for (int p = 0; p < kPoints; ++p) {
    const float x = static_cast<float>(p) / static_cast<float>(kPoints - 1);
    const float mu = x * x;
    es[p] = worst_albedo(c, SampledLobe::Specular, mu);
    if (c.clearcoat > 0.0f) ec[p] = worst_albedo(c, SampledLobe::Clearcoat, mu).x;
  }
  for (const float mu : kDiffuseViews) diffuse_max = glm::max(diffuse_max, diffuse_albedo(c, mu));
  EnergyTables t;
  t.on = true;
  for (int i = 0; i < kEnergyTableSize; ++i) {
    // Largest over the two intervals around entry i.
    Spectrum s(0.0f);
    float k = 0.0f;
    for (int p = std::max(0, (i - 1) * kSub); p <= std::min(kPoints - 1, (i + 1) * kSub); ++p) {
      s = glm::max(s, es[p]);
      k = std::max(k, ec[p]);
    }
    t.specular[i] = glm::min(Spectrum(1.0f), s + kEnergyMargin);
    t.coat[i] = c.clearcoat > 0.0f ? std::min(1.0f, k + kEnergyMargin) : 0.0f;
  }
  t.diffuse_scale = Spectrum(1.0f) / glm::max(Spectrum(1.0f), diffuse_max + kEnergyMargin);
  return t;
}

}  // namespace

Spectrum EnergyTables::specular_transmit(float mu) const {
  using namespace width1;
  return scalars(generic::specular_transmit(kScalar, F{mu}, [&](F i) { return lanes(specular[static_cast<int>(i.raw)]); }));
}

float EnergyTables::coat_transmit(float mu) const {
  using namespace width1;
  return generic::coat_transmit(kScalar, F{mu}, [&](F i) { return F{coat[static_cast<int>(i.raw)]}; }).raw;
}

EnergyTables make_energy_tables(const Closure& c) {
  static std::mutex mutex;
  static std::map<std::array<float, 17>, EnergyTables> cache;
  const std::array<float, 17> key{c.lambert.x, c.diffuse.x, c.diffuse.y, c.diffuse.z, c.roughness, c.subsurface,
                                  c.sheen.x,   c.sheen.y,   c.sheen.z,   c.specular,  c.spec0.x,  c.spec0.y,
                                  c.spec0.z,   c.ax,        c.ay,        c.clearcoat, c.clearcoat_alpha};
  {
    const std::lock_guard<std::mutex> lock(mutex);
    if (const auto it = cache.find(key); it != cache.end()) return it->second;
  }
  const EnergyTables t = compute(c);
  const std::lock_guard<std::mutex> lock(mutex);
  return cache.emplace(key, t).first->second;
}

}  // namespace pathlab::disney
