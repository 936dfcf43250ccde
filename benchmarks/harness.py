"""Timing loop: run solver variants over a test set and collect one row per QP.

A pass is one variant solving the whole set; passes never interleave per QP, so caches
and warm-start state belong to one solver at a time:

1. every QP is prepared (:meth:`~benchmarks.adapters.Adapter.prepare`) before timing;
2. warm-up: each variant solves the first few QPs and the first QP of each other
   problem size in the set, and is reset, so that first-call costs (loading extension
   modules, caches, a workspace per problem structure) are not timed;
3. ``repeats`` rounds; in each, every variant makes one pass over the set in
   controller-loop order, resetting the warm start at each sequence boundary, with
   the garbage collector off. Rotating the variants round by round (instead of
   running each variant's passes back to back) spreads the drifts of a shared
   machine's speed, which last minutes, over all variants alike. Objects that exist
   before the first round are frozen out of the garbage collector (``gc.freeze``), so
   the collection before each pass costs little.
   The per-QP time reported is the median over the passes and the solution is the one
   of the first pass: a pass is deterministic, except for variants with a time budget
   (fccqp's realtime presets), whose answers depend on where the clock stops them.
   Each round ends with a pass of the floor (:class:`benchmarks.baseline.KktFloor`: one
   ``dsytrf`` per QP), timed the same way.
"""

from __future__ import annotations

import gc
from collections.abc import Sequence
from dataclasses import asdict

import numpy as np
from tqdm import tqdm

from benchmarks.adapters import Adapter, SolveOutcome
from benchmarks.baseline import KktFloor
from benchmarks.metrics import qp_metrics
from benchmarks.testsets import TestSet

__all__ = ["WARMUP_QPS", "run_variants"]

WARMUP_QPS = 5
"""QPs solved (and discarded) by each variant before timing, besides the first QP of each
other problem size (:func:`_warmup_indices`)."""


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


def _warmup_indices(test_set: TestSet) -> list[int]:
    """The QPs of the warm-up: the first :data:`WARMUP_QPS`, then the first QP of each
    problem size ``(n, m)`` they do not have. A solver's first call on a new size is a
    one-time cost of the structure (fccqp allocates a workspace per structure and keeps
    the last few, 1-4 ms on talos_reduced), and talos' set changes size once, at the
    start of its last controller sequence; the startup benchmark
    (:mod:`benchmarks.startup`) times first calls."""
    first = list(range(min(WARMUP_QPS, len(test_set.qps))))
    seen = {qp.P.shape + qp.A.shape for qp in (test_set.qps[i] for i in first)}
    for i, qp in enumerate(test_set.qps):
        size = qp.P.shape + qp.A.shape
        if size not in seen:
            seen.add(size)
            first.append(i)
    return first


def run_variants(
    adapters: Sequence[Adapter],
    test_set: TestSet,
    repeats: int,
    floor: KktFloor,
    progress: bool = True,
) -> list[dict[str, object]]:
    """Time every adapter on every QP of ``test_set`` and judge its solutions.

    Parameters
    ----------
    adapters
        Fresh adapters of the variants, with distinct names.
    test_set
        The QPs, with reference solutions and sequence indices.
    repeats
        Rounds of passes; the time per QP is the median over a variant's passes.
    floor
        The set's KKT factorization floor, timed in each round; its median per QP and
        its equality residual go into each row.
    progress
        Show tqdm bars for the preparation, the warm-up and the timed passes.

    Returns
    -------
    list of dict
        One row per variant and QP (variants in the given order), the columns of
        ``results.csv``.
    """
    robot = test_set.robot
    data = [
        [adapter.prepare(qp) for qp in test_set.qps]
        for adapter in tqdm(adapters, desc=f"{robot}: preparing inputs", leave=False,
                            disable=not progress)
    ]
    warm = _warmup_indices(test_set)
    bar = tqdm(adapters, desc=f"{robot}: warm-up (first calls, untimed)",
               leave=False, disable=not progress)
    for adapter, prepared in zip(bar, data, strict=True):
        bar.set_postfix_str(adapter.name)
        _one_pass(adapter, [prepared[i] for i in warm], test_set.sequence[warm])
    # Freeze what exists now (prepared data, models): the collection before each pass then
    # walks only new objects (without this, 40 % of a run went into gc.collect).
    gc.collect()
    gc.freeze()
    try:
        return _timed_rounds(adapters, data, test_set, repeats, floor, progress)
    finally:
        gc.unfreeze()


def _timed_rounds(
    adapters: Sequence[Adapter],
    data: Sequence[Sequence[object]],
    test_set: TestSet,
    repeats: int,
    floor: KktFloor,
    progress: bool,
) -> list[dict[str, object]]:
    """``repeats`` rounds of one pass per adapter and one of the floor, rotating; the
    rows of every QP."""
    robot, n_qps = test_set.robot, len(test_set.qps)
    times = np.zeros((len(adapters), repeats, n_qps))
    floor_times = np.zeros((repeats, n_qps))
    first: list[list[SolveOutcome]] = [[] for _ in adapters]
    bar = tqdm(
        total=repeats * n_qps * len(adapters), desc=f"{robot}: timing {repeats} passes",
        leave=False,
        disable=not progress,
    )
    for r in range(repeats):
        for k, (adapter, prepared) in enumerate(zip(adapters, data, strict=True)):
            gc.collect()
            gc.disable()
            try:
                outcomes = _one_pass(adapter, prepared, test_set.sequence)
            finally:
                gc.enable()
            times[k, r] = [o.time for o in outcomes]
            first[k] = first[k] or outcomes
            bar.update(n_qps)
        gc.collect()
        gc.disable()
        try:
            floor_times[r] = floor.time_pass()
        finally:
            gc.enable()
    bar.close()
    kkt = [(float(np.median(floor_times[:, i])), floor.residuals[i]) for i in range(n_qps)]
    rows = []
    for k, adapter in enumerate(adapters):
        rows += _rows(adapter, test_set, times[k], first[k], kkt)
    return rows


def _rows(
    adapter: Adapter,
    test_set: TestSet,
    times: np.ndarray,
    first: Sequence[SolveOutcome],
    kkt: Sequence[tuple[float, float]],
) -> list[dict[str, object]]:
    """One result row per QP of one variant, from its pass times and first outcomes."""
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
