"""Python face of the Fortran core: simulate a case, evaluate the right-hand side.

Nothing here computes physics. Each call writes the case as a namelist file and hands its path
to the f2py-wrapped API (fortran/api.f90), the same reader the executable uses.
"""
from __future__ import annotations

import contextlib
import functools
import os
import tempfile
import time
from dataclasses import dataclass, field

import numpy as np

from . import _core
from .case import Case, load_case, raise_for

_api = _core.spline_api
STATE_NAMES = ("x1", "y1", "x2", "y2", "D1", "D2", "D3")
THERMAL_LEVELS = ("none", "bulk", "oneway", "coupled")   #: stats["thermal_level"] 0..3


def level_name(dof: int, thermal: str) -> str:
    """A model level of the fidelity ladder, e.g. '7-DOF coupled'."""
    return f"{dof}-DOF {thermal}"


@functools.cache
def _names(kind: str, n: int) -> tuple:
    out = []
    for i in range(1, n + 1):
        name, unit = _api.api_names(kind, i)
        out.append((name.decode().strip(), unit.decode().strip()))
    return tuple(out)


@contextlib.contextmanager
def _case_file(case: Case):
    fd, path = tempfile.mkstemp(prefix=f"pyspline-{case.name or 'case'}-", suffix=".nml")
    os.close(fd)
    try:
        case.to_namelist(path)
        yield path
    finally:
        os.unlink(path)


@dataclass
class Result:
    """A simulation in SI units. Per-tooth arrays have shape (nt, Z)."""
    case: Case
    t: np.ndarray            #: output times [s]
    y: np.ndarray            #: states (nt, 14): x1, y1, x2, y2, D1, D2, D3 [m], then their velocities [m/s]
    tooth: dict              #: per-tooth quantities by name: F, Fx, Fy [N], dn, c [m], Tf [degC], rc1, rc2 [m]
    Tm: np.ndarray           #: meshing torque T_m (Eq. 22) [N m]
    stats: dict = field(default_factory=dict)   #: CVODE statistics and run time

    @property
    def level(self) -> str:
        """The model level that ran (differs from the case's under fidelity = 'auto')."""
        return level_name(self.stats["dof"], THERMAL_LEVELS[self.stats["thermal_level"]])

    @property
    def kv(self) -> np.ndarray:
        """Dynamic load coefficient k_v = |T_m| / T_d."""
        return np.abs(self.Tm) / self.case["t_d"]

    def __getattr__(self, name):
        tooth = self.__dict__.get("tooth", {})
        if name in tooth:
            return tooth[name]
        if name in STATE_NAMES:
            return self.y[:, STATE_NAMES.index(name)]
        if name.startswith("v") and name[1:] in STATE_NAMES:
            return self.y[:, 7 + STATE_NAMES.index(name[1:])]
        raise AttributeError(name)


def simulate(case) -> Result:
    """Run one case (a Case, a dict of fields or a namelist path) and return a Result.
    Raises CaseError, SolverError or ThermalInterferenceError with a message naming the case."""
    case = load_case(case)
    with _case_file(case) as path:
        z, nt, nq, ns, ierr, msg = _api.api_sizes(path)
        raise_for(ierr, msg)
        t0 = time.perf_counter()
        t, y, tooth, tm, stats, ierr, msg = _api.api_simulate(path, z, nt, nq, ns)
        wall = time.perf_counter() - t0
        raise_for(ierr, msg)
    qnames = [n for n, _ in _names("tooth", nq)]
    stats = {n: (float(v) if n.endswith(("_s", "_degC")) or n.startswith("fidelity_eps")
                 else int(v)) for (n, _), v in zip(_names("stats", ns), stats)}
    stats["wall_s"] = wall
    return Result(case=case, t=t, y=y, tooth={n: tooth[:, :, i] for i, n in enumerate(qnames)},
                  Tm=tm, stats=stats)


def rhs(case, t: float, y) -> tuple[np.ndarray, dict, float]:
    """The Fortran right-hand side in SI units at (t, y), contact states from the state.
    Returns (dy/dt, per-tooth dict as in Result.tooth but 1-D, T_m). For tests and peers."""
    case = load_case(case)
    with _case_file(case) as path:
        return rhs_at_path(path, case["z"], t, y)


