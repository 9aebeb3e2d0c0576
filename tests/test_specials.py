"""The classification of a continued branch's special points (pyspline/specials.py,
docs/continuation.md) on branch records made up here: a grazing at which the field turns back
is a non-smooth fold, one the branch passes through is a grazing, and a grazing next to a
smooth fold (a multiplier at +1) stays a grazing beside that fold. No drive turns at a
grazing (the contact force is continuous there, so are the multipliers: docs/continuation.md),
so the records stand in for one; the Z16 drive near its cusp, whose turn lies 1.57 r/min past
its grazing, is held as a smooth fold and a grazing, with no jump of the multipliers. A
failed step's grazing is bisected on a made-up line branch."""
import numpy as np
import pytest

from pyspline import specials

MU = np.array([0.5, 0.2])


def branch(ps, at):
    """Points along a line in u whose field values are ps, a grazing recorded between point
    at-1 and point at (at the field's value of point at)."""
    pts = []
    for i, p in enumerate(ps):
        u = np.array([float(i), p])
        pts.append(dict(u=u, tau=np.array([1.0, 0.0]), p=p, mu=MU, tests=specials.tests(MU),
                        contact={"signature": (int(i >= at),), "closest_approach": 0.0}))
    pts[at]["grazing"] = specials.special(dict(pts[at], sigma=0.5), "grazing")
    return pts


def kinds(found):
    return [(sp["type"], sp["p"]) for sp in found]


@pytest.mark.parametrize("ps, kind", [([0.0, 1.0, 2.0, 1.5, 1.0], "nonsmooth_fold"),
                                      ([0.0, 1.0, 2.0, 2.5, 3.0], "grazing"),
                                      ([3.0, 2.0, 1.0, 1.5, 2.0], "nonsmooth_fold")])
def test_a_grazing_where_the_field_turns_is_a_nonsmooth_fold(ps, kind):
    found = specials.locate(None, branch(ps, 2))
    assert kinds(found) == [(kind, ps[2])]
    assert specials.smooth(found[0]) == (kind == "grazing")


@pytest.mark.parametrize("critical, expected", [
    (1.0 + 0j, [("grazing", 2.0), ("fold", 2.2)]),          # a smooth fold next to it
    (1.7 + 0j, [("nonsmooth_fold", 2.0)])])                 # the multiplier jumped across +1
def test_a_fold_beside_a_turning_grazing(monkeypatch, critical, expected):
    pts = branch([0.0, 1.0, 2.0, 1.5, 1.0], 2)
    for pt in pts[3:]:                  # det(M - I) changes sign between points 2 and 3
        pt["tests"] = dict(pt["tests"], fold=-pt["tests"]["fold"])
    monkeypatch.setattr(specials, "_secant", lambda br, a, b, sigma_b, kind: dict(
        a, p=2.2, sigma=0.3, type=kind, critical=critical))
    assert kinds(specials.locate(None, pts)) == expected


def test_a_point_located_twice_is_reported_once():
    """A special point of the same kind and branch at the same field value as one kept before,
    at one of that one's other section points (the same orbit), is reported once
    (specials.once); on another branch, or not at a section point, it is kept."""
    def sp(u, branch=0):
        return dict(type="fold", branch=branch, u=np.array(u, float))
    first, other = [0.0, 0.0, 5.0], [1.0, 1.0, 5.0]
    sections = lambda k: [k["u"], np.array(other)] if list(k["u"]) == first else [k["u"]]
    kept = specials.once([sp(first), sp(other), sp(other, 1), sp([2.0, 2.0, 5.0])], sections,
                         1e-6)
    assert [(list(k["u"]), k["branch"]) for k in kept] == [
        (first, 0), (other, 1), ([2.0, 2.0, 5.0], 0)]


@pytest.mark.parametrize("fails, offset, found", [
    ((0.45, 1.1), 0.0, True),       # failing past the grazing only: bracketed between converged
    ((0.3, 0.45), 0.05, False),     # failing between converged points (a jump past them)
    ((2.0, 2.0), 5.0, False)])      # all converge, the first past it a branch away
