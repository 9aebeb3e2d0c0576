import os
import shutil
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parent.parent
CASES = ROOT / "cases"
sys.path.insert(0, str(Path(__file__).resolve().parent))   # the oracle


@pytest.fixture(scope="session")
def exe():
    """The spline-dyn executable installed with the package (or SPLINE_DYN)."""
    path = os.environ.get("SPLINE_DYN") or shutil.which("spline-dyn")
    if not path:
        pytest.fail("spline-dyn is not on PATH: pip install . installs it")
    return path


PAPER = dict(k_m=2.3e5, m_1=2.0, m_2=2.0)
