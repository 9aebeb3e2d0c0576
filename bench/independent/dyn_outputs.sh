#!/bin/bash
# spline-dyn's CSV and summary of every shipped case (as shipped; goal = 'statistics'; the
# same with lyapunov off and realisations = 2 on 2 OpenMP threads),
# per build, then compared between two builds, every byte but the clocks (core_wall_s, wall_s)
# and the output's own path. usage: [COMPARE_ONLY=1] bench/independent/dyn_outputs.sh OUTDIR BEFORE AFTER
out=$1; shift; here=$(dirname "$0")
norm() { sed -E 's/(core_wall_s|wall_s)( \[s\])?[= ]+[^ ]+//g; s#'"$out"'/[^/]+/##g' "$1"; }
[ -n "$COMPARE_ONLY" ] || for c in "$@"; do
  d=$out/$c; mkdir -p "$d"
  for f in "$here"/../cases/*.nml; do
    n=$(basename "$f" .nml); [ "$n" = template ] && continue
    /work/venv/ic34_$c/bin/spline-dyn "$f" -o "$d/$n.csv" --summary "$d/$n.summary" > "$d/$n.log" 2>&1; echo "exit $?" >> "$d/$n.log"
    /work/venv/ic34_$c/bin/spline-dyn "$f" --set "goal='statistics'" -o "$d/$n.stat.csv" --summary "$d/$n.stat.summary" > "$d/$n.stat.log" 2>&1; echo "exit $?" >> "$d/$n.stat.log"
    OMP_NUM_THREADS=2 /work/venv/ic34_$c/bin/spline-dyn "$f" --set "goal='statistics'" --set lyapunov=.false. --set realisations=2 \
        -o "$d/$n.real2.csv" --summary "$d/$n.real2.summary" > "$d/$n.real2.log" 2>&1; echo "exit $?" >> "$d/$n.real2.log"
  done
done
a=$out/$1; b=$out/$2; nd=0; nf=0
for p in "$a"/*; do
  f=$(basename "$p"); nf=$((nf + 1))
  if ! cmp -s <(norm "$p") <(norm "$b/$f"); then
    echo "differs: $f"; nd=$((nd + 1))
  fi
done
echo "$nf files compared ($(ls "$a"/*.csv | wc -l) CSVs), $nd differ"
