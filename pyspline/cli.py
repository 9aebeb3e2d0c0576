"""pyspline: simulate involute spline couplings (Xue, Shen & Xue 2025, and beyond).

commands (each --help says what it writes and where):
  cases list | copy NAME [DEST]   the shipped cases; copy one to start your own (template)
  run CASE...                     run cases, print what each answers (--out DIR: NAME.npz)
  plot CASE... [--out DIR]        one scene as a figure: DIR/NAME.png
  sweep CASE --set F=a:b:n ...    sweep one or two fields (or --table design.csv): DIR/sweep.nc
  continue CASE --field F ...     follow a periodic orbit in F: DIR/continuation.nc, figure
  merge SUMMARY... --out DIR      spline-dyn --summary files into DIR/sweep.nc
  reproduce [--out DIR]           the paper's scenarios: figures, verification table, summary
  calibrate, check-exe            fit the paper's unknowns; executable against Python
Also `python -m pyspline`. The standalone executable is spline-dyn (spline-dyn --help)."""
from __future__ import annotations

import argparse
import concurrent.futures as cf
import shlex
import sys
import warnings
from pathlib import Path

import numpy as np

from .case import load_case
from .errors import CaseError, SolverError, SplineError, SplineWarning, ThermalInterferenceError
from .mergecli import add_merge
from .summary import NOT_SETTLED
from .sweeps import MERGED, POINTS_DIR, parse_values, sweep


def _pm(value, se, fmt) -> str:
    """value +- its standard error to 2 digits (left out where there is none: NaN)."""
    return f"{value:{fmt}}" + (f" +- {se:.2g}" if np.isfinite(se) else "")


def _summary(res, warned: int | None = None) -> str:
    """What `pyspline run` prints for a run: a line of ranges, then the engineer's questions
    (docs/model.md section 15): which teeth carry what, does it rattle, how hot, how close to
    the limits, how far to trust the numbers (+- a standard error by batch means over
    revolutions), and whether the input drew plausibility warnings (`warned`: their number)."""
    F = res.tooth["F"]
    s = res.stats
    ld = res.loads      # the core's loads of the run (docs/model.md section 15)
    z = F.shape[1]
    lines = [
        f"{res.case.name:>16s}  F_j [{F.min():8.2f}, {F.max():8.2f}] N  "
        f"T_m [{res.Tm.min():7.2f}, {res.Tm.max():7.2f}] N m  "
        f"k_v [{res.kv.min():.3f}, {res.kv.max():.3f}]  "
        f"D2 [{res.D2.min():.4e}, {res.D2.max():.4e}] m  "
        f"{res.level}  steps {s['steps']}  {s['wall_s']*1e3:.0f} ms",
        f"  teeth:  load sharing {ld['load_sharing']:.3f} (tooth "
        f"{ld['load_sharing_tooth']:.0f}: {ld['F_static'] * ld['load_sharing']:.1f} N against "
        f"{ld['F_static']:.1f} N static); per revolution "
        f"{_pm(ld['load_sharing_rev'], ld['load_sharing_rev_se'], '.3f')}" if ld["F_static"] > 0
        else f"  teeth:  load sharing undefined (T_d = 0: no static tooth load); largest tooth "
             f"load {np.max(ld['F_peak']):.1f} N",
        f"  rattle: free teeth {_pm(ld['teeth_free_mean'], ld['teeth_free_mean_se'], '.2f')} "
        f"of {z} (never loaded {ld['teeth_unloaded']:.0f}); on the back flank "
        f"{ld['teeth_back']:.0f} teeth; impacts/rev "
        f"{_pm(ld['impacts_per_rev'], ld['impacts_per_rev_se'], '.2f')}; closing speed max "
        f"{ld['closing_speed_max'] * 1e3:.1f} mm/s",
        f"  heat:   T_f max {ld['Tf_max']:.3g} degC"
        + (f" (tooth {ld['Tf_max_tooth']:.0f}, t = {ld['Tf_max_t_s']:.4g} s); per revolution "
           f"{_pm(ld['Tf_max_rev'], ld['Tf_max_rev_se'], '.3g')} degC"
           if ld["Tf_max_tooth"] > 0 else " (no flash temperature at this thermal level)"),
        f"  limits: stress root/flank/shear {ld['sigma_root'] * 1e-6:.1f}/"
        f"{ld['sigma_flank'] * 1e-6:.1f}/{ld['tau_pitch'] * 1e-6:.1f} MPa, "
        f"{100 * ld['stress_ratio']:.0f} % of the typical allowable (docs/model.md section 15)",
        f"  trust:  {ld['revolutions']:.1f} revolutions; T_m RMS "
        f"{_pm(float(np.sqrt(np.mean(res.Tm ** 2))), ld['Tm_rms_se'], '.4g')} N m"
        + ("" if ld["batches"] >= 2 else " (no standard errors: fewer than 2 whole revolutions)")
        + _accuracy_note(res)]
    if warned is not None:
        lines.append("  input:  " + ("no plausibility warning" if not warned else
                                     f"{warned} plausibility warning{'s' * (warned > 1)} "
                                     "(the warning: lines)"))
    return "\n".join(lines)


