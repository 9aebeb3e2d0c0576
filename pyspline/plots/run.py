"""The figure of one run: `scene`, one page (what `pyspline plot` draws).

It takes numpy arrays, returns a matplotlib Figure and, when given `path`, writes it there as
PNG. Figures are built on `matplotlib.figure.Figure` and rendered by Agg, independent of pyplot
and of the interactive backend, so sweeps do not accumulate open figures.

No figure magnifies round-off: a signal whose span is below the solver's resolution
(style.roundoff_span: 3e-7 of its size, or 10 rtol) is drawn on a range around its value
and labelled "no dynamic content"; colour scales come from the second half of a run and line
panels from the run after its first tenth (a start transient is clipped, and the colour bar or a
note says so, with where the transient reaches); spectra end at the Nyquist frequency of the
data and say when the tooth pass lies beyond it (with a SplineWarning).

Imports only numpy, matplotlib and pyspline.errors, no compiled core.
"""
from __future__ import annotations

import numpy as np
from matplotlib.figure import Figure
from matplotlib.lines import Line2D
from matplotlib.ticker import MaxNLocator

from . import style as ps


# --------------------------------------------------------------------------- scene

def _time_signal(ax, t, x, name, unit, colour, rtol, scale=0.0):
    """x(t) on ax with an SI prefix and no offset text; a round-off signal (`ps.roundoff_span`)
    on +-1 % around its value, with a note; a signal whose start transient reaches beyond the
    second half's range (`ps.settled_limits`) on that range, saying so and where the transient
    reaches. Returns (factor, prefixed unit, span or None)."""
    span = ps.roundoff_span(x, scale, rtol)
    size = ps.scale_of(x, scale)
    late = None if span is not None else settled_range(t, x, rtol, unit)
    k, u = ps.prefix([size] if span is not None else (late[:2] if late else x), unit)
    ax.plot(t, x / k, lw=0.7, color=colour)
    ax.set_ylabel(f"{name} [{u}]" if u else name)
    ax.grid(alpha=0.3, lw=0.5)
    ax.ticklabel_format(axis="y", useOffset=False)
    if span is not None:
        ax.set_ylim(*(v / k for v in ps.flat_limits(float(np.nanmean(x)), scale)))
        ps.note(ax, ps.no_content(span, unit))
    elif late:
        ax.set_ylim(late[0] / k, late[1] / k)
        ps.note(ax, late[2], loc="below")        # the clipped transient crosses the corners
    return k, u, span


#: A line plot's range leaves out the start transient: the range after this fraction of the
#: run, when the start reaches beyond it (`ps.settled_limits`). A tenth, not the colour maps'
#: half: a line shows how the drive settles (the ring-down after the engagement's impacts).
LINE_START = 0.1


def settled_range(t, x, rtol, unit=""):
    """(lo, hi, words) of the axis of a line plot of x(t) that leaves out a start transient,
    by the colour scales' rule (`ps.settled_limits`) after the first LINE_START of the run,
    with 5 % margins; None when there is no transient to leave out. The words say which range
    is drawn and where the transient reaches (in `unit`)."""
    lo, hi, words = ps.settled_limits(t, x, rtol, start=LINE_START)
    if not words:
        return None
    pad = 0.05 * (hi - lo)
    x = np.asarray(x, dtype=float)
    unit = "" if unit in ("", "-") else f" {unit}"
    reach = f"{ps.eng(np.nanmin(x), 3)} to {ps.eng(np.nanmax(x), 3)}{unit}"
    words = words.replace("colour range", "range").replace(
        "; start transient clipped", f"; start transient clipped ({reach})")
    return lo - pad, hi + pad, words


def _tooth_map(fig, ax, t, q, label, cmap, rtol):
    q = np.asarray(q, dtype=float)
    ax.set_xlabel("time t [s]")
    if q.ndim == 1:                      # a per-time summary (e.g. max over teeth)
        _time_signal(ax, t, q, label, "", "tab:red", rtol)
        return
    zt = q.shape[1]
    lo, hi, words = ps.settled_limits(t, q, rtol)
    im = ax.imshow(q.T, aspect="auto", origin="lower", cmap=cmap, interpolation="nearest",
                   extent=(t[0], t[-1], 0.5, zt + 0.5), vmin=lo, vmax=hi)
    ax.set_ylabel("tooth j")
    ax.yaxis.set_major_locator(MaxNLocator(nbins=8, integer=True, min_n_ticks=1))
    cb = fig.colorbar(im, ax=ax, pad=0.02, extend="both" if "clipped" in words else "neither",
                      format=ps.ENG_FORMATTER)
    cb.set_label(f"{label}\n({words})" if words else label)


def _absent(ax, text):
    ax.set_axis_off()
    ax.text(0.5, 0.5, text, ha="center", va="center", fontsize=9, color="0.4",
            transform=ax.transAxes)


