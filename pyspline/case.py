"""Case input: the fields of a case (namelist group ``&spline_case``), read from files or given
as a dict, and handed to the core in memory as field values; ``Model``, the case loaded into the
core (``Case.model``).

The defaults live in the Fortran core only (``case_t`` in fortran/input/case.f90): Python reads them
from the core once, so a field that Python knows is a field the executable knows, with the same
default. A case file is loaded by the core in one call (api_load_file: the path checked, read
and parsed by the reader spline-dyn uses, then validated and built), so a bad file gets the same
message from both; the fields come back as two flat arrays laid out by the core's field table
(fortran/input/case_values.f90), and go back to the core the same way. What Python checks itself: the
Python types of a dict's values.
"""
from __future__ import annotations

import functools
import os
import re
from collections.abc import Mapping
from pathlib import Path

import numpy as np

from . import bridge
from .errors import CaseError, decode
from .result import _names, _warn, raise_for, run, warning_lines

GROUP = "spline_case"
_CONTROL = re.compile(rb"[\x00-\x1f\x7f]")
NAME_BYTES = 128   #: longest case name (UTF-8 bytes; fortran/input/case.f90 namelen)
#: list fields with one number per tooth (as many as the most teeth): a shorter list gives the
#: first teeth, as in a namelist file
PER_TOOTH = frozenset({"spacing_error"})


@functools.cache
def _layout() -> tuple:
    """The core's field table (api_names('layout')) as (name, kind, offset, size) in the
    order of the value arrays, and the sizes of the real array and the character buffer."""
    rows, nv, nc = [], 0, 0
    for i in range(1, 1000):
        name, layout, _ = (x.decode().strip() for x in bridge.name_entry("layout", i))
        if not name:
            break
        kind, n = layout[0], int(layout[1:] or 1)
        rows.append((name, kind, nc if kind == "c" else nv, n))
        if kind == "c":
            nc += n
        else:
            nv += n
    return tuple(rows), nv, nc


def _fields_of(values: np.ndarray, chars: np.ndarray) -> tuple[dict, bool]:
    """A case's fields (Python types) from the core's value arrays (fortran/input/case_values.f90),
    and whether its strings are the bytes the core holds (not when Python strips a leading
    blank or replaces bytes that are no UTF-8)."""
    rows = _layout()[0]
    v = values.tolist()
    s = chars.astype(np.uint8).tobytes()
    out, exact = {}, True
    for name, kind, i, n in rows:
        if kind == "c":
            raw = s[i:i + n].rstrip(b" ")
            out[name] = text = raw.decode("utf-8", "replace").strip()
            exact = exact and text.encode() == raw
        elif kind == "r":
            out[name] = v[i] if n == 1 else v[i:i + n]
        elif kind == "i":
            out[name] = int(v[i])
        else:
            out[name] = v[i] != 0.0
    return out, exact


def _values_of(fields: Mapping):
    """The value arrays of a case's (checked) fields, or None if one cannot cross as a value
    (an integer beyond 32 bits, a string longer than its field): that case goes as text, for
    the reader's message."""
    rows, nv, nc = _layout()
    v = np.zeros(nv)
    s = bytearray(b" " * nc)
    for name, kind, i, n in rows:
        x = fields[name]
        if kind == "c":
            try:
                b = x.encode("utf-8")
            except UnicodeEncodeError:      # a lone surrogate: the text path says so
                return None
            if len(b) > n:
                return None
            s[i:i + len(b)] = b
        elif kind == "i":
            if not -2147483647 <= x <= 2147483647:
                return None
            v[i] = x
        elif n == 1:
            v[i] = x
        else:
            v[i:i + n] = x
    return v, np.frombuffer(bytes(s), dtype=np.uint8).astype(np.int32)


@functools.cache
def defaults() -> dict:
    """Every case field with its default, as the Fortran core defines them."""
    rows, nv, nc = _layout()
    values, chars, ierr, msg = bridge.defaults(nv, nc)
    if ierr:
        raise CaseError(decode(msg))
    return _fields_of(values, chars)[0]


def _shown(path: str) -> str:
    """A path as messages show it (fortran/input/case.f90 shown): the last 237 characters of a long one."""
    return path if len(path) <= 240 else "..." + path[-237:]


