// The vectorised stages of vector_stages.h, 16 paths per AVX-512 register.
//
// Compiled with -mavx512f/dq/bw/vl -ffp-contract=off (wavefront/CMakeLists.txt)
// and called only when vector_stages::cpu_supported(). Every function here
// has internal linkage except the two stages, and nothing is included but the
// plain-data header and <immintrin.h>: see vector_stages.h for why.
//
// Each step names the scalar code it mirrors. The order of every sum and
// product follows that code (GLM's dot is (x + y) + z; a vec3 divided by a
// float divides each component; std::max(a, b) is _mm512_max_ps(b, a)), so
// that a lane's result has the same bits as the scalar one.
#include "wavefront/vector_stages.h"

#include <immintrin.h>

namespace pathlab::vector_stages {
namespace {

using F = __m512;
using I = __m512i;
using M = __mmask16;

constexpr float kInvPi = 1.0f / 3.14159265358979323846f;  // core/math.h
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

// Lane k's float at base + offset + idx[k] bytes (0 in lanes outside m).
F gather(M m, I idx, const void* base, std::size_t offset) {
  return _mm512_mask_i32gather_ps(_mm512_setzero_ps(), m, idx, static_cast<const char*>(base) + offset, 1);
}
V3 gather3(M m, I idx, const void* base, std::size_t offset) {
  return {gather(m, idx, base, offset), gather(m, idx, base, offset + 4), gather(m, idx, base, offset + 8)};
}
void scatter(M m, I idx, void* base, std::size_t offset, F v) {
  _mm512_mask_i32scatter_ps(static_cast<char*>(base) + offset, m, idx, v, 1);
}
void scatter3(M m, I idx, void* base, std::size_t offset, const V3& v) {
  scatter(m, idx, base, offset, v.x);
  scatter(m, idx, base, offset + 4, v.y);
  scatter(m, idx, base, offset + 8, v.z);
}
// Byte offsets of 16 consecutive records of `size` bytes.
I strided(std::size_t size) {
  return _mm512_mullo_epi32(_mm512_set_epi32(15, 14, 13, 12, 11, 10, 9, 8, 7, 6, 5, 4, 3, 2, 1, 0),
                            _mm512_set1_epi32(static_cast<int>(size)));
}
void* advance(void* p, std::size_t bytes) { return static_cast<char*>(p) + bytes; }
const void* advance(const void* p, std::size_t bytes) { return static_cast<const char*>(p) + bytes; }

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
  const F d = dot(abs(n), error);
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
  sin_cos_quarter(mul(k(3.14159265358979323846f / 4.0f), select(wide, div(oy, ox), div(ox, oy))), &s, &c);
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
Streams streams(const WaveView& w, std::size_t i0, M m, I vertex) {
  const auto m_lo = static_cast<__mmask8>(m & 0xff), m_hi = static_cast<__mmask8>(m >> 8);
  const I key_lo = _mm512_maskz_loadu_epi64(m_lo, w.rng + i0), key_hi = _mm512_maskz_loadu_epi64(m_hi, w.rng + i0 + 8);
  const I v_lo = _mm512_slli_epi64(_mm512_cvtepu32_epi64(_mm512_castsi512_si256(vertex)), 32);
  const I v_hi = _mm512_slli_epi64(_mm512_cvtepu32_epi64(_mm512_extracti64x4_epi64(vertex, 1)), 32);
  return {_mm512_xor_si512(key_lo, v_lo), _mm512_xor_si512(key_hi, v_hi)};
}

// The lanes of slots [i0, i0 + 16) that exist, and which of them are alive.
M lanes(std::size_t n, std::size_t i0) {
  return n - i0 >= 16 ? M(0xffff) : static_cast<M>((1u << (n - i0)) - 1u);
}
M alive_lanes(const WaveView& w, std::size_t i0, M in) {
  const I a = _mm512_cvtepu8_epi32(_mm_maskz_loadu_epi8(in, w.alive + i0));
  return _mm512_test_epi32_mask(a, a);
}

// Byte offsets into Scene::shape of each lane's surfel's shape.
I shape_offsets(M m, const void* surfels, I surfel_idx) {
  const I shape = _mm512_mask_i32gather_epi32(_mm512_setzero_si512(), m, surfel_idx,
                                              advance(surfels, layout::kSurfelShape), 1);
  return _mm512_slli_epi32(shape, 6);  // 16 floats per shape
}
F shape_value(M m, const Scene& sc, I shape_offset, std::size_t index) {
  return gather(m, shape_offset, sc.shape, 4 * index);
}
V3 shape_value3(M m, const Scene& sc, I shape_offset, std::size_t index) {
  return gather3(m, shape_offset, sc.shape, 4 * index);
}

// power_heuristic (core/sampling.h).
F power_heuristic(F a, F b) {
  const F r = div(b, a);
  F w = div(k(1.0f), add(k(1.0f), mul(r, r)));
  w = _mm512_mask_mov_ps(w, _mm512_cmp_ps_mask(a, k(0.0f), _CMP_NGT_UQ), k(0.0f));
  return _mm512_mask_mov_ps(w, _mm512_fpclass_ps_mask(a, 0x18), k(1.0f));
}

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
    const F c = _mm512_mask_i32gather_ps(_mm512_setzero_ps(), valid, _mm512_sub_epi32(cand, _mm512_set1_epi32(1)),
                                         lights.cdf, 4);
    idx = _mm512_mask_mov_epi32(idx, valid & le(c, u), cand);
  }
  return _mm512_min_epu32(idx, _mm512_set1_epi32(static_cast<int>(count - 1)));
}

}  // namespace

