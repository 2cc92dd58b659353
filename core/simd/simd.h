// Which SIMD instruction set pathlab's vectorised code runs.
//
// Per-lane code is written once, over Google Highway's portable vectors, in
// the core/simd/*-inl.h headers, and compiled for every target below by
// Highway's foreach_target (one translation unit, one namespace per
// target); HWY_DYNAMIC_DISPATCH calls the best one this processor runs
// unless the user asked for another (`--simd NAME` or the PATHLAB_SIMD
// environment variable), so an AVX-512 machine can measure its AVX2 and
// SSE4 code too. `scalar` is the same source at width 1.
//
// Every target computes the same bits: the headers use IEEE's correctly
// rounded +, -, *, / and sqrt only, no fused multiply-add (-ffp-contract=off
// project-wide; Highway's MulAdd is never called), and pathlab's own
// polynomials for the transcendentals (sin_cos_quarter), never a libm or
// hwy/contrib/math call whose last bits depend on the target.
#pragma once

#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace pathlab {

enum class SimdTarget { Auto, Avx512, Avx2, Sse4, Scalar };

const char* simd_target_name(SimdTarget t);  // "auto", "avx512", "avx2", "sse4", "scalar"
std::optional<SimdTarget> parse_simd_target(std::string_view name);

// The targets this processor runs and pathlab is compiled for, best first
// (never Auto; always ends with Scalar).
std::vector<SimdTarget> supported_simd_targets();

// Makes dispatch choose `t` (Auto: the best supported one) from now on.
// Throws InputError naming the target and what the processor has when it
// cannot run it. Not thread-safe: call it before rendering.
void select_simd_target(SimdTarget t);

// select_simd_target(parse(value of PATHLAB_SIMD)) if that variable is set
// and not empty; an unknown name or an unsupported target throws InputError
// naming the variable.
void select_simd_target_from_environment();
// What a command line does: the target it asked for (--simd), else
// $PATHLAB_SIMD's, else the best this processor runs. InputError as above,
// an asked-for target's naming `option`.
void select_simd_target(std::optional<SimdTarget> asked, std::string_view option);

// The target dispatch calls now (never Auto).
SimdTarget active_simd_target();

}  // namespace pathlab
