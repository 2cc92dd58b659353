// MpiJob in a build without MPI (PATHLAB_WITH_MPI=OFF): a job of one
// process. Started by mpirun, each process would render the whole image on
// its own: refused instead.
#include "distributed/mpi_job.h"

#include "core/error.h"

#include <cstdlib>

namespace pathlab {

MpiJob::MpiJob() {
  if (launched_by_mpirun())
    throw SystemError("this pathlab was built without MPI (PATHLAB_WITH_MPI=OFF); run it without mpirun");
}

MpiJob::~MpiJob() = default;

MpiJob::Result MpiJob::render(const Tracer&, Film&, std::uint32_t, std::uint32_t, std::uint32_t,
                              const std::function<bool()>&, const WantsCheckpointFn&, const ReducedFn&,
                              const ProgressFn&) const {
  throw SystemError("MpiJob::render: built without MPI");
}

}  // namespace pathlab
