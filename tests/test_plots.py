"""What the figures show: no round-off drawn as content, colour scales past a start transient,
spectra that end at the Nyquist frequency and say when the tooth pass lies beyond it, numbers in
short engineering notation; and the exit codes of every pyspline command (README)."""
import warnings
from pathlib import Path

import numpy as np
import pytest
from test_analysis import _load_src

pl = _load_src("plots")
ps = _load_src("plots.style")
SplineWarning = _load_src("errors").SplineWarning
CORPUS = Path(__file__).resolve().parent / "corpus"


def _texts(ax):
    return " ".join(t.get_text() for t in ax.texts)


# --------------------------------------------------------------------------- notation

@pytest.mark.parametrize("value, text", [
    (4.9999999999999996e-05, "50e-6"), (1e-4, "100e-6"), (2.5e-5, "25e-6"), (1.92e9, "1.92e9"),
    (30.7, "30.7"), (6000.0, "6000"), (12000.0, "12000"), (0.5, "0.5"), (0.0, "0"),
    (-2.5e-7, "-250e-9"), (999.96e-6, "1e-3"), (1.23456e-5, "12.35e-6"), (float("nan"), "nan")])
def test_eng(value, text):
    assert ps.eng(value) == text
    if np.isfinite(value):    # the text reads back as the value to 4 digits
        assert float(text) == pytest.approx(value, rel=5e-4)


# --------------------------------------------------------------------------- round-off

def _equilibrium(n=2001, ripple_d2=0.0):
    """A run at equilibrium whose D2 and T_m carry round-off (spans of 1e-10 and 5e-8 of their
    values, what physical_lx1e-4 shows), plus a D2 ripple of relative size `ripple_d2`."""
    rng = np.random.default_rng(3)
    t = np.linspace(0.0, 0.1, n)
    w = 2 * np.pi * 100.0
    D2 = -1.9365e-4 * (1 + rng.uniform(-5e-11, 5e-11, n) + ripple_d2 * np.sin(2 * w * t))
    vD2 = -1.9365e-4 * (ripple_d2 * 2 * w * np.cos(2 * w * t)) + 1e-10 * rng.standard_normal(n)
    Tm = -30.7 * (1 + rng.uniform(-2.5e-8, 2.5e-8, n))
    F = np.full((n, 16), -138.0) + 20 * np.cos(w * t[:, None] - np.arange(16))
    return t, D2, vD2, Tm, F


def test_scene_does_not_zoom_into_round_off():
    t, D2, vD2, Tm, F = _equilibrium()
    fig = pl.scene(t, D2, vD2, Tm, F, speed_rpm=6000, z=16)
    ax_d, ax_t, ax_p = fig.axes[:3]
    for ax, x, k in ((ax_d, D2, 1e-6), (ax_t, Tm, 1.0)):
        lo, hi = (v * k for v in ax.get_ylim())
        # the range is +-1 % of the value, not the round-off span (1e6 times smaller or more)
        assert hi - lo == pytest.approx(0.02 * abs(x.mean()), rel=1e-6)
        assert hi - lo > 1e4 * np.ptp(x)
        assert lo < x.mean() < hi
        assert "no dynamic content" in _texts(ax)
        assert ax.yaxis.get_offset_text().get_text() == ""     # no offset text
    assert "no dynamic content" in _texts(ax_p)
    assert (np.diff(ax_p.get_ylim()) > 1e3 * np.ptp(vD2) / 1e-3).all()   # mm/s axis


def test_scene_draws_a_small_real_ripple():
    # D2's stiffness ripple in physical_ripple with the paper's shafts: 1.7e-6 of D2; T_m 2e-3
    t, D2, vD2, Tm, F = _equilibrium(ripple_d2=1.7e-6)
    Tm = Tm * (1 + 2e-3 * np.sin(2 * np.pi * 1600 * t))
    fig = pl.scene(t, D2, vD2, Tm, F, speed_rpm=6000, z=16)
    for ax, x, k in ((fig.axes[0], D2, 1e-6), (fig.axes[1], Tm, 1.0)):
        lo, hi = (v * k for v in ax.get_ylim())
        assert hi - lo < 1.5 * np.ptp(x)            # zoomed to the data (margins only)
        assert "no dynamic content" not in _texts(ax)


