"""Analysis of simulated spline-coupling motion: periodicity of Poincare sections, amplitude
spectra, shaft orders, largest Lyapunov exponents and summary statistics.

Every function takes plain arrays in SI units (time [s], displacement [m], velocity [m/s],
torque [N m], force [N], frequency [Hz], speed [rpm]) and imports only numpy, so this module
can be used and tested without the compiled core.
"""
from __future__ import annotations

from typing import NamedTuple

import numpy as np

__all__ = ["LyapunovFit", "amplitude_spectrum", "classify_period", "is_chaotic",
           "largest_lyapunov_fit", "orders", "period_tolerance", "predictability_horizon", "stats",
           "tooth_pass_hz"]

#: The periodicity tolerance is this many times the solver's relative tolerance ...
PERIOD_RTOL_FACTOR = 100.0
#: ... but never below this (accumulated double-precision round-off).
PERIOD_TOL_FLOOR = 1e-9


# --------------------------------------------------------------------------- periodicity

def period_tolerance(rtol: float) -> float:
    """Relative tolerance for "two section points coincide", from the solver's `rtol`:
    ``max(100 * rtol, 1e-9)``.

    CVODE keeps the *local* error per step below ``rtol * |y|`` (plus atol); the *global* error
    after many steps, and the error of a section located by root finding, is typically 10-100
    times larger. Differences below 100 rtol are therefore not distinguishable from solver error;
    the floor 1e-9 stands for round-off, which no tolerance can beat."""
    rtol = float(rtol)
    if not np.isfinite(rtol) or rtol < 0:
        raise ValueError(f"rtol must be a finite non-negative number, got {rtol!r}")
    return max(PERIOD_RTOL_FACTOR * rtol, PERIOD_TOL_FLOOR)


def _section_array(points) -> np.ndarray:
    """(n_points, n_coords) float array; a 1-D input is one coordinate. Trailing all-NaN rows
    (the padding of a ragged sweep) are dropped; NaN anywhere else is an error."""
    p = np.asarray(points, dtype=float)
    if p.ndim == 1:
        p = p[:, None]
    if p.ndim != 2:
        raise ValueError(f"points must be 1-D or (n_points, n_coords), got shape {p.shape}")
    bad = ~np.isfinite(p).all(axis=1)
    if bad.any():
        last_good = np.flatnonzero(~bad)
        n = last_good[-1] + 1 if last_good.size else 0
        if bad[:n].any() or not np.isnan(p[n:]).all():
            raise ValueError("points contain NaN or inf before the end of the sequence; only "
                             "trailing all-NaN rows (padding) are allowed")
        p = p[:n]
    return p


