"""Continuation of periodic orbits (pyspline.continuation, docs/continuation.md): held against
the closed-form forced response of the linear full-contact drive, the closed-form speed at
which that response first opens a tooth (grazing), folds of the backlash resonance with a
multiplier at +1 and the hysteresis of follow-up / follow-down sweeps between them, the CLI."""
import contextlib
import io
import re
import sys
import types
import warnings

import numpy as np
import pytest

import pyspline
import pyspline.cli
from conftest import CASES, PAPER_SHAFTS, jacobian
from test_orbits import A_RIPPLE, linear_scene, scale_of

pytestmark = PAPER_SHAFTS   # expected warnings (conftest)

# a drive whose ripple reaches the mesh: the paper's aligned drive at dof 3 with shafts of
# k_t = 1000 N m/rad (the paper's 7.9 filter the ripple out); its mesh mode near 45 Hz
# (damping ratio 0.014) is forced by a ripple of order 1, a = 0.15: the linear response would
# open the teeth near 2510 rpm, so the resonance bends over (softening), folds twice and
# hits the back flanks
RESONANCE = pyspline.load_case(CASES / "paper_ideal.nml", start="equilibrium", method="bdf",
                               rtol=1e-9, atol=1e-11, t_end=0.05, n_out=201, roots=True, dof=3,
                               k_t1=1e3, k_t2=1e3, ripple_order=[1, 0, 0, 0],
                               ripple_amp=[0.15, 0, 0, 0])


def forced_response(case, rpm, order, amp):
    """(y_eq, Y, A) of the linear full-contact drive at speed rpm: static equilibrium, complex
    amplitude of the forced response y_eq + Re[Y exp(i order omega t)], and its Jacobian."""
    c = case.replace(speed_rpm=float(rpm))
    model = c.model
    y_eq = model.start_state()
    A = jacobian(model, y_eq)
    info = model.info()
    B = np.zeros(14, complex)
    B[11] = -1j * (-info["r_b"] * c["t_d"] * amp / c["j_m"])
    return y_eq, np.linalg.solve(1j * order * info["omega"] * np.eye(14) - A, B), A


@pytest.fixture(scope="module")
def resonance_branch():
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", pyspline.SplineWarning)
        return pyspline.continuation(RESONANCE, "speed_rpm", 2300, 2530, progress=False)


@pytest.fixture(scope="module")
def linear_branch(tmp_path_factory):
    """The linear scene's branch over 2600-3800 r/min (steps of 0.1) from `pyspline continue`
    (its continuation.nc): (case, branch, the command's outcome, its directory). Held to the
    closed form and to the Python call."""
    import xarray as xr
    case, *_ = linear_scene(2.0)
    tmp = tmp_path_factory.mktemp("linear")
    (tmp / "scene.nml").write_text(case.text())
    run = cli(tmp, "continue", "scene.nml", "--field", "speed_rpm", "--start", "2600",
              "--stop", "3800", "--ds", "0.1", "--out", "out", "--quiet")
    assert run.returncode == 0, run.stderr
    with xr.open_dataset(tmp / "out" / "continuation.nc", engine="netcdf4") as ds:
        return case, ds.load(), run, tmp


def test_linear_branch_is_the_closed_form(linear_branch):
    """Full contact: every point of the branch over speed through the mesh resonance is the
    closed-form forced response y_eq + Re Y(omega), its multipliers exp(lambda_i T); all
    stable, no special point."""
    case, ds, *_ = linear_branch
    s = scale_of(case)
    assert ds.attrs["n_points"] >= 5 and ds.attrs["n_special"] == 0
    assert ds.speed_rpm[0] == 2600 and ds.speed_rpm[-1] == pytest.approx(3800, rel=1e-12)
    assert np.all(np.diff(ds.speed_rpm) > 0)
    amp = []
    for p, y0, mu in zip(ds.speed_rpm.values, ds.y0.values,
                         ds.mu_real.values + 1j * ds.mu_imag.values):
        y_eq, Y, A = forced_response(case, p, 2.0, A_RIPPLE)
        amp.append(np.abs(Y / s).max())
        # the corrector's tol (100 rtol) times |(I - M)^-1| (< 10 here), 1e5 below the response
        assert np.abs((y0 - (y_eq + Y.real)) / s).max() < 1e-7 < 1e-4 * amp[-1]
        want = np.exp(np.linalg.eigvals(A) * 2 * np.pi / (p * np.pi / 30))
        assert max(np.abs(mu - w).min() for w in want) < 1e-5
    assert ds.stable.all() and (ds.switches == 0).all()
    # T_m peak-to-peak peaks at the mesh mode (105 Hz: 3160 rpm at order 2)
    assert 2900 < float(ds.speed_rpm[int(np.argmax(ds.Tm_pp.data))]) < 3450


