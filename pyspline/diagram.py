"""Every branch in one call (`pyspline.branches`, `pyspline continue --all`): follow sweeps up
and down find the periodic attractors of a band, each distinct one seeds a continuation over
the band (stable and unstable parts), branches through the same orbit are merged; and the folds
of a band followed in a second field (`fold_curve`, `pyspline continue --fold`).
docs/continuation.md."""
from __future__ import annotations

import warnings

import numpy as np

from .arclength import (check_handed_on, continuation, field_label, parse_field, set_field,
                        valid_value)
from .errors import CaseError, SolverError, SplineError, SplineWarning
from .grazecurve import options
from .orbits import (CALL_SECONDS, OrbitError, out_of_time, repeat_revolutions,
                     section_points, time_bound)
from .specials import on_polyline, same_point


def _stretches(period):
    """(first, last, n) index runs of one direction's sweep points with the same period n
    (n = 0: no period found: not settled, chaotic or quasi-periodic)."""
    per = np.nan_to_num(np.asarray(period, float)).astype(int)
    edges = np.r_[0, np.flatnonzero(np.diff(per)) + 1, len(per)]
    return [(int(a), int(b) - 1, int(per[a])) for a, b in zip(edges[:-1], edges[1:])]


def _spans(stretches):
    return "; ".join(f"{d} {a:g}..{b:g}" + (f" ({what})" if what else "")
                     for d, a, b, what, _ in stretches)


def _without_period(case, final, n, max_n):
    """What a stretch that seeded nothing is, as (text, kind; kind 1 chaotic, 0 not, -1 not
    told): its sections' period n beyond max_n (0), or, when they gave none (n = 0), chaotic or
    not, by the largest Lyapunov exponent (Benettin) of a run as long as the sweep's sampled
    window continued from its middle point's final state (y, t), with renormalisations at
    least every quarter revolution: 'chaotic: ...' (1) when it and the slope of the log
    separation are positive beyond the spread of its running estimate (analysis.is_chaotic),
    else 'no period found within N revolutions, not chaotic: ...' (0: a run not settled, or
    quasi-periodic); -1 when its run failed."""
    from .analysis import largest_lyapunov_fit
    from .follow import continued
    from .orbits import _wall
    from .result import run
    if n > max_n:
        return f"period {n} > max_n = {max_n}", 0
    omega = case.model.info()["omega"]
    c = continued(case.replace(         # the sweep's window, no transient (it ran before)
        lyapunov=True, lyapunov_interval=min(case["lyapunov_interval"], 0.25), t_transient=0.0,
        transient_revolutions=0.0, t_end=case["t_end"] - case["t_transient"]), *final, omega)
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", SplineWarning)
            res = run(c.model, max_seconds=_wall(c.model, np.inf))
        ly = res.lyapunov
        fit = largest_lyapunov_fit(ly["t"], ly["log_growth"], t0=float(res.t[0]))
    except (SplineError, ValueError) as exc:
        return f"no period found, chaos not told (its Lyapunov run: {exc})", -1
    text, chaotic = lyapunov_verdict(fit)
    if chaotic:
        return f"chaotic: {text}", 1
    revs = (res.t[-1] - res.t[0]) * omega / (2 * np.pi)
    return f"no period found within {revs:.0f} revolutions, not chaotic: {text}", 0


def lyapunov_verdict(fit):
    """The chaos verdict of a Benettin record's fit (analysis.is_chaotic) and the evidence it
    rests on, as (text, chaotic): the running estimate, the slope of the log separation over
    the last two thirds and the spread both are held against."""
    from .analysis import is_chaotic
    return (f"largest Lyapunov exponent {fit.lam:.3g} 1/s, slope of the log separation "
            f"{fit.slope:.3g} 1/s (spread {fit.spread:.2g})",
            is_chaotic(fit.lam, fit.spread, fit.slope))


def _cut(sw):
    """Where (direction, value) the follow sweep's run was cut or not run by the call's time
    bound (follow.run_chain: its error names the wall-time bound)."""
    return np.char.find(sw.error.values.astype(str), "wall-time bound") >= 0