def classify_period(points, rtol: float, max_period: int = 32, scale=None, *,
                    tail: float = 0.5) -> tuple[int, dict]:
    """Period of a sequence of Poincare-section points, ordered in time.

    Period n means ``points[k + n] == points[k]`` for every k in the tail of the sequence,
    within the tolerance ``tol = max(100 * rtol, 1e-9)`` (see `period_tolerance`) relative to
    `scale`. The answer is the smallest such n <= `max_period`, or 0 for "not periodic"
    (quasi-periodic, chaotic, not yet settled, or a period longer than `max_period`).

    Parameters
    ----------
    points : array (n_points, n_coords) or (n_points,)
        Section points in time order, e.g. columns (D2 [m], dD2/dt [m/s]). Trailing all-NaN
        rows (padding) are ignored.
    rtol : float
        Relative tolerance the solver ran with.
    max_period : int
        Largest period tested. Only periods n with at least n pairs in the tail (``n <=
        n_used // 2``) can be tested: give the solver at least ``4 * max_period`` sections for
        the default ``tail=0.5``.
    scale : float or array (n_coords,), optional, in the units of each coordinate
        What the tolerance is relative to. Default: the RMS *magnitude* of each coordinate over
        the points used, ``sqrt(mean(x_j**2))`` (not the standard deviation, not the extent).
        This is the quantity CVODE's relative tolerance multiplies (``rtol * |y|``), so a fixed
        point at D2 = 20 um with solver noise of 1e-10 m counts as period 1, and a coordinate
        that is identically zero (zero extent and zero magnitude) always matches. A coordinate
        that is zero *up to noise* (e.g. dD2/dt sampled where it vanishes) has no magnitude to
        measure the noise against: pass `scale` in that case, e.g. the extent or RMS of the whole
        trajectory (D2, dD2/dt), not just of the section points.
    tail : float in (0, 1]
        Fraction of the sequence used, from the end (default: the last half), so that the
        transient before the attractor does not count.

    Returns
    -------
    period : int
        Smallest fitting n in 1..max_period, or 0 if none fits.
    info : dict
        ``residual`` {n: largest |points[k+n] - points[k]| / scale over all pairs in the tail
        and all coordinates} for every n tested (dimensionless); ``tol`` the tolerance used;
        ``n_points`` the number of points used; ``n_max_tested`` the largest n tested;
        ``scale`` the per-coordinate scale [coordinate units].

    The residual is a maximum, not a mean: every pair must fit, so a chaotic sequence that comes
    close to itself now and then is not mistaken for a periodic one.
    """
    p = _section_array(points)
    tol = period_tolerance(rtol)
    if not 0 < tail <= 1:
        raise ValueError(f"tail must be in (0, 1], got {tail!r}")
    if int(max_period) < 1:
        raise ValueError(f"max_period must be >= 1, got {max_period!r}")
    n_used = int(np.ceil(tail * len(p)))
    if n_used < 2:
        raise ValueError(f"need at least 2 section points in the tail, got {n_used} "
                         f"(of {len(p)} points, tail = {tail:g})")
    q = p[-n_used:]
    if scale is None:
        s = np.sqrt(np.mean(q**2, axis=0))
        s = np.where(s > 0, s, 1.0)            # identically zero: differences are zero as well
    else:
        s = np.broadcast_to(np.asarray(scale, dtype=float), (q.shape[1],)).copy()
        if not (np.isfinite(s).all() and (s > 0).all()):
            raise ValueError(f"scale must be finite and positive, got {scale!r}")
    z = q / s
    n_max = min(int(max_period), n_used // 2)      # each phase compared at least once
    # all n at once: d[n - 1, k] = max over coordinates of |z[k + n] - z[k]| (k + n past the
    # end: masked); the coordinates come first, so that their max is one of 2-D rows
    ns = np.arange(1, n_max + 1)
    later = np.arange(len(z))[None, :] + ns[:, None]
    zt = z.T
    d = np.abs(zt[:, np.minimum(later, len(z) - 1)] - zt[:, None, :]).max(axis=0)
    worst = np.where(later < len(z), d, 0.0).max(axis=1)
    residual = {int(n): float(r) for n, r in zip(ns, worst)}
    fits = np.flatnonzero(worst <= tol)
    period = int(fits[0]) + 1 if fits.size else 0
    info = dict(residual=residual, tol=tol, n_points=n_used, n_max_tested=n_max, scale=s)
    return period, info


# --------------------------------------------------------------------------- spectra

_COSINE_WINDOWS = {                      # periodic (DFT-even) cosine-sum windows
    "rect": (1.0,), "boxcar": (1.0,), "none": (1.0,),
    "hann": (0.5, 0.5),
    "hamming": (0.54, 0.46),
    "blackman": (0.42, 0.5, 0.08),
    # flat top (as scipy.signal.windows.flattop): scalloping loss < 0.01 dB, for amplitudes of
    # tones that fall between bins
    "flattop": (0.21557895, 0.41663158, 0.277263158, 0.083578947, 0.006947368),
}


def _window(window, n: int) -> np.ndarray:
    if window is None:
        return np.ones(n)
    if isinstance(window, str):
        key = window.lower()
        if key not in _COSINE_WINDOWS:
            raise ValueError(f"unknown window {window!r}; use one of {sorted(_COSINE_WINDOWS)} "
                             "or an array of weights")
        k = np.arange(n)
        return sum((-1) ** i * a * np.cos(2 * np.pi * i * k / n)
                   for i, a in enumerate(_COSINE_WINDOWS[key]))
    w = np.asarray(window, dtype=float)
    if w.shape != (n,):
        raise ValueError(f"window array has shape {w.shape}, signal has {n} samples")
    return w


def check_uniform(t, rel: float = 1e-6) -> float:
    """Sampling interval [s] of the strictly increasing, uniformly spaced times `t` [s];
    ValueError naming the problem otherwise. Steps may differ by `rel` times the mean step."""
    t = np.asarray(t, dtype=float)
    if t.ndim != 1 or len(t) < 2:
        raise ValueError(f"t must be 1-D with at least 2 samples, got shape {t.shape}")
    if not np.isfinite(t).all():
        raise ValueError("t contains NaN or inf")
    dt = np.diff(t)
    if (dt <= 0).any():
        k = int(np.flatnonzero(dt <= 0)[0])
        raise ValueError(f"t is not strictly increasing: t[{k + 1}] = {t[k + 1]!r} s <= "
                         f"t[{k}] = {t[k]!r} s")
    h = (t[-1] - t[0]) / (len(t) - 1)
    dev = np.abs(dt - h).max()
    if dev > rel * h:
        raise ValueError(f"t is not uniformly sampled: steps range from {dt.min():.6g} s to "
                         f"{dt.max():.6g} s (mean {h:.6g} s); resample onto a uniform grid "
                         "first, e.g. with np.interp")
    return float(h)


def amplitude_spectrum(t, x, detrend=True, window="hann"):
    """Single-sided amplitude spectrum of a uniformly sampled signal.

    A sinusoid ``A sin(2 pi f t)`` shows a peak of height A [units of x] at f [Hz]: the spectrum
    is divided by the window's coherent gain ``sum(w)`` (not ``N``) and doubled for 0 < f <
    Nyquist. The height is exact for a tone centred on a bin; between bins the Hann window reads
    up to 15 % low (scalloping loss) — use ``window='flattop'`` when amplitudes of arbitrary
    tones matter (< 0.1 % loss, wider peaks).

    Parameters
    ----------
    t : array (N,) [s]
        Strictly increasing, uniform sample times (steps equal to 1e-6 of the step); otherwise
        ValueError.
    x : array (N,)
        The signal, any unit (e.g. T_m [N m]).
    detrend : bool or {'constant', 'linear'}
        Remove the mean (True or 'constant', default) or a least-squares line ('linear') first,
        so that the static load does not leak into low frequencies; False keeps the DC term.
    window : str or array (N,) or None
        'hann' (default), 'flattop', 'hamming', 'blackman', 'rect' (= None), or weights.

    Returns
    -------
    freq_hz : array (N//2 + 1,) [Hz], from 0 to the Nyquist frequency.
    amplitude : array (N//2 + 1,) [units of x], peak amplitude.
    """
    t = np.asarray(t, dtype=float)
    x = np.asarray(x, dtype=float)
    if x.shape != t.shape:
        raise ValueError(f"t and x must have the same shape, got {t.shape} and {x.shape}")
    h = check_uniform(t)
    if not np.isfinite(x).all():
        raise ValueError("x contains NaN or inf")
    n = len(x)
    if detrend is True or detrend == "constant":
        x = x - x.mean()
    elif detrend == "linear":
        x = x - np.polyval(np.polyfit(t - t[0], x, 1), t - t[0])
    elif detrend not in (False, None):
        raise ValueError(f"detrend must be True, False, 'constant' or 'linear', got {detrend!r}")
    w = _window(window, n)
    amp = np.abs(np.fft.rfft(x * w)) / w.sum()
    amp[1:(n + 1) // 2] *= 2.0          # one-sided; DC and (even n) Nyquist appear once
    return np.fft.rfftfreq(n, h), amp


def orders(freq_hz, speed_rpm):
    """Frequency [Hz] expressed in shaft orders (multiples of the rotation frequency
    ``|speed_rpm| / 60`` Hz). Broadcasts like numpy."""
    f_shaft = np.abs(np.asarray(speed_rpm, dtype=float)) / 60.0
    if np.any(f_shaft == 0):
        raise ValueError("speed_rpm must be non-zero to express frequencies in orders")
    return np.asarray(freq_hz, dtype=float) / f_shaft


def tooth_pass_hz(speed_rpm, z):
    """Tooth-pass (meshing) frequency [Hz] of a spline with `z` teeth at `speed_rpm` [rpm]:
    ``z * |speed_rpm| / 60``. It is shaft order z."""
    return np.abs(np.asarray(speed_rpm, dtype=float)) * z / 60.0


# --------------------------------------------------------------------------- Lyapunov

class LyapunovFit(NamedTuple):
    """Result of `largest_lyapunov_fit` (all exponents in 1/s when times are in s)."""
    lambda_t: np.ndarray   #: running estimate cumulative / elapsed time, per renormalisation [1/s]
    lam: float             #: final running estimate lambda_t[-1] [1/s]
    spread: float          #: max - min of lambda_t over the last third of the elapsed time [1/s]
    rel_spread: float      #: spread / |lam| (inf if lam == 0); small means converged
    slope: float           #: least-squares slope of log_growth over the last two thirds [1/s]


def largest_lyapunov_fit(times, log_growth, t0: float | None = None) -> LyapunovFit:
    """Largest Lyapunov exponent from a Benettin (two-trajectory) computation.

    Parameters
    ----------
    times : array (n,) [s]
        Times of the renormalisations, strictly increasing.
    log_growth : array (n,) [-]
        Cumulative sum of ``ln(d_k / d_0)``, the log stretch factors of the separation up to
        each renormalisation.
    t0 : float [s], optional
        Time at which the perturbation was introduced. Default: if ``log_growth[0] == 0`` the
        first entry is taken as the start (``t0 = times[0]``, entry dropped); otherwise the
        first entry is taken as the first renormalisation, one interval after the start
        (``t0 = times[0] - (times[1] - times[0])``). Absolute times (e.g. starting after a
        settling time) are therefore fine.

    Returns
    -------
    LyapunovFit(lambda_t, lam, spread, rel_spread, slope)
        ``lambda_t = log_growth / (times - t0)`` is the classic running estimate and ``lam`` its
        final value. Its convergence: ``spread`` = max - min of lambda_t over the last third of
        the elapsed time, ``rel_spread = spread / |lam|`` (a few per cent or less: converged; for
        lam near 0, read the absolute spread). ``slope``, fitted over the last two thirds, is
        insensitive to the growth during the initial alignment onto the unstable direction (an
        offset in log_growth that the running estimate only forgets as 1/t).
    """
    t = np.asarray(times, dtype=float)
    s = np.asarray(log_growth, dtype=float)
    if t.ndim != 1 or t.shape != s.shape:
        raise ValueError(f"times and log_growth must be 1-D of equal length, got {t.shape} "
                         f"and {s.shape}")
    if len(t) < 3:
        raise ValueError(f"need at least 3 renormalisations, got {len(t)}")
    if not (np.isfinite(t).all() and np.isfinite(s).all()):
        raise ValueError("times or log_growth contain NaN or inf")
    if (np.diff(t) <= 0).any():
        raise ValueError("times must be strictly increasing")
    if t0 is None:
        if s[0] == 0:
            t0, t, s = t[0], t[1:], s[1:]
        else:
            t0 = t[0] - (t[1] - t[0])
    elapsed = t - t0
    if (elapsed <= 0).any():
        raise ValueError(f"times must be later than t0 = {t0!r} s")
    lam_t = s / elapsed
    lam = float(lam_t[-1])
    span = elapsed[-1]
    last_third = elapsed >= elapsed[-1] - span / 3
    spread = float(np.ptp(lam_t[last_third]))
    rel = spread / abs(lam) if lam != 0 else np.inf
    fit = elapsed >= elapsed[-1] - 2 * span / 3
    if fit.sum() >= 2:
        slope = float(np.polyfit(elapsed[fit], s[fit], 1)[0])
    else:
        slope = lam
    return LyapunovFit(lam_t, lam, spread, float(rel), slope)


def is_chaotic(lam, spread, slope):
    """Chaos by a Benettin record's fit (`largest_lyapunov_fit`): the running estimate `lam` and
    the `slope` of the log separation over the last two thirds of the window [1/s] both positive
    beyond the `spread` of the running estimate over the last third (NaN spread counts as 0):
    ``min(lam, slope) > max(spread, 0)``. The slope keeps a chaotic transient that died out
    within the window (the separation grows, then stays flat) from counting: the running
    estimate s/t still carries its growth, the slope does not. NaN lam or slope is not chaotic.
    Works on scalars (returns bool) and arrays."""
    a = np.minimum(np.asarray(lam, dtype=float), np.asarray(slope, dtype=float))
    s = np.nan_to_num(np.asarray(spread, dtype=float), nan=0.0)
    out = np.isfinite(a) & (a > np.maximum(s, 0.0))
    return bool(out) if out.ndim == 0 else out


def predictability_horizon(lam):
    """Predictability horizon ``1 / lam`` [s] for a largest Lyapunov exponent `lam` [1/s]: the
    time in which an error grows by the factor e. Infinite for lam <= 0 (no exponential error
    growth). Works on scalars (returns float) and arrays; NaN stays NaN."""
    a = np.asarray(lam, dtype=float)
    with np.errstate(divide="ignore"):
        out = np.where(a > 0, 1.0 / np.where(a > 0, a, 1.0), np.inf)
    out = np.where(np.isnan(a), np.nan, out)
    return float(out) if out.ndim == 0 else out


# --------------------------------------------------------------------------- statistics

def stats(x, quantiles: bool = True) -> dict:
    """Summary of a signal, NaN ignored, in the units of `x`: ``max``, ``min``, ``mean``,
    ``rms`` (root mean square about zero, ``sqrt(mean(x**2))``), and the quantiles ``q05``,
    ``q50`` (median) and ``q95`` (unless quantiles=False: they cost a sort)."""
    a = np.asarray(x, dtype=float)
    nan = np.isnan(a)
    a = a[~nan] if nan.any() else a.ravel()
    if a.size == 0:
        raise ValueError("stats of an empty (or all-NaN) array")
    out = dict(max=float(a.max()), min=float(a.min()), mean=float(a.mean()),
               rms=float(np.sqrt(np.mean(a**2))))
    if quantiles:
        q05, q50, q95 = np.quantile(a, [0.05, 0.5, 0.95])
        out.update(q05=float(q05), q50=float(q50), q95=float(q95))
    return out