def test_grazing_where_the_linear_response_first_opens_a_tooth(resonance_branch):
    """The first grazing on the way up is where the closed-form linear response's swing of
    D2 reaches the static contact deflection |D2_eq| - c0 (every tooth opens at once in the
    aligned drive); located by bisection on the contact sequence of the sampled trajectory."""
    ds = resonance_branch
    kinds = list(ds.special_type.values)
    first = kinds.index("grazing")
    rpm = float(ds.special_speed_rpm[first])

    def margin(p):
        y_eq, Y, _ = forced_response(RESONANCE, p, 1.0, 0.15)
        return abs(y_eq[5]) - RESONANCE["c0"] - abs(Y[5])
    lo, hi = 2400.0, 2540.0
    assert margin(lo) > 0 > margin(hi)
    for _ in range(40):
        mid = (lo + hi) / 2
        lo, hi = (mid, hi) if margin(mid) > 0 else (lo, mid)
    # sampled at 201 points a period, the closest approach is missed by ~ (pi/200)^2 / 2 of
    # the swing, 0.1 rpm here
    assert rpm == pytest.approx(lo, abs=0.1)
    assert 0 <= float(ds.special_closest_approach[first]) < 1e-6 * RESONANCE["c0"] * 1e3


def test_folds_have_a_multiplier_at_one(resonance_branch):
    """The resonance bends over: two folds, each with a real multiplier at +1 (located by the
    secant on det(M - I)); stable below the first fold, unstable between, stable after."""
    ds = resonance_branch
    folds = np.flatnonzero(ds.special_type.values == "fold")
    assert len(folds) == 2
    mu = ds.special_mu_real.values[folds] + 1j * ds.special_mu_imag.values[folds]
    assert np.abs(mu - 1).max() < 1e-3, mu
    assert (ds.special_smooth.values[folds] == 1).all()
    p_hi, p_lo = ds.special_speed_rpm.values[folds]
    assert 2400 < p_lo < p_hi < 2530
    # the field turns back at the folds and only there; stable, unstable, stable between them
    p, stable = ds.speed_rpm.values, ds.stable.values.astype(bool)
    i1, i2 = np.flatnonzero(np.diff(np.sign(np.diff(p)))) + 1
    assert p[i1] == pytest.approx(p_hi, abs=0.5) and p[i2] == pytest.approx(p_lo, abs=0.5)
    assert stable[:i1].all() and not stable[i1 + 1:i2].any() and stable[i2 + 1:].all()

def test_follow_sweeps_jump_at_the_folds(resonance_branch):
    """follow='both' over the same scene: between the folds the up sweep stays on the lower
    stable branch and the down sweep on the upper one (T_m peak-to-peak within 2 % of the
    continuation's); below them both are on the one branch."""
    ds = resonance_branch
    folds = np.sort(ds.special_speed_rpm.values[ds.special_type.values == "fold"])
    speeds = np.linspace(2300, 2530, 24)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", pyspline.SplineWarning)
        sw = pyspline.sweep(RESONANCE.replace(t_end=1.0, t_transient=0.8, n_out=1001),
                            speed_rpm=speeds, follow="both", progress=False, spectrum=False)
    assert list(sw.direction.values) == ["up", "down"] and sw.attrs["follow"] == "both"
    assert (sw.error == "").all()
    pp = (sw.Tm_max - sw.Tm_min).values
    p, y, stable = ds.speed_rpm.values, ds.Tm_pp.values, ds.stable.values.astype(bool)
    lower = stable & (np.arange(len(p)) < np.argmin(np.abs(p - folds[1])))
    upper = stable & (np.arange(len(p)) > np.argmin(np.abs(p - folds[0])))
    inside = (speeds > folds[0] + 5) & (speeds < folds[1] - 5)
    assert inside.sum() >= 8
    for s, up, down in zip(speeds[inside], pp[0, inside], pp[1, inside]):
        assert up == pytest.approx(np.interp(s, p[lower], y[lower]), rel=0.02)
        order = np.argsort(p[upper])
        assert down == pytest.approx(np.interp(s, p[upper][order], y[upper][order]), rel=0.02)
        assert down > 1.5 * up
    # below the folds one attractor (the up chain's first run starts from the equilibrium:
    # not settled in its 0.8 s, left out)
    below = (speeds > speeds[0]) & (speeds < folds[0] - 15)
    want = np.interp(speeds[below], p[lower], y[lower])
    assert np.allclose(pp[:, below], want, rtol=0.02)


