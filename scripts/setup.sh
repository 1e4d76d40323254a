#!/usr/bin/env bash
# Installs the Debian packages jointid needs. Safe to run twice: only missing packages are installed.
set -euo pipefail
packages=(build-essential cmake pkg-config libeigen3-dev libspectra-dev libsuitesparse-dev
  libtomlplusplus-dev nlohmann-json3-dev libcli11-dev libfmt-dev libgtest-dev libgmock-dev
  libbenchmark-dev libvtk9-dev xvfb xauth
  # Python 3 (standard library only): the documentation's figures and their checks
  # (scripts/update_docs.py, tests/docs).
  python3
  # The Python module jointid (python/, docs/python.md): pybind11 for the interpreter of
  # python3-dev, numpy, pytest for its tests, matplotlib for the examples' figures.
  pybind11-dev python3-dev python3-numpy python3-pytest python3-matplotlib
  # FFTW (pkg-config fftw3): random excitation signals and Welch spectra (fem/fft.hpp).
  libfftw3-dev
  # ccache: CI's sanitized build takes the tests' objects of the plain build from it
  # (scripts/compiler_cache.sh).
  ccache
  # OpenBLAS takes over libblas.so.3 (Debian's alternatives) from the reference BLAS, which
  # CHOLMOD's supernodal factorisation otherwise runs on: 8x faster on a 10^5-DOF frame.
  libopenblas0-pthread
  # The optional distributed modal engine (jointid_fem_slepc) and its tests under mpirun -np 2:
  # PETSc with MUMPS, SLEPc, Open MPI. About 50 s to install here (issue 11).
  petsc-dev libslepc-real-dev)
missing=()
for p in "${packages[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if ((${#missing[@]})); then
  sudo_cmd=()
  [ "$(id -u)" -ne 0 ] && sudo_cmd=(sudo)
  echo "setup: installing ${missing[*]}"
  "${sudo_cmd[@]}" apt-get update -qq
  DEBIAN_FRONTEND=noninteractive "${sudo_cmd[@]}" apt-get install -y -qq --no-install-recommends "${missing[@]}"
else
  echo "setup: all packages present"
fi
