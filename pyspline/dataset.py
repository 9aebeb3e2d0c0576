"""The dataset of a sweep: the per-point summaries gathered into an xarray.Dataset (units and
descriptions in each variable's attrs: from the core's tables for the swept fields, the
statistics, the loads and the summaries of a result quantity), written to NetCDF-4 (engine
netcdf4: netCDF-C, 5-10x faster than h5netcdf at writing and reading these files of many small
variables) atomically, and read back (`open_sweep`); and a continuation's branches as one
(`continuation_dataset`)."""
from __future__ import annotations

import functools
import itertools
import os
from pathlib import Path

import numpy as np

from ._build_info import provenance
from .core import LOAD_QUANTITIES, QUANTITIES, STATE_QUANTITIES, TOOTH_QUANTITIES, _names, cf_units
from .errors import CaseError
from .specials import SPECIAL_TYPES, smooth

__all__ = ["build_dataset", "continuation_dataset", "field_meta", "open_sweep", "write_netcdf"]

ENGINE = "netcdf4"
MERGED = "sweep.nc"     #: the merged sweep in a sweep's output directory


# --------------------------------------------------------------------------- field metadata

@functools.cache
def field_meta() -> dict:
    """{field: (long_name, units)} from the core's field table (fortran/input/case_type.f90, through
    api_names('fields')): e.g. 'l_x' -> ('parallel misalignment of spline 1 in x', 'm'); a
    ratio's unit is '1'; an option whose description lists its choices is named by its name."""
    return {n: (n if "|" in d else d or n, cf_units(u)) for n, u, d in _names("fields")}


def _field_attrs(name: str) -> dict:
    long, units = field_meta().get(name, (name, ""))
    return {"long_name": long, "units": units} if units else {"long_name": long}


# --------------------------------------------------------------------------- dataset

_VAR_ATTRS = {
    "section_t": ("time of the Poincare section point", "s"),
    "period": ("period of the section sequence (0: not periodic; -1: not settled, the Lyapunov "
               "exponent < 0: lengthen t_transient; NaN: no result)", ""),
    "period_residual": ("largest relative mismatch of the section at the period found (at the "
                        "best period tested if none)", ""),
    "lyapunov": ("largest Lyapunov exponent", "1/s"),
    "lyapunov_spread": ("spread (max - min) of the running Lyapunov estimate over the last "
                        "third of the window", "1/s"),
    "lyapunov_rel_spread": ("lyapunov_spread / |lyapunov| (small: converged)", ""),
    "lyapunov_slope": ("slope of the log growth over the last two thirds of the window", "1/s"),
    "predictability_horizon": ("predictability horizon 1/lambda (inf: lambda <= 0)", "s"),
    "chaotic": ("1: the exponent and the slope of the log growth are positive beyond the "
                "exponent's spread (chaos: read statistics, not trajectories); 0: not; NaN: no "
                "estimate", ""),
    "Tm_spectrum": ("amplitude spectrum of T_m (Hann window, mean removed; max over each order "
                    "bin)", cf_units(QUANTITIES["Tm"][1])),
    "wall_s": ("wall time of the run (Python call)", "s"),
    "error": ("error message of the point ('' if it ran)", ""),
    "error_class": ("exception class of the point's error ('' if it ran)", ""),
    "warnings": ("the point's warnings, one per line, the core's words ('' if none)", ""),
    "point_hash": ("hash of the point's case text and summary options (point file name)", ""),
}


#: Summaries of a result quantity of the core's table: name -> (what, quantity); their unit is
#: the quantity's, their long_name what of its description.
_OF_QUANTITY = {f"{q}_{w}": (w, q) for q in ("Tm", "kv", "F") for w in ("max", "min", "rms")}
_OF_QUANTITY.update(Tf_max=("max", "Tf"), D2_max=("max", "D2"), D2_min=("min", "D2"),
                    D2_rms=("rms", "D2"),
                    section_D2=("section", "D2"), section_vD2=("section", "vD2"))
_WHAT = {"max": "max of the {}", "min": "min of the {}", "rms": "RMS of the {}",
         "section": "{} on the Poincare section"}


#: the text variables of a sweep point
_TEXT = ("error", "error_class", "warnings")


def _stat_attrs(name: str) -> tuple:
    """(long_name, units) of a sweep variable: the sweep's own (_VAR_ATTRS), a summary of a
    result quantity or a run statistic (the core's tables), else (name, '')."""
    if name in _VAR_ATTRS:
        return _VAR_ATTRS[name]
    if name in _OF_QUANTITY:
        what, q = _OF_QUANTITY[name]
        long, unit = QUANTITIES[q]
        if q in TOOTH_QUANTITIES and what != "section":
            long += " over all teeth"
        return _WHAT[what].format(long), cf_units(unit)
    if name in LOAD_QUANTITIES:
        long, unit = LOAD_QUANTITIES[name]
        return long, cf_units(unit)
    stats = {n: (d, cf_units(u)) for n, u, d in _names("stats")}
    return stats.get(name, (name, ""))


