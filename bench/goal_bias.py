"""Is `goal = 'statistics'` biased on chaos_z24 (issue 34)? A measurement, not part of the race.

    python bench/goal_bias.py run --n 30 --out DIR       # in each build's venv: DIR/<build>.json
    python bench/goal_bias.py report DIR/*.json          # the table of every build's file

`run` takes realisations k = 0..n-1 of chaos_z24 as shipped (0.3 s engagement, 0.5 s sampled,
lyapunov off; realisation k starts D1 k 1e-9 m off, bench/race.py's _realisation, so k < 7 are
the race's seven) in four settings: the goal (`goal = 'statistics'`: ERK Cash-Karp without
roots at rtol 1e-2, atol 1e-4, its transient at 3e-2, 3e-4), the same set by case fields (so its
transient runs at 1e-2 too), its next tighter rung (rtol 3e-3, atol 3e-5, transient as well)
and the race's reference (BDF + roots, rtol 1e-10). Per run the race's statistics (race.statistics_of: T_m RMS and k_v's 5, 50, 95 %
quantiles, means over the revolutions), written after each realisation.

`report`, per build, setting and statistic against the reference of the same build: the means
over the realisations, their standard errors (spread between realisations / sqrt(n)), Welch's
z, the relative bias (setting - reference) / reference with its 95 % interval (Welch's t
quantile; the reference mean in the denominator taken as exact), and the variance ratio; the
race's z on realisations 0..6 alone, and how often the race's 7-against-7 test fails on subsets
drawn from the n (as measured, and with the goal's mean shifted onto the reference's); and the
builds' references and goals against each other, and both builds pooled.
"""
from __future__ import annotations

import argparse
import json
import sys
import warnings
from pathlib import Path

import numpy as np
from scipy import stats

sys.path.insert(0, str(Path(__file__).resolve().parent))
import race  # noqa: E402  (bench/race.py: the scene, realisations, reference and statistics)

NAMES = ("T_m RMS", "k_v 5 %", "k_v 50 %", "k_v 95 %")
SETTINGS = {"goal": dict(goal="statistics"),
            "erk_ck_1e-2": dict(method="erk", erk_table="cash_karp", roots=False, rtol=1e-2,
                                atol=1e-4),
            "erk_ck_3e-3": dict(method="erk", erk_table="cash_karp", roots=False, rtol=3e-3,
                                atol=3e-5)}
RACE_N = 7


def run(n, out):
    from pyspline import simulate
    from pyspline._build_info import BUILD
    case = race._case("chaos_z24", dict(lyapunov=False), False)
    path = Path(out) / f"{BUILD.split(',')[0].split(' ')[0]}.json"
    path.parent.mkdir(parents=True, exist_ok=True)
    recs = json.loads(path.read_text())["runs"] if path.exists() else []
    done = {(r["setting"], r["k"]) for r in recs}
    for k in range(n):
        real = race._realisation(case, k)
        for name, kw in [*SETTINGS.items(), ("reference", None)]:
            if (name, k) in done:
                continue
            res = simulate(real.replace(**kw)) if kw else race._reference(real, 1e-10)
            mean, se = race.statistics_of(case, res.t, res.Tm)
            recs.append(dict(setting=name, k=k, stats=mean.tolist(), batch_se=se.tolist(),
                             rhs=res.stats["rhs_evals"]))
        path.write_text(json.dumps(dict(build=BUILD, runs=recs), indent=0))
        print(f"{path.name}: realisation {k} done", flush=True)


def welch(a, b):
    """Means, standard errors, z, relative bias with its 95 % interval, variance ratio of samples
    a (a setting) and b (the reference)."""
    ma, mb = a.mean(), b.mean()
    va, vb = a.var(ddof=1) / len(a), b.var(ddof=1) / len(b)
    se = np.sqrt(va + vb)
    df = se**4 / (va**2 / (len(a) - 1) + vb**2 / (len(b) - 1)) if se > 0 else np.inf
    h = stats.t.ppf(0.975, df) * se
    return dict(ma=ma, sa=np.sqrt(va), mb=mb, sb=np.sqrt(vb), z=abs(ma - mb) / se if se else 0.0,
                p=2 * stats.t.sf(abs(ma - mb) / se, df) if se else 1.0,
                rel=(ma - mb) / mb, lo=(ma - mb - h) / mb, hi=(ma - mb + h) / mb,
                var=a.var(ddof=1) / b.var(ddof=1))


