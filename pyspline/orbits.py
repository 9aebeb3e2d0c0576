"""Periodic orbits of a forced run and their Floquet multipliers (docs/orbits.md).

The shaft turns at constant omega, so a run is forced with the shaft period T = 2 pi / omega
(torque ripple of a fractional order n_k repeats after the revolutions that make n n_k whole).
A period-n orbit is a fixed point of the n-fold period map, P^n(y0) = y0, where P^n takes the
state at the section time t0 to the state at t0 + n T (the core integrates it:
spline_orbits::period_map, with the case's tolerances, root-located contact switches and
linear tail). Nothing here computes physics: the map is the core's, Newton and the
eigenvalues are linear algebra on its values.
"""
from __future__ import annotations

import contextvars
import time
import warnings
from contextlib import contextmanager
from dataclasses import dataclass, field
from fractions import Fraction
from math import lcm

import numpy as np

from . import bridge
from .case import Case
from .core import STATE_QUANTITIES, Result, load, run_outcome
from .errors import CaseError, SolverError, SplineError, SplineWarning
from .result import run as run_model

NSTATE = 14
#: wall-time bound [s] of one call of the core's map (a map_and_monodromy run, or all the runs of
#: one _period_map call); its step bounds are the case's max_steps and max_total_steps
MAP_SECONDS = 60.0
#: wall-time bound [s] of a whole call of continuation, branches or fold_curve (max_seconds):
#: five times the longest complete call measured (a Z24 band, 60 s on one core)
CALL_SECONDS = 300.0

#: (deadline on time.perf_counter, the bound's words) of the innermost time_bound
_DEADLINE = contextvars.ContextVar("pyspline_deadline", default=(np.inf, ""))


class OrbitError(SplineError):
    """Newton on P^n(y) - y = 0 did not converge (the message says what was tried and the
    residual reached)."""


@dataclass
class Orbit:
    """A periodic orbit: its section point y0 at t0 and its Floquet multipliers.

    ``monodromy`` is M = dP^n/dy0 over the integrated states ``states`` (the torsional ones at
    dof 3), in the scaled states of Eq. 25 (same eigenvalues as in SI units)."""
    case: Case
    n: int                   #: shaft periods of the map
    period: float            #: n T = 2 pi n / omega [s]
    t0: float                #: section time [s]
    y0: np.ndarray           #: the orbit's state at t0 (14,), SI
    trajectory: Result       #: simulate from (t0, y0) over one period (case's n_out points)
    monodromy: np.ndarray    #: M (k, k): variational equations + saltation, or central differences
    states: tuple            #: names of the k states M acts on
    multipliers: np.ndarray  #: eigenvalues of M, largest modulus first
    stable: bool             #: every |mu| < 1 - margin
    margin: float            #: the margin of ``stable``
    residual: float          #: max |P^n(y0) - y0| in the scaled states of Eq. 25
    iterations: int          #: Newton steps taken
    residuals: list = field(default_factory=list)   #: the scaled residual before each step and at the end
    fd_step: float = 0.0     #: the central-difference step (scaled states; method 'fd')
    method: str = "exact"    #: how M was computed: 'exact' or 'fd'


def _seconds(max_seconds, what: str) -> float:
    """max_seconds as a float; CaseError naming it and `what` unless a number > 0 (inf: none)."""
    if isinstance(max_seconds, bool) or not isinstance(max_seconds, (int, float, np.number)) \
            or not max_seconds > 0:
        raise CaseError(f"{what}: max_seconds = {max_seconds!r}: the wall-time bound must be a "
                        "number of seconds > 0 (math.inf: none)")
    return float(max_seconds)


@contextmanager
def time_bound(max_seconds, what: str):
    """Within it every map run ends by max_seconds from now, or by an enclosing bound if that
    one ends first; out_of_time() says when it has passed. CaseError for a bad max_seconds."""
    end = time.perf_counter() + _seconds(max_seconds, what)
    token = _DEADLINE.set(min(_DEADLINE.get(), (end, f"the wall-time bound of {what}, "
                                                     f"max_seconds = {max_seconds:.3g} s,")))
    try:
        yield
    finally:
        _DEADLINE.reset(token)


