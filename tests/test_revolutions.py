"""Run length and sampling in shaft revolutions (revolutions, transient_revolutions,
outputs_per_revolution): a speed sweep samples every speed alike; 0 leaves the times as given;
a revolution field wins over its time field; bad values name the field."""
import subprocess

import numpy as np
import pytest

import pyspline
from conftest import CASES, PAPER, PAPER_SHAFTS

pytestmark = PAPER_SHAFTS   # expected warnings (conftest)
from pyspline.plots import sweeps as sweepplots

SPEEDS = [2000.0, 3700.0, 6000.0, 12500.0, 20000.0]


def times(**fields):
    return pyspline.load_case(dict(PAPER, **fields)).model.output_times()


@pytest.mark.parametrize("rpm", SPEEDS)
def test_every_speed_gets_the_same_revolutions_and_samples(rpm):
    period = 60.0 / rpm
    t = times(speed_rpm=rpm, revolutions=5, outputs_per_revolution=64)
    assert len(t) == 5 * 64 + 1
    assert t[0] == 0.0 and t[-1] == pytest.approx(5 * period, rel=1e-15)
    np.testing.assert_allclose(np.diff(t), period / 64, rtol=1e-12)
    # a transient in revolutions: outputs over the last 3 of 5 revolutions, from t0
    t = times(speed_rpm=rpm, t0=0.25, revolutions=5, transient_revolutions=2,
              outputs_per_revolution=64)
    assert len(t) == 3 * 64 + 1
    assert t[0] == pytest.approx(0.25 + 2 * period, rel=1e-15)
    assert t[-1] == pytest.approx(0.25 + 5 * period, rel=1e-15)


def test_outputs_per_revolution_over_a_run_in_seconds():
    """n_out = outputs_per_revolution x the output window's revolutions + 1 (nearest whole)."""
    t = times(speed_rpm=6000.0, t_end=0.1, t_transient=0.02, outputs_per_revolution=10)
    assert len(t) == 8 * 10 + 1 and t[0] == 0.02 and t[-1] == 0.1
    t = times(speed_rpm=6000.0, t_end=0.1, outputs_per_revolution=2.26)     # 22.6 -> 23 steps
    assert len(t) == 24


def test_revolutions_win_over_t_end_and_t_transient():
    t = times(speed_rpm=6000.0, t_end=0.5, t_transient=0.3, n_out=7, revolutions=4,
              transient_revolutions=1)
    assert len(t) == 7 and t[0] == pytest.approx(0.01) and t[-1] == pytest.approx(0.04)
    # t0 beyond the (ignored) t_end is no fault when revolutions gives the end
    t = times(speed_rpm=6000.0, t0=1.0, revolutions=2, outputs_per_revolution=4)
    assert len(t) == 9 and t[-1] == pytest.approx(1.02, rel=1e-15)


def test_zero_values_leave_the_times_as_given():
    """0 in every revolution field: the times from t0, t_end, t_transient, n_out, computed
    here as the core's run.f90 does (uniform on [t0 + t_transient, t_end], t_end exact)."""
    fields = dict(speed_rpm=4321.0, t0=0.013, t_end=0.171, t_transient=0.029, n_out=389)
    t = times(**fields, revolutions=0, transient_revolutions=0, outputs_per_revolution=0)
    ta, te, n = 0.013 + 0.029, 0.171, 389
    expect = ta + (te - ta) * np.arange(n) / (n - 1)
    expect[-1] = te
    np.testing.assert_array_equal(t, expect)
    np.testing.assert_array_equal(t, times(**fields))
    a = pyspline.simulate(pyspline.load_case(CASES / "paper_ideal.nml", t_end=0.02, n_out=129))
    b = pyspline.simulate(pyspline.load_case(CASES / "paper_ideal.nml", t_end=0.02, n_out=129,
                                             revolutions=0.0, outputs_per_revolution=0.0))
    np.testing.assert_array_equal(a.t, b.t)
    np.testing.assert_array_equal(a.Tm, b.Tm)
    np.testing.assert_array_equal(a.D2, b.D2)


