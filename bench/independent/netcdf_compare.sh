#!/bin/bash
# Claim 3: a 70-variable sweep (physical_z24 over 4 misalignments) written by the CLI at both
# commits (wall and CPU of the whole call, alternating), then the engines warm and cold.
# usage: [CLI_ONLY=1] bench/independent/netcdf_compare.sh OUTDIR CALLS WARM_REPEATS COLD_REPEATS BEFORE AFTER
# (the CLI calls append to OUTDIR/cli_times.txt; the medians are over every call there)
out=$1; calls=$2; warm=$3; colds=$4; shift 4; mkdir -p "$out"
here=$(dirname "$0"); case=$here/../cases/physical_z24.nml
uptime
for k in $(seq 1 "$calls"); do
  for c in "$@"; do
    rm -rf "$out/sweep.$c"
    /usr/bin/time -f "$c call $k: %e s wall, %U s user, %S s sys" /work/venv/ic34_$c/bin/pyspline sweep "$case" \
        --set l_x=0:1e-4:4 --out "$out/sweep.$c" --quiet > /dev/null 2>> "$out/cli_times.txt"
  done
done
grep call "$out/cli_times.txt"
python3 - "$out/cli_times.txt" "$@" <<'PY'
import re, sys, statistics as st
lines = open(sys.argv[1]).read().splitlines()
cpu = {}
for c in sys.argv[2:]:
    rows = [list(map(float, re.findall(r"([\d.]+) s", l))) for l in lines if l.startswith(c + " call")]
    cpu[c] = [r[1] + r[2] for r in rows]
    print(f"{c}: {len(rows)} CLI calls, median wall {st.median(r[0] for r in rows):.2f} s, "
          f"median CPU (user+sys) {st.median(cpu[c]):.2f} s")
a, b = sys.argv[2:4]
d = [x - y for x, y in zip(cpu[a], cpu[b])]
print(f"{a} - {b}, calls paired in order: CPU median {st.median(d):.2f} s [{min(d):.2f} to {max(d):.2f}]")
PY
[ -n "$CLI_ONLY" ] && { uptime; exit 0; }
py=/work/venv/ic34/bin/python
for c in "$@"; do echo "sweep.nc written at $c:"; $py -P "$here/netcdf_io.py" "$out/sweep.$c/sweep.nc" "$out/io.$c" 1 | grep -E "variables|written by|bytes"; done
$py -P "$here/netcdf_io.py" "$out/sweep.$1/sweep.nc" "$out/io" "$warm"
for k in $(seq 1 "$colds"); do for e in h5netcdf netcdf4; do $py -P "$here/netcdf_io.py" "$out/sweep.$1/sweep.nc" "$out/io" cold $e; done; done > "$out/cold.jsonl"
python3 - "$out/cold.jsonl" <<'PY'
import json, sys, statistics as st
rows = [json.loads(l) for l in open(sys.argv[1])]
for e in ("h5netcdf", "netcdf4"):
    r = [x for x in rows if x["engine"] == e]
    print(f"cold {e}: {len(r)} processes, " + ", ".join(f"{k} median {st.median(x[k] for x in r):.3f} s" for k in ("write_cpu", "write_wall", "read_cpu", "read_wall")))
PY
uptime
