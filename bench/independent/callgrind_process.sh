#!/bin/bash
# Instructions of a whole process (every thread) running bench/independent/goal_run.py MODE, per build,
# less the same process with MODE empty (imports, the model loaded, no run). PYTHONHASHSEED=0.
# usage: bench/independent/callgrind_process.sh OUTDIR MODE COMMIT...
out=$1; mode=$2; shift 2; mkdir -p "$out"; here=$(dirname "$0")
for c in "$@"; do
  for m in empty "$mode"; do
    PYTHONHASHSEED=0 valgrind --tool=callgrind --callgrind-out-file="$out/proc.$c.$m" \
        /work/venv/ic34_$c/bin/python -P "$here/goal_run.py" "$here/../cases/chaos_z24.nml" $m > "$out/proc.$c.$m.log" 2>&1
  done
  e=$(grep -h Collected "$out/proc.$c.empty.log" | awk '{print $NF}'); r=$(grep -h Collected "$out/proc.$c.$mode.log" | awk '{print $NF}')
  echo "$c $mode: $(grep -h rhs_evals "$out/proc.$c.$mode.log"); process $r, empty $e, difference $((r - e))"
done
