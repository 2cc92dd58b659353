// Textured material parameters in a scene file: {"texture": "wood.png", ...}
// wherever a material takes a number or a colour (docs/scene-format.md,
// "Textures").
#include "core/data_dir.h"
#include "core/error.h"
#include "core/limits.h"
#include "core/scene_loader_internal.h"

#include <OpenImageIO/imageio.h>

#include <algorithm>
#include <sstream>

namespace pathlab::scene_detail {

bool is_texture(const Node& node) { return node.value().is_object() && node.has("texture"); }

namespace {

// The location prefix of `node`'s messages ("<file>:<line>:<col>: <pointer>").
std::string location(const Node& node) {
  const std::string m = node.message("");
  return m.substr(0, m.size() - 2);
}

}  // namespace

TextureRef read_texture(const Node& node, Scene& scene, TextureUse use, TextureColorSpace default_space) {
  const bool normal_map = use == TextureUse::NormalMap;
  if (normal_map) node.allow_only({"texture", "scale", "wrap", "channel", "colorspace"});
  else node.allow_only({"texture", "scale", "offset", "colorspace", "wrap", "channel"});
  const Node file = node.required("texture");
  if (file.string().empty()) file.fail("the texture file name is empty");
  const std::filesystem::path path = resolve_scene_path(scene.file.parent_path(), file.string());
  TextureColorSpace space = default_space;
  if (node.has("colorspace")) {
    const std::string name = node.child("colorspace").string();
    const auto s = parse_texture_color_space(name);
    if (!s) node.child("colorspace").fail("unknown colorspace " + in_quotes(name) + " (expected srgb or linear)");
    space = *s;
  }
  TextureRef ref;
  if (node.has("wrap")) {
    const std::string name = node.child("wrap").string();
    const auto w = parse_texture_wrap(name);
    if (!w) {
      const std::array<std::string_view, 4> names{"repeat", "clamp", "black", "mirror"};
      const std::string near = suggestion(name, names);
      node.child("wrap").fail("unknown wrap mode " + in_quotes(name) +
                              (near.empty() ? " (expected repeat, clamp, black or mirror)" : near));
    }
    ref.wrap = *w;
  }
  if (node.has("scale")) {
    const Node s = node.child("scale");
    if (normal_map) {
      // glTF's normalTexture.scale: may be negative. Within kMaxNormalMapScale,
      // so that the tilted normal's squared length stays a float.
      if (!(std::abs(s.number()) <= double(kMaxNormalMapScale)))
        s.fail("a normal map's scale must lie in [-1e6, 1e6] (beyond, the tilted normal's length overflows)");
      ref.scale = Spectrum(static_cast<float>(s.number()));
    } else {
      if (s.value().is_number() && s.number() < 0.0) s.fail("scale must not be negative");
      ref.scale = s.color(false);
    }
  }
  if (node.has("offset")) {
    const Node o = node.child("offset");
    if (!o.value().is_number() && !(o.value().is_array() && o.value().size() == 3))
      o.fail("expected one number or an array of 3 numbers, found " + describe(o.value()));
    ref.offset = o.value().is_number() ? Spectrum(static_cast<float>(o.number())) : o.vector3();
  }
  // The header now, so that a missing or unreadable file, or a channel it
  // lacks, is reported at the key that names it.
  if (names_data_file(file.string()) && !std::filesystem::exists(path))
    file.fail(file.string() + ": " + path.string() + " does not exist; " + data_directory_hint());
  require_regular(file, path, "texture");
  if (!std::filesystem::is_regular_file(path)) file.fail("texture " + path.string() + " does not exist");
  int channels = 0;
  {
    auto in = OIIO::ImageInput::open(path.string());
    if (!in) file.fail("texture " + path.string() + ": cannot read it (" + OIIO::geterror() + ")");
    channels = in->spec().nchannels;
  }
  if (channels < 1 || channels > 4)
    file.fail("texture " + path.string() + " has " + std::to_string(channels) +
              " channels (1 to 4 are supported: grey, grey+alpha, RGB, RGBA)");
  if (node.has("channel")) {
    const Node c = node.child("channel");
    const std::int64_t k = c.integer();
    const bool colour = use == TextureUse::Color || normal_map;
    const std::int64_t last = colour ? (channels < 3 ? 0 : channels - 3) : channels - 1;
    if (k < 0 || k > last) {
      std::ostringstream m;
      m << "channel " << k << " is out of range: " << path.filename().string() << " has " << channels
        << " channel(s), so a " << (colour ? "colour (3 channels from 'channel')" : "number") << " may start at 0"
        << (last > 0 ? " to " + std::to_string(last) : std::string());
      c.fail(m.str());
    }
    ref.channel = static_cast<std::uint8_t>(k);
  }
  if (normal_map && channels < 3) file.fail("a normal map needs 3 channels; " + path.string() + " has " + std::to_string(channels));
  // One image per file and colour space, however many parameters read it.
  for (std::uint32_t i = 0; i < scene.textures.size(); ++i)
    if (scene.textures[i].file == path && scene.textures[i].colorspace == space) {
      ref.image = i;
      return ref;
    }
  ref.image = static_cast<std::uint32_t>(scene.textures.size());
  scene.textures.push_back({path, space, location(file)});
  if (std::find(scene.input_files.begin(), scene.input_files.end(), path) == scene.input_files.end())
    scene.input_files.push_back(path);
  return ref;
}

}  // namespace pathlab::scene_detail
