"""Grazings of fold_curve's orbits (docs/branches.md): the grazing nearest each fold along its
value's branch (fold_grazing), and the grazing curve in the two fields (trace, curves).

A grazing is where the contact signature of the orbit changes along a branch in the first
field (specials.contact_measures; a tooth's closest approach reaches zero). The grazing curve
is followed by a predictor-corrector on the second field: a step in field2 (landing on each
value of field2 it passes), a secant predictor of the first field in the plane, and at the new
value of field2 the branch in the first field corrected at the predicted point and walked to
its nearest grazing, which is bisected as continuation locates one (specials.graze). A step
whose grazing lies further than `move` (scaled) from the prediction, or changes its contact
signatures either side, is halved; below ds_min the curve stops there ('the grazing is lost'):
where it meets a fold (the branch ends there), turns back in field2, or another grazing takes
its place. The unknowns are FoldSystem's (pyspline.foldcurve): z the scaled section state, q1,
q2 each field over a tenth of its magnitude. Nothing here computes physics: the map, M and the
trajectories are the core's."""
from __future__ import annotations

import warnings

import numpy as np

from .arclength import _Branch, _Problem, field_label, set_field
from .errors import CaseError, SolverError, SplineWarning
from .orbits import out_of_time
from .specials import graze, point_at

#: the grazing curve's steps (scaled field2), the prediction's largest miss (scaled field1)
#: and its most points per direction; `fold_curve(..., graze_curves=dict(...))` sets them
STEPS = dict(ds=0.1, ds_min=2e-3, ds_max=0.5, move=0.02, max_points=40)


def at(sys, u) -> str:
    """'field = v, field2 = w' of the scaled unknowns u (their last two: q1, q2)."""
    return ", ".join(f"{field_label(*f)} = {v:.6g}" for f, v in zip(sys.fields, sys.p_of(u)))


def options(value) -> dict | None:
    """fold_curve's graze_curves: False (none), True (STEPS) or a dict of some of STEPS' keys;
    CaseError naming the key and why."""
    if value is False or value is None:
        return None
    if value is True:
        return dict(STEPS)
    if not isinstance(value, dict):
        raise CaseError(f"graze_curves = {value!r}: True, False or a dict of "
                        f"{', '.join(STEPS)}")
    out = dict(STEPS)
    for k, v in value.items():
        if k not in STEPS:
            raise CaseError(f"graze_curves[{k!r}]: not one of {', '.join(STEPS)}")
        whole = k == "max_points"
        if isinstance(v, bool) or not isinstance(v, (int, np.integer) if whole else
                                                 (int, float, np.integer, np.floating)) \
                or not np.isfinite(v) or v <= (1 if whole else 0):
            raise CaseError(f"graze_curves[{k!r}] = {v!r}: " + (
                "a whole number >= 2" if whole else "a finite number > 0"))
        out[k] = v
    if not out["ds_min"] <= out["ds"] <= out["ds_max"]:
        raise CaseError(f"graze_curves: ds_min <= ds <= ds_max wanted (ds_min {out['ds_min']:g}, "
                        f"ds {out['ds']:g}, ds_max {out['ds_max']:g})")
    return out


def value_branch(sys, q2, y_fixed):
    """The branch in the first field at the scaled value q2 of field2, in sys's unknowns."""
    (name, index), (name2, index2) = sys.fields
    with warnings.catch_warnings():     # the case's notes: said by the seed's run
        warnings.simplefilter("ignore", SplineWarning)
        prob = _Problem(set_field(sys.case, name2, index2, sys.p_of([0.0, q2])[1]), name,
                        index, sys.n, sys.p0[0], sys.p0[0], sys.t0)
    prob.pscale, prob.d0, prob.free = sys.pscale[0], sys.d0, sys.free     # sys's unknowns
    return _Branch(prob, sys.n, y_fixed, sys.tol, 6)


def fold_grazing(sys, u, y_fixed, **walk):
    """The grazing nearest the fold point u (converged, at field2 fixed) along its
    one-parameter branch in the first field (nearest's record and why, as `nearest`)."""
    if late := out_of_time():
        return None, f"{late} was reached"
    br = value_branch(sys, u[-1], y_fixed)
    try:
        F, J, M, y = br.prob.evaluate(y_fixed, u[:-1], sys.n)
        a = br.point((u[:-1], F, J, M, y, 0, [float(np.abs(F).max())]),
                     np.linalg.svd(J)[2][-1])
    except (SolverError, CaseError) as exc:
        a, br.last_error = None, str(exc)
    if a is None:
        return None, f"the fold's orbit did not run: {br.last_error}"
    return nearest(sys, br, a, u[-1], **walk)