def build_dataset(grid: dict, keys: list, summaries: dict, hashes: dict, options: dict,
                  attrs: dict, point_fields: dict | None = None):
    """The Dataset of a sweep over `grid` ({field: values}): `keys` are the keys every summary
    has, `summaries` and `hashes` are by grid index (a point without a summary is marked
    NotComputed), `options` the summary options, `attrs` the Dataset's attrs (the counts
    n_points, n_ok, n_failed, n_missing are added). A design table: grid {'point': row
    numbers} and point_fields {field: values per point}, coordinates along 'point'."""
    import xarray as xr

    names = list(grid)
    shape = tuple(len(grid[n]) for n in names)
    ragged = [k for k in keys if k.startswith("section_")]
    n_sec = max([len(np.atleast_1d(s[k])) for s in summaries.values() for k in ragged] or [0])
    data = {}
    for k in keys:
        if k in _TEXT:
            data[k] = np.full(shape, "", dtype=object)
        elif k in ragged:
            data[k] = np.full(shape + (n_sec,), np.nan)
        elif k == "Tm_spectrum":
            data[k] = np.full(shape + (len(options["orders"]),), np.nan)
        else:
            data[k] = np.full(shape, np.nan)
    data["point_hash"] = np.full(shape, "", dtype=object)
    for index in itertools.product(*(range(n) for n in shape)):
        data["point_hash"][index] = hashes.get(index, "")
        s = summaries.get(index)
        if s is None:
            data["error"][index] = "not computed (the sweep stopped before this point)"
            data["error_class"][index] = "NotComputed"
            continue
        for k in keys:
            v = s[k]
            if k in ragged:
                v = np.atleast_1d(np.asarray(v, dtype=float))
                data[k][index + (slice(0, len(v)),)] = v
            elif k in _TEXT:
                data[k][index] = str(v)
            else:
                data[k][index] = v
    variables = {}
    for k, v in data.items():
        dims = tuple(names)
        if k in ragged:
            dims += ("section_point",)
        elif k == "Tm_spectrum":
            dims += ("order",)
        if v.dtype == object:
            v = v.astype(str)
        long, units = _stat_attrs(k)
        a = {"long_name": long}
        if units:
            a["units"] = units
        variables[k] = (dims, v, a)
    coords = {n: (n, np.asarray(grid[n]), _field_attrs(n)) for n in names}
    if point_fields is not None:
        coords["point"] = ("point", np.asarray(grid["point"]),
                           {"long_name": "design point (row of the design table)"})
        coords.update({f: ("point", np.asarray(v), _field_attrs(f))
                       for f, v in point_fields.items()})
    if options.get("orders") is not None:
        coords["order"] = ("order", np.asarray(options["orders"], dtype=float),
                           {"long_name": "shaft order (frequency / shaft rotation frequency)",
                            "units": "1"})
    ds = xr.Dataset(variables, coords=coords, attrs=attrs)
    failed = (ds["error"] != "").values
    ds.attrs.update(n_points=int(np.prod(shape)), n_ok=int((~failed).sum()),
                    n_failed=int((failed & (ds["error_class"] != "NotComputed").values).sum()),
                    n_missing=int((ds["error_class"] == "NotComputed").values.sum()))
    return ds


def write_netcdf(ds, path) -> Path:
    """Write a dataset to NetCDF-4 (engine netcdf4, float arrays compressed) through a
    temporary file and os.replace, so a reader never sees half a file."""
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    tmp = path.with_name(f".{path.name}.{os.getpid()}.tmp")
    enc = {k: {"zlib": True, "complevel": 4} for k, v in ds.data_vars.items()
           if v.dtype.kind == "f" and v.size > 1}
    try:
        ds.to_netcdf(tmp, engine=ENGINE, encoding=enc)
        os.replace(tmp, path)
    finally:
        if tmp.exists():
            tmp.unlink()
    return path


#: what every sweep dataset has (build_dataset), and a continuation's does not
_SWEEP_MARKS = ("error", "error_class", "point_hash")


def open_sweep(path):
    """Read a sweep written by `sweep` or `merge` (DIR/sweep.nc or DIR) fully into memory.
    A path that is no such file (missing, unreadable, damaged, another netCDF such as a
    continuation.nc) is a CaseError naming it."""
    import xarray as xr
    path = Path(path)
    if path.is_dir():
        path = path / MERGED
    if not path.is_file():
        raise CaseError(f"open_sweep: {path} is no file" + (" (no sweep.nc in the directory)"
                                                            if path.name == MERGED else ""))
    try:
        with xr.open_dataset(path, engine=ENGINE) as ds:
            ds = ds.load()
    except Exception as exc:     # netCDF4, xarray: whatever the damage, name the file
        raise CaseError(f"open_sweep: {path} cannot be read as a sweep (NetCDF-4): "
                        f"{type(exc).__name__}: {exc}") from None
    missing = [k for k in _SWEEP_MARKS if k not in ds]
    if missing or "swept" not in ds.attrs:
        raise CaseError(f"open_sweep: {path} is no sweep of pyspline (no "
                        f"{', '.join(missing) or 'attribute swept'}; a continuation is read "
                        "with xarray.open_dataset)")
    return ds