def field_hint(word: str) -> str:
    """The case field nearest to a misspelt name ('' if none is near): the core's suggestion."""
    return bridge.field_hint(str(word).encode("utf-8", "replace")[:64]).decode().strip()


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
    """A set of case fields (SI units), their Python types checked. Immutable; ``replace``
    makes variants. ``case.model`` is the case loaded into the core (validated and built once:
    by load_case for a file, else on first use)."""

    def __init__(self, fields: Mapping, name: str | None = None, source: str | None = None):
        label = name or fields.get("name") or "unnamed"
        self._fields = dict(defaults())
        self.source = source
        self._model = None
        self._update(fields, label if isinstance(label, str) else repr(label)[:40])
        if name is not None and "name" not in {k.lower() for k in fields}:
            self._fields["name"] = name
            self._check_name()

    def _update(self, fields: Mapping, label: str) -> None:
        """Check and set `fields` (the others were checked when they were set)."""
        base = defaults()
        for key, value in fields.items():
            if not isinstance(key, str):
                raise CaseError(f"case {label}: a field name must be a string, not {key!r:.40}")
            k = key.lower()
            if k not in base:
                hint = field_hint(k)
                raise CaseError(f"case {label}: unknown field '{key}'"
                                + (f": did you mean {hint}?" if hint else
                                   " (see cases/template.nml or pyspline.defaults() for the fields)"))
            self._fields[k] = _coerce(label, k, value, base[k])
        self._check_name()

    def _check_name(self) -> None:
        if len(self._fields["name"].encode()) > NAME_BYTES:
            raise CaseError(f"case {self._fields['name'][:40]}...: field name is longer than "
                            f"{NAME_BYTES} bytes (UTF-8)")

    # Mapping protocol
    def __getitem__(self, key):
        return self._fields[key.lower()]

    def __iter__(self):
        return iter(self._fields)

    def __len__(self):
        return len(self._fields)

    def __dask_tokenize__(self):     # Dask hashes task arguments: the text says it all, and
        return ("pyspline.Case", self.text())   # costs 15 us (pickling it twice: 10 times more)

    def __getstate__(self):          # a loaded model is rebuilt where the case is used
        return {"_fields": self._fields, "source": self.source, "_model": None}

    @property
    def name(self) -> str:
        return self._fields["name"]

    @property
    def model(self):
        """The case loaded into the core (pyspline.Model), built on first use and kept (a
        case file's is built by load_case, in the same core call that read the file)."""
        if not hasattr(self._model, "bytes"):    # None, or the parts load_case built
            self._model = Model(self)
        return self._model

    def replace(self, **changes) -> "Case":
        """A copy with some fields changed, e.g. ``case.replace(l_x=5e-5, name='lx5e-5')``."""
        new = Case.__new__(Case)
        new._fields, new.source, new._model = dict(self._fields), self.source, None
        new._update(changes, changes.get("name") if isinstance(changes.get("name"), str)
                    else self.name)
        return new

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
    """Check a field's type against its default's (the core checks sizes and ranges, with the
    same messages as for a file: a whole number beyond 32 bits, NaN, a string longer than its
    field). numpy scalars and arrays count as the Python numbers and lists they hold."""
    def bad(why):
        return CaseError(f"case {label}: field {key} = {value!r:.60} {why}")

    if hasattr(value, "tolist") and not isinstance(value, (str, bytes)):
        try:
            value = value.tolist()      # numpy scalar -> int/float/bool/str, array -> list
        except Exception:               # a foreign object with a tolist of its own
            raise bad("is not a value a case field takes") from None
    if isinstance(default, bool):
        if not isinstance(value, bool):
            raise bad("must be .true. or .false.")
        return value
    if isinstance(default, str):
        if not isinstance(value, str):
            raise bad("must be a string")
        if any(ord(ch) < 32 or ord(ch) == 127 for ch in value):
            raise bad("holds a control character (e.g. a newline)")
        return value.strip()
    if isinstance(default, list):
        if key in PER_TOOTH:            # teeth 1 .. len(value); the others keep their defaults
            if not isinstance(value, (list, tuple)) or not 0 < len(value) <= len(default):
                raise bad(f"must be a list of 1 to {len(default)} numbers (one per tooth)")
            return [_coerce(label, key, v, d) for v, d in zip(value, default)] + default[len(value):]
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
    try:
        return float(value)
    except OverflowError:               # a Python int beyond the largest double
        raise CaseError(f"case {label}: field {key} = {str(value)[:20]}... is beyond the largest "
                        "number (1.8e308)") from None


def case_from_text(text: str, source: str | None = None) -> Case:
    """A case from namelist text held in memory, read by the core's reader (api_read_text) but
    neither validated nor built (``.model`` does both); CaseError with the reader's message."""
    rows, nv, nc = _layout()
    values, chars, ierr, msg = bridge.read_text(text.encode("utf-8"), nv, nc)
    if ierr:
        raise CaseError(decode(msg))
    fields = _fields_of(values, chars)[0]
    return Case(fields, source=source)


def load_case(source, **overrides) -> Case:
    """Read a case: a namelist file path (group &spline_case), a dict of fields, or a Case.
    Keyword overrides replace fields. Any bad input raises CaseError naming the case (for a
    file: the path, line and field, in the words spline-dyn uses). A file is read, validated
    and built by one core call: ``load_case(path).model`` costs nothing more (a case whose
    model cannot be built raises when ``.model`` is used, as a dict's does)."""
    if isinstance(source, Case):
        return source.replace(**overrides) if overrides else source
    if isinstance(source, Mapping):
        return Case({**source, **overrides})
    if not isinstance(source, (str, os.PathLike)):
        raise CaseError(f"a case is a namelist file path, a dict of fields or a Case, not "
                        f"{type(source).__name__}")
    path = os.fspath(source)
    if isinstance(path, bytes):
        path = os.fsdecode(path)
    if "\0" in path:                   # C would see a shorter path
        raise CaseError(f"case file {_shown(path)!r}: embedded null byte")
    rows, nv, nc = _layout()
    model, sizes, values, chars, warn, stage, ierr, msg = bridge.load_file(
        os.fsencode(path), 0 if overrides else 1, bridge.MODEL_BYTES, nv, nc)
    if stage == 0:
        raise CaseError(decode(msg))
    fields, exact = _fields_of(values, chars)
    if overrides:
        return Case({**fields, **overrides}, source=path)
    if _CONTROL.search(chars.astype(np.uint8).tobytes()):   # what Case() refuses that the
        for name, kind, _, _ in rows:                        # reader lets through: a tab in
            if kind == "c":                                  # a string, a control character
                _coerce(fields["name"] or "unnamed", name, fields[name], "")   # in the stem
    case = Case.__new__(Case)
    case._fields, case.source, case._model = fields, path, None
    case._check_name()
    if stage == 2 and exact:   # else .model builds it again from the fields Python holds
        model.flags.writeable = False
        case._model = (model, sizes, warn)
    return case