def _accuracy_note(res) -> str:
    """The trust line's words on the numerical error (docs/accuracy.md): the error estimate of
    the tooth forces against a tighter run, or the statistics goal's settings."""
    s = res.stats
    if res.case["goal"] == "statistics":
        k = res.case["realisations"]
        return (f"; goal statistics: ERK (Cash-Karp) without root finding at rtol {s['rtol_used']:.0e} "
                "(the transient looser), statistics biased about 1 % at most, under their standard error "
                "(chaos_z24), the trajectory not resolved"
                + (f"; {k} realisations, standard errors from their spread, at least their batch means'" if k > 1 else ""))
    if s["F_error_est"] < 0 and s["F_parted_t_s"] < 0:
        return ""
    note = (f"; F error est {s['F_error_est']:.2g} up to t = {s['F_error_t_s']:.4g} s"
            if s["F_error_est"] >= 0 else "; F error not estimated")
    if s["F_parted_t_s"] >= 0:
        note += f" (a tighter run parts at t = {s['F_parted_t_s']:.4g} s: chaos?)"
    acc = res.case["accuracy"]
    return note + (f" (accuracy {acc:.2g}, rtol {s['rtol_used']:.2g})" if acc > 0 else "")


#: exit status of each failure (README, "Errors and exit codes"; spline-dyn's err_exit_code)
EXIT_CODES = ((CaseError, 2), (SolverError, 3), (ThermalInterferenceError, 4),
              (KeyboardInterrupt, 130))


def exit_code(exc: BaseException) -> int:
    """The exit status of a failure: CaseError 2, SolverError 3, ThermalInterferenceError 4,
    KeyboardInterrupt 130, anything else 1."""
    return next((code for cls, code in EXIT_CODES if isinstance(exc, cls)), 1)


def _one_line(exc: BaseException) -> str:
    """An exception as one line: its class and its message, newlines folded."""
    return f"{type(exc).__name__}: {' '.join(str(exc).split())}"


def check_out_dir(path, option: str = "--out") -> Path:
    """An output directory of a command, checked before anything is computed: a directory or a
    new path under a writable directory; else CaseError naming the path and why (exit 2)."""
    import os
    p = Path(path)
    if p.exists() and not p.is_dir():
        raise CaseError(f"{option} {p}: exists and is not a directory (an output directory is "
                        "wanted)")
    parent = p
    while not parent.exists():          # the nearest part of the path that exists
        parent = parent.parent
    if not parent.is_dir():
        raise CaseError(f"{option} {p}: cannot be made: {parent} is not a directory")
    if not os.access(parent, os.W_OK | os.X_OK):
        raise CaseError(f"{option} {p}: cannot write there ({parent} is not writable)")
    return p


_RESULT_KEY = "pyspline_case"     #: the member that marks an .npz written by `pyspline run`


def _safe_stem(name: str) -> str:
    """A case name as a file name: characters other than letters, digits, '.', '_', '-' become '_'."""
    stem = "".join(ch if ch.isascii() and (ch.isalnum() or ch in "._-") else "_" for ch in name)
    stem = stem.strip(".") or "case"
    return stem[:120]


def _is_our_result(path: Path) -> bool:
    """An .npz that `pyspline run --out` wrote (it holds the case text as _RESULT_KEY)."""
    try:
        with np.load(path, allow_pickle=False) as f:
            return _RESULT_KEY in f.files
    except Exception:
        return False