def cli(tmp_path, *args):
    """`pyspline ARGS` in this process, from tmp_path: the command line's parsing, output and
    exit status without a second interpreter's imports (`python -m pyspline` itself runs in
    tests/test_plots.py). Returns (returncode, stdout, stderr) by name."""
    out, err = io.StringIO(), io.StringIO()
    with contextlib.chdir(tmp_path), contextlib.redirect_stdout(out), \
            contextlib.redirect_stderr(err):
        code = pyspline.cli.main([str(a) for a in args])
    return types.SimpleNamespace(returncode=code, stdout=out.getvalue(), stderr=err.getvalue())


def test_cli_end_to_end(tmp_path, linear_branch):
    """`pyspline continue` on the linear scene (the fixture's run): continuation.nc holds the
    branch (the same numbers as the Python call: its first 4 points, where the Python call
    stops at max_points = 4), frequency_response.png is drawn, exit 0; a field that cannot be
    continued, or --check without --fold, is a CaseError naming it, exit 2."""
    case, ds, run, out = linear_branch
    assert "wrote out/continuation.nc" in run.stdout and "points on 1 branch(es)" in run.stdout
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", pyspline.SplineWarning)     # max_points reached
        want = pyspline.continuation(case, "speed_rpm", 2600, 3800, progress=False, ds=0.1,
                                     max_points=4)
    assert want.sizes["point"] == 4 and ds.sizes["point"] > 4
    assert np.array_equal(ds.speed_rpm[:4], want.speed_rpm)
    assert np.array_equal(ds.y0[:4], want.y0)
    assert ds.attrs["command"].startswith("pyspline continue")
    assert (out / "out" / "frequency_response.png").stat().st_size > 10_000
    path = out / "scene.nml"
    run = cli(tmp_path, "continue", str(path), "--field", "z", "--start", "16", "--stop", "20")
    assert run.returncode == 2 and "field z cannot be continued" in run.stderr, run.stderr
    # --check without --fold was ignored, whatever its value
    run = cli(tmp_path, "continue", str(path), "--field", "speed_rpm", "--start", "2600",
              "--stop", "3000", "--check", "x")
    assert run.returncode == 2 and "--check: an option of --fold" in run.stderr, run.stderr
    # a follow sweep from the command line: both directions in sweep.nc, one overlaid figure
    run = cli(tmp_path, "sweep", str(path), "--set", "speed_rpm=2600:3000:3", "--follow", "both",
              "--fix", "t_end=0.04", "--out", "sw", "--quiet")
    assert run.returncode == 0, run.stderr
    sw = pyspline.open_sweep(tmp_path / "sw")
    assert list(sw.direction.values) == ["up", "down"] and sw.attrs["follow"] == "both"
    assert "--follow=both" in sw.attrs["command"] and (sw.error == "").all()
    assert (tmp_path / "sw" / "bifurcation.png").exists()