def nearest(sys, br, a, q2, ds=0.02, ds_min=1e-4, ds_max=0.25, reach=2.0, iters=12):
    """The grazing nearest the branch point a (a record of br.point) at the scaled value q2 of
    field2: the branch followed from a both ways by arclength steps (continuation's corrector,
    the secant as predictor), always the way walked less, until the contact signature changes
    at a point (or, in a failed step, at its predictor), the grazing then bisected (`iters`
    times) as continuation locates it (specials.graze). (the grazing's special record with
    'bracket': the field's span between the points either side of it, 'sides': their
    signatures, 'ends': their field values; or None; 'found' or why not: none within the
    arclength `reach` (scaled) either way, or the way's corrector failed)."""
    ways = [dict(a, tau=s * a["tau"], s=0.0, ds=ds) for s in (1, -1)]
    why = f"no grazing within {reach:g} of arclength (scaled) either way"
    while ways:
        if late := out_of_time():
            return None, f"{late} was reached"
        i = min(range(len(ways)), key=lambda j: ways[j]["s"])
        w, sig = ways[i], ways[i]["contact"]["signature"]
        pred = np.r_[w["u"] + w["ds"] * w["tau"], q2]
        b, loc = point_at(br, w, w["ds"]), False
        if b is not None and b["contact"]["signature"] != sig:
            loc = graze(br, w, b, w["ds"], iters)
        elif b is None and not w.get("diagnosed") and br.signature(pred[:-1]) != sig:
            w["diagnosed"] = True       # once from a point, as continuation's diagnosis
            loc = graze(br, w, None, w["ds"], iters)
        if loc:
            last, past = loc[:2]
            return dict(loc[-1], bracket=abs(past["p"] - last["p"]), ends=(last["p"], past["p"]),
                        sides=(last["contact"]["signature"], past["contact"]["signature"])), \
                "found"
        if b is None:
            w["ds"] /= 2
            if w["ds"] < ds_min:
                why = (f"the branch's corrector failed at {at(sys, pred)} with the step down "
                       f"to {w['ds']:.3g}: {getattr(br, 'last_error', '')}")
                ways.pop(i)
        elif loc is None:
            why = f"a contact change with no grazing located next to {at(sys, pred)}"
            ways.pop(i)
        else:
            ways[i] = dict(b, s=w["s"] + w["ds"], ds=min(ds_max, 1.5 * w["ds"]))
            if ways[i]["s"] >= reach:
                ways.pop(i)
    return None, why


def _located(sys, g, q1, q2, y_fixed, move):
    """The grazing at the scaled value q2 of field2 nearest the predicted q1, from the orbit of
    the grazing g before it: (its record with q = (q1, q2), None) or (None, why not)."""
    br = value_branch(sys, q2, y_fixed)
    e = np.eye(len(g["u"]))[-1]
    res = br.correct(np.r_[g["u"][:-1], q1], e, q1)
    a = None if res is None else br.point(res, e)
    if a is None:
        return None, f"the branch's corrector failed at the prediction {at(sys, [q1, q2])}: " \
                     f"{getattr(br, 'last_error', 'no convergence')}"
    new, why = nearest(sys, br, a, q2, reach=max(4 * move, 0.1))
    if new is None:
        return None, f"no grazing found from the prediction {at(sys, [q1, q2])}: {why}"
    if set(new["sides"]) != set(g["sides"]):
        return None, (f"the grazing next to {at(sys, [q1, q2])} is another: the contact "
                      f"changes per period either side {_changes(new)} against {_changes(g)}")
    miss = abs(new["u"][-1] - q1)
    if miss > move:
        return None, f"the grazing lies {miss:.3g} (scaled) from the prediction (move {move:g})"
    return dict(new, q=np.array([new["u"][-1], q2])), None


