"""A fold of a periodic orbit followed in two fields by the minimally extended system
(docs/branches.md, `fold_curve`).

Unknowns u = (z, q1, q2): z the orbit's section state over the integrated states, scaled by
Eq. 25 with the seed's scales, q1, q2 the two fields, each scaled by a tenth of its magnitude
(as arclength's q). Equations: F = P^n(y) - y = 0 (arclength's residual) and g = 0, g from
the bordered system [[M - I, b], [c^T, 0]] [v; g] = [0; 1] (M the exact monodromy of the
variational run, with saltation; b, c the left and right singular vectors of M - I of the
smallest singular value at the previous point), plus the pseudo-arclength row. g's
derivatives: g_z = -w^T (M(z + eps v) - M(z - eps v)) / (2 eps) (the symmetry of second
derivatives: the whole gradient from two variational runs), g_q = -w^T (M(q + h) - M(q - h))
v / (2 h), with [w^T, g'] the transposed bordered solve; F_q from the same runs at q +- h:
seven variational runs per Newton iteration whatever the state's size. The contact signature
of the orbit (specials.contact_measures) must stay the seed's (the saltation in M holds within one contact sequence):
where it changes, the direction stops ('grazing at ...'). At each value of field2 the grazing
nearest each fold is found along that value's branch from the fold's orbit, and followed in
field2 on request (pyspline.grazecurve: fold_grazing, curves). Nothing here computes physics: the map, M and
the trajectories are the core's."""
from __future__ import annotations

import warnings

import numpy as np

from .arclength import (_map_only, _null_tangent, continuation, field_label, parse_field,
                        scaled_map, set_field)
from .errors import CaseError, SolverError, SplineError, SplineWarning
from .grazecurve import at as _at, curves as graze_curves, fold_grazing, variables
from .orbits import _scale, _trajectory, forcing_periods, map_and_monodromy, out_of_time
from .result import sundials_said
from .specials import contact_measures, multipliers