def test_roundoff_rule():
    x = 5.0 + np.array([0.0, 1.0])
    assert ps.roundoff_span(x * 1e-7 + 5.0) is not None          # 1e-7 of the value
    assert ps.roundoff_span(x * 1e-5 + 5.0) is None               # 1e-5 of the value
    assert ps.roundoff_span(x * 1e-5 + 5.0, rtol=1e-5) is not None   # a loose rtol: 10 rtol
    assert ps.roundoff_span([0.0, 1e-12], scale=1.0) is not None  # near zero: the scale counts
    assert ps.roundoff_span([0.0, 1e-12]) is None


# --------------------------------------------------------------------------- colour limits

def test_colour_limits_leave_out_the_start_transient():
    t, D2, vD2, Tm, F = _equilibrium()
    F[:50] = -2000.0 * np.exp(-t[:50] / 1e-3)[:, None]        # the start from rest
    F[0] = -5000.0                                          # the t = 0 spike
    fig = pl.scene(t, D2, vD2, Tm, F, speed_rpm=6000, z=16)
    im = fig.axes[3].images[0]
    lo, hi = im.get_clim()
    late = F[t >= 0.05]
    assert (lo, hi) == (late.min(), late.max())
    assert lo > -200                                        # not the spike's -5000
    cbar_label = fig.axes[-1].get_ylabel() + " ".join(a.get_ylabel() for a in fig.axes)
    assert "start transient clipped" in cbar_label


def _from_rest(n=4001):
    """A run from rest: D2 falls from 0 to -100 um in 20 ms with an overshoot, T_m spikes to
    about -420 N m at the engagement, then both ring down (150 Hz, decay 5 1/s) to -100.2 um and
    -50 N m: physical_z24's shape."""
    t = np.linspace(0.0, 1.0, n)
    ring = np.exp(-5 * t) * np.sin(2 * np.pi * 150 * t)
    engage = np.clip(t / 0.02, 0, 1)
    D2 = -100.2e-6 * engage + 0.07e-6 * ring - 5e-6 * np.exp(-((t - 0.012) / 0.003) ** 2)
    vD2 = np.gradient(D2, t)
    Tm = -50.0 * engage + 15.0 * ring - 378.0 * np.exp(-((t - 0.012) / 0.002) ** 2)
    F = np.repeat(Tm[:, None] / (24 * 0.0127), 24, axis=1)
    return t, D2, vD2, Tm, F


def test_line_panels_leave_out_the_start_transient():
    """D_2(t), T_m(t) and the phase plane are drawn on the range after the first tenth of the
    run (plots.LINE_START), with 5 % margins, when the start reaches beyond it; the note says
    so and where the transient reaches."""
    t, D2, vD2, Tm, F = _from_rest()
    fig = pl.scene(t, D2, vD2, Tm, F, speed_rpm=3000, z=24)
    ax_d, ax_t, ax_p = fig.axes[:3]
    late = t >= 0.1
    for ax, x, k, axis in ((ax_d, D2, 1e-6, "y"), (ax_t, Tm, 1.0, "y"), (ax_p, D2, 1e-6, "x"),
                           (ax_p, vD2, 1e-6, "y")):
        lo, hi = (v * k for v in (ax.get_ylim() if axis == "y" else ax.get_xlim()))
        span = np.ptp(x[late])
        assert lo == pytest.approx(x[late].min() - 0.05 * span, rel=1e-9, abs=1e-9 * span)
        assert hi == pytest.approx(x[late].max() + 0.05 * span, rel=1e-9, abs=1e-9 * span)
        assert x.min() < lo or x.max() > hi                  # the start is clipped
        assert "start transient clipped" in _texts(ax)
    assert f"({ps.eng(Tm.min(), 3)} to {ps.eng(Tm.max(), 3)} N m)" in _texts(ax_t)
    assert Tm.min() < -400 and ax_t.get_ylim()[0] > -70      # not the spike
    # a steady oscillation has no transient: its whole range is drawn
    steady = -50.0 + 5.0 * np.sin(2 * np.pi * 150 * t)
    fig = pl.scene(t, D2, vD2, steady, F, speed_rpm=3000, z=24)
    assert "start transient" not in _texts(fig.axes[1])
    lo, hi = fig.axes[1].get_ylim()
    assert lo <= steady.min() and hi >= steady.max() and hi - lo < 1.2 * np.ptp(steady)


