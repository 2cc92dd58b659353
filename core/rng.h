// Counter-based random numbers: u(seed, pixel, sample, bounce, dim) is a pure
// function, a hash of its key, so any sample of any pixel can be replayed
// alone, on any thread, in any order, and both tracers see the same numbers.
#pragma once

#include "core/sample_dims.h"
#include "core/sobol.h"

#include <bit>
#include <cstdint>
#include <optional>
#include <string_view>

namespace pathlab {

// A strong 64-bit bijective mixer (the splitmix64 finaliser, Steele et al.
// 2014; core/sobol.h's, which the zsobol sampler's parts use too). Every
// output bit depends on every input bit.
constexpr std::uint64_t mix64(std::uint64_t z) { return sobol::mix(z); }

// Top 24 bits of a hash as a float in [0, 1): every value is exactly
// representable, and 1 - 2^-24 is the largest, so u < 1 always holds
// (sobol::top24_to_float, which a stream's numbers take, core/simd/stream-generic.h).
constexpr float to_unit_float(std::uint64_t h) {
  return sobol::top24_to_float(static_cast<std::uint32_t>(h >> 40));
}

// Where the numbers of get() come from (RenderSettings::sampler, the scene
// key "sampler"; docs/scene-format.md, Samplers). bits() and the Alpha
// dimension are the hash under every sampler.
enum class SamplerKind : std::uint8_t {
  Independent,  // every number a hash of its key
  ZSobol,       // Owen-scrambled Sobol' points, pixels in Morton order (pbrt-v4's ZSobolSampler)
};
constexpr const char* sampler_name(SamplerKind k) { return k == SamplerKind::ZSobol ? "zsobol" : "independent"; }
constexpr std::optional<SamplerKind> parse_sampler(std::string_view name) {
  if (name == "independent") return SamplerKind::Independent;
  if (name == "zsobol") return SamplerKind::ZSobol;
  return std::nullopt;
}

// The zsobol sampler's dimensions. Each named dimension of a vertex belongs
// to one of kSobolSlotsPerVertex slots, a 2D pair (FilmX/Y, LensX/Y,
// LightX/Y, DirectionX/Y) or a 1D dimension alone, and a slot of vertex k is
// number kSobolSlotsPerVertex * k + entity: consecutive per vertex. A pair
// draws Sobol' dimensions 0 and 1 of the same index, a 1D slot dimension 0;
// every slot has its own index permutation and scrambling (padding), so the
// slots are decorrelated and there is no last dimension.
struct SobolSlot {
  std::uint32_t entity;  // 0 .. kSobolSlotsPerVertex - 1
  int axis;              // Sobol' dimension: 0 or 1
};
inline constexpr std::uint32_t kSobolSlotsPerVertex = 9;
constexpr SobolSlot sobol_slot(Dim dim) {
  switch (dim) {
    case Dim::FilmX: return {0, 0};
    case Dim::FilmY: return {0, 1};
    case Dim::LensX: return {1, 0};
    case Dim::LensY: return {1, 1};
    case Dim::DeltaLightChoice: return {2, 0};
    case Dim::LightChoice: return {3, 0};
    case Dim::LightX: return {4, 0};
    case Dim::LightY: return {4, 1};
    case Dim::Technique: return {5, 0};
    case Dim::LobeChoice: return {6, 0};
    case Dim::DirectionX: return {7, 0};
    case Dim::DirectionY: return {7, 1};
    case Dim::Roulette: return {8, 0};
    case Dim::Alpha:  // drawn by bits(), the hash, under every sampler
    case Dim::Count: break;
  }
  return {kSobolSlotsPerVertex, 0};
}

// Whether the zsobol sampler draws dim from its points (else dim is the
// hash, as under the independent sampler: Alpha, whose key bits() takes).
constexpr bool zsobol_draws(Dim dim) { return sobol_slot(dim).entity < kSobolSlotsPerVertex; }
// The dimension after x: a pair's second (FilmY after FilmX).
constexpr Dim next_dim(Dim x) { return static_cast<Dim>(static_cast<std::uint32_t>(x) + 1); }
// Whether x and next_dim(x) are a 2D slot's axes 0 and 1, drawn by zsobol
// from one point (get2 permutes its index once): FilmX, LensX, LightX and
// DirectionX.
constexpr bool zsobol_pair(Dim x) {
  return zsobol_draws(x) && sobol_slot(x).axis == 0 && sobol_slot(next_dim(x)).entity == sobol_slot(x).entity;
}
// A stream's zsobol bits when it is not zsobol's: every number the hash.
inline constexpr std::uint32_t kNoZSobol = 0xffffffffu;

// How a stream composes the hashes into its numbers, written once for every
// width (core/simd/stream-generic.h), here over lane1's one plain uint64;
// the wavefront's lanes compile the same text over Highway's vectors
// (core/simd/sobol-inl.h).
namespace sobol::width1 {
#include "core/simd/stream-generic.h"
}  // namespace sobol::width1

// The random numbers of one pixel sample. The key is hashed in a chain,
// each link injecting 64 bits of key into a fully mixed state:
//   h1 = mix(mix(seed + golden) ^ (pixel << 32 | sample))
//   u  = mix(h1 ^ (bounce << 32 | dim))
// Under the zsobol sampler (made by SamplerSetup::stream) get() is instead
// point `index` of a 2D Sobol' sequence, its index's digits permuted and its
// value scrambled per slot (see SamplerSetup); bits() stays the hash. Each
// number is core/simd/stream-generic.h's at width 1 (sobol::width1), the
// text the wavefront's vectorised stages draw their lanes' numbers by.
class SampleStream {
 public:
  constexpr SampleStream(std::uint64_t seed, std::uint32_t pixel, std::uint32_t sample)
      : key_(sobol::width1::stream_key(sobol::detail::kLane, sobol::detail::lane(seed_key(seed)),
                                       sobol::detail::lane(pixel_sample(pixel, sample)))
                 .raw) {}

