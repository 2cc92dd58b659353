#include "core/material.h"

namespace pathlab {

const char* lobe_name(Lobe lobe) {
  switch (lobe) {
    case Lobe::Lambert: return "lambert";
    case Lobe::MirrorImpulse: return "mirror";
    case Lobe::Count: break;
  }
  return "?";
}

const char* material_type_name(MaterialType type) {
  switch (type) {
    case MaterialType::Diffuse: return "diffuse";
    case MaterialType::Mirror: return "mirror";
    case MaterialType::Emissive: return "emissive";
  }
  return "?";
}

LobeMask Material::lobes() const {
  switch (type) {
    case MaterialType::Diffuse: return lobe_bit(Lobe::Lambert);
    case MaterialType::Mirror: return lobe_bit(Lobe::MirrorImpulse);
    case MaterialType::Emissive: return 0;
  }
  return 0;
}

}  // namespace pathlab
