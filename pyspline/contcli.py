"""`pyspline continue`: the command line of pyspline.continuation (docs/continuation.md)."""
from __future__ import annotations

import numpy as np

from .case import load_case
from .arclength import INTERRUPTED, continuation, parse_field
from .errors import CaseError
from .orbits import CALL_SECONDS


CONTINUE_HELP = """\
Follow the period-n orbit of CASE in one real field from --start to --stop by pseudo-arclength
continuation, through stable and unstable parts; locate folds (a multiplier through +1),
period doublings (through -1; the doubled branch is followed too), Neimark-Sacker points (a
complex pair through the unit circle) and grazing (a tooth's contact sequence changes).

Writes into --out DIR:
  DIR/continuation.nc          the branch points and special points (xarray.open_dataset(
                               path); docs/continuation.md)
  DIR/frequency_response.png   --measure (T_m peak-to-peak) against the field: stable solid,
                               unstable dashed, special points marked; with --sweep N the
                               runs of a follow-up and follow-down sweep of N points over it
  DIR/sweep.nc                 with --sweep N: that sweep
Prints one line per special point. Exit status: README's (CaseError 2, SolverError 3); 1 when
the branch could not be followed to --stop (the points so far are written, with where and why
it stopped: attrs['status'] and the last line on stderr) or no orbit was found at --start.
With --band LO HI the doubled branches that period doublings start are followed over LO..HI
(holding --start and --stop; default --start..--stop), e.g. down past --start to their fold.

With --all: every periodic branch of the band (pyspline.branches): a follow sweep of --sweep N
points (default 31; runs of the case's t_end: let it settle them, e.g. --fix t_end=1
--fix t_transient=0.5) seeds a continuation from each distinct attractor; branches.nc (the
branches), sweep.nc and branches.png. With --fold FIELD2=V1,V2,...: the folds of the branch
over --start..--stop at V1 followed in FIELD2 over the values' range by the extended system,
through cusps (pyspline.fold_curve; --repeated: a continuation at each value instead), the
folds at each value, the brute-force verdicts of follow sweeps of --sweep N points (default
31) at the values of --check V,V,... overlaid; fold_curve.nc and fold_curve.png. With
--graze-curves the grazing nearest each fold is followed as a curve in FIELD2 too.

example: pyspline continue cases/physical_ripple.nml --field speed_rpm --start 5000 --stop 7000
"""


def cmd_continue(args, fixed, exit_code) -> int:
    import sys
    from pathlib import Path
    from .dataset import write_netcdf
    from .errors import SplineError
    from .plots.continuation import MEASURES, frequency_response
    out = Path(args.out)
    try:
        case = load_case(args.case, **fixed(args.fix))
        command = " ".join(["pyspline", "continue", args.case, f"--field={args.field}",
                            f"--start={args.start:g}", f"--stop={args.stop:g}", f"--n={args.n}"])
        name, index = parse_field(case, args.field)
        if args.sweep < 0 or args.sweep == 1:
            raise CaseError(f"--sweep {args.sweep}: the follow sweep's number of points, >= 2 "
                            "(0: no sweep)")
        if args.sweep and index is not None:
            raise CaseError(f"--sweep: a follow sweep runs whole fields; {args.field} is "
                            "one element of an array field")
        band = _band(args)
        for flag, on in (("--repeated", args.repeated), ("--graze-curves", args.graze_curves),
                         ("--check", args.check)):
            if on and not args.fold:
                raise CaseError(f"{flag}: an option of --fold; give --fold FIELD2=V1,V2,...")
        if args.all or args.fold:
            if band is not None:
                raise CaseError("--band: the range of continue's doubled branches; --all and "
                                "--fold set it themselves (each seed's halves, the whole band)")
            return _other(args, case, name, index, command, out)
        if band is not None:
            command += f" --band {band[0]:g} {band[1]:g}"
        ds = continuation(case, args.field, args.start, args.stop, n=args.n, ds=args.ds,
                          ds_max=args.ds_max, max_angle=args.max_angle,
                          max_points=args.max_points, tol=args.tol, progress=not args.quiet,
                          command=command, max_seconds=args.max_seconds, band=band,
                          keep_interrupted=True)
        sw = None
        if args.sweep:
            from .sweeps import sweep
            sw = sweep(case, progress=not args.quiet, follow="both", spectrum=False,
                       **{name: np.linspace(args.start, args.stop, args.sweep)})
    except SplineError as exc:
        print(f"error: {type(exc).__name__}: {' '.join(str(exc).split())}", file=sys.stderr)
        return exit_code(exc)
    write_netcdf(ds, out / "continuation.nc")
    label = ds.attrs["field"]
    print(f"{ds.attrs['n_points']} points on {ds.attrs['n_branches']} branch(es), "
          f"{int(ds.stable.sum())} stable, in {ds.attrs['wall_s']:.1f} s")
    for i in range(ds.sizes["special"]):
        print(special_line(ds, i))
    print(f"wrote {out / 'continuation.nc'}")
    if sw is not None:
        write_netcdf(sw, out / "sweep.nc")
        print(f"wrote {out / 'sweep.nc'}")
    path = out / "frequency_response.png"
    frequency_response(ds, args.measure, sweep=sw, path=path,
                       title=f"{case.name}: {MEASURES[args.measure][0]} of the periodic orbits "
                             f"vs {label}" + (", follow sweeps up and down" if sw else "")
                             + ("" if ds.attrs["status"] == "complete" else
                                f" (stopped at {label} = {float(ds[label][-1]):.6g})"))
    print(f"wrote {path}")
    if ds.attrs["status"] != "complete":
        print(f"stopped: {ds.attrs['status']}", file=sys.stderr)
        return 130 if ds.attrs["status"].startswith(INTERRUPTED) else 1
    return 0


