// The partial film: a film's whole state for a range of sample passes, with
// the fingerprint of everything that determined it. One mechanism serves
// checkpoints (`render --checkpoint/--resume`), sample ranges (`render
// --passes A..B`) and their merge (`pathlab merge`): a pass is sample index
// k of every pixel, the film's sums are exact (core/fixed_sum.h), so films of
// disjoint passes add up to the bits of one render of them all.
//
// The file format (docs/overnight.md, "The partial film file"): an 8-byte
// magic "PLPFILM1", the length of a JSON header (little-endian u64), the
// header, the film's arrays of little-endian 64-bit words, and an XXH3-128
// checksum of everything before it. Files are written atomically: to a
// temporary file beside the target, flushed to disk, then renamed over it.
#pragma once

#include "core/film.h"
#include "core/render.h"
#include "core/scene.h"

#include <cstdint>
#include <filesystem>
#include <string>
#include <string_view>
#include <vector>

namespace pathlab {

// What determines a render's samples, line by line ("setting seed 7",
// "file meshes/bunny.ply 8f2c...", ...), and a digest of the lines. Two
// renders with the same digest draw the same samples.
struct Fingerprint {
  std::vector<std::string> lines;
  std::string digest;  // 32 hex digits: XXH3-128 of the lines
  bool operator==(const Fingerprint& o) const { return digest == o.digest; }
};

// The fingerprint of rendering `scene` (with its final render settings and
// resolution) with the tracer named `tracer`: the pathlab version, the
// content of the scene file and of every file it loads (Scene::input_files),
// and every setting that changes a sample. Not in it: spp (a partial film
// says which passes it holds), threads, wave sizes, ray modes and process
// counts (none changes a sample's bits). Throws InputError if a file cannot
// be read.
Fingerprint render_fingerprint(const Scene& scene, std::string_view tracer);

// For messages: the lines in which `was` and `now` differ, as
// "  checkpoint: setting seed 7\n  this render: setting seed 8\n".
std::string fingerprint_difference(const Fingerprint& was, const Fingerprint& now, std::string_view was_name,
                                   std::string_view now_name);

struct PassRange {
  std::uint32_t begin = 0, end = 0;  // passes [begin, end): sample indices of every pixel
  std::uint32_t count() const { return end - begin; }
};

// What a partial film says of itself besides its film.
struct PartialFilmInfo {
  PassRange passes;
  std::uint32_t target_spp = 0;  // the spp of the render it belongs to (what resume goes on to)
  Fingerprint fingerprint;
  RenderStats stats;             // samples, rays, clamping; seconds: render time summed over its pieces
  std::uint32_t processes = 1;   // partial films merged into it (a process each, or an MPI rank)
  std::uint32_t resumes = 0;     // times a render of it was resumed from a checkpoint
};

struct PartialFilm {
  Film film;
  PartialFilmInfo info;
};

// Writes `film` with `info` to `path` atomically. Throws SystemError naming
// the file.
void write_partial_film(const Film& film, const PartialFilmInfo& info, const std::filesystem::path& path);
// Reads a partial film. Throws InputError naming the file and what is wrong:
// missing, not a partial film, truncated, its checksum does not match,
// inconsistent header.
PartialFilm read_partial_film(const std::filesystem::path& path);

// Merges partial films of one render (equal fingerprints) whose passes are
// disjoint and together contiguous, in the order of their passes. Throws
// InputError naming the files if fingerprints differ (and how), if passes
// overlap or leave a gap, or if the films differ in size or moments.
PartialFilm merge_partial_films(std::vector<PartialFilm> parts, const std::vector<std::filesystem::path>& names);

// The image metadata that says what a (partial) film holds: passes, spp,
// processes, resumes, fingerprint.
std::vector<std::pair<std::string, std::string>> partial_film_metadata(const PartialFilmInfo& info);

}  // namespace pathlab
