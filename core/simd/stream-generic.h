// The sample streams over 64-bit lanes, one stream per lane, written once for
// every width as core/simd/sobol-generic.h's hashes are: how SampleStream
// (core/rng.h) composes those hashes into a sample's numbers. core/rng.h
// includes this text in pathlab::sobol::width1 over lane1's one plain uint64
// (SampleStream's get, get2 and bits, core/alpha.h's alpha_key: the numbers
// the reference tracer and the wavefront's scalar stages draw) and
// core/simd/sobol-inl.h in each Highway target's namespace (the wavefront's
// vectorised stages, whose Streams hold a block's paths in two registers of
// 64-bit lanes). Integer arithmetic throughout, so every width computes the
// same bits by construction.
//
// What is composed here: the stream key, a dimension's hash at a vertex,
// which dimensions the zsobol sampler draws from its points and which two
// draw one point (zsobol_draws, zsobol_pair in core/rng.h), a dimension's
// zsobol slot, and the alpha key's 32 bits. What each width does on its own:
// the 24-bit number to a float (times 2^-24: sobol::top24_to_float at width
// 1; the stages pack two registers of 64-bit lanes into one of floats first,
// docs/one-estimator.md says why that is not one text).
//
// No include guard and no includes: this is the body of the namespace it is
// included in, after core/simd/sobol-generic.h (mix64, zsobol_top24) and
// core/rng.h's sampler dimensions (Dim, sobol_slot, zsobol_draws,
// zsobol_pair, kSobolSlotsPerVertex, kNoZSobol). The operations are found by
// argument-dependent lookup on the lane type, as in sobol-generic.h.

// SampleStream::key(): the stream's key, pixel_sample (SampleStream::
// pixel_sample: pixel << 32 | sample) hashed with seed_key
// (SampleStream::seed_key(seed)).
template <class D64, class V64 = VecOf<D64>>
constexpr HWY_INLINE V64 stream_key(D64 d64, V64 seed_key, V64 pixel_sample) {
  return mix64(d64, Xor(seed_key, pixel_sample));
}

// The streams' state at one vertex (SampleStream's bounce), a stream per lane.
template <class V64>
struct VertexStreams {
  V64 key;    // key() ^ vertex << 32: every dimension's hash key of the vertex but the dimension
  V64 slot;   // zsobol: vertex * kSobolSlotsPerVertex, the vertex's first slot
  V64 index;  // zsobol: SamplerSetup::zsobol_index
  V64 zkey;   // zsobol: SamplerSetup::zsobol_key
};
// Under the independent sampler (zsobol's fields 0, never read).
template <class D64, class V64 = VecOf<D64>>
constexpr HWY_INLINE VertexStreams<V64> vertex_streams(D64 d64, V64 key, V64 vertex) {
  return {Xor(key, ShiftLeft<32>(vertex)), Set(d64, 0), Set(d64, 0), Set(d64, 0)};
}
// Under zsobol.
template <class D64, class V64 = VecOf<D64>>
constexpr HWY_INLINE VertexStreams<V64> vertex_streams(D64 d64, V64 key, V64 vertex, V64 index, V64 zkey) {
  return {Xor(key, ShiftLeft<32>(vertex)), mul64(d64, vertex, kSobolSlotsPerVertex), index, zkey};
}

// SampleStream::bits: the hash of dimension `dim` at the vertex,
// mix64(key ^ (vertex << 32 | dim)) (the two halves apart, so the or is the
// xor). The hash under every sampler.
template <class D64, class V64 = VecOf<D64>>
constexpr HWY_INLINE V64 stream_bits(D64 d64, const VertexStreams<V64>& s, Dim dim) {
  return mix64(d64, Xor(s.key, Set(d64, static_cast<std::uint64_t>(dim))));
}

// alpha_key (core/alpha.h): the key of the rays leaving the vertex, the high
// 32 bits of dimension Alpha's hash, in each lane's low 32 bits.
template <class D64, class V64 = VecOf<D64>>
constexpr HWY_INLINE V64 stream_alpha_key(D64 d64, const VertexStreams<V64>& s) {
  return ShiftRight<32>(stream_bits(d64, s, Dim::Alpha));
}

// The zsobol slot dim draws from at the vertex: the vertex's first plus the
// slot's entity (sobol_slot), modulo 2^32 as SampleStream's uint32 was.
template <class D64, class V64 = VecOf<D64>>
constexpr HWY_INLINE V64 zsobol_slot_of(D64 d64, const VertexStreams<V64>& s, Dim dim) {
  return And(s.slot + Set(d64, sobol_slot(dim).entity), Set(d64, 0xffffffffu));
}

// SampleStream::get as a 24-bit number (the float is it times 2^-24): with
// `zsobol_bits` (SamplerSetup::zsobol_bits, or kNoZSobol) a zsobol stream's
// point of dim's slot in the slot's axis when zsobol draws dim, else the top
// 24 bits of dim's hash.
template <class D64, class V64 = VecOf<D64>>
constexpr HWY_INLINE V64 stream_top24(D64 d64, const VertexStreams<V64>& s, unsigned zsobol_bits, Dim dim) {
  if (zsobol_bits != kNoZSobol && zsobol_draws(dim))
    return zsobol_top24(d64, s.index, s.zkey, zsobol_bits, zsobol_slot_of(d64, s, dim), sobol_slot(dim).axis,
                        static_cast<V64*>(nullptr));
  return ShiftRight<40>(stream_bits(d64, s, dim));
}

// SampleStream::get2: x's number and, into `second`, x + 1's, each
// stream_top24's bits; for a zsobol pair both axes of one point, so the
// pair's index permutation (the sampler's main cost) is done once.
template <class D64, class V64 = VecOf<D64>>
constexpr HWY_INLINE V64 stream_top24_pair(D64 d64, const VertexStreams<V64>& s, unsigned zsobol_bits, Dim x,
                                           V64& second) {
  if (zsobol_bits != kNoZSobol && zsobol_pair(x))
    return zsobol_top24(d64, s.index, s.zkey, zsobol_bits, zsobol_slot_of(d64, s, x), 0, &second);
  second = stream_top24(d64, s, zsobol_bits, next_dim(x));
  return stream_top24(d64, s, zsobol_bits, x);
}