def special_line(ds, i: int) -> str:
    """The line `pyspline continue` prints for special point i of a continuation Dataset; a
    grazing's closest approach is NaN when every tooth switches over the period: said so."""
    from .plots.continuation import MEASURES
    label, kind = ds.attrs["field"], str(ds.special_type.values[i])
    mu = complex(ds.special_mu_real[i], ds.special_mu_imag[i])
    near = float(ds.special_closest_approach[i])
    what = (f"critical multiplier {mu:.4f}" if kind != "grazing" else
            f"closest approach {near:.3g} m" if np.isfinite(near) else
            "closest approach none (every tooth switches over the period)")
    return (f"{kind:16s} {label} = {float(ds[f'special_{label}'][i]):.6g}  period "
            f"{int(ds.special_n[i])}  {what}  {MEASURES['Tm_pp'][0]} "
            f"{float(ds.special_Tm_pp[i]):.4g} N m"
            + ("" if ds.special_smooth[i] else "  (non-smooth: the multiplier jumped across)"))


def _band(args):
    """--band LO HI as (lo, hi), or None; CaseError naming it unless finite with lo < hi and
    holding --start and --stop."""
    if args.band is None:
        return None
    lo, hi = args.band
    if not (np.isfinite(lo) and np.isfinite(hi) and lo < hi):
        raise CaseError(f"--band {lo:g} {hi:g}: two finite values LO < HI")
    for arg, v in (("--start", args.start), ("--stop", args.stop)):
        if not lo <= v <= hi:
            raise CaseError(f"--band {lo:g} {hi:g}: does not hold {arg} {v:g} (the band "
                            "holds the branch from --start to --stop)")
    return lo, hi


def _values(text: str, what: str):
    try:
        v = np.array([float(x) for x in text.split(",")])
    except ValueError:
        raise CaseError(f"{what} {text!r}: numbers separated by commas") from None
    if not len(v) or not np.isfinite(v).all():
        raise CaseError(f"{what} {text!r}: finite numbers separated by commas")
    return v


def _other(args, case, name, index, command, out) -> int:
    """`continue --all` (pyspline.branches) and `continue --fold` (pyspline.fold_curve)."""
    from .diagram import branches, fold_curve
    from .dataset import write_netcdf
    from .plots import fold_plane, frequency_response
    if args.all and args.fold:
        raise CaseError("--all and --fold: one at a time")
    points = args.sweep or 31
    if points < 3:
        raise CaseError(f"--sweep {args.sweep}: the follow sweeps' number of points, >= 3")
    if args.all:
        ds, sw = branches(case, args.field, args.start, args.stop, points=points,
                          progress=not args.quiet, command=command + " --all", ds=args.ds,
                          ds_max=args.ds_max, max_angle=args.max_angle,
                          max_points=args.max_points, tol=args.tol, max_seconds=args.max_seconds)
        write_netcdf(ds, out / "branches.nc")
        write_netcdf(sw, out / "sweep.nc")
        print(f"{ds.attrs['n_points']} points on {ds.attrs['n_branches']} branch(es) from the "
              f"seeds {ds.attrs['seeds']}; no periodic attractor: {ds.attrs['no_period'] or '-'}")
        for kind, p in zip(ds.special_type.values, ds[f"special_{ds.attrs['field']}"].values):
            print(f"{kind:16s} {ds.attrs['field']} = {p:.6g}")
        frequency_response(ds, args.measure, sweep=sw, path=out / "branches.png",
                           title=f"{case.name}: every periodic branch found, follow sweeps up "
                                 "and down")
        print(f"wrote {out / 'branches.nc'}, {out / 'sweep.nc'}, {out / 'branches.png'}")
        status = ds.attrs["status"]
    else:
        field2, _, text = args.fold.partition("=")
        fc = fold_curve(case, args.field, args.start, args.stop, field2.strip(),
                        _values(text, f"--fold {field2}="), n=args.n, progress=not args.quiet,
                        check=_values(args.check, "--check") if args.check else (),
                        check_points=points, command=command + f" --fold {args.fold}"
                        + " --repeated" * args.repeated + " --graze-curves" * args.graze_curves,
                        ds=args.ds, ds_max=args.ds_max, max_angle=args.max_angle,
                        max_points=args.max_points, tol=args.tol, max_seconds=args.max_seconds,
                        method="repeated" if args.repeated else "extended",
                        graze_curves=args.graze_curves)
        write_netcdf(fc, out / "fold_curve.nc")
        near = fc.fold_grazing.values if "fold_grazing" in fc else fc.fold.values * np.nan
        for v, f, g, h in zip(fc.value2.values, fc.fold.values, fc.grazing.values, near):
            print(f"{field2.strip()} = {v:.6g}: folds {np.round(f[np.isfinite(f)], 2)}, "
                  f"grazings {np.round(g[np.isfinite(g)], 2)}"
                  + (f", nearest each fold {np.round(h[np.isfinite(f)], 2)}"
                     if np.isfinite(h).any() else ""))
        if "cusp" in fc.attrs:
            print(f"cusps: {fc.attrs['cusp']}")
        if "graze_curve_status" in fc.attrs:
            print(f"grazing curves ({fc.sizes['graze_point']} points): "
                  f"{fc.attrs['graze_curve_status']}")
        fold_plane(fc, path=out / "fold_curve.png")
        print(f"wrote {out / 'fold_curve.nc'}, {out / 'fold_curve.png'}")
        status = fc.attrs["status"]
    if status != "complete":
        import sys
        print(f"stopped: {status}", file=sys.stderr)
        return 1
    return 0


