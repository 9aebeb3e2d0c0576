"""Pseudo-arclength continuation of a periodic orbit in one case field (docs/continuation.md).

The unknowns are u = (z, q): z the section state of the orbit over the integrated states,
scaled by Eq. 25 with the scales of the start point (l_ref, l_ref w_ref), q = (p - start) /
|stop - start| the field. The residual F(z, p) = P^n_p(y) - y and its monodromy M come from
the core through orbits.map_and_monodromy (the case rebuilt at p, the map over the period
2 pi n / omega(p)); dF/dp by central differences of the map at p +- h. Predictor along the
tangent of the branch, corrector Newton on [F; tangent . (u - u_pred)] with the bordered
Jacobian [[M - I, dF/dq], [tangent^T]]. Special points are located by the Illinois secant on
a test function of the multipliers (folds, period doublings, Neimark-Sacker points) or by
bisection on the contact sequence of the orbit's trajectory (grazing). Nothing here computes
physics: the map, M and the trajectories are the core's.
"""
from __future__ import annotations

import re
import time
import warnings

import numpy as np

from .case import Case, defaults, load_case
from .core import load, sundials_said
from .dataset import continuation_dataset
from .errors import CaseError, SolverError, SplineWarning
from .orbits import (CALL_SECONDS, OrbitError, _period_map, _scale, _trajectory, fd_monodromy,
                     forcing_periods, map_and_monodromy, out_of_time, periodic_orbit,
                     section_points, time_bound)
from . import ends, specials
from .specials import SPECIAL_TYPES, contact_measures, locate, multipliers, smooth, tests

__all__ = ["continuation", "SPECIAL_TYPES"]

#: run-control and identity fields: not physical parameters of the orbit
_NOT_CONTINUABLE = {"t0", "t_end", "t_transient", "rtol", "atol", "revolutions",
                    "transient_revolutions", "outputs_per_revolution", "dq0", "dv0",
                    "lyapunov_d0", "h_max", "h0", "max_step", "h_min"}


def parse_field(case: Case, field: str) -> tuple[str, int | None]:
    """'speed_rpm' -> ('speed_rpm', None); 'ripple_amp' or 'ripple_amp(2)' -> (name, index 0
    or 1): an array field is continued in one element (1-based in the text, first by default).
    CaseError naming the field when it is unknown, not a real number or a run setting."""
    m = re.fullmatch(r"\s*([a-z_][a-z0-9_]*)\s*(?:\(\s*(\d+)\s*\))?\s*", str(field).lower())
    if not m:
        raise CaseError(f"case {case.name}: field {field!r}: expected NAME or NAME(i)")
    name, idx = m.group(1), m.group(2)
    known = defaults()
    if name not in known:
        raise CaseError(f"case {case.name}: unknown field '{name}' to continue (see "
                        "cases/template.nml)")
    value = known[name]
    arr = isinstance(value, (list, tuple))
    elem = value[0] if arr and len(value) else value
    if name in _NOT_CONTINUABLE or isinstance(elem, (bool, str, int)) or not isinstance(elem, float):
        raise CaseError(f"case {case.name}: field {name} cannot be continued: a periodic orbit "
                        "is continued in a real-valued physical field (speed_rpm, t_d, l_x, "
                        "ripple_amp, unbalance, ...), not a whole number, an option or a run "
                        "setting")
    if idx is not None and not arr:
        raise CaseError(f"case {case.name}: field {name} is not an array: no index ({field})")
    if arr:
        i = 0 if idx is None else int(idx) - 1
        if not 0 <= i < len(value):
            raise CaseError(f"case {case.name}: field {field}: index out of 1..{len(value)}")
        return name, i
    return name, None


def check_arguments(case, label, start, stop, n, tol, **positive):
    """(start, stop, tol) as floats, tol's default 100 rtol; CaseError naming the argument when
    start or stop is not a finite number or they are equal, n not a whole number >= 1, tol or
    one of `positive` (ds, ds_min, ds_max, ...) not a finite number > 0, ds_min > ds_max."""
    def bad(arg, value, why):
        raise CaseError(f"case {case.name}: continuation in {label}: {arg} = {value!r}: {why}")
    if isinstance(n, bool) or not isinstance(n, (int, np.integer)) or n < 1:
        bad("n", n, "the shaft revolutions of the period must be a whole number >= 1")
    tol = 100 * case["rtol"] if tol is None else tol
    out = {}
    for arg, value in dict(start=start, stop=stop, tol=tol, **positive).items():
        try:
            out[arg] = float(value)
        except (TypeError, ValueError):
            bad(arg, value, "not a number")
        if not np.isfinite(out[arg]):
            bad(arg, value, "must be finite")
        if arg not in ("start", "stop") and not out[arg] > 0:
            bad(arg, value, "must be > 0")
    if out["start"] == out["stop"]:
        bad("stop", stop, "start and stop must differ")
    if out.get("ds_min", 0) > out.get("ds_max", np.inf):
        bad("ds_min", positive["ds_min"], f"greater than ds_max = {positive['ds_max']!r}")
    return out["start"], out["stop"], out["tol"]


