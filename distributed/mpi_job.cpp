#include "distributed/mpi_job.h"

#include "core/error.h"

#include <mpi.h>

#include <algorithm>
#include <array>
#include <chrono>
#include <cstdlib>
#include <cstring>
#include <string>
#include <utility>
#include <vector>

namespace pathlab {
namespace {

void check(int code, const char* what) {
  if (code == MPI_SUCCESS) return;
  char text[MPI_MAX_ERROR_STRING];
  int length = 0;
  MPI_Error_string(code, text, &length);
  throw SystemError(std::string("MPI: ") + what + " failed: " + std::string(text, static_cast<std::size_t>(length)));
}

// The reduction's operations: exact integer addition of the film's words.
// Commutative and associative, so MPI may combine ranks in any order.
void add_pixels(void* in, void* inout, int* n, MPI_Datatype*) {
  Film::add_pixel_words(static_cast<const std::uint64_t*>(in), static_cast<std::uint64_t*>(inout),
                        static_cast<std::size_t>(*n));
}
void add_sums(void* in, void* inout, int* n, MPI_Datatype*) {
  Film::add_sum_words(static_cast<const std::uint64_t*>(in), static_cast<std::uint64_t*>(inout),
                      static_cast<std::size_t>(*n));
}

// MPI counts are ints: large arrays go in chunks.
constexpr std::size_t kChunk = std::size_t{1} << 24;

struct Reduction {
  MPI_Datatype pixel = MPI_DATATYPE_NULL, sum = MPI_DATATYPE_NULL;
  MPI_Op pixel_add = MPI_OP_NULL, sum_add = MPI_OP_NULL;
  Reduction() {
    check(MPI_Type_contiguous(static_cast<int>(Film::kPixelWords), MPI_UINT64_T, &pixel), "MPI_Type_contiguous");
    check(MPI_Type_commit(&pixel), "MPI_Type_commit");
    check(MPI_Type_contiguous(2, MPI_UINT64_T, &sum), "MPI_Type_contiguous");
    check(MPI_Type_commit(&sum), "MPI_Type_commit");
    check(MPI_Op_create(&add_pixels, 1, &pixel_add), "MPI_Op_create");
    check(MPI_Op_create(&add_sums, 1, &sum_add), "MPI_Op_create");
  }
  ~Reduction() {
    MPI_Op_free(&pixel_add);
    MPI_Op_free(&sum_add);
    MPI_Type_free(&pixel);
    MPI_Type_free(&sum);
  }
  // Reduces `n` elements of `type` (each `words` words) from `in` to `out` on rank 0.
  static void reduce(const std::uint64_t* in, std::uint64_t* out, std::size_t n, std::size_t words, MPI_Datatype type,
                     MPI_Op op) {
    for (std::size_t b = 0; b < n; b += kChunk) {
      const int count = static_cast<int>(std::min(kChunk, n - b));
      check(MPI_Reduce(in + b * words, out ? out + b * words : nullptr, count, type, op, 0, MPI_COMM_WORLD),
            "MPI_Reduce of the film");
    }
  }
};

// A bad sample as it travels: x, y, sample and the radiance's bits.
using BadWire = std::array<std::uint32_t, 6>;

}  // namespace

MpiJob::MpiJob() {
  if (!launched_by_mpirun()) return;
  int provided = 0;
  check(MPI_Init_thread(nullptr, nullptr, MPI_THREAD_FUNNELED, &provided), "MPI_Init_thread");
  initialised_ = true;
  MPI_Comm_set_errhandler(MPI_COMM_WORLD, MPI_ERRORS_RETURN);
  check(MPI_Comm_rank(MPI_COMM_WORLD, &rank_), "MPI_Comm_rank");
  check(MPI_Comm_size(MPI_COMM_WORLD, &size_), "MPI_Comm_size");
}

MpiJob::~MpiJob() {
  if (initialised_) MPI_Finalize();
}

void MpiJob::reduce(const Film& film, const RenderStats& stats, Film* sum, RenderStats* total) const {
  const Reduction r;
  const Film::ConstWords in = film.words();
  const Film::Words out = rank_ == 0 ? sum->words() : Film::Words{};
  const std::size_t pixels = static_cast<std::size_t>(film.width()) * film.height();
  Reduction::reduce(in.pixels.data(), rank_ == 0 ? out.pixels.data() : nullptr, pixels, Film::kPixelWords, r.pixel,
                    r.pixel_add);
  if (!in.moments.empty())
    Reduction::reduce(in.moments.data(), rank_ == 0 ? out.moments.data() : nullptr, in.moments.size() / 2, 2, r.sum,
                      r.sum_add);
  if (!in.splat.empty())
    Reduction::reduce(in.splat.data(), rank_ == 0 ? out.splat.data() : nullptr, in.splat.size() / 2, 2, r.sum,
                      r.sum_add);

  // Counts and stats: integers summed exactly; the energies as fixed-point sums.
  const std::array<std::uint64_t, 5> counts{stats.samples, stats.rays, stats.clamped_samples, film.bad_sample_count(),
                                            film.rays_cast()};
  std::array<std::uint64_t, 5> count_sums{};
  check(MPI_Reduce(counts.data(), count_sums.data(), 5, MPI_UINT64_T, MPI_SUM, 0, MPI_COMM_WORLD), "MPI_Reduce");
  const std::array<std::uint64_t, 4> energies{stats.energy_total.low(), stats.energy_total.high(),
                                              stats.energy_clamped.low(), stats.energy_clamped.high()};
  std::array<std::uint64_t, 4> energy_sums{};
  check(MPI_Reduce(energies.data(), energy_sums.data(), 2, r.sum, r.sum_add, 0, MPI_COMM_WORLD), "MPI_Reduce");
  double seconds = 0.0;
  check(MPI_Reduce(&stats.seconds, &seconds, 1, MPI_DOUBLE, MPI_MAX, 0, MPI_COMM_WORLD), "MPI_Reduce");
  // The bad samples each rank kept; rank 0 keeps the first of them all.
  std::vector<BadWire> mine(Film::kMaxBadSamplesKept, BadWire{0xffffffffu, 0, 0, 0, 0, 0});
  for (std::size_t i = 0; i < film.bad_samples().size(); ++i) {
    const BadSample& b = film.bad_samples()[i];
    mine[i] = {b.x, b.y, b.sample, std::bit_cast<std::uint32_t>(b.L.x), std::bit_cast<std::uint32_t>(b.L.y),
               std::bit_cast<std::uint32_t>(b.L.z)};
  }
  std::vector<BadWire> all(rank_ == 0 ? mine.size() * static_cast<std::size_t>(size_) : 0);
  const int per_rank = static_cast<int>(mine.size() * 6);
  check(MPI_Gather(mine.data(), per_rank, MPI_UINT32_T, all.data(), per_rank, MPI_UINT32_T, 0, MPI_COMM_WORLD),
        "MPI_Gather");
  if (rank_ != 0) return;
  std::vector<BadSample> kept;
  for (const BadWire& w : all)
    if (w[0] != 0xffffffffu)
      kept.push_back({w[0], w[1], w[2],
                      Spectrum(std::bit_cast<float>(w[3]), std::bit_cast<float>(w[4]), std::bit_cast<float>(w[5]))});
  sum->restore_counts(count_sums[3], count_sums[4], std::move(kept));
  *total = RenderStats{};
  total->samples = count_sums[0];
  total->rays = count_sums[1];
  total->clamped_samples = count_sums[2];
  total->energy_total = Sum1::from_words(energy_sums[0], energy_sums[1]);
  total->energy_clamped = Sum1::from_words(energy_sums[2], energy_sums[3]);
  total->seconds = seconds;
  total->bad_samples = count_sums[3];
}

MpiJob::Result MpiJob::render(const Tracer& tracer, Film& film, std::uint32_t start, std::uint32_t last,
                              std::uint32_t block, const std::function<bool()>& interrupted,
                              const WantsCheckpointFn& wants_checkpoint, const ReducedFn& reduced,
                              const ProgressFn& progress) const {
  block = std::max<std::uint32_t>(block, 1);
  const auto n = static_cast<std::uint64_t>(size_);
  RenderStats stats;  // this rank's
  Result result{start, false};
  const auto reduce_and_report = [&](std::uint32_t end) {
    const auto t0 = std::chrono::steady_clock::now();
    std::unique_ptr<Film> sum;
    if (rank_ == 0)
      sum = std::make_unique<Film>(film.width(), film.height(), film.filter(),
                                   film.keeps_variance() ? FilmMoments::MeanAndVariance : FilmMoments::Mean);
    RenderStats total;
    reduce(film, stats, sum.get(), &total);
    ++result.reductions;
    result.reduce_seconds += std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    if (rank_ == 0) reduced(end, *sum, total);
  };
  const Film::ConstWords w = std::as_const(film).words();
  result.film_bytes = 8 * (w.pixels.size() + w.moments.size() + w.splat.size());
  for (std::uint64_t round = 0;; ++round) {
    const std::uint64_t round_start = start + round * n * block;
    if (round_start >= last) break;
    const std::uint64_t mine = round_start + static_cast<std::uint64_t>(rank_) * block;
    if (mine < last) {
      const auto to = static_cast<std::uint32_t>(std::min<std::uint64_t>(mine + block, last));
      const RenderStats s = render_samples(tracer, film, static_cast<std::uint32_t>(mine), to);
      const double seconds = stats.seconds + s.seconds;
      stats += s;
      stats.seconds = seconds;
    }
    result.end = static_cast<std::uint32_t>(std::min<std::uint64_t>(round_start + n * block, last));
    if (rank_ == 0 && progress) progress(static_cast<double>(result.end - start) / (last - start));
    // 1: some rank was interrupted; 2: rank 0 wants a checkpoint.
    int flags = (interrupted && interrupted() ? 1 : 0) | (rank_ == 0 && result.end < last && wants_checkpoint &&
                                                                  wants_checkpoint()
                                                              ? 2
                                                              : 0);
    int agreed = 0;
    check(MPI_Allreduce(&flags, &agreed, 1, MPI_INT, MPI_BOR, MPI_COMM_WORLD), "MPI_Allreduce");
    if (agreed & 1) {
      result.stopped = true;
      break;
    }
    if ((agreed & 2) != 0) reduce_and_report(result.end);
  }
  reduce_and_report(result.end);
  return result;
}

}  // namespace pathlab
