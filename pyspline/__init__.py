"""pyspline: nonlinear dynamics of an involute spline coupling with parallel misalignment and
flash temperature (Xue, Shen & Xue 2025). The physics lives in the Fortran core (fortran/);
this package reads cases, runs them and plots them."""
from .batch import merge
from .case import Case, defaults, load_case
from .cluster import local_dask_client
from .core import Model, Result, load, mesh_stiffness, rhs, simulate, start_state, tooth_stiffness
from .dataset import open_sweep
from .errors import CaseError, SolverError, SplineError, SplineWarning, ThermalInterferenceError
from .orbits import Orbit, OrbitError, periodic_orbit
from .arclength import continuation
from .diagram import branches, fold_curve
from .sweeps import sweep

__all__ = ["Case", "CaseError", "Model", "Result", "SolverError", "SplineError", "SplineWarning",
           "ThermalInterferenceError", "defaults", "load", "load_case", "local_dask_client",
           "merge", "mesh_stiffness", "open_sweep", "Orbit", "OrbitError", "periodic_orbit", "continuation", "branches", "fold_curve", "rhs", "simulate", "start_state", "sweep", "tooth_stiffness"]
from importlib.metadata import PackageNotFoundError, version as _version

try:
    __version__ = _version("pyspline")      #: from meson.build's project version
except PackageNotFoundError:                # pragma: no cover - not installed
    __version__ = "unknown"