def _checked(base, field, start, stop, n, *, tol, max_points, max_corrector, monodromy,
             switch=True, detect=True, band=None, **positive):
    """continuation's arguments checked (CaseError naming the one that is bad; start and stop
    valid values of the field, with the forcing periodic over n revolutions; band valid
    values holding them): (its _Problem, the field's label, start, stop, tol); prob.band:
    the range of the doubled branches in q."""
    name, index = parse_field(base, field)
    label = field_label(name, index)
    start, stop, tol = check_arguments(base, label, start, stop, n, tol, **positive)
    for arg, whole, least in (("max_points", max_points, 1), ("max_corrector", max_corrector, 0)):
        if isinstance(whole, bool) or not isinstance(whole, (int, np.integer)) or whole < least:
            raise CaseError(f"case {base.name}: continuation in {label}: {arg} = {whole!r}: a "
                            f"whole number >= {least}")
    if monodromy not in ("exact", "fd"):
        raise CaseError(f"case {base.name}: monodromy = {monodromy!r}: 'exact' (variational "
                        "equations) or 'fd' (central differences of the map)")
    prob = _Problem(base, name, index, n, start, stop, float(base["t0"]), monodromy)
    try:
        ends = sorted(map(float, (start, stop) if band is None else band))
    except (TypeError, ValueError):
        ends = []
    if len(ends) != 2 or not np.isfinite(ends).all() or ends[0] > min(start, stop) \
            or ends[1] < max(start, stop):
        raise CaseError(f"continuation in {label}: band = {band!r}: two values holding start "
                        f"= {start:g} and stop = {stop:g}")
    for arg, value in (("stop", stop), ("start", start), ("band", ends[0]), ("band", ends[1])):
        valid_value(prob.model, value, label, f"continuation in {label}: {arg} = ")
    prob.band = tuple((v - start) / prob.pscale for v in ends)
    h = prob.h * max(abs(start), prob.pscale)       # evaluate's difference step at start
    why = []
    for p in (start + h, start - h):
        try:
            prob.model(p)
            break
        except CaseError as exc:
            why.append(str(exc))
    else:
        raise CaseError(f"case {base.name}: field {label} cannot be continued: its valid values "
                        f"are isolated (none within {h:.3g} of start = {start:g}: {why[0]}); "
                        "continuation follows a field that varies continuously")
    return prob, label, start, stop, tol


def valid_value(load_at, value: float, label: str, prefix: str):
    """load_at(value): the model of a case with a field (its `label`) at value, checked by
    loading it; CaseError '{prefix}{value} is not a valid value of {label}: why' where it fails
    (continuation's start and stop, fold_curve's values of its second field)."""
    try:
        return load_at(value)
    except CaseError as exc:
        raise CaseError(f"{prefix}{value:g} is not a valid value of {label}: {exc}") from None


#: continuation's arguments that branches and fold_curve set themselves (not in their **cont)
_OWN = ("case", "field", "start", "stop", "n", "guess", "progress", "command", "max_seconds",
        "band", "keep_interrupted")


def check_handed_on(case, field, start, stop, n, cont: dict) -> None:
    """CaseError, before anything runs, for what continuation would refuse among the keywords
    `cont` that branches and fold_curve hand on to it: a name it does not take (or one they
    set themselves), or a bad value (continuation's checks, its defaults for the rest)."""
    import inspect
    params = inspect.signature(continuation).parameters
    for k, v in cont.items():
        if k not in params or k in _OWN:
            raise CaseError(f"{k} = {v!r}: not a keyword of continuation to hand on (those are "
                            f"{', '.join(k for k in params if k not in _OWN)})")
    _checked(load_case(case), field, start, stop, n, **{
        k: p.default for k, p in params.items() if k not in _OWN} | cont)


def set_field(case: Case, name: str, index, p: float) -> Case:
    """The case with field `name` (its element `index` of an array field) set to p."""
    if index is None:
        return case.replace(**{name: float(p)})
    v = list(case[name])
    v[index] = float(p)
    return case.replace(**{name: v})


