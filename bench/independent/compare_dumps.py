"""Compare two bench/independent/dump_cases.py directories array by array, bit for bit.

usage: python -P bench/independent/compare_dumps.py DIR_A DIR_B

Prints one line per run (case.setting): 'same' (every array has the same dtype, shape and
bytes), or the arrays that differ (with the largest absolute difference), or are missing on a
side. Exit code 1 if any run differs.
"""
import glob
import os
import sys

import numpy as np


def compare(a, b):
    diffs = []
    for key in sorted(set(a) | set(b)):
        if key not in a or key not in b:
            diffs.append(f"{key}: only in {'A' if key in a else 'B'}")
            continue
        x, y = a[key], b[key]
        if x.dtype != y.dtype or x.shape != y.shape:
            diffs.append(f"{key}: {x.dtype}{x.shape} against {y.dtype}{y.shape}")
        elif x.tobytes() != y.tobytes():
            if x.dtype.kind in "fc":
                diffs.append(f"{key}: max |diff| {np.nanmax(np.abs(x - y)):.3g}")
            else:
                diffs.append(f"{key}: {x.ravel()[:3]} against {y.ravel()[:3]}")
    return diffs


def main():
    dir_a, dir_b = sys.argv[1:3]
    names = sorted({os.path.basename(p) for p in glob.glob(os.path.join(dir_a, "*.npz"))}
                   | {os.path.basename(p) for p in glob.glob(os.path.join(dir_b, "*.npz"))})
    n_diff = n_arrays = 0
    for name in names:
        pa, pb = os.path.join(dir_a, name), os.path.join(dir_b, name)
        if not (os.path.exists(pa) and os.path.exists(pb)):
            print(f"{name[:-4]}: only in {'A' if os.path.exists(pa) else 'B'}")
            n_diff += 1
            continue
        with np.load(pa) as fa, np.load(pb) as fb:
            a, b = dict(fa), dict(fb)
        n_arrays += len(a)
        diffs = compare(a, b)
        n_diff += bool(diffs)
        tag = " (refused: " + str(a["error"])[:80] + ")" if "error" in a and not diffs else ""
        print(f"{name[:-4]}: " + ("; ".join(diffs) if diffs else f"same, {len(a)} arrays{tag}"))
    print(f"{len(names)} runs, {n_arrays} arrays compared, {n_diff} runs differ")
    sys.exit(1 if n_diff else 0)


if __name__ == "__main__":
    main()