def test_colour_limits_without_transient_are_the_whole_range():
    t, *_ , F = _equilibrium()
    lo, hi, words = ps.settled_limits(t, F)
    assert (lo, hi, words) == (F.min(), F.max(), "")


# --------------------------------------------------------------------------- Nyquist

def _nyquist_spectra(rpm, f_nyq=2000.0, bins=400):
    """Spectra on a common Hz axis up to 4000 Hz, NaN above the Nyquist frequency f_nyq."""
    f = np.linspace(0, 4000.0, bins)
    a = np.exp(-((f[None, :] - 16 * np.asarray(rpm)[:, None] / 60) / 30) ** 2) + 1e-3
    a[:, f > f_nyq] = np.nan
    return dict(speed_rpm=np.asarray(rpm, float), freq_hz=f, amplitude=a)


def test_waterfall_stops_at_nyquist_and_warns_about_tooth_pass():
    ds = _nyquist_spectra([3000, 6000, 9000, 12000])
    with pytest.warns(SplineWarning) as rec:
        fig = pl.waterfall(ds, z=16, duration=0.3)
    ax = fig.axes[0]
    f_last = ds["freq_hz"][ds["freq_hz"] <= 2000].max()
    assert ax.get_xlim()[1] <= 2000.0 and ax.get_xlim()[1] == pytest.approx(f_last)
    msg = str(rec[0].message)
    # 16 x 12000/60 = 3200 Hz; n_out over 0.3 s with (n - 1) / 0.6 > 3200 Hz: 1922
    for number in ("3200 Hz", f"{ps.eng(f_last)} Hz", "12000 rpm", "n_out >= 1922", "9000 rpm"):
        assert number in msg
    assert "3200 Hz" in _texts(ax)
    assert ps.samples_needed(3200.0, 0.3) == 1922
    assert (1922 - 1) / (2 * 0.3) > 3200.0 >= (1921 - 1) / (2 * 0.3)


@pytest.mark.parametrize("f_nyq", [4880.0, 4905.0, 4950.0, 8000.0])
def test_waterfall_labels_stay_clear_of_the_colour_bar(f_nyq):
    """A narrow speed sweep (5900-6100 r/min, Z = 24) whose data end just before, at, or past
    where the 48x line leaves the top of the plot (4900 Hz), or far beyond: after a draw at the
    default size, every order label lies within the axes' width and none overlaps the colour
    bar (its ticks and label included)."""
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    rpm = np.linspace(5900, 6100, 5)
    f = np.linspace(0, 8000.0, 801)
    a = np.exp(-((f[None, :] - 24 * rpm[:, None] / 60) / 30) ** 2) + 1e-3
    a[:, f > f_nyq] = np.nan
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", SplineWarning)      # 48x past the data: said
        fig = pl.waterfall(dict(speed_rpm=rpm, freq_hz=f, amplitude=a), z=24)
    FigureCanvasAgg(fig).draw()
    renderer = fig.canvas.get_renderer()
    ax, bar = fig.axes
    edge, bar_box = ax.get_window_extent(renderer).x1, bar.get_tightbbox(renderer)
    labels = [t for t in ax.texts if t.get_text().strip().endswith("x")]
    assert {t.get_text().strip() for t in labels} == {"1x", "2x", "24x", "48x"}
    for t in labels:
        box = t.get_window_extent(renderer)
        assert box.x1 <= edge + 0.5 and not box.overlaps(bar_box), (t.get_text(), box, edge)


def test_waterfall_of_round_off_says_so():
    """Amplitudes of 1e-7 of a signal's size are round-off (the run plots' rule): the map says
    so; at 1e-5 of it they are content and it does not."""
    ds = _nyquist_spectra([3000, 6000], f_nyq=4000.0)
    top = float(np.nanmax(ds["amplitude"]))
    flat = pl.waterfall(ds, z=16, scale=top / 1e-7, rtol=1e-8)
    assert "these amplitudes are round-off" in _texts(flat.axes[0])
    real = pl.waterfall(ds, z=16, scale=top / 1e-5, rtol=1e-8)
    assert "round-off" not in _texts(real.axes[0])
    assert ps.roundoff_amplitude(1.0, 1e7, rtol=1e-8) and not ps.roundoff_amplitude(1.0, 1e6)


