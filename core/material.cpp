#include "core/material.h"

#include "core/scene.h"

#include <algorithm>

namespace pathlab {

const char* lobe_name(Lobe lobe) {
  switch (lobe) {
    case Lobe::Lambert: return "lambert";
    case Lobe::MirrorImpulse: return "mirror";
    case Lobe::DisneyDiffuse: return "disney-diffuse";
    case Lobe::Sheen: return "sheen";
    case Lobe::Specular: return "specular";
    case Lobe::Clearcoat: return "clearcoat";
    case Lobe::DielectricReflection: return "dielectric-reflection";
    case Lobe::DielectricTransmission: return "dielectric-transmission";
    case Lobe::Count: break;
  }
  return "?";
}

const char* material_type_name(MaterialType type) {
  switch (type) {
    case MaterialType::Diffuse: return "diffuse";
    case MaterialType::Mirror: return "mirror";
    case MaterialType::Emissive: return "emissive";
    case MaterialType::Disney: return "disney";
    case MaterialType::Dielectric: return "dielectric";
  }
  return "?";
}

const char* bsdf_sampling_name(BsdfSampling s) { return s == BsdfSampling::Vndf ? "vndf" : "cospow"; }

std::optional<BsdfSampling> parse_bsdf_sampling(std::string_view name) {
  if (name == "vndf") return BsdfSampling::Vndf;
  if (name == "cospow") return BsdfSampling::Cospow;
  return std::nullopt;
}

const char* shading_path_name(ShadingPath p) {
  switch (p) {
    case ShadingPath::LambertOnly: return "lambert-only";
    case ShadingPath::Disney: return "disney";
    case ShadingPath::DisneyClearcoat: return "disney+clearcoat";
    case ShadingPath::General: return "general";
  }
  return "?";
}

bool Material::scatters() const {
  switch (type) {
    case MaterialType::Diffuse:
    case MaterialType::Mirror: return !is_black(albedo) || texture_of(MaterialParam::Albedo) != nullptr;
    case MaterialType::Emissive: return false;
    case MaterialType::Disney: return true;  // Schlick Fresnel reflects at grazing angles whatever the colours
    case MaterialType::Dielectric:
      return !is_black(glass.reflectance) || !is_black(glass.transmittance) ||
             texture_of(MaterialParam::GlassReflectance) != nullptr ||
             texture_of(MaterialParam::GlassTransmittance) != nullptr;
  }
  return false;
}

void Material::set_texture(MaterialParam p, const TextureRef& texture) {
  for (TexturedParam& t : textured)
    if (t.param == p) {
      t.texture = texture;
      return;
    }
  textured.push_back({p, texture});
  if (p == MaterialParam::Emission) emission_textured = true;
}

const TexturedParam* Material::texture_of(MaterialParam p) const {
  for (const TexturedParam& t : textured)
    if (t.param == p) return &t;
  return nullptr;
}

LobeMask Material::lobes() const {
  switch (type) {
    case MaterialType::Diffuse: return lobe_bit(Lobe::Lambert);
    case MaterialType::Mirror: return lobe_bit(Lobe::MirrorImpulse);
    case MaterialType::Emissive: return 0;
    case MaterialType::Disney: {
      // A textured parameter may take any value: count the lobe it may switch on.
      const bool metallic_below_1 = disney.metallic < 1.0f || texture_of(MaterialParam::Metallic);
      LobeMask m = lobe_bit(Lobe::Specular);
      if (metallic_below_1) m |= lobe_bit(Lobe::DisneyDiffuse);
      if (metallic_below_1 && (disney.sheen > 0.0f || texture_of(MaterialParam::Sheen))) m |= lobe_bit(Lobe::Sheen);
      if (disney.clearcoat > 0.0f || texture_of(MaterialParam::Clearcoat)) m |= lobe_bit(Lobe::Clearcoat);
      return m;
    }
    case MaterialType::Dielectric:
      return lobe_bit(Lobe::DielectricReflection) | lobe_bit(Lobe::DielectricTransmission);
  }
  return 0;
}

Material diffuse_material(const Spectrum& albedo) {
  Material m;
  m.name = "diffuse";
  m.albedo = albedo;
  m.closure = disney::lambert_closure(albedo);
  return m;
}

Material disney_material(const DisneyParams& params) {
  Material m;
  m.name = "disney";
  m.type = MaterialType::Disney;
  m.disney = params;
  m.closure = disney::make_closure(params);
  return m;
}

Material dielectric_material(const DielectricParams& params) {
  Material m;
  m.name = "dielectric";
  m.type = MaterialType::Dielectric;
  m.glass = params;
  return m;
}

namespace {

float clamp01(float v) { return std::clamp(v, 0.0f, 1.0f); }
Spectrum clamp01(const Spectrum& c) { return glm::clamp(c, Spectrum(0.0f), Spectrum(1.0f)); }

}  // namespace

void evaluate_textured(const Material& m, const Textures& textures, const TextureFootprint& at, SurfaceParams* out) {
  out->albedo = m.albedo;
  out->emission = m.emission;
  out->glass = m.glass;
  DisneyParams p = m.disney;
  for (const TexturedParam& t : m.textured) {
    const TextureRef& r = t.texture;
    switch (t.param) {
      case MaterialParam::Albedo: out->albedo = clamp01(textures.color(r, at)); break;
      case MaterialParam::Emission: out->emission = emission_at(m, &textures, at.uv); break;
      case MaterialParam::GlassReflectance: out->glass.reflectance = clamp01(textures.color(r, at)); break;
      case MaterialParam::GlassTransmittance: out->glass.transmittance = clamp01(textures.color(r, at)); break;
      case MaterialParam::BaseColor: p.base_color = clamp01(textures.color(r, at)); break;
      case MaterialParam::Metallic: p.metallic = clamp01(textures.number(r, at)); break;
      case MaterialParam::Subsurface: p.subsurface = clamp01(textures.number(r, at)); break;
      case MaterialParam::Specular: p.specular = clamp01(textures.number(r, at)); break;
      case MaterialParam::SpecularTint: p.specular_tint = clamp01(textures.number(r, at)); break;
      case MaterialParam::Roughness: p.roughness = clamp01(textures.number(r, at)); break;
      case MaterialParam::Anisotropic: p.anisotropic = clamp01(textures.number(r, at)); break;
      case MaterialParam::Sheen: p.sheen = clamp01(textures.number(r, at)); break;
      case MaterialParam::SheenTint: p.sheen_tint = clamp01(textures.number(r, at)); break;
      case MaterialParam::Clearcoat: p.clearcoat = clamp01(textures.number(r, at)); break;
      case MaterialParam::ClearcoatGloss: p.clearcoat_gloss = clamp01(textures.number(r, at)); break;
    }
  }
  // The closure from the evaluated parameters, as configure_shading()
  // builds an untextured material's (energy compensation is refused with
  // textures at load: its tables are built per material, not per hit).
  // Only the code that reads it pays for it: a Lambert material's closure is
  // read by the general shading path alone (the closure holds the energy
  // tables, some 500 bytes, so building it per hit is not free).
  if (m.type == MaterialType::Disney) disney::set_closure(p, &out->closure);
  else if (m.shading.path == ShadingPath::General) out->closure = disney::lambert_closure(out->albedo);
}

Spectrum emission_at(const Material& m, const Textures* textures, vec2 uv) {
  if (textures == nullptr) return m.emission;
  const TexturedParam* t = m.texture_of(MaterialParam::Emission);
  return t == nullptr ? m.emission : glm::max(textures->color(t->texture, TextureFootprint{uv, 0.0f}), Spectrum(0.0f));
}

ShadingPath shading_path_for(LobeMask lobes, bool force_general) {
  if (force_general) return ShadingPath::General;
  if ((lobes & kDisneyLobeMask) == 0) return ShadingPath::LambertOnly;
  if ((lobes & lobe_bit(Lobe::Clearcoat)) == 0) return ShadingPath::Disney;
  return ShadingPath::DisneyClearcoat;
}

void configure_shading(Scene& scene) {
  LobeMask lobes = 0;
  for (const Shape& shape : scene.shapes) lobes |= scene.materials[shape.material].lobes();
  ShadingConfig config;
  config.path = shading_path_for(lobes, scene.render.force_general_shading);
  config.sampling = scene.render.bsdf_sampling;
  config.min_pdf = scene.render.min_pdf;
  for (Material& m : scene.materials) {
    m.shading = config;
    m.closure = m.type == MaterialType::Disney ? disney::make_closure(m.disney) : disney::lambert_closure(m.albedo);
  }
}

}  // namespace pathlab
