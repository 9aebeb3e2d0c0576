"""pyspline.analysis and pyspline.plots on constructed data. Both modules are loaded by file
path, so these tests need neither the compiled core nor an installed pyspline."""
import importlib
import importlib.util
import sys
import types
from pathlib import Path

import numpy as np
import pytest

ROOT = Path(__file__).resolve().parent.parent


def _load(name, rel):
    spec = importlib.util.spec_from_file_location(name, ROOT / rel)
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    return mod


def _load_src(name):
    """pyspline/<name>.py as a module of a stand-in package over the source tree, so that its
    relative imports work without pyspline/__init__.py (which needs the compiled core)."""
    if "_pyspline_src" not in sys.modules:
        pkg = types.ModuleType("_pyspline_src")
        pkg.__path__ = [str(ROOT / "pyspline")]
        sys.modules["_pyspline_src"] = pkg
    return importlib.import_module(f"_pyspline_src.{name}")


an = _load("pyspline_analysis", "pyspline/analysis.py")
pl = _load_src("plots")

PNG_MAGIC = b"\x89PNG\r\n\x1a\n"


def logistic(r, n, x0=0.3, skip=500):
    x = np.empty(n)
    v = x0
    for _ in range(skip):
        v = r * v * (1 - v)
    for k in range(n):
        v = r * v * (1 - v)
        x[k] = v
    return x


# --------------------------------------------------------------------------- classify_period

def test_period_1_with_noise_below_tolerance():
    rng = np.random.default_rng(1)
    # a fixed point (D2 = 20 um, dD2/dt = 3 mm/s) with relative noise 1e-7 << 100 rtol = 1e-4
    p = np.array([20e-6, 3e-3]) * (1 + 1e-7 * rng.uniform(-0.5, 0.5, (200, 2)))
    period, info = an.classify_period(p, rtol=1e-6)
    assert period == 1
    assert info["tol"] == pytest.approx(1e-4)
    assert info["n_points"] == 100
    assert info["residual"][1] < 1e-6


def test_exact_fixed_point_and_zero_extent():
    assert an.classify_period(np.full((50, 2), 1.5e-5), rtol=1e-8)[0] == 1
    assert an.classify_period(np.zeros((50, 2)), rtol=1e-8)[0] == 1   # zero extent and magnitude


def test_period_3_cycle():
    cycle = np.array([[1.0, 0.2], [-0.5, 0.7], [0.3, -0.9]])
    p = np.tile(cycle, (40, 1))
    period, info = an.classify_period(p, rtol=1e-8)
    assert period == 3
    assert info["residual"][1] > 0.1 and info["residual"][2] > 0.1
    assert info["residual"][3] == 0.0
    assert 6 in info["residual"]                      # multiples fit too; the smallest is returned


def test_period_2_logistic():
    period, info = an.classify_period(logistic(3.2, 400), rtol=1e-8)
    assert period == 2
    assert info["residual"][1] > 0.1


def test_period_4_logistic_after_transient():
    # r = 3.5: period 4. Start without the skip so the tail rule has to discard the transient.
    x = logistic(3.5, 600, skip=0)
    assert an.classify_period(x, rtol=1e-8)[0] == 4


def test_quasi_periodic_rotation_is_not_periodic():
    theta = 2 * np.pi * (np.sqrt(5) - 1) / 2 * np.arange(400)      # golden-mean rotation
    p = np.c_[np.cos(theta), np.sin(theta)]
    period, info = an.classify_period(p, rtol=1e-6)
    assert period == 0
    assert info["n_max_tested"] == 32
    assert min(info["residual"].values()) > 10 * info["tol"]


def test_chaotic_logistic_is_not_periodic():
    period, info = an.classify_period(logistic(3.9, 400), rtol=1e-6)
    assert period == 0
    assert min(info["residual"].values()) > 10 * info["tol"]


@pytest.mark.parametrize("rtol, expected", [(1e-6, 1), (1e-7, 0), (1e-8, 0)])
def test_period_tolerance_tied_to_rtol(rtol, expected):
    """Relative noise 1e-5 (uniform in +-1e-5, so pair differences up to 2e-5) is within
    100 rtol = 1e-4 at rtol 1e-6: period 1, the solver cannot resolve it. At rtol 1e-7
    (tol 1e-5) and 1e-8 (tol 1e-6) it is resolved, and random: not periodic."""
    rng = np.random.default_rng(7)
    p = 1.0 + 1e-5 * rng.uniform(-1, 1, 400)
    assert an.classify_period(p, rtol=rtol)[0] == expected


