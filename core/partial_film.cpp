#include "core/partial_film.h"

#include "core/error.h"
#include "core/json_number.h"
#include "core/limits.h"
#include "core/render.h"
#include "core/temp_files.h"

#include <nlohmann/json.hpp>
#include <xxhash.h>

#include <algorithm>
#include <array>
#include <charconv>
#include <cerrno>
#include <cinttypes>
#include <cstdio>
#include <cstring>
#include <fcntl.h>
#include <fstream>
#include <memory>
#include <unistd.h>

namespace pathlab {
namespace fs = std::filesystem;
using json = nlohmann::json;

namespace {

constexpr char kMagic[8] = {'P', 'L', 'P', 'F', 'I', 'L', 'M', '1'};
constexpr int kFormatVersion = 1;

std::string hex128(const XXH128_hash_t& h) {
  char text[33];
  std::snprintf(text, sizeof text, "%016" PRIx64 "%016" PRIx64, static_cast<std::uint64_t>(h.high64),
                static_cast<std::uint64_t>(h.low64));
  return text;
}

std::string hex64(std::uint64_t v) {
  char text[17];
  std::snprintf(text, sizeof text, "%016" PRIx64, v);
  return text;
}

// A float as C's "%a": exact, so that settings differing in the last bit differ.
std::string exact(double v) {
  char text[64];
  std::snprintf(text, sizeof text, "%a", v);
  return text;
}

// XXH3-128 of a file's content, streamed.
std::string hash_file(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw InputError(path.string() + ": cannot be read to fingerprint the render");
  const std::unique_ptr<XXH3_state_t, decltype(&XXH3_freeState)> state(XXH3_createState(), &XXH3_freeState);
  XXH3_128bits_reset(state.get());
  std::vector<char> buffer(std::size_t{1} << 20);
  while (in) {
    in.read(buffer.data(), static_cast<std::streamsize>(buffer.size()));
    XXH3_128bits_update(state.get(), buffer.data(), static_cast<std::size_t>(in.gcount()));
  }
  if (in.bad()) throw InputError(path.string() + ": read failed while fingerprinting the render");
  return hex128(XXH3_128bits_digest(state.get()));
}

const char* filter_name(FilterKind f) { return f == FilterKind::Box ? "box" : "bilinear"; }

// ----------------------------------------------------------------- writing

// A file written through a checksum: every byte written is hashed.
class HashedWriter {
 public:
  HashedWriter(const fs::path& path, const fs::path& target) : path_(path), target_(target) {
    fd_ = ::open(path.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
    if (fd_ < 0) fail("cannot create it");
    XXH3_128bits_reset(state_.get());
  }
  ~HashedWriter() {
    if (fd_ >= 0) ::close(fd_);
  }
  void write(const void* data, std::size_t n) {
    XXH3_128bits_update(state_.get(), data, n);
    const char* p = static_cast<const char*>(data);
    while (n > 0) {
      const ssize_t k = ::write(fd_, p, std::min<std::size_t>(n, std::size_t{1} << 30));
      if (k < 0 && errno == EINTR) continue;
      if (k <= 0) fail(std::strerror(errno));
      p += k;
      n -= static_cast<std::size_t>(k);
    }
  }
  void write_u64(std::uint64_t v) {
    unsigned char b[8];
    for (int i = 0; i < 8; ++i) b[i] = static_cast<unsigned char>(v >> (8 * i));
    write(b, 8);
  }
  XXH128_hash_t digest() const { return XXH3_128bits_digest(state_.get()); }
  // Flushes to the disk and closes.
  void finish() {
    if (::fsync(fd_) != 0) fail(std::string("fsync: ") + std::strerror(errno));
    if (::close(fd_) != 0) {
      fd_ = -1;
      fail(std::string("close: ") + std::strerror(errno));
    }
    fd_ = -1;
  }

 private:
  [[noreturn]] void fail(const std::string& why) const {
    throw SystemError(target_.string() + ": could not write the partial film (" + path_.filename().string() +
                      "): " + why);
  }
  fs::path path_, target_;
  int fd_ = -1;
  std::unique_ptr<XXH3_state_t, decltype(&XXH3_freeState)> state_{XXH3_createState(), &XXH3_freeState};
};

json sum_json(const Sum1& s) { return json::array({hex64(s.low()), hex64(s.high())}); }

// ----------------------------------------------------------------- reading

XXH128_hash_t hash_from_bytes(const unsigned char (&b)[16]) {
  XXH128_hash_t h;
  h.low64 = 0;
  h.high64 = 0;
  for (int i = 0; i < 8; ++i) h.low64 |= static_cast<XXH64_hash_t>(b[i]) << (8 * i);
  for (int i = 0; i < 8; ++i) h.high64 |= static_cast<XXH64_hash_t>(b[8 + i]) << (8 * i);
  return h;
}

class Reader {
 public:
  explicit Reader(const fs::path& path) : path_(path) {
    // A folder opens as a stream whose every read fails ("read failed").
    if (const std::string kind = special_file_kind(path); !kind.empty()) fail("it is " + kind + ", not a file");
    in_.open(path, std::ios::binary);
    if (!in_) fail(fs::exists(path) ? "cannot be read" : "does not exist");
    in_.seekg(0, std::ios::end);
    size_ = static_cast<std::uint64_t>(in_.tellg());
    in_.seekg(0);
    XXH3_128bits_reset(state_.get());
  }
  std::uint64_t size() const { return size_; }
  std::uint64_t position() const { return position_; }
  void read(void* data, std::size_t n) {
    if (position_ + n > size_) fail("truncated (it ends inside its data)");
    in_.read(static_cast<char*>(data), static_cast<std::streamsize>(n));
    if (!in_) fail("reading it failed at byte " + std::to_string(position_) + " (an input/output error)");
    XXH3_128bits_update(state_.get(), data, n);
    position_ += n;
  }
  std::uint64_t read_u64() {
    unsigned char b[8];
    read(b, 8);
    std::uint64_t v = 0;
    for (int i = 0; i < 8; ++i) v |= static_cast<std::uint64_t>(b[i]) << (8 * i);
    return v;
  }
  XXH128_hash_t digest() const { return XXH3_128bits_digest(state_.get()); }
  // Reads the stored checksum (not hashed).
  std::string read_checksum() {
    if (position_ + 16 != size_) fail(position_ + 16 > size_ ? "truncated (its checksum is missing)" : "has bytes after its checksum");
    unsigned char b[16];
    in_.read(reinterpret_cast<char*>(b), 16);
    if (!in_) fail("reading it failed at byte " + std::to_string(position_) + " (an input/output error)");
    return hex128(hash_from_bytes(b));
  }
  [[noreturn]] void fail(const std::string& why) const {
    throw InputError(path_.string() + ": not a usable partial film: " + why);
  }
  // A header the file's checksum vouches for was written so (by another
  // version of pathlab, or another program); one it does not is damaged,
  // which a flipped bit in its length or a digit of its resolution must
  // not pass for a truncated file.
  [[noreturn]] void header_fail(const std::string& why) const {
    if (intact()) fail(why + ": not a partial film of this pathlab version");
    fail("its header is corrupt: " + why + " (its checksum does not match its content)");
  }
  // True if a complete JSON value starts after the length field and more
  // follows it: the header is all there, so its length field is wrong.
  bool complete_json_header() const {
    std::ifstream in(path_, std::ios::binary);
    in.seekg(sizeof kMagic + 8);
    try {
      json header;
      in >> header;
    } catch (const json::exception&) {
      return false;
    }
    return in && in.peek() != std::char_traits<char>::eof();
  }

