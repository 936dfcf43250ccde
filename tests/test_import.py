"""``import fccqp`` stays cheap: the compiled core (and scipy's LAPACK) load on first use."""

import subprocess
import sys


def test_import_does_not_load_the_compiled_core():
    code = "import sys, fccqp; print('fccqp.admm' in sys.modules, 'scipy.linalg' in sys.modules)"
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    assert out.stdout.split() == ["False", "False"]


def test_solver_loads_on_first_access():
    code = "import sys, fccqp; fccqp.Solver; print('fccqp.admm' in sys.modules)"
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    assert out.stdout.strip() == "True"


def test_first_solve_does_not_import_scipy_linalg_and_it_still_imports_after():
    code = (
        "import sys, numpy as np, fccqp; fccqp.solve(np.eye(2), np.ones(2));"
        "print('scipy.linalg' in sys.modules);"
        "import scipy.linalg;"
        "print(scipy.linalg.cython_lapack is sys.modules['scipy.linalg.cython_lapack'])"
    )
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    assert out.stdout.split() == ["False", "True"]
