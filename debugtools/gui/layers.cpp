#include "debugtools/gui/layers.h"

#include "core/error.h"

#include <OpenImageIO/imageio.h>

#include <algorithm>
#include <memory>
#include <sstream>

namespace pathlab::debug {
namespace {

// "albedo.R" -> ("albedo", "R"); "R" -> ("beauty", "R"); "a.b.c" -> ("a.b", "c").
std::pair<std::string, std::string> split_channel(const std::string& name) {
  const auto dot = name.rfind('.');
  if (dot == std::string::npos) return {"beauty", name};
  return {name.substr(0, dot), name.substr(dot + 1)};
}

}  // namespace

std::vector<Layer> layers_from_channels(int width, int height, const std::vector<ExrChannel>& channels) {
  // Group by layer in order of first appearance; within a layer R, G, B, A
  // (or X, Y, Z) come first in that order, whatever order the file has them in
  // (OpenEXR stores channels sorted by name: B before G before R).
  std::vector<std::pair<std::string, std::vector<std::pair<std::string, const std::vector<float>*>>>> groups;
  for (const ExrChannel& c : channels) {
    auto [layer_name, channel] = split_channel(c.name);
    auto it = std::find_if(groups.begin(), groups.end(), [&](const auto& g) { return g.first == layer_name; });
    if (it == groups.end()) it = groups.insert(groups.end(), {layer_name, {}});
    it->second.emplace_back(channel, &c.values);
  }
  const auto rank = [](const std::string& c) {
    static const char* const order[] = {"R", "G", "B", "A", "X", "Y", "Z"};
    for (int i = 0; i < 7; ++i)
      if (c == order[i]) return i < 4 ? i : i - 4;
    return 10;
  };
  std::vector<Layer> layers;
  const std::size_t n = static_cast<std::size_t>(width) * height;
  for (auto& [name, members] : groups) {
    std::stable_sort(members.begin(), members.end(), [&](const auto& a, const auto& b) { return rank(a.first) < rank(b.first); });
    Layer& layer = layers.emplace_back();
    layer.name = name;
    layer.image = Image(width, height);
    for (const auto& [channel, values] : members) {
      layer.channels += (layer.count ? "," : "") + channel;
      const int k = layer.count++;
      if (k >= 3 || values->size() != n) continue;
      for (std::size_t i = 0; i < n; ++i) {
        vec3& p = layer.image.pixels[i];
        if (k == 0) p = vec3((*values)[i]);  // replicated until more channels come
        else p[k] = (*values)[i];
      }
    }
    if (layer.count == 2)  // keep x and y, no copy of x in z
      for (vec3& p : layer.image.pixels) p.z = 0.0f;
  }
  return layers;
}

std::vector<Layer> read_image_layers(const std::filesystem::path& file) {
  const auto fail = [&](const std::string& why) { throw InputError(file.string() + ": cannot read image: " + why); };
  if (!std::filesystem::is_regular_file(file)) fail("no such file");
  std::unique_ptr<OIIO::ImageInput> in = OIIO::ImageInput::open(file.string());
  if (!in) fail(OIIO::geterror());
  const OIIO::ImageSpec spec = in->spec();
  if (spec.nchannels < 1 || spec.width <= 0 || spec.height <= 0 || spec.depth != 1) fail("unsupported image shape");
  const std::size_t n = static_cast<std::size_t>(spec.width) * spec.height;
  std::vector<float> buffer(n * static_cast<std::size_t>(spec.nchannels));
  if (!in->read_image(0, 0, 0, spec.nchannels, OIIO::TypeFloat, buffer.data())) fail(in->geterror());
  in->close();
  std::vector<ExrChannel> channels(static_cast<std::size_t>(spec.nchannels));
  for (int c = 0; c < spec.nchannels; ++c) {
    ExrChannel& ch = channels[static_cast<std::size_t>(c)];
    ch.name = c < static_cast<int>(spec.channelnames.size()) ? spec.channelnames[static_cast<std::size_t>(c)]
                                                             : "channel" + std::to_string(c);
    ch.values.resize(n);
    for (std::size_t i = 0; i < n; ++i) ch.values[i] = buffer[i * static_cast<std::size_t>(spec.nchannels) + static_cast<std::size_t>(c)];
  }
  return layers_from_channels(spec.width, spec.height, channels);
}

const Layer* find_layer(const std::vector<Layer>& layers, std::string_view name) {
  for (const Layer& l : layers)
    if (l.name == name) return &l;
  return nullptr;
}

std::vector<std::string> channel_names(const Layer& layer) {
  std::vector<std::string> out;
  std::istringstream in(layer.channels);
  for (std::string c; std::getline(in, c, ',');) out.push_back(c);
  return out;
}

}  // namespace pathlab::debug