def test_cli_special_lines_say_a_grazing_without_a_closest_approach():
    """The printed line of each special point; a grazing where every tooth switches has no
    closest approach (NaN, docs/continuation.md): said in words (the resonance's grazing at
    2414.95 r/min printed 'closest approach nan m')."""
    from pyspline.contcli import special_line
    xr = pytest.importorskip("xarray")
    ds = xr.Dataset({"special_type": ("special", ["grazing", "grazing", "fold"]),
                     "special_speed_rpm": ("special", [2509.7, 2414.95, 2410.64]),
                     "special_n": ("special", [1, 1, 1]),
                     "special_mu_real": ("special", [np.nan, np.nan, 1.0]),
                     "special_mu_imag": ("special", [np.nan, np.nan, 0.0]),
                     "special_closest_approach": ("special", [1.17e-7, np.nan, 2e-6]),
                     "special_Tm_pp": ("special", [61.4, 75.69, 80.89]),
                     "special_smooth": ("special", [1, 1, 1])}, attrs={"field": "speed_rpm"})
    lines = [special_line(ds, i) for i in range(3)]
    assert "closest approach 1.17e-07 m" in lines[0]
    assert "closest approach none (every tooth switches over the period)" in lines[1]
    assert "critical multiplier 1.0000+0.0000j" in lines[2]
    assert not any("nan" in line for line in lines), lines


@pytest.mark.parametrize("field, match", [
    ("method", "field method cannot be continued"),
    ("rtol", "field rtol cannot be continued"),
    ("nonsense", "unknown field 'nonsense'"),
    ("speed_rpm(2)", "field speed_rpm is not an array"),
    ("ripple_amp(5)", r"ripple_amp\(5\): index out of 1..4")])
def test_field_that_cannot_be_continued(field, match):
    with pytest.raises(pyspline.CaseError, match=match):
        pyspline.continuation(RESONANCE, field, 0.1, 0.2, progress=False)


def test_bad_range_and_follow():
    with pytest.raises(pyspline.CaseError, match=r"guess has shape \(6,\): a state has 14"):
        pyspline.continuation(RESONANCE, "t_d", 30, 31, guess=np.zeros(6), progress=False)
    with pytest.raises(pyspline.CaseError, match="speed_rpm = 0.0: the shaft does not turn"):
        pyspline.continuation(RESONANCE.replace(speed_rpm=0.0), "t_d", 30, 31, progress=False)
    with pytest.raises(pyspline.CaseError, match="monodromy = 'adjoint': 'exact'"):
        pyspline.continuation(RESONANCE, "t_d", 30, 31, monodromy="adjoint", progress=False)
    with pytest.raises(pyspline.CaseError, match="follow= needs exactly one swept field"):
        pyspline.sweep(RESONANCE, speed_rpm=[1, 2], t_d=[1, 2], follow="up", progress=False)
    with pytest.raises(pyspline.CaseError, match="follow must be one of up, down, both"):
        pyspline.sweep(RESONANCE, speed_rpm=[1, 2], follow="sideways", progress=False)


@pytest.mark.parametrize("kwargs, match", [
    (dict(stop=30.0), r"stop = 30.0: start and stop must differ"),
    (dict(stop=np.nan), r"stop = nan: must be finite"),
    (dict(stop="x"), r"stop = 'x': not a number"),
    (dict(ds=0.0), r"ds = 0.0: must be > 0"),
    (dict(ds=-0.1), r"ds = -0.1: must be > 0"),
    (dict(ds=np.nan), r"ds = nan: must be finite"),
    (dict(ds_min=0.5, ds_max=0.25), r"ds_min = 0.5: greater than ds_max = 0.25"),
    (dict(max_points=0), r"max_points = 0: a whole number >= 1"),
    (dict(max_points=2.5), r"max_points = 2.5: a whole number >= 1"),
    (dict(max_angle=0.0), r"max_angle = 0.0: must be > 0"),
    (dict(tol=0.0), r"tol = 0.0: must be > 0"),
    (dict(tol=-1e-7), r"tol = -1e-07: must be > 0"),
    (dict(tol=np.nan), r"tol = nan: must be finite"),
    (dict(n="1"), r"n = '1': the shaft revolutions of the period must be a whole number"),
    (dict(n=0), r"n = 0: the shaft revolutions"),
    (dict(band=(30.5, 31.0)), r"band = \(30.5, 31.0\): two values holding start = 30 and stop"),
    (dict(band=(30.0,)), r"band = \(30.0,\): two values holding"),
    (dict(band=("a", 31.0)), r"band = \('a', 31.0\): two values holding"),
])
def test_bad_arguments_name_themselves(kwargs, match):
    """Each bad argument: a CaseError naming it and why, before anything runs."""
    args = dict(stop=31.0) | kwargs
    stop = args.pop("stop")
    with pytest.raises(pyspline.CaseError, match=r"continuation in t_d: " + match):
        pyspline.continuation(RESONANCE, "t_d", 30.0, stop, progress=False, **args)