class FoldSystem:
    """The case at (p1, p2) = fields (name, index) f1 and f2, and the extended system's
    residual and Jacobian at u = (z, q1, q2)."""

    def __init__(self, case, f1, f2, n, p0, pscale, free, d0, tol):
        self.case, self.fields, self.n = case, (f1, f2), n
        self.p0, self.pscale = np.asarray(p0, float), np.asarray(pscale, float)
        self.free, self.d0, self.tol = free, d0, tol
        self.t0 = float(case["t0"])
        self.h = case["rtol"] ** 0.5            # difference steps, as arclength's dF/dp
        self.models = {}
        self.b = self.c = None

    def p_of(self, u):
        return self.p0 + u[-2:] * self.pscale

    def model(self, p):
        """The loaded case at p = (p1, p2); CaseError outside a field's valid range."""
        key = tuple(map(float, p))
        m = self.models.get(key)
        if m is None:
            from .core import load
            if len(self.models) > 16:
                self.models.clear()
            c = self.case
            for (name, index), v in zip(self.fields, key):
                c = set_field(c, name, index, v)
            with warnings.catch_warnings():     # the case's notes: said by the seed's run
                warnings.simplefilter("ignore", SplineWarning)
                m = load(c)
            forcing_periods(m.case, self.n)
            self.models[key] = m
        return m

    def state(self, u, y_fixed):
        y = np.array(y_fixed, float)
        y[self.free] = u[:-2] * self.d0[self.free]
        return y

    def t1(self, p):
        return self.t0 + 2 * np.pi * self.n / self.model(p).info()["omega"]

    def orbit(self, u, y_fixed):
        """The run of one period from u's state: the contact signature of its orbit
        (specials.contact_measures) and its trajectory."""
        p = self.p_of(u)
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", SplineWarning)
            tr = _trajectory(self.model(p).case, self.t0, self.t1(p), self.state(u, y_fixed))
        return contact_measures(tr), tr

    def run(self, u, y_fixed):
        """(F, M) at u, in the seed's scales (one variational run)."""
        p = self.p_of(u)
        return scaled_map(map_and_monodromy, self.model(p), self.t0, self.t1(p),
                          self.state(u, y_fixed), self.d0)[:2]

    def border(self, M):
        """b, c: the left and right singular vectors of M - I of its smallest singular value."""
        U, _, Vt = np.linalg.svd(M - np.eye(len(M)))
        self.b, self.c = U[:, -1], Vt[-1]

    def bordered(self, M):
        """(v, g, w): [[M - I, b], [c^T, 0]] [v; g] = [0; 1] and its transposed solve's w."""
        k = len(M)
        A = np.block([[M - np.eye(k), self.b[:, None]], [self.c[None, :], np.zeros((1, 1))]])
        e = np.eye(k + 1)[-1]
        s, t = np.linalg.solve(A, e), np.linalg.solve(A.T, e)
        return s[:k], s[k], t[:k]

    def g(self, u, y_fixed):
        return self.bordered(self.run(u, y_fixed)[1])[1]

    def evaluate(self, u, y_fixed):
        """F (k,), g, J = [[M - I, F_q1, F_q2], [g_z, g_q1, g_q2]] (k + 1, k + 2), M."""
        F, M = self.run(u, y_fixed)
        v, g, w = self.bordered(M)
        k = len(F)
        eps = self.h * max(1.0, np.abs(u[:-2]).max())
        dz = np.r_[v, 0.0, 0.0] * eps / np.linalg.norm(v)
        Mp, Mm = (self.run(u + s * dz, y_fixed)[1] for s in (1, -1))
        gz = -w @ (Mp - Mm) / (2 * eps / np.linalg.norm(v))
        Fq, gq = np.empty((k, 2)), np.empty(2)
        for i in range(2):
            hq = self.h * max(1.0, abs(self.p_of(u)[i]) / self.pscale[i])
            side = {}
            for s in (1, -1):
                du = np.zeros_like(u)
                du[k + i] = s * hq
                try:
                    side[s] = (s * hq, *self.run(u + du, y_fixed))
                except CaseError:           # the field's range ends within hq: one-sided
                    continue
            if not side:
                raise CaseError(f"{field_label(*self.fields[i])} = {self.p_of(u)[i]:.6g}: no "
                                "valid value within the difference step of it")
            (qa, Fa, Ma), (qb, Fb, Mb) = (list(side.values()) + [(0.0, F, M)])[:2]
            Fq[:, i] = (Fa - Fb) / (qa - qb)
            gq[i] = -w @ ((Ma - Mb) @ v) / (qa - qb)
        J = np.block([[M - np.eye(k), Fq], [gz[None, :], gq[None, :]]])
        return F, g, J, M

    def correct(self, u_pred, row, target, y_fixed, max_iter=8):
        """Newton on [F; g; row . u - target] from u_pred: (u, J, M, iterations) or None, with
        self.last_error saying why."""
        u, hist = u_pred.copy(), []
        for it in range(max_iter + 1):
            try:
                F, g, J, M = self.evaluate(u, y_fixed)
            except (SolverError, CaseError, np.linalg.LinAlgError) as exc:
                self.last_error = str(exc)
                return None
            r = max(np.abs(F).max(), abs(g))
            hist.append(r)
            if r <= self.tol and it > 0:
                return u, J, M, it
            if it == max_iter or (it >= 2 and r > hist[-2]) or not np.isfinite(r):
                break
            try:
                u = u + np.linalg.solve(np.vstack([J, row]), -np.r_[F, g, row @ u - target])
            except np.linalg.LinAlgError:
                break
        self.last_error = (f"the corrector did not converge (residual max(|F|, |g|) "
                           f"{', '.join(f'{x:.2g}' for x in hist)}; wanted {self.tol:.3g})")
        return None

    def point(self, res, y_fixed):
        """The record of a converged point: u, p, y, M, its multipliers and contact."""
        u, J, M, it = res
        contact, tr = self.orbit(u, y_fixed)
        return dict(u=u, J=J, p=self.p_of(u), y=self.state(u, y_fixed), M=M, mu=multipliers(M),
                    iterations=it, contact=contact, Tm_pp=float(np.ptp(tr.Tm)))


