"""How a continued branch ends before its band's end (pyspline/ends.py, docs/continuation.md):
the n-general tests of a period-n branch's merge into the period-n/2 branch and of a branch
that comes back onto its own orbit, on section points and branch records made up here (the
doubling scene's period-4 branch comes back onto itself after 77 s: docs/continuation.md,
Limits; its merge is tested on the scene, tests/test_cont_more.py), and their wiring into
continuation on the linear scene, with the failed-step bound and its fallbacks' shares."""
import re
import warnings
from types import SimpleNamespace

import numpy as np
import pytest

import pyspline
import pyspline.arclength as arc
from pyspline import ends
from conftest import PAPER_SHAFTS


def _branch(n):
    return SimpleNamespace(n=n, tol=1e-6, prob=SimpleNamespace(name="speed_rpm"))


def _pt(z, q):
    return dict(u=np.array([z, q]), p=q)


@pytest.mark.parametrize("n", [2, 4])
def test_merged_at_the_middle_section_point(n):
    """A period-n branch (z its distance from the period-n/2 orbit along the critical
    eigenvector; P^(n/2) mirrors it, the other section points lie far off) ends where its next
    point is a fixed point of P^(n/2), or where P^(n/2) of it lies nearer the point before
    than the point itself (past the doubling, on its own other half); not before. An odd
    number of section points (no period-n/2 orbit) never merges."""
    br, a = _branch(n), _pt(0.3, 0.0)

    def secs(z):        # its section points y, P(y), ..., P^(n-1)(y): P^(n/2) is -z
        far = [_pt(5.0 + k, 0.01)["u"] for k in range(n // 2 - 1)]
        return np.array([[z, 0.01], *far, [-z, 0.01], *far])
    assert ends.merged(br, a, _pt(0.2, 0.01), secs(0.2)) == ""
    said = ends.merged(br, a, _pt(-0.1, 0.01), secs(-0.1))
    assert re.fullmatch(rf"the period-{n} branch reached a period doubling between speed_rpm = "
                        rf"0 and 0.01, where it merges into the period-{n // 2} branch .*", said)
    assert ends.merged(br, a, _pt(1e-7, 0.01), secs(1e-7))
    assert ends.apart(1722.90168, 1722.902139) == ("1722.9017", "1722.9021")   # never "1722.9 and 1722.9"
    assert ends.merged(br, a, _pt(1e-7, 0.01), secs(1e-7)[:n - 1]) == ""


def test_returned_onto_its_own_other_half():
    """A made-up period-2 branch that closes on itself with its section points swapped: its
    points u(t) = (cos t, sin t, q = cos 2t / 10) at t = 0, 0.2, ..., P(u(t)) = u(t + pi).
    It has come back onto its own orbit at the first point past t = pi (P of it lies on the
    branch traced before, between its first two points), not before; the segment ending at the
    last point is left out (next to a doubling the other half lies that near it)."""
    def u(t):
        return np.array([np.cos(t), np.sin(t), 0.1 * np.cos(2 * t)])
    br, pts, said = _branch(2), [], ""
    for t in np.arange(0, 5, 0.2):
        new = dict(u=u(t), p=0.1 * np.cos(2 * t))
        said = ends.returned(br, pts, new, np.array([u(t), u(t + np.pi)]))
        if said:
            break
        pts.append(new)
    assert len(pts) == 16 and t == pytest.approx(3.2), t
    assert re.fullmatch(r"the period-2 branch came back onto its own orbit at speed_rpm = "
                        r"\S+ \(its section point 1 on the branch traced before, .*\): it ends "
                        r"at \S+", said), said
    assert not ends.returned(br, pts[:2], dict(u=u(0.4), p=0.0), np.array([u(0.4), u(0.2)]))


@PAPER_SHAFTS
def test_continuation_ends_where_it_comes_back(monkeypatch):
    """The wiring: on the linear scene, whose other section points are made up to be the
    branch's second point (two of them: an odd count, no merge), the branch ends at its third
    point (the fourth one's lies on the branch traced before the third), status and a
    SplineWarning saying so."""
    from test_orbits import linear_scene
    case, *_ = linear_scene(2.0)
    first = []

    def sections(self, pt):
        first.append(first[0] if first else pt["u"])
        return np.array([pt["u"], first[0], first[0]])
    monkeypatch.setattr(arc._Problem, "sections", sections)
    with pytest.warns(pyspline.SplineWarning, match="came back onto its own orbit"):
        ds = pyspline.continuation(case, "speed_rpm", 2600, 2700, progress=False, ds_max=0.05)
    assert ds.sizes["point"] == 3 and float(ds.speed_rpm[-1]) < 2700
    assert re.fullmatch(r"the period-1 branch came back onto its own orbit at speed_rpm = \S+ "
                        r".*: it ends at \S+", ds.attrs["status"]), ds.attrs["status"]


@PAPER_SHAFTS
def test_failing_steps_end_within_their_bound(monkeypatch):
    """The linear scene whose first method has a wrong dF/dp (tests/test_cont_more.py) and
    whose fallbacks keep the tangent it had (their own switched off): every step from the
    start fails. With the bound per point lowered to 28 corrector iterations, 8 of them each
    fallback's (one failed step: max_corrector + 1), the branch is its start alone, its status naming the bound, after at most one
    failed step's iterations (max_corrector + 1, and one for a fallback's tangent) past it: the
    evaluations counted here, the start's included. Each of the three fallbacks is tried (the
    halvings of the method before it stop where only the shares of the fallbacks not yet tried
    are left; before, the first fallback's halvings took the whole bound)."""
    from test_orbits import linear_scene
    case, *_ = linear_scene(2.0)
    evaluate, calls = arc._Problem.evaluate, []

    def wrong(self, y, u, n):
        calls.append((self.how, self.case["method"]))
        F, J, M, yy = evaluate(self, y, u, n)
        if self.how == "exact":
            J = np.c_[J[:, :-1], 1e3 * np.random.default_rng(1).standard_normal(len(F))]
        return F, J, M, yy
    monkeypatch.setattr(arc._Problem, "evaluate", wrong)
    monkeypatch.setattr(arc, "_retangent", lambda *args: None)
    monkeypatch.setattr(ends, "FAILED_EVALS", 28)
    monkeypatch.setattr(ends, "FALLBACK_EVALS", 8)
    with pytest.warns(pyspline.SplineWarning, match="within the bound of 28 corrector"):
        ds = pyspline.continuation(case, "speed_rpm", 2600, 2650, progress=False, ds_min=0.01,
                                   max_points=6)
    taken = int(re.search(r"within the bound of 28 corrector iterations for a point's failed "
                          r"steps \((\d+) taken\)", ds.attrs["status"]).group(1))
    assert ds.sizes["point"] == 1 and 28 < taken <= 28 + 6 + 2, ds.attrs["status"]
    assert ds.attrs["fallbacks"].count("speed_rpm = 2600") == 3, ds.attrs["fallbacks"]
    stages = [calls[0]] + [c for i, c in enumerate(calls[1:]) if c != calls[i]]
    assert len(stages) == 4 and len(set(stages)) == 4, stages
    assert len(calls) <= 2 + taken, len(calls)
