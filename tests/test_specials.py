"""The classification of a continued branch's special points (pyspline/specials.py,
docs/continuation.md) on branch records made up here: a grazing at which the field turns back
is a non-smooth fold, one the branch passes through is a grazing, and a grazing next to a
smooth fold (a multiplier at +1) stays a grazing beside that fold. (None of the project's
scenes turns at a grazing: their folds are smooth, 0.8 to 4.3 r/min from the nearest grazing;
the records stand in for one.)"""
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
