"""Case input: the fields of a case (namelist group ``&spline_case``), read from files or given
as a dict, and handed to the core in memory as namelist text.

The defaults live in the Fortran core only (``case_t`` in fortran/case.f90): Python reads them
from the core once, so a field that Python knows is a field the executable knows, with the same
default. A case file is read by the core's reader (api_parse, the one spline-dyn uses), so a
bad file gets the same message from both; ranges are checked by the core too. What Python
checks itself: that the path is a regular file (the same words as fortran/case.f90
case_check_file) and the Python types of a dict's values.
"""
from __future__ import annotations

import errno
import functools
import os
import stat
from collections.abc import Mapping
from pathlib import Path

import f90nml
import numpy as np

try:
    from . import _core
except ImportError as exc:  # the source tree shadows the installed package
    raise ImportError(
        f"pyspline's compiled core (_core) is not next to {__file__}: this is the source tree, "
        "not the installed package. Run `bash scripts/setup.sh` (pip install .) and import "
        "pyspline from outside the repository root (or use the `pyspline` command).") from exc

from .errors import CaseError, decode

GROUP = "spline_case"
NAME_BYTES = 128   #: longest case name (UTF-8 bytes; fortran/case.f90 namelen)
MAX_CASE_BYTES = 1048576   #: largest case file (fortran/case.f90 max_case_bytes)


@functools.cache
def defaults() -> dict:
    """Every case field with its default, as the Fortran core defines them."""
    text = _core.spline_api.api_defaults().decode()
    nml = f90nml.reads(text)
    return {k.lower(): _clean(v) for k, v in nml[GROUP].items()}


def _clean(v):
    return v.strip() if isinstance(v, str) else v


def _shown(path: str) -> str:
    """A path as messages show it (fortran/case.f90 shown): the last 237 characters of a long one."""
    return path if len(path) <= 240 else "..." + path[-237:]


def _check_file(path: str) -> None:
    """Refuse, before opening, a path that is not a regular file of at most MAX_CASE_BYTES (a
    FIFO blocks the open, a device never ends): fortran/case.f90 case_check_file, same words."""
    shown = _shown(path)
    try:
        st = os.stat(path)
    except FileNotFoundError:
        if os.path.islink(path):
            raise CaseError(f"case file {shown} does not exist (a dangling symbolic link)") from None
        raise CaseError(f"case file {shown} does not exist") from None
    except OSError as exc:
        why = os.strerror(exc.errno) if exc.errno else str(exc)
        if exc.errno == errno.ELOOP:
            raise CaseError(f"case file {shown}: {why} (a symbolic-link loop)") from None
        raise CaseError(f"case file {shown}: {why}") from None
    except ValueError as exc:          # an embedded NUL character
        raise CaseError(f"case file {shown!r}: {exc}") from None
    mode = st.st_mode
    kinds = [(stat.S_ISDIR, "is a directory, not a case file"),
             (stat.S_ISFIFO, "is a FIFO (named pipe), not a case file"),
             (stat.S_ISCHR, "is a character device, not a case file"),
             (stat.S_ISBLK, "is a block device, not a case file"),
             (stat.S_ISSOCK, "is a socket, not a case file")]
    if not stat.S_ISREG(mode):
        why = next((w for test, w in kinds if test(mode)), "is not a regular file")
        raise CaseError(f"case file {shown} {why}")
    if st.st_size > MAX_CASE_BYTES:
        raise CaseError(f"case file {shown} is {st.st_size} bytes: a case file holds at most "
                        f"{MAX_CASE_BYTES} bytes")


def field_hint(word: str) -> str:
    """The case field nearest to a misspelt name ('' if none is near): the core's suggestion."""
    return _core.spline_api.api_field_hint(str(word).encode("utf-8", "replace")[:64]).decode().strip()


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
        """The case loaded into the core (pyspline.Model), built on first use and kept."""
        if self._model is None:
            from .core import Model
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


def load_case(source, **overrides) -> Case:
    """Read a case: a namelist file path (group &spline_case), a dict of fields, or a Case.
    Keyword overrides replace fields. Any bad input raises CaseError naming the case (for a
    file: the path, line and field, in the words spline-dyn uses)."""
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
    _check_file(path)
    try:
        with open(path, "rb") as f:
            data = f.read(MAX_CASE_BYTES + 1)
    except OSError as exc:
        raise CaseError(f"case file {_shown(path)}: cannot read it: "
                        f"{os.strerror(exc.errno) if exc.errno else exc}") from None
    # the byte values as an array: a NUL byte must reach the reader (bytes would end there)
    codes = np.frombuffer(data, dtype=np.uint8).astype(np.int32)
    canon, ierr, msg = _core.spline_api.api_parse(codes, os.fsencode(path))
    if ierr:
        raise CaseError(decode(msg))
    fields = {k.lower(): _clean(v) for k, v in f90nml.reads(canon.decode("utf-8", "replace"))[GROUP].items()}
    return Case({**fields, **overrides}, source=path)