def _split_at_jumps(pp, a, b):
    """Split the run [a, b] of a chain where its response pp jumps (a step more than five
    times the run's median step: the chain fell onto another attractor)."""
    steps = np.abs(np.diff(pp[a:b + 1]))
    if len(steps) < 2:
        return [(a, b)]
    big = np.flatnonzero(steps > 5 * np.median(steps) + 1e-3 * np.abs(pp[a:b + 1]).max())
    cuts = np.r_[a, a + big + 1, b + 1]
    return [(int(i), int(j) - 1) for i, j in zip(cuts[:-1], cuts[1:])]


def _at_phase(case, y, t):
    """The state the run from y at time t reaches at the next time with the forcing phase of
    the case's t0 (the continuation's section)."""
    from .core import load
    from .orbits import _period_map
    model = load(case)
    span = 2 * np.pi * repeat_revolutions(case) / model.info()["omega"]
    dt = (case["t0"] - t) % span
    if dt < 1e-9 * span:
        return np.asarray(y, float)
    y1, _ = _period_map(model, t, t + dt, np.asarray(y, float)[:, None])
    return y1[:, 0]


def _seed(case, final, n, max_n):
    """The stable period-n orbit the sweep's run at `case` ended near (final: its state and
    time): n from the exact sections when the sweep found one, else the first n <= max_n whose
    Newton converges from that state onto a stable orbit; None when there is none (not
    settled, chaotic or quasi-periodic)."""
    from .orbits import periodic_orbit
    guess = _at_phase(case, *final)
    for m in ([n] if 0 < n <= max_n else range(1, max_n + 1)):
        try:
            orb = periodic_orbit(case, m, guess=guess)
        except SplineError:
            continue
        if orb.stable:
            return orb
    return None


def _on_branch(ds, label, p, y, scale, tol):
    """Whether (p, y) lies on a branch of `ds` (specials.on_polyline), in the continuation's
    scaled unknowns (the states by Eq. 25, the field by a tenth of its magnitude)."""
    pscale = 0.1 * max(abs(p), np.abs(ds[label].values).max())
    x = np.r_[p / pscale, np.asarray(y) / scale]
    return any(on_polyline(np.c_[ds[label].values[rows] / pscale, ds.y0.values[rows] / scale],
                           x, tol)
               for rows in (np.flatnonzero(ds.branch.values == b)
                            for b in np.unique(ds.branch.values)))


def merged(pieces, label, scale, tol, phases=None):
    """The indices of the pieces to keep, largest first: a piece every point of which lies on
    a kept one (_on_branch), at its own section points or, for a period-n piece, all at the
    k-th of them (phases(piece): the states there, one (points, 14) array per k), is the same
    branch and goes."""
    keep = []
    for i in sorted(range(len(pieces)), key=lambda i: -pieces[i].sizes["point"]):
        ps = pieces[i][label].values
        ways = [pieces[i].y0.values] + (list(phases(pieces[i])) if phases and keep else [])
        if not any(all(_on_branch(pieces[j], label, p, y, scale, tol) for p, y in zip(ps, ys))
                   for ys in ways for j in keep):
            keep.append(i)
    return keep


def _phases(case, name, piece):
    """The states of a period-n piece's points at each of their other section points
    (section_points): one (points, 14) array per section point after the first; none when a
    map run fails (or the time bound has passed: the branches so far are returned as they
    are)."""
    n = int(piece.n.values[0])
    if n == 1:
        return []
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", SplineWarning)      # the case's notes, said before
            ys = np.array([section_points(case.replace(**{name: float(p)}).model, case["t0"],
                                          n, y)
                           for p, y in zip(piece[name].values, piece.y0.values)])
    except SolverError:
        return []
    return list(ys.transpose(1, 0, 2)[1:])


def _section_points(orb):
    """The seed orbit's section points (section_points); its own alone when a map run fails."""
    try:
        return section_points(orb.case.model, orb.t0, orb.n, orb.y0)
    except SolverError:
        return orb.y0[None]