def trace(sys, seed, y_fixed, bounds, direction, ds=0.05, ds_min=1e-3, ds_max=0.5,
          max_angle=0.3, max_points=100):
    """One direction of the fold curve from the seed point (a record of sys.point): the points
    in order and what ended it ('complete': the curve left the rectangle `bounds` ((q1 lo,
    hi), (q2 lo, hi)), its last point put on the side it crossed; 'grazing at ...': the contact
    signature changed, located to ds_min along the curve; or where and why it failed)."""
    k2 = len(seed["u"])
    sig0 = seed["contact"]["signature"]
    tau = _null_tangent(seed["J"], direction * np.eye(k2)[-1])
    a = dict(seed, tau=tau)
    pts = [a]
    lo, hi = np.array(bounds).T
    while len(pts) < max_points:
        if late := out_of_time():
            return pts, f"{late} was reached at {_at(sys, a['u'])}"
        pred = a["u"] + ds * a["tau"]
        q = pred[-2:]
        out = (q < lo - 1e-12) | (q > hi + 1e-12)
        end = None
        if out.any():       # onto the side crossed first, that field fixed
            t = a["tau"][-2:]
            frac = [((hi[i] if t[i] > 0 else lo[i]) - a["u"][k2 - 2 + i]) / t[i] if out[i]
                    else np.inf for i in range(2)]
            i = int(np.argmin(frac))
            end = (i, hi[i] if t[i] > 0 else lo[i])
            step = frac[i]
            if step < 1e-9:             # on that side already (the seed's value): the end
                return pts, "complete"
            res = sys.correct(a["u"] + step * a["tau"], np.eye(k2)[k2 - 2 + i], end[1], y_fixed)
        else:
            step = ds
            res = sys.correct(pred, a["tau"], a["tau"] @ pred, y_fixed)
        if res is not None and np.linalg.norm(res[0] - a["u"] - step * a["tau"]) > max(step, 1e-9):
            res, sys.last_error = None, "the corrector went further than the step (another curve)"
        new = None
        if res is not None:
            try:
                new = sys.point(res, y_fixed)
            except SolverError as exc:
                sys.last_error = str(exc)
        if new is not None and new["contact"]["signature"] != sig0:
            if ds / 2 < ds_min or end is not None and step / 2 < ds_min:
                return pts, _grazing(sys, a, new["u"], sig0, new["contact"]["signature"])
            new = None
        if new is None:
            ds = min(ds, step) / 2
            if ds < ds_min:
                return pts, _failed(sys, a, pred, ds, sig0, y_fixed)
            continue
        sec = new["u"] - a["u"]
        new["tau"] = sec / np.linalg.norm(sec)
        angle = np.arccos(np.clip(new["tau"] @ a["tau"], -1, 1))
        if angle > 2 * max_angle and ds / 2 >= ds_min and end is None:
            ds /= 2
            continue
        pts.append(new)
        sys.border(new["M"])
        if end is not None:
            return pts, "complete"
        a = new
        grow = 1.5 if new["iterations"] <= 2 else (0.6 if new["iterations"] >= 4 else 1.0)
        ds = max(ds_min, min(ds_max, ds * grow, ds * max_angle / max(angle, 1e-12)))
    return pts, f"max_points = {max_points} reached at {_at(sys, pts[-1]['u'])}"


