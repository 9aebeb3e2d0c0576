"""The integrator layer (fortran/integration/integrator.f90): SUNDIALS' own messages never reach stdout or
stderr (captured at the file-descriptor level, where C's fprintf writes), in any entry point;
its warnings come back counted, once per run (a SplineWarning; spline-dyn: a 'warning:' line);
map runs are bounded in steps and in wall time, and a run that meets a bound names it.

The warning scene: physical_z24 started at t0 = 9.99e5 s, where the scaled time is about 3e8
and a step of a few 1e-9 no longer changes it: CVODE and ERKStep warn "t + h = t"."""
import math
import os
import re
import subprocess
import tempfile
import warnings
from contextlib import contextmanager

import numpy as np
import pytest

import pyspline
from conftest import CASES, PAPER_SUPPORTS
from pyspline import orbits

pytestmark = [PAPER_SUPPORTS]   # expected warnings (conftest)

T0 = 9.99e5
SPAN = 1e-3
COUNT = re.compile(r"SUNDIALS warned (\d+) time\(s\) in this run")
RAW = ("[CVODE", "[ARKODE", "WARNING]", "ERROR]")   # how SUNDIALS prints its messages itself


def far_case(**fields):
    case = pyspline.load_case(CASES / "physical_z24.nml")
    return case.replace(t0=T0, t_end=T0 + SPAN, t_transient=0.0, n_out=3, **fields)


@contextmanager
def captured_fds():
    """Everything written to file descriptors 1 and 2 inside the block (C's stdio too)."""
    out = {}
    with tempfile.TemporaryFile() as f:
        saved = [os.dup(1), os.dup(2)]
        try:
            os.dup2(f.fileno(), 1)
            os.dup2(f.fileno(), 2)
            yield out
        finally:
            os.dup2(saved[0], 1)
            os.dup2(saved[1], 2)
            for fd in saved:
                os.close(fd)
            f.seek(0)
            out["text"] = f.read().decode("utf-8", "replace")


def quiet_with_warnings(call):
    """Run call with fds 1, 2 captured; no SUNDIALS text may appear there. Returns the messages
    of the SplineWarnings about SUNDIALS' warnings."""
    with captured_fds() as out, warnings.catch_warnings(record=True) as got:
        warnings.simplefilter("always")
        call()
    assert not any(r in out["text"] for r in RAW), out["text"][:2000]
    assert "t + h = t" not in out["text"]
    return [str(w.message) for w in got
            if issubclass(w.category, pyspline.SplineWarning) and COUNT.search(str(w.message))]


ENTRY_POINTS = {
    "simulate": lambda c: pyspline.simulate(c),
    "lyapunov_tangent": lambda c: pyspline.simulate(c.replace(lyapunov=True,
                                                              lyapunov_method="tangent")),
    "lyapunov_copy": lambda c: pyspline.simulate(c.replace(lyapunov=True)),
    "map_and_monodromy": lambda c: orbits.map_and_monodromy(c, T0, T0 + SPAN,
                                                            pyspline.start_state(c)),
    "period_map": lambda c: orbits._period_map(pyspline.load(c), T0, T0 + SPAN,
                                               pyspline.start_state(c)[:, None]),
}


@pytest.mark.parametrize("entry", ENTRY_POINTS)
@pytest.mark.parametrize("method", [dict(method="adams", roots=True), dict(method="bdf"),
                                    dict(method="erk", roots=True)], ids=["adams", "bdf", "erk"])
def test_no_sundials_text_but_one_counted_warning(entry, method):
    case = far_case(**method)
    msgs = quiet_with_warnings(lambda: ENTRY_POINTS[entry](case))
    # the variational run is CVODE's whatever the method (spline_variational); a simulate's
    # first warning comes from its state run, before the Lyapunov runs
    lib = "ARKODE" if method["method"] == "erk" and entry != "map_and_monodromy" else "CVODE"
    assert len(msgs) == 1, msgs                            # once per run
    assert int(COUNT.search(msgs[0]).group(1)) >= 1
    assert f"the first, from {lib} in " in msgs[0] and "t + h = t" in msgs[0], msgs[0]
    assert msgs[0].startswith(f"case {case.name}: ")


def test_ordinary_runs_raise_no_integrator_warning():
    case = pyspline.load_case(CASES / "physical_z24.nml").replace(t_end=0.02, t_transient=0.0,
                                                                   n_out=11)
    for call in ENTRY_POINTS.values():
        if call is ENTRY_POINTS["map_and_monodromy"] or call is ENTRY_POINTS["period_map"]:
            call = {ENTRY_POINTS["map_and_monodromy"]: lambda c: orbits.map_and_monodromy(
                c, 0.0, 0.01, pyspline.start_state(c)),
                    ENTRY_POINTS["period_map"]: lambda c: orbits._period_map(
                pyspline.load(c), 0.0, 0.01, pyspline.start_state(c)[:, None])}[call]
        assert quiet_with_warnings(lambda: call(case)) == []