def test_field_values_outside_their_range():
    """A stop outside the field's valid range names the stop (not a difference step's value);
    a speed of 0 has no forcing period; a ripple order that does not repeat in one revolution
    is refused at the stop as at the start, and one whose valid values are whole numbers (1 to
    2) cannot be continued (no valid value within the difference step); periodic_orbit refuses
    tol = nan."""
    with pytest.raises(pyspline.CaseError, match=r"stop = 0 is not a valid value of speed_rpm: "
                       r".*speed_rpm = 0.0: the shaft does not turn"):
        pyspline.continuation(RESONANCE, "speed_rpm", 2300, 0.0, progress=False)
    with pytest.raises(pyspline.CaseError, match=r"stop = 1e\+07 is not a valid value of "
                       r"speed_rpm: .*speed_rpm"):
        pyspline.continuation(RESONANCE, "speed_rpm", 2300, 1e7, progress=False)
    with pytest.raises(pyspline.CaseError, match=r"stop = 1.5 is not a valid value of "
                       r"ripple_order\(1\): .*ripple_order = 1.5 .* does not repeat within n = 1"):
        pyspline.continuation(RESONANCE, "ripple_order(1)", 1.0, 1.5, progress=False)
    with pytest.raises(pyspline.CaseError, match=r"field ripple_order\(1\) cannot be continued: "
                       r"its valid values are isolated \(none within 3.16e-05 of start = 1: "
                       r".*does not repeat within n = 1"):
        pyspline.continuation(RESONANCE, "ripple_order(1)", 1.0, 2.0, progress=False)
    with pytest.raises(pyspline.CaseError, match=r"tol = nan: the scaled residual to reach"):
        pyspline.periodic_orbit(RESONANCE, tol=float("nan"))


def test_corrector_failure_keeps_the_branch_and_says_where(tmp_path):
    """A corrector allowed no Newton step cannot converge off the start: the step halves down
    to ds_min with every fallback (the other monodromy, then the other integrator), and the
    branch so far comes back with its status naming where, the residual reached and its
    history, and a SplineWarning; the CLI writes what it has, says where it stopped, exits 1."""
    case, *_ = linear_scene(2.0)
    where = (r"continuation in speed_rpm: the corrector did not converge after point 1 of branch "
             r"0, near speed_rpm = 26.*arclength step down to .*scaled residual .*wanted "
             r"1e-09\), history")
    with pytest.warns(pyspline.SplineWarning, match=where + r".*the branch so far is returned "
                      r"\(1 points"):
        ds = pyspline.continuation(case, "speed_rpm", 2600, 3800, progress=False,
                                   max_corrector=0, ds_min=0.04, ds_max=0.05)
    assert re.search(where, ds.attrs["status"]) and ds.attrs["n_points"] == 1
    assert float(ds.speed_rpm[0]) == 2600 and ds.residual[0] <= 1e-9
    assert ds.attrs["fallbacks"].count("speed_rpm = 2600: ") == 3, ds.attrs["fallbacks"]
    path = tmp_path / "scene.nml"
    path.write_text(case.replace(ripple_amp=[0.3, 0, 0, 0]).text())
    run = cli(tmp_path, "continue", str(path), "--field", "speed_rpm", "--start", "2600",
              "--stop", "3800", "--max-points", "3", "--out", "out", "--quiet")
    assert run.returncode == 1, run.stderr
    assert "stopped: max_points = 3 reached at speed_rpm = " in run.stderr
    assert "3 points on 1 branch(es)" in run.stdout
    assert (tmp_path / "out" / "frequency_response.png").stat().st_size > 10_000
    run = cli(tmp_path, "continue", str(path), "--field", "speed_rpm", "--start", "2600",
              "--stop", "3800", "--sweep", "-1", "--out", "out2", "--quiet")
    assert run.returncode == 2 and "--sweep -1: the follow sweep's number of points" in \
        run.stderr and not (tmp_path / "out2").exists(), run.stderr


