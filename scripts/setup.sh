#!/usr/bin/env bash
# Install the toolchain (gfortran, SUNDIALS 6.4 with its Fortran 2003 modules) and the Python
# packages, build an optimised CVODE and ARKODE, then build and install pyspline (the f2py extension and
# the spline-dyn executable).
#
# Why build CVODE and ARKODE: Debian 12's SUNDIALS 6.4.1 libraries are compiled without optimisation
# (debian/rules sets CMAKE_C_FLAGS=-fcommon, which replaces the -O2 of dpkg-buildflags, and
# no CMAKE_BUILD_TYPE), and CVODE's own work per step is most of a run. So this script takes
# Debian's source package of the same version (apt-get source) and builds CVODE, ARKODE (ERKStep,
# method = 'erk') and their Fortran modules optimised (C: -O3 -fno-semantic-interposition) into $PYSPLINE_SUNDIALS (~1 min,
# once; default under ~/.cache; a prefix without ARKODE, from an older setup.sh, is rebuilt). Same version, same numbers: on x86-64 without -march the
# compiler contracts no FMAs and reassociates no sums, so results are bit-identical to the
# Debian build (tests/test_build.py); a run is up to 2.4x faster at -O2, and -O3 took another
# 11 % off a paper_lx1e-4 point (docs/building.md). If the source cannot be had, pyspline is built on Debian's libraries, with a warning.
# PYSPLINE_SUNDIALS=system skips the build.
set -euo pipefail
cd "$(dirname "$0")/.."
SUDO=""; [ "$(id -u)" -ne 0 ] && SUDO="sudo"
need=()
for pkg in gfortran libsundials-dev libsundials-fortran-dev liblapack-dev libblas-dev cmake; do
  dpkg -s "$pkg" >/dev/null 2>&1 || need+=("$pkg")
done
if [ ${#need[@]} -gt 0 ]; then
  $SUDO apt-get update -qq
  DEBIAN_FRONTEND=noninteractive $SUDO apt-get install -y -qq --no-install-recommends "${need[@]}"
fi
python3 -m pip install -q --disable-pip-version-check \
  "numpy>=2.0" meson meson-python ninja pytest hypothesis matplotlib scipy f90nml tqdm \
  xarray "h5netcdf[h5py]" distributed

# Test-only cross-checks and benchmark peers (never imported by the package): ROSS (an
# independent potential-energy stiffness; 2.3 needs plotly < 6), numba + numbalsoda (the
# compiled-LSODA peer of bench/numba_peer.py), dask-jobqueue (tests/test_batch.py renders the
# SLURMCluster job script of docs/building.md).
python3 -m pip install -q --disable-pip-version-check ross-rotordynamics "plotly<6" numba numbalsoda \
  dask-jobqueue

# The source of exactly the installed version: same interface, same numbers.
version="$(dpkg-query -W -f='${Version}' libsundials-dev)"
prefix="${PYSPLINE_SUNDIALS:-${XDG_CACHE_HOME:-$HOME/.cache}/pyspline/sundials-$version-O3-arkode}"
build_sundials() {
  local work src
  work="$(mktemp -d)"
  # Debian's source package needs a deb-src entry for the same archive as the binaries.
  if ! apt-get source --download-only --print-uris sundials >/dev/null 2>&1; then
    sed -n 's/^Types: deb$/Types: deb-src/p; /^URIs:/p; /^Suites:/p; /^Components:/p; /^Signed-By:/p' \
      /etc/apt/sources.list.d/debian.sources 2>/dev/null | head -5 \
      | $SUDO tee /etc/apt/sources.list.d/pyspline-deb-src.sources >/dev/null || return 1
    $SUDO apt-get update -qq || return 1
  fi
  (cd "$work" && apt-get source --download-only -qq "sundials=$version") >/dev/null 2>&1 || return 1
  tar -xf "$work"/sundials_*.orig.tar.* -C "$work" || return 1
  src="$(ls -d "$work"/sundials-*/ | head -1)"
  cmake -S "$src" -B "$work/build" -G Ninja -DCMAKE_BUILD_TYPE=Release \
    -DCMAKE_C_FLAGS_RELEASE="-O3 -fno-semantic-interposition" -DCMAKE_Fortran_FLAGS_RELEASE=-O2 \
    -DCMAKE_Fortran_COMPILER=gfortran -DBUILD_FORTRAN_MODULE_INTERFACE=ON \
    -DBUILD_ARKODE=ON -DBUILD_CVODES=OFF -DBUILD_IDA=OFF -DBUILD_IDAS=OFF -DBUILD_KINSOL=OFF \
    -DBUILD_STATIC_LIBS=OFF -DEXAMPLES_ENABLE_C=OFF -DEXAMPLES_ENABLE_F2003=OFF \
    -DEXAMPLES_INSTALL=OFF -DCMAKE_INSTALL_PREFIX="$prefix" \
    -DCMAKE_INSTALL_RPATH="$prefix/lib" -DCMAKE_INSTALL_LIBDIR=lib >"$work/cmake.log" 2>&1 \
    && cmake --build "$work/build" -j 2 >>"$work/cmake.log" 2>&1 \
    && cmake --install "$work/build" >>"$work/cmake.log" 2>&1 \
    || { tail -20 "$work/cmake.log" >&2; return 1; }
  rm -rf "$work"
}
setup_args=()
if [ "$prefix" != "system" ]; then
  if [ ! -f "$prefix/fortran/fcvode_mod.mod" ] || [ ! -f "$prefix/fortran/farkode_erkstep_mod.mod" ]; then
    echo "setup: building optimised CVODE and ARKODE $version into $prefix (Debian's build is unoptimised)"
    build_sundials || { echo "setup: WARNING: could not build CVODE and ARKODE; using Debian's unoptimised SUNDIALS (same numbers, ~2.4x slower)" >&2; prefix=system; }
  fi
  [ "$prefix" != "system" ] && setup_args=("-Csetup-args=-Dsundials_prefix=$prefix")
fi
python3 -m pip install -q --disable-pip-version-check --no-build-isolation "${setup_args[@]}" .