void generate_camera_rays(const Camera& c, const WaveView& w) {
  using namespace layout;
  const I ray_idx = strided(kRaySize), film_idx = strided(8), spectrum_idx = strided(12), prev_idx = strided(kPrevSize);
  const V3 position{k(c.position[0]), k(c.position[1]), k(c.position[2])};
  const V3 forward{k(c.forward[0]), k(c.forward[1]), k(c.forward[2])};
  const V3 right{k(c.right[0]), k(c.right[1]), k(c.right[2])};
  const V3 up{k(c.up[0]), k(c.up[1]), k(c.up[2])};
  const V3 zero{k(0.0f), k(0.0f), k(0.0f)}, one{k(1.0f), k(1.0f), k(1.0f)};
  for (std::size_t i0 = 0; i0 < w.n; i0 += 16) {
    const M in = lanes(w.n, i0);
    const Streams rng = streams(w, i0, in, _mm512_setzero_si512());  // the camera's numbers are vertex 0's
    // The film position: pixel + FilmX/Y (wavefront_tracer.cpp).
    const F fx = add(_mm512_cvtepu32_ps(_mm512_maskz_loadu_epi32(in, w.x + i0)), rng.u(Dim::FilmX));
    const F fy = add(_mm512_cvtepu32_ps(_mm512_maskz_loadu_epi32(in, w.y + i0)), rng.u(Dim::FilmY));
    scatter(in, film_idx, w.film + 2 * i0, 0, fx);
    scatter(in, film_idx, w.film + 2 * i0, 4, fy);
    // Camera::generate_ray, pinhole.
    const F sx = mul(mul(sub(mul(mul(k(2.0f), fx), k(c.inv_width)), k(1.0f)), k(c.tan_half_fov)), k(c.aspect));
    const F sy = mul(sub(k(1.0f), mul(mul(k(2.0f), fy), k(c.inv_height))), k(c.tan_half_fov));
    const V3 v = add(add(forward, mul(sx, right)), mul(sy, up));
    const V3 d = mul(div(k(1.0f), _mm512_sqrt_ps(dot(v, v))), v);  // glm::normalize: v * (1 / sqrt(v.v))
    void* rays = advance(w.ray, i0 * kRaySize);
    scatter3(in, ray_idx, rays, kRayOrigin, position);
    scatter3(in, ray_idx, rays, kRayDir, d);
    scatter(in, ray_idx, rays, kRayTmax, k(__builtin_inff()));
    // A fresh path: beta 1, L 0, PreviousVertex{} (at 0, pdf 0, impulse, BSDF
    // technique), no rays yet, alive, about to reach vertex 1.
    scatter3(in, spectrum_idx, w.beta + 3 * i0, 0, one);
    scatter3(in, spectrum_idx, w.L + 3 * i0, 0, zero);
    void* prev = advance(w.prev, i0 * kPrevSize);
    scatter3(in, prev_idx, prev, kPrevP, zero);
    scatter(in, prev_idx, prev, kPrevPdf, k(0.0f));
    _mm512_mask_i32scatter_epi32(advance(prev, kPrevImpulse), in, prev_idx, _mm512_set1_epi32(0x0101), 1);
    _mm512_mask_storeu_epi32(w.rays + i0, in, _mm512_setzero_si512());
    _mm512_mask_storeu_epi32(w.vertex + i0, in, _mm512_set1_epi32(1));
    _mm512_mask_cvtepi32_storeu_epi8(w.alive + i0, in, _mm512_set1_epi32(1));
  }
}

