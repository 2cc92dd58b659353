// The vectorised stages of vector_stages.h, written once over Google
// Highway's portable vectors and compiled for every x86 SIMD target
// (foreach_target: AVX-512, AVX2, SSE4 — 16, 8 or 4 paths at a time);
// HWY_DYNAMIC_DISPATCH runs the one core/simd/simd.h selected. The
// per-lane steps of the estimator are core's (core/simd/*-inl.h,
// core/bsdf/*-inl.h: the same source core's scalar code runs at width 1);
// what is here is the stages' own business: the wave's arrays, the scene
// tables, gathers, which step each lane takes, packing and compaction.
//
// Each step names the scalar code it computes. Every lane computes that
// code's bits: the order of every sum and product is the scalar one, no
// fused multiply-add (-ffp-contract=off project-wide), std::max(a, b) is
// hn::Max(b, a). tests/test_wavefront.cpp (VectorStages) checks every
// sample of several scenes bit for bit against the scalar stages, at every
// target this processor runs.
//
// The wave's arrays are padded (WavefrontTracer::Lanes): a block of lanes
// is loaded whole, and the lanes beyond the live paths are ignored.
#undef HWY_TARGET_INCLUDE
#define HWY_TARGET_INCLUDE "wavefront/vector_stages.cpp"
#include <hwy/foreach_target.h>  // must come before highway.h

#include <hwy/highway.h>

#include "core/bsdf/dielectric-inl.h"
#include "core/bsdf/disney-inl.h"
#include "core/bsdf/lambert-inl.h"
#include "core/bsdf/mirror-inl.h"
#include "core/simd/environment-inl.h"
#include "core/simd/lanes-inl.h"
#include "core/simd/light_bvh-inl.h"
#include "core/simd/lights-inl.h"
#include "core/simd/sampling-inl.h"
#include "core/simd/shading_frame-inl.h"
#include "core/simd/sobol-inl.h"
#include "core/simd/spherical-inl.h"
#include "core/simd/texture_inputs-inl.h"
#include "core/material.h"
#include "core/rng.h"
#include "core/scene.h"
#include "wavefront/vector_stages.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>
#include <stdexcept>
#include <type_traits>

#ifndef PATHLAB_VECTOR_STAGES_GENERAL
#define PATHLAB_VECTOR_STAGES_GENERAL
namespace pathlab::vector_stages {
// A general material's BSDF (Scene::general) for the path in slot i, by
// core's Surfel: what the scalar stages compute for it, one path at a time.
// Compiled once, for the baseline target (at the end of this file); each
// target's stages call them for the lanes of such materials.
struct GeneralSample {
  float wi[3], weight[3], pdf;
  bool impulse;
};
// Surfel::eval and Surfel::pdf towards wi.
void general_eval(const Scene& scene, const Wave& wave, std::size_t i, const float wi[3], float f[3], float* pdf);
// Surfel::scatter; false where it samples nothing.
bool general_scatter(const Scene& scene, const Wave& wave, std::size_t i, float u_lobe, float u0, float u1,
                     GeneralSample* out);
// Lights beyond what the lanes sample (Scene::general_lights: an
// environment image too large for the gathers' indices), by core's
// LightSampler for the path in slot i: a light sample and its shadow
// ray (origin, direction, tmax; shadow_ray), false where sample() gives none.
struct GeneralLight {
  float wi[3], Le[3], pdf, ray[7];
};
bool general_light(const Scene& scene, const Wave& wave, std::size_t i, float u_choice, float u0, float u1,
                   GeneralLight* out);
// The light the path's ray finds: the sky along an escaped ray (Scene::sky;
// LightSampler::sky), or the density with which the light sampler would
// have chosen the emitter it hit (LightSampler::pdf from the previous vertex).
void general_sky(const Scene& scene, const Wave& wave, std::size_t i, float Le[3], float* pdf);
float general_light_pdf(const Scene& scene, const Wave& wave, std::size_t i);
// The rest of the Surfel of the hit in slot i, by core (resolve_shading
// from the lanes' point, or the whole of CompiledScene::resolve for a hit on
// an instance or a material that reads textures), written to its arrays:
// point, error bound, geometric normal, shading frame and flags.
void general_resolve(const Scene& scene, const Wave& wave, std::size_t i);
// The texels a kTexturedHits hit in slot i reads (evaluate_textured, core/
// material.h: OpenImageIO's lookups at the footprint kTexU, kTexV,
// kTexWidth) into the slot's SurfaceParams.
void general_texels(const Scene& scene, const Wave& wave, std::size_t i);
// LightSampler::emission_at_point: the radiance a light sample at p (on a
// triangle at barycentrics b1, b2) of light entry `light` carries, for an
// emitter whose emission is a texture.
void general_light_emission(const Scene& scene, std::int32_t light, float b1, float b2, const float p[3], float Le[3]);
}  // namespace pathlab::vector_stages
#endif

HWY_BEFORE_NAMESPACE();
namespace pathlab::vector_stages::HWY_NAMESPACE {
namespace hn = hwy::HWY_NAMESPACE;
using pathlab::HWY_NAMESPACE::Vec3;

#if HWY_TARGET == HWY_EMU128 || HWY_TARGET == HWY_SCALAR
// Never called: width 1 is the scalar stages (wavefront_tracer.cpp), and
// cpu_supported() is false there.
[[noreturn]] void width_one() { throw std::logic_error("vector_stages: called at width 1 (run the scalar stages)"); }
void generate_camera_rays(const Scene&, const Camera&, const Wave&) { width_one(); }
void prefetch_hits(const Scene&, const Wave&) { width_one(); }
void resolve(const Scene&, const Wave&) { width_one(); }
void add_emission(const Scene&, const Wave&) { width_one(); }
std::size_t sample_lights(const Scene&, const Wave&) { width_one(); }
void scatter(const Scene&, const Wave&) { width_one(); }
void hash_keys(std::uint64_t*, std::size_t, std::uint64_t) { width_one(); }
std::size_t compact(const Scene&, const Wave&, void*, std::uint32_t) { width_one(); }
std::size_t lanes() { return 1; }
#else

using pathlab::HWY_NAMESPACE::add_sun;
using pathlab::HWY_NAMESPACE::area_light_sample;
using pathlab::HWY_NAMESPACE::AreaLight;
using pathlab::HWY_NAMESPACE::AreaLightSample;
using pathlab::HWY_NAMESPACE::emitter_hit_pdf;
using pathlab::HWY_NAMESPACE::bvh_pick;
using pathlab::HWY_NAMESPACE::BvhTable;
using pathlab::HWY_NAMESPACE::bvh_share;
using pathlab::HWY_NAMESPACE::camera_ray;
using pathlab::HWY_NAMESPACE::CameraPlane;
using pathlab::HWY_NAMESPACE::samples_area_lights;
using pathlab::HWY_NAMESPACE::sky_or_area_sample;
using pathlab::HWY_NAMESPACE::previous_vertex;
using pathlab::HWY_NAMESPACE::PreviousVertexLanes;
using pathlab::HWY_NAMESPACE::CornerUvs;
using pathlab::HWY_NAMESPACE::delta_light_contribution;
using pathlab::HWY_NAMESPACE::light_contribution;
using pathlab::HWY_NAMESPACE::delta_light_sample;
using pathlab::HWY_NAMESPACE::DeltaLightLanes;
using pathlab::HWY_NAMESPACE::env_sample_direction;
using pathlab::HWY_NAMESPACE::ClosureLanes;
using pathlab::HWY_NAMESPACE::dielectric_sample;
using pathlab::HWY_NAMESPACE::distribution2d_sample;
using pathlab::HWY_NAMESPACE::disney_eval;
using pathlab::HWY_NAMESPACE::disney_pdf;
using pathlab::HWY_NAMESPACE::disney_scatter;
using pathlab::HWY_NAMESPACE::dot;
using pathlab::HWY_NAMESPACE::emitted_towards;
using pathlab::HWY_NAMESPACE::facing_normal;
using pathlab::HWY_NAMESPACE::footprint_width;
using pathlab::HWY_NAMESPACE::frame;
using pathlab::HWY_NAMESPACE::scattered_side_ok;
using pathlab::HWY_NAMESPACE::surface_eval_ok;
using pathlab::HWY_NAMESPACE::surface_scatter_ok;
using pathlab::HWY_NAMESPACE::upper_side;
using pathlab::HWY_NAMESPACE::vertex_streams;
using pathlab::HWY_NAMESPACE::VertexStreams;
using pathlab::HWY_NAMESPACE::is_black;
using pathlab::HWY_NAMESPACE::lambert_eval;
using pathlab::HWY_NAMESPACE::lambert_sample;
using pathlab::HWY_NAMESPACE::mirror_sample;
using pathlab::HWY_NAMESPACE::NoEnergy;
using pathlab::HWY_NAMESPACE::normal_mapped_frame;
using pathlab::HWY_NAMESPACE::light_grid_point;
using pathlab::HWY_NAMESPACE::pick_cdf;
using pathlab::HWY_NAMESPACE::pick_pmf;
using pathlab::HWY_NAMESPACE::tree_or_sky_pick;
using pathlab::HWY_NAMESPACE::sky_sample;
using pathlab::HWY_NAMESPACE::roulette;
using pathlab::HWY_NAMESPACE::surface_frame;
using pathlab::HWY_NAMESPACE::surface_point;
using pathlab::HWY_NAMESPACE::select;
using pathlab::HWY_NAMESPACE::shadow_ray;
using pathlab::HWY_NAMESPACE::spawn_origin;
using pathlab::HWY_NAMESPACE::scattered_cone;
using pathlab::HWY_NAMESPACE::solid_angle_draw;
using pathlab::HWY_NAMESPACE::SolidAngleDraw;
using pathlab::HWY_NAMESPACE::sphere_texture_inputs;
using pathlab::HWY_NAMESPACE::stream_alpha_key;
using pathlab::HWY_NAMESPACE::stream_key;
using pathlab::HWY_NAMESPACE::stream_top24;
using pathlab::HWY_NAMESPACE::stream_top24_pair;
using pathlab::HWY_NAMESPACE::sun_direction;
using pathlab::HWY_NAMESPACE::splat3;
using pathlab::HWY_NAMESPACE::to_local;
using pathlab::HWY_NAMESPACE::to_local_upper;
using pathlab::HWY_NAMESPACE::to_world;
using pathlab::HWY_NAMESPACE::TextureInputs;
using pathlab::HWY_NAMESPACE::triangle_texture_inputs;
using pathlab::HWY_NAMESPACE::CospowLobes;
using pathlab::HWY_NAMESPACE::VndfLobes;
using pathlab::HWY_NAMESPACE::zero_unless;

using DF = hn::ScalableTag<float>;
using DI = hn::RebindToSigned<DF>;
using DU = hn::RebindToUnsigned<DF>;
using D8 = hn::Rebind<std::uint8_t, DF>;
using D64 = hn::Repartition<std::uint64_t, DF>;  // half as many lanes
using DH = hn::Half<DU>;
using VF = hn::Vec<DF>;
using VI = hn::Vec<DI>;
using VU = hn::Vec<DU>;
using V64 = hn::Vec<D64>;
using M = hn::Mask<DF>;
using V3 = Vec3<VF>;
using DD = hn::Repartition<double, DF>;  // half as many lanes
using VD = hn::Vec<DD>;
using MD = hn::Mask<DD>;
using DDI = hn::RebindToSigned<DD>;
using VDI = hn::Vec<DDI>;
using V3D = Vec3<VD>;

std::size_t lanes() { return hn::Lanes(DF()); }

VF k(float v) { return hn::Set(DF(), v); }
V3 zero3() { return splat3(DF(), 0.0f, 0.0f, 0.0f); }
// A block's lanes at the widest width: the arrays that carry them to and
// from core's per-path calls.
constexpr std::size_t kMaxLanes = hn::MaxLanes(DF());
V3 load_lanes(const float (&a)[3][kMaxLanes]) { return {hn::Load(DF(), a[0]), hn::Load(DF(), a[1]), hn::Load(DF(), a[2])}; }
// Masks of float lanes from integer comparisons, and back.
template <class MI>
M fmask(MI m) {
  return hn::RebindMask(DF(), m);
}

// The lanes of slots [i0, i0 + lanes) that hold live paths.
M live(std::size_t n, std::size_t i0) { return hn::FirstN(DF(), n - i0); }

// Slots [i0, i0 + lanes) of the wave's arrays: 0 outside m; nothing stored outside m.
VF load(const Wave& w, FloatArray a, std::size_t i0, M m) { return hn::IfThenElseZero(m, hn::LoadU(DF(), w.f[a] + i0)); }
V3 load3(const Wave& w, FloatArray x, std::size_t i0, M m) {
  return {load(w, x, i0, m), load(w, static_cast<FloatArray>(x + 1), i0, m),
          load(w, static_cast<FloatArray>(x + 2), i0, m)};
}
void store(const Wave& w, FloatArray a, std::size_t i0, M m, VF v) { hn::BlendedStore(v, m, DF(), w.f[a] + i0); }
void store3(const Wave& w, FloatArray x, std::size_t i0, M m, const V3& v) {
  store(w, x, i0, m, v.x);
  store(w, static_cast<FloatArray>(x + 1), i0, m, v.y);
  store(w, static_cast<FloatArray>(x + 2), i0, m, v.z);
}
VI load(const Wave& w, UintArray a, std::size_t i0, M m) {
  return hn::IfThenElseZero(hn::RebindMask(DI(), m), hn::BitCast(DI(), hn::LoadU(DU(), w.u[a] + i0)));
}
void store(const Wave& w, UintArray a, std::size_t i0, M m, VI v) {
  hn::BlendedStore(hn::BitCast(DU(), v), hn::RebindMask(DU(), m), DU(), w.u[a] + i0);
}
// A byte array as a mask of the lanes whose byte is not 0, and back.
M load_mask(const Wave& w, ByteArray a, std::size_t i0, M m) {
  const VU v = hn::PromoteTo(DU(), hn::LoadU(D8(), w.b[a] + i0));
  return hn::And(m, fmask(v != hn::Zero(DU())));
}
// Bytes p[0, lanes) become v's lanes where m is set (0 to 255 each) and
// stay elsewhere: a whole block is read and written (the arrays are padded).
void store_bytes(std::uint8_t* p, M m, VI v) {
  const VI old = hn::PromoteTo(DI(), hn::LoadU(D8(), p));
  hn::StoreU(hn::DemoteTo(D8(), hn::IfThenElse(hn::RebindMask(DI(), m), v, old)), D8(), p);
}
void store_mask(const Wave& w, ByteArray a, std::size_t i0, M m, M value) {
  store_bytes(w.b[a] + i0, m, hn::IfThenElseZero(hn::RebindMask(DI(), value), hn::Set(DI(), 1)));
}

// Float `index` of entry `entry` of a table with `stride` floats per entry (0 outside m).
VF gather(M m, const float* base, VI entry, int stride, int index) {
  if (hn::AllFalse(DF(), m)) return hn::Zero(DF());
  const VI at = entry * hn::Set(DI(), stride) + hn::Set(DI(), index);
  return hn::IfThenElseZero(m, hn::GatherIndex(DF(), base, hn::IfThenElseZero(hn::RebindMask(DI(), m), at)));
}
V3 gather3(M m, const float* base, VI entry, int stride, int index) {
  return {gather(m, base, entry, stride, index), gather(m, base, entry, stride, index + 1),
          gather(m, base, entry, stride, index + 2)};
}
// Entry `entry` of a table of at most lanes() entries kept by column (`row`
// holds one field of every entry): a permute of a register, not a gather.
VF permute(M m, const float* row, VI entry) {
  const VI at = hn::IfThenElseZero(hn::RebindMask(DI(), m), entry);
  return hn::IfThenElseZero(m, hn::TableLookupLanes(hn::LoadU(DF(), row), hn::IndicesFromVec(DF(), at)));
}

// Field `field` of each lane's shape (Scene::shape). 0 outside m.
VF shape_value(M m, const Scene& sc, VI shape, ShapeField field) {
  if (sc.shape_columns && sc.shape_count <= lanes()) return permute(m, sc.shape_columns + 16 * field, shape);
  return gather(m, sc.shape, shape, kShapeFields, field);
}
V3 shape_value3(M m, const Scene& sc, VI shape, ShapeField field) {
  return {shape_value(m, sc, shape, field), shape_value(m, sc, shape, static_cast<ShapeField>(field + 1)),
          shape_value(m, sc, shape, static_cast<ShapeField>(field + 2))};
}
VI shape_int(M m, const Scene& sc, VI shape, ShapeField field) {
  return hn::BitCast(DI(), shape_value(m, sc, shape, field));
}
M shape_flag(M m, const Scene& sc, VI shape, ShapeField field) {
  return hn::AndNot(shape_value(m, sc, shape, field) == k(0.0f), m);
}
// Field `field` of each lane's light entry (Lights). 0 outside m.
VF light_value(M m, const Lights& lights, VI entry, LightField field) {
  if (lights.columns && lights.count <= lanes()) return permute(m, lights.columns + 16 * field, entry);
  switch (field) {
    case kLightCdf: return gather(m, lights.cdf, entry, 1, 0);
    case kLightPmf: return gather(m, lights.pmf, entry, 1, 0);
    case kLightInvArea: return gather(m, lights.inv_area, entry, 1, 0);
    default: return gather(m, lights.triangle, entry, 16, field);
  }
}
V3 light_value3(M m, const Lights& lights, VI entry, LightField field) {
  return {light_value(m, lights, entry, field), light_value(m, lights, entry, static_cast<LightField>(field + 1)),
          light_value(m, lights, entry, static_cast<LightField>(field + 2))};
}

// Packing the lanes of a mask to the front, for several arrays at once: the
// order of the kept lanes is worked out once (a compress of the lane
// numbers), and each array then costs one permute and one masked store.
// (Highway's CompressBlendedStore per array would redo the first step each
// time - a table lookup on AVX2 - and on AVX-512 compresses straight to
// memory, several times slower than in a register on Intel cores.)
struct Packer {
  std::size_t count;
  decltype(hn::IndicesFromVec(DF(), hn::Zero(DI()))) order;
  M first;  // the lanes [0, count)
  explicit Packer(M m)
      : count(hn::CountTrue(DF(), m)),
        // The lanes past count are unspecified after Compress: 0, so that every index is valid.
        order(hn::IndicesFromVec(DF(), hn::IfThenElseZero(hn::FirstN(DI(), hn::CountTrue(DF(), m)),
                                                          hn::Compress(hn::Iota(DI(), 0), hn::RebindMask(DI(), m))))),
        first(hn::FirstN(DF(), count)) {}
  // The kept lanes of v written to to[0, count).
  void store(float* to, VF v) const { hn::BlendedStore(hn::TableLookupLanes(v, order), first, DF(), to); }
  void store(std::uint32_t* to, VU v) const {
    const VF packed = hn::TableLookupLanes(hn::BitCast(DF(), v), order);
    hn::BlendedStore(hn::BitCast(DU(), packed), hn::RebindMask(DU(), first), DU(), to);
  }
  VI packed(VI v) const { return hn::BitCast(DI(), hn::TableLookupLanes(hn::BitCast(DF(), v), order)); }
};

// SampleStream's numbers for the block's paths at their current vertex:
// core/simd/stream-generic.h's, the text SampleStream draws by at width 1,
// on each half of the block in 64-bit lanes (core/simd/sobol-inl.h). unit()
// is the stages' own: it packs the halves into the block's floats.
struct Streams {
  VertexStreams<V64> lo, hi;  // the block's halves
  unsigned zsobol_bits;       // SampleStream's: Scene::zsobol_bits, or kNoZSobol