  // key() is mix64(seed_key(seed) ^ pixel_sample(pixel, sample)).
  static constexpr std::uint64_t seed_key(std::uint64_t seed) { return mix64(seed + 0x9e3779b97f4a7c15ull); }
  static constexpr std::uint64_t pixel_sample(std::uint32_t pixel, std::uint32_t sample) {
    return (static_cast<std::uint64_t>(pixel) << 32) | sample;
  }

  constexpr float get(std::uint32_t bounce, Dim dim) const {
    return unit(sobol::width1::stream_top24(sobol::detail::kLane, at(bounce), index_bits_, dim));
  }
  // The whole 64-bit hash get() takes its top 24 bits from, for a decision
  // that needs more than one float's worth (a ray's alpha key, core/alpha.h).
  constexpr std::uint64_t bits(std::uint32_t bounce, Dim dim) const {
    return sobol::width1::stream_bits(sobol::detail::kLane, at(bounce), dim).raw;
  }
  // The hashed (seed, pixel, sample): under the independent sampler get() is
  // to_unit_float(mix64(key() ^ (bounce << 32 | dim))), for code that draws
  // many streams' numbers at once.
  constexpr std::uint64_t key() const { return key_; }
  // False under zsobol: get() is then no function of key() alone.
  constexpr bool independent() const { return index_bits_ == kNoZSobol; }

  // The two numbers of a 2D pair: {get(bounce, x), get(bounce, x + 1)} bit
  // for bit, for x = FilmX, LensX, LightX or DirectionX. Under zsobol the
  // pair's index permutation, the sampler's main cost, is done once.
  struct Pair {
    float x, y;
  };
  constexpr Pair get2(std::uint32_t bounce, Dim x) const {
    lane1::U64 second{};
    const lane1::U64 first = sobol::width1::stream_top24_pair(sobol::detail::kLane, at(bounce), index_bits_, x, second);
    return {unit(first), unit(second)};
  }

  // The stream at vertex `bounce` as core/simd/stream-generic.h takes it,
  // one lane (core/alpha.h's alpha_key draws through it).
  constexpr sobol::width1::VertexStreams<lane1::U64> at(std::uint32_t bounce) const {
    return sobol::width1::vertex_streams(sobol::detail::kLane, sobol::detail::lane(key_), sobol::detail::lane(bounce),
                                         sobol::detail::lane(index_), sobol::detail::lane(sobol_key_));
  }

