// The buffers pathlab-debug can show, as named layers: those of the render
// (the EXR channels aov_channels() lists for the film and the AOVs, so a
// layer added there shows up here without GUI changes) and those of an
// image file (every layer of a multi-layer EXR). Channel "R" of layer
// "albedo" is the EXR channel "albedo.R"; channels without a dot form the
// layer "beauty".
#pragma once

#include "core/image_io.h"

#include <filesystem>
#include <string>
#include <string_view>
#include <vector>

namespace pathlab::debug {

struct Layer {
  std::string name;      // "beauty" for the unnamed channels, else the EXR layer ("albedo", "L0", ...)
  std::string channels;  // the channel names in file order, joined by ',' ("R,G,B", "Z")
  int count = 0;         // number of channels (Image keeps the first three)
  Image image;           // one channel: in all of x, y, z; two: in x and y
};

// Groups EXR channels into layers, in the order each layer first appears.
std::vector<Layer> layers_from_channels(int width, int height, const std::vector<ExrChannel>& channels);

// Every layer of an image file (an EXR's layers; any other image: "beauty").
// Throws InputError naming the file.
std::vector<Layer> read_image_layers(const std::filesystem::path& file);

const Layer* find_layer(const std::vector<Layer>& layers, std::string_view name);

// The names of the channels of a layer ("R", "G", "B").
std::vector<std::string> channel_names(const Layer& layer);

}  // namespace pathlab::debug