def test_waterfall_within_nyquist_does_not_warn():
    ds = _nyquist_spectra([3000, 6000], f_nyq=4000.0)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        fig = pl.waterfall(ds, z=16)
    assert fig.axes[0].get_xlim()[1] <= 4000.0
    assert "Nyquist" not in _texts(fig.axes[0])


def test_scene_spectrum_names_a_tooth_pass_beyond_nyquist():
    t = np.linspace(0, 0.3, 1201)                          # Nyquist 2000 Hz
    t_, D2, vD2, Tm, F = _equilibrium(n=len(t), ripple_d2=1e-3)
    Tm = Tm * (1 + 1e-2 * np.sin(2 * np.pi * 50 * t))
    f = np.fft.rfftfreq(len(t), t[1] - t[0])
    spec = (f, np.abs(np.fft.rfft(Tm - Tm.mean())) / len(t))
    with pytest.warns(SplineWarning, match="n_out >= 1922"):
        fig = pl.scene(t, D2, vD2, Tm, F, spectrum=spec, speed_rpm=12000, z=16)
    ax_s = fig.axes[5]
    assert ax_s.get_xlim()[1] <= f.max()
    assert "above the Nyquist" in _texts(ax_s)


# --------------------------------------------------------------------------- exit codes

@pytest.fixture()
def bad_case(tmp_path):
    path = tmp_path / "bad.nml"
    path.write_text((CORPUS / "syntax_misspelt_lx.nml").read_text())
    return path


def test_exit_code_mapping():
    from pyspline import CaseError, SolverError, ThermalInterferenceError
    from pyspline.cli import exit_code
    assert [exit_code(e) for e in (CaseError("x"), SolverError("x"),
                                   ThermalInterferenceError("x"), KeyboardInterrupt(),
                                   OSError("x"))] == [2, 3, 4, 130, 1]


@pytest.mark.parametrize("name, code", [("syntax_misspelt_lx", 2),
                                        ("runaway_starved_max_steps", 3),
                                        ("thermal_bulk_closes_backlash", 4)])
@pytest.mark.parametrize("command", ["run", "plot"])
def test_run_and_plot_exit_codes(command, name, code, tmp_path, capsys):
    from pyspline.cli import main
    args = [command, str(CORPUS / f"{name}.nml")]
    assert main(args + (["--out", str(tmp_path)] if command == "plot" else [])) == code
    assert "error" in capsys.readouterr().err


def test_sweep_exit_code_on_a_bad_case(bad_case, tmp_path, capsys):
    from pyspline.cli import main
    assert main(["sweep", str(bad_case), "--set", "l_x=0,1e-4", "--out",
                 str(tmp_path / "o"), "--quiet"]) == 2
    assert "error" in capsys.readouterr().err


@pytest.mark.parametrize("command", [["reproduce", "--quick"], ["calibrate", "--quick"],
                                     ["check-exe"]])
def test_paper_commands_exit_2_on_a_bad_case(command, bad_case, tmp_path, capsys):
    from pyspline.cli import main
    cases = tmp_path / "cases"
    cases.mkdir()
    from pyspline.paper import ALL_CASES
    for name in ALL_CASES:
        (cases / f"{name}.nml").write_text(bad_case.read_text())
    extra = ["--out", str(tmp_path / "o")] if command[0] == "reproduce" else []
    assert main(command + ["--cases", str(cases)] + extra) == 2
    assert "error: CaseError" in capsys.readouterr().err


def test_interrupt_exits_130(monkeypatch, tmp_path):
    import pyspline.core
    from pyspline.cli import main

    def interrupted(*a, **k):
        raise KeyboardInterrupt
    monkeypatch.setattr(pyspline.core, "simulate", interrupted)
    case = CORPUS / "ok_minimal.nml"
    assert main(["run", str(case)]) == 130
    assert main(["plot", str(case), "--out", str(tmp_path)]) == 130
