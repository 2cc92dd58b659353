// One render over the ranks of an MPI job equals one process, bit for bit
// (distributed/mpi_job.h), and checkpoints move between rank counts. Runs the
// real binary under mpirun (--oversubscribe: 3 ranks on 2 cores).
#include "core/image_io.h"
#include "core/partial_film.h"
#include "tests/process_util.h"
#include "tests/temp_dir.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <string>
#include <vector>

namespace pathlab {
namespace {

namespace fs = std::filesystem;

class Mpi : public test::TempDirTest {
 protected:
  // pathlab render with the test's settings, under mpirun -n `ranks` (0: without mpirun).
  int render(int ranks, const std::string& out, std::vector<std::string> extra, const std::string& spp = "12") {
    std::vector<std::string> args{"render", "-o", (dir_ / out).string(), "--spp", spp, "--tracer", "wavefront",
                                  "--threads", "1", "-q"};
    args.insert(args.end(), extra.begin(), extra.end());
    if (std::find(extra.begin(), extra.end(), "--resolution") == extra.end())
      args.insert(args.end(), {"--resolution", "40x30"});
    if (ranks == 0) return test::run_process(PATHLAB_BINARY, args);
    std::vector<std::string> mpi{"--oversubscribe", "--allow-run-as-root", "-n", std::to_string(ranks), PATHLAB_BINARY};
    mpi.insert(mpi.end(), args.begin(), args.end());
    return test::run_process(PATHLAB_MPIEXEC, mpi);
  }
};

TEST_F(Mpi, OneTwoAndThreeRanksGiveTheBitsOfOneProcess) {
  // 256x256: a block is 4 passes (2^18 samples), so 3 ranks share 12 passes.
  const std::vector<std::string> big{"--resolution", "256x256"};
  ASSERT_EQ(render(0, "one.exr", big), 0);
  const std::vector<float> one = test::pixel_floats(dir_ / "one.exr");
  for (const int ranks : {1, 2, 3}) {
    const std::string out = "ranks" + std::to_string(ranks) + ".exr";
    const std::string ck = (dir_ / ("ranks" + std::to_string(ranks) + ".pfilm")).string();
    std::vector<std::string> args = big;
    args.insert(args.end(), {"--checkpoint", ck});
    ASSERT_EQ(render(ranks, out, args), 0) << ranks << " ranks";
    EXPECT_EQ(test::pixel_floats(dir_ / out), one) << ranks << " ranks";
    // Every pass once: a rank tracing another's passes too would leave the
    // mean alone but not the counts.
    const PartialFilm pf = read_partial_film(ck);
    EXPECT_EQ(pf.film.sample_count(0, 0), 12u);
    EXPECT_EQ(pf.film.sample_count(255, 255), 12u);
    EXPECT_EQ(pf.info.stats.samples, 12u * 256 * 256);
    ImageMetadata meta;
    read_image(dir_ / out, &meta);
    EXPECT_NE(std::find(meta.begin(), meta.end(), std::pair<std::string, std::string>("spp", "12")), meta.end());
  }
}

TEST_F(Mpi, CheckpointsMoveBetweenRankCounts) {
  ASSERT_EQ(render(0, "one.exr", {}), 0);
  const std::vector<float> one = test::pixel_floats(dir_ / "one.exr");
  const std::string ck = (dir_ / "ck.pfilm").string();
  // Passes 0..5 by 2 ranks, 5..9 by 3 resuming, 9..12 by one process.
  ASSERT_EQ(render(2, "a.exr", {"--checkpoint", ck}, "5"), 0);
  EXPECT_EQ(read_partial_film(ck).info.passes.end, 5u);
  ASSERT_EQ(render(3, "b.exr", {"--checkpoint", ck, "--resume", ck}, "9"), 0);
  EXPECT_EQ(read_partial_film(ck).info.passes.end, 9u);
  ASSERT_EQ(render(0, "c.exr", {"--checkpoint", ck, "--resume", ck}), 0);
  EXPECT_EQ(test::pixel_floats(dir_ / "c.exr"), one);
  EXPECT_EQ(read_partial_film(ck).info.resumes, 2u);
}

}  // namespace
}  // namespace pathlab