def _save_result(res, out: Path, taken: set) -> tuple[Path, str]:
    """Write a result into out as NAME.npz, atomically (a temporary file renamed). A name
    another case of this run already took gets -2, -3, ...; a file of the same name that
    pyspline did not write is never replaced (the result goes to the next free name); an
    earlier pyspline result is replaced. Returns the path and a note for the user ('' if none)."""
    import os
    import tempfile
    stem = _safe_stem(res.case.name)
    note = ""
    k = 1
    while True:
        path = out / (f"{stem}.npz" if k == 1 else f"{stem}-{k}.npz")
        if path in taken:
            note = f"another case of this run is named {res.case.name!r}"
        elif path.exists() and not (path.is_file() and _is_our_result(path)):
            note = f"{path} exists and was not written by pyspline run: not overwritten"
        else:
            break
        k += 1
    if path.exists():
        note = (note + "; " if note else "") + f"replaced the earlier result {path.name}"
    fd, tmp = tempfile.mkstemp(prefix=f".{path.name}.", suffix=".tmp", dir=out)
    try:
        with os.fdopen(fd, "wb") as f:
            extra = {f"stat_{k}": np.array(v) for k, v in res.stats.items()}
            if res.section_t is not None and len(res.section_t):
                extra.update(section_t=res.section_t, section_y=res.section_y)
            np.savez_compressed(f, t=res.t, y=res.y, Tm=res.Tm, kv=res.kv, **res.tooth,
                                **res.loads, **extra,
                                **{_RESULT_KEY: np.array(res.case.text())})
        os.replace(tmp, path)
    except BaseException:
        Path(tmp).unlink(missing_ok=True)
        raise
    taken.add(path)
    return path, note


def cmd_run(args) -> int:
    """Run each case; a failure of any kind in one prints one line and the next case runs.
    The exit status is that of the first failure (`exit_code`), 0 if every case ran."""
    from .core import simulate
    status = 0
    taken: set = set()
    out = Path(args.out) if args.out else None
    for path in args.cases:
        try:
            with warnings.catch_warnings(record=True) as rec:
                warnings.simplefilter("always", SplineWarning)
                res = simulate(load_case(path, **_fixed(getattr(args, "fix", None))))
            for w in rec:                       # shown as usual (the warning: lines), counted
                warnings.showwarning(w.message, w.category, w.filename, w.lineno)
            print(_summary(res, sum(issubclass(w.category, SplineWarning) for w in rec)))
            if out is not None:
                out.mkdir(parents=True, exist_ok=True)
                saved, note = _save_result(res, out, taken)
                if note:
                    print(f"note: case {res.case.name}: result in {saved} ({note})", file=sys.stderr)
        except KeyboardInterrupt:
            print(f"interrupted: {path}", file=sys.stderr)
            return 130
        except Exception as exc:      # any failure: one line, then the next case
            print(f"error: {path}: {_one_line(exc)}", file=sys.stderr)
            status = status or exit_code(exc)
    return status


#: what `pyspline reproduce` writes into --out, besides the figures (named in summary.json)
_REPRODUCE_MARK = ".pyspline-reproduce"


def _reproduce_files() -> list[str]:
    from .paper import FIGURES, PHYSICAL
    return ([f"{k}.png" for k in FIGURES] + [f"{c}.png" for c in PHYSICAL]
            + ["verification.csv", "verification.md", "summary.json"])


def _foreign_files(out: Path) -> list[str]:
    """The files reproduce would write into out that an earlier reproduce did not write."""
    import json
    if not out.exists():
        return []
    ours: set = set()
    mark = out / _REPRODUCE_MARK
    if mark.is_file():
        ours = set(mark.read_text(encoding="utf-8", errors="replace").split())
    else:
        try:           # a directory an earlier reproduce (before the mark existed) wrote
            s = json.loads((out / "summary.json").read_text(encoding="utf-8"))
            if {"rows", "figures", "executable_check"} <= set(s):
                ours = set(_reproduce_files()) | set(s["figures"])
        except Exception:
            pass
    return [n for n in _reproduce_files() if (out / n).exists() and n not in ours]


def _cases_arg(args, names) -> Path | None:
    """--cases DIR of reproduce, calibrate and check-exe: a directory holding the cases `names`
    the command reads (a CaseError naming --cases and what is missing); None if not given."""
    if args.cases is None:
        return None
    d = Path(args.cases)
    if not d.is_dir():
        raise CaseError(f"--cases {d}: no such directory")
    missing = [f"{n}.nml" for n in names if not (d / f"{n}.nml").is_file()]
    if missing:
        raise CaseError(f"--cases {d}: the directory lacks {', '.join(missing)}")
    return d