def _changes(g) -> str:
    return " and ".join(str(sum(s[len(s) // 2:])) for s in g["sides"])


def trace(sys, g, q2, y_fixed, values, bounds, direction, ds, ds_min, ds_max, move,
          max_points):
    """One direction of the grazing curve from the located grazing g (a record of `nearest`)
    at the scaled value q2 of field2: steps in q2 (landing on each of the scaled `values`
    passed), the first field predicted by the secant of the last two points (the first step:
    unchanged), each grazing located by `_located`; a step that fails is halved, one that
    succeeds grows 1.5x (not one cut short to land on a value) up to ds_max. (the points
    in order, what ended it: 'complete' at the side of `bounds` (q2 lo, hi); 'the grazing is
    lost ...' with the step below ds_min; max_points, the time bound)."""
    pts = [dict(g, q=np.array([g["u"][-1], q2]))]
    end = bounds[1] if direction > 0 else bounds[0]
    while len(pts) < max_points:
        q = pts[-1]["q"]
        if late := out_of_time():
            return pts, f"{late} was reached at {at(sys, q)}"
        if (end - q[1]) * direction <= 1e-12:
            return pts, "complete"
        to = q[1] + direction * ds
        passed = [v for v in values if 1e-12 < (v - q[1]) * direction < (to - q[1]) * direction]
        to = min(passed + [to], key=lambda v: abs(v - q[1]))
        to = end if (to - end) * direction > 0 else to
        step = abs(to - q[1])
        slope = 0.0 if len(pts) < 2 else (q[0] - pts[-2]["q"][0]) / (q[1] - pts[-2]["q"][1])
        new, why = _located(sys, pts[-1], q[0] + slope * (to - q[1]), to, y_fixed, move)
        if new is None:
            ds = step / 2
            if ds < ds_min:
                return pts, f"the grazing is lost past {at(sys, q)} (step below {ds_min:g}): {why}"
            continue
        pts.append(new)
        ds = min(ds_max, 1.5 * ds) if step >= ds else ds    # a step cut to a value: kept
    return pts, f"max_points = {max_points} reached at {at(sys, pts[-1]['q'])}"


def curves(sys, near, ys, values2, steps):
    """From each located grazing of `near` (fold_grazing's (record, why) per value and fold;
    ys: the fixed states of each fold) not on a curve traced before (a point of it at that
    value with the same signatures either side, within `move` of it: the criterion a step
    accepts a grazing by), the grazing curve both ways over [min, max] of values2: (curves:
    lists of point records in order of field2; status per curve: each direction's end)."""
    q2s = (np.asarray(values2, float) - sys.p0[1]) / sys.pscale[1]
    bounds = (q2s.min(), q2s.max())
    out, status = [], []
    for q2, row, yrow in zip(q2s, near, ys):
        for (g, _), y in zip(row, yrow):
            if g is None or any(abs(p["q"][1] - q2) < 1e-12 and set(p["sides"]) ==
                                set(g["sides"]) and abs(p["q"][0] - g["u"][-1]) <=
                                steps["move"] for c in out for p in c):
                continue
            halves, ends = [], []
            for d in (-1, 1):
                pts, why = trace(sys, g, q2, y, q2s, bounds, d, **steps)
                halves.append(pts)
                ends.append(f"{'down' if d < 0 else 'up'}: {why}")
            out.append(halves[0][::-1] + halves[1][1:])
            status.append("; ".join(ends))
    return out, status


def variables(sys, traced, status):
    """The grazing curves as fold_curve's variables: along dim graze_point `graze_curve`
    (which), `graze_curve_field`, `graze_curve_field2`, `graze_curve_ends` (the first
    field's values of the points either side of the grazing), `graze_curve_y0`; along dim
    graze_curve `graze_curve_status`."""
    pts = [(i, p) for i, c in enumerate(traced) for p in c]
    return {"graze_curve": (("graze_point",), np.array([i for i, _ in pts], int)),
            "graze_curve_field": (("graze_point",), np.array([p["p"] for _, p in pts])),
            "graze_curve_field2": (("graze_point",),
                                   np.array([sys.p_of(p["q"])[1] for _, p in pts])),
            "graze_curve_ends": (("graze_point", "side"),
                                 np.array([p["ends"] for _, p in pts]).reshape(-1, 2)),
            "graze_curve_y0": (("graze_point", "state"),
                               np.array([p["y"] for _, p in pts]).reshape(-1, 14)),
            "graze_curve_status": (("graze_curve",), np.array(status, dtype=object))}