def test_a_failed_steps_grazing_needs_converged_points_either_side(monkeypatch, fails,
                                                                   offset, found):
    """specials.graze in a failed step (no end point) on a made-up line branch u = (sigma, 0)
    whose contact signature changes at sigma 0.3, the points from sigma 0.45 on moved by
    `offset` (another part of the branch), the corrector failing on the hyperplanes inside
    `fails`: a midpoint that fails before any past the grazing converged counts as past it,
    and the grazing is bracketed between converged points to the bisection's width; one that
    fails between converged points, or a first point past it further from the next than 8
    times their sigma difference, leaves it not located (the step is a failed step)."""
    def at(br, a, s, start=None):
        if fails[0] < s < fails[1]:
            return None
        u = np.array([s, offset * (s >= 0.45)])
        return dict(u=u, tau=np.array([1.0, 0.0]), p=s, mu=MU, tests=specials.tests(MU), sigma=s,
                    contact={"signature": (int(s > 0.3),), "closest_approach": abs(s - 0.3)})
    monkeypatch.setattr(specials, "point_at", at)
    a = dict(at(None, None, 0.0), sigma=None)
    loc = specials.graze(type("Br", (), {"restart": lambda self, a, s: None})(), a, None, 1.0)
    assert (loc is not None) == found
    if found:
        last, past, beyond, sp = loc
        assert last["p"] <= 0.3 < past["p"] == sp["p"] and past["p"] - last["p"] == 2.0 ** -8
        assert beyond["p"] == 0.375


@pytest.mark.filterwarnings("ignore:SUNDIALS warned:pyspline.SplineWarning")
def test_the_z16_drive_turns_at_a_smooth_fold_past_its_grazing():
    """The 7-DOF Z16 drive near its cusp (ripple amplitude a = 0.085, docs/continuation.md):
    up the full-contact branch the teeth open at a grazing, and the branch turns 1.57 r/min
    further on, at a smooth fold (a real multiplier at +1), not at the grazing: no
    non-smooth fold is reported. At the grazing the multipliers do not jump: the rightmost
    pair either side of it differs by a square root of the distance (d at 0.003 r/min
    either side about a third of d at 0.03; a jump would keep d), so the branch cannot turn
    there."""
    from test_cont_drives import DRIVE
    import pyspline
    case = DRIVE.replace(rtol=1e-7, atol=1e-9, ripple_amp=[0.085, 0, 0, 0])
    ds = pyspline.continuation(case, "speed_rpm", 2587.0, 2590.0, progress=False,
                               ds_max=0.05, max_angle=0.3)
    kind, p = ds.special_type.values, ds.special_speed_rpm.values
    assert "nonsmooth_fold" not in kind and kind[0] == "grazing" and list(kind).count("fold") == 2
    g, (lo, hi) = p[0], np.sort(p[kind == "fold"])
    assert ds.switches.values[ds.speed_rpm.values < g].max() == 0       # full contact below
    assert 1.0 < hi - g < 2.5 and lo < hi, (g, lo, hi)
    crit = (ds.special_mu_real + 1j * ds.special_mu_imag).values[kind == "fold"]
    assert (np.abs(crit - 1) < 1e-2).all() and (ds.special_smooth.values[kind == "fold"] == 1).all()
    guess = ds.y0.values[np.argmin(np.abs(ds.speed_rpm.values - g))]

    def rightmost(x):
        mu = pyspline.periodic_orbit(case.replace(speed_rpm=x), guess=guess).multipliers
        pair = mu[np.argsort(-mu.real)][:2]
        return pair[np.argsort(pair.imag)]
    d = [np.abs(rightmost(g + h) - rightmost(g - h)).max() for h in (0.003, 0.03)]
    assert d[0] < 1e-2 and d[0] < 0.5 * d[1], d
