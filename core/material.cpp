#include "core/material.h"

#include "core/scene.h"

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
    case MaterialType::Mirror: return !is_black(albedo);
    case MaterialType::Emissive: return false;
    case MaterialType::Disney: return true;  // Schlick Fresnel reflects at grazing angles whatever the colours
    case MaterialType::Dielectric: return !is_black(glass.reflectance) || !is_black(glass.transmittance);
  }
  return false;
}

LobeMask Material::lobes() const {
  switch (type) {
    case MaterialType::Diffuse: return lobe_bit(Lobe::Lambert);
    case MaterialType::Mirror: return lobe_bit(Lobe::MirrorImpulse);
    case MaterialType::Emissive: return 0;
    case MaterialType::Disney: {
      LobeMask m = lobe_bit(Lobe::Specular);
      if (disney.metallic < 1.0f) m |= lobe_bit(Lobe::DisneyDiffuse);
      if (disney.metallic < 1.0f && disney.sheen > 0.0f) m |= lobe_bit(Lobe::Sheen);
      if (disney.clearcoat > 0.0f) m |= lobe_bit(Lobe::Clearcoat);
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