def time_left() -> float:
    """The seconds left of the innermost time_bound (inf outside any)."""
    return _DEADLINE.get()[0] - time.perf_counter()


def out_of_time() -> str:
    """'' within the time of the innermost time_bound, else the bound's words."""
    return _DEADLINE.get()[1] if time_left() <= 0 else ""


def _wall(model, max_seconds) -> float:
    """The core's wall-time bound for max_seconds (> 0; inf: none, 0 to the core), cut to what
    the innermost time_bound leaves (a microsecond once it has passed: the run stops at once)."""
    left = min(_seconds(max_seconds, f"case {model.case.name}: a map run"),
               max(time_left(), 1e-6))
    return 0.0 if np.isinf(left) else left


def _period_map(model, t0: float, t1: float, ys: np.ndarray, max_seconds: float = MAP_SECONDS
                ) -> tuple[np.ndarray, np.ndarray]:
    """The core's map of the columns of ys (14, k), SI: (their states at t1, the mask of the
    integrated states). SolverError when the runs take more than max_seconds in all."""
    y1, mask, ierr, msg = bridge.period_map(model.bytes, t0, t1, np.asfortranarray(ys),
                                            _wall(model, max_seconds))
    run_outcome(ierr, msg)
    if not np.isfinite(y1).all():
        raise SolverError(f"case {model.case.name}: the period map from t = {t0} s to {t1} s "
                          "gave a non-finite state (the model left its range)")
    return y1, mask.astype(bool)