@pytest.mark.parametrize("rtol", [1e-6, 1e-8, 1e-12])
def test_period_tolerance_threshold(rtol):
    """A period-2 split of 0.9 tol is period 1, one of 1.1 tol is period 2, where
    tol = max(100 rtol, 1e-9) relative to the RMS magnitude."""
    tol = an.period_tolerance(rtol)
    assert tol == max(100 * rtol, 1e-9)
    k = np.arange(200) % 2
    assert an.classify_period(3e-5 * (1 + 0.9 * tol * k), rtol=rtol)[0] == 1
    assert an.classify_period(3e-5 * (1 + 1.1 * tol * k), rtol=rtol)[0] == 2


def test_small_period_2_below_tolerance_counts_as_period_1():
    # a period-2 split of 1e-6 (relative) is resolved at rtol 1e-10 but not at rtol 1e-7
    p = 1.0 + 1e-6 * (np.arange(200) % 2)
    assert an.classify_period(p, rtol=1e-7)[0] == 1
    assert an.classify_period(p, rtol=1e-10)[0] == 2
    assert an.period_tolerance(0.0) == 1e-9


def test_scale_argument_for_coordinate_zero_up_to_noise():
    rng = np.random.default_rng(3)
    # dD2/dt vanishes at the section, up to solver noise: its own magnitude is the noise ...
    p = np.c_[np.full(100, 2e-5), 1e-12 * rng.standard_normal(100)]
    assert an.classify_period(p, rtol=1e-6)[0] == 0
    # ... measured against the trajectory's velocity extent (0.1 m/s) it is a fixed point
    assert an.classify_period(p, rtol=1e-6, scale=[2e-5, 0.1])[0] == 1


def test_period_longer_than_tested_and_padding():
    cycle = np.arange(5.0) + 1
    p = np.tile(cycle, 20)
    assert an.classify_period(p, rtol=1e-8, max_period=4)[0] == 0
    padded = np.r_[p, np.full(7, np.nan)]                    # NaN padding of a ragged sweep
    period, info = an.classify_period(padded, rtol=1e-8)
    assert period == 5 and info["n_points"] == 50
    with pytest.raises(ValueError, match="NaN"):
        an.classify_period(np.r_[1.0, np.nan, p], rtol=1e-8)


def test_short_sequence_limits_tested_periods():
    period, info = an.classify_period(np.tile([1.0, 2.0, 3.0], 4), rtol=1e-8)   # 6 in the tail
    assert info["n_max_tested"] == 3 and period == 3


# --------------------------------------------------------------------------- spectra

def test_amplitude_spectrum_two_sines_on_bins():
    fs, n = 2000.0, 4000
    t = np.arange(n) / fs
    f1, f2 = 37.5, 212.0                                   # bin width 0.5 Hz: on bins
    x = 5.0 + 1.3 * np.sin(2 * np.pi * f1 * t) + 0.2 * np.cos(2 * np.pi * f2 * t + 0.4)
    f, a = an.amplitude_spectrum(t, x)
    df = f[1] - f[0]
    assert df == pytest.approx(0.5)
    assert a[0] < 1e-9                                       # mean removed
    for ft, at in ((f1, 1.3), (f2, 0.2)):
        band = np.abs(f - ft) < 5
        k = np.flatnonzero(band)[np.argmax(a[band])]
        assert abs(f[k] - ft) <= df
        assert a[k] == pytest.approx(at, rel=0.01)


def test_amplitude_spectrum_flattop_off_bin():
    fs, n = 1000.0, 3000
    t = 0.25 + np.arange(n) / fs
    f1, f2 = 41.17, 133.61                                  # between bins (width 1/3 Hz)
    x = 2.0 * np.sin(2 * np.pi * f1 * t) + 0.5 * np.sin(2 * np.pi * f2 * t + 1.0)
    f, a = an.amplitude_spectrum(t, x, window="flattop")
    df = f[1] - f[0]
    for ft, at in ((f1, 2.0), (f2, 0.5)):
        band = np.abs(f - ft) < 3
        k = np.flatnonzero(band)[np.argmax(a[band])]
        assert abs(f[k] - ft) <= df
        assert a[k] == pytest.approx(at, rel=0.01)
    # the Hann window reads low between bins (scalloping), which is why flattop exists
    _, ah = an.amplitude_spectrum(t, x, window="hann")
    assert ah[np.abs(f - f1) < 3].max() < 0.99 * 2.0


