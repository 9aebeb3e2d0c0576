#!/usr/bin/env bash
# Set up a Debian 12 machine for pyspline and install it: the toolchain (gfortran, cmake, reference
# LAPACK), an optimised CVODE and ARKODE built from Debian's SUNDIALS source package, the Python
# packages, then pyspline itself (the f2py extension and the spline-dyn executable).
# `--tests` adds what only the tests use: pytest, pytest-xdist, hypothesis, f90nml, the
# cross-checks and peers (ROSS, numba, numbalsoda, dask-jobqueue) and Debian's CVODE and ARKODE
# runtime libraries (tests/test_build.py: the optimised build gives Debian's numbers bit for bit),
# and compiles the numba peer's right-hand sides into numba's cache (bench/__pycache__) and, where
# pip did not byte-compile, the modules the tests' collection imports.
# One line per step; each step's output goes to $log, whose tail is printed if a step fails.
#
# Why build CVODE and ARKODE: Debian 12's SUNDIALS 6.4.1 libraries are compiled without
# optimisation (debian/rules' CMAKE_C_FLAGS=-fcommon replaces dpkg-buildflags' -O2), and CVODE's
# own work per step is most of a run. The source of the same version builds optimised (C: -O3
# -fno-semantic-interposition) into $PYSPLINE_SUNDIALS (default under ~/.cache; once): same
# version, same numbers, up to 2.4x faster (docs/building.md). Only if the source cannot be had,
# Debian's libsundials-dev and libsundials-fortran-dev (with their MPI/PETSc chain) are installed
# and pyspline is built on them, with a warning. PYSPLINE_SUNDIALS=system takes that route.
set -euo pipefail
cd "$(dirname "$0")/.."
tests=0; [ "${1:-}" = "--tests" ] && tests=1
SUDO=""; [ "$(id -u)" -ne 0 ] && SUDO="sudo"
log="$(mktemp -t pyspline-setup.XXXXXX.log)"
step() {   # step "what" command...: one line with its wall and CPU seconds, the output in $log
  local what="$1" t0=$SECONDS; shift
  printf 'setup: %s ... ' "$what"
  if ("$@" >>"$log" 2>&1; rc=$?; times >"$log.cpu"; exit $rc); then
    echo "done ($((SECONDS - t0)) s, $(cpu_of "$log.cpu") s of CPU)"
  else echo "FAILED (the last lines of $log:)"; tail -20 "$log" >&2; return 1; fi
}
cpu_of() {   # the CPU seconds (user + sys of the processes waited for) in the output of `times`
  awk 'NR == 2 {gsub(/[ms]/, " "); printf "%.0f", $1 * 60 + $2 + $3 * 60 + $4}' "$1"
}
# background "what" name command...: starts a step in the background (a line saying so), its
# output in $log.name; finish name: waits for it, then its line as step's (its wall time counted
# from its start)
declare -A bg_pid bg_t0 bg_what
background() {
  local name="$2"; bg_what[$name]="$1"; bg_t0[$name]=$SECONDS; shift 2
  echo "setup: ${bg_what[$name]} ... in the background"
  ("$@" >"$log.$name" 2>&1; rc=$?; times >"$log.$name.cpu"; exit $rc) &
  bg_pid[$name]=$!
}
finish() {
  local name="$1"
  [ -n "${bg_pid[$name]:-}" ] || return 0
  printf 'setup: %s ... ' "${bg_what[$name]}"
  if wait "${bg_pid[$name]}"; then
    echo "done ($((SECONDS - bg_t0[$name])) s, $(cpu_of "$log.$name.cpu") s of CPU, in the background)"
    cat "$log.$name" >>"$log"; rm -f "$log.$name" "$log.$name.cpu"; unset "bg_pid[$name]"
  else
    echo "FAILED (the last lines of $log.$name:)"; tail -20 "$log.$name" >&2; unset "bg_pid[$name]"
    return 1
  fi
}
# a failed step stops the script once the steps still in the background have ended
trap wait EXIT
apt_install() {
  DEBIAN_FRONTEND=noninteractive $SUDO apt-get install -y -qq --no-install-recommends "$@"
}
# Byte-compiling every module pip installs is most of its CPU time (43 of 56 s); without it the
# first import compiles what it uses (6 s for `pyspline reproduce`) and keeps it, unless
# PYTHONDONTWRITEBYTECODE is set: then every process would compile its imports anew.
pip_opts=(); [ -z "${PYTHONDONTWRITEBYTECODE:-}" ] && pip_opts=(--no-compile)
# Debian's own python3 refuses pip outside a venv (PEP 668, "externally-managed-environment"):
# the README's commands need pyspline and pytest on PATH afterwards, so outside a venv they go
# into /usr/local (root; ~/.local otherwise), with pip's --break-system-packages. In a venv
# (activated before setup.sh) or another Python (pyenv, conda) they go where pip puts them.
managed() {
  python3 -c 'import os, sys, sysconfig
sys.exit(sys.prefix != sys.base_prefix
         or not os.path.exists(os.path.join(sysconfig.get_path("stdlib"), "EXTERNALLY-MANAGED")))'
}
if managed; then
  pip_opts+=(--break-system-packages)
  echo "setup: $(command -v python3) is externally managed (PEP 668): pip installs outside a venv" \
    "into $([ "$(id -u)" -eq 0 ] && echo /usr/local || echo "~/.local") (activate a venv first to avoid it)"