def race_fails(a, b, draws=20000, seed=1):
    """How often the race's test fails (z_max > 3, bench/race.py) on RACE_N realisations of a
    setting and of the reference drawn without replacement from the samples a and b."""
    rng = np.random.default_rng(seed)
    fails = 0
    for _ in range(draws):
        x = a[rng.permutation(len(a))[:RACE_N]]
        y = b[rng.permutation(len(b))[:RACE_N]]
        d = np.abs(x.mean(0) - y.mean(0))
        se = np.sqrt(x.var(0, ddof=1) / RACE_N + y.var(0, ddof=1) / RACE_N)
        fails += np.any(d > 3 * se)
    return fails / draws


def table(label, sa, sb):
    print(f"\n{label} (n = {len(sa)} against {len(sb)})")
    print(f"  {'statistic':9s} {'mean +- se':>20s} {'reference +- se':>20s} {'z':>5s} {'p':>6s} "
          f"{'rel. bias [95 % CI]':>28s} {'var ratio':>9s}")
    zs = []
    for j, name in enumerate(NAMES):
        w = welch(sa[:, j], sb[:, j])
        zs.append(w["z"])
        print(f"  {name:9s} {w['ma']:11.5g} +- {w['sa']:<6.2g} {w['mb']:11.5g} +- {w['sb']:<6.2g} "
              f"{w['z']:5.2f} {w['p']:6.3f} {100*w['rel']:+7.2f} % [{100*w['lo']:+6.2f}, "
              f"{100*w['hi']:+6.2f}] % {w['var']:9.2f}")
    return zs


def report(files):
    data = {}
    for f in files:
        d = json.loads(Path(f).read_text())
        by = {}
        for r in sorted(d["runs"], key=lambda r: r["k"]):
            by.setdefault(r["setting"], []).append(r["stats"])
        data[d["build"]] = {s: np.array(v) for s, v in by.items()}
    for build, by in data.items():
        print(f"\n=== {build}")
        ref = by["reference"]
        for s in SETTINGS:
            if s in by:
                n = min(len(by[s]), len(ref))
                table(f"{s} vs reference, realisations 0..{n-1}", by[s][:n], ref[:n])
        z7 = table(f"goal vs reference, the race's realisations 0..{RACE_N-1}",
                   by["goal"][:RACE_N], ref[:RACE_N])
        print(f"  the race's z_max: {max(z7):.4g} ({NAMES[int(np.argmax(z7))]})")
        a, b = by["goal"], ref
        print(f"  the race's test (z_max of {RACE_N} against {RACE_N} <= 3) on subsets drawn from "
              f"these: fails {100*race_fails(a, b):.1f} %, with the goal's mean shifted onto the "
              f"reference's (no bias) {100*race_fails(a - a.mean(0) + b.mean(0), b):.1f} %")
    builds = list(data)
    for i, a in enumerate(builds):
        for b in builds[i + 1:]:
            table(f"reference of {a} vs reference of {b}", data[a]["reference"],
                  data[b]["reference"])
            table(f"goal of {a} vs goal of {b}", data[a]["goal"], data[b]["goal"])
    if len(builds) > 1:
        pooled = {s: np.vstack([data[b][s] for b in builds]) for s in ["reference", *SETTINGS]
                  if all(s in data[b] for b in builds)}
        for s in SETTINGS:
            if s in pooled:
                table(f"{s} vs reference, both builds pooled", pooled[s], pooled["reference"])


if __name__ == "__main__":
    warnings.simplefilter("ignore")      # chaos_z24's shipped wind-up and start warnings
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    sub = p.add_subparsers(dest="cmd", required=True)
    r = sub.add_parser("run")
    r.add_argument("--n", type=int, default=30)
    r.add_argument("--out", default="out/goal_bias")
    q = sub.add_parser("report")
    q.add_argument("files", nargs="+")
    a = p.parse_args()
    run(a.n, a.out) if a.cmd == "run" else report(a.files)
