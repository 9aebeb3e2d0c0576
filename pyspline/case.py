"""Case input: Fortran namelist files (group ``&spline_case``) read with f90nml.

The defaults live in the Fortran core only (``case_defaults`` in fortran/case.f90): Python asks
the core to write them out once and reads them back, so a field that Python knows is a field the
executable knows, with the same default.
"""
from __future__ import annotations

import functools
import math
import os
import tempfile
from collections.abc import Mapping
from pathlib import Path

import f90nml

try:
    from . import _core
except ImportError as exc:  # the source tree shadows the installed package
    raise ImportError(
        f"pyspline's compiled core (_core) is not next to {__file__}: this is the source tree, "
        "not the installed package. Run `bash scripts/setup.sh` (pip install .) and import "
        "pyspline from outside the repository root (or use the `pyspline` command).") from exc

GROUP = "spline_case"


class SplineError(RuntimeError):
    """Any failure of a pyspline case; the message names the case."""


class CaseError(SplineError, ValueError):
    """A bad case: unknown or ill-typed field, value out of range (the message names the field)."""


class SolverError(SplineError):
    """CVODE (or the static-equilibrium solve) failed; the message names the flag and the time."""


class ThermalInterferenceError(SplineError):
    """Thermal growth closed the backlash of a tooth pair (Eq. 2: c_j <= 0)."""


_ERRORS = {1: CaseError, 2: SolverError, 3: ThermalInterferenceError}


def raise_for(ierr: int, errmsg) -> None:
    """Turn the core's (ierr, message) into the matching exception."""
    if ierr != 0:
        msg = errmsg.decode() if isinstance(errmsg, bytes) else str(errmsg)
        raise _ERRORS.get(int(ierr), SplineError)(msg.strip())


@functools.cache
def defaults() -> dict:
    """Every case field with its default, as the Fortran core defines them."""
    with tempfile.TemporaryDirectory() as tmp:
        path = os.path.join(tmp, "defaults.nml")
        ierr, msg = _core.spline_api.api_write_defaults(path)
        raise_for(ierr, msg)
        nml = f90nml.read(path)
    return {k.lower(): _clean(v) for k, v in nml[GROUP].items()}


def _clean(v):
    return v.strip() if isinstance(v, str) else v


class Case(Mapping):
    """A validated set of case fields (SI units). Immutable; ``replace`` makes variants."""

    def __init__(self, fields: Mapping, name: str | None = None, source: str | None = None):
        base = defaults()
        merged = dict(base)
        label = name or fields.get("name") or "unnamed"
        for key, value in fields.items():
            k = key.lower()
            if k not in base:
                raise CaseError(f"case {label}: unknown field '{key}' (see cases/README or "
                                f"pyspline.defaults() for the fields)")
            merged[k] = _coerce(label, k, value, base[k])
        if name is not None and "name" not in {k.lower() for k in fields}:
            merged["name"] = name
        self._fields = merged
        self.source = source

    # Mapping protocol
    def __getitem__(self, key):
        return self._fields[key.lower()]

    def __iter__(self):
        return iter(self._fields)

    def __len__(self):
        return len(self._fields)

    @property
    def name(self) -> str:
        return self._fields["name"]

    def replace(self, **changes) -> "Case":
        """A copy with some fields changed, e.g. ``case.replace(l_x=5e-5, name='lx5e-5')``."""
        fields = {**self._fields, **changes}
        return Case(fields, source=self.source)

    def changed(self) -> dict:
        """The fields that differ from the defaults (what a case file needs to say)."""
        base = defaults()
        return {k: v for k, v in self._fields.items() if base[k] != v}

    def to_namelist(self, path) -> None:
        """Write the case as a namelist file that spline-dyn reads: the name and the fields
        that differ from the defaults, like the files in cases/ (and 6x faster to write)."""
        nml = f90nml.Namelist({GROUP: {"name": self.name, **self.changed()}})
        nml.float_format = ".17g"
        nml.write(str(path), force=True)

    def __repr__(self):
        return f"Case({self.changed()!r})"


def _coerce(label, key, value, default):
    """Check a field's type against its default's (the core validates ranges)."""
    def bad(why):
        return CaseError(f"case {label}: field {key} = {value!r} {why}")

    if isinstance(default, bool):
        if not isinstance(value, bool):
            raise bad("must be .true. or .false.")
        return value
    if isinstance(default, str):
        if not isinstance(value, str):
            raise bad("must be a string")
        return value.strip()
    if isinstance(default, list):
        if not isinstance(value, (list, tuple)) or len(value) != len(default):
            raise bad(f"must be a list of {len(default)} numbers")
        return [_coerce(label, key, v, d) for v, d in zip(value, default)]
    if isinstance(default, int):
        if isinstance(value, bool) or not isinstance(value, int) and not (
                isinstance(value, float) and value.is_integer()):
            raise bad("must be a whole number")
        return int(value)
    if isinstance(value, bool) or not isinstance(value, (int, float)):
        raise bad("must be a number")
    value = float(value)
    if not math.isfinite(value):
        raise bad("is not a finite number")
    return value


def load_case(source, **overrides) -> Case:
    """Read a case: a namelist file path (group &spline_case), a dict of fields, or a Case.
    Keyword overrides replace fields. Unknown fields raise CaseError."""
    if isinstance(source, Case):
        return source.replace(**overrides) if overrides else source
    if isinstance(source, Mapping):
        return Case({**source, **overrides})
    path = Path(source)
    if not path.is_file():
        raise CaseError(f"case file {path} does not exist")
    try:
        nml = f90nml.read(str(path))
    except Exception as exc:  # f90nml raises several types for bad syntax
        raise CaseError(f"case file {path}: cannot read namelist: {exc}") from exc
    groups = [g.lower() for g in nml.keys()]
    if groups != [GROUP]:
        raise CaseError(f"case file {path}: expected one namelist group &{GROUP}, found "
                        f"{', '.join('&' + g for g in groups) or 'none'}")
    fields = {k: _clean(v) for k, v in nml[GROUP].items()}
    return Case({**fields, **overrides}, name=path.stem, source=str(path))