def add_continue(sub, fixed, exit_code) -> None:
    """The `continue` subcommand (pyspline/cli.py)."""
    import argparse
    r = sub.add_parser("continue", help="follow a periodic orbit in one field (pseudo-arclength "
                       "continuation): continuation.nc and frequency_response.png in --out",
                       description=CONTINUE_HELP,
                       formatter_class=argparse.RawDescriptionHelpFormatter)
    r.add_argument("case", metavar="CASE", help="case file (namelist)")
    r.add_argument("--field", required=True, help="the field: speed_rpm, t_d, l_x, "
                   "ripple_amp (its first element), ripple_amp(2), unbalance(1), ...")
    r.add_argument("--start", type=float, required=True, help="the field's first value")
    r.add_argument("--stop", type=float, required=True, help="the field's last value")
    r.add_argument("--n", type=int, default=1, help="shaft revolutions of the period (default 1)")
    r.add_argument("--ds", type=float, default=0.05, help="first arclength step (default 0.05)")
    r.add_argument("--ds-max", type=float, default=0.25, help="largest arclength step "
                   "(default 0.25)")
    r.add_argument("--max-angle", type=float, default=0.15, metavar="RAD", help="the tangent's "
                   "turn a step aims at (default 0.15 rad; twice it halves the step)")
    r.add_argument("--max-points", type=int, default=200, help="most branch points (200)")
    r.add_argument("--tol", type=float, help="corrector residual, scaled (default 100 rtol)")
    r.add_argument("--band", nargs=2, type=float, metavar=("LO", "HI"),
                   help="the field's range over which doubled branches (period doublings) are "
                   "followed, holding --start and --stop (default --start..--stop)")
    r.add_argument("--measure", choices=("Tm_pp", "F_max", "D2_pp"), default="Tm_pp",
                   help="response measure of the figure (default Tm_pp)")
    r.add_argument("--sweep", type=int, default=0, metavar="N",
                   help="also a follow-up and follow-down sweep of N points, overlaid")
    r.add_argument("--all", action="store_true", help="every periodic branch of the band, "
                   "seeded by follow sweeps of --sweep N points (default 31): branches.nc, .png")
    r.add_argument("--fold", metavar="FIELD2=V1,V2,...", help="the folds and grazings followed "
                   "in a second field: fold_curve.nc and fold_curve.png")
    r.add_argument("--repeated", action="store_true", help="with --fold: a continuation at "
                   "each value of FIELD2 instead of the extended system (gives every value's "
                   "grazings)")
    r.add_argument("--graze-curves", action="store_true", help="with --fold: the grazing "
                   "nearest each fold followed as a curve in FIELD2 over the values' range "
                   "(graze_curve_*; 0.3-0.5 s of CPU a point)")
    r.add_argument("--check", metavar="V1,V2,...", help="with --fold: values of FIELD2 with a "
                   "follow sweep's verdict (one orbit or two) overlaid")
    r.add_argument("--max-seconds", type=float, default=CALL_SECONDS, metavar="S",
                   help=f"wall-time bound of the whole call (default {CALL_SECONDS:g}; inf: "
                   "none): past it what was computed is written, exit 1")
    r.add_argument("--fix", action="append", metavar="FIELD=VALUE",
                   help="change a field of the case (e.g. rtol=1e-9)")
    r.add_argument("--out", default=".", metavar="DIR", help="output directory (default .)")
    r.add_argument("--quiet", action="store_true", help="no progress bar")
    r.set_defaults(func=lambda a: cmd_continue(a, fixed, exit_code))
