#!/usr/bin/env bash
# Install the toolchain (gfortran, SUNDIALS 6.4 with its Fortran 2003 modules) and the Python
# packages, then build and install pyspline (the f2py extension and the spline-dyn executable).
set -euo pipefail
cd "$(dirname "$0")/.."
need=()
for pkg in gfortran libsundials-dev libsundials-fortran-dev; do
  dpkg -s "$pkg" >/dev/null 2>&1 || need+=("$pkg")
done
if [ ${#need[@]} -gt 0 ]; then
  SUDO=""; [ "$(id -u)" -ne 0 ] && SUDO="sudo"
  $SUDO apt-get update -qq
  DEBIAN_FRONTEND=noninteractive $SUDO apt-get install -y -qq --no-install-recommends "${need[@]}"
fi
python3 -m pip install -q --disable-pip-version-check \
  "numpy>=2.0" meson meson-python ninja pytest matplotlib scipy f90nml tqdm
python3 -m pip install -q --disable-pip-version-check --no-build-isolation .