def _distinct(ds, label, scale, tol, phases=None):
    """The branches of `ds` (_concat's) without those every point of which lies on another
    (merged: a seed's branch traced from another seed too, at the same or another section
    point of a period-n orbit, or a doubled branch another seed's continuation traced),
    renumbered; and the indices of the seeds kept."""
    nb = ds.branch.values
    every = np.unique(nb)
    keep = sorted(every[merged([ds.isel(point=nb == b) for b in every], label, scale, tol,
                               phases)])
    ds = ds.isel(point=np.isin(nb, keep), special=np.isin(ds.special_branch.values, keep))
    ds["branch"] = ("point", np.searchsorted(keep, ds.branch.values))
    ds["special_branch"] = ("special", np.searchsorted(keep, ds.special_branch.values))
    kept = np.unique(ds.seed.values)
    ds["seed"] = ("point", np.searchsorted(kept, ds.seed.values))
    ds["special_seed"] = ("special", np.searchsorted(kept, ds.special_seed.values))
    return ds, kept


def one_doubling(ds, label, scale, tol):
    """The special points of `ds` with each period doubling once: the one recorded where a
    period-2n branch ends at its merge (special_n n on a branch of period 2n) goes when the
    period-n branch located it too (the same field value and state within sqrt(tol) in the
    scaled unknowns, specials.same_point): that one lists the merging branch in
    special_merge (-1: none)."""
    kind, sb, sn = ds.special_type.values, ds.special_branch.values, ds.special_n.values
    n_of = {int(b): int(n) for b, n in zip(ds.branch.values, ds.n.values)}
    pscale = 0.1 * np.abs(ds[label].values).max()
    u = np.c_[ds[f"special_{label}"].values / pscale, ds.special_y0.values / scale]
    other, drop = np.full(len(kind), -1), np.zeros(len(kind), bool)
    for i in np.flatnonzero((kind == "period_doubling") & (sn != [n_of[int(b)] for b in sb])):
        for j in np.flatnonzero((kind == "period_doubling") & (sn == sn[i])):
            if n_of[int(sb[j])] == sn[j] and same_point(u[i], u[j], tol):
                other[j], drop[i] = sb[i], True
    ds["special_merge"] = ("special", other, {
        "long_name": "the period-2n branch that ends at this period doubling (-1: none)"})
    return ds.isel(special=~drop)


def _join(down, up, label):
    """One branch from a seed's two halves: `down` (seed to start) reversed, then `up` (seed to
    stop) without its first point (the seed again). Doubled branches keep their own numbers."""
    import xarray as xr
    pv = [v for v in down.data_vars if "point" in down[v].dims]
    sv = [v for v in down.data_vars if "special" in down[v].dims]
    main_d = np.flatnonzero(down.branch.values == 0)[::-1]
    rest_d = np.flatnonzero(down.branch.values != 0)
    main_u = np.flatnonzero(up.branch.values == 0)[1:]
    rest_u = np.flatnonzero(up.branch.values != 0)
    dn = down[pv].isel(point=np.r_[main_d, rest_d])
    un = up[pv].isel(point=np.r_[main_u, rest_u])
    nb = int(down.branch.max()) + 1
    un["branch"] = xr.where(un.branch > 0, un.branch + nb - 1, 0)
    sp_u = up[sv].copy()
    sp_u["special_branch"] = xr.where(sp_u.special_branch > 0, sp_u.special_branch + nb - 1, 0)
    out = xr.merge([xr.concat([dn, un], dim="point"),
                    xr.concat([down[sv], sp_u], dim="special")], combine_attrs="override")
    out.attrs = dict(up.attrs)
    return out


def _concat(pieces):
    """The branches of several seeds as one Dataset: `branch` numbered through, `seed` the
    seed each point and special point came from."""
    import xarray as xr
    pts, sps, nb = [], [], 0
    for s, d in enumerate(pieces):
        pv = [v for v in d.data_vars if "point" in d[v].dims]
        sv = [v for v in d.data_vars if "special" in d[v].dims]
        a, b = d[pv].copy(), d[sv].copy()
        a["branch"] = a.branch + nb
        b["special_branch"] = b.special_branch + nb
        a["seed"] = ("point", np.full(a.sizes["point"], s))
        b["special_seed"] = ("special", np.full(b.sizes["special"], s, int))
        nb += int(d.branch.max()) + 1
        pts.append(a)
        sps.append(b)
    return xr.merge([xr.concat(pts, dim="point"), xr.concat(sps, dim="special")],
                    combine_attrs="override")