def test_spline_dyn_prints_the_count_as_a_warning_line(exe, tmp_path):
    case = far_case(method="adams", roots=True)
    nml = tmp_path / "far.nml"
    case.to_namelist(nml)
    run = subprocess.run([exe, str(nml), "-o", str(tmp_path / "far.csv")], capture_output=True,
                         text=True)
    assert run.returncode == 0, run.stderr
    assert not any(r in run.stderr + run.stdout for r in RAW), run.stderr
    lines = [ln for ln in run.stderr.splitlines() if COUNT.search(ln)]
    assert len(lines) == 1 and lines[0].startswith("spline-dyn: warning: case "), run.stderr
    # the same count as Python's warning for the same run
    msgs = quiet_with_warnings(lambda: pyspline.simulate(case))
    assert COUNT.search(msgs[0]).group(1) == COUNT.search(lines[0]).group(1)


def test_a_failure_carries_sundials_text_not_stderr():
    """A run that fails inside CVODE: its own text joins the error, none is printed."""
    case = far_case(method="adams", roots=True, max_steps=3)
    with captured_fds() as out:
        with pytest.raises(pyspline.SolverError, match="max_steps = 3"):
            orbits.map_and_monodromy(case, T0, T0 + SPAN, pyspline.start_state(case))
    assert not any(r in out["text"] for r in RAW), out["text"]


@pytest.fixture(scope="module")
def z24():
    case = pyspline.load_case(CASES / "physical_z24.nml", method="adams", roots=True)
    return case, pyspline.start_state(case), 2 * np.pi / (case["speed_rpm"] * np.pi / 30)


@pytest.mark.parametrize("field", ["max_steps", "max_total_steps"])
def test_variational_run_bounded_in_steps(z24, field):
    """The variational run counts its steps over every restart at a contact switch (the state
    run's bounds, spline_integrator::integrator_advance): a bound below what the period takes
    fails, naming the field, and the same bound above it does not."""
    case, y0, period = z24
    with pytest.raises(pyspline.SolverError, match=rf"variational run took {field} = 50 "):
        orbits.map_and_monodromy(case.replace(**{field: 50}), 0.0, period, y0)
    y1, M, _ = orbits.map_and_monodromy(case.replace(**{field: 10 ** 6}), 0.0, period, y0)
    y1b, Mb, _ = orbits.map_and_monodromy(case, 0.0, period, y0)
    np.testing.assert_array_equal(y1, y1b)
    np.testing.assert_array_equal(M, Mb)


def test_map_runs_bounded_in_wall_time(z24):
    """A wall-time bound met stops the map with a SolverError that names it (both maps)."""
    case, y0, period = z24
    for call in (lambda s: orbits.map_and_monodromy(case, 0.0, period, y0, max_seconds=s),
                 lambda s: orbits._period_map(pyspline.load(case), 0.0, period,
                                              np.repeat(y0[:, None], 3, axis=1), max_seconds=s)):
        with pytest.raises(pyspline.SolverError, match=r"wall-time bound max_seconds = 1.00E-09 s"):
            call(1e-9)
        for bad in (0.0, -1.0, math.nan, "60", None):
            with pytest.raises(pyspline.CaseError, match="max_seconds"):
                call(bad)


def test_wall_bound_leaves_the_numbers_unchanged(z24):
    """Under a wall-time bound the integrator is called in chunks of steps (the clock read
    between them): the map and its monodromy are the same to the bit. Over 3 periods each
    takes more steps in one call than a chunk (spline_integrator's wall_chunk = 20000: a bound
    of one chunk stops it)."""
    case, y0, period = z24
    long = case.replace(t_end=5 * period, max_steps=10 ** 6)
    chunk = long.replace(max_steps=20000)
    with pytest.raises(pyspline.SolverError, match="took max_steps = 20000"):
        orbits.map_and_monodromy(chunk, 0.0, 3 * period, y0)
    with pytest.raises(pyspline.SolverError, match="took max_steps = 20000"):
        orbits._period_map(pyspline.load(chunk), 0.0, 3 * period, y0[:, None])
    runs = [orbits.map_and_monodromy(long, 0.0, 3 * period, y0, max_seconds=s)
            for s in (math.inf, 1e6)]
    np.testing.assert_array_equal(runs[0][0], runs[1][0])
    np.testing.assert_array_equal(runs[0][1], runs[1][1])
    maps = [orbits._period_map(pyspline.load(long), 0.0, 3 * period, y0[:, None], max_seconds=s)[0]
            for s in (math.inf, 1e6)]
    np.testing.assert_array_equal(maps[0], maps[1])
