#!/bin/bash
# Claim 2: bench/independent/realisations.py at two builds in alternating blocks (one process at a time).
# usage: [SERIAL=serial] bench/independent/realisations_compare.sh OUTDIR BLOCKS ROUNDS BEFORE AFTER
out=$1; blocks=$2; rounds=$3; shift 3; mkdir -p "$out"
here=$(dirname "$0"); case=$here/../cases/chaos_z24.nml
for b in $(seq 1 "$blocks"); do
  for c in "$@"; do
    /work/venv/ic34_$c/bin/python -P "$here/realisations.py" "$case" "$rounds" "$out/real.$c.$b.json" $SERIAL
  done
done
uptime
python3 "$here/summarize_realisations.py" "$out" "$@"