def section_points(model, t0: float, n: int, y) -> np.ndarray:
    """The section points of the period-n orbit through y (14,), SI, at t0: (m, 14), y and its
    images under the core's map over the r revolutions after which the forcing repeats
    (repeat_revolutions), m = n / r of them. A period-n orbit is the same orbit from any of them
    (a period-2 orbit of a forcing of one revolution: y and P(y))."""
    r = repeat_revolutions(model.case)
    t1 = t0 + 2 * np.pi * r / model.info()["omega"]
    out = [np.asarray(y, float)]
    for _ in range(n // r - 1):
        out.append(_period_map(model, t0, t1, out[-1][:, None])[0][:, 0])
    return np.array(out)


def _scale(model) -> np.ndarray:
    """The scales of Eq. 25 per state: l_ref for displacements, l_ref w_ref for velocities."""
    info = model.info()
    return np.r_[np.full(7, info["l_ref"]), np.full(7, info["l_ref"] * info["w_ref"])]


def map_and_monodromy(model, t0: float, t1: float, y: np.ndarray, saltation: bool = True,
                      max_seconds: float = MAP_SECONDS) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The period map from t0 to t1 and its monodromy, from the core's variational equations.

    model: a loaded model (pyspline.load) or a Case. y: (14,) SI state at t0. Returns (y1, M,
    free): y1 (14,) the SI state at t1; M (k, k) = dP/dy0 over the integrated states in the
    scaled states of Eq. 25 (l_ref, l_ref w_ref), the tangents integrated beside the state
    (spline_variational::tangent_flow) with the saltation matrix at every root-located contact
    switch (saltation=False leaves it out: wrong wherever a switch is crossed, kept to show
    it); free (14,) bool, the integrated states (the torsional six at dof 3). One run, bounded
    in steps by the case's max_steps and max_total_steps and in wall time by max_seconds
    (math.inf: none).
    CaseError for the thermal level coupled (not covered), SolverError when the run fails or
    meets a bound (the message names it)."""
    if isinstance(model, Case):
        model = load(model)
    y = np.asarray(y, dtype=float)
    if y.shape != (NSTATE,) or not np.isfinite(y).all():
        raise CaseError(f"case {model.case.name}: y (shape {y.shape}) must be a state of "
                        f"{NSTATE} finite SI values ({', '.join(STATE_QUANTITIES)})")
    y1, phi, mask, _nsw, ierr, msg = bridge.map_monodromy(model.bytes, float(t0), float(t1), y,
                                                          int(bool(saltation)),
                                                          _wall(model, max_seconds))
    run_outcome(ierr, msg)
    if not np.isfinite(y1).all() or not np.isfinite(phi).all():
        raise SolverError(f"case {model.case.name}: the variational run from t = {t0} s to {t1} s "
                          "gave a non-finite state or monodromy (the model left its range)")
    free = mask.astype(bool)
    k = int(free.sum())
    return y1, np.array(phi[:k, :k]), free


def fd_monodromy(model, t0: float, t1: float, y: np.ndarray, h: float | None = None
                 ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """map_and_monodromy's (y1, M, free) with M by central differences of the core's map
    (period_map): state i (scaled) stepped by h max(1, |y_i|), h = rtol^(1/3) by default; all
    2k + 1 runs in one call. For checking the exact M."""
    if isinstance(model, Case):
        model = load(model)
    y = np.asarray(y, dtype=float)
    scale = _scale(model)
    h = model.case["rtol"] ** (1 / 3) if h is None else float(h)
    y1, free = _period_map(model, t0, t1, y[:, None])
    idx = np.flatnonzero(free)
    steps = h * np.maximum(1.0, np.abs(y[idx] / scale[idx]))
    cols = np.repeat(y[:, None], 2 * len(idx), axis=1)
    for c, (i, s) in enumerate(zip(idx, steps)):
        cols[i, 2 * c] += s * scale[i]
        cols[i, 2 * c + 1] -= s * scale[i]
    yd, _ = _period_map(model, t0, t1, cols)
    z1 = yd[idx] / scale[idx, None]
    return y1[:, 0], (z1[:, 0::2] - z1[:, 1::2]) / (2 * steps), free


def repeat_revolutions(case) -> int:
    """The shaft revolutions after which the case's forcing repeats (ripple orders n_k of
    non-zero amplitude: the lcm of their denominators, up to 1000; 1 otherwise)."""
    m = 1
    for order, amp in zip(case["ripple_order"], case["ripple_amp"]):
        if amp:
            m = lcm(m, Fraction(order).limit_denominator(1000).denominator)
    return m


def forcing_periods(case: Case, n: int) -> None:
    """Check that the forcing repeats after n shaft revolutions: omega > 0 and every torque
    ripple term of non-zero amplitude has an order n_k with n n_k whole. CaseError otherwise,
    naming the field and the n that would do."""
    if not case["speed_rpm"] > 0:
        raise CaseError(f"case {case.name}: speed_rpm = {case['speed_rpm']}: the shaft does not "
                        "turn, so there is no forcing period T = 2 pi/omega for a periodic orbit")
    for order, amp in zip(case["ripple_order"], case["ripple_amp"]):
        if amp == 0 or float(order * n).is_integer():
            continue
        frac = Fraction(order).limit_denominator(1000)
        hint = (f"; n = {frac.denominator} revolutions would repeat it"
                if abs(float(frac) - order) <= 1e-12 * abs(order) else
                " (no whole number of revolutions up to 1000 repeats it)")
        raise CaseError(f"case {case.name}: ripple_order = {order:g} (ripple_amp = {amp:g}) does "
                        f"not repeat within n = {n} shaft revolution(s): n * ripple_order must be "
                        f"a whole number{hint}")


def periodic_orbit(case, n: int = 1, guess=None, t0: float | None = None, tol: float | None = None,
                   max_iter: int = 12, margin: float = 1e-4, monodromy: str = "exact",
                   max_seconds: float = MAP_SECONDS) -> Orbit:
    """The period-n orbit of a forced case near a guess, and its Floquet multipliers.

    Newton on F(y) = P^n(y) - y = 0, with P^n the core's map over n shaft periods from the
    section time t0 (default: the case's t0) and the Jacobian M - I, in the scaled states of
    Eq. 25 (l_ref for the displacements, l_ref w_ref for the velocities). The monodromy
    M = dP^n/dy0: monodromy='exact' (default) from the core's variational equations with the
    saltation matrix at every located contact switch, in the same run as the map
    (map_and_monodromy: one run per Newton step); monodromy='fd' from central differences of
    the map, state i stepped by h = rtol^(1/3) (the truncation error h^2 balances the map's
    noise rtol / h), 2k + 1 runs per step. A step that does not lower the residual is halved
    (up to 6 times). An orbit that grazes a contact switch is not detected (its map is not
    differentiable there; docs/orbits.md).

    guess: a state (14,), SI, at t0; default: the state at t0 + k n T that ends (or first
    follows) the case's own run from its start (its t_end settles it).
    tol: the scaled residual max_i |P^n(y0) - y0|_i to reach; default 100 rtol.
    margin: stable means every |mu| < 1 - margin (the multipliers carry the error of M: the
    differences' h^2 + rtol / h, 1e-7 to 4e-7 at rtol 1e-11; exact M a few 1e-9 there; keep
    margin well above it).
    max_seconds: the wall time the whole call may take, the settling run of the default guess
    and every map run included (default MAP_SECONDS; math.inf: none).

    Returns an Orbit. Raises CaseError for bad input (n, guess, a case without a forcing
    period, max_seconds), OrbitError when Newton does not converge (what was tried, the
    residual reached) or max_seconds has passed (it names the bound), SolverError when a run of
    the map fails."""
    model = load(case)
    case = model.case
    if isinstance(n, bool) or not isinstance(n, (int, np.integer)) or n < 1:
        raise CaseError(f"case {case.name}: n = {n!r}: the number of shaft periods of the "
                        "orbit must be a whole number >= 1")
    n = int(n)
    forcing_periods(case, n)
    info = model.info()
    omega, period = info["omega"], 2 * np.pi * n / info["omega"]
    t0 = float(case["t0"] if t0 is None else t0)
    t1 = t0 + period
    tol = 100 * case["rtol"] if tol is None else float(tol)
    if not (np.isfinite(tol) and tol > 0):
        raise CaseError(f"case {case.name}: tol = {tol!r}: the scaled residual to reach must be "
                        "a finite number > 0")
    if monodromy not in ("exact", "fd"):
        raise CaseError(f"case {case.name}: monodromy = {monodromy!r}: 'exact' (variational "
                        "equations) or 'fd' (central differences of the map)")
    if guess is not None:
        guess = np.asarray(guess, dtype=float)
        if guess.shape != (NSTATE,):
            raise CaseError(f"case {case.name}: guess has shape {guess.shape}: a state has "
                            f"{NSTATE} entries ({', '.join(STATE_QUANTITIES)}), SI")
        if not np.isfinite(guess).all():
            raise CaseError(f"case {case.name}: guess is not finite")
    with time_bound(max_seconds, f"periodic_orbit (case {case.name})"):
        try:
            y = _settled_state(model, t0, period) if guess is None else guess
            return _newton(model, n, t0, t1, y, tol, max_iter, margin, monodromy)
        except SolverError:
            late = out_of_time()
            if not late:
                raise
            raise OrbitError(f"case {case.name}: no period-{n} orbit found (period {period:.6g} "
                             f"s from t0 = {t0:.6g} s): {late} was reached in a run of the "
                             "map (the settling run of the default guess or a Newton step)"
                             ) from None


def _newton(model, n, t0, t1, y, tol, max_iter, margin, monodromy) -> Orbit:
    """periodic_orbit's Newton iteration from y (its arguments checked)."""
    case, period, rtol = model.case, t1 - t0, model.case["rtol"]
    scale = _scale(model)
    h = rtol ** (1 / 3)

    def step(y, with_m):
        """(scaled residual, M or None, free) at y: one variational run (exact), or the map and,
        if with_m, its 2k differenced runs (fd)."""
        if monodromy == "exact":
            y1, M, free = map_and_monodromy(model, t0, t1, y)
        elif with_m:
            y1, M, free = fd_monodromy(model, t0, t1, y, h)
        else:
            y1, free = _period_map(model, t0, t1, y[:, None])
            y1, M = y1[:, 0], None
        return (y1 - y) / scale, M, free

    r, M, free = step(y, True)
    hist = [float(np.abs(r[free]).max())]
    it = 0
    while hist[-1] > tol:
        if late := out_of_time():
            _fail(case, n, period, t0, it, hist, tol, f"{late} was reached")
        if it == max_iter:
            _fail(case, n, period, t0, it, hist, tol, "the iteration limit max_iter was reached")
        if M is None:
            _, M, _ = step(y, True)
        try:
            dz = np.linalg.solve(M - np.eye(len(M)), -r[free])
        except np.linalg.LinAlgError:
            _fail(case, n, period, t0, it, hist, tol, "M - I is singular (a multiplier at 1)")
        it += 1
        for _ in range(7):
            y_new = y.copy()
            y_new[free] += dz * scale[free]
            r_new, M_new, _ = step(y_new, False)
            if np.abs(r_new[free]).max() < hist[-1]:
                break
            dz = dz / 2
        else:
            _fail(case, n, period, t0, it, hist, tol,
                  "the Newton step, halved 6 times, did not lower the residual")
        y, r, M = y_new, r_new, M_new
        hist.append(float(np.abs(r[free]).max()))
    if M is None:
        _, M, _ = step(y, True)
    mu = np.linalg.eigvals(M)
    mu = mu[np.argsort(-np.abs(mu), kind="stable")]
    names = tuple(str(s) for s, f in zip(STATE_QUANTITIES, free) if f)
    return Orbit(case=case, n=n, period=period, t0=t0, y0=y, trajectory=_trajectory(case, t0, t1, y),
                 monodromy=M, states=names, multipliers=mu,
                 stable=bool(np.all(np.abs(mu) < 1 - margin)), margin=margin,
                 residual=hist[-1], iterations=it, residuals=hist,
                 fd_step=h if monodromy == "fd" else 0.0, method=monodromy)


def _fail(case, n, period, t0, it, hist, tol, why):
    raise OrbitError(
        f"case {case.name}: no period-{n} orbit found (Newton on P^n(y) - y = 0, period "
        f"{period:.6g} s from t0 = {t0:.6g} s): {why} after {it} Newton step(s); scaled residual "
        f"{hist[-1]:.3g} (wanted {tol:.3g}), history {', '.join(f'{v:.2g}' for v in hist)}. "
        "Try a guess nearer the orbit (a longer settling run: t_end), another n, or a "
        "looser tol")


#: run-length fields given in shaft revolutions win over t_end, t_transient, n_out: zeroed
#: where a run's times are set here (when the case has them)
_REVOLUTION_FIELDS = ("revolutions", "transient_revolutions", "outputs_per_revolution")


def _run(case: Case, **times) -> Case:
    """The case with its run times set (t_end, t_transient, n_out, ...), no section, no
    Lyapunov exponent."""
    times.update({k: 0.0 for k in _REVOLUTION_FIELDS if k in case})
    return case.replace(section="none", lyapunov=False, **times)


def _settled_state(model, t0: float, period: float) -> np.ndarray:
    """The state at the first t0 + k period (k >= 1) at or after the case's t_end, from a run of
    the case from its start (the default guess), a map run per period (the first up to the first
    t0 + j period after the case's t0): the case's max_steps bounds a period's steps, not the
    whole settling run's, as it bounds an output interval's in the case's own run."""
    case = model.case
    t_end = float(model.output_times()[-1])      # the case's t_end, however it was given
    j = int(np.floor((case["t0"] - t0) / period)) + 1
    k = max(int(np.ceil((t_end - t0) / period - 1e-9)), j)
    y, ta = model.start_state()[:, None], case["t0"]
    for tb in t0 + period * np.arange(j, k + 1):
        y, _ = _period_map(model, ta, tb, y)
        ta = tb
    return y[:, 0]


def _trajectory(case: Case, t0: float, t1: float, y0: np.ndarray) -> Result:
    """simulate from (t0, y0) to t1: start at rest plus the state as dq0, dv0 (exact: 0 + y),
    bounded in wall time as a map run (MAP_SECONDS, cut to the call's time left)."""
    run = _run(case, start="rest", dq0=list(y0[:7]), dv0=list(y0[7:]), t0=t0, t_end=t1,
               t_transient=0.0)
    with warnings.catch_warnings():
        # the orbit may start in contact: the start-at-rest overlap warning says nothing here
        warnings.filterwarnings("ignore", message=r".*start = 'rest' with", category=SplineWarning)
        model = load(run)
        return run_model(model, max_seconds=_wall(model, MAP_SECONDS))
