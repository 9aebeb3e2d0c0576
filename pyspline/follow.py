"""Sweeps that follow a branch (``sweep(..., follow='up' | 'down' | 'both')``): the points of
one swept field run in order of its value, each from the previous point's final state, so
that hysteresis and coexisting attractors show (docs/continuation.md).

The state at the end of a point becomes the next point's start ('rest' plus the state as
dq0, dv0: exact) at a start time t0' that keeps the forcing's phase: omega' t0' = omega t_end
modulo the revolutions after which the forcing repeats (orbits.forcing_periods; 1 for whole
ripple orders), t_end moved by the same shift (a run length in revolutions is kept). A chain
is serial: an executor runs one chain per direction ('both': up and down at once).
"""
from __future__ import annotations

from math import inf

import numpy as np

from .errors import SolverError
from .orbits import repeat_revolutions
from .summary import failed_summary, summarise

DIRECTIONS = ("up", "down", "both")


def continued(case, y, t_prev: float, omega_prev: float):
    """`case` started from state y (14,), SI, that a run at omega_prev reached at t_prev, at
    the start time with the same forcing phase."""
    omega = case.model.info()["omega"]
    if not omega > 0 or not omega_prev > 0:
        shift = 0.0
    else:
        span = 2 * np.pi * repeat_revolutions(case)
        shift = (omega_prev * t_prev) % span / omega - case["t0"]
    times = dict(t0=case["t0"] + shift)
    if not (case["revolutions"] if "revolutions" in case else 0):
        times["t_end"] = case["t_end"] + shift
    return case.replace(start="rest", dq0=[float(v) for v in y[:7]],
                        dv0=[float(v) for v in y[7:]], **times)


def run_chain(cases: list, options: dict) -> list:
    """Summaries of the cases run in the given order, each from the previous one's final
    state (a failed point breaks the chain: the next starts from its own start). Within a
    call's time bound (orbits.time_bound: pyspline.branches, fold_curve; in this thread) each
    run is cut to the time left, and once it has passed the rest are not run: failed points
    naming the bound."""
    from .orbits import _wall, out_of_time
    from .result import collected, run as run_model
    out, prev = [], None
    for case in cases:
        if not isinstance(case, Exception) and (late := out_of_time()):
            case = SolverError(f"{late} was reached before this run")
        if isinstance(case, Exception):
            out.append(failed_summary(case, options))
            prev = None
            continue
        with collected() as said:       # the point's warnings: in its summary, not raised
            try:
                run = case if prev is None else continued(case, *prev)
                res = run_model(run.model, max_seconds=_wall(run.model, inf))
                out.append(summarise(res, options))
                if options.get("final_state"):     # sweep(finals=...): pyspline.branches' seeds
                    out[-1]["final"] = (res.y[-1].copy(), float(res.t[-1]))
                prev = (res.y[-1].copy(), float(res.t[-1]), run.model.info()["omega"])
            except Exception as exc:        # noqa: BLE001 -- a failed point is a result
                out.append(dict(failed_summary(exc, options), warnings="\n".join(said)))
                prev = None
        # the start 'rest' overlap note says nothing here (a chain starts where it was)
        out[-1]["warnings"] = "\n".join(w for w in out[-1]["warnings"].splitlines()
                                        if "start = 'rest' with" not in w)
    return out


def follow_sweep(cases: dict, field_values, follow: str, options: dict, executor, bar):
    """{direction: {index: summary}} of a one-field sweep run as chains (cases: {(i,): Case});
    up: increasing field value, down: decreasing."""
    order = np.argsort(np.asarray(field_values), kind="stable")
    dirs = ("up", "down") if follow == "both" else (follow,)
    chains = {d: [(int(i),) for i in (order if d == "up" else order[::-1])] for d in dirs}
    out = {}
    if executor is None:
        for d, idx in chains.items():
            out[d] = dict(zip(idx, run_chain([cases[i] for i in idx], options)))
            bar.update(len(idx))
    else:
        futs = {d: executor.submit(run_chain, [cases[i] for i in idx], options)
                for d, idx in chains.items()}
        for d, fut in futs.items():
            out[d] = dict(zip(chains[d], fut.result()))
            bar.update(len(chains[d]))
    return out