def field_label(name: str, index) -> str:
    return name if index is None else f"{name}({index + 1})"


class _Problem:
    """The case at a value p of the field, its map and monodromy in the start's scales."""

    def __init__(self, case, name, index, n, start, stop, t0, monodromy="exact"):
        self.case, self.name, self.index, self.n = case, name, index, n
        self.set_monodromy(monodromy)
        # a tenth of the field's magnitude is one unit of q, as l_ref is of the states: the
        # scaling and the difference step of dF/dp do not depend on the band's width
        self.p0, self.pscale = float(start), 0.1 * max(abs(float(start)), abs(float(stop)))
        self.t0 = t0
        self.models, self.log, self.jumps, self.unlocated, self.diagnosed = {}, [], 0, 0, 0
        self.evals = 0      # corrector iterations so far (ends.FAILED_EVALS)
        self.d0 = _scale(self.model(self.p0))
        self.rtol = case["rtol"]
        # dF/dp's difference step: rtol^(1/2), not the smooth optimum rtol^(1/3) (+-5 r/min
        # at 2400 r/min and rtol 1e-8), which straddles a grazing next to a fold and stalls
        # Newton there (M is exact; dF/dp enters the Newton step and the null-vector tangent)
        self.h = self.rtol ** 0.5

    def set_monodromy(self, monodromy):
        self.how = monodromy
        self.monodromy = map_and_monodromy if monodromy == "exact" else fd_monodromy

    def set_method(self, method):
        """The case's integrator ('adams', 'bdf', 'erk', ...): the models rebuilt."""
        self.case, self.models = self.case.replace(method=method), {}

    def case_at(self, p: float) -> Case:
        return set_field(self.case, self.name, self.index, p)

    def model(self, p: float):
        """The loaded case at p; CaseError when p is outside the field's valid range or the
        forcing does not repeat in the orbit's period there."""
        m = self.models.get(p)
        if m is None:
            if len(self.models) > 8:
                self.models.clear()
            with warnings.catch_warnings():     # the case's notes: said once, at the start
                if self.models or hasattr(self, "d0"):
                    warnings.simplefilter("ignore", SplineWarning)
                m = load(self.case_at(p))
            forcing_periods(m.case, self.n)
            self.models[p] = m
        return m

    def t1(self, p: float, n: int) -> float:
        return self.t0 + 2 * np.pi * n / self.model(p).info()["omega"]

    def p_of(self, q: float) -> float:
        return self.p0 + q * self.pscale

    def state(self, y_fixed, u):
        """The state (14,), SI, of u = (z, q): y_fixed with z in the integrated states."""
        y = np.array(y_fixed, float)
        y[self.free] = u[:-1] * self.d0[self.free]
        return y

    def sections(self, pt):
        """The scaled unknowns u of the branch point pt (a record of _Branch.point) at each of
        its orbit's section points (orbits.section_points), its own first; its own alone
        when a map run fails (or the time bound has passed)."""
        try:
            ys = section_points(self.model(pt["p"]), self.t0, pt["n"], pt["y"])
        except SolverError:
            ys = pt["y"][None]
        return np.c_[ys[:, self.free] / self.d0[self.free], np.full(len(ys), pt["u"][-1])]

    def evaluate(self, y_fixed, u, n):
        """At u = (z, q): F (k,), J = [M - I, dF/dq] (k, k+1), M (k, k), the state y (14,)."""
        p = self.p_of(u[-1])
        y = self.state(y_fixed, u)
        model = self.model(p)
        self.evals += 1
        F, M, free = scaled_map(self.monodromy, model, self.t0, self.t1(p, n), y, self.d0)
        hp = self.h * max(abs(p), self.pscale)
        Fq = {}
        for pp in (p + hp, p - hp):
            try:
                mm = self.model(pp)
            except CaseError:       # the field's range ends within hp: one-sided
                continue
            y1p, _, _ = _map_only(mm, self.t0, self.t1(pp, n), y)
            Fq[pp] = (y1p - y)[free] / self.d0[free]
        if not Fq:
            raise CaseError(f"case {self.case.name}: {self.name} = {p:.6g}: no valid value "
                            f"within {hp:.3g} of it for the difference dF/d{self.name}")
        (pa, Fa), (pb, Fb) = (list(Fq.items()) + [(p, F)])[:2]
        J = np.c_[M - np.eye(len(M)), (Fa - Fb) / ((pa - pb) / self.pscale)]
        return F, J, M, y