  VF u(Dim dim) const {
    const D64 d64;
    return unit(stream_top24(d64, lo, zsobol_bits, dim), stream_top24(d64, hi, zsobol_bits, dim));
  }
  // SampleStream::get2: {u(x), u(x + 1)}, the pair's point made once under zsobol.
  void u2(Dim x, VF& a, VF& b) const {
    const D64 d64;
    V64 lo2, hi2;
    const V64 lo1 = stream_top24_pair(d64, lo, zsobol_bits, x, lo2);
    const V64 hi1 = stream_top24_pair(d64, hi, zsobol_bits, x, hi2);
    a = unit(lo1, hi1);
    b = unit(lo2, hi2);
  }
  // alpha_key (core/alpha.h) of the rays leaving the vertex.
  VU alpha_key() const {
    const D64 d64;
    const V64 a = stream_alpha_key(d64, lo), b = stream_alpha_key(d64, hi);
    return hn::ConcatEven(DU(), hn::BitCast(DU(), b), hn::BitCast(DU(), a));  // the low words, in order
  }

 private:
  // Two halves of 24-bit integers as the floats of the block, times 2^-24
  // (sobol::top24_to_float's product).
  static VF unit(V64 a, V64 b) {
    const VU bits = hn::ConcatEven(DU(), hn::BitCast(DU(), b), hn::BitCast(DU(), a));  // the low words, in order
    return hn::ConvertTo(DF(), hn::BitCast(DI(), bits)) * hn::Set(DF(), 0x1p-24f);
  }
};
Streams streams(const Scene& sc, const Wave& w, std::size_t i0, VI vertex) {
  const D64 d64;
  const DH dh;
  const std::size_t half = hn::Lanes(d64);
  const VU v = hn::BitCast(DU(), vertex);
  const V64 vertex_lo = hn::PromoteTo(d64, hn::LowerHalf(dh, v)), vertex_hi = hn::PromoteTo(d64, hn::UpperHalf(dh, v));
  const V64 key_lo = hn::LoadU(d64, w.rng + i0), key_hi = hn::LoadU(d64, w.rng + i0 + half);
  if (!sc.zsobol) return {vertex_streams(d64, key_lo, vertex_lo), vertex_streams(d64, key_hi, vertex_hi), kNoZSobol};
  return {vertex_streams(d64, key_lo, vertex_lo, hn::LoadU(d64, w.zindex + i0), hn::LoadU(d64, w.zkey + i0)),
          vertex_streams(d64, key_hi, vertex_hi, hn::LoadU(d64, w.zindex + i0 + half),
                         hn::LoadU(d64, w.zkey + i0 + half)),
          sc.zsobol_bits};
}

// LightSampler::pick (pick_cdf) over the lights' cdf.
VI pick(M m, const Lights& lights, VF u) {
  const auto cdf_at = [&](M valid, VF i) { return light_value(valid, lights, hn::ConvertTo(DI(), i), kLightCdf); };
  return hn::ConvertTo(DI(), pick_cdf(DF(), m, lights.count, u, cdf_at));
}

// The light BVH (core/light_bvh.cpp), each half of a block in double lanes.
// Float lanes to the halves' doubles and back (exact both ways for the
// values here: floats, and whole numbers below 2^24).
VD half_d(VF v, bool upper) {
  const hn::Half<DF> dh;
  return hn::PromoteTo(DD(), upper ? hn::UpperHalf(dh, v) : hn::LowerHalf(dh, v));
}
V3D half_d(const V3& v, bool upper) { return {half_d(v.x, upper), half_d(v.y, upper), half_d(v.z, upper)}; }
MD half_mask(M m, bool upper) { return half_d(hn::IfThenElseZero(m, k(1.0f)), upper) != hn::Zero(DD()); }
VF join_f(VD lo, VD hi) {
  const hn::Rebind<float, DD> dfh;
  return hn::Combine(DF(), hn::DemoteTo(dfh, hi), hn::DemoteTo(dfh, lo));
}

// fn(slot, lane) for each lane of m, in lane order (the general materials'
// paths, shaded one at a time).
template <class Fn>
void for_each_lane(M m, std::size_t i0, Fn&& fn) {
  HWY_ALIGN std::int32_t set[kMaxLanes];
  hn::Store(hn::VecFromMask(DI(), hn::RebindMask(DI(), m)), DI(), set);
  for (std::size_t j = 0; j < lanes(); ++j)
    if (set[j] != 0) fn(i0 + j, j);
}

void generate_camera_rays(const Scene& sc, const Camera& c, const Wave& w) {
  const DF df;
  const CameraPlane<VF> plane{splat3(df, c.position[0], c.position[1], c.position[2]),
                              splat3(df, c.forward[0], c.forward[1], c.forward[2]),
                              splat3(df, c.right[0], c.right[1], c.right[2]),
                              splat3(df, c.up[0], c.up[1], c.up[2]),
                              k(c.tan_half_fov), k(c.aspect), k(c.inv_width), k(c.inv_height)};
  const V3 zero = zero3(), one = splat3(df, 1.0f, 1.0f, 1.0f);
  for (std::size_t i0 = 0; i0 < w.n; i0 += lanes()) {
    const M in = live(w.n, i0);
    const Streams rng = streams(sc, w, i0, hn::Zero(DI()));  // the camera's numbers are vertex 0's
    // The film position: pixel + FilmX/Y (wavefront_tracer.cpp).
    VF ux, uy;
    rng.u2(Dim::FilmX, ux, uy);
    const VF fx = hn::ConvertTo(df, load(w, kPixelX, i0, in)) + ux;
    const VF fy = hn::ConvertTo(df, load(w, kPixelY, i0, in)) + uy;
    store(w, kFilmX, i0, in, fx);
    store(w, kFilmY, i0, in, fy);
    // Camera::generate_ray.
    V3 origin, dir;
    camera_ray(df, plane, c.aperture_radius, c.focus_distance, fx, fy,
               [&](VF& lu, VF& lv) { rng.u2(Dim::LensX, lu, lv); }, origin, dir);
    store3(w, kOx, i0, in, origin);
    store3(w, kDx, i0, in, dir);
    store(w, kTmax, i0, in, k(std::numeric_limits<float>::infinity()));
    if (sc.alpha) store(w, kAlphaKey, i0, in, hn::BitCast(DI(), rng.alpha_key()));
    if (sc.textured) {
      store(w, kConeWidth, i0, in, k(sc.camera_cone_width));
      store(w, kConeSpread, i0, in, k(sc.camera_cone_spread));
    }
    // A fresh path: beta 1, L 0, PreviousVertex{} (at 0, pdf 0, an impulse,
    // the BSDF technique), no rays yet, alive, about to reach vertex 1.
    store3(w, kBetaR, i0, in, one);
    store3(w, kLR, i0, in, zero);
    store3(w, kPrevX, i0, in, zero);
    store3(w, kPrevNx, i0, in, zero);
    store(w, kPrevPdf, i0, in, k(0.0f));
    store_mask(w, kPrevImpulse, i0, in, in);
    store_mask(w, kPrevBsdfTechnique, i0, in, in);
    store(w, kRays, i0, in, hn::Zero(DI()));
    store(w, kVertex, i0, in, hn::Set(DI(), 1));
    store_mask(w, kAlive, i0, in, in);
  }
}

void prefetch_hits(const Scene& sc, const Wave& w) {
  HWY_ALIGN std::int32_t tri[hn::MaxLanes(DI())];
  for (std::size_t i0 = 0; i0 < w.n; i0 += lanes()) {
    const M found = load_mask(w, kFound, i0, live(w.n, i0));
    if (hn::AllFalse(DF(), found)) continue;
    const VI shape = load(w, kShape, i0, found);
    const M mesh = hn::AndNot(shape_flag(found, sc, shape, kIsSphere), found);
    if (hn::AllFalse(DF(), mesh)) continue;
    const VI t = shape_int(mesh, sc, shape, kFirstTriangle) + load(w, kPrim, i0, mesh);
    hn::Store(hn::IfThenElse(hn::RebindMask(DI(), mesh), t, hn::Set(DI(), -1)), DI(), tri);
    for (std::size_t j = 0; j < lanes(); ++j) {
      if (tri[j] < 0) continue;
      const float* p = sc.triangles + 12 * static_cast<std::size_t>(tri[j]);
      __builtin_prefetch(p);       // p0 ...
      __builtin_prefetch(p + 11);  // ... n: a triangle may straddle two lines
    }
    if (!sc.vertex_normals) continue;
    // And the vertex normals of those whose frame resolve() makes (kNormalsAt).
    const VI at = shape_int(mesh, sc, shape, kNormalsAt);
    const M framed = hn::And(mesh, fmask(hn::Not(at < hn::Zero(DI()))));
    hn::Store(hn::IfThenElse(hn::RebindMask(DI(), framed), at + load(w, kPrim, i0, framed), hn::Set(DI(), -1)), DI(), tri);
    for (std::size_t j = 0; j < lanes(); ++j) {
      if (tri[j] < 0) continue;
      const float* n = sc.vertex_normals + 9 * static_cast<std::size_t>(tri[j]);
      __builtin_prefetch(n);
      __builtin_prefetch(n + 8);
    }
  }
}

// A hit as core/simd/lanes-inl.h's surface_point reads it, for the lanes of
// m: the path's ray and distance (kOx.., kDx.., kHitT), the shape's
// triangle (Scene::triangles: corners and normal) or sphere (kCenter,
// kRadius, kFlipped), and the instance's placement (PlacementField).
struct HitLanes {
  const Scene& sc;
  const Wave& w;
  std::size_t i0;
  VI shape, instance;
  void ray(M m, V3& o, V3& dir, VF& t) const {
    o = load3(w, kOx, i0, m);
    dir = load3(w, kDx, i0, m);
    t = load(w, kHitT, i0, m);
  }
  void triangle(M m, V3& p0, V3& p1, V3& p2, V3& n) const {
    const VI tri = shape_int(m, sc, shape, kFirstTriangle) + load(w, kPrim, i0, m);
    p0 = gather3(m, sc.triangles, tri, 12, 0);
    p1 = gather3(m, sc.triangles, tri, 12, 3);
    p2 = gather3(m, sc.triangles, tri, 12, 6);
    n = gather3(m, sc.triangles, tri, 12, 9);
  }
  M sphere(M m, V3& center, VF& radius) const {
    center = shape_value3(m, sc, shape, kCenter);
    radius = shape_value(m, sc, shape, kRadius);
    return shape_flag(m, sc, shape, kFlipped);
  }
  V3 column(M m, int field) const { return gather3(m, sc.placements, instance, kPlacementFloats, field); }
  void to_local(M m, V3 (&c)[4]) const {
    for (int k = 0; k < 4; ++k) c[k] = column(m, kToLocal + 3 * k);
  }
  void to_world(M m, V3 (&c)[4]) const {
    for (int k = 0; k < 4; ++k) c[k] = column(m, kToWorld + 3 * k);
  }
  void to_normal(M m, V3 (&c)[3]) const {
    for (int k = 0; k < 3; ++k) c[k] = column(m, kToNormal + 3 * k);
  }
};

// An instance's placement as core/simd/texture_inputs-inl.h and
// shading_frame-inl.h read it: the columns of Scene::placements
// (PlacementField) gathered for the lanes of m, but the inverse transpose's,
// which resolve()'s surface_point gathered already for every placed lane
// (`normal`), and whether it mirrors (kMirrors).
struct PlacementLanes {
  const Scene& sc;
  VI instance;
  const V3 (&normal)[3];
  V3 column(M m, int field) const { return gather3(m, sc.placements, instance, kPlacementFloats, field); }
  void linear(M m, V3 (&c)[3]) const {
    for (int k = 0; k < 3; ++k) c[k] = column(m, kToWorld + 3 * k);
  }
  void to_local(M m, V3 (&c)[4]) const {
    for (int k = 0; k < 4; ++k) c[k] = column(m, kToLocal + 3 * k);
  }
  void to_normal(M, V3 (&c)[3]) const {
    for (int k = 0; k < 3; ++k) c[k] = normal[k];
  }
  M mirrors(M m) const { return hn::And(m, gather(m, sc.placements, instance, kPlacementFloats, kMirrors) > k(0.0f)); }
};

void resolve(const Scene& sc, const Wave& w) {
  const DF df;
  for (std::size_t i0 = 0; i0 < w.n; i0 += lanes()) {
    const M in = live(w.n, i0);
    store(w, kRays, i0, in, load(w, kRays, i0, in) + hn::Set(DI(), 1));
    const M found = load_mask(w, kFound, i0, in);
    if (hn::AllFalse(df, found)) continue;
    const VI shape = load(w, kShape, i0, found);
    const M sphere = shape_flag(found, sc, shape, kIsSphere), mesh = hn::AndNot(sphere, found);
    // A hit on an instance (kInstance not kNoInstance, all ones) was found
    // in its group's own space: resolved there, then placed by the
    // instance's transforms, as CompiledScene::resolve does.
    M placed = hn::FirstN(df, 0);
    VI instance = hn::Zero(DI());
    if (sc.instanced) {
      instance = load(w, kInstance, i0, found);
      placed = hn::And(found, fmask(instance != hn::Set(DI(), -1)));
    }
    // The point, its error bound and the front normal in world space
    // (CompiledScene::resolve: core/simd/lanes-inl.h's surface_point).
    V3 p, error, n, to_normal[3];
    surface_point(df, mesh, sphere, placed, load(w, kHitU, i0, mesh), load(w, kHitV, i0, mesh),
                  HitLanes{sc, w, i0, shape, instance}, p, error, n, to_normal);
    const PlacementLanes place{sc, instance, to_normal};
    store3(w, kPx, i0, found, p);
    store3(w, kErrX, i0, found, error);
    store3(w, kNx, i0, found, n);
    // resolve's Frame(n) (the geometric normal's) for the lanes of m, no shading normal.
    const auto store_normal_frame = [&](M m) {
      V3 fs, ft;
      frame(df, n, fs, ft);
      store3(w, kFsX, i0, m, fs);
      store3(w, kFtX, i0, m, ft);
      store3(w, kFnX, i0, m, n);
      store_mask(w, kShadingNormal, i0, m, hn::FirstN(df, 0));
    };
    // By core, path by path: the hits whose Surfel core makes (below).
    M by_core = hn::FirstN(df, 0);
    // A normal that is not finite (a sliver's): resolve() marks its Surfel
    // shading_normal (NaN != NaN), and Surfel then absorbs the path. The
    // lanes leave such hits, like every kGeneral shape's, to core's Surfel.
    const M finite = hn::And(hn::IsFinite(n.x), hn::And(hn::IsFinite(n.y), hn::IsFinite(n.z)));
    M general = hn::AndNot(finite, found);
    by_core = hn::Or(by_core, general);
    if (sc.general) {
      general = hn::Or(general, shape_flag(found, sc, shape, kGeneral));
      by_core = hn::Or(by_core, shape_flag(general, sc, shape, kResolveByCore));
      // The others shade in the geometric normal's Frame (resolve's Frame(n)), made here.
      if (const M plain = hn::AndNot(by_core, general); !hn::AllFalse(df, plain)) {
        store_normal_frame(plain);
        store_mask(w, kHasParams, i0, plain, hn::FirstN(df, 0));
      }
    }
    store_mask(w, kShadeByCore, i0, found, general);
    // A frame of its own (kFramed), which the lanes shade in, made here as
    // CompiledScene::resolve makes it (below).
    if (sc.framed) {
      const M framed = shape_flag(hn::AndNot(hn::Or(general, by_core), found), sc, shape, kFramed);
      // The frames the lanes make (CompiledScene::shading_frame): of vertex normals (kNormalsAt), of tangents
      // (kTangentsAt) about those or the geometric normal, and Frame(n) for a flat textured mesh (kTexturedHits;
      // its texture lookups' footprint below); a normal map's tilt after the texels are read (below).
      const VI normals_at = shape_int(framed, sc, shape, kNormalsAt);
      const M smooth = hn::And(framed, fmask(hn::Not(normals_at < hn::Zero(DI()))));
      M tangents = hn::FirstN(df, 0);
      VI tangents_at = hn::Zero(DI());
      if (sc.vertex_tangents) {
        tangents_at = shape_int(framed, sc, shape, kTangentsAt);
        tangents = hn::And(framed, fmask(hn::Not(tangents_at < hn::Zero(DI()))));
      }
      const M here = hn::Or(smooth, tangents);
      const M textured = sc.textured_hits ? shape_flag(framed, sc, shape, kTexturedHits) : hn::FirstN(df, 0);
      by_core = hn::Or(by_core, hn::AndNot(hn::Or(here, textured), framed));
      if (!hn::AllFalse(df, here)) {
        // CompiledScene::shading_frame (core/simd/shading_frame-inl.h): the vertex normals' shading normal, the
        // frame about it of Frame(ns) or of the tangents, read from their per-triangle arrays.
        const auto normals = [&](M m, V3 (&vn)[3]) {
          const VI tri = normals_at + load(w, kPrim, i0, m);
          for (int k = 0; k < 3; ++k) vn[k] = gather3(m, sc.vertex_normals, tri, 9, 3 * k);
        };
        const auto vertex_tangents = [&](M m, V3 (&t)[3], VF (&tw)[3]) {
          const VI tri = tangents_at + load(w, kPrim, i0, m);
          for (int k = 0; k < 3; ++k) {
            t[k] = gather3(m, sc.vertex_tangents, tri, 12, 4 * k);
            tw[k] = gather(m, sc.vertex_tangents, tri, 12, 4 * k + 3);
          }
        };
        const auto flipped = [&](M m) { return shape_flag(m, sc, shape, kFlipped); };
        V3 fs, ft, ns;
        const M shading = surface_frame(df, load(w, kHitU, i0, here), load(w, kHitV, i0, here), n, smooth, normals,
                                        tangents, vertex_tangents, flipped, placed, place, fs, ft, ns);
        store3(w, kFsX, i0, here, fs);
        store3(w, kFtX, i0, here, ft);
        store3(w, kFnX, i0, here, ns);
        store_mask(w, kShadingNormal, i0, here, shading);
        store_mask(w, kHasParams, i0, here, hn::FirstN(df, 0));
      }
      if (!hn::AllFalse(df, textured)) {
        // CompiledScene::shading_frame's Frame(n) where no vertex normals made one.
        if (const M flat = hn::AndNot(here, textured); !hn::AllFalse(df, flat)) store_normal_frame(flat);
        // CompiledScene::read_textures' footprint: the texture coordinates and the width of the ray cone there in
        // uv (footprint_width), from the uv area per world area (core/simd/texture_inputs-inl.h).
        TextureInputs<VF> tex{hn::Zero(df), hn::Zero(df), hn::Zero(df)};
        if (const M tmesh = hn::AndNot(sphere, textured); !hn::AllFalse(df, tmesh)) {
          // A mesh's: of the shape's triangle prim and, where the mesh has them (kUvsAt), its corners' uvs.
          const VI tri = shape_int(tmesh, sc, shape, kFirstTriangle) + load(w, kPrim, i0, tmesh);
          const VI uvs_at = shape_int(tmesh, sc, shape, kUvsAt);
          const M has_uvs = hn::And(tmesh, fmask(hn::Not(uvs_at < hn::Zero(DI()))));
          const auto corner_uvs = [&](M m) {
            const VI at = uvs_at + load(w, kPrim, i0, m);
            CornerUvs<VF> c;
            for (int k = 0; k < 3; ++k) {
              c.u[k] = gather(m, sc.triangle_uvs, at, 6, 2 * k);
              c.v[k] = gather(m, sc.triangle_uvs, at, 6, 2 * k + 1);
            }
            return c;
          };
          tex = triangle_texture_inputs(df, load(w, kHitU, i0, tmesh), load(w, kHitV, i0, tmesh),
                                        gather3(tmesh, sc.triangles, tri, 12, 0),
                                        gather3(tmesh, sc.triangles, tri, 12, 3),
                                        gather3(tmesh, sc.triangles, tri, 12, 6), has_uvs, corner_uvs,
                                        hn::And(tmesh, placed), place);
        }
        if (const M tsphere = hn::And(sphere, textured); !hn::AllFalse(df, tsphere)) {
          // A sphere's, at the point p (in its own space by the instance's to_local).
          const TextureInputs<VF> ts = sphere_texture_inputs(df, p, shape_value3(tsphere, sc, shape, kCenter),
                                                             shape_value(tsphere, sc, shape, kRadius),
                                                             hn::And(tsphere, placed), place);
          tex.u = hn::IfThenElse(tsphere, ts.u, tex.u);
          tex.v = hn::IfThenElse(tsphere, ts.v, tex.v);
          tex.uv_per_area = hn::IfThenElse(tsphere, ts.uv_per_area, tex.uv_per_area);
        }
        const VF width = footprint_width(df, load(w, kConeWidth, i0, textured), load(w, kConeSpread, i0, textured),
                                         load3(w, kOx, i0, textured), load3(w, kDx, i0, textured), p, n,
                                         tex.uv_per_area);
        store(w, kTexU, i0, textured, tex.u);
        store(w, kTexV, i0, textured, tex.v);
        store(w, kTexWidth, i0, textured, width);
        store_mask(w, kHasParams, i0, textured, shape_flag(textured, sc, shape, kTexturedParams));
        // The texels: OpenImageIO's lookups, by core, path by path, into the slot's SurfaceParams and kMapR...
        for_each_lane(textured, i0, [&](std::size_t i, std::size_t) { general_texels(sc, w, i); });
        // A normal map tilts the frame (CompiledScene::read_textures: normal_mapped_frame).
        if (const M mapped = shape_flag(textured, sc, shape, kNormalMapped); !hn::AllFalse(df, mapped)) {
          V3 fs = load3(w, kFsX, i0, mapped), ft = load3(w, kFtX, i0, mapped), fn = load3(w, kFnX, i0, mapped);
          M shading;
          const M tilted = hn::And(mapped, normal_mapped_frame(df, load3(w, kMapR, i0, mapped),
                                                               shape_value(mapped, sc, shape, kNormalMapScale), n, fs,
                                                               ft, fn, shading));
          store3(w, kFsX, i0, tilted, fs);
          store3(w, kFtX, i0, tilted, ft);
          store3(w, kFnX, i0, tilted, fn);
          store_mask(w, kShadingNormal, i0, tilted, shading);
        }
      }
    }
    for_each_lane(by_core, i0, [&](std::size_t i, std::size_t) { general_resolve(sc, w, i); });
  }
}

// Under light_sampling solid_angle: core/simd/spherical-inl.h's
// solid_angle_draw from ref of the lights in the lanes of m (triangles p0
// p1 p2; spheres, where `sphere`: centre p0, radius p1.x), computed in the
// double halves of the registers and carried to floats, as LightSampler's
// sample() and pdf() carry it; with u (lu, lv) given, the point drawn.
using SolidAngleLanes = SolidAngleDraw<VF, M>;
// Under light_sampling area: no lane in solid angle.
SolidAngleLanes no_solid_angle() { return {hn::FirstN(DF(), 0), k(0.0f), k(0.0f), k(0.0f), zero3()}; }
SolidAngleLanes solid_angle_lanes(M m, M sphere, const V3& ref, const V3& p0, const V3& p1, const V3& p2,
                                  const VF* lu = nullptr, const VF* lv = nullptr) {
  const DD dd;
  VD use[2], density[2], b1[2], b2[2];
  V3D n[2];
  for (int h = 0; h < 2; ++h) {
    const MD in = half_mask(m, h);
    const VD zero = hn::Zero(dd);
    const SolidAngleDraw<VD, MD> view =
        solid_angle_draw(dd, in, half_mask(sphere, h), half_d(ref, h), half_d(p0, h), half_d(p1, h), half_d(p2, h),
                         lu != nullptr, lu ? half_d(*lu, h) : zero, lv ? half_d(*lv, h) : zero);
    use[h] = hn::IfThenElseZero(view.use, hn::Set(dd, 1.0));
    density[h] = view.density;
    b1[h] = view.b1;
    b2[h] = view.b2;
    n[h] = view.n;
  }
  SolidAngleLanes sa;
  sa.use = hn::And(m, join_f(use[0], use[1]) != k(0.0f));
  sa.density = join_f(density[0], density[1]);
  sa.b1 = join_f(b1[0], b1[1]);
  sa.b2 = join_f(b2[0], b2[1]);
  sa.n = {join_f(n[0].x, n[1].x), join_f(n[0].y, n[1].y), join_f(n[0].z, n[1].z)};
  return sa;
}

// The lanes of m whose light entry is a sphere (none if the scene has no sphere light).
M sphere_lights(M m, const Lights& lights, VI entry) {
  if (!lights.sphere) return hn::FirstN(DF(), 0);
  return hn::And(m, gather(m, lights.sphere, entry, 1, 0) != k(0.0f));
}

// LightSampler::pdf(prev.p, s) of triangle and sphere lights, in the lanes
// of lit (hits on emitters).
VF triangle_light_pdf(const Scene& sc, const Wave& w, std::size_t i0, M lit, VI shape, const V3& n) {
  const DF df;
  const VI first = shape_int(lit, sc, shape, kFirstLight);
  const M light = hn::And(lit, fmask(hn::Not(first < hn::Zero(DI()))));
  const VI entry = first + load(w, kPrim, i0, light);
  const VF inv_area = light_value(light, sc.lights, entry, kLightInvArea);
  VF pmf = light_value(light, sc.lights, entry, kLightPmf);
  if (sc.lights.bvh_nodes && !hn::AllFalse(df, light)) {
    // LightSampler::pick_pmf from the previous vertex's query: the
    // tree's share for the tree's lights (their power pmf is 0).
    const VI safe_entry = hn::IfThenElseZero(hn::RebindMask(DI(), light), entry);
    const VI tree_light = hn::GatherIndex(DI(), sc.lights.bvh_light, safe_entry);
    const M in_tree = hn::And(light, fmask(hn::Not(tree_light < hn::Zero(DI()))));
    // core/simd/lights-inl.h's pick_pmf, the tree's walk back in the registers' double halves.
    const auto share_of = [&](M m) {
      const V3 qp = load3(w, kPrevX, i0, m), qn = load3(w, kPrevNx, i0, m);
      const VF tl = hn::ConvertTo(df, hn::IfThenElseZero(hn::RebindMask(DI(), m), tree_light));
      const VD grid = hn::Set(DD(), static_cast<double>(sc.lights.bvh_grid));
      VD share[2];
      for (int h = 0; h < 2; ++h)
        share[h] = bvh_share(DD(), DDI(), hn::RebindToUnsigned<DD>(), BvhTable<DD, DDI>{DD(), DDI(), sc.lights.bvh_nodes},
                             sc.lights.bvh_trail, half_d(qp, h), half_d(qn, h), half_d(tl, h), grid, half_mask(m, h));
      return join_f(share[0], share[1]);
    };
    pmf = pick_pmf(df, in_tree, pmf, share_of);
  }
  // LightSampler::pdf's densities and zero rule (emitter_hit_pdf), the
  // solid-angle rule in the registers' double halves.
  const V3 prev = load3(w, kPrevX, i0, light);
  const auto solid_angle = [&](M m) {
    if (!sc.solid_angle) return no_solid_angle();
    return solid_angle_lanes(m, sphere_lights(m, sc.lights, entry), prev, light_value3(m, sc.lights, entry, kLightP0),
                             light_value3(m, sc.lights, entry, kLightP1), light_value3(m, sc.lights, entry, kLightP2));
  };
  return emitter_hit_pdf(df, light, prev, load3(w, kPx, i0, light), n, pmf, inv_area,
                         sc.lights.bvh || sc.solid_angle, solid_angle);
}

// emission_weight (core/strategy_weights.h) for the lanes of lit (0 elsewhere).
VF emission_weight(const Scene& sc, const Wave& w, std::size_t i0, M lit, VF light_pdf) {
  const M impulse = load_mask(w, kPrevImpulse, i0, lit);
  const M bsdf_technique = load_mask(w, kPrevBsdfTechnique, i0, lit);
  const VF prev_pdf = load(w, kPrevPdf, i0, lit);
  return hn::IfThenElseZero(
      lit, pathlab::HWY_NAMESPACE::emission_weight(DF(), sc.strategy, impulse, bsdf_technique, prev_pdf, light_pdf));
}

// An environment image's rotation (GLM's columns) applied to v, as
// core/environment_map.cpp's rotate: (m[0] v.x + m[1] v.y) + m[2] v.z.
V3 rotate(const float* m, const V3& v) {
  const DF df;
  return to_world(splat3(df, m[0], m[1], m[2]), splat3(df, m[3], m[4], m[5]), splat3(df, m[6], m[7], m[8]), v.x, v.y,
                  v.z);
}

// An environment image's texel (x, y): its index among the texels.
VI texel_index(const Sky& s, VI x, VI y) { return y * hn::Set(DI(), static_cast<std::int32_t>(s.width)) + x; }

// The image sampler's cdfs as the generic code reads them (entry i of the
// rows', entry i of row y's; core/simd/lights-inl.h), gathered in the lanes of m.
struct SkyCdfs {
  const Sky& s;
  VF row(M m, VF i) const { return gather(m, s.row_cdf, hn::ConvertTo(DI(), i), 1, 0); }
  VF column(M m, VF y, VF i) const {
    const VI start = hn::ConvertTo(DI(), y) * hn::Set(DI(), static_cast<std::int32_t>(s.width) + 1);
    return gather(m, s.column_cdf, start + hn::ConvertTo(DI(), i), 1, 0);
  }
};

// EnvironmentMap::lookup in the lanes of m (core/simd/environment-inl.h's
// env_lookup): the radiance of the texel dir falls in, and the density in
// solid angle with which the map is sampled there.
void env_lookup(const Sky& s, M m, const V3& dir, V3& Le, VF& pdf) {
  VF x, y;
  pdf = pathlab::HWY_NAMESPACE::env_lookup(DF(), m, rotate(s.to_local, dir), static_cast<std::size_t>(s.width),
                                           static_cast<std::size_t>(s.height), SkyCdfs{s}, x, y);
  pdf = hn::IfThenElseZero(m, pdf);
  Le = gather3(m, s.image, texel_index(s, hn::ConvertTo(DI(), x), hn::ConvertTo(DI(), y)), 3, 0);
}

// EnvironmentMap::sample in the lanes of ok (u = (ux, uy)):
// distribution2d_sample and env_sample_direction (core/simd/), and the
// radiance of the texel drawn; the lanes it gives none leave ok.
void env_sample(const Sky& s, VF ux, VF uy, M& ok, V3& wi, V3& Le, VF& pdf) {
  const DF df;
  VF px, py, uv_pdf, x, y;
  distribution2d_sample(df, ok, static_cast<std::size_t>(s.width), static_cast<std::size_t>(s.height), ux, uy,
                        SkyCdfs{s}, px, py, uv_pdf, x, y);
  wi = env_sample_direction(df, ok, px, py, uv_pdf, splat3(df, s.to_world[0], s.to_world[1], s.to_world[2]),
                            splat3(df, s.to_world[3], s.to_world[4], s.to_world[5]),
                            splat3(df, s.to_world[6], s.to_world[7], s.to_world[8]), pdf);
  Le = gather3(ok, s.image, texel_index(s, hn::ConvertTo(DI(), x), hn::ConvertTo(DI(), y)), 3, 0);
}

// The sun disks' radiance and density along dir added to Le and pdf.
void add_suns(const Sky& s, const V3& dir, V3& Le, VF& pdf) {
  const DF df;
  for (std::size_t j = 0; j < s.suns; ++j) {
    const float* sun = s.sun + j * kSunFields;
    add_sun(df, dir, splat3(df, sun[kSunN], sun[kSunN + 1], sun[kSunN + 2]), k(sun[kSunSin2]),
            splat3(df, sun[kSunLe], sun[kSunLe + 1], sun[kSunLe + 2]), k(sun[kSunPdf]), Le, pdf);
  }
}

// The sky as core/simd/lights-inl.h's sky_sample and sky_along read it:
// Sky's tables, and each lane's light entry (for sky_sample's sun disks).
struct SkyView {
  const Sky& s;
  VI light;
  bool image() const { return s.image != nullptr; }
  M sample_image(M m, VF ux, VF uy, V3& wi, V3& Le, VF& pdf) const {
    M drawn = m;
    env_sample(s, ux, uy, drawn, wi, Le, pdf);
    return drawn;
  }
  void lookup(M m, const V3& dir, V3& Le, VF& pdf) const { env_lookup(s, m, dir, Le, pdf); }
  V3 radiance() const { return splat3(DF(), s.Le[0], s.Le[1], s.Le[2]); }
  VF env_pmf() const { return k(s.pmf); }
  void add_suns(const V3& dir, V3& Le, VF& pdf) const { vector_stages::HWY_NAMESPACE::add_suns(s, dir, Le, pdf); }
  void along(M m, const V3& dir, V3& Le, VF& pdf) const {
    pathlab::HWY_NAMESPACE::sky_along(DF(), m, dir, *this, Le, pdf);
  }
  void sun_directions(M m, VF ux, VF uy, V3& wi) const {
    const DF d;
    for (std::size_t j = 0; j < s.suns; ++j) {
      const float* sun = s.sun + j * kSunFields;
      const M at_sun = hn::And(m, hn::RebindMask(d, light == hn::Set(DI(), static_cast<std::int32_t>(sun[kSunEntry]))));
      if (hn::AllFalse(d, at_sun)) continue;
      const auto at = [&](int f) { return splat3(d, sun[f], sun[f + 1], sun[f + 2]); };
      wi = select(at_sun, sun_direction(d, at(kSunS), at(kSunT), at(kSunN), k(sun[kSunOneMinusCos]), ux, uy), wi);
    }
  }
};

// LightSampler::sky along dir in the lanes of m (sky_along).
void sky_along(const Sky& s, M m, const V3& dir, V3& Le, VF& pdf) { SkyView{s, hn::Zero(DI())}.along(m, dir, Le, pdf); }

void add_emission(const Scene& sc, const Wave& w) {
  const DF df;
  const V3 zero = zero3();
  for (std::size_t i0 = 0; i0 < w.n; i0 += lanes()) {
    const M in = live(w.n, i0);
    const M found = load_mask(w, kFound, i0, in);
    const V3 beta = load3(w, kBetaR, i0, in);
    const V3 L = load3(w, kLR, i0, in);
    // Escaped: no environment, so Le = 0 and its weight 0; L += beta * (0 * 0).
    // A ray the accel refused (t = NaN) makes the sample bad (NaN).
    V3 L_new = L + beta * (k(0.0f) * zero);
    const M escaped = hn::AndNot(found, in);
    const M refused = hn::And(escaped, hn::IsNaN(load(w, kHitT, i0, escaped)));
    if (!hn::AllFalse(df, refused)) {
      const V3 nan = splat3(df, NAN, NAN, NAN);
      L_new = select(refused, nan, L_new);
    }
    if (const M sky = hn::AndNot(refused, escaped); sc.sky && !hn::AllFalse(df, sky)) {
      // The environment and sun disks along the ray (LightSampler::sky): in
      // the lanes, or path by path when core samples the lights (general_lights).
      V3 Le;
      VF density;
      if (sc.general_lights) {
        HWY_ALIGN float radiance[3][kMaxLanes] = {}, densities[kMaxLanes] = {};
        for_each_lane(sky, i0, [&](std::size_t i, std::size_t j) {
          float e[3];
          general_sky(sc, w, i, e, &densities[j]);
          for (int c = 0; c < 3; ++c) radiance[c][j] = e[c];
        });
        Le = load_lanes(radiance);
        density = hn::Load(df, densities);
      } else {
        sky_along(sc.skies, sky, load3(w, kDx, i0, sky), Le, density);
      }
      const VF weight = emission_weight(sc, w, i0, hn::AndNot(is_black(df, Le), sky), density);
      L_new = select(sky, L + beta * (weight * Le), L_new);
    }
    M alive = hn::FirstN(df, 0);
    if (!hn::AllFalse(df, found)) {
      // Surfel::emitted.
      const VI shape = load(w, kShape, i0, found);
      const V3 wo = -load3(w, kDx, i0, found);
      const V3 n = load3(w, kNx, i0, found);
      V3 emission = zero_unless(shape_flag(found, sc, shape, kEmits), shape_value3(found, sc, shape, kEmission));
      if (sc.textured) {
        // A textured emission's radiance at the hit: the texel resolve() read into the slot's SurfaceParams
        // (evaluate_textured), as Surfel::emitted takes it.
        const M textured = shape_flag(found, sc, shape, kTexturedEmission);
        if (!hn::AllFalse(df, textured)) {
          HWY_ALIGN float radiance[3][kMaxLanes] = {};
          for_each_lane(textured, i0, [&](std::size_t i, std::size_t j) {
            for (int c = 0; c < 3; ++c) radiance[c][j] = w.params[i].emission[c];
          });
          emission = select(textured, load_lanes(radiance), emission);
        }
      }
      const V3 Le = emitted_towards(df, shape_flag(found, sc, shape, kTwoSided), n, wo, emission);
      const M lit = hn::AndNot(is_black(df, Le), found);
      // LightSampler::pdf(prev.p, s).
      VF light_pdf;
      if (sc.general_lights) {
        // By core's LightSampler, path by path.
        HWY_ALIGN float density[kMaxLanes] = {};
        for_each_lane(lit, i0, [&](std::size_t i, std::size_t j) { density[j] = general_light_pdf(sc, w, i); });
        light_pdf = hn::Load(df, density);
      } else {
        light_pdf = triangle_light_pdf(sc, w, i0, lit, shape, n);
      }
      L_new = select(found, L + beta * (emission_weight(sc, w, i0, lit, light_pdf) * Le), L_new);
      // The path goes on if it may take another vertex and the surface scatters.
      alive = hn::And(fmask(hn::Not(load(w, kVertex, i0, found) > hn::Set(DI(), sc.max_vertex))),
                      shape_flag(found, sc, shape, kScatters));
    }
    store3(w, kLR, i0, in, L_new);
    store_mask(w, kAlive, i0, in, alive);
  }
}

// What a light sample brings to sample_lights: its direction, radiance and
// density, and the shadow ray towards it (origin, direction, tmax).
struct LightLanes {
  V3 wi, Le;
  VF pdf;
  VF ray[7];
};

// LightSampler::pick from the shading point sp (normal n, towards the
// viewer wo): each lane's light entry and its probability; the lanes of ok
// it picks nothing for (the tree gives them nothing) leave ok.
VI pick_light(const Scene& sc, VF u_choice, const V3& sp, const V3& n, const V3& wo, M& ok, VF& pmf) {
  const DF df;
  const Lights& lights = sc.lights;
  if (!lights.bvh) {
    const VI light = pick(ok, lights, u_choice);
    pmf = light_value(ok, lights, light, kLightPmf);
    return light;
  }
  // Under bvh: the grid point k of u_choice (in the registers' double
  // halves), then core/simd/lights-inl.h's tree_or_sky_pick: the tree's walk
  // from light_query(s, wo) below bvh_grid (in the double halves too), else
  // the sky's entry.
  VD grid_k[2];
  for (int h = 0; h < 2; ++h) grid_k[h] = light_grid_point(DD(), half_d(u_choice, h));
  const auto walk = [&](M tree, VF& share) {
    const V3 qn = facing_normal(df, n, wo);  // light_query's
    VD shares[2], tree_light[2];
    for (int h = 0; h < 2; ++h)
      bvh_pick(DD(), DDI(), BvhTable<DD, DDI>{DD(), DDI(), lights.bvh_nodes}, half_d(sp, h), half_d(qn, h), grid_k[h],
               hn::Set(DD(), static_cast<double>(lights.bvh_grid)), half_mask(tree, h), tree_light[h], shares[h]);
    share = join_f(shares[0], shares[1]);
    const M ok_tree = hn::And(tree, share > k(0.0f));
    const VI tl = hn::IfThenElseZero(hn::RebindMask(DI(), ok_tree), hn::ConvertTo(DI(), join_f(tree_light[0], tree_light[1])));
    return hn::IfThenElseZero(hn::RebindMask(DI(), ok_tree), hn::GatherIndex(DI(), lights.bvh_entry, tl));
  };
  const Sky& s = sc.skies;
  const auto starts = [&](M valid, VF i) { return gather(valid, s.starts, hn::ConvertTo(DI(), i), 1, 0); };
  const auto sky_entry = [&](M valid, VF j) { return hn::ConvertTo(DI(), gather(valid, s.entries, hn::ConvertTo(DI(), j), 1, 0)); };
  const auto pmf_of = [&](M valid, VI light) { return light_value(valid, lights, light, kLightPmf); };
  VI light;
  ok = tree_or_sky_pick(df, DI(), ok, join_f(grid_k[0], grid_k[1]),  // exact: below 2^24
                        k(lights.bvh_nodes ? static_cast<float>(lights.bvh_grid) : 0.0f), s.count, walk, starts,
                        sky_entry, pmf_of, light, pmf);
  return light;
}

// LightSampler::sample's point on a triangle or sphere light in the lanes
// of ok (core/simd/lights-inl.h's area_light_sample, the solid-angle rule in
// the registers' double halves), with its radiance and the shadow ray
// towards it; the lanes it gives no sample leave ok.
LightLanes triangle_light(const Scene& sc, const Wave& w, std::size_t i0, VI light, VF pmf, VF lu, VF lv, const V3& sp,
                          const V3& n, M& ok) {
  const DF df;
  const Lights& lights = sc.lights;
  AreaLight<VF, M> e;
  e.p0 = light_value3(ok, lights, light, kLightP0);
  e.p1 = light_value3(ok, lights, light, kLightP1);
  e.p2 = light_value3(ok, lights, light, kLightP2);
  e.n = light_value3(ok, lights, light, kLightNormal);
  e.sphere = sphere_lights(ok, lights, light);
  e.flip = hn::And(e.sphere, e.p1.y != k(0.0f));  // a sphere's p1 is (radius, flip, 0)
  e.two_sided = light_value(ok, lights, light, kLightTwoSided) != k(0.0f);
  e.inv_area = light_value(ok, lights, light, kLightInvArea);
  const auto solid_angle = [&](M m) {
    if (sc.solid_angle) return solid_angle_lanes(m, e.sphere, sp, e.p0, e.p1, e.p2, &lu, &lv);
    return no_solid_angle();
  };
  AreaLightSample<VF> s;
  ok = area_light_sample(df, ok, sp, e, pmf, lu, lv, solid_angle, false, s);
  LightLanes ls;
  ls.wi = s.wi;
  ls.pdf = s.pdf;
  ls.Le = light_value3(ok, lights, light, kLightLe);
  if (lights.textured) {
    // An emission texture's texel at the point, read by core, path by path.
    if (const M textured = hn::And(ok, gather(ok, lights.textured, light, 1, 0) != k(0.0f));
        !hn::AllFalse(df, textured)) {
      HWY_ALIGN float at[5][kMaxLanes], radiance[3][kMaxLanes];
      HWY_ALIGN std::int32_t entry[kMaxLanes];
      hn::Store(s.b1, df, at[0]), hn::Store(s.b2, df, at[1]);
      hn::Store(s.p.x, df, at[2]), hn::Store(s.p.y, df, at[3]), hn::Store(s.p.z, df, at[4]);
      hn::Store(light, DI(), entry);
      hn::Store(ls.Le.x, df, radiance[0]), hn::Store(ls.Le.y, df, radiance[1]), hn::Store(ls.Le.z, df, radiance[2]);
      for_each_lane(textured, i0, [&](std::size_t, std::size_t j) {
        const float p[3] = {at[2][j], at[3][j], at[4][j]};
        float e[3];
        general_light_emission(sc, entry[j], at[0][j], at[1][j], p, e);
        for (int c = 0; c < 3; ++c) radiance[c][j] = e[c];
      });
      ls.Le = load_lanes(radiance);
    }
  }

  V3 origin, dir;
  VF len;
  shadow_ray(df, ok, hn::FirstN(df, 0), sp, load3(w, kErrX, i0, ok), n, s.wi, s.p, s.error, s.n, origin, dir, len);
  const VF ray[7] = {origin.x, origin.y, origin.z, dir.x, dir.y, dir.z, len};
  std::copy(std::begin(ray), std::end(ray), ls.ray);
  return ls;
}

// LightSampler::sample of the sky's entries in the lanes of ok
// (core/simd/lights-inl.h's sky_sample), and the shadow ray escaping along
// the direction (Surfel::spawn); the lanes it gives no sample leave ok.
LightLanes sky_light(const Scene& sc, const Wave& w, std::size_t i0, VI light, VF lu, VF lv, const V3& sp, const V3& n,
                     M& ok) {
  const DF df;
  const Sky& s = sc.skies;
  // The environment's lanes (none where it is not sampled: its entry is -1).
  const M env = hn::RebindMask(df, light == hn::Set(DI(), static_cast<std::int32_t>(s.environment)));
  LightLanes ls;
  ok = sky_sample(df, ok, env, lu, lv, SkyView{s, light}, ls.wi, ls.Le, ls.pdf);
  V3 origin, dir;
  VF len;
  shadow_ray(df, ok, ok, sp, load3(w, kErrX, i0, ok), n, ls.wi, zero3(), zero3(), zero3(), origin, dir, len);
  const VF ray[7] = {origin.x, origin.y, origin.z, dir.x, dir.y, dir.z, len};
  std::copy(std::begin(ray), std::end(ray), ls.ray);
  return ls;
}

// LightSampler::sample for triangle and sphere lights sampled by area and
// the sky of Sky, in the lanes of ok; those it gives no sample leave ok.
LightLanes area_or_sky_light(const Scene& sc, const Wave& w, std::size_t i0, const Streams& rng, const V3& sp,
                             const V3& wo, const V3& n, M& ok) {
  const DF df;
  VF pmf;
  const VI light = pick_light(sc, rng.u(Dim::LightChoice), sp, n, wo, ok, pmf);
  VF lu, lv;
  rng.u2(Dim::LightX, lu, lv);
  // core/simd/lights-inl.h's sky_or_area_sample: the sky's lanes, the others.
  LightLanes from_sky{}, from_area{};
  M sky;
  ok = sky_or_area_sample(
      df, ok, light, hn::Set(DI(), static_cast<std::int32_t>(sc.skies.first_entry)), sky,
      [&](M m) {
        from_sky = sky_light(sc, w, i0, light, lu, lv, sp, n, m);
        return m;
      },
      [&](M m) {
        from_area = triangle_light(sc, w, i0, light, pmf, lu, lv, sp, n, m);
        return m;
      });
  if (hn::AllFalse(df, sky)) return from_area;
  LightLanes& ls = from_area;
  ls.wi = select(sky, from_sky.wi, ls.wi);
  ls.Le = select(sky, from_sky.Le, ls.Le);
  ls.pdf = hn::IfThenElse(sky, from_sky.pdf, ls.pdf);
  for (int a = 0; a < 7; ++a) ls.ray[a] = hn::IfThenElse(sky, from_sky.ray[a], ls.ray[a]);
  return ls;
}

// LightSampler::sample_delta and its shadow ray (shadow_ray: to the point,
// or escaping along a directional light's direction), in the lanes; the
// lanes of ok it gives no sample leave ok.
LightLanes delta_light(const Scene& sc, const Wave& w, std::size_t i0, const Streams& rng, const V3& sp, const V3& n,
                       M& ok) {
  const DF df;
  const DeltaLights& d = sc.deltas;
  // core/simd/lights-inl.h's delta_light_sample, over the delta lights' table.
  const auto pick_delta = [&](M m, VF u) {
    const auto cdf_at = [&](M valid, VF i) { return gather(valid, d.cdf, hn::ConvertTo(DI(), i), 1, 0); };
    return hn::ConvertTo(DI(), pick_cdf(df, m, d.count, u, cdf_at));
  };
  const auto light_of = [&](M m, VI light) {
    const auto field = [&](int f) { return gather(m, d.table, light, kDeltaFields, f); };
    const auto field3 = [&](int f) { return gather3(m, d.table, light, kDeltaFields, f); };
    const VF kind = field(kDeltaKind);
    return DeltaLightLanes<VF, M>{kind == k(static_cast<float>(kDeltaDirectional)),
                                  kind == k(static_cast<float>(kDeltaSpot)),
                                  field3(kDeltaPosition),
                                  field3(kDeltaDirection),
                                  field3(kDeltaIntensity),
                                  field(kDeltaCosOuter),
                                  field(kDeltaCosInner),
                                  field(kDeltaPmf)};
  };
  LightLanes ls;
  VF dist;
  DeltaLightLanes<VF, M> light;
  delta_light_sample(df, ok, rng.u(Dim::DeltaLightChoice), sp, pick_delta, light_of, light, ls.wi, dist, ls.Le);
  ls.pdf = light.pmf;
  // To a point's or spot's position (no error, its normal -wi), or escaping along a directional light's wi.
  V3 origin, dir;
  VF len;
  shadow_ray(df, ok, light.directional, sp, load3(w, kErrX, i0, ok), n, ls.wi, light.position, zero3(), -ls.wi, origin,
             dir, len);
  const VF ray[7] = {origin.x, origin.y, origin.z, dir.x, dir.y, dir.z, len};
  std::copy(std::begin(ray), std::end(ray), ls.ray);
  return ls;
}

// Any other lights (Scene::general_lights): LightSampler::sample and
// shadow_ray by core, path by path (general_light).
LightLanes other_light(const Scene& sc, const Wave& w, std::size_t i0, const Streams& rng, M& ok) {
  const DF df;
  HWY_ALIGN float u[3][kMaxLanes] = {}, wi[3][kMaxLanes] = {}, Le[3][kMaxLanes] = {}, pdf[kMaxLanes] = {},
                ray[7][kMaxLanes] = {};
  HWY_ALIGN std::int32_t sampled[kMaxLanes] = {};
  hn::Store(rng.u(Dim::LightChoice), df, u[0]);
  VF lu, lv;
  rng.u2(Dim::LightX, lu, lv);
  hn::Store(lu, df, u[1]);
  hn::Store(lv, df, u[2]);
  for_each_lane(ok, i0, [&](std::size_t i, std::size_t j) {
    GeneralLight gl;
    if (!general_light(sc, w, i, u[0][j], u[1][j], u[2][j], &gl)) return;
    sampled[j] = 1;
    for (int c = 0; c < 3; ++c) {
      wi[c][j] = gl.wi[c];
      Le[c][j] = gl.Le[c];
    }
    pdf[j] = gl.pdf;
    for (int a = 0; a < 7; ++a) ray[a][j] = gl.ray[a];
  });
  ok = hn::And(ok, fmask(hn::Load(DI(), sampled) != hn::Zero(DI())));
  LightLanes ls{load_lanes(wi), load_lanes(Le), hn::Load(df, pdf), {}};
  for (int a = 0; a < 7; ++a) ls.ray[a] = hn::Load(df, ray[a]);
  return ls;
}

// Each lane's shape's Disney closure (ShapeField kDiffuse...; no Lambert lobe).
ClosureLanes<VF> closure_lanes(M m, const Scene& sc, VI shape) {
  ClosureLanes<VF> c;
  c.lambert = zero3();
  for_each_closure_field(c, [&](auto& v, ShapeField field, FloatArray) {
    if constexpr (std::is_same_v<std::decay_t<decltype(v)>, VF>)
      v = shape_value(m, sc, shape, field);
    else
      v = shape_value3(m, sc, shape, field);
  });
  return c;
}

// The lanes of `framed` (a frame of their own: kFramed, not core's to
// shade) whose Surfel reads its parameters from Wave::params.
M textured_lanes(const Scene& sc, const Wave& w, std::size_t i0, M framed) {
  if (!sc.textured || hn::AllFalse(DF(), framed)) return hn::FirstN(DF(), 0);
  return load_mask(w, kHasParams, i0, framed);
}
// Surfel's MaterialView for the lanes of m: the Lambert albedo, and the
// Disney closure, of each lane's shape, or of its slot's SurfaceParams in
// the lanes of `textured`.
V3 albedo_lanes(M m, const Scene& sc, const Wave& w, std::size_t i0, VI shape, M textured) {
  const V3 albedo = shape_value3(m, sc, shape, kAlbedo);
  if (hn::AllFalse(DF(), textured)) return albedo;
  return select(textured, load3(w, kPrmAlbedo, i0, textured), albedo);
}
ClosureLanes<VF> closure_lanes(M m, const Scene& sc, const Wave& w, std::size_t i0, VI shape, M textured) {
  ClosureLanes<VF> c = closure_lanes(m, sc, shape);
  const M t = hn::And(m, textured);
  if (hn::AllFalse(DF(), t)) return c;
  for_each_closure_field(c, [&](auto& v, ShapeField, FloatArray a) {
    if constexpr (std::is_same_v<std::decay_t<decltype(v)>, VF>)
      v = hn::IfThenElse(t, load(w, a, i0, t), v);
    else
      v = select(t, load3(w, a, i0, t), v);
  });
  return c;
}

// Energy compensation's layers for the lanes of `on` (disney-inl.h's
// Energy), from their materials' tables in Scene::energy (`base`: each
// lane's first float there).
struct LaneEnergy {
  M lanes_on;
  VI base;
  const float* table;
  static constexpr bool any() { return true; }
  M on(DF) const { return lanes_on; }
  VF at(VI index) const {
    return hn::IfThenElseZero(lanes_on, hn::GatherIndex(DF(), table, hn::IfThenElseZero(hn::RebindMask(DI(), lanes_on), base + index)));
  }
  V3 specular_transmit(DF d, VF mu) const {
    return pathlab::HWY_NAMESPACE::specular_transmit(d, mu, [&](VF i) {
      const VI at3 = hn::Set(DI(), kEnergySpecular) + hn::ConvertTo(DI(), i) * hn::Set(DI(), 3);
      return V3{at(at3), at(at3 + hn::Set(DI(), 1)), at(at3 + hn::Set(DI(), 2))};
    });
  }
  VF coat_transmit(DF d, VF mu) const {
    return pathlab::HWY_NAMESPACE::coat_transmit(
        d, mu, [&](VF i) { return at(hn::Set(DI(), kEnergyCoat) + hn::ConvertTo(DI(), i)); });
  }
  V3 diffuse_scale(DF) const {
    return {at(hn::Set(DI(), kEnergyDiffuseScale)), at(hn::Set(DI(), kEnergyDiffuseScale + 1)),
            at(hn::Set(DI(), kEnergyDiffuseScale + 2))};
  }
};

// fn(std::integral_constant<unsigned, F>, energy, sampler) for the Disney
// lanes of m: F the lobes of the scene (Scene::disney), so that the lanes
// shade with the lobes core's ShadingPath compiles in; energy a LaneEnergy
// if some of the lanes' materials have energy tables, else NoEnergy
// (nothing of it compiled into the call); sampler the glossy lobes'
// (Scene::disney_cospow: CospowLobes, else VndfLobes).
template <class Fn>
void with_disney_model(M m, const Scene& sc, VI shape, Fn&& fn) {
  constexpr unsigned kLobes = 1u, kCoat = 2u;  // disney::Features
  const auto with_sampler = [&](auto lobes, const auto& energy) {
    if (sc.disney_cospow) fn(lobes, energy, CospowLobes{});
    else fn(lobes, energy, VndfLobes{});
  };
  const auto with_lobes = [&](const auto& energy) {
    if (sc.disney == (kLobes | kCoat)) with_sampler(std::integral_constant<unsigned, kLobes | kCoat>{}, energy);
    else with_sampler(std::integral_constant<unsigned, kLobes>{}, energy);
  };
  if (sc.energy) {
    const VI base = shape_int(m, sc, shape, kEnergy);
    const M on = hn::And(m, hn::RebindMask(DF(), base > hn::Set(DI(), -1)));
    if (!hn::AllFalse(DF(), on)) return with_lobes(LaneEnergy{on, base, sc.energy});
  }
  with_lobes(NoEnergy{});
}

// The lanes of m that the lanes shade as Disney materials.
M disney_lanes(M m, const Scene& sc, VI shape) {
  if (sc.disney == 0 || hn::AllFalse(DF(), m)) return hn::FirstN(DF(), 0);
  return hn::And(m, shape_value(m, sc, shape, kLaneMaterial) == k(static_cast<float>(kLaneDisney)));
}

// The frame the lanes of m shade in: the geometric normal n's (Frame(n)),
// or, for a hit that has one of its own (ShapeField kFramed; not core's:
// kShadeByCore), that frame as resolve() kept it. Returns those lanes.
M shading_frame(const Scene& sc, const Wave& w, std::size_t i0, M m, VI shape, const V3& n, V3& fs, V3& ft, V3& fn) {
  frame(DF(), n, fs, ft);
  fn = n;
  if (!sc.framed) return hn::FirstN(DF(), 0);
  const M framed = hn::AndNot(load_mask(w, kShadeByCore, i0, m), shape_flag(m, sc, shape, kFramed));
  if (!hn::AllFalse(DF(), framed)) {
    fs = select(framed, load3(w, kFsX, i0, framed), fs);
    ft = select(framed, load3(w, kFtX, i0, framed), ft);
    fn = select(framed, load3(w, kFnX, i0, framed), fn);
  }
  return framed;
}
// The lanes of m whose material is one-sided (Material::one_sided).
M one_sided_lanes(const Scene& sc, M m, VI shape) {
  return sc.one_sided ? shape_flag(m, sc, shape, kOneSided) : hn::FirstN(DF(), 0);
}
// The lanes of `framed` (shading_frame) whose hit has a shading normal (Surfel::shading_normal).
M shading_normal_lanes(const Wave& w, std::size_t i0, M framed) {
  return hn::AllFalse(DF(), framed) ? framed : load_mask(w, kShadingNormal, i0, framed);
}

// Surfel::eval and Surfel::pdf towards wi for the lanes of ok (which lose
// the lanes whose f is black): the Lambert and Disney lobes in the lanes
// (core/surfel.cpp, bsdf/lambert-inl.h, disney-inl.h), in the geometric
// normal's frame or a kFramed hit's own; the lanes of kShadeByCore by core,
// path by path.
void eval_bsdf(const Scene& sc, const Wave& w, std::size_t i0, VI shape, const V3& wo, const V3& n, const V3& wi, M& ok,
               V3& f, VF& pdf_bsdf) {
  const DF df;
  // In the geometric normal's frame, or the hit's own (kFramed).
  V3 fs, ft, fn, wo_local, wi_local;
  const M framed = shading_frame(sc, w, i0, ok, shape, n, fs, ft, fn);
  const M textured = textured_lanes(sc, w, i0, framed);
  // Surfel::eval's rules (surface_eval_ok): a one-sided surface's front, a shading normal's geometric side.
  const M one_sided = one_sided_lanes(sc, ok, shape), shading_normal = shading_normal_lanes(w, i0, framed);
  if (!hn::AllFalse(df, hn::Or(one_sided, shading_normal)))
    ok = hn::And(ok, surface_eval_ok(df, one_sided, shading_normal, dot(wo, n), dot(wi, n)));
  to_local_upper(df, fs, ft, fn, wo, wi, wo_local, wi_local);
  lambert_eval(df, albedo_lanes(ok, sc, w, i0, shape, textured), wi_local.z, f, pdf_bsdf);
  if (sc.impulses) {
    // A mirror's or a dielectric's f and pdf are 0 towards every direction (Surfel::eval, Surfel::pdf).
    const M lambert = shape_value(ok, sc, shape, kLaneMaterial) == k(static_cast<float>(kLaneLambert));
    f = zero_unless(lambert, f);
    pdf_bsdf = hn::IfThenElseZero(lambert, pdf_bsdf);
  }
  if (const M dm = disney_lanes(hn::AndNot(load_mask(w, kShadeByCore, i0, ok), ok), sc, shape); !hn::AllFalse(df, dm)) {
    // Surfel::eval and Surfel::pdf of a Disney material (disney::eval, disney::pdf).
    const ClosureLanes<VF> c = closure_lanes(dm, sc, w, i0, shape, textured);
    with_disney_model(dm, sc, shape, [&](auto lobes, const auto& energy, const auto& sampler) {
      constexpr unsigned F = decltype(lobes)::value;
      f = select(dm, disney_eval<F>(df, c, wo_local, wi_local, energy, {}), f);
      pdf_bsdf = hn::IfThenElse(dm, disney_pdf<F>(df, c, wo_local, wi_local, sampler, energy, {}), pdf_bsdf);
    });
  }
  if (const M general = load_mask(w, kShadeByCore, i0, ok); !hn::AllFalse(df, general)) {
    HWY_ALIGN float to[3][kMaxLanes], value[3][kMaxLanes] = {}, density[kMaxLanes] = {};
    hn::Store(wi.x, df, to[0]);
    hn::Store(wi.y, df, to[1]);
    hn::Store(wi.z, df, to[2]);
    for_each_lane(general, i0, [&](std::size_t i, std::size_t j) {
      const float d[3] = {to[0][j], to[1][j], to[2][j]};
      float fj[3];
      general_eval(sc, w, i, d, fj, &density[j]);
      for (int c = 0; c < 3; ++c) value[c][j] = fj[c];
    });
    f = select(general, load_lanes(value), f);
    pdf_bsdf = hn::IfThenElse(general, hn::Load(df, density), pdf_bsdf);
  }
  ok = hn::AndNot(is_black(df, f), ok);
}

// A shadow ray to trace for the lanes of ok, and the light it brings if
// nothing blocks it.
struct ShadowLanes {
  M ok;
  V3 unoccluded;
  VF ray[7];
};

// The block's shadow rays written to the kQ arrays from slot `queries` on,
// in path order, a delta light's before an area light's (the scalar stages'
// order, and so Embree's batch); returns how many.
// `alpha_keys`: the rays' alpha keys (Scene::alpha), else null.
std::size_t pack_shadow_rays(const Wave& w, std::size_t i0, std::size_t queries, const ShadowLanes* delta,
                             const ShadowLanes& area, const VU* alpha_keys) {
  const DF df;
  if (delta == nullptr) {
    const Packer pack(area.ok);
    for (int a = 0; a < 7; ++a) pack.store(w.f[kQOx + a] + queries, area.ray[a]);
    pack.store(w.f[kQUnR] + queries, area.unoccluded.x);
    pack.store(w.f[kQUnG] + queries, area.unoccluded.y);
    pack.store(w.f[kQUnB] + queries, area.unoccluded.z);
    pack.store(w.u[kQPath] + queries, hn::Iota(DU(), static_cast<std::uint32_t>(i0)));
    if (alpha_keys) pack.store(w.u[kQAlphaKey] + queries, *alpha_keys);
    return pack.count;
  }
  HWY_ALIGN std::uint32_t keys[kMaxLanes] = {};
  if (alpha_keys) hn::Store(*alpha_keys, DU(), keys);
  // Two rays a path: interleaved one lane at a time.
  HWY_ALIGN float v[2][10][kMaxLanes];
  HWY_ALIGN std::int32_t set[2][kMaxLanes];
  const ShadowLanes* both[2] = {delta, &area};
  for (int k2 = 0; k2 < 2; ++k2) {
    const ShadowLanes& s = *both[k2];
    for (int a = 0; a < 7; ++a) hn::Store(s.ray[a], df, v[k2][a]);
    hn::Store(s.unoccluded.x, df, v[k2][7]);
    hn::Store(s.unoccluded.y, df, v[k2][8]);
    hn::Store(s.unoccluded.z, df, v[k2][9]);
    hn::Store(hn::VecFromMask(DI(), hn::RebindMask(DI(), s.ok)), DI(), set[k2]);
  }
  std::size_t q = queries;
  for (std::size_t j = 0; j < lanes(); ++j)
    for (int k2 = 0; k2 < 2; ++k2) {
      if (set[k2][j] == 0) continue;
      for (int a = 0; a < 7; ++a) w.f[kQOx + a][q] = v[k2][a][j];
      for (int c = 0; c < 3; ++c) w.f[kQUnR + c][q] = v[k2][7 + c][j];
      w.u[kQPath][q] = static_cast<std::uint32_t>(i0 + j);
      if (alpha_keys) w.u[kQAlphaKey][q] = keys[j];
      ++q;
    }
  return q - queries;
}

std::size_t sample_lights(const Scene& sc, const Wave& w) {
  const DF df;
  std::size_t queries = 0;
  for (std::size_t i0 = 0; i0 < w.n; i0 += lanes()) {
    const M in = live(w.n, i0);
    const M alive = load_mask(w, kAlive, i0, in);
    if (hn::AllFalse(df, alive)) continue;
    const VI vertex = load(w, kVertex, i0, in);
    const Streams rng = streams(sc, w, i0, vertex);
    const V3 sp = load3(w, kPx, i0, alive);
    const V3 wo = -load3(w, kDx, i0, alive);
    const V3 n = load3(w, kNx, i0, alive);  // the geometric normal (eval_bsdf takes a kFramed hit's frame)
    const VI shape = load(w, kShape, i0, alive);

    // A delta light, in every strategy (LightSampler::sample_delta): f Le /
    // pdf, weight 1.
    ShadowLanes delta{hn::FirstN(df, 0), zero3(), {}};
    if (sc.deltas.count != 0) {
      delta.ok = alive;
      const LightLanes ls = delta_light(sc, w, i0, rng, sp, n, delta.ok);
      V3 f;
      VF pdf_bsdf;
      eval_bsdf(sc, w, i0, shape, wo, n, ls.wi, delta.ok, f, pdf_bsdf);
      delta.unoccluded = delta_light_contribution(f, ls.Le, ls.pdf);
      std::copy(std::begin(ls.ray), std::end(ls.ray), delta.ray);
    }

    // An area light, where the strategy samples them.
    ShadowLanes area{alive, zero3(), {}};
    M& ok = area.ok;
    if (sc.lights.count == 0 && !sc.general_lights)
      ok = hn::FirstN(df, 0);
    else
      ok = samples_area_lights(df, sc.strategy, ok, [&] { return rng.u(Dim::Technique); });
    if (!hn::AllFalse(df, ok)) {
      const LightLanes ls =
          sc.general_lights ? other_light(sc, w, i0, rng, ok) : area_or_sky_light(sc, w, i0, rng, sp, wo, n, ok);
      V3 f;
      VF pdf_bsdf;
      eval_bsdf(sc, w, i0, shape, wo, n, ls.wi, ok, f, pdf_bsdf);
      const VF weight = pathlab::HWY_NAMESPACE::light_sample_weight(df, sc.strategy, ls.pdf, pdf_bsdf);
      area.unoccluded = light_contribution(f, ls.Le, weight, ls.pdf);
      std::copy(std::begin(ls.ray), std::end(ls.ray), area.ray);
    }
    if (hn::AllFalse(df, hn::Or(delta.ok, ok))) continue;

    // The shadow rays, packed behind the previous ones with the slot of the
    // path each belongs to (add_light); each counts as one of its path's rays.
    // A vertex's shadow rays share its alpha key (core/alpha.h).
    const VU alpha_keys = sc.alpha ? rng.alpha_key() : hn::Zero(DU());
    queries += pack_shadow_rays(w, i0, queries, sc.deltas.count != 0 ? &delta : nullptr, area, sc.alpha ? &alpha_keys : nullptr);
    const VI rays = load(w, kRays, i0, alive);
    store(w, kRays, i0, alive,
          rays + hn::IfThenElseZero(hn::RebindMask(DI(), delta.ok), hn::Set(DI(), 1)) +
              hn::IfThenElseZero(hn::RebindMask(DI(), ok), hn::Set(DI(), 1)));
  }
  return queries;
}

void scatter(const Scene& sc, const Wave& w) {
  const DF df;
  for (std::size_t i0 = 0; i0 < w.n; i0 += lanes()) {
    const M in = live(w.n, i0);
    M ok = load_mask(w, kAlive, i0, in);
    if (hn::AllFalse(df, ok)) continue;
    VI vertex = load(w, kVertex, i0, in);
    const Streams rng = streams(sc, w, i0, vertex);

    // Surfel::scatter, Lambert (lambert::sample): nothing where the density
    // is unusable.
    V3 local;
    VF pdf;
    VF du, dv;
    rng.u2(Dim::DirectionX, du, dv);
    const M usable = lambert_sample(df, du, dv, k(sc.min_pdf), local, pdf);
    const VI shape = load(w, kShape, i0, ok);
    const M general = load_mask(w, kShadeByCore, i0, ok);
    // The impulses' lanes (mirror, dielectric) and the Disney lanes decide their own below.
    M impulses = hn::FirstN(df, 0);
    if (sc.impulses) {
      const VF material = shape_value(ok, sc, shape, kLaneMaterial);
      impulses = hn::AndNot(general, hn::And(ok, hn::Or(material == k(static_cast<float>(kLaneMirror)),
                                                        material == k(static_cast<float>(kLaneDielectric)))));
    }
    const M disneys = disney_lanes(hn::AndNot(general, ok), sc, shape);
    ok = hn::Or(hn::Or(hn::Or(general, impulses), disneys), hn::And(ok, usable));
    const V3 wo = -load3(w, kDx, i0, ok);
    const V3 n = load3(w, kNx, i0, ok);
    // The geometric normal's frame, or the hit's own (kFramed).
    V3 fs, ft, fn;
    const M framed = shading_frame(sc, w, i0, ok, shape, n, fs, ft, fn);
    const M textured = textured_lanes(sc, w, i0, framed);
    // Surfel::scatter's rules before the draw (surface_scatter_ok): nothing
    // from behind a one-sided material, nor from a dielectric whose two
    // normals disagree about wo's side.
    const VF wo_z = dot(wo, n), wo_fz = dot(wo, fn);
    const M one_sided = one_sided_lanes(sc, ok, shape), shading_normal = shading_normal_lanes(w, i0, framed);
    M glass = hn::FirstN(df, 0);
    if (!hn::AllFalse(df, impulses))
      glass = hn::And(impulses, shape_value(impulses, sc, shape, kLaneMaterial) == k(static_cast<float>(kLaneDielectric)));
    if (const M glass_shading_normal = hn::And(glass, shading_normal); !hn::AllFalse(df, hn::Or(one_sided, glass_shading_normal)))
      ok = hn::And(ok, surface_scatter_ok(df, one_sided, glass_shading_normal, wo_z, wo_fz));
    const VF side = upper_side(df, wo_fz);
    V3 wi = to_world(fs, ft, fn, local.x, local.y, local.z * side);
    V3 weight = albedo_lanes(ok, sc, w, i0, shape, textured);
    M impulse = hn::FirstN(df, 0), transmitted = impulse;
    const M im = hn::And(impulses, ok), g = hn::And(general, ok), dm = hn::And(disneys, ok);
    // The lobe choice, drawn once for the impulses' lanes, the Disney lanes and core's.
    const VF u_lobe = hn::AllFalse(df, hn::Or(hn::Or(im, g), dm)) ? hn::Zero(df) : rng.u(Dim::LobeChoice);
    if (!hn::AllFalse(df, dm)) {
      // Surfel::scatter_in_frame of a Disney material (wo's side up, as the
      // reflection models take it): a direction from the lobes' mixture,
      // weighted by f cos over the mixture's density there (disney_scatter, as disney::scatter).
      const ClosureLanes<VF> c = closure_lanes(dm, sc, w, i0, shape, textured);
      const V3 wo_local = to_local(fs, ft, fn, wo);
      const V3 wo_up{wo_local.x, wo_local.y, wo_local.z * side};
      with_disney_model(dm, sc, shape, [&](auto lobes, const auto& energy, const auto& sampler) {
        constexpr unsigned F = decltype(lobes)::value;
        V3 local_d, weight_d;
        VF pdf_d, family;
        const M drawn = disney_scatter<F>(df, c, wo_up, u_lobe, du, dv, sampler, energy, k(sc.min_pdf), {}, local_d,
                                          weight_d, pdf_d, family);
        wi = select(dm, to_world(fs, ft, fn, local_d.x, local_d.y, local_d.z * side), wi);
        weight = select(dm, weight_d, weight);
        pdf = hn::IfThenElse(dm, pdf_d, pdf);
        ok = hn::AndNot(hn::AndNot(drawn, dm), ok);
      });
    }
    if (!hn::AllFalse(df, im)) {
      // Surfel::scatter_in_frame of a mirror (wo's side up, as the
      // reflection models take it) and of a dielectric (the frame as is).
      const VF material = shape_value(im, sc, shape, kLaneMaterial);
      const M mirror = hn::And(im, material == k(static_cast<float>(kLaneMirror)));
      glass = hn::And(im, glass);
      const V3 wo_local = to_local(fs, ft, fn, wo);
      if (!hn::AllFalse(df, mirror)) {
        V3 local_m, weight_m;
        VF pdf_m;
        const M mirrored = mirror_sample(df, weight, u_lobe, V3{wo_local.x, wo_local.y, wo_local.z * side}, local_m,
                                         weight_m, pdf_m);
        wi = select(mirror, to_world(fs, ft, fn, local_m.x, local_m.y, local_m.z * side), wi);
        weight = select(mirror, weight_m, weight);
        pdf = hn::IfThenElse(mirror, pdf_m, pdf);
        ok = hn::AndNot(hn::AndNot(mirrored, mirror), ok);
      }
      if (!hn::AllFalse(df, glass)) {
        V3 local_g, weight_g;
        VF pdf_g;
        // Its tints, from the slot's SurfaceParams where textures give them (kHasParams).
        V3 reflectance = shape_value3(glass, sc, shape, kReflectance);
        V3 transmittance = shape_value3(glass, sc, shape, kTransmittance);
        if (const M tinted = hn::And(glass, textured); !hn::AllFalse(df, tinted)) {
          reflectance = select(tinted, load3(w, kPrmReflectance, i0, tinted), reflectance);
          transmittance = select(tinted, load3(w, kPrmTransmittance, i0, tinted), transmittance);
        }
        const M crossed = dielectric_sample(df, shape_value(glass, sc, shape, kIor), reflectance, transmittance, u_lobe,
                                            wo_local, local_g, weight_g, pdf_g, transmitted);
        wi = select(glass, to_world(fs, ft, fn, local_g.x, local_g.y, local_g.z), wi);
        weight = select(glass, weight_g, weight);
        pdf = hn::IfThenElse(glass, pdf_g, pdf);
        ok = hn::AndNot(hn::AndNot(crossed, glass), ok);
        transmitted = hn::And(glass, transmitted);
      }
      impulse = im;
    }
    // Surfel::scatter's rule after the draw (scattered_side_ok): under a
    // shading normal, wi on wo's geometric side, or across it if transmitted.
    if (const M lobes = hn::And(ok, shading_normal); !hn::AllFalse(df, lobes))
      ok = hn::And(ok, scattered_side_ok(df, lobes, transmitted, wo_z, dot(wi, n)));
    if (!hn::AllFalse(df, g)) {
      // Any other material: Surfel::scatter, path by path.
      HWY_ALIGN float u[3][kMaxLanes], dir[3][kMaxLanes] = {}, wt[3][kMaxLanes] = {}, density[kMaxLanes] = {};
      HWY_ALIGN std::int32_t scattered[kMaxLanes] = {}, impulse_of[kMaxLanes] = {};
      hn::Store(u_lobe, df, u[0]);
      hn::Store(du, df, u[1]);
      hn::Store(dv, df, u[2]);
      for_each_lane(g, i0, [&](std::size_t i, std::size_t j) {
        GeneralSample bs;
        if (!general_scatter(sc, w, i, u[0][j], u[1][j], u[2][j], &bs)) return;
        scattered[j] = 1;
        impulse_of[j] = bs.impulse ? 1 : 0;
        density[j] = bs.pdf;
        for (int c = 0; c < 3; ++c) {
          dir[c][j] = bs.wi[c];
          wt[c][j] = bs.weight[c];
        }
      });
      wi = select(g, load_lanes(dir), wi);
      weight = select(g, load_lanes(wt), weight);
      pdf = hn::IfThenElse(g, hn::Load(df, density), pdf);
      impulse = hn::Or(impulse, hn::And(g, fmask(hn::Load(DI(), impulse_of) != hn::Zero(DI()))));
      ok = hn::AndNot(hn::AndNot(fmask(hn::Load(DI(), scattered) != hn::Zero(DI())), g), ok);
    }
    ok = hn::AndNot(is_black(df, weight), ok);

    // Russian roulette (the scatter stage).
    const V3 beta = load3(w, kBetaR, i0, ok);
    const M rr = hn::And(ok, fmask(vertex > hn::Set(DI(), sc.rr_depth)));
    if (!hn::AllFalse(df, rr)) {
      VF survival;
      const M survives = roulette(df, rr, beta, rng.u(Dim::Roulette), weight, survival);
      ok = hn::Or(hn::AndNot(rr, ok), survives);
    }
    store3(w, kBetaR, i0, ok, beta * weight);

    // The PreviousVertex the scatter leaves.
    const V3 sp = load3(w, kPx, i0, ok);
    const PreviousVertexLanes<VF, M> prev =
        previous_vertex(df, sc.strategy, ok, sp, n, wo, pdf, impulse, [&] { return rng.u(Dim::Technique); });
    store3(w, kPrevX, i0, ok, prev.p);
    store3(w, kPrevNx, i0, ok, prev.n);
    store(w, kPrevPdf, i0, ok, prev.pdf);
    store_mask(w, kPrevImpulse, i0, ok, prev.impulse);
    store_mask(w, kPrevBsdfTechnique, i0, ok, prev.bsdf_technique);

    if (sc.textured && !hn::AllFalse(df, ok)) {
      // The ray cone after the scatter (scattered_cone, core/ray_cone.h; none under the point filter).
      VF width = hn::Zero(df), spread = hn::Zero(df);
      if (static_cast<TextureFilter>(sc.texture_filter) != TextureFilter::Point) {
        const V3 o = load3(w, kOx, i0, ok);
        scattered_cone(df, load(w, kConeWidth, i0, ok), load(w, kConeSpread, i0, ok), hn::Sqrt(dot(sp - o, sp - o)),
                       impulse, pdf, width, spread);
      }
      store(w, kConeWidth, i0, ok, width);
      store(w, kConeSpread, i0, ok, spread);
    }

    // Surfel::spawn(wi).
    const V3 err = load3(w, kErrX, i0, ok);
    store3(w, kOx, i0, ok, spawn_origin(df, sp, err, n, wi));
    store3(w, kDx, i0, ok, wi);
    store(w, kTmax, i0, ok, k(std::numeric_limits<float>::infinity()));
    if (sc.alpha) store(w, kAlphaKey, i0, ok, hn::BitCast(DI(), rng.alpha_key()));
    vertex = vertex + hn::Set(DI(), 1);
    store(w, kVertex, i0, ok, vertex);
    store_mask(w, kAlive, i0, in, ok);
  }
}

void hash_keys(std::uint64_t* keys, std::size_t n, std::uint64_t seed_key) {
  const D64 d64;
  const V64 seed = hn::Set(d64, seed_key);
  for (std::size_t i0 = 0; i0 < n; i0 += hn::Lanes(d64))
    hn::StoreU(stream_key(d64, seed, hn::LoadU(d64, keys + i0)), d64, keys + i0);
}

std::size_t compact(const Scene& sc, const Wave& w, void* samples, std::uint32_t first_slot) {
  static constexpr FloatArray kMovedFloats[] = {kOx,   kOy,   kOz,   kDx,   kDy,    kDz,    kTmax,  kBetaR,   kBetaG, kBetaB,
                                                kLR,   kLG,   kLB,   kPrevX, kPrevY, kPrevZ, kPrevPdf, kFilmX, kFilmY,
                                                kPrevNx, kPrevNy, kPrevNz};
  static constexpr UintArray kMovedUints[] = {kOutIndex, kRays, kVertex};
  static constexpr ByteArray kMovedBytes[] = {kPrevImpulse, kPrevBsdfTechnique};
  const DF df;
  const D64 d64;
  const DH dh;
  HWY_ALIGN std::int32_t dead[hn::MaxLanes(DI())];
  std::size_t m = 0;
  for (std::size_t i0 = 0; i0 < w.n; i0 += lanes()) {
    const M in = live(w.n, i0);
    const M alive = load_mask(w, kAlive, i0, in);
    // The paths that ended: FilmSample{film, L, rays, hits}, field by field
    // (a Sample built on the stack and copied whole would be read back
    // before its parts' stores retire: a store-forwarding stall per path).
    const M ended = hn::AndNot(alive, in);
    if (!hn::AllFalse(df, ended)) {
      hn::Store(hn::VecFromMask(DI(), hn::RebindMask(DI(), ended)), DI(), dead);
      for (std::size_t j = 0; j < lanes(); ++j) {
        if (dead[j] == 0) continue;
        const std::size_t i = i0 + j;
        char* out = static_cast<char*>(samples) + sizeof(Sample) * (w.u[kOutIndex][i] - first_slot);
        const std::uint32_t hits = w.u[kVertex][i] - (w.b[kFound][i] ? 0u : 1u);
        std::memcpy(out + offsetof(Sample, film_x), &w.f[kFilmX][i], sizeof(float));
        std::memcpy(out + offsetof(Sample, film_y), &w.f[kFilmY][i], sizeof(float));
        std::memcpy(out + offsetof(Sample, L) + 0 * sizeof(float), &w.f[kLR][i], sizeof(float));
        std::memcpy(out + offsetof(Sample, L) + 1 * sizeof(float), &w.f[kLG][i], sizeof(float));
        std::memcpy(out + offsetof(Sample, L) + 2 * sizeof(float), &w.f[kLB][i], sizeof(float));
        std::memcpy(out + offsetof(Sample, rays), &w.u[kRays][i], sizeof(std::uint32_t));
        std::memcpy(out + offsetof(Sample, hits), &hits, sizeof(std::uint32_t));
      }
    }
    // The survivors, packed behind the previous ones (m <= i0: a block is
    // read before anything is written over it).
    if (hn::AllFalse(df, ended) && m == i0) {
      m += hn::CountTrue(df, alive);
      continue;
    }
    const Packer pack(alive);
    const std::size_t count = pack.count;
    for (FloatArray a : kMovedFloats) pack.store(w.f[a] + m, hn::LoadU(df, w.f[a] + i0));
    if (sc.textured)
      for (FloatArray a : {kConeWidth, kConeSpread}) pack.store(w.f[a] + m, hn::LoadU(df, w.f[a] + i0));
    if (sc.alpha) pack.store(w.u[kAlphaKey] + m, hn::LoadU(DU(), w.u[kAlphaKey] + i0));
    for (UintArray a : kMovedUints) pack.store(w.u[a] + m, hn::LoadU(DU(), w.u[a] + i0));
    for (ByteArray a : kMovedBytes)
      store_bytes(w.b[a] + m, pack.first, pack.packed(hn::PromoteTo(DI(), hn::LoadU(D8(), w.b[a] + i0))));
    // The keys: each half of the block's lanes as 64-bit lanes.
    const VU alive_bits = hn::VecFromMask(DU(), hn::RebindMask(DU(), alive));
    const auto alive_lo = hn::PromoteTo(d64, hn::LowerHalf(dh, alive_bits)) != hn::Zero(d64);
    const auto alive_hi = hn::PromoteTo(d64, hn::UpperHalf(dh, alive_bits)) != hn::Zero(d64);
    const std::size_t half = hn::Lanes(d64);
    auto move64 = [&](std::uint64_t* a) {
      const std::size_t lo = hn::CompressBlendedStore(hn::LoadU(d64, a + i0), alive_lo, d64, a + m);
      hn::CompressBlendedStore(hn::LoadU(d64, a + i0 + half), alive_hi, d64, a + m + lo);
    };
    move64(w.rng);
    if (sc.zsobol) {
      move64(w.zindex);
      move64(w.zkey);
    }
    store_bytes(w.b[kAlive] + m, pack.first, hn::Set(DI(), 1));
    m += count;
  }
  return m;
}

#endif  // HWY_TARGET
}  // namespace pathlab::vector_stages::HWY_NAMESPACE
HWY_AFTER_NAMESPACE();

