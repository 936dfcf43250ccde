"""The speed floor of the report: one LAPACK ``dsytrf`` of each QP's KKT matrix.

Any method that keeps the equalities of a QP exact factors ``[[P + sigma I, A'], [A, 0]]``
at least once, so the time of that factorization is the yardstick every median is
divided by; its solve (``dsytrs``) of the equality-only problem gives the equality
residual an exact-equality solver can reach on the QP ("factorization accuracy").
"""

from __future__ import annotations

import gc
import time

import numpy as np
from scipy.linalg import lapack

from benchmarks.testsets import TestSet
from benchmarks.wbc_qp import WbcQP

__all__ = ["KKT_REGULARIZATION", "baseline", "kkt_factorization_time"]

KKT_REGULARIZATION = 1e-6
"""Diagonal added to ``P`` in the baseline KKT matrix (fccqp's default ``sigma``)."""

_LWORK_PER_ROW = 64
"""dsytrf work size per row (its block size): scipy's default work size is unblocked."""


def kkt_factorization_time(qp: WbcQP, repeats: int) -> tuple[float, float]:
    """Median time of one ``dsytrf`` of ``[[P + 1e-6 I, A'], [A, 0]]`` and its accuracy.

    The second value is ``||A x - b||_inf`` of the equality-constrained minimizer solved
    with that factorization (``dsytrs``), NaN when the factorization fails.
    """
    n, m = qp.n, qp.A.shape[0]
    K = np.zeros((n + m, n + m), order="F")
    K[:n, :n] = qp.P + KKT_REGULARIZATION * np.eye(n)
    K[n:, :n] = qp.A
    K[:n, n:] = qp.A.T
    times = []
    for _ in range(repeats):
        start = time.perf_counter()
        lu, ipiv, info = lapack.dsytrf(K, lower=1, lwork=_LWORK_PER_ROW * (n + m))
        times.append(time.perf_counter() - start)
    if info != 0:
        return float(np.median(times)), float("nan")
    rhs = np.concatenate([-qp.q, qp.b])
    sol, _ = lapack.dsytrs(lu, ipiv, rhs, lower=1)
    return float(np.median(times)), qp.equality_residual(sol[:n])


def baseline(test_set: TestSet, repeats: int) -> list[tuple[float, float]]:
    """Per QP of ``test_set``: median ``dsytrf`` time and its equality residual."""
    gc.collect()
    gc.disable()
    try:
        return [kkt_factorization_time(qp, max(repeats, 3)) for qp in test_set.qps]
    finally:
        gc.enable()
