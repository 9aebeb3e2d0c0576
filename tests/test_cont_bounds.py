"""Whole calls bounded in wall time (docs/continuation.md, "Time bounds"): periodic_orbit ends
with an OrbitError naming its max_seconds; continuation, branches and fold_curve return what
they computed with attrs['status'] naming the bound and a SplineWarning; `pyspline continue
--max-seconds`. On the 7-DOF Z16 drive of tests/test_cont_drives.py and the chaotic
rattle_z24, whose periodic_orbit took 110 s to fail without a bound."""
import math
import re
import time
import warnings

import numpy as np
import pytest
import xarray as xr

import pyspline
from conftest import CASES
from test_cont_drives import BAND, DRIVE

#: slack of a bound [s], wall time on a machine shared by several processes a core: the
#: corrector under way (its map runs are cut only every 20000 steps), the point's period,
#: the dataset; the calls these bounds stop take 20-300 s without them
SLACK = 5.0


@pytest.fixture(scope="module", autouse=True)
def warm():
    """xarray imports its array backends at the first Dataset (seconds): not the bound's."""
    xr.Dataset({"x": ("p", np.zeros(2))})


def timed(call):
    t = time.perf_counter()
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always", pyspline.SplineWarning)
        out = call()
    return out, time.perf_counter() - t, [str(w.message) for w in caught
                                          if issubclass(w.category, pyspline.SplineWarning)]


@pytest.mark.filterwarnings("ignore:case rattle_z24:pyspline.SplineWarning")  # soft shafts
def test_periodic_orbit_ends_at_its_bound_naming_it():
    """rattle_z24 (chaotic: no period-1 orbit) fails within 0.5 s and the slack, its settling
    run included, with an OrbitError naming the bound; the default bound is 60 s."""
    case = pyspline.load_case(CASES / "rattle_z24.nml")
    t = time.perf_counter()
    with pytest.raises(pyspline.OrbitError, match=r"periodic_orbit .*max_seconds = 0.5 s"):
        pyspline.periodic_orbit(case, max_seconds=0.5)
    assert time.perf_counter() - t < 0.5 + SLACK
    assert pyspline.orbits.MAP_SECONDS == 60


def test_continuation_keeps_its_points_at_the_bound():
    """Started on the orbit at 2200 r/min, a 0.5 s bound stops the continuation of the band
    within the slack: the branch so far (points from 2200 r/min, in order), the status
    naming the bound and where, one SplineWarning."""
    orb = pyspline.periodic_orbit(DRIVE.replace(speed_rpm=BAND[0]))
    ds, took, said = timed(lambda: pyspline.continuation(DRIVE, "speed_rpm", *BAND, guess=orb.y0,
                                                         progress=False, max_seconds=0.5))
    assert took < 0.5 + SLACK
    st = ds.attrs["status"]
    assert "continuation (case paper_ideal), max_seconds = 0.5 s, was reached at speed_rpm" in st
    p = ds.speed_rpm.values
    assert p[0] == BAND[0] and BAND[0] < p[-1] < BAND[1] and (np.diff(p) > 0).all()
    assert f"{p[-1]:.6g}" in st and len(said) == 1 and st in said[0]


def test_branches_and_fold_curve_end_at_their_bounds():
    """branches: a bound that passes within the seeding sweep leaves no branch traced: an
    OrbitError naming it. fold_curve over three values of the ripple amplitude within 0.75 s:
    the extended system's seed stops at it, every value's status names it; the repeated
    method's each value gets its share of what is left (0.25 s for the first), every one stops
    at it
    (its status names the share), the call within the bound and the slack, a SplineWarning;
    the check sweep after it is not run (-1)."""
    with pytest.raises(pyspline.OrbitError, match=r"branches, max_seconds = 0.001 s, was "
                       "reached before any branch"):
        pyspline.branches(DRIVE, "speed_rpm", *BAND, points=3, progress=False,
                          max_seconds=1e-3)
    fc, took, said = timed(lambda: pyspline.fold_curve(
        DRIVE, "speed_rpm", *BAND, "ripple_amp(1)", [0.25, 0.2, 0.18], progress=False,
        check=[0.25], max_seconds=0.75))
    assert took < 0.75 + SLACK
    assert all("fold_curve, max_seconds = 0.75 s, was reached" in s for s in fc.status.values)
    assert (fc.coexist == -1).all() and "before the check sweeps at 0.25" in fc.attrs["status"]
    assert len(said) == 1 and fc.attrs["status"] in said[0]
    fc, took, said = timed(lambda: pyspline.fold_curve(
        DRIVE, "speed_rpm", *BAND, "ripple_amp(1)", [0.25, 0.2, 0.18], progress=False,
        check=[0.25], max_seconds=0.75, method="repeated"))
    assert took < 0.75 + SLACK
    st = fc.status.values
    assert re.search(r"fold_curve at ripple_amp\(1\) = 0.25, max_seconds = 0.2(5|4\d) s, "
                     "was reached", st[0]), st[0]    # 0.248: a few ms passed before the first
    assert all("max_seconds" in s for s in st), st
    assert (fc.coexist == -1).all() and "before the check sweeps at 0.25" in fc.attrs["status"]
    assert len(said) == 1 and fc.attrs["status"] in said[0]