def branches(case, field: str, start: float, stop: float, points: int = 31, *,
             max_n: int = 8, progress: bool = True, command: str | None = None,
             sweep_case=None, max_seconds: float = CALL_SECONDS, **cont):
    """Every periodic branch of `case` over `field` in [start, stop] from one call.

    A follow sweep up and down (`points` values from start to stop, runs of `sweep_case`,
    default `case`: give it a t_end that settles) finds the attractors: each stretch of a
    direction with one period n from the exact Poincare sections (0: none found) and no jump in
    T_m peak-to-peak is an attractor; its middle point's final state, brought to the case's
    section phase, seeds `periodic_orbit` (period n, or when the sections gave none, the first
    n <= max_n on which Newton converges to a stable orbit) and a continuation from there to
    start and to stop (`cont`: continuation's keywords). A seed whose orbit lies on a branch
    already traced (same orbit at the same value, at any of its n section points) is not
    continued again; a branch whose every point lies on another (at the same section point, or
    every point at its k-th) is dropped. Stretches without a stable periodic orbit of n <= max_n
    (chaotic or quasi-periodic, or not settled) seed nothing; listed in attrs['no_period'].

    max_seconds : the wall time of the whole call (orbits.CALL_SECONDS; math.inf: none), shared
        by the follow sweep's runs, then the seeds' orbits and continuations in turn (each
        gets what is left; a run is cut where it passes, the runs after it not run): past it
        the branches so far are returned, 'status' saying so, with a SplineWarning;
        OrbitError naming it when none was traced.

    Returns (Dataset, sweep): the Dataset of `continuation` for all the branches (dim 'point',
    'branch' numbered through, 'seed' the seed's index; dims 'special' likewise; attrs
    'seeds': field value, direction and period of each seed continued, 'status' each seed's),
    and the follow sweep's Dataset (pyspline.plots.frequency_response(ds, sweep=sw) draws both)."""
    with time_bound(max_seconds, "branches"):
        return _branches(case, field, start, stop, points, max_n, progress, command,
                         sweep_case, cont)