def scaled_map(monodromy, model, t0, t1, y, d0):
    """F = P(y) - y and M = dP/dy over the integrated states of the period map from (t0, y) to
    t1 (monodromy: orbits.map_and_monodromy or fd_monodromy), in the scales d0 (Eq. 25 at the
    start: one unit of each state however far the field moves), and those states' indices."""
    y1, Mp, free = monodromy(model, t0, t1, y)
    d = _scale(model)[free] / d0[free]
    return (y1 - y)[free] / d0[free], d[:, None] * Mp / d[None, :], free


def _null_tangent(J, orient):
    """The unit null vector of J (k, k+1), oriented along orient (orient itself when the
    bordered system is singular)."""
    try:
        tau = np.linalg.solve(np.vstack([J, orient]), np.eye(J.shape[1])[-1])
    except np.linalg.LinAlgError:
        tau = np.array(orient, float)
    return tau / np.linalg.norm(tau)


def _map_only(model, t0, t1, y):
    """The core's map alone (no monodromy): (y1, None, free)."""
    y1, free = _period_map(model, t0, t1, np.asarray(y, float)[:, None])
    return y1[:, 0], None, free


# --------------------------------------------------------------------------- the branch

class _Branch:
    def __init__(self, prob: _Problem, n: int, y_fixed, tol, max_corr):
        self.prob, self.n, self.y_fixed, self.tol, self.max_corr = prob, n, y_fixed, tol, max_corr

    def correct(self, u_pred, row, target):
        """Newton on [F(u); row . u - target] from u_pred. (u, F, J, M, y, iterations,
        residual history) or None when it does not converge."""
        u = u_pred.copy()
        hist = []
        for it in range(self.max_corr + 1):
            try:
                F, J, M, y = self.prob.evaluate(self.y_fixed, u, self.n)
            except (SolverError, CaseError) as exc:   # a run of the map failed, or the
                # point is outside the field's valid range: this step fails
                self.last_hist = hist + [np.nan]
                self.last_error = str(exc)
                return None
            r = float(np.abs(F).max())
            hist.append(r)
            if r <= self.tol and it > 0 or (r <= self.tol and abs(row @ u - target) < 1e-12):
                return u, F, J, M, y, it, hist
            if it == self.max_corr or (it >= 2 and r > hist[-2]) or not np.isfinite(r):
                break
            A = np.vstack([J, row])
            try:
                du = np.linalg.solve(A, -np.r_[F, row @ u - target])
            except np.linalg.LinAlgError:
                break
            u = u + du
        self.last_hist = hist
        return None

    def point(self, res, prev):
        """The record of the corrector's converged point res and its tangent: the secant from
        prev, the branch point before it; at a branch's first point (prev the direction to
        head in) the null vector of J oriented along prev. (The secant is what the predictor
        follows: near a grazing dF/dp by differences of the map over +-h is a secant across
        contact changes, and the null vector of J is off the branch.) None when the point's
        one-period state run fails (last_error says why): the step fails."""
        u, F, J, M, y, it, hist = res
        tau = u - prev["u"] if isinstance(prev, dict) else np.zeros_like(u)
        tau = tau / np.linalg.norm(tau) if np.linalg.norm(tau) > 0 else \
            _null_tangent(J, prev["tau"] if isinstance(prev, dict) else prev)
        mu = multipliers(M)
        p = self.prob.p_of(u[-1])
        try:
            tr = self.trajectory(y, p)
        except SolverError as exc:
            self.last_hist, self.last_error = hist, str(exc)
            return None
        return dict(u=u, tau=tau, p=p, y=y, M=M, J=J, mu=mu, tests=tests(mu),
                    contact=contact_measures(tr), Tm_pp=float(np.ptp(tr.Tm)),
                    F_max=float(np.abs(tr.tooth["F"]).max()), D2_pp=float(np.ptp(tr.D2)),
                    residual=hist[-1], iterations=it, n=self.n)

    def trajectory(self, y, p):
        """One period of the run from state y at the field's value p (the core's Result)."""
        prob = self.prob
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", SplineWarning)
            return _trajectory(prob.case_at(p), prob.t0, prob.t1(p, self.n), y)

    def signature(self, u):
        """The contact signature of the run of one period from u (a predictor); None when the
        run fails or u is outside the field's valid range."""
        try:
            return contact_measures(self.trajectory(self.prob.state(self.y_fixed, u),
                                                    self.prob.p_of(u[-1])))["signature"]
        except (SolverError, CaseError):
            return None

    def restart(self, a, sigma, periods=3):
        """The branch point at sigma along a's tangent, the corrector started from the state a
        short simulation (`periods` periods of the map) reaches from the predictor: for a
        predictor just past a grazing that the corrector fails from. None when it fails or
        lands further than sigma from the predictor."""
        prob = self.prob
        pred = a["u"] + sigma * a["tau"]
        p = prob.p_of(pred[-1])
        try:
            y = prob.state(self.y_fixed, pred)
            for _ in range(periods):
                y = _map_only(prob.model(p), prob.t0, prob.t1(p, self.n), y)[0]
        except (SolverError, CaseError):
            return None
        start = np.r_[y[prob.free] / prob.d0[prob.free], pred[-1]]
        return specials.point_at(self, a, sigma, start)


