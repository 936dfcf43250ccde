"""`import fccqp` stays light: the numba kernels load on first use."""

import subprocess
import sys


def test_import_does_not_load_numba():
    code = "import sys, fccqp; print('numba' in sys.modules, 'qpsolvers' in sys.modules)"
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    assert out.stdout.split() == ["False", "False"]


def test_solver_loads_on_first_access():
    code = "import sys, fccqp; fccqp.Solver; print('numba' in sys.modules)"
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    assert out.stdout.strip() == "True"