def test_ctrl_c_keeps_the_points_found(tmp_path, monkeypatch):
    """Ctrl-C during `pyspline continue` (a KeyboardInterrupt at the 4th point) writes the
    points found so far as a stopped branch does (continuation.nc, the figure), its status
    'interrupted (Ctrl-C) at speed_rpm = ...', and exits 130 (it wrote nothing)."""
    import xarray as xr
    from pyspline.arclength import _Branch
    case, *_ = linear_scene(2.0)
    path = tmp_path / "scene.nml"
    path.write_text(case.replace(ripple_amp=[0.3, 0, 0, 0]).text())
    point, calls = _Branch.point, []

    def interrupted(self, res, prev):
        calls.append(1)
        if len(calls) == 4:
            raise KeyboardInterrupt
        return point(self, res, prev)
    monkeypatch.setattr(_Branch, "point", interrupted)
    run = cli(tmp_path, "continue", str(path), "--field", "speed_rpm", "--start", "2600",
              "--stop", "3800", "--out", "out", "--quiet")
    assert run.returncode == 130, run.stderr
    assert re.search(r"stopped: interrupted \(Ctrl-C\) at speed_rpm = 26\d\d", run.stderr)
    assert "3 points on 1 branch(es)" in run.stdout
    with xr.open_dataset(tmp_path / "out" / "continuation.nc", engine="netcdf4") as ds:
        assert ds.attrs["n_points"] == 3 and ds.attrs["status"].startswith("interrupted")
    assert (tmp_path / "out" / "frequency_response.png").stat().st_size > 10_000