def continuation(case, field: str, start: float, stop: float, n: int = 1, guess=None, *,
                 ds: float = 0.05, ds_min: float = 1e-4, ds_max: float = 0.25, max_angle: float = 0.15,
                 max_points: int = 200, tol: float | None = None, max_corrector: int = 6,
                 margin: float = 1e-4, switch: bool = True, detect: bool = True,
                 monodromy: str = "exact", progress: bool = True, command: str | None = None,
                 max_seconds: float = CALL_SECONDS, band=None, keep_interrupted: bool = False):
    """Pseudo-arclength continuation of the period-n orbit of `case` in `field` from `start`
    to `stop`, through stable and unstable parts; returns an xarray.Dataset.

    field : a real case field ('speed_rpm', 't_d', 'l_x', 'ripple_amp' (its first element),
        'ripple_amp(2)', 'unbalance(1)', ...). CaseError naming it otherwise.
    guess : the orbit's state (14,), SI, at t0 for `start` (default: periodic_orbit's, the end
        of a settled run of the case at `start`).
    ds, ds_min, ds_max : arclength steps in the units of u = (z, q): the section state scaled
        by Eq. 25 and q = (p - start) / (max(|start|, |stop|) / 10), the same whatever the
        band's width. A step whose corrector needs <= 2 iterations grows 1.5x, one that needs
        >= 4 shrinks; a failed one halves (a run of the map that fails, a point outside the
        field's valid range, a converged point further from its predictor than the step or
        whose contact sequence changed with no grazing located between, i.e. on another
        branch, fail it), unless its predictor changes the contact sequence and the grazing
        is located on the step: the branch goes on past it; below ds_min (or past the halvings'
        share of the failed-step bound, ends.halvings_end) the other monodromy, then the other
        integrator (ERK, or BDF for ERK) are tried (attrs['fallbacks']); when they fail too,
        the branch so far is returned with attrs['status'] saying where and why, and a
        SplineWarning. max_angle [rad]: a step whose tangent turns more than twice it is
        halved; the next step is scaled to turn by about it.
    tol : the corrector's scaled residual max |P^n(y) - y| (default 100 rtol).
    margin : stable means every |mu| < 1 - margin.
    switch : at a period doubling continue the doubled branch (n -> 2n) from it along the
        critical eigenvector, over `band`.
    band : (a, b) holding start and stop: the range of the field over which doubled branches
        are followed (default start..stop; branches gives each seed's halves the whole band).
    detect : report folds, period doublings, Neimark-Sacker points, grazings and non-smooth
        folds (grazings are located while following either way).
    monodromy : 'exact' (variational equations, one run per corrector iteration) or 'fd'
        (central differences of the map, 2k + 1 runs: for checking, bench/continuation.py).
    max_seconds : the wall time of the call (orbits.CALL_SECONDS; math.inf: none): past it the
        branch so far is returned with its status saying so (special points not yet located
        stay so).
    keep_interrupted : Ctrl-C (KeyboardInterrupt) while a branch is followed returns the points
        so far, status 'interrupted (Ctrl-C) at ...' (`pyspline continue`); default: raised.

    Dataset: dim 'point' (the branch points in order; variable 'branch' numbers the branches,
    'n' their periods): the field's value, y0 (point, state), Tm_pp, F_max, D2_pp, the
    multipliers (mu_real, mu_imag, mu_abs; dim 'multiplier', largest modulus first), stable,
    closest_approach, switches, residual, iterations; dim 'special': type, the field's value,
    branch, the critical multiplier, Tm_pp, F_max, y0. attrs: case, field, start, stop, n,
    timing, status ('complete', or where and why it stopped), fallbacks, rejected_jumps (steps
    whose corrector landed on another branch), rejected_unlocated (steps whose contact
    sequence changed with no grazing located), diagnosed_grazings (failed steps carried
    across a grazing).

    CaseError naming the argument for bad input: start == stop, a start or stop outside the
    field's valid range, a non-finite or non-positive ds, ds_min, ds_max, max_angle or tol,
    ds_min > ds_max, max_points < 1, n not a whole number >= 1. OrbitError when no orbit is
    found at the start."""
    from tqdm import tqdm
    base = load_case(case)
    wall0 = time.perf_counter()
    prob, label, start, stop, tol = _checked(
        base, field, start, stop, n, tol=tol, ds=ds, ds_min=ds_min, ds_max=ds_max,
        max_angle=max_angle, margin=margin, max_points=max_points, max_corrector=max_corrector,
        monodromy=monodromy, band=band)
    t0 = prob.t0
    c0 = prob.case_at(start)
    with sundials_said("the continuation's map runs") as said, \
            time_bound(max_seconds, f"continuation (case {base.name})"):
        orbit = periodic_orbit(c0, n=n, guess=guess, tol=tol, monodromy=monodromy)
        prob.free = _map_only(prob.model(start), t0, prob.t1(start, n), orbit.y0)[2]
        k = int(prob.free.sum())
        branches, found, status = [], [], "complete"
        bar = tqdm(total=max_points, desc=f"continue {label}", unit="point", disable=not progress,
                   dynamic_ncols=True)
        try:
            u0 = np.r_[orbit.y0[prob.free] / prob.d0[prob.free], 0.0]
            todo = [(n, u0, None, orbit.y0.copy())]
            while todo and sum(len(b) for b in branches) < max_points:
                nb, u_start, tau0, y_fixed = todo.pop(0)
                br = _Branch(prob, nb, y_fixed, tol, max_corrector)
                q_end = (stop - start) / prob.pscale
                try:
                    pts, why = _follow(br, u_start, tau0, q_end, sorted((0.0, q_end)) if tau0
                                       is None else prob.band, ds, ds_min, ds_max, max_angle,
                                       max_points - sum(len(b) for b in branches),
                                       len(branches), bar)
                except KeyboardInterrupt:       # Ctrl-C: the points so far are the result
                    pts, todo = getattr(br, "pts", []), []
                    if not keep_interrupted or not pts and not branches:
                        raise
                    why = INTERRUPTED + (f" at {prob.name} = {pts[-1]['p']:.6g}" if pts else "")
                ends.use(prob, monodromy, base["method"])
                if why != "complete" and (status == "complete" or why.startswith(INTERRUPTED)):
                    status = why
                branches.append(pts)
                if detect and not out_of_time() and not why.startswith(INTERRUPTED):
                    for sp in locate(br, pts):
                        sp["branch"] = len(branches) - 1
                        found.append(sp)
                        if (sp["type"] == "period_doubling" and switch and len(branches) < 4
                                and nb <= 4 * n and smooth(sp) and not sp.get("merge")):
                            todo.append(_doubled_start(sp, nb, y_fixed))
        finally:
            bar.close()
        found = specials.once(found, prob.sections, tol)    # a point located twice, once
    wall = time.perf_counter() - wall0
    if status != "complete":
        warnings.warn(f"{status}: the branch so far is returned ({sum(map(len, branches))} "
                      "points; attrs['status'])", SplineWarning, stacklevel=2)
    return continuation_dataset(base, prob, label, branches, found, margin, k, dict(
        start=start, stop=stop, n=n, tol=tol, wall_s=wall, monodromy=monodromy, status=status,
        fallbacks="; ".join(prob.log) or "none", rejected_jumps=prob.jumps,
        rejected_unlocated=prob.unlocated, diagnosed_grazings=prob.diagnosed,
        sundials_warnings=said["runs"],
        command=command or f"pyspline.continuation({base.name!r}, {label!r}, {start:g}, "
                           f"{stop:g}, n={n})"))