def scene(t, D2, vD2, Tm, F, Tf=None, section=None, spectrum=None, speed_rpm=None,
          z: int | None = None, path=None, title: str | None = None,
          rtol: float = 1e-8) -> Figure:
    """One page on one run.

    t [s] (nt,); D2 [m] and vD2 = dD2/dt [m/s] (nt,); Tm, the meshing torque [N m] (nt,);
    F, the tooth loads [N] (nt, Z); Tf, flash temperatures [degC] (nt, Z) or their maximum
    over the teeth (nt,); section, Poincare points (n, 2) as (D2 [m], dD2/dt [m/s]); spectrum,
    ``(freq_hz, amplitude)`` of Tm [Hz, N m] (e.g. from analysis.amplitude_spectrum);
    speed_rpm [rpm] and z (teeth) for the order marks (z defaults to F.shape[1]); rtol, the
    relative tolerance the run was computed with (case['rtol']), for the round-off test.

    Panels: D2(t); T_m(t); phase plane (D2, dD2/dt) with the section points; tooth x time map
    of F; the same of T_f (or its max over teeth); spectrum of T_m up to 2.5 Z shaft orders
    and at most the Nyquist frequency, with shaft orders (1x, 2x) and tooth-pass orders (Zx,
    2Zx) dashed and a shaft-order axis on top. A panel whose data is not given says so; a
    signal that is round-off says "no dynamic content" (dD2/dt with D2, on a range of omega
    |D2|, omega the shaft's angular speed); the colour maps take their range from the
    second half of the run, the lines (D_2, T_m, the phase plane) from the run after its first
    tenth when a start transient reaches beyond it (`settled_range`); a tooth pass above the Nyquist frequency is named on the spectrum
    and warned about (SplineWarning, with the n_out that resolves it)."""
    t = np.asarray(t, dtype=float)
    D2 = np.asarray(D2, dtype=float)
    vD2 = np.asarray(vD2, dtype=float)
    Tm = np.asarray(Tm, dtype=float)
    F = np.asarray(F, dtype=float)
    if F.ndim == 1:
        F = F[:, None]
    for name, arr in (("D2", D2), ("vD2", vD2), ("Tm", Tm), ("F", F)):
        if arr.shape[0] != t.shape[0]:
            raise ValueError(f"{name} has {arr.shape[0]} samples, t has {t.shape[0]}")
    if z is None:
        z = F.shape[1]
    duration = float(t[-1] - t[0]) if len(t) > 1 else 0.0
    f_shaft = None if not speed_rpm else abs(float(speed_rpm)) / 60.0
    omega = 2 * np.pi * (f_shaft or (1.0 / duration if duration > 0 else 1.0))
    v_scale = omega * ps.scale_of(D2)
    fig = Figure(figsize=(16, 11), layout="constrained")
    gs = fig.add_gridspec(3, 3, height_ratios=(1, 1, 1.2), width_ratios=(1, 1, 1.05))
    ax_d = fig.add_subplot(gs[0, :2])
    ax_t = fig.add_subplot(gs[1, :2], sharex=ax_d)
    ax_p = fig.add_subplot(gs[:2, 2])
    ax_f = fig.add_subplot(gs[2, 0])
    ax_tf = fig.add_subplot(gs[2, 1])
    ax_s = fig.add_subplot(gs[2, 2])

    kd, ud, d_flat = _time_signal(ax_d, t, D2, "D_2", "m", "tab:blue", rtol)
    ax_d.set_title("relative displacement D_2 on the line of action", fontsize=10)
    ax_d.tick_params(labelbottom=False)
    _, _, tm_flat = _time_signal(ax_t, t, Tm, "T_m", "N m", "tab:green", rtol)
    ax_t.set_xlabel("time t [s]")
    ax_t.set_title("meshing torque T_m", fontsize=10)

    _phase_plane(ax_p, D2, vD2, section, (kd, ud, d_flat), v_scale, t, rtol)
    _tooth_map(fig, ax_f, t, F, "tooth load F_j [N]", "viridis", rtol)
    ax_f.set_title("tooth load F_j", fontsize=10)
    if Tf is None:
        _absent(ax_tf, "flash temperature T_f\nnot given")
    else:
        Tf = np.asarray(Tf, dtype=float)
        two_d = Tf.ndim == 2
        _tooth_map(fig, ax_tf, t, Tf, "flash temperature T_f [°C]" if two_d
                   else "max over teeth of T_f [°C]", "inferno", rtol)
        ax_tf.set_title("flash temperature T_f" if two_d else "flash temperature, hottest tooth",
                        fontsize=10)
    if spectrum is None:
        _absent(ax_s, "spectrum of T_m not given\n(spectrum=amplitude_spectrum(t, Tm))")
    else:
        _spectrum(ax_s, spectrum, f_shaft, z, speed_rpm, duration, tm_flat)
    if title:
        fig.suptitle(title)
    return ps.finish(fig, path)


