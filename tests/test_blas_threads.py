"""The solve-time guard that keeps scipy's OpenBLAS single-threaded (fccqp.blas_threads)."""

import numpy as np
import pytest

import fccqp
from fccqp import blas_threads


@pytest.mark.skipif(blas_threads.GUARD is None, reason="no OpenBLAS thread setter found")
def test_guard_sets_one_thread_and_restores_the_count():
    before = blas_threads.threads()
    assert blas_threads.threads_inside_a_solve() == 1
    fccqp.solve(np.eye(3), np.ones(3), lb=np.zeros(3), ub=np.ones(3))
    assert blas_threads.threads() == before