def test_a_bounded_simulate_is_the_unbounded_one():
    """A run given a wall-time bound it does not reach (the integrator then advances in
    chunks of 20000 steps between clock reads: this run takes about 35000) gives the
    unbounded run's numbers bit for bit."""
    from pyspline.result import run
    case = DRIVE.replace(speed_rpm=2450.0, t_end=3.0, n_out=301)
    free, bound = pyspline.simulate(case), run(case.model, max_seconds=1e3)
    assert free.stats["steps"] > 20000, free.stats["steps"]
    np.testing.assert_array_equal(bound.y, free.y)
    np.testing.assert_array_equal(bound.Tm, free.Tm)


def test_follow_sweeps_end_at_the_call_bound():
    """The follow sweeps inside branches and fold_curve share the call's bound: runs of 1000 s
    without the closed-form tail (a minute each; the sweeps would take minutes) are cut where
    it passes, the rest not run.
    branches with 0.25 s: an OrbitError naming it within the slack. fold_curve with 3 s over a
    10 r/min band (its continuation: one step, complete): the check sweep is cut, each
    speed's verdict -1, the status naming the bound, the call within the bound and the
    slack."""
    long = DRIVE.replace(t_end=1000.0, n_out=201, linear_tail=False)
    t = time.perf_counter()
    with pytest.raises(pyspline.OrbitError, match=r"branches, max_seconds = 0.25 s, was "
                       "reached"):
        pyspline.branches(DRIVE, "speed_rpm", 2200, 2210, points=3, progress=False,
                          sweep_case=long, max_seconds=0.25)
    assert time.perf_counter() - t < 0.25 + SLACK
    fc, took, said = timed(lambda: pyspline.fold_curve(
        DRIVE, "speed_rpm", 2200, 2210, "ripple_amp(1)", [0.25], progress=False, check=[0.25],
        check_points=3, check_case=long, max_seconds=3))
    assert took < 3 + SLACK
    assert list(fc.status.values) == ["complete"] and (fc.coexist == -1).all()
    assert "max_seconds = 3 s, was reached before the check sweeps at 0.25" in said[0]


def test_a_failed_state_run_keeps_the_branch(monkeypatch):
    """A point's one-period state run (its T_m, forces and contact sequence; bounded as a map
    run) that fails past 2250 r/min fails the step, not the call: the full-contact branch from
    2200 r/min comes back up to 2250, its status naming the failure, with a SplineWarning."""
    import importlib
    cont = importlib.import_module("pyspline.arclength")
    original = cont._Branch.trajectory

    def failing(self, y, p):
        if p > 2250:
            raise pyspline.SolverError("the state run failed here")
        return original(self, y, p)
    monkeypatch.setattr(cont._Branch, "trajectory", failing)
    ds, _, said = timed(lambda: pyspline.continuation(DRIVE, "speed_rpm", 2200, 2300,
                                                      progress=False, ds_min=0.01))
    p = ds.speed_rpm.values
    assert p[0] == 2200 and 2200 < p[-1] <= 2250 and (np.diff(p) > 0).all()
    assert "(last failure: the state run failed here)" in ds.attrs["status"]
    assert len(said) == 1 and ds.attrs["status"] in said[0]


@pytest.mark.parametrize("bad", [0.0, -1.0, math.nan, "60", None, True])
def test_bad_bound_is_a_case_error(bad):
    with pytest.raises(pyspline.CaseError, match="max_seconds"):
        pyspline.periodic_orbit(DRIVE, max_seconds=bad)
    with pytest.raises(pyspline.CaseError, match="continuation .*max_seconds"):
        pyspline.continuation(DRIVE, "speed_rpm", *BAND, progress=False, max_seconds=bad)
    with pytest.raises(pyspline.CaseError, match="fold_curve: max_seconds"):
        pyspline.fold_curve(DRIVE, "speed_rpm", *BAND, "ripple_amp(1)", [0.2],
                            max_seconds=bad)
    with pytest.raises(pyspline.CaseError, match="branches: max_seconds"):
        pyspline.branches(DRIVE, "speed_rpm", *BAND, max_seconds=bad)


def test_cli_max_seconds(tmp_path):
    """`pyspline continue --max-seconds 1` writes the branch so far and says where it
    stopped, exit 1."""
    from test_continuation import cli
    path = tmp_path / "drive.nml"
    path.write_text(DRIVE.text())
    run = cli(tmp_path, "continue", str(path), "--field", "speed_rpm", "--start",
              str(BAND[0]), "--stop", str(BAND[1]), "--quiet", "--out", "out",
              "--max-seconds", "1")
    assert run.returncode == 1 and "stopped: the wall-time bound" in run.stderr, run.stderr
    ds = xr.open_dataset(tmp_path / "out" / "continuation.nc", engine="netcdf4")
    assert "max_seconds = 1 s" in ds.attrs["status"] and ds.sizes["point"] >= 1
