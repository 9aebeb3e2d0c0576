"""Exceptions of pyspline, one per error code of the Fortran core (fortran/common/errors.f90)."""
from __future__ import annotations


class SplineError(RuntimeError):
    """Any failure of a pyspline case; the message names the case."""


class CaseError(SplineError, ValueError):
    """A bad case: unknown or ill-typed field, value out of range (the message names the field)."""


class SolverError(SplineError):
    """CVODE (or the static-equilibrium solve) failed; the message names the flag and the time."""


class ThermalInterferenceError(SplineError):
    """Thermal growth closed the backlash of a tooth pair (Eq. 2: c_j <= 0)."""


class SplineWarning(UserWarning):
    """A result that ran but deserves a second look (the message says why)."""


#: the core's error names (api_names('errors')) -> exception class
BY_NAME = {"case": CaseError, "solver": SolverError, "thermal": ThermalInterferenceError,
           "interrupted": KeyboardInterrupt}


def decode(msg) -> str:
    """A message from the core (bytes, possibly cut inside a UTF-8 character) as text, without
    the blank padding of its Fortran buffer (what spline-dyn prints: trim(msg))."""
    if isinstance(msg, bytes):
        msg = msg.decode("utf-8", errors="replace")
    return str(msg).rstrip(" \0").lstrip(" ")
