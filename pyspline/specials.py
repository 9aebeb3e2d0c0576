"""Special points of a continued branch (docs/continuation.md): test functions of the Floquet
multipliers (folds, period doublings, Neimark-Sacker points) located by the Illinois secant on
the arclength, and the contact sequence of the orbit (grazing) located by bisection. The
grazing is located while the branch is followed: a converged point whose contact sequence
changed is accepted only when the grazing is located between it and the point before (the same
branch), and a failed step whose predictor changes the sequence is carried across the grazing
(`diagnose`). A branch that turns in the field at a grazing is a non-smooth fold. `br` is the
branch being followed (arclength._Branch): its corrector and point records are the core's map
and trajectories; nothing here computes physics."""
from __future__ import annotations

import numpy as np

#: special points and what each test function watches
SPECIAL_TYPES = {"fold": "a real multiplier through +1 (det(M - I) changes sign)",
                 "period_doubling": "a real multiplier through -1 (det(M + I) changes sign)",
                 "neimark_sacker": "a complex pair of multipliers through the unit circle",
                 "grazing": "the contact sequence of a tooth over the period changes (a "
                            "closest approach |dn_j| - c_j reaches zero)",
                 "nonsmooth_fold": "the branch turns back in the field at a grazing (no "
                                   "multiplier at +1: it jumps there)"}

#: consecutive points about a located grazing lie within this many of their arclength differences
CONTINUITY = 8.0


def multipliers(M) -> np.ndarray:
    mu = np.linalg.eigvals(M)
    return mu[np.argsort(-np.abs(mu), kind="stable")]


def tests(mu) -> dict:
    """Test functions of the multipliers (their sign changes between points mark a point)."""
    pairs = mu[mu.imag > 1e-9 * np.maximum(1, np.abs(mu))]
    return {"fold": float(np.prod(mu - 1).real), "period_doubling": float(np.prod(mu + 1).real),
            "neimark_sacker": float(np.prod(np.abs(pairs) ** 2 - 1)) if len(pairs) else np.nan,
            "_pairs": len(pairs)}


def contact_measures(tr) -> dict:
    """From one period of the orbit's trajectory (a Result): s_j(t) = |dn_j| - c_j, the contact
    deflection of tooth j (> 0 in contact on either flank, < 0 its gap): the signature of the
    contact sequence (per tooth: the number of sign changes over the period, at the case's
    output samples, and the side of a tooth that never changes, -1 for one that does: not the
    side at t0 of a tooth that switches, which changes where a switch crosses the section time
    with the sequence unchanged), and the closest approach: the smallest |s_j| over the teeth
    whose contact does not change over the period (NaN if every tooth switches)."""
    s = np.abs(tr.dn) - tr.c
    pos = s > 0
    changes = (pos[1:] != pos[:-1]).sum(axis=0)
    steady = changes == 0
    closest = float(np.abs(s[:, steady]).min()) if steady.any() else np.nan
    return {"signature": tuple(map(int, np.r_[np.where(steady, pos[0], -1), changes])),
            "closest_approach": closest, "switches": int(changes.sum())}


def far(u, pred, ds) -> bool:
    """A converged point further from its predictor than the step: on another branch."""
    return bool(np.linalg.norm(u - pred) > ds)


def point_at(br, a, sigma, start=None):
    """The branch point at arclength sigma from point a (along a's tangent), the corrector
    started from `start` (default the predictor); None when the corrector fails or lands
    further than sigma from its predictor (another branch)."""
    tau = a["tau"]
    pred = a["u"] + sigma * tau
    res = br.correct(pred if start is None else start, tau, tau @ pred)
    pt = None if res is None or far(res[0], pred, sigma) else br.point(res, a)
    return None if pt is None else dict(pt, sigma=sigma)


# --------------------------------------------------------------------------- grazing