def _doubled_start(sp, nb, y_fixed):
    """The start of the doubled branch at a period doubling: the point, with a tangent along
    the eigenvector of the multiplier at -1 (in z; the field fixed)."""
    w, V = np.linalg.eig(sp["M"])
    v = np.real(V[:, np.argmin(np.abs(w + 1))])
    tau = np.r_[v / np.linalg.norm(v), 0.0]
    return (2 * nb, sp["u"], tau, y_fixed)


#: the status of a continuation stopped by Ctrl-C (KeyboardInterrupt), its points kept
INTERRUPTED = "interrupted (Ctrl-C)"


def _follow(br, u0, tau0, q_end, bounds, ds, ds_min, ds_max, max_angle, max_points, ibranch,
            bar):
    """The points of one branch from u0 and what ended it: predictor-corrector until q leaves
    bounds (the last point put on its end: 'complete'), max_points, a step that fails below
    ds_min with every fallback (the other monodromy, then the other integrator) or after
    ends.FAILED_EVALS corrector iterations from its point, a period doubling where the branch
    merges into the period-n/2 one (past it, or its steps failing next to it: located, the
    last point's 'merge') or its own orbit
    reached again (ends): a sentence saying where and why. A converged point further from its
    predictor than the step itself, or whose contact sequence changed with no grazing located
    between (specials.graze), is on another branch: a rejected step. A failed step whose
    predictor changes the contact sequence is carried across the grazing (specials.diagnose)
    before it is shrunk."""
    prob = br.prob
    k = len(u0)
    e_q = np.eye(k)[-1]
    head = np.sign(q_end) * e_q if tau0 is None else tau0     # the way the branch goes
    if tau0 is None:                  # the first branch: start on the orbit, head to stop
        first = br.correct(u0, e_q, u0[-1])
        first = None if first is None else br.point(first, head)
        if first is None:
            _fail(br, u0, ds, "at the start")
        pts = br.pts = [first]      # br.pts: the points so far, kept on Ctrl-C
    else:                             # a doubled branch: off the point along tau0
        tau = tau0
        res = br.correct(u0 + ds * tau, tau, tau @ (u0 + ds * tau))
        new = None if res is None or not ends.new_orbit(br, res[4], res[0]) else br.point(res, tau)
        if new is None:
            warnings.warn(f"case {prob.case.name}: no period-{br.n} branch found next to the "
                          f"period doubling at {prob.name} = {prob.p_of(u0[-1]):.6g}",
                          SplineWarning, stacklevel=3)
            return [], "complete"
        pts = br.pts = [new]
    bar.update(1)
    lo, hi = bounds

    def inside(q):                    # q within the bounds, to round-off
        return lo - 1e-12 <= q <= hi + 1e-12
    fallbacks = ends.fallbacks(prob)
    primary, on_fallback = (prob.how, prob.case["method"]), 0
    mark = prob.evals               # corrector iterations at the last point (but diagnoses)
    while len(pts) < max_points:
        if late := out_of_time():
            return pts, f"{late} was reached at {prob.name} = {pts[-1]['p']:.6g}"
        a = pts[-1]
        step = ds
        pred = a["u"] + ds * a["tau"]
        end = None
        if not inside(pred[-1]):
            end = hi if pred[-1] > hi else lo
            res = None
            if abs(a["tau"][-1]) > 1e-3:      # the last step: onto the end, the field fixed
                step = (end - a["u"][-1]) / a["tau"][-1]
                pred = a["u"] + step * a["tau"]
                res = br.correct(pred, e_q, end)
        else:
            res = br.correct(pred, a["tau"], a["tau"] @ pred)
            if res is not None and not inside(res[0][-1]):
                end = hi if res[0][-1] > hi else lo     # converged past the end: onto it
                res = _onto(br, res[0], pred, ds, end)
        if res is not None and end is None and specials.far(res[0], pred, ds):
            br.last_hist, br.last_error = res[6], (
                f"the corrector went {np.linalg.norm(res[0] - pred):.3g} from a predictor "
                f"{ds:.3g} along the branch (another branch)")
            res, prob.jumps = None, prob.jumps + 1
        new = None if res is None else br.point(res, a)
        if new is not None and new["contact"]["signature"] != a["contact"]["signature"]:
            loc = specials.graze(br, a, new, float(a["tau"] @ (new["u"] - a["u"])))
            if loc is None:
                br.last_hist, br.last_error = res[6], (
                    f"the contact sequence changed ({a['contact']['switches']} to "
                    f"{new['contact']['switches']} switches a period) with no grazing located "
                    "between (another branch)")
                new, prob.unlocated = None, prob.unlocated + 1
            else:
                new["grazing"] = loc[-1]
        if new is None:
            lost = prob.evals - mark
            if lost > ends.FAILED_EVALS:
                return pts, _where(br, pred, ds, f"after point {len(pts)} of branch {ibranch} "
                                   f"within the bound of {ends.FAILED_EVALS} corrector iterations "
                                   f"for a point's failed steps ({lost} taken)")
            e = prob.evals      # the diagnosis, once a point, is bounded on its own
            crossed = specials.diagnose(br, a, pred, step) if step > 0 else None
            mark += prob.evals - e
            # none past the end (those crossings are not the branch's: it ends before them)
            crossed = [c for c in crossed or () if inside(c["u"][-1])]
            if crossed:
                pts += crossed
                bar.update(len(crossed))
                prob.diagnosed, mark = prob.diagnosed + 1, prob.evals
                continue
            if not a.get("null"):   # the secant can be off after a kink: the null vector once
                a["tau"], a["null"] = _null_tangent(a["J"], a["tau"]), True
                continue
            ds /= 2
            if ds < ds_min or ends.halvings_end(lost, len(fallbacks)):
                if br.n % 2 == 0 and not a.get("merge_tried"):    # next to its doubling?
                    e, a["merge_tried"] = prob.evals, True      # bounded on its own
                    sp = ends.reached_merge(br, pts)
                    mark += prob.evals - e
                    if sp:
                        a["merge"] = sp
                        return pts, ends.merge_words(br, a, sp["p"])
                if not fallbacks:
                    return pts, _where(br, pred, ds, f"after point {len(pts)} of branch {ibranch}")
                ends.use(prob, *fallbacks.pop(0))
                prob.log.append(f"{prob.name} = {a['p']:.6g}: {prob.how} monodromy, method "
                                f"{prob.case['method']} ({getattr(br, 'last_error', '')})")
                _retangent(br, a, a["u"] - pts[-2]["u"] if len(pts) > 1 else head)
                ds, on_fallback = min(ds_max, 64 * ds_min), 5
            continue
        it = res[5]
        angle = np.arccos(np.clip(new["tau"] @ a["tau"], -1, 1))
        if angle > 2 * max_angle and ds > ds_min:      # the branch turns: a shorter step
            ds = max(ds_min, ds / 2)
            continue
        secs = prob.sections(new)
        if merged := ends.merged(br, a, new, secs):
            if sp := ends.merge_doubling(br, pts, new):
                a["merge"] = sp
            return pts, merged
        if back := ends.returned(br, pts, new, secs):
            return pts, back
        pts.append(new)
        bar.update(1)
        mark = prob.evals
        if end is not None:
            return pts, "complete"
        if on_fallback:                 # a few points on the fallback, then the primary again
            on_fallback -= 1
            if not on_fallback:
                ends.use(prob, *primary)
                fallbacks = ends.fallbacks(prob)
        grow = 1.5 if it <= 2 else (0.6 if it >= 4 else 1.0)
        ds = max(ds_min, min(ds_max, ds * grow, ds * max_angle / max(angle, 1e-12)))
    return pts, f"max_points = {max_points} reached at {prob.name} = {pts[-1]['p']:.6g}"