def test_neimark_sacker_pair_on_the_unit_circle():
    """With a = 0.5 the upper branch, past its fold, loses stability to a torus and regains
    it: two Neimark-Sacker points, each with a complex pair located on the unit circle
    (secant on |mu|^2 - 1), and between them a complex pair outside it."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", pyspline.SplineWarning)
        ds = pyspline.continuation(RESONANCE.replace(ripple_amp=[0.5, 0, 0, 0]), "speed_rpm",
                                   2000, 2300, ds_max=0.5, progress=False)
    ns = np.flatnonzero(ds.special_type.values == "neimark_sacker")
    assert len(ns) == 2
    mu = ds.special_mu_real.values[ns] + 1j * ds.special_mu_imag.values[ns]
    assert np.abs(np.abs(mu) - 1).max() < 1e-3, mu
    assert (np.abs(np.angle(mu)) > 0.1).all() and (np.abs(np.angle(mu)) < np.pi - 0.1).all()
    assert (ds.special_smooth.values[ns] == 1).all()
    # between them (on the branch, after the first) the pair is outside: unstable
    first, second = ds.special_speed_rpm.values[ns]
    p = ds.speed_rpm.values
    i1, i2 = np.flatnonzero(np.diff(np.sign(np.diff(p)))) + 1     # the two folds
    after_fold = np.arange(len(p)) > i2
    inside = after_fold & (p > min(first, second) + 1) & (p < max(first, second) - 1)
    assert inside.sum() >= 2
    pair = np.abs(ds.mu_imag.values[inside]) > 1e-6
    outside = (ds.mu_abs.values[inside] > 1) & pair
    assert outside.any(axis=1).all() and not ds.stable.values[inside].any()


def test_follow_chains_on_processes_are_the_serial_ones():
    """An executor runs one chain per direction: the same numbers as serially; 'up' and
    'down' alone are the directions of 'both' (down listed in either order of the values)."""
    import concurrent.futures as cf
    case = RESONANCE.replace(t_end=0.3, t_transient=0.2, n_out=101)
    speeds = np.linspace(2400, 2520, 5)
    kw = dict(progress=False, spectrum=False)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", pyspline.SplineWarning)
        both = pyspline.sweep(case, speed_rpm=speeds, follow="both", **kw)
        with cf.ProcessPoolExecutor(2) as ex:
            par = pyspline.sweep(case, speed_rpm=speeds, follow="both", executor=ex, **kw)
        up = pyspline.sweep(case, speed_rpm=speeds, follow="up", **kw)
        down = pyspline.sweep(case, speed_rpm=speeds[::-1], follow="down", **kw)
    assert np.array_equal(both.Tm_max, par.Tm_max)
    assert np.array_equal(both.section_D2, par.section_D2, equal_nan=True)
    assert "direction" not in up.dims and up.attrs["follow"] == "up"
    assert np.array_equal(up.Tm_max, both.Tm_max.sel(direction="up"))
    assert np.array_equal(down.Tm_max.values[::-1], both.Tm_max.sel(direction="down"))
    # the directions differ here (2400-2520 r/min spans the folds' hysteresis)
    assert not np.allclose(both.Tm_max.sel(direction="up"), both.Tm_max.sel(direction="down"))


# double-sided impacts: the resonance's drive with a ripple twice the mean torque (the drive
# torque reverses every revolution, so the teeth strike both flanks, 4 switches per tooth and
# revolution); continued in speed, the period-1 orbit's multiplier moves smoothly through -1
# at 1623.6 r/min with the contact sequence unchanged (a smooth period doubling)
DOUBLING = RESONANCE.replace(ripple_amp=[2.0, 0, 0, 0], speed_rpm=1600.0)
STOP = 1635.0       # the period-2 branch stable from its fold (1618.4 r/min) on


@pytest.fixture(scope="module")
def doubling_branch():
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", pyspline.SplineWarning)
        return pyspline.continuation(DOUBLING, "speed_rpm", 1600, STOP, max_points=120,
                                     progress=False)


def test_period_doubling_switches_to_the_doubled_branch(doubling_branch):
    """A period doubling located with a multiplier at -1 (secant on det(M + I)) on a branch
    whose contact sequence does not change there; the branch switch follows the period-2
    orbit from it (subcritical: it bends back, folds, and comes back stable). Its points are
    genuine period-2 orbits: P^2(y) = y with P(y) far from y, two section points over two
    revolutions, and a brute-force run from the equilibrium settles on the same two points
    (at 1600 r/min, below the doubling, on the period-1 orbit: one section point)."""
    from pyspline.orbits import _period_map, map_and_monodromy
    ds = doubling_branch
    pd = np.flatnonzero(ds.special_type.values == "period_doubling")
    assert len(pd) == 1 and ds.special_branch.values[pd[0]] == 0
    mu = complex(ds.special_mu_real[pd[0]], ds.special_mu_imag[pd[0]])
    assert abs(mu + 1) < 1e-3 and ds.special_smooth.values[pd[0]] == 1, mu
    p_pd = float(ds.special_speed_rpm[pd[0]])
    assert 1600 < p_pd < STOP
    # branch 0 (period 1): stable below, a real multiplier below -1 above; one contact sequence
    b0 = ds.branch.values == 0
    p0, st0 = ds.speed_rpm.values[b0], ds.stable.values[b0].astype(bool)
    assert st0[p0 < p_pd - 0.5].all() and not st0[p0 > p_pd + 0.5].any()
    real = np.abs(ds.mu_imag.values[b0]) < 1e-9
    assert (np.where(real, ds.mu_real.values[b0], 0).min(axis=1)[p0 > p_pd + 0.5] < -1).all()
    assert len(set(ds.switches.values[b0])) == 1
    # branch 1: period 2, starts at the doubling, ends at stop stable
    b1 = np.flatnonzero(ds.branch.values == 1)
    assert len(b1) >= 5 and (ds.n.values[b1] == 2).all()
    assert float(ds.speed_rpm[b1[0]]) == pytest.approx(p_pd, abs=0.5)
    last = b1[-1]
    assert float(ds.speed_rpm[last]) == pytest.approx(STOP, rel=1e-12) and ds.stable[last]
    case = DOUBLING.replace(speed_rpm=STOP)
    y = ds.y0.values[last]
    T = 60 / STOP
    s = scale_of(case)
    y2, _, free = map_and_monodromy(case, 0.0, 2 * T, y)
    y1 = _period_map(case.model, 0.0, T, y[:, None])[0][:, 0]
    assert np.abs((y2 - y)[free] / s[free]).max() < 1e-5
    assert np.abs((y1 - y)[free] / s[free]).max() > 0.1
    # its section over two revolutions: two points (y and P(y)), one revolution apart
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", pyspline.SplineWarning)
        run = pyspline.simulate(case.replace(start="rest", dq0=list(y[:7]), dv0=list(y[7:]),
                                             t_end=40 * T, n_out=401, section="shaft"))
        brute = pyspline.simulate(case.replace(t_end=100 * T, t_transient=70 * T, n_out=401,
                                               section="shaft", max_steps=10_000_000))
    for sec in (run.section_y[-10:], brute.section_y[-10:]):
        even, odd = sec[0::2], sec[1::2]
        assert np.ptp(even[:, free], axis=0).max() / s[free].min() < 1e-4
        assert np.abs(even[0] - odd[0])[free].max() > 0.1 * s[free].min()
        def off(a, b):
            return np.abs((a - b)[free] / s[free]).max()
        # the two points are the orbit's y and P(y), in either order
        assert min(off(even[0], y) + off(odd[0], y1), off(even[0], y1) + off(odd[0], y)) < 1e-4
    # below the doubling (and below the period-2 branch's fold) the brute force is period 1
    T0 = 60 / 1600.0
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", pyspline.SplineWarning)
        low = pyspline.simulate(DOUBLING.replace(t_end=160 * T0, t_transient=130 * T0, n_out=401,
                                                 section="shaft", max_steps=10_000_000))
    s0 = scale_of(DOUBLING)
    assert float(ds.speed_rpm[0]) == 1600 and ds.stable[0]
    assert np.abs((low.section_y[-10:] - ds.y0.values[0])[:, free] / s0[free]).max() < 1e-3


def test_frequency_response_figure(doubling_branch):
    """The figure: each branch stable solid and unstable dashed (period 1 and period 2), the
    special points marked at their located values, the follow sweeps' points over them."""
    from pyspline.plots import frequency_response
    ds = doubling_branch
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", pyspline.SplineWarning)
        sw = pyspline.sweep(DOUBLING.replace(t_end=0.5, t_transient=0.3, n_out=201),
                            speed_rpm=np.linspace(1600, STOP, 4), follow="both",
                            progress=False, spectrum=False)
    fig = frequency_response(ds, "Tm_pp", sweep=sw)
    ax = fig.axes[0]
    labels = [t.get_text() for t in fig.legends[0].get_texts()]
    for want in ("period-1 orbits, stable", "period-1 orbits, unstable", "period-2 orbits, stable",
                 "period-2 orbits, unstable", "period doubling (mu = -1) (1)", "fold (mu = +1) (1)"):
        assert want in labels, labels
    assert any(lab.startswith("follow up") for lab in labels)
    assert any(lab.startswith("follow down") for lab in labels)
    lines = ax.get_lines()
    dashed = [ln for ln in lines if ln.get_linestyle() not in ("-", "None", "")]
    assert dashed and any(ln.get_linestyle() == "-" for ln in lines)
    pd = ds.special_type.values == "period_doubling"
    mark = [ln for ln in lines if ln.get_marker() == "s"]
    assert len(mark) == 1
    fx = float(ds.speed_rpm[0]) / lines[0].get_xdata()[0]       # the axis' unit prefix
    fy = float(ds.Tm_pp[0]) / lines[0].get_ydata()[0]
    assert np.allclose(mark[0].get_xdata() * fx, ds.special_speed_rpm.values[pd])
    assert np.allclose(mark[0].get_ydata() * fy, ds.special_Tm_pp.values[pd])


