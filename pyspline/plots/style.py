"""What pyspline's figures share: units and SI prefixes from a dataset's attrs, numbers in short
engineering notation (`eng`), the test for a signal that is only round-off (`roundoff_span`)
and the axis drawn for it, colour limits that leave out a start transient
(`settled_limits`), and the note on a spectrum whose tooth pass lies beyond the Nyquist
frequency (`nyquist_note`).

Imports only numpy, matplotlib and pyspline.errors (no compiled core).
"""
from __future__ import annotations

import math
import textwrap
import warnings
from pathlib import Path

import numpy as np
from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.figure import Figure
from matplotlib.ticker import FuncFormatter

from ..errors import SplineWarning

# Colours of periods 1, 2, 3, 4 (Okabe-Ito, colour-blind safe) and > 4; not periodic is grey.
PERIOD_COLOURS = {1: "#0072B2", 2: "#D55E00", 3: "#009E73", 4: "#CC79A7", 5: "#000000",
                  6: "#E69F00"}   # 6: not settled (summary.NOT_SETTLED), not a period
NOT_PERIODIC = "0.6"
SHAFT_STYLE = dict(color="0.25", ls=(0, (4, 3)), lw=0.9)
TOOTH_STYLE = dict(color="tab:red", ls=(0, (6, 3)), lw=1.1)
NOTE_BOX = dict(fc="w", ec="0.6", alpha=0.9, boxstyle="round,pad=0.3")

_PREFIXES = ((1e-12, "p"), (1e-9, "n"), (1e-6, "µ"), (1e-3, "m"), (1.0, ""), (1e3, "k"),
             (1e6, "M"))
_PREFIXABLE = {"m", "m/s", "N", "N m", "N*m", "Nm", "s"}

#: A signal whose span (max - min) is below max(ROUNDOFF_REL, ROUNDOFF_RTOLS x rtol) times its
#: size is solver round-off, not dynamics. The floor: the equilibrium of physical_lx1e-4 holds
#: T_m to 5e-8 of its value at rtol 1e-6, 1e-8 and 1e-10 alike (D_2 to 1e-10); the smallest real
#: content measured, the stiffness ripple of D_2 in physical_ripple with the paper's soft
#: shafts, is 1.7e-6 of D_2 (with the shipped steel shafts physical_z24's settled ripple is
#: 7e-6, physical_ripple's 9e-5). 3e-7 sits between them with a factor 5 or more either side;
#: a loose rtol raises the bar to 10 rtol (CVODE's error per step is about rtol x |value|).
ROUNDOFF_REL = 3e-7
ROUNDOFF_RTOLS = 10.0


def eng(value, digits: int = 4) -> str:
    """A number, short, for legends, titles and notes: `digits` significant digits, trailing
    zeros dropped; plain in [0.01, 100000) ('30.7', '6000', '0.5'), else with an exponent that
    is a multiple of 3 ('50e-6' for 4.9999999999999996e-05, '1.92e9', '-250e-9')."""
    v = float(value)
    if v == 0 or not math.isfinite(v):
        return "0" if v == 0 else str(v)
    v = float(f"{v:.{digits}g}")
    if 1e-2 <= abs(v) < 1e5:
        return np.format_float_positional(v, trim="-")
    exp = 3 * math.floor(math.log10(abs(v)) / 3)
    mant = float(f"{v / 10.0 ** exp:.{digits}g}")
    if abs(mant) >= 1000:                    # rounded up to the next power of 1000
        mant, exp = mant / 1000, exp + 3
    return f"{np.format_float_positional(mant, trim='-')}e{exp}"


ENG_FORMATTER = FuncFormatter(lambda v, _pos: eng(v, 4))


def finish(fig: Figure, path, dpi: float = 110) -> Figure:
    """fig written to path (None: not written) as PNG at `dpi`, drawn once: the constrained
    layout runs in that draw (Figure.savefig draws a figure with a layout engine twice, the
    first time without rendering, and runs the layout in both: about half of a page's time)."""
    if path is not None:
        path = Path(path)
        path.parent.mkdir(parents=True, exist_ok=True)
        own = fig.dpi
        fig.dpi = dpi
        try:
            FigureCanvasAgg(fig).print_png(path)
        finally:
            fig.dpi = own
    return fig