def test_a_speed_sweep_runs_every_point_over_the_same_revolutions():
    rpm = [2000.0, 6000.0, 20000.0]
    ds = pyspline.sweep(dict(PAPER, revolutions=5, outputs_per_revolution=64), speed_rpm=rpm,
                        progress=False)
    assert (ds["error"].values == "").all()
    for k, s in enumerate(rpm):
        # a section point at every whole revolution after t0, the last at t_end
        np.testing.assert_allclose(ds["section_t"].values[k], np.arange(1, 6) * 60.0 / s,
                                   rtol=1e-12)
    # 64 samples per revolution at every speed: the same Nyquist order (32), so the same
    # orders of the binned spectrum are beyond it
    beyond = np.isnan(ds["Tm_spectrum"].values)
    assert beyond.any() and (beyond == beyond[0]).all()
    assert np.asarray(ds["order"])[~beyond[0]].max() <= 32.0
    assert sweepplots._duration(ds) is None     # the sampled time differs by speed


def test_executable_gives_the_same_times_and_run(exe, tmp_path):
    out = tmp_path / "out.csv"
    run = subprocess.run([exe, str(CASES / "paper_ideal.nml"), "--set", "revolutions=5",
                          "--set", "outputs_per_revolution=64", "--set", "speed_rpm=3700",
                          "-o", str(out)], capture_output=True, text=True)
    assert run.returncode == 0, run.stderr
    header, data = pyspline.core.read_csv(out)
    case = pyspline.load_case(CASES / "paper_ideal.nml", revolutions=5,
                              outputs_per_revolution=64, speed_rpm=3700.0)
    res = pyspline.simulate(case)
    assert header[0] == "t [s]" and len(res.t) == 5 * 64 + 1
    np.testing.assert_array_equal(data[:, 0], case.model.output_times())
    np.testing.assert_array_equal(data[:, 0], res.t)
    col = {h.split(" [")[0]: i for i, h in enumerate(header)}
    np.testing.assert_array_equal(data[:, col["Tm"]], res.Tm)


@pytest.mark.parametrize("fields, match", [
    (dict(revolutions=-1.0), "field revolutions "),
    (dict(transient_revolutions=-0.5), "field transient_revolutions "),
    (dict(outputs_per_revolution=-64.0), "field outputs_per_revolution "),
    (dict(revolutions=float("nan")), "field revolutions "),
    (dict(outputs_per_revolution=float("inf")), "field outputs_per_revolution "),
    (dict(revolutions=5.0, speed_rpm=0.0), "field revolutions = 5.* needs a positive speed_rpm"),
    (dict(transient_revolutions=1.0, speed_rpm=0.0),
     "field transient_revolutions .*needs a positive speed_rpm"),
    (dict(outputs_per_revolution=64.0, speed_rpm=0.0),
     "field outputs_per_revolution .*needs a positive speed_rpm"),
    (dict(revolutions=1e9, speed_rpm=6000.0), "field revolutions .*beyond"),
    (dict(revolutions=5.0, transient_revolutions=6.0), "field transient_revolutions .*t_end"),
    (dict(revolutions=5.0, t_transient=1.0), "field t_transient .*revolutions = 5"),
    (dict(revolutions=5.0, outputs_per_revolution=1e12), "field outputs_per_revolution .*memory"),
    (dict(revolutions=1e5, outputs_per_revolution=1e10, speed_rpm=6000.0),
     "field outputs_per_revolution .*"),
])
def test_bad_values_name_the_field(fields, match):
    with pytest.raises(pyspline.CaseError, match=match):
        pyspline.load_case(dict(PAPER, name="revs", **fields)).model


def test_executable_names_the_field(exe):
    run = subprocess.run([exe, str(CASES / "paper_ideal.nml"), "--set", "revolutions=3",
                          "--set", "speed_rpm=0"], capture_output=True, text=True)
    assert run.returncode == 2 and "field revolutions" in run.stderr
