// The vectorised stages of vector_stages.h, 16 paths per AVX-512 register.
//
// Compiled with -mavx512f/dq/bw/vl (wavefront/CMakeLists.txt; -ffp-contract=off
// project-wide) and called only when vector_stages::cpu_supported(). Every
// function here has internal linkage except the stages vector_stages.h
// declares, and nothing is included but that plain-data header and
// <immintrin.h>: see vector_stages.h for why.
//
// Each step names the scalar code it mirrors. The order of every sum and
// product follows that code (GLM's dot is (x + y) + z; a vec3 divided by a
// float divides each component; std::max(a, b) is _mm512_max_ps(b, a)), so
// that a lane's result has the same bits as the scalar one.
#include "wavefront/vector_stages.h"

#include <immintrin.h>

#include <limits>

namespace pathlab::vector_stages {
namespace {

using F = __m512;
using I = __m512i;
using M = __mmask16;

constexpr float kInvPi = 1.0f / 3.14159265358979323846f;  // core/math.h
constexpr float kGamma3 = (3.0f * 0x1p-24f) / (1.0f - 3.0f * 0x1p-24f);  // gamma_bound(3), core/geometry.h
constexpr float kGamma7 = (7.0f * 0x1p-24f) / (1.0f - 7.0f * 0x1p-24f);  // gamma_bound(7), core/geometry.h

F k(float v) { return _mm512_set1_ps(v); }
F add(F a, F b) { return _mm512_add_ps(a, b); }
F sub(F a, F b) { return _mm512_sub_ps(a, b); }
F mul(F a, F b) { return _mm512_mul_ps(a, b); }
F div(F a, F b) { return _mm512_div_ps(a, b); }
F neg(F a) { return _mm512_castsi512_ps(_mm512_xor_si512(_mm512_castps_si512(a), _mm512_set1_epi32(INT32_MIN))); }
F select(M m, F if_true, F if_false) { return _mm512_mask_blend_ps(m, if_false, if_true); }
M lt(F a, F b) { return _mm512_cmp_ps_mask(a, b, _CMP_LT_OQ); }
M le(F a, F b) { return _mm512_cmp_ps_mask(a, b, _CMP_LE_OQ); }
M gt(F a, F b) { return _mm512_cmp_ps_mask(a, b, _CMP_GT_OQ); }
M ge(F a, F b) { return _mm512_cmp_ps_mask(a, b, _CMP_GE_OQ); }
M eq(F a, F b) { return _mm512_cmp_ps_mask(a, b, _CMP_EQ_OQ); }

struct V3 {
  F x, y, z;
};
V3 add(const V3& a, const V3& b) { return {add(a.x, b.x), add(a.y, b.y), add(a.z, b.z)}; }
V3 sub(const V3& a, const V3& b) { return {sub(a.x, b.x), sub(a.y, b.y), sub(a.z, b.z)}; }
V3 mul(const V3& a, const V3& b) { return {mul(a.x, b.x), mul(a.y, b.y), mul(a.z, b.z)}; }
V3 mul(F s, const V3& a) { return {mul(s, a.x), mul(s, a.y), mul(s, a.z)}; }
V3 div(const V3& a, F s) { return {div(a.x, s), div(a.y, s), div(a.z, s)}; }
V3 neg(const V3& a) { return {neg(a.x), neg(a.y), neg(a.z)}; }
V3 abs(const V3& a) { return {_mm512_abs_ps(a.x), _mm512_abs_ps(a.y), _mm512_abs_ps(a.z)}; }
V3 select(M m, const V3& a, const V3& b) { return {select(m, a.x, b.x), select(m, a.y, b.y), select(m, a.z, b.z)}; }
F dot(const V3& a, const V3& b) { return add(add(mul(a.x, b.x), mul(a.y, b.y)), mul(a.z, b.z)); }
M is_black(const V3& a) { return eq(a.x, k(0.0f)) & eq(a.y, k(0.0f)) & eq(a.z, k(0.0f)); }

// next_float_up / next_float_down (core/ray.h), lane by lane.
F next_float(F v, bool up) {
  const I bits = _mm512_castps_si512(v);
  const M positive = gt(v, k(0.0f));
  const I away = _mm512_add_epi32(bits, _mm512_set1_epi32(1)), toward = _mm512_sub_epi32(bits, _mm512_set1_epi32(1));
  I r = up ? _mm512_mask_blend_epi32(positive, toward, away) : _mm512_mask_blend_epi32(positive, away, toward);
  r = _mm512_mask_mov_epi32(r, eq(v, k(0.0f)), _mm512_set1_epi32(up ? 1 : INT32_MIN + 1));  // +-denorm_min
  const M keep = _mm512_cmp_ps_mask(v, v, _CMP_UNORD_Q) | eq(v, k(up ? __builtin_inff() : -__builtin_inff()));
  return _mm512_castsi512_ps(_mm512_mask_mov_epi32(r, keep, bits));
}

// offset_ray_origin (core/ray.cpp).
V3 offset_ray_origin(const V3& p, const V3& error, const V3& n) {
  F d = dot(abs(n), error);
  // No error across the surface: one float of the largest coordinate.
  const V3 a = abs(p);
  const F largest = _mm512_max_ps(a.x, _mm512_max_ps(a.y, a.z));
  d = _mm512_mask_mov_ps(d, eq(d, k(0.0f)), _mm512_max_ps(mul(largest, k(0x1p-23f)), k(0x1p-100f)));
  const V3 offset = mul(d, n);
  const V3 po = add(p, offset);
  auto step = [](F c, F o) {
    c = _mm512_mask_mov_ps(c, gt(o, k(0.0f)), next_float(c, true));
    return _mm512_mask_mov_ps(c, lt(o, k(0.0f)), next_float(c, false));
  };
  return {step(po.x, offset.x), step(po.y, offset.y), step(po.z, offset.z)};
}

// sin_cos_quarter (core/sampling.cpp), term by term.
void sin_cos_quarter(F x, F* sin, F* cos) {
  const F z = mul(x, x);
  *sin = add(mul(mul(sub(mul(add(mul(k(-1.9515295891e-4f), z), k(8.3321608736e-3f)), z), k(1.6666654611e-1f)), z), x), x);
  *cos = add(sub(mul(mul(add(mul(sub(mul(k(2.443315711809948e-5f), z), k(1.388731625493765e-3f)), z),
                             k(4.166664568298827e-2f)),
                         z),
                     z),
                 mul(k(0.5f), z)),
             k(1.0f));
}

// square_to_concentric_disk (core/sampling.cpp).
void concentric_disk(F ux, F uy, F* dx, F* dy) {
  const F ox = sub(mul(k(2.0f), ux), k(1.0f)), oy = sub(mul(k(2.0f), uy), k(1.0f));
  const M wide = gt(_mm512_abs_ps(ox), _mm512_abs_ps(oy));  // the left and right wedges
  const F r = select(wide, ox, oy);
  F s, c;
  // One division per lane, of whichever ratio the lane's wedge takes.
  sin_cos_quarter(mul(k(3.14159265358979323846f / 4.0f), div(select(wide, oy, ox), select(wide, ox, oy))), &s, &c);
  const M centre = eq(ox, k(0.0f)) & eq(oy, k(0.0f));
  *dx = _mm512_maskz_mov_ps(~centre, mul(r, select(wide, c, s)));
  *dy = _mm512_maskz_mov_ps(~centre, mul(r, select(wide, s, c)));
}

// mix64 (core/rng.h) on 8 64-bit lanes.
I mix64(I z) {
  z = _mm512_mullo_epi64(_mm512_xor_si512(z, _mm512_srli_epi64(z, 30)),
                         _mm512_set1_epi64(static_cast<long long>(0xbf58476d1ce4e5b9ull)));
  z = _mm512_mullo_epi64(_mm512_xor_si512(z, _mm512_srli_epi64(z, 27)),
                         _mm512_set1_epi64(static_cast<long long>(0x94d049bb133111ebull)));
  return _mm512_xor_si512(z, _mm512_srli_epi64(z, 31));
}

// SampleStream::get for 16 paths at their current vertex: the key with the
// vertex already xored into its high half (lanes 0-7 and 8-15).
struct Streams {
  I lo, hi;
  F u(Dim dim) const {
    const I d = _mm512_set1_epi64(static_cast<long long>(dim));
    const __m256 a = _mm512_cvtepi64_ps(_mm512_srli_epi64(mix64(_mm512_xor_si512(lo, d)), 40));
    const __m256 b = _mm512_cvtepi64_ps(_mm512_srli_epi64(mix64(_mm512_xor_si512(hi, d)), 40));
    return mul(_mm512_insertf32x8(_mm512_castps256_ps512(a), b, 1), k(0x1p-24f));
  }
};
Streams streams(const Wave& w, std::size_t i0, M m, I vertex) {
  const auto m_lo = static_cast<__mmask8>(m & 0xff), m_hi = static_cast<__mmask8>(m >> 8);
  const I key_lo = _mm512_maskz_loadu_epi64(m_lo, w.rng + i0), key_hi = _mm512_maskz_loadu_epi64(m_hi, w.rng + i0 + 8);
  const I v_lo = _mm512_slli_epi64(_mm512_cvtepu32_epi64(_mm512_castsi512_si256(vertex)), 32);
  const I v_hi = _mm512_slli_epi64(_mm512_cvtepu32_epi64(_mm512_extracti64x4_epi64(vertex, 1)), 32);
  return {_mm512_xor_si512(key_lo, v_lo), _mm512_xor_si512(key_hi, v_hi)};
}

// The lanes of slots [i0, i0 + 16) that exist.
M lanes(std::size_t n, std::size_t i0) {
  return n - i0 >= 16 ? M(0xffff) : static_cast<M>((1u << (n - i0)) - 1u);
}

// Slots [i0, i0 + 16) of the wave's arrays (0 outside m; nothing stored outside m).
F load(const Wave& w, FloatArray a, std::size_t i0, M m) { return _mm512_maskz_loadu_ps(m, w.f[a] + i0); }
V3 load3(const Wave& w, FloatArray x, std::size_t i0, M m) {
  return {load(w, x, i0, m), load(w, static_cast<FloatArray>(x + 1), i0, m), load(w, static_cast<FloatArray>(x + 2), i0, m)};
}
void store(const Wave& w, FloatArray a, std::size_t i0, M m, F v) { _mm512_mask_storeu_ps(w.f[a] + i0, m, v); }
void store3(const Wave& w, FloatArray x, std::size_t i0, M m, const V3& v) {
  store(w, x, i0, m, v.x);
  store(w, static_cast<FloatArray>(x + 1), i0, m, v.y);
  store(w, static_cast<FloatArray>(x + 2), i0, m, v.z);
}
I load(const Wave& w, UintArray a, std::size_t i0, M m) { return _mm512_maskz_loadu_epi32(m, w.u[a] + i0); }
void store(const Wave& w, UintArray a, std::size_t i0, M m, I v) { _mm512_mask_storeu_epi32(w.u[a] + i0, m, v); }
// A byte array as a mask of the lanes whose byte is not 0, and back.
M load_mask(const Wave& w, ByteArray a, std::size_t i0, M m) {
  const I v = _mm512_cvtepu8_epi32(_mm_maskz_loadu_epi8(m, w.b[a] + i0));
  return _mm512_test_epi32_mask(v, v);
}
void store_mask(const Wave& w, ByteArray a, std::size_t i0, M m, M value) {
  _mm512_mask_cvtepi32_storeu_epi8(w.b[a] + i0, m, _mm512_maskz_mov_epi32(value, _mm512_set1_epi32(1)));
}

// Float `index` of entry `entry` of a table with `stride` floats per entry
// (0 outside m).
F gather(M m, const float* base, I entry, int stride, int index) {
  const I at = _mm512_add_epi32(_mm512_mullo_epi32(entry, _mm512_set1_epi32(stride)), _mm512_set1_epi32(index));
  return _mm512_mask_i32gather_ps(_mm512_setzero_ps(), m, at, base, 4);
}
V3 gather3(M m, const float* base, I entry, int stride, int index) {
  return {gather(m, base, entry, stride, index), gather(m, base, entry, stride, index + 1),
          gather(m, base, entry, stride, index + 2)};
}
// Entry `entry` of a table of at most 16 entries kept by column (`row`
// holds one field of every entry): a permute, not a gather (0 outside m).
F permute(M m, const float* row, I entry) { return _mm512_maskz_permutexvar_ps(m, entry, _mm512_loadu_ps(row)); }

// Field `field` of each lane's shape (Scene::shape); `shape` is the shape
// index. 0 outside m.
F shape_value(M m, const Scene& sc, I shape, ShapeField field) {
  if (sc.shape_columns) return permute(m, sc.shape_columns + 16 * field, shape);
  return gather(m, sc.shape, shape, kShapeFields, field);
}
V3 shape_value3(M m, const Scene& sc, I shape, ShapeField field) {
  return {shape_value(m, sc, shape, field), shape_value(m, sc, shape, static_cast<ShapeField>(field + 1)),
          shape_value(m, sc, shape, static_cast<ShapeField>(field + 2))};
}
I shape_int(M m, const Scene& sc, I shape, ShapeField field) {
  return _mm512_castps_si512(shape_value(m, sc, shape, field));
}
M shape_flag(M m, const Scene& sc, I shape, ShapeField field) {
  return m & ~eq(shape_value(m, sc, shape, field), k(0.0f));
}
// Field `field` of each lane's light entry (Lights). 0 outside m.
F light_value(M m, const Lights& lights, I entry, LightField field) {
  if (lights.columns) return permute(m, lights.columns + 16 * field, entry);
  switch (field) {
    case kLightCdf: return gather(m, lights.cdf, entry, 1, 0);
    case kLightPmf: return gather(m, lights.pmf, entry, 1, 0);
    case kLightInvArea: return gather(m, lights.inv_area, entry, 1, 0);
    default: return gather(m, lights.triangle, entry, 16, field);
  }
}
V3 light_value3(M m, const Lights& lights, I entry, LightField field) {
  return {light_value(m, lights, entry, field), light_value(m, lights, entry, static_cast<LightField>(field + 1)),
          light_value(m, lights, entry, static_cast<LightField>(field + 2))};
}

// The lanes of m packed to the front of `to` (to[0, popcount(m))). A
// compress into a register and a masked store: on Intel cores a compress
// straight to memory is several times slower.
M packed_lanes(M m) { return static_cast<M>((1u << __builtin_popcount(m)) - 1u); }
void compress_store(float* to, M m, F v) { _mm512_mask_storeu_ps(to, packed_lanes(m), _mm512_maskz_compress_ps(m, v)); }
void compress_store(std::uint32_t* to, M m, I v) {
  _mm512_mask_storeu_epi32(to, packed_lanes(m), _mm512_maskz_compress_epi32(m, v));
}
void compress_store(std::uint64_t* to, __mmask8 m, I v) {
  const auto packed = static_cast<__mmask8>((1u << __builtin_popcount(m)) - 1u);
  _mm512_mask_storeu_epi64(to, packed, _mm512_maskz_compress_epi64(m, v));
}

// power_heuristic (core/sampling.h).
F power_heuristic(F a, F b) {
  const F r = div(b, a);
  F w = div(k(1.0f), add(k(1.0f), mul(r, r)));
  w = _mm512_mask_mov_ps(w, _mm512_cmp_ps_mask(a, k(0.0f), _CMP_NGT_UQ), k(0.0f));
  return _mm512_mask_mov_ps(w, _mm512_fpclass_ps_mask(a, 0x18), k(1.0f));
}

// Frame(n) (core/math.h): the shading frame's s and t. Only scatter needs
// them, so it makes them from n rather than resolve() storing six more
// arrays per path.
void frame(const V3& n, V3* s, V3* t) {
  const F sign = _mm512_castsi512_ps(_mm512_or_si512(
      _mm512_and_si512(_mm512_castps_si512(n.z), _mm512_set1_epi32(INT32_MIN)), _mm512_castps_si512(k(1.0f))));
  const F a = div(k(-1.0f), add(sign, n.z));
  const F b = mul(mul(n.x, n.y), a);
  *s = V3{add(k(1.0f), mul(mul(mul(sign, n.x), n.x), a)), mul(sign, b), mul(neg(sign), n.x)};
  *t = V3{b, add(sign, mul(mul(n.y, n.y), a)), neg(n.y)};
}

// glm::normalize: v * (1 / sqrt(v.v)).
V3 normalize(const V3& v) { return mul(div(k(1.0f), _mm512_sqrt_ps(dot(v, v))), v); }

// LightSampler::pick: the first entry whose cdf exceeds u (the last entry if
// none does), as a branch-free binary search.
I pick(M m, const Lights& lights, F u) {
  const auto count = static_cast<std::uint32_t>(lights.count);
  std::uint32_t step = 1;
  while (step * 2 <= count) step *= 2;
  I idx = _mm512_setzero_si512();
  for (; step > 0; step /= 2) {
    const I cand = _mm512_add_epi32(idx, _mm512_set1_epi32(static_cast<int>(step)));
    const M valid = m & _mm512_cmple_epu32_mask(cand, _mm512_set1_epi32(static_cast<int>(count)));
    const F c = light_value(valid, lights, _mm512_sub_epi32(cand, _mm512_set1_epi32(1)), kLightCdf);
    idx = _mm512_mask_mov_epi32(idx, valid & le(c, u), cand);
  }
  return _mm512_min_epu32(idx, _mm512_set1_epi32(static_cast<int>(count - 1)));
}

}  // namespace

void generate_camera_rays(const Camera& c, const Wave& w) {
  const V3 position{k(c.position[0]), k(c.position[1]), k(c.position[2])};
  const V3 forward{k(c.forward[0]), k(c.forward[1]), k(c.forward[2])};
  const V3 right{k(c.right[0]), k(c.right[1]), k(c.right[2])};
  const V3 up{k(c.up[0]), k(c.up[1]), k(c.up[2])};
  const V3 zero{k(0.0f), k(0.0f), k(0.0f)}, one{k(1.0f), k(1.0f), k(1.0f)};
  for (std::size_t i0 = 0; i0 < w.n; i0 += 16) {
    const M in = lanes(w.n, i0);
    const Streams rng = streams(w, i0, in, _mm512_setzero_si512());  // the camera's numbers are vertex 0's
    // The film position: pixel + FilmX/Y (wavefront_tracer.cpp).
    const F fx = add(_mm512_cvtepu32_ps(load(w, kPixelX, i0, in)), rng.u(Dim::FilmX));
    const F fy = add(_mm512_cvtepu32_ps(load(w, kPixelY, i0, in)), rng.u(Dim::FilmY));
    store(w, kFilmX, i0, in, fx);
    store(w, kFilmY, i0, in, fy);
    // Camera::generate_ray.
    const F sx = mul(mul(sub(mul(mul(k(2.0f), fx), k(c.inv_width)), k(1.0f)), k(c.tan_half_fov)), k(c.aspect));
    const F sy = mul(sub(k(1.0f), mul(mul(k(2.0f), fy), k(c.inv_height))), k(c.tan_half_fov));
    const V3 d = normalize(add(add(forward, mul(sx, right)), mul(sy, up)));
    if (c.aperture_radius <= 0.0f) {
      store3(w, kOx, i0, in, position);
      store3(w, kDx, i0, in, d);
    } else {
      // Thin lens: through the point of the plane in focus.
      const V3 focus = add(position, mul(div(k(c.focus_distance), dot(d, forward)), d));
      F lx, ly;
      concentric_disk(rng.u(Dim::LensX), rng.u(Dim::LensY), &lx, &ly);
      lx = mul(k(c.aperture_radius), lx);
      ly = mul(k(c.aperture_radius), ly);
      const V3 origin = add(add(position, mul(lx, right)), mul(ly, up));
      store3(w, kOx, i0, in, origin);
      store3(w, kDx, i0, in, normalize(sub(focus, origin)));
    }
    store(w, kTmax, i0, in, k(__builtin_inff()));
    // A fresh path: beta 1, L 0, PreviousVertex{} (at 0, pdf 0, an impulse,
    // the BSDF technique), no rays yet, alive, about to reach vertex 1.
    store3(w, kBetaR, i0, in, one);
    store3(w, kLR, i0, in, zero);
    store3(w, kPrevX, i0, in, zero);
    store(w, kPrevPdf, i0, in, k(0.0f));
    store_mask(w, kPrevImpulse, i0, in, in);
    store_mask(w, kPrevBsdfTechnique, i0, in, in);
    store(w, kRays, i0, in, _mm512_setzero_si512());
    store(w, kVertex, i0, in, _mm512_set1_epi32(1));
    store_mask(w, kAlive, i0, in, in);
  }
}

void prefetch_hits(const Scene& sc, const Wave& w) {
  for (std::size_t i0 = 0; i0 < w.n; i0 += 16) {
    const M found = load_mask(w, kFound, i0, lanes(w.n, i0));
    if (found == 0) continue;
    const I shape = load(w, kShape, i0, found);
    const M mesh = found & ~shape_flag(found, sc, shape, kIsSphere);
    if (mesh == 0) continue;
    alignas(64) std::uint32_t tri[16];
    _mm512_store_si512(tri, _mm512_add_epi32(shape_int(mesh, sc, shape, kFirstTriangle), load(w, kPrim, i0, mesh)));
    for (M m = mesh; m != 0; m &= static_cast<M>(m - 1)) {
      const float* t = sc.triangles + 12 * static_cast<std::size_t>(tri[__builtin_ctz(m)]);
      __builtin_prefetch(t);       // p0 ...
      __builtin_prefetch(t + 11);  // ... n: a triangle may straddle two lines
    }
  }
}

void resolve(const Scene& sc, const Wave& w) {
  constexpr float kGamma5 = (5.0f * 0x1p-24f) / (1.0f - 5.0f * 0x1p-24f);
  constexpr float kGamma2 = (2.0f * 0x1p-24f) / (1.0f - 2.0f * 0x1p-24f);
  for (std::size_t i0 = 0; i0 < w.n; i0 += 16) {
    const M in = lanes(w.n, i0);
    store(w, kRays, i0, in, _mm512_add_epi32(load(w, kRays, i0, in), _mm512_set1_epi32(1)));
    const M found = load_mask(w, kFound, i0, in);
    if (found == 0) continue;
    const I shape = load(w, kShape, i0, found);
    const M sphere = shape_flag(found, sc, shape, kIsSphere), mesh = found & ~sphere;
    const V3 zero{k(0.0f), k(0.0f), k(0.0f)};
    V3 p = zero, error = zero, n = zero;
    if (mesh != 0) {
      // triangle_point (core/geometry.cpp) of the shape's triangle prim.
      const I tri = _mm512_add_epi32(shape_int(mesh, sc, shape, kFirstTriangle), load(w, kPrim, i0, mesh));
      const V3 p0 = gather3(mesh, sc.triangles, tri, 12, 0), p1 = gather3(mesh, sc.triangles, tri, 12, 3),
               p2 = gather3(mesh, sc.triangles, tri, 12, 6);
      n = gather3(mesh, sc.triangles, tri, 12, 9);
      const F b1 = load(w, kHitU, i0, mesh), b2 = load(w, kHitV, i0, mesh);
      const F b0 = sub(sub(k(1.0f), b1), b2);
      p = add(add(mul(b0, p0), mul(b1, p1)), mul(b2, p2));
      error = mul(k(kGamma7), add(add(abs(mul(b0, p0)), abs(mul(b1, p1))), abs(mul(b2, p2))));
    }
    if (sphere != 0) {
      // sphere_point (core/geometry.cpp) of origin + t dir.
      const F t = load(w, kHitT, i0, sphere);
      const V3 o = load3(w, kOx, i0, sphere), d = load3(w, kDx, i0, sphere);
      const V3 center = shape_value3(sphere, sc, shape, kCenter);
      const F radius = shape_value(sphere, sc, shape, kRadius);
      const V3 dir = normalize(sub(add(o, mul(t, d)), center));
      const V3 rdir = mul(radius, dir);
      const V3 sp = add(center, rdir);
      const V3 serr = add(mul(k(kGamma5), abs(rdir)), mul(k(kGamma2), abs(sp)));
      const V3 sn = select(shape_flag(sphere, sc, shape, kFlipped), neg(dir), dir);
      p = select(sphere, sp, p);
      error = select(sphere, serr, error);
      n = select(sphere, sn, n);
    }
    store3(w, kPx, i0, found, p);
    store3(w, kErrX, i0, found, error);
    store3(w, kNx, i0, found, n);
  }
}

void add_emission(const Scene& sc, const Wave& w) {
  const V3 zero{k(0.0f), k(0.0f), k(0.0f)};
  for (std::size_t i0 = 0; i0 < w.n; i0 += 16) {
    const M in = lanes(w.n, i0);
    const M found = load_mask(w, kFound, i0, in);
    const V3 beta = load3(w, kBetaR, i0, in);
    const V3 L = load3(w, kLR, i0, in);
    // Escaped: no environment, so Le = 0 and its weight 0; L += beta * (0 * 0).
    // A ray the accel refused (t = NaN) makes the sample bad (NaN).
    V3 L_new = add(L, mul(beta, mul(k(0.0f), zero)));
    if (const M refused = in & ~found & _mm512_cmp_ps_mask(load(w, kHitT, i0, in & ~found), k(0.0f), _CMP_UNORD_Q);
        refused != 0) {
      const F nan = k(std::numeric_limits<float>::quiet_NaN());
      L_new = V3{_mm512_mask_mov_ps(L_new.x, refused, nan), _mm512_mask_mov_ps(L_new.y, refused, nan),
                 _mm512_mask_mov_ps(L_new.z, refused, nan)};
    }
    M alive = 0;
    if (found != 0) {
      // Surfel::emitted.
      const I shape = load(w, kShape, i0, found);
      const V3 wo = neg(load3(w, kDx, i0, found));
      const V3 n = load3(w, kNx, i0, found);
      const M facing = shape_flag(found, sc, shape, kTwoSided) | gt(dot(n, wo), k(0.0f));
      const V3 Le = select(shape_flag(found, sc, shape, kEmits) & facing, shape_value3(found, sc, shape, kEmission), zero);
      const M lit = found & ~is_black(Le);
      // LightSampler::pdf(prev.p, s).
      const M impulse = load_mask(w, kPrevImpulse, i0, lit);
      const M bsdf_technique = load_mask(w, kPrevBsdfTechnique, i0, lit);
      const F prev_pdf = load(w, kPrevPdf, i0, lit);
      const I first = shape_int(lit, sc, shape, kFirstLight);
      const M light = lit & _mm512_cmpge_epi32_mask(first, _mm512_setzero_si512());
      const I entry = _mm512_add_epi32(first, load(w, kPrim, i0, light));
      const V3 d = sub(load3(w, kPx, i0, light), load3(w, kPrevX, i0, light));
      const F dist = _mm512_sqrt_ps(dot(d, d));
      const F c = _mm512_abs_ps(div(dot(n, d), dist));
      const F inv_area = light_value(light, sc.lights, entry, kLightInvArea);
      const F pmf = light_value(light, sc.lights, entry, kLightPmf);
      const F to_solid_angle = select(gt(c, k(0.0f)), div(mul(mul(inv_area, dist), dist), c), k(0.0f));
      const F light_pdf = _mm512_maskz_mov_ps(light, mul(pmf, to_solid_angle));
      // emission_weight (core/strategy_weights.h).
      F weight = k(1.0f);
      if (sc.strategy == Strategy::Light) weight = select(gt(light_pdf, k(0.0f)), k(0.0f), k(1.0f));
      if (sc.strategy == Strategy::Mis) weight = power_heuristic(prev_pdf, light_pdf);
      if (sc.strategy == Strategy::LightBsdf)
        weight = _mm512_maskz_mov_ps(bsdf_technique, div(mul(k(2.0f), prev_pdf), add(prev_pdf, light_pdf)));
      weight = _mm512_maskz_mov_ps(lit, _mm512_mask_mov_ps(weight, impulse, k(1.0f)));
      L_new = select(found, add(L, mul(beta, mul(weight, Le))), L_new);
      // The path goes on if it may take another vertex and the surface scatters.
      alive = _mm512_cmple_epi32_mask(load(w, kVertex, i0, found), _mm512_set1_epi32(sc.max_vertex)) &
              shape_flag(found, sc, shape, kScatters);
    }
    store3(w, kLR, i0, in, L_new);
    store_mask(w, kAlive, i0, in, alive);
  }
}

std::size_t sample_lights(const Scene& sc, const Wave& w) {
  std::size_t queries = 0;
  for (std::size_t i0 = 0; i0 < w.n; i0 += 16) {
    const M in = lanes(w.n, i0);
    const I vertex = load(w, kVertex, i0, in);
    const Streams rng = streams(w, i0, in, vertex);
    // samples_area_lights (core/strategy_weights.h).
    M ok = load_mask(w, kAlive, i0, in);
    if (sc.strategy == Strategy::Bsdf || sc.lights.count == 0) ok = 0;
    if (sc.strategy == Strategy::LightBsdf) ok &= lt(rng.u(Dim::Technique), k(0.5f));
    if (ok == 0) {
      store_mask(w, kHasQuery, i0, in, 0);
      continue;
    }

    // LightSampler::sample: pick a triangle, then a point uniformly on it
    // (square_to_uniform_triangle, triangle_point).
    const I light = pick(ok, sc.lights, rng.u(Dim::LightChoice));
    const F ux = rng.u(Dim::LightX), uy = rng.u(Dim::LightY);
    const F s = _mm512_sqrt_ps(ux);
    const F b1 = mul(uy, s), b2 = sub(k(1.0f), s);
    const F b0 = sub(sub(k(1.0f), b1), b2);
    const V3 p0 = light_value3(ok, sc.lights, light, kLightP0), p1 = light_value3(ok, sc.lights, light, kLightP1),
             p2 = light_value3(ok, sc.lights, light, kLightP2), ln = light_value3(ok, sc.lights, light, kLightNormal),
             Le = light_value3(ok, sc.lights, light, kLightLe);
    const F two_sided = light_value(ok, sc.lights, light, kLightTwoSided);
    const V3 lp = add(add(mul(b0, p0), mul(b1, p1)), mul(b2, p2));
    const V3 lerr = mul(k(kGamma7), add(add(abs(mul(b0, p0)), abs(mul(b1, p1))), abs(mul(b2, p2))));

    const V3 sp = load3(w, kPx, i0, ok);
    const V3 d = sub(lp, sp);
    const F dist = _mm512_sqrt_ps(dot(d, d));
    ok &= gt(dist, k(0.0f));
    const V3 wi = div(d, dist);
    const F cos_light = dot(ln, neg(wi));
    ok &= ~eq(two_sided, k(0.0f)) | _mm512_cmp_ps_mask(cos_light, k(0.0f), _CMP_NLE_UQ);  // back of a one-sided emitter
    // pmf * area_to_solid_angle(1 / area, dist, cos_light) (core/sampling.h).
    const F c = _mm512_abs_ps(cos_light);
    const F inv_area = light_value(ok, sc.lights, light, kLightInvArea);
    const F pmf = light_value(ok, sc.lights, light, kLightPmf);
    const F to_solid_angle = select(gt(c, k(0.0f)), div(mul(mul(inv_area, dist), dist), c), k(0.0f));
    const F pdf_light = mul(pmf, to_solid_angle);
    ok &= gt(pdf_light, k(0.0f)) & ~_mm512_fpclass_ps_mask(pdf_light, 0x18);  // seen edge-on

    // Surfel::eval and Surfel::pdf of the Lambert lobe (core/surfel.cpp,
    // bsdf/lambert.h): only the local z of wo and wi matters.
    const V3 wo = neg(load3(w, kDx, i0, ok));
    const V3 n = load3(w, kNx, i0, ok);  // the frame's normal is the surface's
    const F wo_z = dot(wo, n);
    // A one-sided material is black unless wo and wi both leave its front
    // (Surfel::eval); with wo in front, upper below is wi in front.
    if (sc.one_sided) ok &= ~shape_flag(ok, sc, load(w, kShape, i0, ok), kOneSided) | gt(wo_z, k(0.0f));
    F wi_z = dot(wi, n);
    wi_z = select(lt(wo_z, k(0.0f)), neg(wi_z), wi_z);
    const M upper = gt(wi_z, k(0.0f));
    const F cos_pi = mul(wi_z, k(kInvPi));
    const V3 rho = shape_value3(ok, sc, load(w, kShape, i0, ok), kAlbedo);
    const V3 f = select(upper, mul(cos_pi, rho), V3{k(0.0f), k(0.0f), k(0.0f)});
    ok &= ~is_black(f);
    const F pdf_bsdf = select(upper, cos_pi, k(0.0f));

    // light_sample_weight (core/strategy_weights.h).
    F weight = k(1.0f);
    if (sc.strategy == Strategy::Mis) weight = power_heuristic(pdf_light, pdf_bsdf);
    if (sc.strategy == Strategy::LightBsdf) weight = div(mul(k(2.0f), pdf_light), add(pdf_light, pdf_bsdf));
    store3(w, kUnR, i0, ok, mul(div(weight, pdf_light), mul(f, Le)));

    // Surfel::spawn_to(lp, lerr, ln), packed behind the previous ones in
    // path order (add_light() finds them again by kHasQuery).
    const V3 err = load3(w, kErrX, i0, ok);
    const V3 origin = offset_ray_origin(sp, err, select(ge(dot(d, n), k(0.0f)), n, neg(n)));
    const V3 reach = mul(k(kGamma3), abs(sub(lp, origin)));  // the float ray's own reach error
    const V3 end = offset_ray_origin(lp, add(lerr, reach), select(ge(dot(sub(origin, lp), ln), k(0.0f)), ln, neg(ln)));
    const V3 dd = sub(end, origin);
    const F len = _mm512_sqrt_ps(dot(dd, dd));
    const V3 dir = div(dd, len);
    const F q[7] = {origin.x, origin.y, origin.z, dir.x, dir.y, dir.z, len};
    for (int a = 0; a < 7; ++a) compress_store(w.f[kQOx + a] + queries, ok, q[a]);
    store_mask(w, kHasQuery, i0, in, ok);
    // The shadow ray counts as one of the path's rays.
    store(w, kRays, i0, ok, _mm512_add_epi32(load(w, kRays, i0, ok), _mm512_set1_epi32(1)));
    queries += static_cast<std::size_t>(__builtin_popcount(ok));
  }
  return queries;
}

void add_light(const Wave& w, std::size_t queries) {
  // The packed shadow rays are in path order, at most one per path: block
  // i0's are the next popcount(has) of them.
  std::size_t r = 0;
  for (std::size_t i0 = 0; i0 < w.n && r < queries; i0 += 16) {
    const M in = lanes(w.n, i0);
    const M has = load_mask(w, kHasQuery, i0, in);
    if (has == 0) continue;
    const I packed = _mm512_cvtepu8_epi32(_mm_maskz_loadu_epi8(packed_lanes(has), w.b[kQOccluded] + r));
    const I blocked = _mm512_maskz_expand_epi32(has, packed);
    const M visible = has & ~_mm512_test_epi32_mask(blocked, blocked);
    for (int c = 0; c < 3; ++c) {
      const auto l = static_cast<FloatArray>(kLR + c);
      const F added = _mm512_maskz_mov_ps(visible, mul(load(w, static_cast<FloatArray>(kBetaR + c), i0, visible),
                                                      load(w, static_cast<FloatArray>(kUnR + c), i0, visible)));
      store(w, l, i0, has, add(load(w, l, i0, has), added));
    }
    r += static_cast<std::size_t>(__builtin_popcount(has));
  }
}

void scatter(const Scene& sc, const Wave& w) {
  for (std::size_t i0 = 0; i0 < w.n; i0 += 16) {
    const M in = lanes(w.n, i0);
    M ok = load_mask(w, kAlive, i0, in);
    if (ok == 0) continue;
    I vertex = load(w, kVertex, i0, in);
    const Streams rng = streams(w, i0, in, vertex);

    // square_to_cosine_hemisphere (core/sampling.cpp).
    F x, y;
    concentric_disk(rng.u(Dim::DirectionX), rng.u(Dim::DirectionY), &x, &y);
    const F z = _mm512_sqrt_ps(_mm512_max_ps(sub(sub(k(1.0f), mul(x, x)), mul(y, y)), k(0.0f)));

    // Surfel::scatter, Lambert: no sample on the disk's rim, or below min_pdf.
    const F pdf = select(gt(z, k(0.0f)), mul(z, k(kInvPi)), k(0.0f));
    ok &= _mm512_cmp_ps_mask(pdf, k(0.0f), _CMP_NLE_UQ) & _mm512_cmp_ps_mask(pdf, k(sc.min_pdf), _CMP_NLT_UQ);
    const V3 wo = neg(load3(w, kDx, i0, ok));
    const V3 n = load3(w, kNx, i0, ok);
    // Surfel::scatter: nothing from behind a one-sided material.
    if (sc.one_sided) ok &= ~shape_flag(ok, sc, load(w, kShape, i0, ok), kOneSided) | gt(dot(wo, n), k(0.0f));
    V3 fs, ft;
    frame(n, &fs, &ft);
    const F side = select(lt(dot(wo, n), k(0.0f)), k(-1.0f), k(1.0f));
    const V3 wi = add(add(mul(x, fs), mul(y, ft)), mul(mul(z, side), n));  // Frame::to_world
    V3 weight = shape_value3(ok, sc, load(w, kShape, i0, ok), kAlbedo);
    ok &= ~is_black(weight);

    // Russian roulette (the scatter stage).
    V3 beta = load3(w, kBetaR, i0, ok);
    const M rr = ok & _mm512_cmpgt_epi32_mask(vertex, _mm512_set1_epi32(sc.rr_depth));
    if (rr != 0) {
      const V3 bw = mul(beta, weight);
      const F survival = _mm512_min_ps(_mm512_max_ps(_mm512_max_ps(bw.z, bw.y), bw.x), k(1.0f));
      ok &= ~(rr & ~lt(rng.u(Dim::Roulette), survival));
      weight = select(rr, div(weight, survival), weight);
    }
    store3(w, kBetaR, i0, ok, mul(beta, weight));

    // PreviousVertex{s.p, pdf, impulse = false, bsdf_technique}.
    const V3 sp = load3(w, kPx, i0, ok);
    store3(w, kPrevX, i0, ok, sp);
    store(w, kPrevPdf, i0, ok, pdf);
    store_mask(w, kPrevImpulse, i0, ok, 0);
    M bsdf_technique = 0xffff;
    if (sc.strategy == Strategy::LightBsdf) bsdf_technique = ~lt(rng.u(Dim::Technique), k(0.5f));
    store_mask(w, kPrevBsdfTechnique, i0, ok, bsdf_technique);

    // Surfel::spawn(wi).
    const V3 err = load3(w, kErrX, i0, ok);
    store3(w, kOx, i0, ok, offset_ray_origin(sp, err, select(ge(dot(wi, n), k(0.0f)), n, neg(n))));
    store3(w, kDx, i0, ok, wi);
    store(w, kTmax, i0, ok, k(__builtin_inff()));
    vertex = _mm512_add_epi32(vertex, _mm512_set1_epi32(1));
    store(w, kVertex, i0, ok, vertex);
    store_mask(w, kAlive, i0, in, ok);
  }
}

void hash_keys(std::uint64_t* keys, std::size_t n, std::uint64_t seed_key) {
  const I seed = _mm512_set1_epi64(static_cast<long long>(seed_key));
  for (std::size_t i0 = 0; i0 < n; i0 += 8) {
    const auto m = static_cast<__mmask8>(n - i0 >= 8 ? 0xff : (1u << (n - i0)) - 1u);
    _mm512_mask_storeu_epi64(keys + i0, m, mix64(_mm512_xor_si512(seed, _mm512_maskz_loadu_epi64(m, keys + i0))));
  }
}

std::size_t compact(const Wave& w, void* samples, std::uint32_t first_slot) {
  static constexpr FloatArray kMovedFloats[] = {kOx,   kOy,   kOz,   kDx,   kDy,   kDz,      kTmax,  kBetaR, kBetaG,
                                                kBetaB, kLR,  kLG,   kLB,   kPrevX, kPrevY, kPrevZ, kPrevPdf, kFilmX,
                                                kFilmY};
  static constexpr UintArray kMovedUints[] = {kOutIndex, kRays, kVertex};
  static constexpr ByteArray kMovedBytes[] = {kPrevImpulse, kPrevBsdfTechnique};
  std::size_t m = 0;
  for (std::size_t i0 = 0; i0 < w.n; i0 += 16) {
    const M in = lanes(w.n, i0);
    const M alive = load_mask(w, kAlive, i0, in);
    // The paths that ended: FilmSample{film, L, rays, hits}.
    // Field by field: a Sample built on the stack and copied whole would be
    // read back before its parts' stores retire (a store-forwarding stall
    // per path).
    for (M dead = in & ~alive; dead != 0; dead &= static_cast<M>(dead - 1)) {
      const std::size_t i = i0 + static_cast<std::size_t>(__builtin_ctz(dead));
      char* out = static_cast<char*>(samples) + sizeof(Sample) * (w.u[kOutIndex][i] - first_slot);
      const std::uint32_t hits = w.u[kVertex][i] - (w.b[kFound][i] ? 0u : 1u);
      __builtin_memcpy(out + offsetof(Sample, film_x), &w.f[kFilmX][i], sizeof(float));
      __builtin_memcpy(out + offsetof(Sample, film_y), &w.f[kFilmY][i], sizeof(float));
      __builtin_memcpy(out + offsetof(Sample, L) + 0 * sizeof(float), &w.f[kLR][i], sizeof(float));
      __builtin_memcpy(out + offsetof(Sample, L) + 1 * sizeof(float), &w.f[kLG][i], sizeof(float));
      __builtin_memcpy(out + offsetof(Sample, L) + 2 * sizeof(float), &w.f[kLB][i], sizeof(float));
      __builtin_memcpy(out + offsetof(Sample, rays), &w.u[kRays][i], sizeof(std::uint32_t));
      __builtin_memcpy(out + offsetof(Sample, hits), &hits, sizeof(std::uint32_t));
    }
    // The survivors, packed behind the previous ones (m <= i0: a block is
    // read before anything is written over it).
    if (alive == in && m == i0) {
      m += static_cast<std::size_t>(__builtin_popcount(in));
      continue;
    }
    for (FloatArray a : kMovedFloats) compress_store(w.f[a] + m, alive, load(w, a, i0, in));
    for (UintArray a : kMovedUints) compress_store(w.u[a] + m, alive, load(w, a, i0, in));
    const auto count = static_cast<std::size_t>(__builtin_popcount(alive));
    const M packed = packed_lanes(alive);
    for (ByteArray a : kMovedBytes) {
      const I v = _mm512_cvtepu8_epi32(_mm_maskz_loadu_epi8(in, w.b[a] + i0));
      _mm512_mask_cvtepi32_storeu_epi8(w.b[a] + m, packed, _mm512_maskz_compress_epi32(alive, v));
    }
    const auto lo = static_cast<__mmask8>(alive & 0xff), hi = static_cast<__mmask8>(alive >> 8);
    const I key_lo = _mm512_maskz_loadu_epi64(static_cast<__mmask8>(in & 0xff), w.rng + i0);
    const I key_hi = _mm512_maskz_loadu_epi64(static_cast<__mmask8>(in >> 8), w.rng + i0 + 8);
    compress_store(w.rng + m, lo, key_lo);
    compress_store(w.rng + m + static_cast<std::size_t>(__builtin_popcount(lo)), hi, key_hi);
    _mm512_mask_cvtepi32_storeu_epi8(w.b[kAlive] + m, packed, _mm512_set1_epi32(1));
    m += count;
  }
  return m;
}

}  // namespace pathlab::vector_stages
