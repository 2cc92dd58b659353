// pathlab merge PART.pfilm... -o out.exr [--film merged.pfilm]
//
// Adds the partial films of one render (`render --passes A..B -o X.pfilm`,
// or checkpoints) into its image: the same bits as one process rendering
// every pass (docs/overnight.md).
#include "apps/cli/commands.h"
#include "apps/cli/validators.h"

#include "core/error.h"
#include "core/image_io.h"
#include "core/partial_film.h"

#include <cctype>
#include <ostream>

namespace pathlab::cli {

void MergeCommand::add_to(CLI::App& app) {
  CLI::App* cmd = app.add_subcommand("merge", "Merge the partial films of one render into its image");
  cmd->add_option("parts", parts, "Partial films (.pfilm) of disjoint, together contiguous sample passes")
      ->required();
  cmd->add_option("-o,--output", output, "Output EXR (a tone-mapped PNG is written beside it)")->required();
  cmd->add_option("--film", film, "Also write the merged partial film here (to merge or resume further)");
  cmd->add_option("--exposure", exposure, "Exposure of the PNG, in stops")->check(number_range(-64.0, 64.0));
  cmd->add_flag("-q,--quiet", quiet, "Print only warnings and errors");
  cmd->callback([this] { selected = true; });
}

int MergeCommand::run(std::ostream& /*out*/, std::ostream& err) const {
  const std::filesystem::path exr(output);
  if (lower_extension(exr) != ".exr") throw InputError(exr.string() + ": the output must be an .exr file (a .png is written beside it)");
  std::filesystem::path png = exr;
  png.replace_extension(".png");
  ensure_writable(exr);
  ensure_writable(png);
  if (!film.empty()) ensure_writable(film);

  std::vector<PartialFilm> films;
  std::vector<std::filesystem::path> names;
  for (const std::string& p : parts) {
    films.push_back(read_partial_film(p));
    names.emplace_back(p);
  }
  const PartialFilm merged = merge_partial_films(std::move(films), names);
  const PartialFilmInfo& info = merged.info;
  if (!film.empty()) write_partial_film(merged.film, info, film);

  const Image image = merged.film.image();
  ImageMetadata meta = {{"spp", std::to_string(info.passes.count())},
                        {"bad_samples", std::to_string(merged.film.bad_sample_count())},
                        {"version", PATHLAB_VERSION}};
  for (auto& kv : partial_film_metadata(info)) meta.push_back(std::move(kv));
  // What the render was, as its fingerprint lists it ("setting seed 7", ...).
  for (const std::string& line : info.fingerprint.lines)
    if (line.rfind("setting ", 0) == 0) {
      const std::string kv = line.substr(8);
      const std::size_t space = kv.find(' ');
      meta.emplace_back(kv.substr(0, space), space == std::string::npos ? "" : kv.substr(space + 1));
    }
  write_exr(exr, image, meta);
  write_png_beside(exr, png, image, exposure);
  if (merged.film.bad_sample_count() > 0)
    err << "pathlab: warning: " << merged.film.bad_sample_count()
        << " sample(s) had NaN, infinite or out-of-range radiance and were left out of the image\n";
  if (!quiet)
    err << "pathlab: merged " << parts.size() << " partial film(s), passes " << info.passes.begin << ".."
        << info.passes.end << ", into " << exr.string() << " and " << png.string() << "\n";
  return 0;
}

}  // namespace pathlab::cli