void resolve(const Scene& sc, const WaveView& w) {
  using namespace layout;
  const I hit_idx = strided(kHitSize), surfel_idx = strided(kSurfelSize);
  for (std::size_t i0 = 0; i0 < w.n; i0 += 16) {
    const M in = lanes(w.n, i0);
    const I rays = _mm512_maskz_loadu_epi32(in, w.rays + i0);
    _mm512_mask_storeu_epi32(w.rays + i0, in, _mm512_add_epi32(rays, _mm512_set1_epi32(1)));
    const I found_bytes = _mm512_cvtepu8_epi32(_mm_maskz_loadu_epi8(in, w.found + i0));
    const M found = _mm512_test_epi32_mask(found_bytes, found_bytes);
    if (found == 0) continue;
    const void* hits = advance(w.hit, i0 * kHitSize);
    const I shape = _mm512_mask_i32gather_epi32(_mm512_setzero_si512(), found, hit_idx, advance(hits, kHitShape), 1);
    const I prim = _mm512_mask_i32gather_epi32(_mm512_setzero_si512(), found, hit_idx, advance(hits, kHitPrim), 1);
    const F b1 = gather(found, hit_idx, hits, kHitUv), b2 = gather(found, hit_idx, hits, kHitUv + 4);
    // triangle_point (core/geometry.cpp) of triangle first_triangle[shape] + prim.
    const I tri = _mm512_add_epi32(_mm512_mask_i32gather_epi32(_mm512_setzero_si512(), found, shape, sc.first_triangle, 4), prim);
    const I t = _mm512_mullo_epi32(tri, _mm512_set1_epi32(12));  // in floats
    auto vertex3 = [&](int first) {
      return V3{_mm512_mask_i32gather_ps(_mm512_setzero_ps(), found, _mm512_add_epi32(t, _mm512_set1_epi32(first)),
                                         sc.triangles, 4),
                _mm512_mask_i32gather_ps(_mm512_setzero_ps(), found, _mm512_add_epi32(t, _mm512_set1_epi32(first + 1)),
                                         sc.triangles, 4),
                _mm512_mask_i32gather_ps(_mm512_setzero_ps(), found, _mm512_add_epi32(t, _mm512_set1_epi32(first + 2)),
                                         sc.triangles, 4)};
    };
    const V3 p0 = vertex3(0), p1 = vertex3(3), p2 = vertex3(6), n = vertex3(9);
    const F b0 = sub(sub(k(1.0f), b1), b2);
    const V3 p = add(add(mul(b0, p0), mul(b1, p1)), mul(b2, p2));
    const V3 error = mul(k(kGamma7), add(add(abs(mul(b0, p0)), abs(mul(b1, p1))), abs(mul(b2, p2))));
    // Frame(n) (core/math.h).
    const F sign = _mm512_castsi512_ps(_mm512_or_si512(
        _mm512_and_si512(_mm512_castps_si512(n.z), _mm512_set1_epi32(INT32_MIN)), _mm512_castps_si512(k(1.0f))));
    const F a = div(k(-1.0f), add(sign, n.z));
    const F b = mul(mul(n.x, n.y), a);
    const V3 fs{add(k(1.0f), mul(mul(mul(sign, n.x), n.x), a)), mul(sign, b), mul(neg(sign), n.x)};
    const V3 ft{b, add(sign, mul(mul(n.y, n.y), a)), neg(n.y)};
    void* surfels = advance(w.surfel, i0 * kSurfelSize);
    scatter3(found, surfel_idx, surfels, kSurfelP, p);
    scatter3(found, surfel_idx, surfels, kSurfelPError, error);
    scatter3(found, surfel_idx, surfels, kSurfelN, n);
    scatter3(found, surfel_idx, surfels, kSurfelFrameS, fs);
    scatter3(found, surfel_idx, surfels, kSurfelFrameT, ft);
    scatter3(found, surfel_idx, surfels, kSurfelFrameN, n);
    _mm512_mask_i32scatter_epi32(advance(surfels, kSurfelShape), found, surfel_idx, shape, 1);
    _mm512_mask_i32scatter_epi32(advance(surfels, kSurfelPrim), found, surfel_idx, prim, 1);
    // Surfel::material: the shape's material, 64-bit pointers in two halves.
    const I shape_hi = _mm512_shuffle_i64x2(shape, shape, 0x4e), idx_hi = _mm512_shuffle_i64x2(surfel_idx, surfel_idx, 0x4e);
    const auto m_lo = static_cast<__mmask8>(found & 0xff), m_hi = static_cast<__mmask8>(found >> 8);
    const I mat_lo = _mm512_mask_i32gather_epi64(_mm512_setzero_si512(), m_lo, _mm512_castsi512_si256(shape), sc.material, 8);
    const I mat_hi = _mm512_mask_i32gather_epi64(_mm512_setzero_si512(), m_hi, _mm512_castsi512_si256(shape_hi), sc.material, 8);
    _mm512_mask_i32scatter_epi64(advance(surfels, kSurfelMaterial), m_lo, _mm512_castsi512_si256(surfel_idx), mat_lo, 1);
    _mm512_mask_i32scatter_epi64(advance(surfels, kSurfelMaterial), m_hi, _mm512_castsi512_si256(idx_hi), mat_hi, 1);
  }
}

