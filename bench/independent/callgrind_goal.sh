#!/bin/bash
# Instructions of one goal run inside the core's simulate (f2py entry), per build.
# usage: bench/independent/callgrind_goal.sh OUTDIR lyap|nolyap COMMIT...   (venv /work/venv/ic34_COMMIT)
out=$1; mode=$2; shift 2; mkdir -p "$out"
case=$(dirname "$0")/../cases/chaos_z24.nml
for c in "$@"; do
  py=/work/venv/ic34_$c/bin/python
  valgrind --tool=callgrind --toggle-collect=${TOGGLE:-f2py_rout__core_spline_api_api_simulate} \
      --callgrind-out-file="$out/cg.$c.$mode${TOGGLE:+.inner}" "$py" -P "$(dirname "$0")/goal_run.py" "$case" $mode \
      > "$out/cg.$c.$mode${TOGGLE:+.inner}.log" 2>&1
  echo "$c $mode: $(grep -h rhs_evals "$out/cg.$c.$mode${TOGGLE:+.inner}.log") collected $(grep -h 'Collected' "$out/cg.$c.$mode${TOGGLE:+.inner}.log" | awk '{print $NF}')"
done
