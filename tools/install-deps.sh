#!/usr/bin/env bash
# Installs the Debian 12 packages pathlab builds and tests with. Used by the
# README's first command and by CI, so the two cannot drift apart.
set -euo pipefail

packages=(
  build-essential cmake ninja-build pkg-config ccache
  libembree-dev           # Embree 3.13: BVH and ray queries
  libopenimageio-dev      # OpenImageIO 2.4: EXR and PNG output
  libopenexr-dev          # OpenEXR 3.1
  libtbb-dev              # oneTBB: the parallel-for
  libglm-dev              # vector math
  libhwy-dev              # Google Highway 1.0: SIMD code written once, dispatched at run time (core/simd/)
  nlohmann-json3-dev      # scene files, JSON output
  libtinyobjloader-dev    # OBJ meshes
  libtinygltf-dev         # glTF 2.0 files (header only: core/gltf_loader.cpp)
  zlib1g-dev              # .gz meshes
  libxxhash-dev           # checksums and fingerprints of partial films (checkpoints)
  libopenmpi-dev openmpi-bin  # one render over the ranks of an MPI job (distributed/)
  libcli11-dev            # the command line
  libgtest-dev libgmock-dev  # tests
  libbenchmark-dev        # Google Benchmark: bench/
  libvtk9-dev             # path polylines as VTK PolyData (debugtools/)
  libglfw3-dev libgl-dev libimgui-dev  # the pathlab-debug GUI
  xvfb xauth              # run the GUI headless in tests
  clang                   # clang 14: the sanitizer + libFuzzer build of CI (fuzz/, tools/run-fuzzers.sh)
  libclang-rt-14-dev      # clang 14's compiler-rt: libFuzzer, ASan, UBSan and TSan runtimes
  curl ca-certificates    # tools/fetch-data.sh: test data from the npm registry
  git python3             # tools/mutate/run.py (and its ctest mutations_apply)
)

as_root=()
if [ "$(id -u)" -ne 0 ]; then as_root=(sudo); fi
export DEBIAN_FRONTEND=noninteractive
"${as_root[@]}" apt-get update -qq
"${as_root[@]}" apt-get install -y -qq --no-install-recommends "${packages[@]}" >/dev/null
echo "pathlab: Debian packages installed"