void add_emission(const Scene& sc, const WaveView& w) {
  using namespace layout;
  const I surfel_idx = strided(kSurfelSize), ray_idx = strided(kRaySize), spectrum_idx = strided(12),
          prev_idx = strided(kPrevSize);
  const V3 zero{k(0.0f), k(0.0f), k(0.0f)};
  for (std::size_t i0 = 0; i0 < w.n; i0 += 16) {
    const M in = lanes(w.n, i0);
    const I found_bytes = _mm512_cvtepu8_epi32(_mm_maskz_loadu_epi8(in, w.found + i0));
    const M found = _mm512_test_epi32_mask(found_bytes, found_bytes);
    const V3 beta = gather3(in, spectrum_idx, w.beta + 3 * i0, 0);
    V3 L = gather3(in, spectrum_idx, w.L + 3 * i0, 0);
    // Escaped: no environment, so Le = 0 and its weight 0; L += beta * (0 * 0).
    const V3 L_escaped = add(L, mul(beta, mul(k(0.0f), zero)));
    M alive = 0;
    if (found != 0) {
      // Surfel::emitted.
      const void* surfels = advance(w.surfel, i0 * kSurfelSize);
      const I shape = shape_offsets(found, surfels, surfel_idx);
      const V3 wo = neg(gather3(found, ray_idx, advance(w.ray, i0 * kRaySize), kRayDir));
      const V3 n = gather3(found, surfel_idx, surfels, kSurfelN);
      const M emits = found & ~eq(shape_value(found, sc, shape, shape_field::kEmits), k(0.0f));
      const M facing = ~eq(shape_value(found, sc, shape, shape_field::kTwoSided), k(0.0f)) | gt(dot(n, wo), k(0.0f));
      const V3 Le = select(emits & facing, shape_value3(found, sc, shape, shape_field::kEmission), zero);
      const M lit = found & ~is_black(Le);
      // LightSampler::pdf(prev.p, s) for the lit lanes.
      void* prev = advance(w.prev, i0 * kPrevSize);
      const I flags = _mm512_mask_i32gather_epi32(_mm512_setzero_si512(), lit, prev_idx, advance(prev, kPrevImpulse), 1);
      const M impulse = _mm512_test_epi32_mask(flags, _mm512_set1_epi32(0xff));
      const M bsdf_technique = _mm512_test_epi32_mask(flags, _mm512_set1_epi32(0xff00));
      const F prev_pdf = gather(lit, prev_idx, prev, kPrevPdf);
      const I first = _mm512_castps_si512(shape_value(lit, sc, shape, shape_field::kFirstLight));
      const M light = lit & _mm512_cmpge_epi32_mask(first, _mm512_setzero_si512());
      const I prim = _mm512_mask_i32gather_epi32(_mm512_setzero_si512(), light, surfel_idx,
                                                 advance(surfels, kSurfelPrim), 1);
      const I entry = _mm512_add_epi32(first, prim);
      const V3 d = sub(gather3(light, surfel_idx, surfels, kSurfelP), gather3(light, prev_idx, prev, kPrevP));
      const F dist = _mm512_sqrt_ps(dot(d, d));
      const F c = _mm512_abs_ps(div(dot(n, d), dist));
      const F inv_area = _mm512_mask_i32gather_ps(_mm512_setzero_ps(), light, entry, sc.lights.inv_area, 4);
      const F pmf = _mm512_mask_i32gather_ps(_mm512_setzero_ps(), light, entry, sc.lights.pmf, 4);
      const F to_solid_angle = select(gt(c, k(0.0f)), div(mul(mul(inv_area, dist), dist), c), k(0.0f));
      const F light_pdf = _mm512_maskz_mov_ps(light, mul(pmf, to_solid_angle));
      // emission_weight (core/strategy_weights.h).
      F weight = k(1.0f);
      if (sc.strategy == Strategy::Light) weight = select(gt(light_pdf, k(0.0f)), k(0.0f), k(1.0f));
      if (sc.strategy == Strategy::Mis) weight = power_heuristic(prev_pdf, light_pdf);
      if (sc.strategy == Strategy::LightBsdf)
        weight = _mm512_maskz_mov_ps(bsdf_technique, div(mul(k(2.0f), prev_pdf), add(prev_pdf, light_pdf)));
      weight = _mm512_mask_mov_ps(weight, impulse, k(1.0f));
      weight = _mm512_maskz_mov_ps(lit, weight);
      const V3 L_hit = add(L, mul(beta, mul(weight, Le)));
      L = select(found, L_hit, L_escaped);
      // The path goes on if it may take another vertex and the surface scatters.
      const I vertex = _mm512_maskz_loadu_epi32(in, w.vertex + i0);
      alive = found & _mm512_cmple_epi32_mask(vertex, _mm512_set1_epi32(sc.max_vertex)) &
              ~eq(shape_value(found, sc, shape, shape_field::kScatters), k(0.0f));
    } else {
      L = L_escaped;
    }
    scatter3(in, spectrum_idx, w.L + 3 * i0, 0, L);
    _mm512_mask_cvtepi32_storeu_epi8(w.alive + i0, in, _mm512_maskz_mov_epi32(alive, _mm512_set1_epi32(1)));
  }
}

