"""Case input: the fields of a case (namelist group ``&spline_case``), read from files with
f90nml or given as a dict, and handed to the core in memory as namelist text.

The defaults live in the Fortran core only (``case_t`` in fortran/case.f90): Python reads them
from the core once, so a field that Python knows is a field the executable knows, with the same
default. Ranges are checked by the core (the same check for Python and the executable).
"""
from __future__ import annotations

import functools
import math
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

from .errors import CaseError

GROUP = "spline_case"
NAME_BYTES = 128   #: longest case name (UTF-8 bytes; fortran/case.f90 namelen)


@functools.cache
def defaults() -> dict:
    """Every case field with its default, as the Fortran core defines them."""
    text = _core.spline_api.api_defaults().decode()
    nml = f90nml.reads(text)
    return {k.lower(): _clean(v) for k, v in nml[GROUP].items()}


def _clean(v):
    return v.strip() if isinstance(v, str) else v


def _fortran(v) -> str:
    """A field value as namelist text (floats by repr: shortest, exact round trip)."""
    if isinstance(v, bool):
        return ".true." if v else ".false."
    if isinstance(v, (list, tuple)):
        return ", ".join(_fortran(x) for x in v)
    if isinstance(v, str):
        return "'" + v.replace("'", "''") + "'"
    return repr(v)


class Case(Mapping):
    """A validated set of case fields (SI units). Immutable; ``replace`` makes variants.
    ``case.model`` is the case loaded into the core (built once, on first use)."""

    def __init__(self, fields: Mapping, name: str | None = None, source: str | None = None):
        base = defaults()
        merged = dict(base)
        label = name or fields.get("name") or "unnamed"
        for key, value in fields.items():
            k = key.lower()
            if k not in base:
                raise CaseError(f"case {label}: unknown field '{key}' (see cases/template.nml or "
                                f"pyspline.defaults() for the fields)")
            merged[k] = _coerce(label, k, value, base[k])
        if name is not None and "name" not in {k.lower() for k in fields}:
            merged["name"] = name
        if len(merged["name"].encode()) > NAME_BYTES:
            raise CaseError(f"case {merged['name'][:40]}...: field name is longer than "
                            f"{NAME_BYTES} bytes (UTF-8)")
        self._fields = merged
        self.source = source
        self._model = None

    # Mapping protocol
    def __getitem__(self, key):
        return self._fields[key.lower()]

    def __iter__(self):
        return iter(self._fields)

    def __len__(self):
        return len(self._fields)

    def __getstate__(self):          # a loaded model is rebuilt where the case is used
        return {"_fields": self._fields, "source": self.source, "_model": None}

    @property
    def name(self) -> str:
        return self._fields["name"]

    @property
    def model(self):
        """The case loaded into the core (pyspline.Model), built on first use and kept."""
        if self._model is None:
            from .core import Model
            self._model = Model(self)
        return self._model

    def replace(self, **changes) -> "Case":
        """A copy with some fields changed, e.g. ``case.replace(l_x=5e-5, name='lx5e-5')``."""
        fields = {**self._fields, **changes}
        return Case(fields, source=self.source)

    def changed(self) -> dict:
        """The fields that differ from the defaults (what a case file needs to say)."""
        base = defaults()
        return {k: v for k, v in self._fields.items() if base[k] != v}

    def text(self) -> str:
        """The case as namelist text: the name and the fields that differ from the defaults."""
        body = "\n".join(f"  {k} = {_fortran(v)}" for k, v in
                         {"name": self.name, **self.changed()}.items())
        return f"&{GROUP}\n{body}\n/\n"

    def to_namelist(self, path) -> None:
        """Write the case as a namelist file that spline-dyn reads (like the files in cases/)."""
        Path(path).write_text(self.text(), encoding="utf-8")

    def __repr__(self):
        return f"Case({self.changed()!r})"


def _coerce(label, key, value, default):
    """Check a field's type against its default's (the core validates ranges). numpy scalars
    and arrays count as the Python numbers and lists they hold."""
    def bad(why):
        return CaseError(f"case {label}: field {key} = {value!r} {why}")

    if hasattr(value, "tolist") and not isinstance(value, (str, bytes)):
        value = value.tolist()          # numpy scalar -> int/float/bool, array -> list
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
