"""How a continued branch ends before its band's end (docs/continuation.md): a period-n branch
(n even) at its period doubling, where it merges into the period-n/2 branch (the doubling
located there), past it or where its steps fail next to it (reached_merge), a branch that
comes back onto its own orbit at another of its section points, and a point whose steps keep
failing (FAILED_EVALS, each fallback's share of it, the fallbacks themselves). `br` is
the branch being followed (arclength._Branch); the maps are the core's, nothing here computes
physics."""
from __future__ import annotations

import numpy as np

from . import specials
from .errors import CaseError, SolverError
from .orbits import _period_map

#: corrector iterations (each one run of the map with its monodromy, 2k + 1 by differences,
#: and two for dF/dp) that the failed steps from one branch point may take, their retry,
#: halvings and fallbacks together (not the diagnosis nor the doubling's location, bounded on
#: their own): past it the branch ends at that point. Each of the three fallbacks has
#: FALLBACK_EVALS of it: the halvings of the method in use stop where only the shares of the
#: fallbacks not yet tried are left (the case's own method's at 50: the tests' branches took
#: at most 42 before their next point).
FALLBACK_EVALS = 10
FAILED_EVALS = 50 + 3 * FALLBACK_EVALS


def halvings_end(lost, left) -> bool:
    """Whether the halvings of the method in use stop after `lost` corrector iterations of a
    point's failed steps, `left` fallbacks not yet tried: each keeps its own share."""
    return lost > FAILED_EVALS - left * FALLBACK_EVALS


def fallbacks(prob):
    """What a failed step tries next: the other monodromy, then the other integrator (ERK for
    a CVODE method, BDF for ERK) with each monodromy."""
    other = "fd" if prob.how == "exact" else "exact"
    method = "bdf" if prob.case["method"] == "erk" else "erk"
    return [(other, prob.case["method"]), (prob.how, method), (other, method)]


def use(prob, monodromy, method):
    """The problem's map from then on: that monodromy and integrator."""
    prob.set_monodromy(monodromy)
    if method != prob.case["method"]:
        prob.set_method(method)