 private:
  friend class SamplerSetup;
  // A 24-bit number (stream_top24's) as the float in [0, 1) it stands for.
  static constexpr float unit(lane1::U64 top24) { return sobol::top24_to_float(static_cast<std::uint32_t>(top24.raw)); }
  std::uint64_t key_;
  std::uint64_t index_ = 0;       // zsobol: morton(x, y) << log2_spp | sample mod 2^log2_spp
  std::uint64_t sobol_key_ = 0;   // zsobol: a hash of the seed and the sample's replicate
  std::uint32_t index_bits_ = kNoZSobol;  // zsobol: the bits of index_ that are permuted; kNoZSobol: independent
};

// What a sampler needs to know of the render to make the streams of its
// samples: the kind, the seed, the resolution and spp. Made once per render
// (Tracer holds one); stream() is a pure function of it and (x, y, sample).
//
// zsobol lays the samples of the image out on one Sobol' index:
//   index = morton(x, y) << L | (sample mod 2^L),  L = ceil(log2(spp))
// so a pixel's samples are an aligned run of 2^L indices (a (0, L, 2)-net
// in each pair) and neighbouring pixels' runs are neighbours (their union is
// a net too: the error is spread as blue noise over the screen). With spp
// not a power of two a pixel takes the first spp of its 2^L points
// (unbiased; the net is complete only at 2^L). A sample past 2^L (a
// progressive render going on past its spp: render --time, converge's
// ladder) starts a new replicate, q = sample >> L: the same design under an
// independent permutation and scrambling, seeded by (seed, q).
class SamplerSetup {
 public:
  SamplerSetup() = default;
  constexpr SamplerSetup(SamplerKind kind, std::uint64_t seed, std::uint32_t width, std::uint32_t height,
                         std::uint32_t spp)
      : kind_(kind), seed_(seed), width_(width) {
    const std::uint32_t side = width > height ? width : height;
    morton_bits_ = 2 * static_cast<std::uint32_t>(std::bit_width(side > 1 ? side - 1 : 0u));
    log2_spp_ = log2_spp_of(spp);
  }
  // L = ceil(log2(spp)): zsobol lays each pixel's samples out for 2^L.
  static constexpr std::uint32_t log2_spp_of(std::uint32_t spp) {
    return static_cast<std::uint32_t>(std::bit_width(spp > 1 ? spp - 1 : 0u));
  }

  constexpr SampleStream stream(std::uint32_t x, std::uint32_t y, std::uint32_t sample) const {
    SampleStream s(seed_, y * width_ + x, sample);
    if (kind_ == SamplerKind::ZSobol) {
      s.index_ = zsobol_index(x, y, sample);
      s.index_bits_ = zsobol_bits();
      s.sobol_key_ = zsobol_key(sample);
    }
    return s;
  }
  constexpr SamplerKind kind() const { return kind_; }
  constexpr std::uint32_t log2_spp() const { return log2_spp_; }
  // What stream() gives a zsobol stream, for code that draws many streams'
  // numbers at once (the wavefront's vectorised stages, core/simd/sobol-inl.h):
  // its Sobol' index, the bits of it that are permuted, its scrambling key.
  constexpr std::uint64_t zsobol_index(std::uint32_t x, std::uint32_t y, std::uint32_t sample) const {
    const std::uint64_t low = (1ull << log2_spp_) - 1;
    return (sobol::morton(x, y) << log2_spp_) | (sample & low);
  }
  constexpr std::uint32_t zsobol_bits() const { return morton_bits_ + log2_spp_; }
  constexpr std::uint64_t zsobol_key(std::uint32_t sample) const {
    return mix64(SampleStream::seed_key(seed_) ^ mix64((sample >> log2_spp_) + 0x5851f42d4c957f2dull));
  }

 private:
  SamplerKind kind_ = SamplerKind::Independent;
  std::uint64_t seed_ = 0;
  std::uint32_t width_ = 1;
  std::uint32_t morton_bits_ = 0;
  std::uint32_t log2_spp_ = 0;
};

// The same number without building a stream first (independent sampler).
constexpr float sample_u(std::uint64_t seed, std::uint32_t pixel, std::uint32_t sample,
                         std::uint32_t bounce, Dim dim) {
  return SampleStream(seed, pixel, sample).get(bounce, dim);
}

// Under any sampler.
constexpr float sample_u(const SamplerSetup& sampler, std::uint32_t x, std::uint32_t y, std::uint32_t sample,
                         std::uint32_t bounce, Dim dim) {
  return sampler.stream(x, y, sample).get(bounce, dim);
}

}  // namespace pathlab