def test_bench_continuation_quick():
    """bench/run.py continuation --quick: both monodromies on both scenes, interleaved; the
    two continuations of the resonance meet the same special points at the same speeds and
    end on the same orbit (no timing asserted)."""
    import importlib.util
    from conftest import ROOT
    sys.path.insert(0, str(ROOT / "bench"))
    spec = importlib.util.spec_from_file_location("bench_continuation",
                                                  ROOT / "bench" / "continuation.py")
    bc = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(bc)
    rows, summary = bc.measure(quick=True, repeat=1)
    assert [(r["scene"], r["monodromy"]) for r in rows] == [
        ("resonance", "exact"), ("resonance", "fd"), ("impacting", "exact"), ("impacting", "fd")]
    assert all(r["steps"] >= r["points"] > 5 and r["step_median_s"] > 0 for r in rows)
    res, imp = summary
    assert res["agree"]["branches"] == "1/1" and res["agree"]["specials"]
    assert not any("missing" in s for s in res["agree"]["specials"])
    assert res["agree"]["d_last_y0"] < 1e-5 and imp["agree"]["d_last_y0"] < 1e-5
    assert imp["agree"]["branches"].startswith("2/")      # exact: the doubled branch
    lines = bc.format_summary(summary, 1)
    assert sum("fd / exact" in line for line in lines) == 2