 private:
  // True if the last 16 bytes are the XXH3-128 of all before them.
  bool intact() const {
    if (size_ < 16) return false;
    std::ifstream in(path_, std::ios::binary);
    const std::unique_ptr<XXH3_state_t, decltype(&XXH3_freeState)> state(XXH3_createState(), &XXH3_freeState);
    XXH3_128bits_reset(state.get());
    std::vector<char> buffer(std::size_t{1} << 20);
    for (std::uint64_t left = size_ - 16; left > 0;) {
      const std::size_t n = static_cast<std::size_t>(std::min<std::uint64_t>(left, buffer.size()));
      if (!in.read(buffer.data(), static_cast<std::streamsize>(n))) return false;
      XXH3_128bits_update(state.get(), buffer.data(), n);
      left -= n;
    }
    unsigned char b[16];
    if (!in.read(reinterpret_cast<char*>(b), 16)) return false;
    return XXH128_isEqual(hash_from_bytes(b), XXH3_128bits_digest(state.get())) != 0;
  }

  fs::path path_;
  std::ifstream in_;
  std::uint64_t size_ = 0, position_ = 0;
  std::unique_ptr<XXH3_state_t, decltype(&XXH3_freeState)> state_{XXH3_createState(), &XXH3_freeState};
};

// A 64-bit word as the writer gives it: hex digits only (std::stoull threw
// std::invalid_argument on "zz", which is no InputError).
std::uint64_t parse_hex64(const json& j, const Reader& r, const char* key) {
  const std::string text = j.get<std::string>();
  std::uint64_t v = 0;
  const auto [end, ec] = std::from_chars(text.data(), text.data() + text.size(), v, 16);
  if (text.empty() || ec != std::errc() || end != text.data() + text.size())
    r.header_fail(std::string("its stats.") + key + " holds \"" + text.substr(0, 40) + "\", not a 64-bit hex word");
  return v;
}
Sum1 parse_sum(const json& j, const Reader& r, const char* key) {
  return Sum1::from_words(parse_hex64(j.at(0), r, key), parse_hex64(j.at(1), r, key));
}

}  // namespace

// ------------------------------------------------------------- fingerprint

Fingerprint render_fingerprint(const Scene& scene, std::string_view tracer) {
  Fingerprint f;
  f.lines.push_back(std::string("pathlab ") + PATHLAB_VERSION + " " + PATHLAB_GIT_COMMIT);
  if (scene.file.empty())
    f.lines.push_back("scene built-in " + scene.name);
  else
    f.lines.push_back("scene " + scene.file.filename().string() + " " + hash_file(scene.file));
  // By name and content: the same data in another folder (another machine's
  // data directory) is the same render.
  for (const fs::path& p : scene.input_files) f.lines.push_back("file " + p.filename().string() + " " + hash_file(p));
  const RenderSettings& r = scene.render;
  f.lines.push_back("setting tracer " + std::string(tracer));
  f.lines.push_back("setting resolution " + std::to_string(scene.film.width) + "x" + std::to_string(scene.film.height));
  f.lines.push_back(std::string("setting filter ") + filter_name(scene.film.filter));
  // Every setting that changes a sample, as the EXR header records them
  // (core/render.h: one list, so a new setting cannot be left out here).
  for (const auto& [key, value] : sample_settings(r)) f.lines.push_back("setting " + key + " " + value);
  std::string all;
  for (const std::string& line : f.lines) all += line + "\n";
  f.digest = hex128(XXH3_128bits(all.data(), all.size()));
  return f;
}

std::string fingerprint_difference(const Fingerprint& was, const Fingerprint& now, std::string_view was_name,
                                   std::string_view now_name) {
  std::string out;
  const auto missing_from = [](const std::vector<std::string>& lines, const std::vector<std::string>& other) {
    std::vector<std::string> only;
    for (const std::string& l : lines)
      if (std::find(other.begin(), other.end(), l) == other.end()) only.push_back(l);
    return only;
  };
  for (const std::string& l : missing_from(was.lines, now.lines)) out += "  " + std::string(was_name) + ": " + l + "\n";
  for (const std::string& l : missing_from(now.lines, was.lines)) out += "  " + std::string(now_name) + ": " + l + "\n";
  if (out.empty()) out = "  (the same lines in another order)\n";
  out.pop_back();  // the last line's end is the message's
  return out;
}

// ---------------------------------------------------------------- the file

void write_partial_film(const Film& film, const PartialFilmInfo& pf, const fs::path& path) {
  const Film::ConstWords words = film.words();
  json bad = json::array();
  for (const BadSample& b : film.bad_samples())
    bad.push_back({{"x", b.x}, {"y", b.y}, {"sample", b.sample}, {"L", {exact(b.L.x), exact(b.L.y), exact(b.L.z)}}});
  const json header = {
      {"format", "pathlab partial film"},
      {"format_version", kFormatVersion},
      {"pathlab_version", PATHLAB_VERSION},
      {"width", film.width()},
      {"height", film.height()},
      {"filter", filter_name(film.filter())},
      {"moments", film.keeps_variance() ? "mean_and_variance" : "mean"},
      {"passes", {pf.passes.begin, pf.passes.end}},
      {"target_spp", pf.target_spp},
      {"processes", pf.processes},
      {"resumes", pf.resumes},
      {"fingerprint", {{"digest", pf.fingerprint.digest}, {"lines", pf.fingerprint.lines}}},
      {"stats",
       {{"seconds", exact(pf.stats.seconds)},
        {"samples", pf.stats.samples},
        {"rays", pf.stats.rays},
        {"clamped_samples", pf.stats.clamped_samples},
        {"energy_total", sum_json(pf.stats.energy_total)},
        {"energy_clamped", sum_json(pf.stats.energy_clamped)}}},
      {"film_rays", film.rays_cast()},
      {"bad_sample_count", film.bad_sample_count()},
      {"bad_samples", bad},
      {"words", {words.pixels.size(), words.moments.size(), words.splat.size()}},
  };
  const std::string text = header.dump(1);

  // Beside the target, so that the rename stays within one file system.
  fs::path tmp = path;
  tmp += ".tmp-" + std::to_string(::getpid());
  // The folder only now that there is something to write (ensure_writable
  // checked it could be made); what a killed writer left (kill -9) goes, and
  // a signal removes this one (core/temp_files.h).
  const fs::path parent = path.has_parent_path() ? path.parent_path() : fs::path(".");
  if (std::error_code made; !fs::create_directories(parent, made) && made)
    throw InputError(path.string() + ": cannot write output: cannot create folder " + parent.string() + ": " +
                     made.message());
  remove_stale_temp_files(parent, path.filename().string() + ".tmp-");
  const TempFileRegistration registered(tmp);
  try {
    HashedWriter w(tmp, path);
    w.write(kMagic, sizeof kMagic);
    w.write_u64(text.size());
    w.write(text.data(), text.size());
    // The arrays as they lie in memory: x86-64 is little-endian, as the format.
    static_assert(std::endian::native == std::endian::little);
    for (const std::span<const std::uint64_t> a : {words.pixels, words.moments, words.splat})
      w.write(a.data(), a.size_bytes());
    const XXH128_hash_t h = w.digest();
    w.write_u64(h.low64);  // hashed too, unread: the reader stops hashing before it
    w.write_u64(h.high64);
    w.finish();
  } catch (...) {
    std::error_code ignored;
    fs::remove(tmp, ignored);
    throw;
  }
  std::error_code ec;
  fs::rename(tmp, path, ec);
  if (ec) {
    fs::remove(tmp, ec);
    throw SystemError(path.string() + ": could not replace it with the new partial film: " + ec.message());
  }
  // The rename itself reaches the disk with the folder's entry.
  const fs::path& folder = parent;
  if (const int dir = ::open(folder.c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC); dir >= 0) {
    ::fsync(dir);
    ::close(dir);
  }
}

PartialFilm read_partial_film(const fs::path& path) {
  Reader r(path);
  if (r.size() < sizeof kMagic + 8 + 16) r.fail(r.size() == 0 ? "the file is empty" : "too short to be one");
  char magic[sizeof kMagic];
  r.read(magic, sizeof magic);
  if (std::memcmp(magic, kMagic, sizeof kMagic) != 0) r.fail("it does not start with PLPFILM1 (not a pathlab partial film)");
  const std::uint64_t header_size = r.read_u64();
  if (header_size > r.size() - r.position()) {
    // Cut inside its header, or its length field damaged: then the whole
    // header is there, and more after it.
    if (r.complete_json_header())
      r.header_fail("its length field says " + std::to_string(header_size) + " bytes, more than the " +
                    std::to_string(r.size() - r.position()) + " after it");
    r.fail("truncated (it ends inside its header)");
  }
  std::string text(header_size, '\0');
  r.read(text.data(), text.size());
  const json h = json::parse(text, nullptr, false);
  if (h.is_discarded() || !h.is_object()) r.header_fail("it is not JSON");
  // A length a few bytes too long that took in only blanks of the film's words.
  if (!text.ends_with('}')) r.header_fail("it does not end where its length field says (" + std::to_string(header_size) + " bytes)");

  // Every count as the integer type it is kept in: a corrupted header's
  // 8.9e68 or -1 is refused here, not converted.
  const auto count = [&r]<std::integral T>(const json& v, const char* name, T) -> T {
    const std::optional<T> n = json_integer<T>(v);
    if (!n) r.header_fail(std::string(name) + " is " + v.dump() + ", not an integer from 0 to " +
                   std::to_string(std::numeric_limits<T>::max()));
    return *n;
  };
  const auto u32 = [&](const json& v, const char* name) { return count(v, name, std::uint32_t{}); };
  const auto u64 = [&](const json& v, const char* name) { return count(v, name, std::uint64_t{}); };
  try {
    if (json_integer<int>(h.at("format_version")) != kFormatVersion)
      r.header_fail("format version " + h.at("format_version").dump() + ", this pathlab reads " +
                    std::to_string(kFormatVersion));
    const std::uint32_t width = u32(h.at("width"), "its width"), height = u32(h.at("height"), "its height");
    if (width < 1 || height < 1 || width > 65536 || height > 65536)
      r.header_fail("its resolution " + std::to_string(width) + "x" + std::to_string(height) + " is out of range");
    const std::string filter = h.at("filter").get<std::string>(), moments = h.at("moments").get<std::string>();
    if ((filter != "box" && filter != "bilinear") || (moments != "mean" && moments != "mean_and_variance"))
      r.header_fail("unknown filter or moments");
    // The arrays must be in the file before a film of that size is made: a
    // corrupted resolution would otherwise allocate (and zero) up to 240 GB.
    const std::uint64_t pixels = static_cast<std::uint64_t>(width) * static_cast<std::uint64_t>(height);
    const std::uint64_t words_per_pixel = Film::kPixelWords + (moments == "mean" ? 0 : Film::kMomentWords) +
                                          (filter == "box" ? 0 : Film::kSplatWords);
    // Before the file's size is judged: a damaged resolution is no truncation.
    const json& counts = h.at("words");
    if (json_integer<std::uint64_t>(counts.at(0)) != pixels * Film::kPixelWords ||
        json_integer<std::uint64_t>(counts.at(1)) != (moments == "mean" ? 0 : pixels * Film::kMomentWords) ||
        json_integer<std::uint64_t>(counts.at(2)) != (filter == "box" ? 0 : pixels * Film::kSplatWords))
      r.header_fail("its array sizes " + counts.dump() + " do not match its resolution " + std::to_string(width) + "x" +
                    std::to_string(height) + ", filter and moments");
    if (pixels * words_per_pixel * 8 + 16 > r.size() - r.position())
      r.fail("truncated: a " + std::to_string(width) + "x" + std::to_string(height) + " film needs " +
             std::to_string(pixels * words_per_pixel * 8) + " bytes of arrays, the file has " +
             std::to_string(r.size() - r.position()) + " after its header, checksum included");
    PartialFilm result{Film(static_cast<int>(width), static_cast<int>(height), filter == "box" ? FilterKind::Box : FilterKind::Bilinear,
                            moments == "mean" ? FilmMoments::Mean : FilmMoments::MeanAndVariance),
                       {}};
    PartialFilmInfo& pf = result.info;
    pf.passes = {u32(h.at("passes").at(0), "its first pass"), u32(h.at("passes").at(1), "its pass range's end")};
    if (pf.passes.end < pf.passes.begin) r.header_fail("its pass range ends before it begins");
    pf.target_spp = u32(h.at("target_spp"), "target_spp");
    pf.processes = u32(h.at("processes"), "processes");
    pf.resumes = u32(h.at("resumes"), "resumes");
    pf.fingerprint.digest = h.at("fingerprint").at("digest").get<std::string>();
    pf.fingerprint.lines = h.at("fingerprint").at("lines").get<std::vector<std::string>>();
    const json& st = h.at("stats");
    pf.stats.seconds = std::strtod(st.at("seconds").get<std::string>().c_str(), nullptr);
    pf.stats.samples = u64(st.at("samples"), "stats.samples");
    pf.stats.rays = u64(st.at("rays"), "stats.rays");
    pf.stats.clamped_samples = u64(st.at("clamped_samples"), "stats.clamped_samples");
    pf.stats.energy_total = parse_sum(st.at("energy_total"), r, "energy_total");
    pf.stats.energy_clamped = parse_sum(st.at("energy_clamped"), r, "energy_clamped");
    std::vector<BadSample> kept;
    for (const json& b : h.at("bad_samples")) {
      const json& L = b.at("L");
      kept.push_back({u32(b.at("x"), "a bad sample's x"), u32(b.at("y"), "a bad sample's y"),
                      u32(b.at("sample"), "a bad sample's number"),
                      Spectrum(std::strtof(L.at(0).get<std::string>().c_str(), nullptr),
                               std::strtof(L.at(1).get<std::string>().c_str(), nullptr),
                               std::strtof(L.at(2).get<std::string>().c_str(), nullptr))});
    }
    result.film.restore_counts(u64(h.at("bad_sample_count"), "bad_sample_count"), u64(h.at("film_rays"), "film_rays"),
                               std::move(kept));
    const Film::Words words = result.film.words();
    for (const std::span<std::uint64_t> a : {words.pixels, words.moments, words.splat}) r.read(a.data(), a.size_bytes());
    const std::string computed = hex128(r.digest());
    if (r.read_checksum() != computed) r.fail("its checksum does not match its content (the file is corrupted)");
    return result;
  } catch (const json::exception& e) {
    r.header_fail(std::string("it is incomplete or malformed (") + e.what() + ")");
  }
}

PartialFilm merge_partial_films(std::vector<PartialFilm> parts, const std::vector<fs::path>& names) {
  if (parts.empty()) throw InputError("merge: no partial films given");
  std::vector<std::size_t> order(parts.size());
  for (std::size_t i = 0; i < order.size(); ++i) order[i] = i;
  for (std::size_t i = 1; i < parts.size(); ++i)
    if (!(parts[i].info.fingerprint == parts[0].info.fingerprint))
      throw InputError("merge: " + names[i].string() + " is not a part of the same render as " + names[0].string() +
                       ":\n" + fingerprint_difference(parts[0].info.fingerprint, parts[i].info.fingerprint,
                                                      names[0].string(), names[i].string()));
  std::stable_sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) {
    return parts[a].info.passes.begin < parts[b].info.passes.begin;
  });
  for (std::size_t k = 1; k < order.size(); ++k) {
    const PartialFilmInfo& prev = parts[order[k - 1]].info;
    const PartialFilmInfo& cur = parts[order[k]].info;
    const auto range = [](const PartialFilmInfo& p) {
      return std::to_string(p.passes.begin) + ".." + std::to_string(p.passes.end);
    };
    if (cur.passes.begin < prev.passes.end)
      throw InputError("merge: " + names[order[k]].string() + " (passes " + range(cur) + ") overlaps " +
                       names[order[k - 1]].string() + " (passes " + range(prev) + ")");
    if (cur.passes.begin > prev.passes.end)
      throw InputError("merge: passes " + std::to_string(prev.passes.end) + ".." + std::to_string(cur.passes.begin) +
                       " are missing between " + names[order[k - 1]].string() + " and " + names[order[k]].string());
  }
  PartialFilm out = std::move(parts[order[0]]);
  for (std::size_t k = 1; k < order.size(); ++k) {
    PartialFilm& p = parts[order[k]];
    if (p.film.width() != out.film.width() || p.film.height() != out.film.height() ||
        p.film.filter() != out.film.filter() || p.film.keeps_variance() != out.film.keeps_variance())
      throw InputError("merge: " + names[order[k]].string() + " holds a film of another size, filter or moments than " +
                       names[order[0]].string());
    out.film.add(p.film);
    out.info.passes.end = p.info.passes.end;
    out.info.target_spp = std::max(out.info.target_spp, p.info.target_spp);
    out.info.stats += p.info.stats;
    out.info.stats.seconds += p.info.stats.seconds;
    out.info.processes += p.info.processes;
    out.info.resumes += p.info.resumes;
  }
  out.info.stats.bad_samples = out.film.bad_sample_count();
  return out;
}

std::vector<std::pair<std::string, std::string>> partial_film_metadata(const PartialFilmInfo& pf) {
  return {{"passes", std::to_string(pf.passes.begin) + ".." + std::to_string(pf.passes.end)},
          {"passes_spp", std::to_string(pf.passes.count())},
          {"processes", std::to_string(pf.processes)},
          {"resumes", std::to_string(pf.resumes)},
          {"fingerprint", pf.fingerprint.digest}};
}

}  // namespace pathlab