fi
pip_install() { python3 -m pip install -q --disable-pip-version-check "${pip_opts[@]}" "$@"; }
# The Python packages need nothing from apt: pip fetches and installs them while apt installs the
# toolchain and SUNDIALS builds (network and disk against CPU). ninja is meson's.
background "pip: build tools and pyspline's packages" pip pip_install "numpy>=2.0" meson \
  meson-python ninja matplotlib scipy tqdm xarray netCDF4 distributed

need=(); update=0
pkgs=(gfortran cmake liblapack-dev libblas-dev)
# the headers of Debian's python3 for the extension (a new Debian has none), xz for SUNDIALS' source
python3 -c 'import os, sys, sysconfig
sys.exit(not os.path.exists(os.path.join(sysconfig.get_path("include"), "Python.h")))' \
  || pkgs+=(python3-dev)
[ "${PYSPLINE_SUNDIALS:-}" = system ] || pkgs+=(xz-utils)
[ $tests = 1 ] && pkgs+=(libsundials-cvode6 libsundials-arkode5)
for pkg in "${pkgs[@]}"; do dpkg -s "$pkg" >/dev/null 2>&1 || need+=("$pkg"); done

prefix="${PYSPLINE_SUNDIALS:-}"
built() { [ -f "$1/fortran/fcvode_mod.mod" ] && [ -f "$1/fortran/farkode_erkstep_mod.mod" ]; }
add_deb_src() {   # Debian's source package needs a deb-src entry for the binaries' archive
  apt-get source --download-only --print-uris sundials >/dev/null 2>&1 && return 0
  sed -n 's/^Types: deb$/Types: deb-src/p; /^URIs:/p; /^Suites:/p; /^Components:/p; /^Signed-By:/p' \
    /etc/apt/sources.list.d/debian.sources 2>/dev/null | head -5 \
    | $SUDO tee /etc/apt/sources.list.d/pyspline-deb-src.sources >/dev/null
  [ -s /etc/apt/sources.list.d/pyspline-deb-src.sources ] && return 0
  $SUDO rm -f /etc/apt/sources.list.d/pyspline-deb-src.sources   # one-line format (debootstrap's)
  sed -n 's/^deb \(.*\)/deb-src \1/p' /etc/apt/sources.list 2>/dev/null \
    | $SUDO tee /etc/apt/sources.list.d/pyspline-deb-src.list >/dev/null
}
sundials_version() {   # the installed libsundials-dev's, else the archive's
  dpkg-query -W -f='${Version}' libsundials-dev 2>/dev/null \
    || apt-cache show --no-all-versions libsundials-dev 2>/dev/null | sed -n 's/^Version: //p'
}
cache="${XDG_CACHE_HOME:-$HOME/.cache}/pyspline"
version="$(sundials_version || true)"
if [ "$prefix" != system ] && { [ -z "$version" ] || ! built "${prefix:-$cache/sundials-$version-O3-arkode}"; }; then
  add_deb_src || true
  update=1   # the package lists, with the deb-src entry
  dpkg -s ninja-build >/dev/null 2>&1 || need+=(ninja-build)   # SUNDIALS' build (pip's is later)