void add_light(const WaveView& w) {
  const I spectrum_idx = strided(12), pair_spectrum_idx = strided(2 * 12);
  for (std::size_t i0 = 0; i0 < w.n; i0 += 16) {
    const M in = lanes(w.n, i0);
    // Slot [2i + 1]'s state (slot [2i], for point lights, is always empty here).
    const I pairs = _mm512_cvtepu16_epi32(_mm256_maskz_loadu_epi16(in, w.shadow_state + 2 * i0));
    const I state = _mm512_srli_epi32(pairs, 8);
    const M traced = in & _mm512_test_epi32_mask(state, state);
    if (traced == 0) continue;
    const M visible = traced & _mm512_cmpeq_epi32_mask(state, _mm512_set1_epi32(2));
    const V3 beta = gather3(traced, spectrum_idx, w.beta + 3 * i0, 0);
    const V3 L = gather3(traced, spectrum_idx, w.L + 3 * i0, 0);
    const V3 unoccluded = gather3(visible, pair_spectrum_idx, w.unoccluded + 3 * (2 * i0 + 1), 0);
    const V3 zero{k(0.0f), k(0.0f), k(0.0f)};
    scatter3(traced, spectrum_idx, w.L + 3 * i0, 0, add(L, select(visible, mul(beta, unoccluded), zero)));
  }
}

