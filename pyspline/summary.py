"""The summary of one sweep point: a run reduced to a few numbers and short arrays (Poincare
section and period, Lyapunov exponent, extremes and RMS, loads, solver statistics, spectrum of
T_m in shaft orders), all NaN for a point that failed. Used by sweeps (pyspline.sweep), follow
sweeps (pyspline.follow) and merged spline-dyn summaries (pyspline.batch).
"""
from __future__ import annotations

import functools
from collections.abc import Sequence

import numpy as np

from . import analysis
from .core import STATE_NAMES

_I_D2 = STATE_NAMES.index("D2")     # column of D2 in Result.y / section_y; dD2/dt is 7 later


def _template(options: dict, stat_names: Sequence[str]) -> dict:
    """The summary of a point that produced nothing (all NaN), with every key a summary has."""
    nan = np.nan
    s = {}
    if options["section"] != "none":
        empty = np.zeros(0)
        s.update(section_t=empty, section_D2=empty, section_vD2=empty, period=nan,
                 period_residual=nan)
    if options["lyapunov"]:
        s.update(lyapunov=nan, lyapunov_spread=nan, lyapunov_rel_spread=nan,
                 lyapunov_slope=nan, predictability_horizon=nan, chaotic=nan)
    s.update({k: nan for k in SWEEP_EXTREMES})
    s.update({k: nan for k in SWEEP_LOADS})
    s.update({k: nan for k in stat_names})
    if options.get("orders") is not None:
        s["Tm_spectrum"] = np.full(len(options["orders"]), nan)
    s.update(error="", error_class="", warnings="")
    return s


#: The extremes and RMS of a run a sweep keeps per point: the core's (Result.extremes, spline-dyn's
#: summary lines run.*; spline_loads::run_extremes), so a sweep and merged summaries agree bit
#: for bit.
SWEEP_EXTREMES = ("Tm_max", "Tm_min", "Tm_rms", "kv_max", "kv_min", "kv_rms", "F_max", "F_min",
                  "F_rms", "Tf_max", "D2_max", "D2_min", "D2_rms")

#: The loads of a run a sweep keeps per point (Result.loads: the core's, docs/model.md
#: section 15; Tf_max too), units from the core's table.
SWEEP_LOADS = ("load_sharing", "free_frac_max", "back_frac_max", "teeth_free_mean", "teeth_back",
               "impacts_per_rev", "closing_speed_max", "Tm_rms_se", "load_sharing_rev",
               "load_sharing_rev_se", "sigma_root", "sigma_flank", "tau_pitch", "kv_rms_se",
               "F_rms_se", "D2_rms_se", "teeth_free_mean_se", "free_frac_max_se",
               "back_frac_max_se", "impacts_per_rev_se", "Tf_max_rev", "Tf_max_rev_se")


@functools.cache
def _stat_names() -> tuple:
    from .core import _names
    return tuple(n for n, *_ in _names("stats")) + ("wall_s",)


def _binned_spectrum(t, x, speed_rpm, orders_axis) -> np.ndarray:
    """Amplitude spectrum of x (Hann window, mean removed) on the order axis: in each bin
    (centre +- step/2) the largest amplitude of the FFT lines in it (peak heights survive a
    coarser axis); a bin with no line (finer axis than the FFT) interpolated; NaN beyond the
    Nyquist frequency and at zero speed."""
    o_axis = np.asarray(orders_axis, dtype=float)
    out = np.full(o_axis.shape, np.nan)
    if speed_rpm == 0 or len(t) < 4:
        return out
    f, a = analysis.amplitude_spectrum(t, x)
    o = analysis.orders(f, speed_rpm)
    step = np.diff(o_axis).min() if len(o_axis) > 1 else 1.0
    k = np.floor((o - o_axis[0]) / step + 0.5).astype(np.int64)
    ok = (k >= 0) & (k < len(o_axis))
    np.fmax.at(out, k[ok], a[ok])
    empty = np.isnan(out) & (o_axis <= o[-1])
    out[empty] = np.interp(o_axis[empty], o, a)
    return out