def half(br, y, u):
    """u = (z, q) of P^(n/2)(y), y the state of the branch point u: its orbit half a period on."""
    prob = br.prob
    p = prob.p_of(u[-1])
    y1, free = _period_map(prob.model(p), prob.t0, prob.t1(p, br.n // 2), np.asarray(y)[:, None])
    return np.r_[y1[free, 0] / prob.d0[free], u[-1]]


def new_orbit(br, y, u):
    """The doubled branch's point is not the period-n orbit again: P^(n/2)(y) != y."""
    return np.abs(half(br, y, u) - u).max() > 1e3 * br.tol


def merged(br, a, new, secs):
    """Where a period-n branch (n even) meets the period-n/2 branch at their period doubling
    (a pitchfork of P^n): new, the point after a, is a fixed point of P^(n/2) (the
    period-n/2 orbit, not to be labelled n), or lies past the doubling on the branch's own
    other section points (P^(n/2) of new nearer a than new itself: the same orbit again, to be
    traced twice). secs: new's u at each of its section points (_Problem.sections; P^(n/2) of
    it is the middle one). A sentence saying so (the branch ends at a), or ''."""
    if len(secs) % 2:
        return ""
    h = secs[len(secs) // 2]
    if np.abs(h - new["u"]).max() > 1e3 * br.tol and \
            np.linalg.norm(h - a["u"]) >= np.linalg.norm(new["u"] - a["u"]):
        return ""
    return merge_words(br, a, new["p"])


def apart(x, y):
    """x and y with as many significant digits (6 at least) as tell them apart."""
    d = 6
    while d < 17 and f"{x:.{d}g}" == f"{y:.{d}g}":
        d += 1
    return f"{x:.{d}g}", f"{y:.{d}g}"


def merge_words(br, a, p):
    """The status of a period-n branch that ends at a, before its doubling at or before p."""
    lo, hi = apart(a["p"], p)
    return (f"the period-{br.n} branch reached a period doubling between {br.prob.name} = "
            f"{lo} and {hi}, where it merges into the period-{br.n // 2} "
            f"branch (past it: the period-{br.n // 2} orbit, or this orbit at its other section "
            "points): it ends there")


def _gap(br, pt):
    """|P^(n/2)(y) - y| of branch point pt, scaled (d: the period-n branch is the parabola
    q* - q ~ d^2 into its doubling at q*)."""
    return float(np.linalg.norm(half(br, pt["y"], pt["u"]) - pt["u"]))


def reached_merge(br, pts, back=12):
    """A period-n branch (n even) whose steps from its last point a fail next to its period
    doubling (there it crosses the period-n/2 branch, a branch point of P^n: its corrector's
    bordered Jacobian is near singular and does not converge to tol): the doubling, located by
    merge_doubling, when the branch's points lead into it. They do when the parabola through a
    and the latest of the `back` points before it whose gap d (_gap) is at least twice a's,
    q* - q = c d^2, puts the doubling where it is located: q_d - q_a within a quarter of
    c d_a^2. The special point (as merge_doubling's), or None: no such point before, a run
    fails, the doubling not located or elsewhere."""
    if br.n % 2 or len(pts) < 2:
        return None
    a = pts[-1]
    try:
        d_a = _gap(br, a)
        for b in pts[-2:-2 - back:-1]:
            d_b = _gap(br, b)
            if d_b >= 2 * d_a:
                break
        else:
            return None
    except (SolverError, CaseError):
        return None
    c = (a["u"][-1] - b["u"][-1]) / (d_b ** 2 - d_a ** 2)
    sp = merge_doubling(br, [b, a], None)
    if sp is None or abs(sp["u"][-1] - a["u"][-1] - c * d_a ** 2) > abs(c) * d_a ** 2 / 4:
        return None
    return sp


def returned(br, pts, new, secs):
    """Whether new, the point after pts, lies at another of its section points (secs[1:], as
    in merged) on the branch traced before (specials.on_polyline, the segments up to the
    point before the last: next to a doubling the other half of the orbit is that near the
    last one): the branch has come back onto its own orbit. A sentence saying so, or ''."""
    X = np.array([pt["u"] for pt in pts[:-1]])
    for j, u in enumerate(secs[1:], 1):
        if specials.on_polyline(X, u, br.tol):
            return (f"the period-{br.n} branch came back onto its own orbit at {br.prob.name} "
                    f"= {new['p']:.6g} (its section point {j} on the branch traced before, "
                    f"within a tenth of a chord): it ends at {pts[-1]['p']:.6g}")
    return ""


def merge_doubling(br, pts, new):
    """The period doubling where the period-n branch pts ends (merged between its last point a
    and new), located on the period-n/2 orbit as on that branch (specials._secant on
    det(M + I) of P^(n/2)): between that orbit at a's field value (Newton from the middle of
    a's section points y and P^(n/2)(y), which meet at the doubling) and at its mirror across
    the doubling's field value estimated from the branch's last two points (the period-n
    branch is a parabola there, q - q* ~ d^2 in d = |P^(n/2)(y) - y|; new's when there is one
    point; None: from the last two alone), or twice as far. On the period-n branch the corrector fails next to the doubling,
    a branch point of P^n. The special point (type period_doubling, n/2, marked 'merge'), or
    None when it is not bracketed or a run fails."""
    prob, a = br.prob, pts[-1]
    hb = type(br)(prob, br.n // 2, br.y_fixed, br.tol, br.max_corr)
    e_q = np.eye(len(a["u"]))[-1]
    try:
        ha = half(br, a["y"], a["u"])
        res = hb.correct((a["u"] + ha) / 2, e_q, a["u"][-1])
        A = None if res is None else hb.point(res, np.sign(a["tau"][-1]) * e_q)
        if A is None or abs(A["tau"][-1]) < 1e-9:
            return None
        q_a, q_star = a["u"][-1], None if new is None else new["u"][-1]
        if len(pts) > 1:
            b = pts[-2]
            d_a = np.linalg.norm(ha - a["u"])
            d_b = np.linalg.norm(half(br, b["y"], b["u"]) - b["u"])
            if d_b > d_a:
                q_star = (q_a * d_b ** 2 - b["u"][-1] * d_a ** 2) / (d_b ** 2 - d_a ** 2)
        for f in (2, 4) if q_star is not None else ():
            q_b = q_a + f * (q_star - q_a)
            res = hb.correct(A["u"] + (q_b - q_a) / A["tau"][-1] * A["tau"], e_q, q_b)
            B = None if res is None else hb.point(res, A)
            if B is not None and np.sign(B["tests"]["period_doubling"]) != np.sign(
                    A["tests"]["period_doubling"]):
                chord = B["u"] - A["u"]
                sigma = float(np.linalg.norm(chord))
                sp = specials._secant(hb, dict(A, tau=chord / sigma), B, sigma, "period_doubling")
                return dict(sp, merge=True)
    except (SolverError, CaseError):
        pass
    return None