void sample_lights(const Scene& sc, const WaveView& w) {
  using namespace layout;
  const I surfel_idx = strided(kSurfelSize), ray_idx = strided(kRaySize), shadow_idx = strided(2 * kRaySize);
  const I pair_spectrum_idx = strided(2 * 12), pair_float_idx = strided(2 * 4);
  for (std::size_t i0 = 0; i0 < w.n; i0 += 16) {
    const M in = lanes(w.n, i0);
    const void* surfels = advance(w.surfel, i0 * kSurfelSize);
    const I vertex = _mm512_maskz_loadu_epi32(in, w.vertex + i0);
    const Streams rng = streams(w, i0, in, vertex);
    // samples_area_lights (core/strategy_weights.h).
    M ok = alive_lanes(w, i0, in);
    if (sc.strategy == Strategy::Bsdf || sc.lights.count == 0) ok = 0;
    if (sc.strategy == Strategy::LightBsdf) ok &= lt(rng.u(Dim::Technique), k(0.5f));

    if (ok != 0) {
      // LightSampler::sample: pick a triangle, then a point uniformly on it
      // (square_to_uniform_triangle, triangle_point).
      const I light = pick(ok, sc.lights, rng.u(Dim::LightChoice));
      const F ux = rng.u(Dim::LightX), uy = rng.u(Dim::LightY);
      const F s = _mm512_sqrt_ps(ux);
      const F b1 = mul(uy, s), b2 = sub(k(1.0f), s);
      const F b0 = sub(sub(k(1.0f), b1), b2);
      const I tri = _mm512_slli_epi32(light, 6);  // 16 floats per light
      const V3 p0 = gather3(ok, tri, sc.lights.triangle, 0), p1 = gather3(ok, tri, sc.lights.triangle, 12),
               p2 = gather3(ok, tri, sc.lights.triangle, 24), ln = gather3(ok, tri, sc.lights.triangle, 36),
               Le = gather3(ok, tri, sc.lights.triangle, 48);
      const F two_sided = gather(ok, tri, sc.lights.triangle, 60);
      const V3 lp = add(add(mul(b0, p0), mul(b1, p1)), mul(b2, p2));
      const V3 lerr = mul(k(kGamma7), add(add(abs(mul(b0, p0)), abs(mul(b1, p1))), abs(mul(b2, p2))));

      const V3 sp = gather3(ok, surfel_idx, surfels, kSurfelP);
      const V3 d = sub(lp, sp);
      const F dist = _mm512_sqrt_ps(dot(d, d));
      ok &= gt(dist, k(0.0f));
      const V3 wi = div(d, dist);
      const F cos_light = dot(ln, neg(wi));
      ok &= ~eq(two_sided, k(0.0f)) | _mm512_cmp_ps_mask(cos_light, k(0.0f), _CMP_NLE_UQ);  // back of a one-sided emitter
      // pmf * area_to_solid_angle(1 / area, dist, cos_light) (core/sampling.h).
      const F c = _mm512_abs_ps(cos_light);
      const F inv_area = _mm512_mask_i32gather_ps(_mm512_setzero_ps(), ok, light, sc.lights.inv_area, 4);
      const F pmf = _mm512_mask_i32gather_ps(_mm512_setzero_ps(), ok, light, sc.lights.pmf, 4);
      const F to_solid_angle = select(gt(c, k(0.0f)), div(mul(mul(inv_area, dist), dist), c), k(0.0f));
      const F pdf_light = mul(pmf, to_solid_angle);
      ok &= gt(pdf_light, k(0.0f)) & ~_mm512_fpclass_ps_mask(pdf_light, 0x18);  // seen edge-on

      // Surfel::eval and Surfel::pdf of the Lambert lobe (core/surfel.cpp,
      // bsdf/lambert.h): only the local z of wo and wi matters.
      const V3 wo = neg(gather3(ok, ray_idx, advance(w.ray, i0 * kRaySize), kRayDir));
      const V3 fn = gather3(ok, surfel_idx, surfels, kSurfelFrameN);
      const F wo_z = dot(wo, fn);
      F wi_z = dot(wi, fn);
      wi_z = select(lt(wo_z, k(0.0f)), neg(wi_z), wi_z);
      const M upper = gt(wi_z, k(0.0f));
      const F cos_pi = mul(wi_z, k(kInvPi));
      const V3 rho = shape_value3(ok, sc, shape_offsets(ok, surfels, surfel_idx), shape_field::kAlbedo);
      const V3 zero{k(0.0f), k(0.0f), k(0.0f)};
      const V3 f = select(upper, mul(cos_pi, rho), zero);
      ok &= ~is_black(f);
      const F pdf_bsdf = select(upper, cos_pi, k(0.0f));

      // light_sample_weight (core/strategy_weights.h); pdf_light is finite and > 0 here.
      F weight = k(1.0f);
      if (sc.strategy == Strategy::Mis) {
        weight = power_heuristic(pdf_light, pdf_bsdf);
      } else if (sc.strategy == Strategy::LightBsdf) {
        weight = div(mul(k(2.0f), pdf_light), add(pdf_light, pdf_bsdf));
      }
      const V3 unoccluded = mul(div(weight, pdf_light), mul(f, Le));

      // Surfel::spawn_to(lp, lerr, ln).
      const V3 sn = gather3(ok, surfel_idx, surfels, kSurfelN), serr = gather3(ok, surfel_idx, surfels, kSurfelPError);
      const V3 origin = offset_ray_origin(sp, serr, select(ge(dot(d, sn), k(0.0f)), sn, neg(sn)));
      const V3 end = offset_ray_origin(lp, lerr, select(ge(dot(sub(origin, lp), ln), k(0.0f)), ln, neg(ln)));
      const V3 dd = sub(end, origin);
      const F len = _mm512_sqrt_ps(dot(dd, dd));

      void* shadow = advance(w.shadow, (2 * i0 + 1) * kRaySize);
      scatter3(ok, shadow_idx, shadow, kRayOrigin, origin);
      scatter3(ok, shadow_idx, shadow, kRayDir, div(dd, len));
      scatter(ok, shadow_idx, shadow, kRayTmax, len);
      scatter3(ok, pair_spectrum_idx, w.unoccluded + 3 * (2 * i0 + 1), 0, unoccluded);
      scatter(ok, pair_float_idx, w.light_weight + 2 * i0 + 1, 0, weight);
    }
    // Slot [2i] (point lights) is empty; slot [2i + 1] is to be traced or empty.
    const I state = _mm512_maskz_mov_epi32(ok, _mm512_set1_epi32(0x0100));
    _mm512_mask_cvtepi32_storeu_epi16(w.shadow_state + 2 * i0, in, state);
  }
}