def _branches(case, field, start, stop, points, max_n, progress, command, sweep_case, cont):
    """branches within its time bound."""
    from .core import load
    from .orbits import _scale
    from .sweeps import sweep
    name, index = parse_field(case, field)
    if index is not None:
        raise CaseError(f"field {field!r}: branches sweeps whole fields (the follow sweep); "
                        "give a scalar field")
    if isinstance(points, bool) or not isinstance(points, (int, np.integer)) or points < 3:
        raise CaseError(f"points = {points!r}: the follow sweep's number of values, a whole "
                        "number >= 3")
    if isinstance(max_n, bool) or not isinstance(max_n, (int, np.integer)) or max_n < 1:
        raise CaseError(f"max_n = {max_n!r}: the longest period to seed, a whole number >= 1")
    check_handed_on(case, field, start, stop, 1, cont)
    values = np.linspace(min(start, stop), max(start, stop), points)
    finals = {}
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", SplineWarning)   # unsettled runs near the folds
        sweep_case = case if sweep_case is None else sweep_case
        sw = sweep(sweep_case, progress=progress,
                   follow="both", spectrum=False, finals=finals, **{name: values})
    scale = _scale(load(case))
    tol = cont.get("tol") or 100 * case["rtol"]         # continuation's corrector's
    pieces, seeds, no_period, status, skipped = [], [], [], [], []
    if (cut := _cut(sw)).any():
        status.append(f"{out_of_time()} was reached in the follow sweeps ({cut.sum()} of "
                      f"{cut.size} runs cut or not run)")
    for d in ("up", "down"):
        idx = np.arange(points) if d == "up" else np.arange(points)[::-1]
        sub = sw.sel(direction=d)
        pp = (sub.Tm_max - sub.Tm_min).values[idx]
        for a, b, n in _stretches(sub.period.values[idx]):
            for i, j in _split_at_jumps(pp, a, b):
                k = idx[(i + j) // 2]
                p = float(values[k])
                orb = None if finals[d][k] is None or out_of_time() else _seed(
                    case.replace(**{name: p}), finals[d][k], n, max_n)
                if orb is None and out_of_time():
                    skipped.append(f"{d} {field} = {p:g}")
                    continue
                if orb is None:
                    no_period.append((d, values[idx[i]], values[idx[j]], *(
                        ("", -1) if finals[d][k] is None else _without_period(
                            sweep_case.replace(**{name: p}), finals[d][k], n, max_n))))
                    continue
                if any(_on_branch(x, field, p, y, scale, tol) for x in pieces
                       for y in _section_points(orb)):
                    continue        # the same orbit, at any of its section points
                halves = []
                for end in (start, stop):
                    if p == end:
                        continue
                    try:
                        with warnings.catch_warnings(record=True):
                            warnings.simplefilter("always", SplineWarning)
                            halves.append(continuation(
                                case, field, p, end, n=orb.n, guess=orb.y0, progress=progress,
                                band=(start, stop), **cont))
                    except OrbitError as exc:   # no time left for its orbit at the seed
                        if not out_of_time():
                            raise
                        status.append(f"seed {d} {field} = {p:g} to {end:g}: {exc}")
                        break
                    if halves[-1].attrs["status"] != "complete":
                        status.append(f"seed {d} {field} = {p:g} to {end:g}: "
                                      f"{halves[-1].attrs['status']}")
                if halves:
                    pieces.append(_join(*halves, field) if len(halves) == 2 else halves[0])
                    seeds.append(f"{p:g} {d} n={orb.n}")
    if skipped:
        status.append(f"{out_of_time()} was reached: seeds not continued: {', '.join(skipped)}")
    if not pieces and out_of_time():
        raise OrbitError(f"branches over {field} = {start:g}..{stop:g}: {out_of_time()} was "
                         "reached before any branch was traced")
    if not pieces:
        raise SplineError(f"branches: no periodic attractor found by the follow sweeps over "
                          f"{field} = {start:g}..{stop:g} (stretches without a period: "
                          f"{_spans(no_period) or 'none'})")
    ds, kept = _distinct(_concat(pieces), field, scale, tol,
                         lambda piece: _phases(case, name, piece))
    ds = one_doubling(ds, field, scale, tol)
    if no_period:       # plots.frequency_response shades them
        ds["no_period_range"] = (("stretch", "end"),
                                 np.sort([[a, b] for _, a, b, *_ in no_period]))
        ds["no_period_chaotic"] = ("stretch", [kind for *_, kind in no_period])  # _without_period
    ds.attrs.update(start=start, stop=stop, seeds="; ".join(seeds[i] for i in kept),
                    no_period=_spans(no_period), status="; ".join(status) or "complete",
                    n_points=ds.sizes["point"], n_branches=int(ds.branch.max()) + 1,
                    command=command or f"pyspline.branches({case.name!r}, {field!r}, "
                                       f"{start:g}, {stop:g}, points={points})")
    if status:
        warnings.warn(f"branches: {ds.attrs['status']}: the branches so far are returned "
                      "(attrs['status'])", SplineWarning, stacklevel=3)
    return ds, sw


def coexistence(sw, rel: float = 0.05):
    """The verdict of a follow='both' sweep per value: True where the up and the down chains
    end on different attractors (T_m peak-to-peak apart by more than `rel` of the larger:
    two orbits coexist), False where they agree (one orbit)."""
    up, down = ((sw.Tm_max - sw.Tm_min).sel(direction=d).values for d in ("up", "down"))
    return np.abs(up - down) > rel * np.maximum(np.abs(up), np.abs(down))


def _predicted_band(prev):
    """The band in which to look for a value's fold pair, from the fold pairs of the values
    before it (prev: (value2, lo, hi), latest last): the last pair, shifted by the last
    shift (linear in the second field) when there are two, widened each side by the larger
    of the pair's width, twice the shift and 2 % of the whole band; None when the last value
    had no fold pair (then the whole band)."""
    if not prev or len(prev[-1]) < 3:
        return None
    v, lo, hi = prev[-1]
    shift = np.zeros(2)
    if len(prev) > 1 and len(prev[-2]) == 3 and prev[-2][0] != v:
        shift = (np.array([lo, hi]) - prev[-2][1:]) / (v - prev[-2][0])
    return shift, v, lo, hi


def _band(start, stop, pred, v):
    """(b0, b1): the predicted fold pair at v with its margins, within [start, stop] and in
    its direction."""
    shift, v_prev, lo, hi = pred
    lo, hi = np.sort(np.array([lo, hi]) + shift * (v - v_prev))
    w = max(hi - lo, 2 * np.abs(shift * (v - v_prev)).max(), 0.02 * abs(stop - start))
    a, b = min(start, stop), max(start, stop)
    b0, b1 = max(a, lo - w), min(b, hi + w)
    return (b0, b1) if stop > start else (b1, b0)


def _guess_at(ds, p):
    """The previous value's orbit at p: its branch from start up to the first fold,
    interpolated linearly per state (its end state beyond it)."""
    ps = ds[ds.attrs["field"]].values
    turn = np.flatnonzero(np.diff(np.sign(np.diff(ps))) != 0)
    last = turn[0] + 2 if len(turn) else len(ps)
    ps, ys = ps[:last], ds.y0.values[:last]
    order = np.argsort(ps)
    return np.array([np.interp(p, ps[order], ys[order, j]) for j in range(ys.shape[1])])


def fold_curve(case, field: str, start: float, stop: float, field2: str, values2, n: int = 1,
               *, check=(), check_points: int = 31, check_case=None, progress: bool = True,
               command: str | None = None, method: str = "extended", narrow: bool = True,
               max_seconds: float = CALL_SECONDS, graze_curves=False, **cont):
    """The folds of the period-n branch over `field` in [start, stop], followed in a second
    field: two folds bound the band where two orbits coexist; where they meet (a cusp) the
    hysteresis ends.

    method : 'extended' (default): the branch is continued over the band at values2[0] (at
        the next values in turn while one gives no smooth fold), and each of its folds is
        followed in (field, field2) by the minimally extended system (pyspline.foldcurve:
        F = P^n(y) - y = 0, g = 0 from the bordered M - I; exact M with saltation, seven
        variational runs per Newton step) within [start, stop] x [min, max of values2], both
        ways, through cusps, until it leaves that rectangle or the orbit's contact sequence
        changes ('grazing at ...': a fold past it is not followed). The folds at each value
        of field2 are where the curves cross it, corrected there, and from each the value's
        branch is walked both ways to the nearest grazing (a grazing curve per fold curve,
        sampled at the values). 'repeated': a continuation
        over the band at each value in turn (`cont`: continuation's keywords, for both), from
        the previous value's orbit at the band's start; gives every value's grazings.
    narrow : (repeated) once a value has a fold pair, the next value's band is narrowed around
        where its folds are predicted (the last pair moved by the last shift, linear in field2;
        margins of the larger of the pair's width, twice the shift and 2 % of the band): the
        branch outside the folds is not traced again. A narrowed band that does not give a
        fold pair is traced again over [start, stop].
    max_seconds : the wall time of the whole call (orbits.CALL_SECONDS; math.inf: none);
        repeated: each value gets what is left over the values left, so a slow value cannot
        take the others' time; its status says when its share ran out. The check sweeps run
        after the folds, in what is left (a run is cut where it passes, the runs after it not
        run: those values' verdicts -1).
    graze_curves : (extended) True, or a dict of some of pyspline.grazecurve.STEPS (ds, ds_min,
        ds_max: steps in field2, scaled by a tenth of its magnitude; move: the largest miss of
        the prediction, in the first field so scaled; max_points per direction): from the
        grazing nearest each fold, the grazing curve followed in field2 over [min, max of
        values2] (a short walk and a bisection per point, 0.3-0.5 s of CPU each; default False).
    check : values of field2 at which a follow sweep up and down (`check_points` values over
    the band, runs of `check_case`, default `case`: give it a t_end that settles) gives the
    brute-force verdict per value: one orbit or two coexisting (`coexistence`).

    Returns a Dataset: dim `value2` (field2's values): `fold` (value2, fold; sorted, NaN
    padded), `grazing` (value2, grazing; in order along the branch from the band's start: the
    first is where the orbit there changes its contact sequence; extended: only the values
    continued), `band` (value2, end: the band continued), `status` (each value's: 'complete'
    or why a fold may be missing there). Extended: `fold_grazing` (value2, fold; beside
    `fold`): the grazing nearest each fold along the value's branch, walked from the fold's
    orbit both ways (NaN where none within reach: attrs['fold_grazing_status'] says why),
    `fold_grazing_bracket` the field's span it was located to; along the curves (dim
    `curve_point`):
    `curve` (which), `curve_field`, `curve_field2`, `curve_y0`, `curve_Tm_pp`,
    `curve_mu_other` (the largest |mu| besides the one at +1), `curve_stable`; dims `cusp`
    (`cusp_field`, `cusp_field2`; attrs['cusp']) and `stop` (`stop_field`, `stop_field2`,
    `stop_status`: where a direction stopped short of the rectangle's side, and why);
    attrs['curve_status'] each direction's. With graze_curves, along dim `graze_point`:
    `graze_curve` (which), `graze_curve_field`, `graze_curve_field2`, `graze_curve_ends` (the
    first field either side of the grazing), `graze_curve_y0`; `graze_curve_status` (dim
    `graze_curve`: each direction's end; attrs['graze_curve_status']). With check, dims `check`
    and `check_point`: `check_value`, `check_field`, `coexist` (-1: a run of either direction
    cut or not run, the time bound had passed). A value at which no orbit is found at its
    band's start (OrbitError, SolverError) has no folds and says so in `status`.
    attrs['status']: 'complete' or what was not, with a SplineWarning."""
    name2, index2 = parse_field(case, field2)
    values2 = _values(case, name2, index2, "values2", values2, 1)
    check = _values(case, name2, index2, "check", check, 0)
    if isinstance(check_points, bool) or not isinstance(check_points, (int, np.integer)) \
            or check_points < 2:
        raise CaseError(f"check_points = {check_points!r}: the check sweeps' number of values, "
                        "a whole number >= 2")
    check_handed_on(case, field, start, stop, n, cont)
    if method not in ("extended", "repeated"):
        raise CaseError(f"method = {method!r}: 'extended' (the fold followed by the extended "
                        "system) or 'repeated' (a continuation per value of field2)")
    graze = options(graze_curves)
    if graze is not None and method != "extended":
        raise CaseError(f"graze_curves with method = {method!r}: the grazing curves start from "
                        "the extended system's grazings (method='extended')")
    with time_bound(max_seconds, "fold_curve"):
        if method == "extended":
            from .foldcurve import curve_dataset, extended
            label = field_label(*parse_field(case, field))
            out = curve_dataset(*extended(case, field, start, stop, name2, index2, values2, n,
                                          progress, cont), label, field_label(name2, index2),
                                values2, graze=graze)
            out["band"] = (("value2", "end"), np.tile([start, stop], (len(values2), 1)))
            out.attrs["field"] = label
        else:
            out = _fold_values(case, field, start, stop, name2, index2, values2, n, narrow,
                               progress, cont)
        if len(check):
            _check(out, case if check_case is None else check_case, field, start, stop, name2,
                   index2, check, check_points, progress)
    bad = list(dict.fromkeys(str(x) for x in out.status.values if x != "complete"))
    if "coexist" in out and (out.coexist < 0).any():
        late = out.check_value.values[(out.coexist < 0).any("check_point")]
        bad.append(f"the wall-time bound of fold_curve, max_seconds = {max_seconds:g} s, was "
                   f"reached before the check sweeps at {', '.join(f'{v:g}' for v in late)} had "
                   "run to their end")
    out.attrs.update(case=case.text(), field2=field2, start=start, stop=stop, n=n,
                     status="; ".join(bad) or "complete",
                     command=command or f"pyspline.fold_curve({case.name!r}, {field!r}, "
                                        f"{start:g}, {stop:g}, {field2!r}, [...])")
    if bad:
        warnings.warn(f"fold_curve: {out.attrs['status']} (attrs['status'])", SplineWarning,
                      stacklevel=2)
    return out


def _values(case, name2, index2, what, values, least):
    """values of the second field (field2: name2, element index2) as a 1-d float array, each
    a valid value of it in `case`; CaseError naming `what` otherwise or when fewer than
    `least`."""
    from .core import load
    label = field_label(name2, index2)
    try:
        v = np.atleast_1d(np.asarray(values, float))
    except (TypeError, ValueError):
        v = None
    if v is None or v.ndim != 1 or len(v) < least or not np.isfinite(v).all():
        raise CaseError(f"{what} = {values!r}: finite values of {label}"
                        + (", at least one" if least else ""))
    for x in v:
        valid_value(lambda p: load(set_field(case, name2, index2, p)), x, label, f"{what}: ")
    return v


def _fold_values(case, field, start, stop, name2, index2, values2, n, narrow, progress, cont):
    """fold_curve's continuations, one per value of the second field, each within its share
    of the time left."""
    import xarray as xr
    from .orbits import time_left
    folds, grazes, bands, status, prev, pairs = [], [], [], [], None, []
    for i, v in enumerate(values2):
        at = set_field(case, name2, index2, v)
        what = f"fold_curve at {field_label(name2, index2)} = {v:g}"
        pred = _predicted_band(pairs) if narrow else None
        tries = ([_band(start, stop, pred, v)] if pred else []) + [(start, stop)]
        with time_bound(max(time_left() / (len(values2) - i), 1e-6), what):
            for b0, b1 in tries:
                try:
                    with warnings.catch_warnings(record=True):
                        warnings.simplefilter("always", SplineWarning)
                        ds = continuation(at, field, b0, b1, n=n, progress=progress,
                                          guess=None if prev is None else _guess_at(prev, b0),
                                          **cont)
                except CaseError:
                    raise
                except SplineError as exc:      # no orbit at start: the other values go on
                    ds, why = None, f"{what}: {type(exc).__name__}: {exc}"
                    continue
                kinds = ds.special_type.values.astype(str)
                sp = ds[f"special_{ds.attrs['field']}"].values
                why = ds.attrs["status"]
                if (kinds == "fold").sum() >= 2 or (b0, b1) == (start, stop) or out_of_time():
                    break
        bands.append((b0, b1))
        status.append(why)
        if ds is None:
            folds.append([])
            grazes.append([])
            pairs.append((v,))
            continue
        prev = ds
        folds.append(np.sort(sp[kinds == "fold"]))
        grazes.append(sp[kinds == "grazing"])       # in order along the branch from b0
        pairs.append((v, *folds[-1][:2]) if len(folds[-1]) >= 2 else (v,))
    from .foldcurve import _padded
    return xr.Dataset({"fold": (("value2", "fold"), _padded(folds)),
                       "grazing": (("value2", "grazing"), _padded(grazes)),
                       "band": (("value2", "end"), np.array(bands, float)),
                       "status": (("value2",), np.array(status, dtype=object))},
                      coords={"value2": values2},
                      attrs=dict(field=field_label(*parse_field(case, field))))


def _check(out, case, field, start, stop, name2, index2, check, points, progress):
    """The follow sweeps' verdicts at the values `check` of the second field into `out`
    (-1 where the time bound had passed before the sweep)."""
    from .sweeps import sweep
    pts = np.linspace(min(start, stop), max(start, stop), points)
    verdict = []
    for v in check:
        if out_of_time():
            verdict.append(np.full(points, -1))
            continue
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", SplineWarning)
            sw = sweep(set_field(case, name2, index2, v), progress=progress, follow="both",
                       spectrum=False, **{parse_field(case, field)[0]: pts})
        verdict.append(np.where(_cut(sw).any(0), -1, coexistence(sw)))
    out["check_value"] = ("check", check)
    out["check_field"] = ("check_point", pts)
    out["coexist"] = (("check", "check_point"), np.array(verdict, int))
