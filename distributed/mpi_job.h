// One render spread over the processes of an MPI job (`mpirun -n N pathlab
// render ...`; docs/overnight.md, "MPI"). Each rank traces its own passes
// into its own film; films are summed to rank 0 by a reduction whose
// operation is exact integer addition (the film's fixed-point sums), so the
// image has the bits of one process rendering every pass, whatever the
// number of ranks and the shape of MPI's reduction tree.
//
// Passes go out in rounds: in round j, rank r traces passes
//   start + (j N + r) B  ..  start + (j N + r + 1) B      (clipped to `last`)
// with B passes per block. After each round the ranks agree (one small
// all-reduce) whether any was interrupted and whether rank 0 wants a
// checkpoint; either makes them reduce their films. The rounds are whole, so
// a checkpoint always holds passes [.., end) without holes, and a job may
// resume from it with another number of ranks.
#pragma once

#include "core/film.h"
#include "core/render.h"
#include "core/tracer.h"

#include <cstdint>
#include <cstdlib>
#include <functional>
#include <memory>

namespace pathlab {

class MpiJob {
 public:
  // True if this process was started by mpirun / mpiexec (Open MPI's or a
  // PMI launcher's environment): only then does pathlab initialise MPI, so
  // the command line works without it.
  static bool launched_by_mpirun() {
    for (const char* v : {"OMPI_COMM_WORLD_SIZE", "PMIX_RANK", "PMI_RANK", "PMI_SIZE"})
      if (std::getenv(v) != nullptr) return true;
    return false;
  }
  // Joins the job (MPI_Init_thread, funnelled: only the calling thread
  // talks to MPI); a job of one process without MPI if not launched by
  // mpirun or built without MPI (PATHLAB_WITH_MPI=OFF). Throws SystemError
  // if MPI fails to start.
  MpiJob();
  ~MpiJob();  // MPI_Finalize
  MpiJob(const MpiJob&) = delete;
  MpiJob& operator=(const MpiJob&) = delete;

  int rank() const { return rank_; }
  int size() const { return size_; }
  bool distributed() const { return size_ > 1; }

  // After each round, on rank 0: whether to reduce and checkpoint now.
  using WantsCheckpointFn = std::function<bool()>;
  // On rank 0, after a reduction: the film summed over ranks (its to keep;
  // passes
  // [.., end) with whatever rank 0's film held before, e.g. a checkpoint it
  // resumed from) and the job's stats.
  using ReducedFn = std::function<void(std::uint32_t end, Film& sum, const RenderStats& stats)>;
  struct Result {
    std::uint32_t end = 0;  // passes [start, end) were traced by the job
    bool stopped = false;   // a rank was interrupted
    int reductions = 0;     // checkpoints and the final one
    double reduce_seconds = 0.0;       // on this rank, in the reductions (waiting for slower ranks included)
    std::uint64_t film_bytes = 0;      // one film's words, what each rank sends per reduction
  };
  // Renders passes [start, last) over the job's ranks into each rank's
  // `film` (same size, filter and moments everywhere), then reduces. The
  // last reduction (at the end or on an interrupt) is reported to `reduced`
  // like the checkpoints. Every rank must call it with the same arguments
  // but its own film; `progress` is called on rank 0 only.
  Result render(const Tracer& tracer, Film& film, std::uint32_t start, std::uint32_t last, std::uint32_t block,
                const std::function<bool()>& interrupted, const WantsCheckpointFn& wants_checkpoint,
                const ReducedFn& reduced, const ProgressFn& progress) const;

 private:
  // The film and stats of every rank summed onto rank 0 (the other ranks'
  // results are empty).
  void reduce(const Film& film, const RenderStats& stats, Film* sum, RenderStats* total) const;

  int rank_ = 0, size_ = 1;
  bool initialised_ = false;
};

}  // namespace pathlab