void scatter(const Scene& sc, const WaveView& w) {
  using namespace layout;
  const I surfel_idx = strided(kSurfelSize), ray_idx = strided(kRaySize), spectrum_idx = strided(12),
          prev_idx = strided(kPrevSize);
  for (std::size_t i0 = 0; i0 < w.n; i0 += 16) {
    const M in = lanes(w.n, i0);
    M ok = alive_lanes(w, i0, in);
    if (ok == 0) continue;
    const void* surfels = advance(w.surfel, i0 * kSurfelSize);
    void* rays = advance(w.ray, i0 * kRaySize);
    I vertex = _mm512_maskz_loadu_epi32(in, w.vertex + i0);
    const Streams rng = streams(w, i0, in, vertex);

    // square_to_cosine_hemisphere (core/sampling.cpp).
    F x, y;
    concentric_disk(rng.u(Dim::DirectionX), rng.u(Dim::DirectionY), &x, &y);
    const F z = _mm512_sqrt_ps(_mm512_max_ps(sub(sub(k(1.0f), mul(x, x)), mul(y, y)), k(0.0f)));

    // Surfel::scatter, Lambert: no sample on the disk's rim, or below min_pdf.
    const F pdf = select(gt(z, k(0.0f)), mul(z, k(kInvPi)), k(0.0f));
    ok &= _mm512_cmp_ps_mask(pdf, k(0.0f), _CMP_NLE_UQ) & _mm512_cmp_ps_mask(pdf, k(sc.min_pdf), _CMP_NLT_UQ);
    const V3 wo = neg(gather3(ok, ray_idx, rays, kRayDir));
    const V3 fs = gather3(ok, surfel_idx, surfels, kSurfelFrameS), ft = gather3(ok, surfel_idx, surfels, kSurfelFrameT),
             fn = gather3(ok, surfel_idx, surfels, kSurfelFrameN);
    const F side = select(lt(dot(wo, fn), k(0.0f)), k(-1.0f), k(1.0f));
    const F wz = mul(z, side);
    const V3 wi = add(add(mul(x, fs), mul(y, ft)), mul(wz, fn));  // Frame::to_world
    V3 weight = shape_value3(ok, sc, shape_offsets(ok, surfels, surfel_idx), shape_field::kAlbedo);
    ok &= ~is_black(weight);

    // Russian roulette (the scatter stage).
    V3 beta = gather3(ok, spectrum_idx, w.beta + 3 * i0, 0);
    const M rr = ok & _mm512_cmpgt_epi32_mask(vertex, _mm512_set1_epi32(sc.rr_depth));
    if (rr != 0) {
      const V3 bw = mul(beta, weight);
      const F survival = _mm512_min_ps(_mm512_max_ps(_mm512_max_ps(bw.z, bw.y), bw.x), k(1.0f));
      ok &= ~(rr & ~lt(rng.u(Dim::Roulette), survival));
      weight = select(rr, div(weight, survival), weight);
    }
    beta = mul(beta, weight);
    scatter3(ok, spectrum_idx, w.beta + 3 * i0, 0, beta);

    // PreviousVertex{s.p, pdf, impulse = false, bsdf_technique}.
    const V3 sp = gather3(ok, surfel_idx, surfels, kSurfelP);
    void* prev = advance(w.prev, i0 * kPrevSize);
    scatter3(ok, prev_idx, prev, kPrevP, sp);
    scatter(ok, prev_idx, prev, kPrevPdf, pdf);
    M bsdf_technique = 0xffff;
    if (sc.strategy == Strategy::LightBsdf) bsdf_technique = ~lt(rng.u(Dim::Technique), k(0.5f));
    static_assert(layout::kPrevBsdfTechnique == layout::kPrevImpulse + 1);
    const I flags = _mm512_maskz_mov_epi32(bsdf_technique, _mm512_set1_epi32(0x0100));  // impulse 0, bsdf_technique
    _mm512_mask_i32scatter_epi32(advance(prev, kPrevImpulse), ok, prev_idx, flags, 1);

    // Surfel::spawn(wi).
    const V3 sn = gather3(ok, surfel_idx, surfels, kSurfelN), serr = gather3(ok, surfel_idx, surfels, kSurfelPError);
    const V3 origin = offset_ray_origin(sp, serr, select(ge(dot(wi, sn), k(0.0f)), sn, neg(sn)));
    scatter3(ok, ray_idx, rays, kRayOrigin, origin);
    scatter3(ok, ray_idx, rays, kRayDir, wi);
    scatter(ok, ray_idx, rays, kRayTmax, k(__builtin_inff()));
    vertex = _mm512_mask_add_epi32(vertex, ok, vertex, _mm512_set1_epi32(1));
    _mm512_mask_storeu_epi32(w.vertex + i0, ok, vertex);
    _mm512_mask_cvtepi32_storeu_epi8(w.alive + i0, in, _mm512_maskz_mov_epi32(ok, _mm512_set1_epi32(1)));
  }
}

}  // namespace pathlab::vector_stages
