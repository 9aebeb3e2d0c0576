"""Medians [min-max] of bench/independent/realisations.py's blocks per build: python3 summarize_realisations.py DIR C1 C2."""
import glob
import json
import sys

import numpy as np

out = sys.argv[1]
for c in sys.argv[2:]:
    rows, rhs, blocks = [], None, []
    for p in sorted(glob.glob(f"{out}/real.{c}.*.json")):
        d = json.load(open(p))
        rows += d["rows"]
        rhs = d["rhs_evals"]
        blocks.append(d["rows"])
    col = {k: np.array([r[k] for r in rows]) for k in rows[0]}
    # the parts: the transient and the copies' RHS calls, at the single run's CPU per call
    # (a first version of realisations.py did not count the transient: parts then unknown)
    parts = (rhs["transient"] + rhs["real2"]) / rhs["single"] if "transient" in rhs else float("nan")
    for kind in ("real2", "real2_serial")[:1 + ("real2_serial_cpu_ms" in col)]:
        col[f"{kind}_minus_single"] = col[f"{kind}_cpu_ms"] - col["single_cpu_ms"]
        col[f"{kind}_beyond_parts"] = col[f"{kind}_cpu_ms"] - parts * col["single_cpu_ms"]
        col[f"{kind}_over_single"] = col[f"{kind}_cpu_ms"] / col["single_cpu_ms"]
    print(f"{c}: {len(rows)} rounds, RHS calls {rhs}, parts / single {parts:.4f}")
    for k, v in col.items():
        q = np.percentile(v, [0, 25, 50, 75, 100])
        print(f"  {k:24s} median {q[2]:9.3f}  quartiles {q[1]:.3f}-{q[3]:.3f}  [{q[0]:.3f}-{q[4]:.3f}]")
    block_medians = [np.median([r["real2_cpu_ms"] - parts * r["single_cpu_ms"] for r in b]) for b in blocks]
    print("  real2_beyond_parts per block (medians): " + ", ".join(f"{m:.2f}" for m in block_medians))
    block_faults = [f"{min(r['real2_minflt'] for r in b)}-{max(r['real2_minflt'] for r in b)}" for b in blocks]
    print("  real2_minflt per block (ranges): " + ", ".join(block_faults))