def test_amplitude_spectrum_rejects_nonuniform_t():
    t = np.arange(100) * 1e-3
    t[50] += 2e-4
    with pytest.raises(ValueError, match="not uniformly sampled"):
        an.amplitude_spectrum(t, np.sin(t))
    with pytest.raises(ValueError, match="not strictly increasing"):
        an.amplitude_spectrum(t[::-1], np.sin(t))
    with pytest.raises(ValueError, match="same shape"):
        an.amplitude_spectrum(np.arange(10.0), np.zeros(9))


def test_orders_and_tooth_pass():
    assert an.tooth_pass_hz(3000, 24) == pytest.approx(1200.0)
    assert an.orders(1200.0, 3000) == pytest.approx(24.0)
    assert np.allclose(an.orders(np.array([50.0, 100.0]), -3000), [1.0, 2.0])
    with pytest.raises(ValueError):
        an.orders(10.0, 0.0)


# --------------------------------------------------------------------------- Lyapunov, stats

def test_largest_lyapunov_fit_recovers_slope():
    lam = 2.5                                               # 1/s
    t = 1.0 + np.arange(1, 20001) * 0.01                    # renormalisations from t = 1 s on
    wobble = 0.3 * np.sin(7.0 * t)                          # bounded: local stretching varies
    fit = an.largest_lyapunov_fit(t, lam * (t - 1.0) + wobble)
    assert fit.lam == pytest.approx(lam, rel=1e-3)
    assert fit.slope == pytest.approx(lam, rel=1e-3)
    assert fit.lambda_t.shape == t.shape
    assert fit.rel_spread < 1e-2
    # an offset from the initial alignment: the running estimate only forgets it as 1/t,
    # the fitted slope does not see it
    fit2 = an.largest_lyapunov_fit(t, lam * (t - 1.0) + wobble + 5.0)
    assert fit2.slope == pytest.approx(lam, rel=1e-3)
    assert abs(fit2.lam - lam) > 1e-3 * lam
    assert fit2.rel_spread > fit.rel_spread


def test_largest_lyapunov_fit_start_entry_and_short_run():
    t = np.arange(0, 101) * 0.1                              # first entry is the start
    fit = an.largest_lyapunov_fit(t, -0.8 * t)
    assert fit.lam == pytest.approx(-0.8) and fit.slope == pytest.approx(-0.8)
    with pytest.raises(ValueError):
        an.largest_lyapunov_fit([0.1, 0.2], [0.1, 0.2])


def test_predictability_horizon():
    assert an.predictability_horizon(4.0) == 0.25
    assert an.predictability_horizon(0.0) == np.inf
    assert an.predictability_horizon(-1.0) == np.inf
    h = an.predictability_horizon(np.array([2.0, -1.0, np.nan]))
    assert h[0] == 0.5 and np.isinf(h[1]) and np.isnan(h[2])


def test_is_chaotic():
    assert an.is_chaotic(900.0, 30.0, 880.0) and not an.is_chaotic(1.4, 2.7, 1.4)
    assert not an.is_chaotic(-0.5, 0.0, -0.5) and not an.is_chaotic(np.nan, 0.0, 1.0)
    assert not an.is_chaotic(5.0, 1.0, np.nan) and not an.is_chaotic(900.0, 30.0, 20.0)
    np.testing.assert_array_equal(an.is_chaotic([5.0, 5.0, -1.0], [1.0, np.nan, 0.0], 5.0),
                                  [True, True, False])


def test_a_transient_that_dies_is_not_chaos():
    """A separation that grows at rate r until t1, then stays: log_growth = r min(t, t1). At the
    end T = 4 t1 the running estimate still reads r t1 / T = r / 4, twice its spread over the
    last third (r t1 (1 / (2T/3) - 1 / T) = r / 8): the running estimate alone calls it chaos.
    The slope over the last two thirds (after t1) is 0: not chaotic. Growth all through
    (t1 = T) is chaos, with both at r."""
    r, t1 = 200.0, 0.1
    t = np.linspace(0, 4 * t1, 401)
    fit = an.largest_lyapunov_fit(t, r * np.minimum(t, t1))
    assert fit.lam == pytest.approx(r / 4) and fit.spread == pytest.approx(r / 8, rel=0.02)
    assert fit.slope == pytest.approx(0.0, abs=1e-9)
    assert an.is_chaotic(fit.lam, fit.spread, fit.lam)         # the running estimate alone
    assert not an.is_chaotic(fit.lam, fit.spread, fit.slope)
    grows = an.largest_lyapunov_fit(t, r * t)
    assert grows.lam == pytest.approx(r) and grows.slope == pytest.approx(r)
    assert an.is_chaotic(grows.lam, grows.spread, grows.slope)