def cmd_reproduce(args) -> int:
    from .paper import ALL_CASES, reproduce
    directory = _cases_arg(args, ALL_CASES)
    out = Path(args.out)          # a directory or a new path: main's check_out_dir
    foreign = _foreign_files(out)
    if foreign:
        print(f"error: reproduce --out {out}: {', '.join(foreign)} exist(s) and were not written "
              "by pyspline reproduce: not overwritten (choose another --out or remove them)",
              file=sys.stderr)
        return 2
    s = reproduce(args.out, quick=args.quick, directory=directory)
    (out / _REPRODUCE_MARK).write_text("\n".join(sorted(set(_reproduce_files()) | set(s["figures"])))
                                       + "\n", encoding="utf-8")
    print((out / "verification.md").read_text())
    print(f"figures: {', '.join(s['figures'])} in {out}/")
    print(f"executable check (spline-dyn vs Python): {s['executable_check']}")
    print(f"k_m: calibrated {s['k_m']['calibrated']:.4g} N/m, potential energy "
          f"{s['k_m']['potential_energy']:.4g} N/m (ratio {s['k_m']['ratio']:.0f})")
    print(f"Poincare distinct points: {s['poincare_distinct_points']}")
    print(f"simulation time {s['run_time_s']:.1f} s; summary.json, verification.csv in {out}/")
    return 0


def cmd_calibrate(args) -> int:
    from .paper import ROWS, calibrate, cases_dir, sensitivities, write_calibration
    directory = cases_dir(_cases_arg(args, sorted({r.case for r in ROWS})))
    fit = calibrate(directory, quick=args.quick)
    print(f"fitted k_m = {fit['k_m']:.6g} N/m to max|D2| = {ROWS[0].paper:g} m of {ROWS[0].case}")
    print(f"fitted f_m = {fit['f_m']:.6g} to max T_f = {ROWS[1].paper:g} degC of {ROWS[1].case}")
    print(f"potential-energy k_m = {fit['k_m_potential_energy']:.4g} N/m: "
          f"{fit['k_m_potential_energy'] / fit['k_m']:.0f} times the fitted value")
    if fit["f_m"] > 1:
        print(f"warning: f_m = {fit['f_m']:.3g} is no friction coefficient: the paper's flash "
              "temperatures are far above what Eqs. 3-7 give (see README)")
    sens = sensitivities(directory, quick=args.quick, fitted=fit)
    print("\nsensitivity d ln(value) / d ln(unknown) of every row:")
    print(f"{'case/quantity':78s} {'k_m':>8s} {'f_m':>8s} {'m_1=m_2':>8s}")
    for key, d in sens.items():
        print(f"{key[:78]:78s} " + " ".join(f"{d[p]:8.3f}" for p in ("k_m", "f_m", "m_1=m_2")))
    if args.write:
        changed = write_calibration(directory, fit)
        print(f"\nwrote k_m (and f_m where present) into {len(changed)} case files in {directory}")
    else:
        print("\n(dry run: --write puts the fitted values into the paper cases)")
    return 0


def cmd_check_exe(args) -> int:
    from .paper import ALL_CASES, cases_dir, check_executable
    rep = check_executable(cases_dir(_cases_arg(args, ALL_CASES)), ALL_CASES, quick=not args.full)
    for k, v in rep.items():
        print(f"{k:24s} {v}")
    return 0 if all(v == "identical" for v in rep.values()) else 1


def _installed_cases() -> Path:
    from .paper import cases_dir
    return cases_dir()