def array(ds, name, dims=None) -> np.ndarray:
    """ds[name] as a float array; for an xarray object, `dims` first in that order."""
    v = ds[name]
    if dims is not None and hasattr(v, "dims") and hasattr(v, "transpose"):
        v = v.transpose(*dims, ..., missing_dims="ignore")
    return np.asarray(v, dtype=float)


def unit_of(ds, name, default="", units=None) -> str:
    """Units of ds[name]: `units[name]` if given, else attrs['units'], else `default`."""
    if units and name in units:
        return str(units[name])
    try:
        return str(ds[name].attrs.get("units", default))
    except AttributeError:
        return default


def long_name(ds, name) -> str:
    try:
        return str(ds[name].attrs.get("long_name", name))
    except AttributeError:
        return str(name)


def label(ds, name, default_units="", units=None, factor_unit=None) -> str:
    """'long_name [units]' from a variable's attrs (or `units`), else 'name [units]';
    `factor_unit` replaces the unit (an SI-prefixed one)."""
    u = factor_unit if factor_unit is not None else unit_of(ds, name, default_units, units)
    long = long_name(ds, name)
    return f"{long} [{u}]" if u else long


def prefix(values, unit: str) -> tuple[float, str]:
    """(factor, unit) with an SI prefix so that the largest |value| / factor is in [1, 1000);
    only for the units in _PREFIXABLE (angles, rpm, degC stay as they are)."""
    a = np.abs(np.asarray(values, dtype=float))
    a = a[np.isfinite(a)]
    if unit not in _PREFIXABLE or a.size == 0 or a.max() == 0:
        return 1.0, unit
    big = a.max()
    factor, p = _PREFIXES[0]
    for f, sym in _PREFIXES:
        if big >= f:
            factor, p = f, sym
    return factor, p + unit


def order_marks(z):
    """(order, label, style) of the shaft orders 1x, 2x and tooth-pass orders Zx, 2Zx."""
    marks = [(1, "1x", SHAFT_STYLE), (2, "2x", SHAFT_STYLE)]
    if z:
        marks += [(z, f"{z}x", TOOTH_STYLE), (2 * z, f"{2 * z}x", TOOTH_STYLE)]
    return marks


# --------------------------------------------------------------------------- round-off

def scale_of(x, scale=0.0) -> float:
    """The magnitude a signal's changes are judged against: max(|mean|, `scale`) (`scale`: the
    quantity's natural size when its mean may be near zero, e.g. a velocity)."""
    x = np.asarray(x, dtype=float)
    x = x[np.isfinite(x)]
    return max(abs(float(x.mean())) if x.size else 0.0, float(scale))


def roundoff_span(x, scale=0.0, rtol=1e-8) -> float | None:
    """The span of x if it is round-off (span <= max(ROUNDOFF_REL, ROUNDOFF_RTOLS rtol) x
    `scale_of(x, scale)`: no dynamic content), else None."""
    x = np.asarray(x, dtype=float)
    x = x[np.isfinite(x)]
    if x.size == 0:
        return None
    span = float(x.max() - x.min())
    bar = max(ROUNDOFF_REL, ROUNDOFF_RTOLS * rtol) * scale_of(x, scale)
    return span if span <= bar else None


def roundoff_amplitude(amplitude, scale, rtol=1e-8) -> bool:
    """A spectrum whose largest amplitude is round-off by the rule of `roundoff_span`: a tone
    of amplitude A spans 2 A, judged against the signal's size `scale` (e.g. its RMS)."""
    bar = max(ROUNDOFF_REL, ROUNDOFF_RTOLS * rtol) * float(scale)
    return bool(scale > 0 and np.isfinite(amplitude) and 2.0 * amplitude <= bar)


def flat_limits(centre, scale) -> tuple[float, float]:
    """Limits around a constant value: +-1 % of max(|centre|, scale) (+-1 if both are 0)."""
    half = 0.01 * max(abs(centre), scale) or 1.0
    return centre - half, centre + half