def _phase_plane(ax, D2, vD2, section, d_axis, v_scale, t=None, rtol=1e-8):
    """(D2, dD2/dt) with the section points; when D2 is round-off, both axes are drawn on
    +-1 % around their values (dD2/dt of v_scale), and the panel says so."""
    kd, ud, d_flat = d_axis
    v_flat = None if d_flat is None else float(np.ptp(vD2))   # v = dD2/dt: flat with D2
    late_d = settled_range(t, D2, rtol, "m") if t is not None and d_flat is None else None
    late_v = settled_range(t, vD2, rtol, "m/s") if t is not None and d_flat is None else None
    kv, uv = ps.prefix([v_scale] if v_flat is not None else (late_v[:2] if late_v else vD2),
                       "m/s")
    ax.plot(D2 / kd, vD2 / kv, lw=0.4, color="0.55")
    title = "phase plane"      # the key in the title: a legend inside would cover the arcs
    if section is not None:
        s = np.asarray(section, dtype=float).reshape(-1, 2)
        ax.plot(s[:, 0] / kd, s[:, 1] / kv, "o", ms=4, color="tab:red", zorder=3)
        title += f"; red: section points ({len(s)})"
    ax.set_xlabel(f"D_2 [{ud}]")
    ax.set_ylabel(f"dD_2/dt [{uv}]")
    ax.set_title(title, fontsize=10)
    ax.grid(alpha=0.3, lw=0.5)
    ax.ticklabel_format(useOffset=False)
    ax.xaxis.set_major_locator(MaxNLocator(nbins=6))
    words = []
    if d_flat is not None:
        ax.set_xlim(*(v / kd for v in ps.flat_limits(float(np.nanmean(D2)), 0.0)))
        words.append(f"D_2: {ps.no_content(d_flat, 'm')}")
    if v_flat is not None:
        ax.set_ylim(*(v / kv for v in ps.flat_limits(float(np.nanmean(vD2)), v_scale)))
        words.append(f"dD_2/dt: {ps.no_content(v_flat, 'm/s')}")
    for late, k, setlim, label in ((late_d, kd, ax.set_xlim, "D_2"),     # a start transient
                                   (late_v, kv, ax.set_ylim, "dD_2/dt")):  # left out
        if late:
            setlim(late[0] / k, late[1] / k)
            words.append(f"{label}: {late[2]}")
    if words:      # the panel is about 4.5 in wide; the trajectory may fill every corner
        ps.note(ax, "\n".join(ps.wrap(w, 4.2, 8) for w in words), loc="below")


def _spectrum(ax, spectrum, f_shaft, z, speed_rpm, duration, tm_flat):
    """The spectrum of T_m up to 2.5 Z shaft orders and at most the Nyquist frequency (the
    highest frequency given), with the order marks; says when the tooth pass is beyond the
    Nyquist frequency (and warns) or when T_m is round-off."""
    fr, am = (np.asarray(v, dtype=float) for v in spectrum)
    f_nyq = fr.max()
    f_max = f_nyq if not f_shaft else min(f_nyq, 2.5 * z * f_shaft)
    keep = (fr > 0) & (fr <= f_max)
    ax.semilogy(fr[keep], am[keep], lw=0.8, color="0.6" if tm_flat is not None else "tab:green")
    pos = am[keep][am[keep] > 0]
    if pos.size:
        ax.set_ylim(max(pos.min(), pos.max() * 1e-4), pos.max() * 3)
    ax.set_xlim(0, f_max)
    words = []
    if tm_flat is not None:
        words.append(f"T_m: {ps.no_content(tm_flat, 'N m')}:\nthese amplitudes are round-off")
    if f_shaft:
        for k, text, st in ps.order_marks(z):
            if k * f_shaft <= f_max:
                ax.axvline(k * f_shaft, **st)
        handles = [Line2D([], [], **ps.SHAFT_STYLE, label="shaft orders 1x, 2x"),
                   Line2D([], [], **ps.TOOTH_STYLE, label=f"tooth pass {z}x, {2 * z}x")]
        ax.legend(handles=handles, fontsize=8, loc="upper right", framealpha=0.9)
        sec = ax.secondary_xaxis("top", functions=(lambda f: f / f_shaft,
                                                   lambda o: o * f_shaft))
        sec.set_xlabel("shaft order", fontsize=8)
        sec.tick_params(labelsize=8)
        if z and z * f_shaft > f_nyq:
            text = ps.nyquist_note(z, z * f_shaft, f_nyq, speed_rpm, duration)
            words.append(text.replace(": ", ":\n", 1).replace(" (", "\n(", 1))
    if words:
        ps.note(ax, "\n".join(words), loc="lower left")
    ax.set_xlabel("frequency [Hz]")
    ax.set_ylabel("amplitude of T_m [N m]")
    ax.set_title("spectrum of T_m", fontsize=10)
    ax.grid(alpha=0.3, lw=0.5, which="major")
