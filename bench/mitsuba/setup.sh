#!/usr/bin/env bash
# Sets up what bench/mitsuba/compare.py needs. NOT part of pathlab's build or tests:
# Mitsuba 3 is a benchmark-only dependency. Idempotent: each step is skipped when it is done.
#
#   1. Debian's libllvm19 (apt-get), which Mitsuba's llvm_ad_rgb variant loads at run time
#      through DRJIT_LIBLLVM_PATH (Dr.Jit JIT-compiles its kernels with LLVM).
#   2. mitsuba==3.9.1 (which brings drjit) and numpy from PyPI, into the Python that runs
#      compare.py ($PYTHON, default python3), with --break-system-packages where pip wants it;
#      if that pip refuses, into a venv at $MITSUBA_VENV (default out/venv-mitsuba in the checkout;
#      then run compare.py with that venv's python).
#   3. Prints the DRJIT_LIBLLVM_PATH to export (compare.py sets it itself when it is unset).
#
# Usage: bash bench/mitsuba/setup.sh            (as root, or with sudo for apt-get)
set -euo pipefail

PYTHON=${PYTHON:-python3}
REPO=$(cd "$(dirname "$0")/../.." && pwd)
MITSUBA_VENV=${MITSUBA_VENV:-$REPO/out/venv-mitsuba}
MITSUBA_VERSION=3.9.1
# Debian 12 libllvm19 (1:19.1.7-3~deb12u1) ships libLLVM.so.19.1 (libLLVM-19.so links to it).
LLVM_LIB=${DRJIT_LIBLLVM_PATH:-/usr/lib/x86_64-linux-gnu/libLLVM.so.19.1}

say() { printf '[setup] %s\n' "$*"; }

if [[ -e $LLVM_LIB ]]; then
    say "libllvm19 present: $LLVM_LIB"
else
    say "installing Debian's libllvm19 (apt-get install -y libllvm19)"
    apt-get update -qq
    apt-get install -y libllvm19
fi
[[ -e $LLVM_LIB ]] || { say "error: $LLVM_LIB missing after installing libllvm19"; exit 1; }

have_mitsuba() {
    "$PYTHON" - "$MITSUBA_VERSION" <<'PY' 2>/dev/null
import sys
import numpy  # noqa: F401
import mitsuba
sys.exit(0 if mitsuba.__version__ == sys.argv[1] else 1)
PY
}

if have_mitsuba; then
    say "mitsuba $MITSUBA_VERSION and numpy already importable by $PYTHON ($(command -v "$PYTHON"))"
else
    say "installing mitsuba==$MITSUBA_VERSION and numpy with $PYTHON -m pip"
    if ! "$PYTHON" -m pip install --break-system-packages "mitsuba==$MITSUBA_VERSION" numpy; then
        say "pip refused a system install; using a venv at $MITSUBA_VENV"
        "$PYTHON" -m venv "$MITSUBA_VENV"
        PYTHON=$MITSUBA_VENV/bin/python
        "$PYTHON" -m pip install "mitsuba==$MITSUBA_VERSION" numpy
        say "run compare.py with $PYTHON (or pass --python $PYTHON)"
    fi
    have_mitsuba || { say "error: mitsuba $MITSUBA_VERSION still not importable by $PYTHON"; exit 1; }
fi

say "checking the variants scalar_rgb and llvm_ad_rgb"
DRJIT_LIBLLVM_PATH=$LLVM_LIB "$PYTHON" - <<'PY'
import drjit as dr
import mitsuba as mi
for v in ("scalar_rgb", "llvm_ad_rgb"):
    mi.set_variant(v)
    if v.startswith("llvm"):
        x = mi.Float([1.5, 2.5]) * 2  # JIT-compiles and runs a kernel through libLLVM
        dr.eval(x)
        assert list(x) == [3.0, 5.0], list(x)
    print(f"[setup] variant {v}: ok")
PY
say "done. compare.py sets DRJIT_LIBLLVM_PATH=$LLVM_LIB unless you export another."