def note(ax, text, loc="upper left", **kw):
    """A boxed note on a panel: in a corner of the axes (`loc`), or with loc='below' under its
    x label, left-aligned with the axes, for a panel whose data may reach every corner (the
    figure's constrained layout makes room)."""
    if loc == "below":
        return ax.annotate(text, (0.0, 0.0), xycoords=("axes fraction", ax.xaxis.label),
                           xytext=(0, -4), textcoords="offset points", ha="left", va="top",
                           fontsize=8, bbox=NOTE_BOX, zorder=5, **kw)
    x, ha = (0.01, "left") if "left" in loc else (0.99, "right")
    y, va = (0.97, "top") if "upper" in loc else (0.03, "bottom")
    return ax.text(x, y, text, transform=ax.transAxes, ha=ha, va=va, fontsize=8,
                   bbox=NOTE_BOX, zorder=5, **kw)


def wrap(text: str, inches: float, size: float = 10.0) -> str:
    """`text` broken at spaces into lines that fit `inches` at font size `size` [pt] (a
    character about 0.55 size wide): a long name in a label or title stays inside the figure."""
    return textwrap.fill(text, max(20, int(inches * 72 / (0.55 * size))))


def no_content(span, unit) -> str:
    unit = "" if unit in ("", "-") else f" {unit}"
    return f"no dynamic content (span {eng(span, 2)}{unit}: round-off)"


# --------------------------------------------------------------------------- colour limits

def settled_limits(t, q, rtol=1e-8, start=0.5) -> tuple[float, float, str]:
    """Colour limits (lo, hi) of q (time along axis 0) and the words for the colour bar. The
    whole range ('') unless the first part of the run (the fraction `start` of it: half for
    the colour maps, a tenth for line plots) reaches beyond the range of the rest by more than
    a tenth of it (a start transient): then the rest's range, saying so. A rest that is
    round-off gets limits around its value (`flat_limits`)."""
    t = np.asarray(t, dtype=float)
    q = np.asarray(q, dtype=float)
    late = q[t >= t[0] + start * (t[-1] - t[0])]
    late = late[np.isfinite(late)]
    whole = q[np.isfinite(q)]
    if late.size == 0:
        return 0.0, 1.0, ""
    t_half = eng(t[0] + start * (t[-1] - t[0]), 3)
    lo, hi = float(late.min()), float(late.max())
    if roundoff_span(late, rtol=rtol) is not None:
        lo, hi = flat_limits(float(late.mean()), 0.0)
        words = f"no dynamic content after t = {t_half} s"
    elif whole.min() >= lo - 0.1 * (hi - lo) and whole.max() <= hi + 0.1 * (hi - lo):
        return float(whole.min()), float(whole.max()), ""    # no transient worth leaving out
    else:
        words = f"colour range of t >= {t_half} s"
    if whole.min() < lo or whole.max() > hi:
        words += "; start transient clipped"
    return lo, hi, words


# --------------------------------------------------------------------------- Nyquist

def samples_needed(f_hz, duration) -> int:
    """n_out that puts f_hz below the Nyquist frequency (n_out - 1) / (2 duration)."""
    return int(math.floor(2.0 * f_hz * duration)) + 2


def nyquist_note(z, f_tp, f_nyq, rpm, duration=None, warn=True) -> str:
    """The words (and a SplineWarning) for a tooth pass f_tp = Z x shaft frequency [Hz] above
    the Nyquist frequency f_nyq [Hz] of the data at rpm; with the sampled duration [s]
    (t_end - t0 - t_transient), the n_out that resolves it."""
    text = (f"tooth pass {z}x = {eng(f_tp)} Hz at {eng(rpm)} rpm is above the Nyquist "
            f"frequency {eng(f_nyq)} Hz of the data: not in the spectrum")
    if duration:
        text += f" (n_out >= {samples_needed(f_tp, duration)} resolves it)"
    if warn:
        warnings.warn(text, SplineWarning, stacklevel=3)
    return text