def cmd_cases(args) -> int:
    """List the shipped cases, or copy one (with its comments) to a file or directory."""
    src = _installed_cases()
    names = sorted(p.stem for p in src.glob("*.nml"))
    if args.action == "list":
        for n in names:
            first = next((ln[1:].strip() for ln in (src / f"{n}.nml").read_text().splitlines()
                          if ln.startswith("!")), "")
            print(f"{n:24s} {first[:90]}")
        print(f"({len(names)} cases in {src}; `pyspline cases copy NAME DEST` copies one)")
        return 0
    if args.name not in names:
        print(f"pyspline: error: no case {args.name!r}: the cases are {', '.join(names)}",
              file=sys.stderr)
        return 2
    dest = Path(args.dest or f"{args.name}.nml")
    if dest.is_dir():
        dest = dest / f"{args.name}.nml"
    if dest.exists() and not args.force:
        print(f"pyspline: error: {dest} exists (--force replaces it)", file=sys.stderr)
        return 2
    try:
        dest.write_text((src / f"{args.name}.nml").read_text())
    except OSError as exc:
        print(f"pyspline: error: cannot write {dest}: {exc.strerror or exc}", file=sys.stderr)
        return 2
    print(f"wrote {dest}")
    return 0


def _assignments(items, what) -> dict:
    out = {}
    for item in items or ():
        if "=" not in item:
            raise CaseError(f"{what} {item!r}: expected FIELD=VALUES")
        k, v = item.split("=", 1)
        k = k.strip().lower()
        if k in out:
            raise CaseError(f"{what}: field {k} given twice")
        out[k] = v
    return out


def _fixed(items) -> dict:
    """--fix FIELD=VALUE pairs -> {field: typed value}; an array field takes a comma list
    (--fix ripple_amp=0.1,0,0,0; a per-tooth list may be shorter: the first teeth)."""
    from .case import defaults
    out = {}
    for k, v in _assignments(items, "--fix").items():
        vals = parse_values(k, v)
        if isinstance(defaults()[k], list):
            out[k] = vals.tolist()
            continue
        if len(vals) != 1:
            raise CaseError(f"--fix {k}={v}: one value expected ({k} is no array field)")
        out[k] = vals[0].item()
    return out


def _make_executor(args):
    """(executor or None, its number of workers or None, closer) for --workers/--threads/
    --scheduler; a Dask cluster's workers are its threads when the sweep starts."""
    if args.scheduler:
        from distributed import Client
        try:
            client = Client(args.scheduler)
        except (ValueError, OSError) as exc:      # a bad address, or no scheduler there
            raise CaseError(f"--scheduler {args.scheduler}: no Dask scheduler reached: "
                            f"{_one_line(exc)}") from None
        return client.get_executor(), max(1, sum(client.nthreads().values())), client.close
    if args.workers > 1:
        ex = (cf.ThreadPoolExecutor(args.workers) if args.threads
              else cf.ProcessPoolExecutor(args.workers))
        return ex, args.workers, lambda: ex.shutdown(wait=False, cancel_futures=True)
    return None, None, lambda: None


def _command(args) -> str:
    """The command line of a parsed `pyspline sweep`, for attrs['command']."""
    parts = ["pyspline", "sweep", args.case]
    parts += [f"--set={v}" for v in args.set or ()] + [f"--fix={v}" for v in args.fix or ()]
    if args.table:
        parts.append(f"--table={args.table}")
    parts += [f"--section={args.section}", f"--out={args.out}"]
    if args.lyapunov:
        parts.append("--lyapunov")
    if args.follow:
        parts.append(f"--follow={args.follow}")
    if args.scheduler:
        parts.append(f"--scheduler={args.scheduler}")
    elif args.workers > 1:
        parts += [f"--workers={args.workers}"] + (["--threads"] if args.threads else [])
    return " ".join(shlex.quote(a) for a in parts)


