// Counter-based random numbers: u(seed, pixel, sample, bounce, dim) is a pure
// function, a hash of its key, so any sample of any pixel can be replayed
// alone, on any thread, in any order, and both tracers see the same numbers.
#pragma once

#include "core/sample_dims.h"

#include <cstdint>

namespace pathlab {

// A strong 64-bit bijective mixer (the splitmix64 finaliser, Steele et al.
// 2014). Every output bit depends on every input bit.
constexpr std::uint64_t mix64(std::uint64_t z) {
  z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ull;
  z = (z ^ (z >> 27)) * 0x94d049bb133111ebull;
  return z ^ (z >> 31);
}

// Top 24 bits of a hash as a float in [0, 1): every value is exactly
// representable, and 1 - 2^-24 is the largest, so u < 1 always holds.
constexpr float to_unit_float(std::uint64_t h) {
  return static_cast<float>(h >> 40) * 0x1p-24f;
}

// The random numbers of one pixel sample. The key is hashed in a chain,
// each link injecting 64 bits of key into a fully mixed state:
//   h1 = mix(mix(seed + golden) ^ (pixel << 32 | sample))
//   u  = mix(h1 ^ (bounce << 32 | dim))
class SampleStream {
 public:
  constexpr SampleStream(std::uint64_t seed, std::uint32_t pixel, std::uint32_t sample)
      : key_(mix64(seed_key(seed) ^ ((static_cast<std::uint64_t>(pixel) << 32) | sample))) {}

  // key() is mix64(seed_key(seed) ^ (pixel << 32 | sample)).
  static constexpr std::uint64_t seed_key(std::uint64_t seed) { return mix64(seed + 0x9e3779b97f4a7c15ull); }

  constexpr float get(std::uint32_t bounce, Dim dim) const { return to_unit_float(bits(bounce, dim)); }
  // The whole 64-bit hash get() takes its top 24 bits from, for a decision
  // that needs more than one float's worth (a ray's alpha key, core/alpha.h).
  constexpr std::uint64_t bits(std::uint32_t bounce, Dim dim) const {
    return mix64(key_ ^ ((static_cast<std::uint64_t>(bounce) << 32) | static_cast<std::uint32_t>(dim)));
  }
  // The hashed (seed, pixel, sample): get() is to_unit_float(mix64(key() ^
  // (bounce << 32 | dim))), for code that draws many streams' numbers at once.
  constexpr std::uint64_t key() const { return key_; }

 private:
  std::uint64_t key_;
};

// The same number without building a stream first.
constexpr float sample_u(std::uint64_t seed, std::uint32_t pixel, std::uint32_t sample,
                         std::uint32_t bounce, Dim dim) {
  return SampleStream(seed, pixel, sample).get(bounce, dim);
}

}  // namespace pathlab