#if HWY_ONCE

#include "core/compiled_scene.h"
#include "core/simd/simd.h"
#include "core/strategy_weights.h"
#include "core/surfel.h"

namespace pathlab::vector_stages {

HWY_EXPORT(generate_camera_rays);
HWY_EXPORT(prefetch_hits);
HWY_EXPORT(resolve);
HWY_EXPORT(add_emission);
HWY_EXPORT(sample_lights);
HWY_EXPORT(scatter);
HWY_EXPORT(hash_keys);
HWY_EXPORT(compact);
HWY_EXPORT(lanes);

bool cpu_supported() { return active_simd_target() != SimdTarget::Scalar; }
std::size_t lanes() { return HWY_DYNAMIC_DISPATCH(lanes)(); }

void generate_camera_rays(const Scene& scene, const Camera& camera, const Wave& wave) {
  HWY_DYNAMIC_DISPATCH(generate_camera_rays)(scene, camera, wave);
}
void prefetch_hits(const Scene& scene, const Wave& wave) { HWY_DYNAMIC_DISPATCH(prefetch_hits)(scene, wave); }
void resolve(const Scene& scene, const Wave& wave) { HWY_DYNAMIC_DISPATCH(resolve)(scene, wave); }
void add_emission(const Scene& scene, const Wave& wave) { HWY_DYNAMIC_DISPATCH(add_emission)(scene, wave); }
std::size_t sample_lights(const Scene& scene, const Wave& wave) {
  return HWY_DYNAMIC_DISPATCH(sample_lights)(scene, wave);
}
void scatter(const Scene& scene, const Wave& wave) { HWY_DYNAMIC_DISPATCH(scatter)(scene, wave); }
void hash_keys(std::uint64_t* keys, std::size_t n, std::uint64_t seed_key) {
  HWY_DYNAMIC_DISPATCH(hash_keys)(keys, n, seed_key);
}
std::size_t compact(const Scene& scene, const Wave& wave, void* samples, std::uint32_t first_slot) {
  return HWY_DYNAMIC_DISPATCH(compact)(scene, wave, samples, first_slot);
}

// Three consecutive arrays (x, y, z) at slot i.
static vec3 at(const Wave& w, FloatArray x, std::size_t i) { return vec3(w.f[x][i], w.f[x + 1][i], w.f[x + 2][i]); }

// The Surfel in slot i as far as the lanes made it: its point, error bound
// and geometric normal (what light_query, shadow_ray and LightSampler::pdf
// read).
static Surfel shading_point(const Wave& w, std::size_t i) {
  Surfel s;
  s.p = at(w, kPx, i);
  s.p_error = at(w, kErrX, i);
  s.n = at(w, kNx, i);
  return s;
}

// The slot's SurfaceParams into the arrays the lanes read (kPrmAlbedo...).
static void store_params(const Wave& w, std::size_t i) {
  const SurfaceParams& p = w.params[i];
  const disney::Closure& c = p.closure;
  const auto three = [&](FloatArray a, const Spectrum& v) {
    for (int k = 0; k < 3; ++k) w.f[a + k][i] = v[k];
  };
  three(kPrmAlbedo, p.albedo);
  three(kPrmReflectance, p.glass.reflectance);
  three(kPrmTransmittance, p.glass.transmittance);
  for_each_closure_field(c, [&](const auto& v, ShapeField, FloatArray a) {
    if constexpr (std::is_same_v<std::decay_t<decltype(v)>, float>)
      w.f[a][i] = v;
    else
      three(a, v);
  });
}

void general_resolve(const Scene& sc, const Wave& w, std::size_t i) {
  RayHit hit;
  hit.t = w.f[kHitT][i];
  hit.shape = w.u[kShape][i];
  hit.prim = w.u[kPrim][i];
  hit.uv = vec2(w.f[kHitU][i], w.f[kHitV][i]);
  if (sc.instanced) hit.instance = w.u[kInstance][i];
  const pathlab::Scene& scene = sc.compiled->scene();
  const Material& m = scene.materials[scene.shapes[hit.shape].material];
  const bool reads_textures = sc.textured && m.reads_textures_at_hits();
  Surfel s;
  if (hit.instance == kNoInstance && !reads_textures) {
    // The lanes placed the point, bit for bit as resolve() does: core adds
    // the rest (resolve_shading).
    s = shading_point(w, i);
    sc.compiled->resolve_shading(hit, &s);
  } else {
    // resolve() of the path's ray (still in kOx... until scatter() spawns
    // the next one), with its cone and its slot's parameters under textures.
    const Ray ray{at(w, kOx, i), at(w, kDx, i), w.f[kTmax][i]};
    if (sc.textured)
      sc.compiled->resolve(ray, hit, &s, RayCone{w.f[kConeWidth][i], w.f[kConeSpread][i]}, &w.params[i]);
    else
      sc.compiled->resolve(ray, hit, &s);
  }
  const vec3* fields[] = {&s.p, &s.p_error, &s.n, &s.frame.s, &s.frame.t, &s.frame.n};
  const FloatArray arrays[] = {kPx, kErrX, kNx, kFsX, kFtX, kFnX};
  for (int a = 0; a < 6; ++a)
    for (int c = 0; c < 3; ++c) w.f[arrays[a] + c][i] = (*fields[a])[c];
  w.b[kShadingNormal][i] = s.shading_normal ? 1 : 0;
  w.b[kHasParams][i] = s.params != nullptr ? 1 : 0;
  if (s.params != nullptr) store_params(w, i);
}

void general_texels(const Scene& sc, const Wave& w, std::size_t i) {
  const pathlab::Scene& scene = sc.compiled->scene();
  const Material& m = scene.materials[scene.shapes[w.u[kShape][i]].material];
  const TextureFootprint at{vec2(w.f[kTexU][i], w.f[kTexV][i]), w.f[kTexWidth][i]};
  if (m.normal_map) {
    const Spectrum c = sc.compiled->textures()->color(m.normal_map->texture, at);
    for (int k = 0; k < 3; ++k) w.f[kMapR + k][i] = c[k];
  }
  if (m.is_textured()) {
    evaluate_textured(m, *sc.compiled->textures(), at, &w.params[i]);
    store_params(w, i);
  }
}

// The Surfel of a hit on a kGeneral shape, from what general_resolve (or,
// for a flat shape, resolve() in the lanes) kept, field for field (uv is
// read only by textures, which resolve() has read into params already).
static Surfel general_surfel(const Scene& sc, const Wave& w, std::size_t i) {
  Surfel s = shading_point(w, i);
  s.frame.s = at(w, kFsX, i);
  s.frame.t = at(w, kFtX, i);
  s.frame.n = at(w, kFnX, i);
  s.uv = vec2(w.f[kHitU][i], w.f[kHitV][i]);
  s.shading_normal = w.b[kShadingNormal][i] != 0;
  s.shape = w.u[kShape][i];
  s.prim = w.u[kPrim][i];
  if (sc.instanced) s.instance = w.u[kInstance][i];
  if (w.b[kHasParams][i] != 0) s.params = &w.params[i];
  const pathlab::Scene& scene = sc.compiled->scene();
  s.material = &scene.materials[scene.shapes[s.shape].material];
  return s;
}

void general_eval(const Scene& sc, const Wave& w, std::size_t i, const float wi[3], float f[3], float* pdf) {
  const Surfel s = general_surfel(sc, w, i);
  const vec3 to(wi[0], wi[1], wi[2]), wo = -at(w, kDx, i);
  const Spectrum value = s.eval(to, wo);
  for (int c = 0; c < 3; ++c) f[c] = value[c];
  *pdf = is_black(value) ? 0.0f : s.pdf(to, wo);  // read only where f is not black
}

bool general_scatter(const Scene& sc, const Wave& w, std::size_t i, float u_lobe, float u0, float u1,
                     GeneralSample* out) {
  const std::optional<BsdfSample> bs = scatter_for(sc.strategy, general_surfel(sc, w, i), -at(w, kDx, i), u_lobe, vec2(u0, u1));
  if (!bs) return false;
  for (int c = 0; c < 3; ++c) {
    out->wi[c] = bs->wi[c];
    out->weight[c] = bs->weight[c];
  }
  out->pdf = bs->pdf;
  out->impulse = bs->impulse;
  return true;
}

bool general_light(const Scene& sc, const Wave& w, std::size_t i, float u_choice, float u0, float u1,
                   GeneralLight* out) {
  const Surfel s = shading_point(w, i);
  const vec3 wo = -at(w, kDx, i);
  const LightSampler& lights = sc.compiled->lights();
  const std::optional<LightSample> ls = lights.sample(light_query(s, wo), u_choice, vec2(u0, u1));
  if (!ls) return false;
  const Ray r = shadow_ray(s, *ls);
  for (int c = 0; c < 3; ++c) {
    out->wi[c] = ls->wi[c];
    out->Le[c] = ls->Le[c];
    out->ray[c] = r.origin[c];
    out->ray[3 + c] = r.dir[c];
  }
  out->pdf = ls->pdf;
  out->ray[6] = r.tmax;
  return true;
}

void general_light_emission(const Scene& sc, std::int32_t light, float b1, float b2, const float p[3], float Le[3]) {
  const Spectrum e =
      sc.compiled->lights().emission_at_point(static_cast<std::size_t>(light), vec2(b1, b2), vec3(p[0], p[1], p[2]));
  for (int c = 0; c < 3; ++c) Le[c] = e[c];
}

void general_sky(const Scene& sc, const Wave& w, std::size_t i, float Le[3], float* pdf) {
  const LightSampler::Sky sky = sc.compiled->lights().sky(at(w, kDx, i));
  for (int c = 0; c < 3; ++c) Le[c] = sky.Le[c];
  *pdf = sky.pdf;
}

float general_light_pdf(const Scene& sc, const Wave& w, std::size_t i) {
  const LightQuery ref{at(w, kPrevX, i), at(w, kPrevNx, i)};
  Surfel hit = shading_point(w, i);  // what LightSampler::pdf reads: the emitter, its point and normal
  hit.shape = w.u[kShape][i];
  hit.prim = w.u[kPrim][i];
  if (sc.instanced) hit.instance = w.u[kInstance][i];
  return sc.compiled->lights().pdf(ref, hit);
}

// The light of every visible sample, once Embree has filled kQOccluded: L
// += beta * unoccluded, and + 0 behind an occluder, as the scalar add_light
// adds. One path per shadow ray: a plain loop over the packed rays.
void add_light(const Wave& w, std::size_t queries) {
  for (std::size_t r = 0; r < queries; ++r) {
    const std::size_t i = w.u[kQPath][r];
    const bool visible = w.b[kQOccluded][r] == 0;
    for (int c = 0; c < 3; ++c)
      w.f[kLR + c][i] += visible ? w.f[kBetaR + c][i] * w.f[kQUnR + c][r] : 0.0f;
  }
}

}  // namespace pathlab::vector_stages

#endif  // HWY_ONCE