def test_stats():
    x = np.r_[np.arange(1.0, 101.0), np.nan]
    s = an.stats(x)
    assert s["max"] == 100 and s["min"] == 1 and s["q50"] == pytest.approx(50.5)
    assert s["q05"] == pytest.approx(5.95) and s["q95"] == pytest.approx(95.05)
    assert s["rms"] == pytest.approx(np.sqrt(np.mean(np.arange(1.0, 101.0) ** 2)))
    light = an.stats(x, quantiles=False)
    assert "q50" not in light and all(light[k] == s[k] for k in ("max", "min", "mean", "rms"))
    with pytest.raises(ValueError):
        an.stats([np.nan])


# --------------------------------------------------------------------------- plots

def _texts_of(ax):
    return " ".join(t.get_text() for t in ax.texts)


def _png_ok(path, fig):
    from matplotlib.figure import Figure
    assert isinstance(fig, Figure)
    data = Path(path).read_bytes()
    assert len(data) > 5000 and data[:8] == PNG_MAGIC


def _sweep(n_param=40, n_pts=64):
    """A dict sweep: logistic-map bifurcation dressed as D2 [m] against l_x [m]."""
    r = np.linspace(2.9, 3.95, n_param)
    sec = np.full((n_param, n_pts), np.nan)
    period = np.zeros(n_param)
    for i, ri in enumerate(r):
        x = logistic(ri, 2 * n_pts)
        m = n_pts if i % 5 else n_pts // 2                   # ragged: some runs shorter
        sec[i, :m] = 1e-5 * (1 + x[-m:])
        period[i] = an.classify_period(x, rtol=1e-8)[0]
    return dict(l_x=(r - 2.9) * 1e-4, section_D2=sec, period=period, r=r)


def test_plot_bifurcation_dict(tmp_path):
    ds = _sweep()
    assert {1, 2, 4, 0} <= set(ds["period"].astype(int))
    fig = pl.bifurcation(ds, "l_x", path=tmp_path / "bif.png")
    _png_ok(tmp_path / "bif.png", fig)
    assert "µm" in fig.axes[0].get_ylabel()


def test_plot_bifurcation_xarray(tmp_path):
    xr = pytest.importorskip("xarray")
    d = _sweep()
    ds = xr.Dataset(
        dict(section_D2=(("section_point", "l_x"), d["section_D2"].T,   # transposed on purpose
                         dict(units="m", long_name="D_2 on the section")),
             period=("l_x", d["period"])),
        coords=dict(l_x=("l_x", d["l_x"], dict(units="m", long_name="misalignment l_x"))))
    fig = pl.bifurcation(ds, "l_x", path=tmp_path / "bif_xr.png")
    _png_ok(tmp_path / "bif_xr.png", fig)
    assert fig.axes[0].get_xlabel() == "misalignment l_x [µm]"


def test_plot_lyapunov(tmp_path):
    p = np.linspace(0, 1, 30)
    lam = 40 * np.sin(3 * p) - 15
    ds = dict(torque=p * 100, lyapunov=lam, lyapunov_spread=np.full(30, 3.0),
              lyapunov_slope=lam)
    fig = pl.lyapunov_vs_param(ds, "torque", path=tmp_path / "lyap.png")
    _png_ok(tmp_path / "lyap.png", fig)
    assert len(fig.axes) == 2                                 # the horizon axis
    n_horizon = len(fig.axes[1].lines[0].get_xdata())
    assert n_horizon == int((lam > 3.0).sum())
    # a small positive estimate whose error bar reaches zero is not called chaos
    ds_noise = dict(torque=p[:3] * 100, lyapunov=np.array([2.0, -1.0, 1.0]),
                    lyapunov_spread=np.array([20.0, 20.0, 20.0]))
    assert len(pl.lyapunov_vs_param(ds_noise, "torque").axes) == 1


def _spectra(z=12):
    rpm = np.linspace(600, 6000, 28)
    fs, n = 4096.0, 4096
    t = np.arange(n) / fs
    amps = []
    rng = np.random.default_rng(5)
    for r in rpm:
        f1 = r / 60
        x = (1.0 * np.sin(2 * np.pi * f1 * t) + 0.3 * np.sin(2 * np.pi * 2 * f1 * t)
             + 2.0 * np.sin(2 * np.pi * z * f1 * t) + 50 / (1 + ((z * f1 - 700) / 40) ** 2)
             * np.sin(2 * np.pi * z * f1 * t + 1)             # a resonance near 700 Hz
             + 0.05 * rng.standard_normal(n))
        f, a = an.amplitude_spectrum(t, x)
        amps.append(a)
    return dict(speed_rpm=rpm, freq_hz=f, amplitude=np.array(amps))