class Model:
    """A case loaded into the core once (validated, geometry and stiffness derived): use it for
    repeated calls (``simulate``, ``rhs``, ``start_state``). It holds the core's model as bytes
    that the caller owns: it can be copied, pickled to another process and used from many
    threads at once. ``Case.model`` keeps one per case."""

    __slots__ = ("case", "bytes", "z", "n_out", "n_section", "n_lyapunov", "n_slices",
                 "warnings", "__weakref__")

    def __init__(self, case):
        case = load_case(case)
        if isinstance(case._model, tuple):       # built by load_case with the file's fields
            data, sizes, warn = case._model
        else:                                    # one core call: validate and build
            packed = _values_of(case._fields)
            if packed is None:                   # a value only the reader can judge
                data, sizes, warn, ierr, msg = bridge.load_text(case.text().encode("utf-8"),
                                                                bridge.MODEL_BYTES)
            else:
                data, sizes, warn, ierr, msg = bridge.load_fields(*packed, bridge.MODEL_BYTES)
            raise_for(ierr, msg)
            data.flags.writeable = False
        self.case, self.bytes = case, data
        self.z, self.n_out, self.n_section, self.n_lyapunov, self.n_slices = sizes.tolist()
        self.warnings = warning_lines(warn)      # the core's model warnings (plausibility)
        _warn(warn)

    def __getstate__(self):
        return {k: getattr(self, k) for k in self.__slots__ if k != "__weakref__"}

    def __setstate__(self, state):
        for k, v in state.items():
            object.__setattr__(self, k, v)

    def __repr__(self):
        return f"Model({self.case.name!r}, z={self.z}, n_out={self.n_out})"

    def simulate(self) -> "Result":
        return run(self)

    def start_state(self) -> np.ndarray:
        """The start state (SI): the static equilibrium (default) or rest, plus dq0, dv0."""
        y, ierr, msg = bridge.start_state(self.bytes)
        raise_for(ierr, msg)
        return y

    def rhs(self, t: float, y) -> np.ndarray:
        """dy/dt in SI units at (t, y), contact states decided by the state (Eqs. 8-24)."""
        ydot, ierr = bridge.rhs(self.bytes, t, y)
        if ierr:
            raise_for(ierr, f"case {self.case.name}: the right-hand side failed at t = {t} s "
                      "(thermal interference)")
        return ydot

    __call__ = rhs

    def rhs_mesh(self, t: float, y) -> tuple[np.ndarray, dict, float]:
        """rhs plus the mesh at (t, y): (dy/dt, per-tooth dict as Result.tooth but 1-D, T_m)."""
        q = _names("tooth")
        ydot, mesh, tm, ierr, msg = bridge.rhs_mesh(self.bytes, self.z, len(q), t,
                                                    np.asarray(y, dtype=float))
        raise_for(ierr, msg)
        return ydot, {n: mesh[:, i] for i, (n, *_) in enumerate(q)}, float(tm)

    def output_times(self) -> np.ndarray:
        t, ierr, msg = bridge.output_times(self.bytes, self.n_out)
        raise_for(ierr, msg)
        return t

    def info(self) -> dict:
        """Derived quantities (SI): r_b, r_pitch, omega, the Eq. 25 scales l_ref and w_ref,
        c_bulk, kappa, the k_m used, k_m_computed, thermal_level, the c_m used, the tooth
        pair's effective mass m_e, the Eq. 18 terms as a dict 'k_terms' (k_h, k_b1, ..., k_m
        of the geometry), and 'spacing_error', the tooth spacing errors in use e_j [m] of teeth
        1 .. Z, shape (Z,): the case's list plus the seeded ones (docs/model.md section 11)."""
        info, terms, spacing, ierr, msg = bridge.model_info(self.bytes, self.z)
        raise_for(ierr, msg)
        out = {n: float(v) for (n, *_), v in zip(_names("info"), info)}
        out["k_m_computed"] = bool(out["k_m_computed"])
        out["thermal_level"] = int(out["thermal_level"])
        out["k_terms"] = {n: float(v) for (n, *_), v in zip(_names("kterms"), terms)}
        out["spacing_error"] = spacing
        return out
