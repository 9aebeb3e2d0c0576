"""A fold of a periodic orbit followed in two fields by the minimally extended system
(docs/continuation.md, `fold_curve`).

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
of the orbit must stay the seed's (the saltation in M holds within one contact sequence):
where it changes, the direction stops ('grazing at ...'). Nothing here computes physics: the
map, M and the trajectories are the core's."""
from __future__ import annotations

import numpy as np

from .arclength import _null_tangent, field_label, set_field
from .errors import CaseError, SolverError, SplineWarning
from .orbits import _scale, _trajectory, forcing_periods, map_and_monodromy, out_of_time
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
            import warnings
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

    def run(self, u, y_fixed):
        """(F, M) at u, in the seed's scales (one variational run)."""
        p = self.p_of(u)
        model = self.model(p)
        y = self.state(u, y_fixed)
        t1 = self.t0 + 2 * np.pi * self.n / model.info()["omega"]
        y1, Mp, free = map_and_monodromy(model, self.t0, t1, y)
        d = _scale(model)[free] / self.d0[free]
        return (y1 - y)[free] / self.d0[free], d[:, None] * Mp / d[None, :]

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
        p = self.p_of(u)
        y = self.state(u, y_fixed)
        model = self.model(p)
        t1 = self.t0 + 2 * np.pi * self.n / model.info()["omega"]
        import warnings
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", SplineWarning)
            tr = _trajectory(model.case, self.t0, t1, y)
        return dict(u=u, J=J, p=p, y=y, M=M, mu=multipliers(M), iterations=it,
                    contact=contact_measures(tr), Tm_pp=float(np.ptp(tr.Tm)))


def trace(sys, seed, y_fixed, bounds, direction, ds=0.05, ds_min=1e-3, ds_max=0.5,
          max_angle=0.3, max_points=100):
    """One direction of the fold curve from the seed point (a record of sys.point): the points
    in order and what ended it ('complete': the curve left the rectangle `bounds` ((q1 lo,
    hi), (q2 lo, hi)), its last point put on the side it crossed; 'grazing at ...': the contact
    signature changed, located to ds_min along the curve; or where and why it failed)."""
    k2 = len(seed["u"])
    sig0 = seed["contact"]["signature"]
    tau = _null_tangent(seed["J"], direction * np.eye(k2)[-1])
    pts, a = [seed], dict(seed, tau=tau)
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
                return pts, (f"grazing at {_at(sys, new['u'])}: the contact sequence changes "
                             f"between it and {_at(sys, a['u'])} (a fold past a grazing, "
                             "non-smooth, is not followed by the extended system)")
            new = None
        if new is None:
            ds = min(ds, step) / 2
            if ds < ds_min:
                return pts, (f"the fold curve's corrector failed at {_at(sys, pred)} with the "
                             f"step down to {ds:.3g}: {sys.last_error}")
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


def _at(sys, u):
    p = sys.p_of(u)
    return ", ".join(f"{field_label(*f)} = {v:.6g}" for f, v in zip(sys.fields, p))


def cusps(pts):
    """The cusps of a traced curve (points in order): where the q2 component of the secant
    changes sign, the field values at the q2 extremum of the parabola in arclength through
    the three points around it."""
    u = np.array([p["u"] for p in pts])
    out = []
    for i in range(1, len(u) - 1):
        d0, d1 = u[i, -1] - u[i - 1, -1], u[i + 1, -1] - u[i, -1]
        if d0 * d1 < 0:
            s = np.r_[0, np.cumsum(np.linalg.norm(np.diff(u[i - 1:i + 2], axis=0), axis=1))]
            c = np.polyfit(s, u[i - 1:i + 2, -1], 2)
            sc = -c[1] / (2 * c[0])
            out.append((i, [np.polyval(np.polyfit(s, u[i - 1:i + 2, j], 2), sc)
                            for j in (-2, -1)]))
    return out


def at_value(sys, pts, q2, y_fixed):
    """The fold points of the traced curve at q2 (the field fixed there): the crossings of
    each segment, corrected from the chord's point; a point on q2 itself as it is. (p1s,
    states)."""
    found = []
    for a, b in zip(pts, pts[1:]):
        fa, fb = a["u"][-1] - q2, b["u"][-1] - q2
        if fa == 0 or fa * fb >= 0:
            continue
        if fb == 0:
            found.append(b)
            continue
        u = a["u"] + fa / (fa - fb) * (b["u"] - a["u"])
        res = sys.correct(u, np.eye(len(u))[-1], q2, y_fixed)
        found.append(dict(u=u, y=sys.state(u, y_fixed)) if res is None else
                     dict(u=res[0], y=sys.state(res[0], y_fixed)))
    if pts and pts[0]["u"][-1] == q2:
        found.insert(0, pts[0])
    return found
