"""Timing loop: run solver variants over a test set and collect one row per QP.

Each variant runs on its own, one after another (never interleaved per QP, so caches
and warm-start state belong to one solver at a time):

1. every QP is prepared (:meth:`~benchmarks.solvers.Adapter.prepare`) before timing;
2. warm-up: the variant solves the first few QPs and is reset, so that JIT
   compilation (fccqp's numba kernels) and first-call costs are not timed;
3. ``repeats`` passes over the whole set in controller-loop order, resetting the
   warm start at each sequence boundary; the garbage collector is off during a pass.
   A pass is deterministic, so the per-QP time reported is the median over the passes
   and the solution is the one of the first pass.
"""

from __future__ import annotations

import gc
from collections.abc import Sequence
from dataclasses import asdict

import numpy as np
from tqdm import tqdm

from benchmarks.metrics import qp_metrics
from benchmarks.solvers import Adapter, SolveOutcome, kkt_factorization_time
from benchmarks.testsets import TestSet

__all__ = ["WARMUP_QPS", "baseline", "run_variant"]

WARMUP_QPS = 5
"""QPs solved (and discarded) by each variant before timing."""


def _one_pass(adapter: Adapter, data: Sequence[object], sequence: np.ndarray) -> list[SolveOutcome]:
    adapter.reset()
    out = []
    previous = None
    for item, seq in zip(data, sequence, strict=True):
        if seq != previous:
            adapter.reset()
            previous = seq
        out.append(adapter.solve(item))
    return out


def baseline(test_set: TestSet, repeats: int) -> list[tuple[float, float]]:
    """Per QP: median ``dsytrf`` time of the KKT matrix and its equality residual."""
    gc.collect()
    gc.disable()
    try:
        return [kkt_factorization_time(qp, max(repeats, 3)) for qp in test_set.qps]
    finally:
        gc.enable()


def run_variant(
    adapter: Adapter,
    test_set: TestSet,
    repeats: int,
    kkt: Sequence[tuple[float, float]],
    progress: bool = True,
) -> list[dict[str, object]]:
    """Time ``adapter`` on every QP of ``test_set`` and judge its solutions.

    Parameters
    ----------
    adapter
        A fresh adapter of the variant.
    test_set
        The QPs, with reference solutions and sequence indices.
    repeats
        Passes over the set; the time per QP is the median over passes.
    kkt
        Output of :func:`baseline` for the set, copied into each row.
    progress
        Show a tqdm bar.

    Returns
    -------
    list of dict
        One row per QP, the columns of ``results.csv``.
    """
    data = [adapter.prepare(qp) for qp in test_set.qps]
    warm = min(WARMUP_QPS, len(data))
    _one_pass(adapter, data[:warm], test_set.sequence[:warm])
    times = np.zeros((repeats, len(data)))
    first: list[SolveOutcome] = []
    bar = tqdm(
        total=repeats * len(data), desc=f"{test_set.robot} {adapter.name}", leave=False,
        disable=not progress,
    )
    for r in range(repeats):
        gc.collect()
        gc.disable()
        try:
            outcomes = _one_pass(adapter, data, test_set.sequence)
        finally:
            gc.enable()
        times[r] = [o.time for o in outcomes]
        first = first or outcomes
        bar.update(len(data))
    bar.close()
    rows = []
    for i, (qp, x_ref, o) in enumerate(zip(test_set.qps, test_set.x_ref, first, strict=True)):
        m = qp_metrics(qp, o.x, x_ref)
        rows.append(
            {
                "robot": test_set.robot,
                "scenario": test_set.scenario,
                "qp": i,
                "sequence": int(test_set.sequence[i]),
                "n": qp.n,
                "m": qp.A.shape[0],
                "contacts": qp.n_contacts,
                "solver": adapter.name,
                "time": float(np.median(times[:, i])),
                "time_min": float(np.min(times[:, i])),
                "iterations": o.iterations,
                "status": o.status,
                "reported": o.success,
                "success": o.success and m.accurate,
                **asdict(m),
                "dsytrf_time": kkt[i][0],
                "dsytrf_equality_residual": kkt[i][1],
                "u": o.x[qp.layout["u"]],
            }
        )
    return rows