def _retangent(br, a, orient):
    """a's tangent from the integrator and monodromy now in use (a fallback's): the null vector
    of their [M - I, dF/dq] at a, oriented along orient (the secant from the point before, or
    the way the branch goes at its first point), not the tangent a had: the failed
    integrator's, whose dF/dp can be wrong. Kept when the run fails."""
    try:
        a["J"] = br.prob.evaluate(br.y_fixed, a["u"], br.n)[1]
    except (SolverError, CaseError):
        return
    a["tau"], a["null"] = _null_tangent(a["J"], orient), True


def _onto(br, u, pred, ds, end):
    """The corrector from u (a point converged past the field's end, pred its predictor)
    with the field fixed at the end: the branch's last point, or None when it fails or lands
    further than the step from the predictor."""
    res = br.correct(u, np.eye(len(u))[-1], end)
    return None if res is None or specials.far(res[0], pred, ds) else res


def _fail(br, u, ds, where):
    raise OrbitError(_where(br, u, ds, where) + ". Try a smaller ds or ds_min, a looser tol, or "
                     "a range that stops short of it")


def _where(br, u, ds, where):
    """Where and why the corrector failed: the field's value, the residuals, the last error."""
    prob = br.prob
    hist = getattr(br, "last_hist", None) or [np.nan]
    return (
        f"case {prob.case.name}: continuation in {prob.name}: the corrector did not converge "
        f"{where}, near {prob.name} = {prob.p_of(u[-1]):.6g} (period-{br.n} orbit), with the "
        f"arclength step down to {ds:.3g}: scaled residual {hist[-1]:.3g} (wanted "
        f"{br.tol:.3g}), history {', '.join(f'{v:.2g}' for v in hist)}"
        + (f" (last failure: {br.last_error})" if getattr(br, "last_error", "") else ""))