def graze(br, a, b, sigma_b, iters=8):
    """The grazing between branch point a (sigma 0) and b (sigma_b along a's tangent), whose
    contact signatures differ, by bisection on sigma: (last, past, beyond, special): the
    corrected points either side of it, with a's signature (last) and with another (past), the
    one furthest past it (beyond: b, or in a failed step the first midpoint past it), the
    grazing recorded at past with last's closest approach. A midpoint whose corrector fails is
    corrected again from a short simulation there (br.restart); in a failed step (b None) one
    that fails too before any midpoint past the grazing converged is past it (the bracket
    shrinks to the converged ones). None when it is not located: a midpoint that fails
    between two converged ones (b's or beyond's side: the bracket's ends then are not known
    to be one branch, and a jump across a fold passes the test below), no converged point
    past it, a midpoint with a third signature, or consecutive points of last, past, beyond
    further apart than CONTINUITY times their arclength difference (a jump to another branch,
    not a grazing: each lies on the hyperplane at its sigma along a's tangent)."""
    sig_a = a["contact"]["signature"]
    lo, hi, last, past, beyond = 0.0, sigma_b, a, b, b
    for _ in range(iters):
        s = (lo + hi) / 2
        pt = point_at(br, a, s) or br.restart(a, s)
        if pt is None and beyond is None:
            hi = s
            continue
        if pt is None:
            return None
        sig = pt["contact"]["signature"]
        if sig == sig_a:
            lo, last = s, pt
        elif b is not None and sig != b["contact"]["signature"]:
            return None
        else:
            hi, past, beyond = s, pt, beyond or pt
    if past is None:
        return None
    chain = [(lo, last), (hi, past)]
    if beyond is not past:
        chain.append((beyond.get("sigma", sigma_b), beyond))
    if any(np.linalg.norm(v["u"] - u["u"]) > CONTINUITY * max(t - s, 1e-12)
           for (s, u), (t, v) in zip(chain, chain[1:])):
        return None
    sp = special(dict(past, sigma=hi), "grazing")
    sp["closest_approach"] = last["contact"]["closest_approach"]
    return last, past, beyond, sp


def diagnose(br, a, pred, ds):
    """A failed step from a to the predictor pred (ds along a's tangent): when the predicted
    orbit's contact signature differs from a's, the grazing located between them and the
    branch points to add: the last before it (unless a) and the first found past it, not the
    nearest (at the grazing the saltation's normal speed is near zero and M near singular),
    which carries the grazing; else None. Once from a point: the shorter steps that follow a
    failed diagnosis are only halved."""
    if a.get("diagnosed") or br.signature(pred) == a["contact"]["signature"]:
        return None
    a["diagnosed"] = True
    loc = graze(br, a, None, ds)
    if loc is None:
        return None
    last, _, beyond, sp = loc
    beyond["grazing"] = sp
    return ([] if last is a else [last]) + [beyond]


# --------------------------------------------------------------------------- location

def locate(br, pts):
    """The special points of a branch (its points in order): multiplier points between each
    pair, the grazings located while following; a grazing where the field turns back and no
    smooth fold is within two steps of it is a non-smooth fold (and a fold next to it whose
    multiplier jumped across +1 is that same point, not reported again)."""
    out = []
    for i, (a, b) in enumerate(zip(pts, pts[1:]), 1):
        out += [dict(sp, at=i) for sp in _multiplier_points(br, a, b)]
        if "grazing" in b:
            out.append(dict(b["grazing"], at=i))
    # the doubling where a period-n branch ends (ends.merge_doubling), at its last point
    out += [dict(pt["merge"], at=i) for i, pt in enumerate(pts) if "merge" in pt]
    for g in out:
        if g["type"] == "grazing" and _turns(pts, g) and not any(
                sp["type"] == "fold" and smooth(sp) and abs(sp["at"] - g["at"]) <= 2
                for sp in out):
            g["type"] = "nonsmooth_fold"
    turned = [g["at"] for g in out if g["type"] == "nonsmooth_fold"]
    out = [sp for sp in out if not (sp["type"] == "fold" and not smooth(sp) and
                                    any(abs(sp["at"] - t) <= 1 for t in turned))]
    return sorted(out, key=lambda s: (s["at"], s["sigma"]))


def _turns(pts, g) -> bool:
    """The field moves one way into the grazing g (between points at-1 and at) and the other
    way out of it, over two steps either side (the points next to a located grazing can be
    within a bisection bracket of it)."""
    i = g["at"]
    before = g["p"] - pts[max(i - 2, 0)]["p"]
    after = pts[min(i + 1, len(pts) - 1)]["p"] - g["p"]
    return before * after < 0


def _multiplier_points(br, a, b):
    out = []
    sigma_b = float(a["tau"] @ (b["u"] - a["u"]))
    if sigma_b <= 0:
        return out
    ta, tb = a["tests"], b["tests"]
    for kind in ("fold", "period_doubling", "neimark_sacker"):
        fa, fb = ta[kind], tb[kind]
        if kind == "neimark_sacker" and ta["_pairs"] != tb["_pairs"]:
            continue
        if np.isfinite(fa) and np.isfinite(fb) and np.sign(fa) != np.sign(fb) and fa != 0:
            sp = _secant(br, a, b, sigma_b, kind)
            if sp is not None:
                out.append(sp)
    return out