def cmd_sweep(args) -> int:
    try:
        grid = {k: parse_values(k, v) for k, v in _assignments(args.set, "--set").items()}
        if args.table:
            if grid:
                raise CaseError("give --table or --set FIELD=VALUES, not both")
            grid = dict(table=args.table)
        elif not 1 <= len(grid) <= 2:
            raise CaseError("give one or two --set FIELD=VALUES to sweep")
        if args.threads and (args.workers < 2 or args.scheduler):
            raise CaseError("--threads: an option of --workers N >= 2 (N threads instead of N "
                            "processes); without it the sweep would run serially")
        case = load_case(args.case, **_fixed(args.fix))
    except SplineError as exc:
        print(f"error: {exc}", file=sys.stderr)
        return exit_code(exc)
    out = Path(args.out)
    executor, workers, close = _make_executor(args)
    try:
        ds = sweep(case, executor=executor, workers=workers, progress=not args.quiet, out=out,
                   section=args.section, lyapunov=args.lyapunov, command=_command(args),
                   follow=args.follow, **grid)
    except SplineError as exc:        # follow= on a grid or a table
        print(f"error: {exc}", file=sys.stderr)
        return exit_code(exc)
    except KeyboardInterrupt:
        print(f"\ninterrupted: the finished points are in {out / POINTS_DIR}/ and merged into "
              f"{out / MERGED}; run the same command again to compute the rest",
              file=sys.stderr)
        return 130
    finally:
        close()
    a = ds.attrs
    print(f"{a['n_points']} points: {a['n_ok']} ran, {a['n_failed']} failed, "
          f"{a['n_missing']} missing; {a['n_computed']} computed now, {a['n_reused']} reused "
          f"from {out / POINTS_DIR}/")
    if "chaotic" in ds and a["n_ok"]:
        n_chaos = int((ds["chaotic"] == 1).sum())
        print(f"{n_chaos} of {a['n_ok']} points chaotic (Lyapunov exponent and the slope of its "
              "log growth positive beyond its spread): read their statistics, sections and "
              "spectra, not their trajectories")
    if "lyapunov" in ds and (n_unsettled := int((ds["period"] == NOT_SETTLED).sum())):
        print(f"{n_unsettled} of {a['n_ok']} points not settled (not periodic, Lyapunov exponent "
              "< 0: the transient has not decayed): lengthen t_transient")
    if a["n_failed"] or a["n_missing"]:
        errors = [e for e in ds["error"].values.ravel() if e]
        print(f"first error: {errors[0]}", file=sys.stderr)
    print(f"wrote {out / MERGED} (xarray.open_dataset(path) or "
          "pyspline.open_sweep)")
    if "point" in ds.dims:    # a design table: no line or grid to draw
        return 1 if a["n_missing"] or a["n_executor_errors"] else 0
    from .plots import sweep_figures
    for path in sweep_figures(ds, out):
        print(f"wrote {path}")
    # failed cases are results; points the executor lost or never ran are not
    return 1 if a["n_missing"] or a["n_executor_errors"] else 0


def cmd_plot(args) -> int:
    """One scene per case; a case that fails prints one line and the next one is drawn. The
    exit status is that of the first failure (`exit_code`), 0 if every case was drawn."""
    from . import analysis, plots
    from .plots import eng
    from .core import STATE_NAMES, simulate
    i_D2 = STATE_NAMES.index("D2")          # its column in section_y; dD2/dt is 7 later
    out = Path(args.out)
    status, drawn = 0, set()
    try:
        fixed = _fixed(args.fix)
    except SplineError as exc:
        print(f"error: {exc}", file=sys.stderr)
        return exit_code(exc)
    for path in args.cases:
        try:
            case = load_case(path, **fixed).replace(section="shaft")
            res = simulate(case)
        except SplineError as exc:
            print(f"error: {exc}", file=sys.stderr)
            status = status or exit_code(exc)
            continue
        spectrum = analysis.amplitude_spectrum(res.t, res.Tm) if len(res.t) >= 4 else None
        sec = None
        if res.section_y is not None and len(res.section_y):
            sec = np.c_[res.section_y[:, i_D2], res.section_y[:, 7 + i_D2]]
        thermal = case["thermal"] != "none"
        stem, k = _safe_stem(case.name), 1      # the case name as a file name; one per case
        while (target := out / (f"{stem}.png" if k == 1 else f"{stem}-{k}.png")) in drawn:
            k += 1
        drawn.add(target)
        plots.scene(res.t, res.D2, res.vD2, res.Tm, res.tooth["F"],
                    Tf=res.tooth["Tf"] if thermal else None, section=sec, spectrum=spectrum,
                    speed_rpm=case["speed_rpm"], z=case["z"], path=target, rtol=case["rtol"],
                    title=f"{case.name}: {res.level}, {eng(case['speed_rpm'])} rpm, "
                          f"T_d = {eng(case['t_d'])} N m, l_x = {eng(case['l_x'])} m, "
                          f"l_y = {eng(case['l_y'])} m; section points once per revolution")
        print(f"wrote {target}")
    return status


