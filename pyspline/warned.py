"""The warnings of a sweep's points said once per kind: the first point's words in full, how
many points raised it, over which values of the swept fields, and the range of each of its
numbers that varies (the largest at which point). A warning's kind is the core's line with
its numbers masked: its words (the fields it names, what it says, the units) are the core's
and differ between kinds, its numbers are the point's. Each point's own lines stay in the
sweep's dataset (variable 'warnings'; docs/sweeps.md)."""
from __future__ import annotations

import re
import warnings

import numpy as np

from .errors import SplineWarning

#: a number in the core's words (1.500E-04, 422.6, -2, 0.20), not the digits of a name (k_t1, t0)
_NUMBER = re.compile(r"(?<![\w.])[-+]?(?:\d+\.?\d*|\.\d+)(?:[eE][-+]?\d+)?(?!\w)")


def kind(line: str) -> str:
    """The kind of one of the core's warning lines: its words, every number masked as '#'."""
    return _NUMBER.sub("#", line)


def _value(v) -> str:
    return f"{v:.6g}" if isinstance(v, (float, np.floating)) else str(v)


def _at(where: dict) -> str:
    return ", ".join(f"{f} = {_value(v)}" for f, v in where.items())


def _span(values: list) -> str:
    """The values of a swept field at the points of a kind: 'lo to hi' (numbers), else the
    distinct ones."""
    if all(isinstance(v, (int, float, np.number)) and not isinstance(v, (bool, np.bool_))
           for v in values):
        lo, hi = min(values), max(values)
        return _value(lo) if lo == hi else f"{_value(lo)} to {_value(hi)}"
    distinct = list(dict.fromkeys(map(_value, values)))
    return ", ".join(distinct[:5]) + (", ..." if len(distinct) > 5 else "")


def _said(raised: list, n: int) -> str:
    """One kind's warning: raised = [(where, line)] of its points (in point order), of n."""
    first = raised[0][1]
    if n == 1:
        return first
    parts = [f"{len(raised)} of {n} points"]
    parts += [f"{f} = {_span([w[f] for w, _ in raised])}" for f in raised[0][0]]
    before = _NUMBER.split(first)          # the words before each number
    varying = []
    for k, column in enumerate(zip(*(_NUMBER.findall(line) for _, line in raised))):
        values = [float(x) for x in column]
        if min(values) == max(values):
            continue
        words = before[k].split()
        label = " ".join(words[-2:] if words[-1:] == ["="] else words[-1:])
        worst = int(np.argmax(np.abs(values)))
        varying.append(f"{label} {column[int(np.argmin(values))]} to "
                       f"{column[int(np.argmax(values))]} (largest at {_at(raised[worst][0])})")
    if varying:
        parts.append("varying: " + ", ".join(varying))
    return f"{first} [{'; '.join(parts)}]"


def grouped(points: list) -> list:
    """The warnings of n points, each kind once (_said): points = [(where, text)], where
    {field: value} of the point, text its warnings one per line ('' if none)."""
    kinds: dict = {}
    for where, text in points:
        for line in dict.fromkeys(filter(None, text.splitlines())):
            kinds.setdefault(kind(line), []).append((where, line))
    return [_said(raised, len(points)) for raised in kinds.values()]


def point_warnings(ds) -> list:
    """[(where, text)] of every point of a sweep's dataset (variable 'warnings'), where: the
    values of its swept fields (and its direction in a follow='both' sweep)."""
    if "warnings" not in ds:
        return []
    text = ds["warnings"]
    names = [f for f in ("direction", *ds.attrs.get("swept", "").split()) if f in ds.coords]
    out = []
    for index in np.ndindex(text.shape):
        lines = str(text.values[index])
        out.append(({f: text[index][f].item() for f in names} if lines else {}, lines))
    return out


def warn_grouped(ds, stacklevel: int = 3) -> None:
    """Each kind of the dataset's point warnings as one SplineWarning (grouped)."""
    for message in grouped(point_warnings(ds)):
        warnings.warn(message, SplineWarning, stacklevel=stacklevel)