_POINT_VARS = {"Tm_pp": ("T_m peak-to-peak over the period", "N m"),
               "F_max": ("largest tooth load over the period", "N"),
               "D2_pp": ("D2 peak-to-peak over the period", "m"),
               "closest_approach": ("closest approach to a contact boundary: smallest |dn_j| - "
                                    "c_j of the teeth whose contact does not change", "m"),
               "switches": ("contact changes of all teeth over the period", "1"),
               "residual": ("corrector residual max |P^n(y) - y| (scaled, Eq. 25)", "1"),
               "iterations": ("corrector iterations", "1")}


def continuation_dataset(case, prob, label, branches, found, margin, k, attrs):
    """A continuation's branches and special points as an xarray.Dataset (docs/continuation.md;
    prob: arclength's problem, whose field `prob.name` is continued)."""
    import xarray as xr
    pts = [(ib, p) for ib, b in enumerate(branches) for p in b]
    npt, nsp = len(pts), len(found)
    mu = np.full((npt, k), np.nan, complex)
    for i, (_, p) in enumerate(pts):
        mu[i, :len(p["mu"])] = p["mu"]
    fa = _field_attrs(prob.name)
    state = [str(s) for s in STATE_QUANTITIES]

    def col(key, rows):
        return np.array([r["contact"][key] if key in ("closest_approach", "switches")
                         else r[key] for r in rows], dtype=float)
    rows = [p for _, p in pts]
    data = {label: (("point",), col("p", rows), fa),
            "branch": (("point",), np.array([ib for ib, _ in pts], int),
                       {"long_name": "branch number (0: from start; later: doubled branches)"}),
            "n": (("point",), np.array([p["n"] for p in rows], int),
                  {"long_name": "shaft revolutions of the orbit's period"}),
            "y0": (("point", "state"), np.array([p["y"] for p in rows]).reshape(npt, 14),
                   {"long_name": "section state at t0 (SI: m, rad; m/s, rad/s)"}),
            "mu_real": (("point", "multiplier"), mu.real, {"long_name": "Floquet multiplier, real part"}),
            "mu_imag": (("point", "multiplier"), mu.imag, {"long_name": "Floquet multiplier, imaginary part"}),
            "mu_abs": (("point", "multiplier"), np.abs(mu), {"long_name": "Floquet multiplier, modulus"}),
            "stable": (("point",), np.array([bool(np.all(np.abs(p["mu"]) < 1 - margin))
                                            for p in rows], np.int8),
                       {"long_name": f"1: every |mu| < 1 - {margin:g}"})}
    for key, (long, unit) in _POINT_VARS.items():
        data[key] = (("point",), col(key, rows), {"long_name": long, "units": unit})
    crit = np.array([s["critical"] for s in found], complex).reshape(nsp)
    data.update({
        "special_type": (("special",), np.array([s["type"] for s in found], dtype=object
                                                ).astype(str) if nsp else np.zeros(0, "<U1"),
                         {"long_name": "special point: " + "; ".join(
                             f"{t}: {d}" for t, d in SPECIAL_TYPES.items())}),
        f"special_{label}": (("special",), col("p", found), fa),
        "special_branch": (("special",), np.array([s["branch"] for s in found], int)),
        "special_n": (("special",), np.array([s["n"] for s in found], int)),
        "special_mu_real": (("special",), crit.real, {"long_name": "critical multiplier, real part"}),
        "special_mu_imag": (("special",), crit.imag, {"long_name": "critical multiplier, imaginary part"}),
        "special_smooth": (("special",), np.array([smooth(s) for s in found], np.int8),
                           {"long_name": "1: the critical multiplier is at +1, -1 or on the unit "
                                         "circle (within 0.01); 0: it jumped across (a "
                                         "non-smooth bifurcation, e.g. at a grazing)"}),
        "special_y0": (("special", "state"), np.array([s["y"] for s in found]).reshape(nsp, 14),
                       {"long_name": "section state at t0 (SI)"}),
    })
    for key in ("Tm_pp", "F_max", "D2_pp", "closest_approach"):
        long, unit = _POINT_VARS[key]
        data[f"special_{key}"] = (("special",), np.array([s[key] for s in found], float),
                                  {"long_name": long, "units": unit})
    ds = xr.Dataset(data, coords={"state": state})
    ds.attrs.update(case=case.text(), field=label, field_name=prob.name,
                    **provenance(), n_points=npt, n_special=nsp,
                    n_branches=len(branches), **attrs)
    return ds