def _secant(br, a, b, sigma_b, kind, iters=12):
    """Illinois secant on sigma for a test function's zero between a (sigma 0) and b."""
    lo, hi, flo, fhi = 0.0, sigma_b, a["tests"][kind], b["tests"][kind]
    best, side = dict(a if abs(flo) < abs(fhi) else b), 0
    best["sigma"] = 0.0 if abs(flo) < abs(fhi) else sigma_b
    for _ in range(iters):
        s = hi - fhi * (hi - lo) / (fhi - flo)
        if not lo < s < hi:
            s = (lo + hi) / 2
        pt = point_at(br, a, s)
        if pt is None and s != (lo + hi) / 2:     # the secant's point failed: the middle
            s = (lo + hi) / 2
            pt = point_at(br, a, s)
        if pt is None:
            break
        f = pt["tests"][kind]
        best = pt
        if np.sign(f) == np.sign(fhi):
            hi, fhi = s, f
            if side == -1:
                flo /= 2
            side = -1
        else:
            lo, flo = s, f
            if side == 1:
                fhi /= 2
            side = 1
        if hi - lo < 1e-6 * sigma_b:
            break
    return special(best, kind)


def special(pt, kind):
    mu = pt["mu"]
    target = {"fold": 1.0, "period_doubling": -1.0}.get(kind)
    if target is not None:
        crit = mu[np.argmin(np.abs(mu - target))]
    elif kind == "neimark_sacker":
        pairs = mu[np.abs(mu.imag) > 1e-9]
        crit = pairs[np.argmin(np.abs(np.abs(pairs) - 1))] if len(pairs) else np.nan
    else:
        crit = mu[0]
    return dict(pt, type=kind, critical=complex(crit),
                closest_approach=pt["contact"]["closest_approach"])


def same_point(u, v, tol) -> bool:
    """Two points of the continuation's scaled unknowns u = (z, q) are one: within sqrt(tol)
    of each other in every component (tol the corrector's residual: a converged point is off
    by about tol, and near a fold, where M - I is singular along the branch, by about its
    square root)."""
    return bool(np.abs(np.asarray(u) - np.asarray(v)).max() <= np.sqrt(tol))


def on_polyline(X, x, tol) -> bool:
    """Whether x lies on the polyline through the rows of X (consecutive points of a branch):
    within a tenth of a chord (the sagitta at the continuation's max_angle is about 2 % of
    it), and at least sqrt(tol) (same_point), of the nearest point of a segment, so that a
    point at a fold, beyond the field values sampled on either side of it, is found too."""
    if len(X) < 2:
        return False
    d, r = np.diff(X, axis=0), np.asarray(x) - X[:-1]
    w = np.clip((r * d).sum(1) / np.maximum((d * d).sum(1), 1e-300), 0, 1)
    dist = np.abs(r - w[:, None] * d).max(1)
    return bool((dist <= np.maximum(0.1 * np.abs(d).max(1), np.sqrt(tol))).any())


def once(sps, sections, tol):
    """The special points without repeats: one of the kind and branch of a point kept before
    and the same point (same_point) as it at any of that point's section points (sections(sp):
    its u at each of its orbit's n / r section points; a period-2 branch continued through
    its doubling comes back at the other one) was located twice and goes."""
    kept = []
    for sp in sps:
        if not any(k["type"] == sp["type"] and k["branch"] == sp["branch"]
                   and same_point(k["u"][-1:], sp["u"][-1:], tol)
                   and any(same_point(u, sp["u"], tol) for u in sections(k)) for k in kept):
            kept.append(sp)
    return kept


def smooth(sp) -> bool:
    """The critical multiplier at +1, -1 or on the unit circle within 0.01 (a grazing: True,
    no multiplier is watched; a non-smooth fold: False, its multipliers jump)."""
    if sp["type"] == "nonsmooth_fold":
        return False
    mu = sp["critical"]
    target = {"fold": 1.0, "period_doubling": -1.0}.get(sp["type"])
    if target is not None:
        return abs(mu - target) < 1e-2
    if sp["type"] == "neimark_sacker":
        return abs(abs(mu) - 1) < 1e-2
    return True
