// What render.intersection = fast costs in accuracy and buys in speed
// (docs/performance.md, "Robust or fast intersection"): rays from random
// points inside closed icospheres of 1,280 to 327,680 triangles, in random
// directions, must all hit the mesh; the ones that do not slipped through a
// crack between two triangles. For each size and each mode, robust and
// fast, the run prints the escaped rays, their rate with a 95 % upper bound,
// and Embree's rate for these rays (one thread, streams of 4,096, the modes
// alternating in rounds so that drift hits both alike).
//
//   pathlab_bench_watertight [RAYS_PER_SIZE]     (default 10^7)
#include "bench/processor.h"
#include "core/embree_accel.h"
#include "core/sampling.h"
#include "tests/closed_mesh.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <random>
#include <vector>

namespace pathlab::bench {
namespace {

struct Tally {
  std::size_t rays = 0, escaped = 0;
  double seconds = 0.0;
};

void cast(const EmbreeAccel& accel, std::mt19937_64& rng, std::size_t n, Tally* tally) {
  std::uniform_real_distribution<float> u(0.0f, 1.0f);
  std::vector<Ray> rays(n);
  for (Ray& ray : rays) {
    // Anywhere in the inscribed cube's middle, any direction.
    const vec3 o = 0.5f * (vec3(u(rng), u(rng), u(rng)) - 0.5f);
    ray = Ray{o, square_to_uniform_sphere(vec2(u(rng), u(rng))), kInfinity};
  }
  std::vector<RayHit> hits(n);
  std::vector<std::uint8_t> found(n);
  const auto start = std::chrono::steady_clock::now();
  accel.intersect_batch(rays, hits, found, RayBatchMode::Stream);
  tally->seconds += std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  tally->rays += n;
  for (std::uint8_t f : found) tally->escaped += f == 0;
}

}  // namespace
}  // namespace pathlab::bench

int main(int argc, char** argv) {
  using namespace pathlab;
  using namespace pathlab::bench;
  const std::size_t per_size = argc > 1 ? std::strtoull(argv[1], nullptr, 10) : 10'000'000;
  if (per_size == 0) {
    std::fprintf(stderr, "usage: pathlab_bench_watertight [RAYS_PER_SIZE > 0]\n");
    return 2;
  }
  std::printf("processor: %s\n", processor().c_str());
  std::printf("%10s %12s  %-7s %9s %10s %12s %12s\n", "triangles", "rays", "mode", "escaped", "rate", "95% bound",
              "rays/s");
  constexpr std::size_t kChunk = 4096, kRounds = 20;
  for (const int subdivisions : {3, 5, 7}) {
    std::vector<Shape> shapes(1);
    shapes[0].mesh = test::icosphere(subdivisions);
    const EmbreeAccel robust(shapes, {}, {}, BvhOptions{.intersection = Intersection::Robust});
    const EmbreeAccel fast(shapes, {}, {}, BvhOptions{.intersection = Intersection::Fast});
    // Both modes see the same rays, round by round, in alternating order.
    Tally tally[2];
    std::mt19937_64 rng[2] = {std::mt19937_64(subdivisions), std::mt19937_64(subdivisions)};
    const std::size_t per_round = (per_size + kRounds - 1) / kRounds;
    for (std::size_t round = 0; round < kRounds; ++round)
      for (int k = 0; k < 2; ++k) {
        const int mode = (round + k) % 2;
        for (std::size_t done = 0; done < per_round; done += kChunk)
          cast(mode == 0 ? robust : fast, rng[mode], std::min(kChunk, per_round - done), &tally[mode]);
      }
    for (int mode = 0; mode < 2; ++mode) {
      const Tally& t = tally[mode];
      const double n = static_cast<double>(t.rays), k = static_cast<double>(t.escaped);
      // 95 % upper bound on the rate: 3 / n for none (the rule of three),
      // else the normal approximation of the Poisson count.
      const double bound = t.escaped == 0 ? 3.0 / n : (k + 1.645 * std::sqrt(k) + 1.0) / n;
      std::printf("%10zu %12zu  %-7s %9zu %10.2e %12.2e %12.3e\n", shapes[0].mesh.triangles.size(), t.rays,
                  mode == 0 ? "robust" : "fast", t.escaped, k / n, bound, n / t.seconds);
    }
    std::printf("%10s %12s  fast / robust rays per second: %.3f\n", "", "",
                (tally[1].rays / tally[1].seconds) / (tally[0].rays / tally[0].seconds));
  }
  return 0;
}