SWEEP_HELP = """\
Run CASE over one field (--set FIELD=VALUES) or a grid of two (two --set), each point reduced
to a summary: Poincare section of D2 and dD2/dt, its period, the largest Lyapunov exponent
(--lyapunov), max/min/RMS of T_m, k_v and F_j, max T_f, solver statistics, the error of a
failed point, and for a speed_rpm sweep the spectrum of T_m in shaft orders.

VALUES: start:stop:num (numpy.linspace, both ends included) or a comma list (10,20,30).
--table design.csv instead: one point per row of a CSV of case fields (header: the fields),
dim 'point' with the fields as coordinates (no figures).

Writes into --out DIR:
  DIR/points/<index>.<hash>.npz   one file per finished point, written as it finishes
  DIR/sweep.nc                    all points merged (NetCDF-4; xarray.open_dataset(path)
                                  or pyspline.open_sweep(DIR))
  DIR/bifurcation.png             section D2 against the first field, coloured by period
                                  (two fields: one panel per value of the second, and
                                  DIR/period_map.png, the period over the grid)
  DIR/lyapunov.png                with --lyapunov: the exponent against the first field
                                  (two fields: a map over the grid)
  DIR/waterfall.png               when speed_rpm is swept: spectrum of T_m against speed
                                  (two fields: waterfall_FIELD=VALUE.png for up to 6 values)
Ctrl-C or a crash keeps the finished points (merged into sweep.nc); running the same command
again computes only the points that are missing (a changed case is recomputed: files are
known by index and by a hash of the point's case). With --workers (processes) or --scheduler
(Dask), points travel in tasks of up to 32 (four tasks per worker), written when their task
ends: a Ctrl-C loses at most the tasks running then.

example: pyspline sweep cases/paper_lx1e-4.nml --set l_x=0:3e-4:61 --workers 2 --out out/lx
"""

PLOT_HELP = """\
Run each CASE (with the Poincare section once per shaft revolution) and draw one page per
case into DIR/CASENAME.png: D2(t), T_m(t), the phase plane (D2, dD2/dt) with the exact
section points, the tooth x time map of the tooth loads F_j, the flash temperatures T_f (thermal
cases), and the spectrum of T_m with shaft orders (1x, 2x) and tooth-pass orders (Zx, 2Zx).
CASENAME: the case name as a file name (as run --out's NAME.npz; a second case of the same
name gets CASENAME-2.png).
"""


def _at_least_one(text: str) -> int:
    try:
        n = int(text)
    except ValueError:
        n = 0
    if n < 1:
        raise argparse.ArgumentTypeError(f"must be a whole number >= 1, got {text!r}")
    return n


def _add_sweep_and_plot(sub) -> None:
    """The `sweep` and `plot` subcommands."""
    fmt = argparse.RawDescriptionHelpFormatter
    r = sub.add_parser("sweep", help="sweep one or two case fields: sweep.nc, bifurcation, "
                       "Lyapunov and waterfall figures in --out", description=SWEEP_HELP,
                       formatter_class=fmt)
    r.add_argument("case", metavar="CASE", help="case file (namelist)")
    r.add_argument("--set", action="append", metavar="FIELD=VALUES",
                   help="a swept field: start:stop:num or v1,v2,...; give one or two")
    r.add_argument("--table", metavar="CSV",
                   help="a design table instead of --set: one point per row, fields as columns")
    r.add_argument("--fix", action="append", metavar="FIELD=VALUE",
                   help="change a field of the case for every point (e.g. t_end=0.5)")
    r.add_argument("--out", required=True, metavar="DIR", help="output directory")
    r.add_argument("--section", choices=("shaft", "tooth"), default="shaft",
                   help="Poincare section once per shaft revolution (default) or tooth pass")
    r.add_argument("--lyapunov", action="store_true",
                   help="largest Lyapunov exponent of every point (a second, perturbed "
                        "trajectory: about 4x the run time on paper_lx1e-4)")
    r.add_argument("--workers", type=_at_least_one, default=1, metavar="N",
                   help="N processes (default 1: serial, in this process)")
    r.add_argument("--threads", action="store_true",
                   help="with --workers N: N threads instead of processes")
    r.add_argument("--scheduler", metavar="ADDRESS",
                   help="run on a Dask cluster (distributed scheduler at ADDRESS, e.g. "
                        "tcp://host:8786)")
    r.add_argument("--follow", choices=("up", "down", "both"),
                   help="one field: run the points in order, each from the previous point's "
                        "final state (hysteresis, coexisting attractors); both: a dim "
                        "'direction'. Serial per direction (--workers: one chain each)")
    r.add_argument("--quiet", action="store_true", help="no progress bar")
    r.set_defaults(func=cmd_sweep)
    r = sub.add_parser("plot", help="one page of figures per case: DIR/CASENAME.png",
                       description=PLOT_HELP, formatter_class=fmt)
    r.add_argument("cases", nargs="+", metavar="CASE", help="case file(s)")
    r.add_argument("--out", default=".", metavar="DIR",
                   help="output directory (default: the current one)")
    r.add_argument("--fix", action="append", metavar="FIELD=VALUE",
                   help="change a field of the case (e.g. t_end=0.5)")
    r.set_defaults(func=cmd_plot)
    add_merge(sub)
    from .contcli import add_continue
    add_continue(sub, _fixed, exit_code)


