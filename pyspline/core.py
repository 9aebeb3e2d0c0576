"""Python face of the Fortran core: load a case, simulate it, evaluate its right-hand side.

Nothing here computes physics. A case goes to the core in memory as its field values (laid out
by the core's field table) and comes back as a loaded model: the bytes of its model_t, held by
the caller (``Model``). Every call takes those bytes, so loaded cases never alias, any number can
be used at once, and simulate and start_state release the GIL: a thread pool runs scenes in
parallel. A SIGINT during a run stops it within one right-hand-side call (KeyboardInterrupt).

The layers below this public face: ``Model`` is pyspline.case's (``Case.model``), ``Result`` and
the run itself pyspline.result's; each imports only the ones below it (tests/test_imports.py).
They, this module and orbits.py call the compiled core (pyspline._core) only through
pyspline.bridge.
"""
from __future__ import annotations

import numpy as np

from . import bridge
from .case import Model, load_case
from .result import (FIELDS, LOAD_QUANTITIES, QUANTITIES, STATE_NAMES,  # noqa: F401 -- the
                     STATE_QUANTITIES, THERMAL_LEVELS, TOOTH_LOAD_QUANTITIES,  # public names
                     TOOTH_QUANTITIES, Result, _names, cf_units, level_name, raise_for,
                     run, run_outcome, sundials_said)


def load(case) -> Model:
    """Load a case (a Case, a dict of fields or a namelist path) into the core."""
    return case if isinstance(case, Model) else load_case(case).model


def simulate(case, executor=None) -> Result:
    """Run one case (a Case, a dict of fields, a namelist path or a loaded Model) and return a
    Result. Raises CaseError, SolverError or ThermalInterferenceError with a message naming the
    case; KeyboardInterrupt if SIGINT arrives during the run. Releases the GIL while it runs.
    realisations = K > 1 (docs/accuracy.md): its K copies run on `executor` (a
    concurrent.futures.Executor; None: a thread each, at most os.cpu_count())."""
    return run(load(case), executor)


def rhs(case, t: float, y) -> tuple[np.ndarray, dict, float]:
    """The Fortran right-hand side in SI units at (t, y), contact states from the state.
    Returns (dy/dt, per-tooth dict as in Result.tooth but 1-D, T_m). For tests and peers."""
    return load(case).rhs_mesh(t, y)


def start_state(case) -> np.ndarray:
    """The case's start state (SI): the static equilibrium (default) or rest, plus dq0, dv0."""
    return load(case).start_state()


def mesh_stiffness(case) -> dict:
    """Eq. 18 by the potential energy method at the pitch point: every term [N/m] (k_h; bending,
    shear, axial of the external (1) and internal (2) tooth; k_m), the k_m the case uses
    ('k_m_used') and whether it is the computed one ('computed')."""
    info = load(case).info()
    out = dict(info["k_terms"])
    out.update(k_m_used=info["k_m"], computed=info["k_m_computed"])
    return out


def tooth_stiffness(z, module, alpha_deg, b, r_root, r_contact, e_mod=2.1e11, nu=0.3,
                    internal=False, r_tip=0.0, nquad=32) -> dict:
    """Bending, shear and axial-compression stiffness [N/m] of one involute tooth of any gear
    (potential energy method; fortran/physics/stiffness.f90), loaded at radius r_contact."""
    kb, ks, ka, ierr, msg = bridge.tooth_stiffness(
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

