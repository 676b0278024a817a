#!/usr/bin/env bash
# Install everything the project needs, idempotently: Debian's FEniCSx stack, then a venv that
# sees it (--system-site-packages), then this package and its PyPI dependencies with numpy < 2.
set -euo pipefail
cd "$(dirname "$0")/.."

# libopenblas0-serial: an optimised single-threaded BLAS/LAPACK in place of the reference one
# (alternatives priority 90 > 10) for numpy, SuperLU and MUMPS; single-threaded so that 2 MPI
# ranks on 2 cores do not oversubscribe (measured gain in docs/verification.md, "Cost").
# python3-h5py-mpi: meshio's XDMF reader needs h5py; Debian's is on the HDF5 version dolfinx's is.
DEBS="python3-dolfinx-real python3-gmsh python3-meshio python3-h5py-mpi python3-scipy python3-matplotlib python3-venv python3-dev gcc libopenblas0-serial"
missing=""
for p in $DEBS; do
    dpkg -s "$p" >/dev/null 2>&1 || missing="$missing $p"
done
if [ -n "$missing" ]; then
    echo "setup: installing Debian packages:$missing"
    SUDO=""; [ "$(id -u)" -eq 0 ] || SUDO="sudo"
    $SUDO apt-get update -qq
    DEBIAN_FRONTEND=noninteractive $SUDO apt-get install -y -qq --no-install-recommends $missing >/dev/null
fi

if [ ! -x .venv/bin/python ]; then
    echo "setup: creating .venv from /usr/bin/python3 with system site packages"
    /usr/bin/python3 -m venv --system-site-packages .venv
fi

stamp=.venv/.installed
if [ ! -f "$stamp" ] || [ pyproject.toml -nt "$stamp" ] || [ constraints.txt -nt "$stamp" ]; then
    echo "setup: installing the project into .venv"
    .venv/bin/python -m pip install -q --upgrade pip >/dev/null
    .venv/bin/python -m pip install -q -c constraints.txt -e ".[dev,viz]"
    touch "$stamp"
fi

# The kernels compiled ahead of time (numba's AOT compiler): saves numba's ≈ 0.5 s load per
# process. Rebuilt when a kernel source, the machine or the environment changed; a failed
# build is not fatal (the kernels then run under numba's JIT, as before).
if ! .venv/bin/python scripts/build_kernels.py --if-stale; then
    echo "setup: WARNING: the ahead-of-time kernel build failed; kernels will use numba's JIT"
fi

# The project's bytecode, written now: a shell with PYTHONDONTWRITEBYTECODE set (as some
# containers and CI images have) never writes it, and every run would compile ≈ 70 modules
# again (≈ 60 ms per `sandwich solve`, 20 ms of them inside the solve's lazy imports). Quick
# when nothing changed (compileall skips up-to-date files).
.venv/bin/python -m compileall -q sandwich \
    >/dev/null || echo "setup: WARNING: compileall failed (runs compile on import)"