def _grazing(sys, a, u, sig0, sig):
    """'grazing at ...': the contact sequence changes between point a and u, and how."""
    changes = [sum(x[len(x) // 2:]) for x in (sig0, sig)]     # (steady sides, changes)
    how = f"the contact changes per period go from {changes[0]} to {changes[1]}"
    return (f"grazing at {_at(sys, u)}: the contact sequence changes between it and "
            f"{_at(sys, a['u'])}: {how} (the saltation in M holds within one sequence; a "
            "non-smooth fold past it is not followed by the extended system)")


def _failed(sys, a, pred, ds, sig0, y_fixed):
    """What ended a direction whose step failed below ds_min: a grazing when the run of one
    period from the predictor has another contact signature, else the corrector's failure."""
    try:
        sig = sys.orbit(pred, y_fixed)[0]["signature"]
    except (SolverError, CaseError):
        sig = sig0
    if sig != sig0:
        return _grazing(sys, a, pred, sig0, sig) + f" (the corrector failed next to it: " \
            f"{sys.last_error})"
    return (f"the fold curve's corrector failed at {_at(sys, pred)} with the step down to "
            f"{ds:.3g}: {sys.last_error}")


def cusps(pts):
    """The cusps of a traced curve (points in order): where the q2 component of the secant
    changes sign and the q1 component too (the curve's projection on the two fields turns
    back: the two folds meet; where only q2 turns, the fold curve has an extremum in the
    second field, not a cusp), the field values at the q2 extremum of the parabola in
    arclength through the three points around it."""
    u = np.array([p["u"] for p in pts])
    out = []
    for i in range(1, len(u) - 1):
        d0, d1 = u[i] - u[i - 1], u[i + 1] - u[i]
        if d0[-1] * d1[-1] < 0 and d0[-2] * d1[-2] < 0:
            s = np.r_[0, np.cumsum(np.linalg.norm(np.diff(u[i - 1:i + 2], axis=0), axis=1))]
            c = np.polyfit(s, u[i - 1:i + 2, -1], 2)
            sc = -c[1] / (2 * c[0])
            out.append((i, [np.polyval(np.polyfit(s, u[i - 1:i + 2, j], 2), sc)
                            for j in (-2, -1)]))
    return out


def at_value(sys, pts, q2, y_fixed):
    """The fold points of a traced curve at q2: its points on q2 and, on each segment that
    crosses it, the point corrected with q2 fixed from the chord's (the chord's own when
    that fails: 'exact' False)."""
    f = [0.0 if abs(p["u"][-1] - q2) < 1e-12 else p["u"][-1] - q2 for p in pts]
    found = [dict(u=p["u"], exact=True) for p, x in zip(pts, f) if x == 0]
    for a, b, fa, fb in zip(pts, pts[1:], f, f[1:]):
        if fa * fb < 0:
            u = a["u"] + fa / (fa - fb) * (b["u"] - a["u"])
            res = sys.correct(u, np.eye(len(u))[-1], q2, y_fixed)
            found.append(dict(u=u, exact=False) if res is None else dict(u=res[0], exact=True))
    return found


def extended(case, field, start, stop, name2, index2, values2, n, progress, cont):
    """fold_curve by the extended system: the branch continued over [start, stop] at the
    values of field2 in turn until one has a smooth fold (the seed), each of its folds not on
    a curve traced before followed both ways within [start, stop] x [min, max of values2].
    Returns (the FoldSystem, None when no value has a fold; curves: lists of point records;
    ends: (last point or None, what ended each direction); tried: the continuation of each
    value tried, in order (its error's text where it found no orbit), the seed's last)."""
    from .core import load
    tried, fold = [], np.zeros(0, bool)
    for v0 in map(float, values2):
        at = set_field(case, name2, index2, v0)
        try:
            with warnings.catch_warnings(record=True):
                warnings.simplefilter("always", SplineWarning)
                ds = continuation(at, field, start, stop, n=n, progress=progress, **cont)
        except CaseError:
            raise
        except SplineError as exc:      # no orbit at the band's start: the next value
            tried.append(f"{type(exc).__name__}: {exc}")
            continue
        tried.append(ds)
        fold = (ds.special_type.values.astype(str) == "fold") & (ds.special_smooth.values == 1)
        if fold.any() or out_of_time():
            break
    if not tried or isinstance(tried[-1], str) or not fold.any():
        return None, [], [], tried
    steps = {k: cont[k] for k in ("ds", "ds_min", "ds_max", "max_angle", "max_points")
             if k in cont}
    pscale = (0.1 * max(abs(start), abs(stop)), 0.1 * np.abs(values2).max() or 1.0)
    model, y_fixed = load(at), ds.special_y0.values[fold][0]
    free = _map_only(model, case["t0"], case["t0"] + 2 * np.pi * n / model.info()["omega"],
                     y_fixed)[2]
    sys = FoldSystem(case, parse_field(case, field), (name2, index2), n, (start, v0), pscale,
                     free, _scale(model), cont.get("tol") or 100 * case["rtol"])
    bounds = (sorted([0.0, (stop - start) / pscale[0]]),
              [(values2.min() - v0) / pscale[1], (values2.max() - v0) / pscale[1]])
    curves, ends = [], []
    for p1, y in zip(ds[f"special_{ds.attrs['field']}"].values[fold], ds.special_y0.values[fold]):
        q1 = (p1 - start) / pscale[0]
        if any(abs(x["u"][-2] - q1) < 1e-6 for c in curves for x in at_value(sys, c, 0.0, y)):
            continue                            # on a curve traced before
        if late := out_of_time():
            ends.append((None, f"{late} was reached before the fold at {_at(sys, [q1, 0])} "
                               "was followed"))
            continue
        u0 = np.r_[y[free] / sys.d0[free], q1, 0.0]
        try:
            sys.border(sys.run(u0, y)[1])
            res = sys.correct(u0, np.eye(len(u0))[-1], 0.0, y)
            seed = None if res is None else sys.point(res, y)
        except (SolverError, np.linalg.LinAlgError) as exc:
            seed, sys.last_error = None, str(exc)
        if seed is None:
            ends.append((None, f"the fold at {_at(sys, u0)} was not corrected onto the "
                               f"extended system: {sys.last_error}"))
            continue
        halves = []
        for d in (-1, 1):
            sys.border(seed["M"])
            pts, why = trace(sys, seed, y, bounds, d, **steps)
            halves.append(pts)
            ends.append((pts[-1], why))
        curves.append(halves[0][::-1] + halves[1][1:])
    return sys, curves, ends, tried


def _status(sys, ends, q2):
    """Each value's status: 'complete', or why the curves may miss a fold there: a value
    between the ends of two directions that stopped next to each other (within 0.05 in the
    scaled fields: the same grazing from either side: a gap in the curve), or, where a
    direction stopped and no other end meets it, every value (the curve past the stop is not
    known: it may come back to any value)."""
    out, left = ["complete"] * len(q2), [(p, w) for p, w in ends if w != "complete"]
    while left:
        p, why = left.pop(0)
        near = [j for j, (r, _) in enumerate(left) if p is not None and r is not None and
                np.abs(r["u"][-2:] - p["u"][-2:]).max() < 0.05]
        if near:
            r, _ = left.pop(near[0])
            lo, hi = sorted((p["u"][-1], r["u"][-1]))
            text = f"the fold curve has a gap between {_at(sys, p['u'])} and {_at(sys, r['u'])}"
            hit = (q2 >= lo) & (q2 <= hi)
        else:
            text, hit = "the fold curve stops (its folds past the stop are not followed)", \
                np.ones(len(q2), bool)
        for j in np.flatnonzero(hit):
            out[j] = f"{text}: {why}" if out[j] == "complete" else out[j]
    return out


def curve_dataset(sys, curves, ends, tried, label1, label2, values2, margin=1e-4, graze=None):
    """The fold curves as fold_curve's variables: fold (value2, fold), status (value2), and
    along the curves (dim curve_point): curve, the two fields, y0, Tm_pp, the largest |mu|
    besides the one at +1 (mu_other) and stable; cusps (dim cusp); the grazings of the
    values continued (those tried for a seed); with graze (grazecurve.options), the grazing
    curves through the grazings nearest the folds (grazecurve.variables)."""
    import xarray as xr
    said = [d if isinstance(d, str) else d.attrs["status"] for d in tried]
    if sys is None:     # no value with a fold: each value continued says what it found
        status = [f"{out_of_time()} was reached before {label2} = {v:g} was continued"
                  for v in values2]     # (the values tried say what they found, below)
    else:
        status = _status(sys, ends, (np.asarray(values2) - sys.p0[1]) / sys.pscale[1])
    at = []
    for j, v in enumerate(values2):
        if j < len(tried) - (sys is not None):      # continued, no fold: its own answer
            status[j], xs = said[j], []
        else:
            xs = _folds_at(sys, curves, v)
        at.append(xs)
        if not all(x["exact"] for x in xs) and status[j] == "complete":
            status[j] = "a fold interpolated on the curve's chord (its corrector failed)"
    folds = [[sys.p_of(x["u"])[0] for x in xs] for xs in at]
    with sundials_said("the runs from the folds to their nearest grazings"):    # after the
        near = [[fold_grazing(sys, x["u"], x["y"]) if x["exact"] else   # folds: a time bound
                 (None, "no exact fold") for x in xs] for xs in at]     # cuts only these
    with sundials_said("the runs along the grazing curves"):
        traced = graze_curves(sys, near, [[x["y"] for x in xs] for xs in at], values2, graze) \
            if graze is not None and sys is not None else None
    for j, r in enumerate(near):
        cut = [why for _, why in r if why.endswith(" was reached")]
        if cut and status[j] == "complete":
            status[j] = f"the grazing nearest a fold not searched: {cut[0]}"
    pts = [(i, x) for i, c in enumerate(curves) for x in c]
    stops = [p for p, w in ends if p is not None and w != "complete"]
    other = [np.abs(np.delete(x["mu"], np.argmin(np.abs(x["mu"] - 1)))).max() for _, x in pts]
    cu = [(i, sys.p_of(np.r_[0.0, q])) for i, c in enumerate(curves) for _, q in cusps(c)]
    grazed = [[] if isinstance(d, str) else d[f"special_{label1}"].values[
        d.special_type.values.astype(str) == "grazing"] for d in tried]
    out = xr.Dataset({
        "fold": (("value2", "fold"), _padded(folds)),
        "grazing": (("value2", "grazing"), _padded(grazed + [[]] * (len(values2) - len(grazed)))),
        "fold_grazing": (("value2", "fold"), _padded([[np.nan if g is None else g["p"]
                                                       for g, _ in r] for r in near])),
        "fold_grazing_bracket": (("value2", "fold"), _padded(
            [[np.nan if g is None else g["bracket"] for g, _ in r] for r in near])),
        "status": (("value2",), np.array(status, dtype=object)),
        "curve": (("curve_point",), np.array([i for i, _ in pts], int)),
        "curve_field": (("curve_point",), np.array([x["p"][0] for _, x in pts])),
        "curve_field2": (("curve_point",), np.array([x["p"][1] for _, x in pts])),
        "curve_y0": (("curve_point", "state"), np.array([x["y"] for _, x in pts]).reshape(-1, 14)),
        "curve_Tm_pp": (("curve_point",), np.array([x["Tm_pp"] for _, x in pts])),
        "curve_mu_other": (("curve_point",), np.array(other)),
        "curve_stable": (("curve_point",), (np.array(other) < 1 - margin).astype(np.int8)),
        "stop_field": (("stop",), np.array([p["p"][0] for p in stops])),
        "stop_field2": (("stop",), np.array([p["p"][1] for p in stops])),
        "stop_status": (("stop",), np.array([w for p, w in ends if p is not None
                                             and w != "complete"], dtype=object)),
        "cusp_field": (("cusp",), np.array([p[0] for _, p in cu])),
        "cusp_field2": (("cusp",), np.array([p[1] for _, p in cu])),
        **({} if traced is None else variables(sys, *traced))},
        coords={"value2": values2})
    out.attrs.update(method="extended", seed_status=said[-1] if said else "none",
                     curve_status="; ".join(w for _, w in ends) or "none traced",
                     cusp="; ".join(f"{label1} = {p[0]:.6g}, {label2} = {p[1]:.6g}"
                                    for _, p in cu) or "none",
                     fold_grazing_status="; ".join(
                         f"{label2} = {v:g}, the fold at {label1} = {f:.6g}: {why}"
                         for v, fs, r in zip(values2, folds, near) for f, (_, why) in zip(fs, r)
                         if why != "found") or "complete")
    if traced is not None:
        out.attrs["graze_curve_status"] = "; ".join(traced[1]) or "no grazing to follow"
    return out


def _folds_at(sys, curves, v):
    """The fold points of the curves at the value v of field2 (at_value), in the order of the
    first field, each with its curve's fixed states y."""
    xs = [] if sys is None else [dict(x, y=c[0]["y"]) for c in curves for x in
                                 at_value(sys, c, (v - sys.p0[1]) / sys.pscale[1], c[0]["y"])]
    return sorted(xs, key=lambda x: sys.p_of(x["u"])[0])


def _padded(rows):
    """Rows of different lengths as one array, NaN padded (at least one column)."""
    out = np.full((len(rows), max([len(r) for r in rows] + [1])), np.nan)
    for i, r in enumerate(rows):
        out[i, :len(r)] = r
    return out