@pytest.mark.parametrize("style", ["map", "lines"])
def test_plot_waterfall(tmp_path, style):
    ds = _spectra()
    fig = pl.waterfall(ds, z=12, style=style, path=tmp_path / f"wf_{style}.png")
    _png_ok(tmp_path / f"wf_{style}.png", fig)
    ax = fig.axes[0]
    assert "tooth pass 12x" in ax.get_title()
    assert (ax.get_xlabel(), ax.get_ylabel()) == ("frequency [Hz]", "shaft speed [rpm]")
    assert ax.get_xlim() == (0.0, ds["freq_hz"].max())          # up to Nyquist, no further
    lo, hi = ax.get_ylim()
    assert lo < ds["speed_rpm"].min() and hi > ds["speed_rpm"].max()
    assert {"1x", "2x", "12x"} <= {t.get_text().strip() for t in ax.texts}   # the order labels
    amp = ds["amplitude"][:, 1:]
    if style == "map":          # the colour scale spans the amplitudes (log)
        clim = ax.collections[0].get_clim()
        assert clim[1] == pytest.approx(amp.max(), rel=1e-6) and 0 < clim[0] < 1e-3 * amp.max()
    else:                       # one line per speed, the note gives the log scale's range
        assert len(ax.collections) == len(ds["speed_rpm"])
        assert f"to {amp.max():.3g}" in _texts_of(ax)


def test_plot_scene(tmp_path):
    z, rpm = 12, 3000.0
    t = np.arange(0, 0.2, 1 / 20000)
    w = 2 * np.pi * rpm / 60
    D2 = 2e-5 + 3e-6 * np.sin(w * t) + 5e-7 * np.sin(z * w * t)
    vD2 = 3e-6 * w * np.cos(w * t) + 5e-7 * z * w * np.cos(z * w * t)
    Tm = 100 + 8 * np.sin(z * w * t) + 3 * np.sin(w * t)
    phase = 2 * np.pi * np.arange(z) / z
    F = 400 * (1 + 0.5 * np.cos(w * t[:, None] - phase))
    Tf = 20 + 0.05 * F
    k = np.arange(0, len(t), int(round(20000 * 60 / rpm)))    # once per revolution
    spec = an.amplitude_spectrum(t, Tm)
    fig = pl.scene(t, D2, vD2, Tm, F, Tf=Tf, section=np.c_[D2[k], vD2[k]], spectrum=spec,
                   speed_rpm=rpm, z=z, path=tmp_path / "scene.png", title="synthetic run")
    _png_ok(tmp_path / "scene.png", fig)
    assert fig._suptitle.get_text() == "synthetic run"
    ax_d, ax_t, ax_p, ax_f, ax_tf, ax_s = fig.axes[:6]
    assert [a.get_title() for a in (ax_t, ax_p, ax_f, ax_tf, ax_s)] == [
        "meshing torque T_m", f"phase plane; red: section points ({len(k)})", "tooth load F_j",
        "flash temperature T_f", "spectrum of T_m"]
    assert ax_p.get_legend() is None          # the key is in the title, no box over the arcs
    assert ax_d.get_ylabel() == "D_2 [µm]" and ax_p.get_ylabel() == "dD_2/dt [mm/s]"
    for ax, x in ((ax_d, D2 * 1e6), (ax_t, Tm)):   # the whole range (no start transient), margins
        lo, hi = ax.get_ylim()
        assert lo < x.min() and hi > x.max() and hi - lo < 1.2 * np.ptp(x)
    assert ax_p.get_xlim() == ax_d.get_ylim()
    assert ax_f.images[0].get_clim() == (F.min(), F.max())
    assert ax_tf.images[0].get_clim() == (Tf.min(), Tf.max())
    peak = max(ax_s.lines, key=lambda ln: np.max(ln.get_ydata()))   # the tooth pass, z f_shaft
    assert peak.get_xdata()[np.argmax(peak.get_ydata())] == pytest.approx(z * rpm / 60, abs=10)
    assert z * rpm / 60 < ax_s.get_xlim()[1] <= 10000.0              # within Nyquist
    fig = pl.scene(t, D2, vD2, Tm, F, Tf=Tf.max(axis=1), path=tmp_path / "scene_min.png")
    _png_ok(tmp_path / "scene_min.png", fig)
    ax_tf = fig.axes[4]       # one temperature a time: the hottest tooth's, as a line
    assert ax_tf.get_title() == "flash temperature, hottest tooth" and not ax_tf.images
    lo, hi = ax_tf.get_ylim()
    assert lo < Tf.max(axis=1).min() and hi > Tf.max(axis=1).max()