fi
updated=0
apt_update() { [ $updated = 1 ] || step "apt-get update" $SUDO apt-get update -qq; updated=1; }
if [ $update = 1 ] || [ ${#need[@]} -gt 0 ]; then
  apt_update
  version="$(sundials_version)"
fi
[ -z "$prefix" ] && prefix="$cache/sundials-$version-O3-arkode"
# SUNDIALS' source is fetched while apt installs the toolchain, then built (`build_sundials`)
work=""
if [ "$prefix" != system ] && ! built "$prefix"; then
  work="$(mktemp -d)"
  background "apt-get source sundials=$version" source \
    sh -c 'cd "$1" && apt-get source --download-only -qq "sundials=$2"' _ "$work" "$version"
fi
if [ ${#need[@]} -gt 0 ]; then step "apt-get install ${need[*]}" apt_install "${need[@]}"; fi

build_sundials() {
  local src
  tar -xf "$work"/sundials_*.orig.tar.* -C "$work" || return 1
  src="$(ls -d "$work"/sundials-*/ | head -1)"
  cmake -S "$src" -B "$work/build" -G Ninja -DCMAKE_BUILD_TYPE=Release \
    -DCMAKE_C_FLAGS_RELEASE="-O3 -fno-semantic-interposition" -DCMAKE_Fortran_FLAGS_RELEASE=-O2 \
    -DCMAKE_Fortran_COMPILER=gfortran -DBUILD_FORTRAN_MODULE_INTERFACE=ON \
    -DBUILD_ARKODE=ON -DBUILD_CVODES=OFF -DBUILD_IDA=OFF -DBUILD_IDAS=OFF -DBUILD_KINSOL=OFF \
    -DBUILD_STATIC_LIBS=OFF -DEXAMPLES_ENABLE_C=OFF -DEXAMPLES_ENABLE_F2003=OFF \
    -DEXAMPLES_INSTALL=OFF -DCMAKE_INSTALL_PREFIX="$prefix" \
    -DCMAKE_INSTALL_RPATH="$prefix/lib" -DCMAKE_INSTALL_LIBDIR=lib \
    && cmake --build "$work/build" -j 2 && cmake --install "$work/build" || return 1
}
if [ -n "$work" ]; then
  if ! finish source \
      || ! step "building optimised CVODE and ARKODE $version into $prefix" build_sundials; then
    echo "setup: WARNING: could not build CVODE and ARKODE; using Debian's unoptimised SUNDIALS (same numbers, ~2.4x slower)" >&2
    prefix=system
  fi
  rm -rf "$work"
fi
setup_args=()
if [ "$prefix" = system ]; then
  if ! dpkg -s libsundials-fortran-dev >/dev/null 2>&1; then
    apt_update
    step "apt-get install Debian's SUNDIALS" apt_install libsundials-dev libsundials-fortran-dev
  fi
else
  # the long form: Debian 12's pip 23.0.1 has no -C
  setup_args=("--config-settings=setup-args=-Dsundials_prefix=$prefix")
fi
finish pip
if [ $tests = 1 ]; then
  # ROSS 2.3 needs plotly < 6; under pytest 9.2 pytest-xdist 3.8's --dist loadgroup stops
  # grouping (pytest-xdist issue 1386): every shared fixture would run on both workers
  step "pip: test packages" pip_install "pytest<9.2" pytest-xdist hypothesis f90nml \
    ross-rotordynamics "plotly<6" numba numbalsoda dask-jobqueue
fi
step "pip install . (pyspline)" pip_install --no-build-isolation "${setup_args[@]}" .
if [ $tests = 1 ]; then
  # numba compiles the peer's right-hand sides (bench/numba_peer.py) into its cache next to them,
  # bench/__pycache__, once here, where each test worker would compile them (6 s of CPU each)
  step "numba: the peer's compiled RHS" python3 -c \
    'import sys; sys.path.insert(0, "bench"); import numba_peer; numba_peer.compile_all()'
  # Without pip's byte-compiling (pip_opts) each test worker compiles every module the tests'
  # collection imports (xarray, pandas, matplotlib, scipy, hypothesis, numba, pyspline) and
  # rewrites the test modules' asserts: 19 s of CPU per worker at the start of the tests, 4 s
  # once compiled. The collection once here keeps both in __pycache__ (tests/__pycache__).
  if [ -z "${PYTHONDONTWRITEBYTECODE:-}" ]; then
    step "pytest: the tests' imports compiled" python3 -P -m pytest -q --collect-only \
      -p no:cacheprovider tests
  fi
fi
rm -f "$log" "$log".*
