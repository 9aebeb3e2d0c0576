"""CPU, wall and minor page faults of realisations = 2 against a single run, many calls in one process.

usage: python -P bench/independent/realisations.py CASE.nml ROUNDS OUT.json [serial]

Each round runs, on loaded models, one single run (goal = 'statistics', lyapunov off), one
realisations = 2 call (the same, two copies on simulate's default executor, a thread each) and
with `serial` one realisations = 2 call on a one-thread executor made once (the copies one after
the other), with resource.getrusage(RUSAGE_SELF) (the process: every thread) and time.perf_counter around
each call. The first 3 rounds warm up and are not kept. Writes every kept round's numbers, the
RHS calls of each kind of call (the same every round: the runs are deterministic; realisations'
stats leave out the shared transient) and those of the transient alone (a run to 1 us past it).
"""
import concurrent.futures
import json
import resource
import sys
import time
import warnings

import pyspline

warnings.simplefilter("ignore")


def measured(model, executor=None):
    r0, w0 = resource.getrusage(resource.RUSAGE_SELF), time.perf_counter()
    res = pyspline.simulate(model, executor)
    w1, r1 = time.perf_counter(), resource.getrusage(resource.RUSAGE_SELF)
    cpu = (r1.ru_utime + r1.ru_stime) - (r0.ru_utime + r0.ru_stime)
    return res, {"cpu_ms": 1e3 * cpu, "wall_ms": 1e3 * (w1 - w0), "minflt": r1.ru_minflt - r0.ru_minflt,
                 "majflt": r1.ru_majflt - r0.ru_majflt}


def main():
    path, rounds, out = sys.argv[1], int(sys.argv[2]), sys.argv[3]
    base = {"goal": "statistics", "lyapunov": False}
    case = pyspline.load_case(path, **base)
    real2 = pyspline.load_case(path, realisations=2, **base).model
    one = concurrent.futures.ThreadPoolExecutor(1)
    runs = {"single": (case.model, None), "real2": (real2, None)}
    if sys.argv[4:] == ["serial"]:
        runs["real2_serial"] = (real2, one)
    t_start = case["t0"] + case["t_transient"]
    transient = pyspline.simulate(case.replace(t_end=t_start + 1e-6, n_out=2))
    rows, rhs = [], {"transient": int(transient.stats["rhs_evals"])}
    for k in range(rounds + 3):
        row = {}
        for kind, (model, executor) in runs.items():
            res, m = measured(model, executor)
            rhs[kind] = int(res.stats["rhs_evals"])
            row.update({f"{kind}_{key}": v for key, v in m.items()})
        if k >= 3:
            rows.append(row)
    with open(out, "w") as f:
        json.dump({"rows": rows, "rhs_evals": rhs, "pyspline": pyspline.__file__}, f)


if __name__ == "__main__":
    main()