def section_summary(s: dict, case, section_t, D2s, vD2s, rms: tuple) -> None:
    """Put the Poincare section (times, D2, dD2/dt) and its period into summary `s`; rms: the
    RMS of D2 and of dD2/dt over the run's outputs."""
    s.update(section_t=np.asarray(section_t, dtype=float), section_D2=D2s, section_vD2=vD2s)
    if len(D2s) >= 4:     # classify_period needs 2 points in the tail (the last half)
        # what the solver's tolerance is relative to: the trajectory's RMS, but at least
        # the scales of Eq. 25 (its atol acts on states scaled by them), so that a fixed
        # point whose dD2/dt is zero up to solver noise counts as period 1
        info = case.model.info()
        scale = [max(rms[0], info["l_ref"]), max(rms[1], info["l_ref"] * info["w_ref"])]
        period, info = analysis.classify_period(np.c_[D2s, vD2s], case["rtol"], scale=scale)
        s["period"] = float(period)
        r = info["residual"]
        s["period_residual"] = r[period] if period else (min(r.values()) if r else np.nan)


#: the period of a section sequence that is not periodic while the largest Lyapunov exponent is
#: negative: the drive contracts, its transient has not decayed (not chaos)
NOT_SETTLED = -1.0


def lyapunov_summary(s: dict, lyap_t, log_growth, exponent: float, t0: float) -> None:
    """Put the Lyapunov exponent and the fit of its Benettin record (times lyap_t, cumulative
    log growth; t0 the first output time) into summary `s`."""
    s.update(lyapunov=exponent, predictability_horizon=analysis.predictability_horizon(exponent))
    if len(lyap_t) >= 3 and np.isfinite(log_growth).all():
        fit = analysis.largest_lyapunov_fit(lyap_t, log_growth, t0=t0)
        chaotic = analysis.is_chaotic(exponent, fit.spread, fit.slope)
        s.update(lyapunov_spread=fit.spread, lyapunov_rel_spread=fit.rel_spread,
                 lyapunov_slope=fit.slope, chaotic=float(chaotic))


def failed_summary(exc: Exception, options: dict) -> dict:
    """The summary of a point that failed: all NaN, the message in 'error' (never empty: a
    message-less exception gives its repr) and the class name in 'error_class'."""
    s = _template(options, _stat_names())
    s.update(error=str(exc) or repr(exc), error_class=type(exc).__name__)
    return s


def summarise(res, options: dict) -> dict:
    """The summary of one Result (see `sweep` for the keys), all numbers in SI units."""
    s = _template(options, _stat_names())
    case = res.case
    if options["section"] != "none" and res.section_y is not None:
        sy = np.asarray(res.section_y, dtype=float).reshape(-1, 14)
        section_summary(s, case, res.section_t, sy[:, _I_D2], sy[:, 7 + _I_D2],
                        (res.extremes["D2_rms"], res.extremes["vD2_rms"]))
    if options["lyapunov"] and res.lyapunov is not None:
        ly = res.lyapunov
        lyapunov_summary(s, ly["t"], ly["log_growth"], float(ly["exponent"]), float(res.t[0]))
        if s["period"] == 0 and s["lyapunov"] < 0:   # contracting onto an orbit not yet reached
            s["period"] = NOT_SETTLED
    s.update({k: res.extremes[k] for k in SWEEP_EXTREMES})
    s.update({k: float(res.loads[k]) for k in SWEEP_LOADS})
    for k in _stat_names():
        if k in res.stats:
            s[k] = float(res.stats[k])
    if options.get("orders") is not None:
        s["Tm_spectrum"] = _binned_spectrum(res.t, res.Tm, case["speed_rpm"], options["orders"])
    s["warnings"] = "\n".join(res.warnings)
    return s

