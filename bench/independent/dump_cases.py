"""Run every shipped case under a few settings and store every output of each run, exactly.

usage: python -P bench/independent/dump_cases.py OUTDIR [CASES_DIR]

Run it with the python of the build to check (its venv); compare two OUTDIRs with
bench/independent/compare_dumps.py. Per case and setting one OUTDIR/<case>.<setting>.npz holds every array
of the Result (outputs, per-tooth arrays, sections, Lyapunov record, face loads), every entry
of loads, extremes and stats (except the two wall-clock stats), the model level and the
warnings' text; or the error's class and text if the run refused or failed.
Settings: default (the case as shipped), statistics (goal = 'statistics'), statistics_nolyap
(the same, lyapunov off), real2 (goal = 'statistics', lyapunov off, realisations = 2).
SHORT shortens t_end of the slow cases (the run's cost is not the point here).
"""
import glob
import os
import sys
import warnings

import numpy as np

import pyspline

SETTINGS = {
    "default": {},
    "statistics": {"goal": "statistics"},
    "statistics_nolyap": {"goal": "statistics", "lyapunov": False},
    "real2": {"goal": "statistics", "lyapunov": False, "realisations": 2},
}
SHORT = {}          # case name -> t_end override (filled from the timing of main's build)
CLOCKS = {"core_wall_s", "wall_s"}


def flatten(res):
    out = {}
    for name in dir(res):
        if name.startswith("_"):
            continue
        v = getattr(res, name)
        if callable(v) or name == "case":
            continue
        if isinstance(v, dict):
            for k, x in v.items():
                if name == "stats" and k in CLOCKS:
                    continue
                out[f"{name}.{k}"] = np.asarray(x)
        elif isinstance(v, tuple):
            out[name] = np.asarray(v, dtype=str)
        elif v is None:
            out[name] = np.asarray("None")
        else:
            out[name] = np.asarray(v)
    return out


def main():
    outdir = sys.argv[1]
    cases_dir = sys.argv[2] if len(sys.argv) > 2 else os.path.join(os.path.dirname(__file__), "..", "cases")
    os.makedirs(outdir, exist_ok=True)
    warnings.simplefilter("ignore")
    for path in sorted(glob.glob(os.path.join(cases_dir, "*.nml"))):
        name = os.path.basename(path)[:-4]
        if name == "template":
            continue
        for setting, fields in SETTINGS.items():
            fields = dict(fields)
            if name in SHORT:
                fields["t_end"] = SHORT[name]
            try:
                res = pyspline.simulate(pyspline.load_case(path, **fields))
                arrays = flatten(res)
            except Exception as exc:        # a refused setting is an output too
                arrays = {"error": np.asarray(f"{type(exc).__name__}: {exc}")}
            np.savez(os.path.join(outdir, f"{name}.{setting}.npz"), **arrays)
            print(name, setting, "error" if "error" in arrays else len(arrays), flush=True)


if __name__ == "__main__":
    main()
