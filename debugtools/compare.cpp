#include "debugtools/compare.h"

#include "analytic-scenes/check.h"
#include "core/error.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <limits>
#include <tuple>
#include <fstream>

namespace pathlab {

bool same_sample(const FilmSample& a, const FilmSample& b) {
  for (int c = 0; c < 3; ++c)
    if (!(std::abs(a.L[c] - b.L[c]) <=
          kSameSampleTolerance * std::max(std::abs(a.L[c]), std::abs(b.L[c])) + kSameSampleAbsolute))
      return false;
  return a.hits == b.hits && a.rays == b.rays;
}

void SampleComparer::add_batch(std::span<const FilmSample> a, std::span<const FilmSample> b, std::uint32_t count,
                               std::uint32_t first) {
  if (a.size() != b.size()) throw InputError("compare: the two sides hold different numbers of samples");
  samples_ += a.size();
  for (std::size_t i = 0; i < a.size(); ++i) {
    if (same_sample(a[i], b[i])) {
      ++equal_;
      continue;
    }
    SampleDisagreement d;
    d.x = static_cast<std::uint32_t>((i / count) % static_cast<std::size_t>(width_));
    d.y = static_cast<std::uint32_t>((i / count) / static_cast<std::size_t>(width_));
    d.sample = first + static_cast<std::uint32_t>(i % count);
    d.a = a[i];
    d.b = b[i];
    differing_.push_back(d);
    if (differing_.size() >= 2 * keep_) trim(keep_);
  }
}

void SampleComparer::trim(std::size_t n) {
  std::sort(differing_.begin(), differing_.end(), [](const SampleDisagreement& p, const SampleDisagreement& q) {
    return std::tie(p.y, p.x, p.sample) < std::tie(q.y, q.x, q.sample);
  });
  if (differing_.size() > n) differing_.resize(n);
}

SampleComparison SampleComparer::finish(const ReplayFn& replay) {
  SampleComparison r;
  r.samples = samples_;
  r.equal = equal_;
  trim(keep_);
  const std::vector<SampleDisagreement>& order = differing_;
  // Few enough to agree: replay them all (each must be explained). Else the
  // verdict is made; the first one says where to look.
  const bool few = static_cast<double>(r.equal) >= kSameSeedShare * static_cast<double>(r.samples);
  const std::size_t replays = few ? order.size() : std::min<std::size_t>(1, order.size());
  for (std::size_t k = 0; k < replays; ++k) {
    SampleDisagreement d = order[k];
    d.divergence = replay(d.x, d.y, d.sample);
    if (!d.divergence.rounding) ++r.unexplained;
    r.replayed.push_back(std::move(d));
  }
  return r;
}

SampleComparison compare_samples(std::span<const FilmSample> a, std::span<const FilmSample> b, int width,
                                 std::uint32_t count, std::uint32_t first, const ReplayFn& replay) {
  SampleComparer c(width, a.size());
  c.add_batch(a, b, count, first);
  return c.finish(replay);
}

PathDivergence replay_divergence(const Tracer& a, const Tracer& b, std::uint32_t x, std::uint32_t y,
                                 std::uint32_t sample, float tolerance) {
  PathRecorder ra, rb;
  a.trace_sample(x, y, sample, &ra);
  b.trace_sample(x, y, sample, &rb);
  return first_divergence(ra.events(), rb.events(), tolerance);
}

SampleComparison compare_tracers(const Tracer& a, const Tracer& b, std::uint32_t spp) {
  const FilmDesc& film = a.scene().scene().film;
  const std::size_t pixels = static_cast<std::size_t>(film.width) * static_cast<std::size_t>(film.height);
  const auto per_batch = static_cast<std::uint32_t>(std::clamp<std::size_t>((std::size_t{1} << 20) / pixels, 1, spp));
  SampleComparer c(film.width, pixels * spp);
  std::vector<FilmSample> sa, sb;
  for (std::uint32_t first = 0; first < spp; first += per_batch) {
    const std::uint32_t count = std::min(per_batch, spp - first);
    sa.resize(pixels * count);
    sb.resize(pixels * count);
    a.render_batch(first, count, sa);
    b.render_batch(first, count, sb);
    c.add_batch(sa, sb, count, first);
  }
  return c.finish([&](std::uint32_t x, std::uint32_t y, std::uint32_t s) { return replay_divergence(a, b, x, y, s); });
}

BounceAccumulator render_bounces(const Tracer& tracer, std::uint32_t spp) {
  const FilmDesc& film = tracer.scene().scene().film;
  BounceAccumulator acc(film.width, film.height);
  const BounceTracer bt(tracer, acc);
  const std::size_t pixels = static_cast<std::size_t>(film.width) * static_cast<std::size_t>(film.height);
  const auto per_batch = static_cast<std::uint32_t>(std::clamp<std::size_t>((std::size_t{1} << 20) / pixels, 1, spp));
  std::vector<FilmSample> out;
  for (std::uint32_t first = 0; first < spp; first += per_batch) {
    const std::uint32_t count = std::min(per_batch, spp - first);
    out.resize(pixels * count);
    bt.render_batch(first, count, out);
  }
  return acc;
}

namespace {
// The largest of `var`'s values over the 3x3 neighbourhood of (x, y), channel c.
double neighbourhood_max(const Image& var, int x, int y, int c) {
  double v = 0.0;
  for (int ny = std::max(0, y - 1); ny <= std::min(var.height - 1, y + 1); ++ny)
    for (int nx = std::max(0, x - 1); nx <= std::min(var.width - 1, x + 1); ++nx)
      v = std::max(v, static_cast<double>(var.at(nx, ny)[c]));
  return v;
}
double sidak(double alpha, double m) { return -std::expm1(std::log1p(-alpha) / m); }
}  // namespace

BounceComparison compare_bounces(const BounceAccumulator& a, const BounceAccumulator& b, double alpha) {
  if (a.width() != b.width() || a.height() != b.height())
    throw InputError("compare: the per-bounce images have different sizes");
  constexpr double kRelFloor = 1e-5, kAbsFloor = 1e-7;  // float rounding, as check.cpp
  const int w = a.width(), h = a.height();
  const double pixels = static_cast<double>(w) * h;
  const double layer_tests = static_cast<double>(kBounceLayers) * kTechniques * 3.0;
  BounceComparison r;
  r.alpha = alpha;
  r.pixel_threshold = normal_two_sided_quantile(sidak(alpha, layer_tests * pixels));
  r.image_threshold = normal_two_sided_quantile(sidak(alpha, layer_tests));
  for (int d = 0; d < kBounceLayers; ++d)
    for (Technique t : {Technique::Bsdf, Technique::Nee}) {
      BounceComparison::Layer& L = r.layers[static_cast<std::size_t>(d)][static_cast<std::size_t>(t)];
      const Image ma = a.mean(d, t), mb = b.mean(d, t), va = a.variance_of_mean(d, t), vb = b.variance_of_mean(d, t);
      L.worst_pixel = {d, t, 0, 0, 0, 0.0, 0.0, 0.0};
      L.image = {d, t, -1, -1, 0, 0.0, 0.0, 0.0};
      for (int c = 0; c < 3; ++c) {
        double sum_d = 0.0, sum_var = 0.0, sum_a = 0.0, sum_b = 0.0;
        for (int y = 0; y < h; ++y)
          for (int x = 0; x < w; ++x) {
            const double xa = ma.at(x, y)[c], xb = mb.at(x, y)[c];
            const double floor = kRelFloor * std::max(std::abs(xa), std::abs(xb)) + kAbsFloor;
            const double var = neighbourhood_max(va, x, y, c) + neighbourhood_max(vb, x, y, c) + floor * floor;
            const double z = (xa - xb) / std::sqrt(var);
            if (std::abs(z) > r.pixel_threshold) ++L.failing_pixels;
            if ((c == 0 && x == 0 && y == 0) || std::abs(z) > std::abs(L.worst_pixel.z)) L.worst_pixel = {d, t, x, y, c, z, xa, xb};
            sum_d += xa - xb;
            sum_var += var;
            sum_a += xa;
            sum_b += xb;
          }
        const double z = (sum_d / pixels) / (std::sqrt(sum_var) / pixels);
        if (c == 0 || std::abs(z) > std::abs(L.image.z)) L.image = {d, t, -1, -1, c, z, sum_a / pixels, sum_b / pixels};
      }
      L.disagree = L.failing_pixels > 0 || std::abs(L.image.z) > r.image_threshold;
      if (L.disagree && r.first_depth < 0) r.first_depth = d;
    }
  return r;
}

// --- the export file ------------------------------------------------------

namespace {
constexpr char kMagic[8] = {'P', 'L', 'S', 'A', 'M', 'P', 'L', '1'};

template <typename T>
void put(std::ofstream& out, const T& v) {
  out.write(reinterpret_cast<const char*>(&v), sizeof v);
}

struct Reader {
  std::ifstream in;
  const std::string& file;
  template <typename T>
  T get(const char* what) {
    T v{};
    if (!in.read(reinterpret_cast<char*>(&v), sizeof v))
      throw InputError(file + ": truncated (reading " + what + "); not a whole `pathlab compare --export` file");
    return v;
  }
};
}  // namespace

void write_sample_export(const std::string& file, const SampleExport& e) {
  const std::string tmp = file + ".part";
  {
    std::ofstream out(tmp, std::ios::binary | std::ios::trunc);
    if (!out) throw SystemError(file + ": cannot write");
    out.write(kMagic, sizeof kMagic);
    put(out, static_cast<std::uint32_t>(e.tracer.size()));
    out.write(e.tracer.data(), static_cast<std::streamsize>(e.tracer.size()));
    put(out, static_cast<std::int32_t>(e.width));
    put(out, static_cast<std::int32_t>(e.height));
    put(out, e.spp);
    put(out, e.seed);
    for (const FilmSample& s : e.samples) {
      put(out, s.film.x), put(out, s.film.y);
      put(out, s.L.x), put(out, s.L.y), put(out, s.L.z);
      put(out, s.rays), put(out, s.hits);
    }
    const std::size_t pixels = static_cast<std::size_t>(e.width) * static_cast<std::size_t>(e.height);
    for (std::size_t p = 0; p < pixels; ++p) {
      put(out, e.bounces.samples(p));
      for (int d = 0; d < kBounceLayers; ++d)
        for (Technique t : {Technique::Bsdf, Technique::Nee}) {
          const BounceAccumulator::Sums& s = e.bounces.sums(p, d, t);
          for (int c = 0; c < 3; ++c) put(out, s.sum[c]);
          for (int c = 0; c < 3; ++c) put(out, s.sum_sq[c]);
        }
    }
    if (!out.flush()) throw SystemError(file + ": write failed");
  }
  std::error_code ec;
  std::filesystem::rename(tmp, file, ec);
  if (ec) throw SystemError(file + ": cannot write: " + ec.message());
}

SampleExport read_sample_export(const std::string& file) {
  Reader r{std::ifstream(file, std::ios::binary), file};
  if (!r.in) throw InputError(file + ": cannot open");
  char magic[8] = {};
  if (!r.in.read(magic, sizeof magic) || std::memcmp(magic, kMagic, sizeof magic) != 0)
    throw InputError(file + ": not a `pathlab compare --export` file (version 1)");
  SampleExport e;
  const auto name_length = r.get<std::uint32_t>("the tracer's name");
  if (name_length > 64) throw InputError(file + ": byte 8: a tracer name of " + std::to_string(name_length) + " bytes");
  e.tracer.resize(name_length);
  if (!r.in.read(e.tracer.data(), name_length)) throw InputError(file + ": truncated (reading the tracer's name)");
  e.width = r.get<std::int32_t>("the width");
  e.height = r.get<std::int32_t>("the height");
  e.spp = r.get<std::uint32_t>("spp");
  e.seed = r.get<std::uint64_t>("the seed");
  if (e.width < 1 || e.height < 1 || e.width > 65536 || e.height > 65536 || e.spp < 1 || e.spp > (1u << 24))
    throw InputError(file + ": header: a " + std::to_string(e.width) + "x" + std::to_string(e.height) + " film at " +
                     std::to_string(e.spp) + " spp is out of range");
  const std::size_t pixels = static_cast<std::size_t>(e.width) * static_cast<std::size_t>(e.height);
  e.samples.resize(pixels * e.spp);
  for (FilmSample& s : e.samples) {
    s.film.x = r.get<float>("a sample"), s.film.y = r.get<float>("a sample");
    s.L.x = r.get<float>("a sample"), s.L.y = r.get<float>("a sample"), s.L.z = r.get<float>("a sample");
    s.rays = r.get<std::uint32_t>("a sample"), s.hits = r.get<std::uint32_t>("a sample");
  }
  e.bounces = BounceAccumulator(e.width, e.height);
  for (std::size_t p = 0; p < pixels; ++p) {
    const auto n = r.get<std::uint64_t>("the per-bounce sums");
    for (int d = 0; d < kBounceLayers; ++d)
      for (Technique t : {Technique::Bsdf, Technique::Nee}) {
        BounceAccumulator::Sums s;
        for (int c = 0; c < 3; ++c) s.sum[c] = r.get<double>("the per-bounce sums");
        for (int c = 0; c < 3; ++c) s.sum_sq[c] = r.get<double>("the per-bounce sums");
        e.bounces.set(p, n, d, t, s);
      }
  }
  if (r.in.peek() != std::char_traits<char>::eof()) throw InputError(file + ": bytes after the end of the data");
  return e;
}

}  // namespace pathlab