def rhs_at_path(path: str, z: int, t: float, y):
    """rhs() on a namelist file that already exists (no temporary file per call)."""
    nq = len(_names("tooth", 8))
    ydot, mesh, tm, ierr, msg = _api.api_rhs(path, z, nq, t, np.asarray(y, dtype=float))
    raise_for(ierr, msg)
    return ydot, {n: mesh[:, i] for i, (n, _) in enumerate(_names("tooth", nq))}, float(tm)


def start_state(case) -> np.ndarray:
    """The case's start state (SI): the static equilibrium (default) or rest, plus dq0, dv0."""
    case = load_case(case)
    with _case_file(case) as path:
        y, ierr, msg = _api.api_start_state(path)
    raise_for(ierr, msg)
    return y


def mesh_stiffness(case) -> dict:
    """Eq. 18 by the potential energy method at the pitch point: every term [N/m] (k_h; bending,
    shear, axial of the external (1) and internal (2) tooth; k_m), the k_m the case uses
    ('k_m_used') and whether it is the computed one ('computed')."""
    case = load_case(case)
    with _case_file(case) as path:
        terms, k_used, computed, ierr, msg = _api.api_mesh_stiffness(path)
    raise_for(ierr, msg)
    names = ("k_h", "k_b1", "k_s1", "k_a1", "k_b2", "k_s2", "k_a2", "k_m")
    out = dict(zip(names, map(float, terms)))
    out.update(k_m_used=float(k_used), computed=bool(computed))
    return out


def tooth_stiffness(z, module, alpha_deg, b, r_root, r_contact, e_mod=2.1e11, nu=0.3,
                    internal=False, r_tip=0.0, nquad=32) -> dict:
    """Bending, shear and axial-compression stiffness [N/m] of one involute tooth of any gear
    (potential energy method; fortran/stiffness.f90), loaded at radius r_contact."""
    kb, ks, ka, ierr, msg = _api.api_tooth_stiffness(
        int(internal), float(z), module, np.radians(alpha_deg), b, r_root, r_tip, e_mod, nu,
        r_contact, nquad)
    raise_for(ierr, msg)
    return {"k_b": kb, "k_s": ks, "k_a": ka}


def cvode_library() -> str:
    """Path of the CVODE shared library this process runs (Linux: from /proc/self/maps), and
    the SUNDIALS build it belongs to: 'optimised' (built by scripts/setup.sh) or 'debian'."""
    from ._build_info import SUNDIALS_LIBDIR
    with open("/proc/self/maps") as maps:
        paths = {line.split()[-1] for line in maps if "libsundials_cvode.so" in line}
    path = paths.pop() if len(paths) == 1 else ", ".join(sorted(paths)) or "not loaded"
    kind = "optimised" if SUNDIALS_LIBDIR and path.startswith(SUNDIALS_LIBDIR) else "debian"
    return f"{path} ({kind})"


def read_csv(path) -> tuple[list[str], np.ndarray]:
    """Read a spline-dyn CSV: the column names (with units) and the data (nt x columns)."""
    with open(path) as f:
        for line in f:
            if not line.startswith("#"):
                header = line.strip().split(",")
                break
        data = np.loadtxt(f, delimiter=",", ndmin=2)
    return header, data


class FortranRHS:
    """The project's Fortran right-hand side (SI) as a Python callable f(t, y), for solvers
    driven from Python (scipy.integrate.solve_ivp in the benchmarks). One case at a time."""

    def __init__(self, case):
        self.case = load_case(case)
        self._tmp = tempfile.TemporaryDirectory(prefix="pyspline-")
        path = os.path.join(self._tmp.name, "case.nml")
        self.case.to_namelist(path)
        ierr, msg = _api.api_load(path)
        raise_for(ierr, msg)
        self.calls = 0

    def __call__(self, t, y):
        self.calls += 1
        ydot, ierr = _api.api_rhs_loaded(t, y)
        if ierr:
            raise_for(ierr, b"case " + self.case.name.encode() + b": RHS failed (thermal)")
        return ydot
