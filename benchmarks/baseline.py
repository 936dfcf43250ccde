"""The speed floor of the report: one LAPACK ``dsytrf`` of each QP's KKT matrix.

Any method that keeps the equalities of a QP exact factors ``[[P + sigma I, A'], [A, 0]]``
at least once, so the time of that factorization is the yardstick every median is
divided by; its solve (``dsytrs``) of the equality-only problem gives the equality
residual an exact-equality solver can reach on the QP ("factorization accuracy").
"""

from __future__ import annotations

import time
from collections.abc import Sequence

import numpy as np
from scipy.linalg import lapack

from benchmarks.wbc_qp import WbcQP

__all__ = ["KKT_REGULARIZATION", "KktFloor"]

KKT_REGULARIZATION = 1e-6
"""Diagonal added to ``P`` in the baseline KKT matrix (fccqp's default ``sigma``)."""

_LWORK_PER_ROW = 64
"""dsytrf work size per row (its block size): scipy's default work size is unblocked."""

REPEATS_PER_QP = 3
"""Back-to-back ``dsytrf`` of one QP in a pass; the pass keeps their median."""


class KktFloor:
    """The floor of some QPs: each QP's KKT matrix ``[[P + 1e-6 I, A'], [A, 0]]``.

    :meth:`time_pass` factors every matrix once per QP (the median of
    ``REPEATS_PER_QP`` back-to-back ``dsytrf``); the harness runs it in its rotation of
    passes, beside the solvers' passes, so that the machine's speed drifts reach the
    floor as they reach the solvers (timed before them, on its own, the floor of one
    run differed by 1.25x from that of another for the same QPs). ``residuals`` holds,
    per QP, ``||A x - b||_inf`` of the equality-constrained minimizer solved with that
    factorization (``dsytrs``), NaN where the factorization fails.
    """

    def __init__(self, qps: Sequence[WbcQP]) -> None:
        self._systems: list[tuple[np.ndarray, int]] = []
        self.residuals: list[float] = []
        for qp in qps:
            n, m = qp.n, qp.A.shape[0]
            K = np.zeros((n + m, n + m), order="F")
            K[:n, :n] = qp.P + KKT_REGULARIZATION * np.eye(n)
            K[n:, :n] = qp.A
            K[:n, n:] = qp.A.T
            lwork = _LWORK_PER_ROW * (n + m)
            self._systems.append((K, lwork))
            lu, ipiv, info = lapack.dsytrf(K, lower=1, lwork=lwork)
            if info != 0:
                self.residuals.append(float("nan"))
                continue
            sol, _ = lapack.dsytrs(lu, ipiv, np.concatenate([-qp.q, qp.b]), lower=1)
            self.residuals.append(qp.equality_residual(sol[:n]))

    def time_pass(self) -> list[float]:
        """Seconds of one ``dsytrf`` per QP (the median of ``REPEATS_PER_QP``)."""
        times = []
        for K, lwork in self._systems:
            repeats = []
            for _ in range(REPEATS_PER_QP):
                start = time.perf_counter()
                lapack.dsytrf(K, lower=1, lwork=lwork)
                repeats.append(time.perf_counter() - start)
            times.append(float(np.median(repeats)))
        return times