def main(argv=None) -> int:
    from . import __version__
    from ._build_info import BUILD
    p = argparse.ArgumentParser(prog="pyspline", description=__doc__,
                                formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--version", action="version", version=f"pyspline {__version__}, {BUILD} build")
    sub = p.add_subparsers(dest="cmd", required=True)
    r = sub.add_parser("cases", help="list the shipped cases, or copy one to start your own "
                       "(template: every field with its default and unit)")
    r.add_argument("action", choices=["list", "copy"])
    r.add_argument("name", nargs="?", default="template", help="case to copy (default: template)")
    r.add_argument("dest", nargs="?", help="file or directory to write (default: ./NAME.nml)")
    r.add_argument("--force", action="store_true", help="replace an existing file")
    r.set_defaults(func=cmd_cases)
    r = sub.add_parser("run", help="run case files and print a summary of each (loads, rattle, "
                       "heat, limits, standard errors, warnings); with --out, "
                       "the results as DIR/NAME.npz (t, y, Tm and the per-tooth arrays, SI)")
    r.add_argument("cases", nargs="+")
    r.add_argument("--out", help="directory for .npz results (NAME.npz per case; never replaces "
                   "a file pyspline did not write; cases of the same name get NAME-2.npz, ...)")
    r.add_argument("--fix", action="append", metavar="FIELD=VALUE",
                   help="change a field of every case (e.g. thermal=oneway)")
    r.set_defaults(func=cmd_run)
    r = sub.add_parser("reproduce", help="run the paper's scenarios and write into --out (default "
                       "out/) the figures (fig*.png), verification.md/.csv and summary.json")
    r.add_argument("--out", default="out", help="output directory (default: out); refused if it "
                   "holds files of the same names that reproduce did not write")
    r.add_argument("--quick", action="store_true", help="0.3 s per case (for CI)")
    r.add_argument("--cases", help="case directory (default: ./cases or the installed copies)")
    r.set_defaults(func=cmd_reproduce)
    r = sub.add_parser("calibrate", help="fit k_m and f_m to the paper's values and print them "
                       "with the sensitivities; --write puts them into the paper's case files")
    r.add_argument("--quick", action="store_true")
    r.add_argument("--write", action="store_true", help="write the fitted values into the cases")
    r.add_argument("--cases")
    r.set_defaults(func=cmd_calibrate)
    r = sub.add_parser("check-exe", help="run the paper cases through spline-dyn (in a temporary "
                       "directory) and compare with Python, number for number; prints the result")
    r.add_argument("--full", action="store_true", help="full length (default: 0.3 s)")
    r.add_argument("--cases")
    r.set_defaults(func=cmd_check_exe)
    _add_sweep_and_plot(sub)
    args = p.parse_args(argv)
    with warnings.catch_warnings():
        warnings.showwarning = _show_warning
        try:
            if getattr(args, "out", None) is not None:    # every command that writes
                check_out_dir(args.out)
            return args.func(args)
        except KeyboardInterrupt:
            print("interrupted", file=sys.stderr)
            return 130
        except SplineError as exc:    # a command without its own handling: README's codes
            print(f"error: {_one_line(exc)}", file=sys.stderr)
            return exit_code(exc)


def _show_warning(message, category, filename, lineno, file=None, line=None):
    """A SplineWarning as the README says: one 'warning:' line on stderr; others as usual."""
    if issubclass(category, SplineWarning):
        print(f"warning: {' '.join(str(message).split())}", file=sys.stderr)
    else:
        sys.stderr.write(warnings.formatwarning(message, category, filename, lineno, line))
