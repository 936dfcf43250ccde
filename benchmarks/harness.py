"""Timing loop: walk solver variants along the paths of the views and collect one row
per variant and QP of each path.

A pass is one variant walking one path (:class:`benchmarks.views.Path`) once; passes
never interleave per QP, so caches and warm-start state belong to one solver at a time:

1. every QP a variant will see is prepared (:meth:`~benchmarks.adapters.Adapter.prepare`)
   before timing;
2. warm-up: each variant solves the first few QPs and the first QP of each other
   problem size its paths hold, and is reset, so that first-call costs (loading
   extension modules, caches, a workspace per problem structure) are not timed;
3. ``repeats`` rounds; in each, every variant makes one pass along each of its paths,
   reset where the path says (:mod:`benchmarks.views`), with the garbage collector
   off. Rotating the variants round by round (instead of running each variant's
   passes back to back) spreads the drifts of a shared machine's speed, which last
   minutes, over all variants alike. Objects that exist before the first round are
   frozen out of the garbage collector (``gc.freeze``), so the collection before each
   pass costs little.
   The per-QP time reported is the median over the passes and the solution is the one
   of the first pass: a pass is deterministic, except for variants with a time budget
   (fccqp's realtime presets), whose answers depend on where the clock stops them.
   Each round ends with a pass of the floor of each test set
   (:class:`benchmarks.baseline.KktFloor`: one ``dsytrf`` per QP), timed the same way.
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
from benchmarks.views import Path, contact_changes, runs_every_view, ticks

__all__ = ["WARMUP_QPS", "run_variants"]

WARMUP_QPS = 5
"""QPs solved (and discarded) by each variant before timing, besides the first QP of each
other problem size (:func:`_warmup_indices`)."""


def _one_pass(adapter: Adapter, data: Sequence[object], fresh: np.ndarray) -> list[SolveOutcome]:
    out = []
    for item, reset in zip(data, fresh, strict=True):
        if reset:
            adapter.reset()
        out.append(adapter.solve(item))
    return out


def _warmup_indices(sets: Sequence[TestSet]) -> list[tuple[int, int]]:
    """The QPs of the warm-up, as (set, QP) positions: the first :data:`WARMUP_QPS` of
    the first set, then the first QP of each problem size ``(n, m)`` not met yet, set
    after set. A solver's first call on a new size is a one-time cost of the structure
    (fccqp allocates a workspace per structure and keeps the last few, 1-4 ms on
    talos_reduced), and the sets change size where a contact is made or broken; the
    startup benchmark (:mod:`benchmarks.startup`) times first calls."""
    first = [(0, i) for i in range(min(WARMUP_QPS, len(sets[0].qps)))]
    seen = {qp.P.shape + qp.A.shape for qp in (sets[0].qps[i] for _, i in first)}
    for k, ts in enumerate(sets):
        for i, qp in enumerate(ts.qps):
            size = qp.P.shape + qp.A.shape
            if size not in seen:
                seen.add(size)
                first.append((k, i))
    return first


def _distinct_sets(paths: Sequence[Path]) -> list[TestSet]:
    return list({id(p.test_set): p.test_set for p in paths}.values())


def run_variants(
    adapters: Sequence[Adapter],
    paths: Sequence[Path],
    repeats: int,
    progress: bool = True,
) -> list[dict[str, object]]:
    """Time every adapter along its paths and judge its solutions.

    Parameters
    ----------
    adapters
        Fresh adapters of the variants, with distinct names.
    paths
        The views' paths (:func:`benchmarks.views.timed_paths`); the first is the warm
        path, which every variant walks; the others only variants that
        :func:`~benchmarks.views.runs_every_view`.
    repeats
        Rounds of passes; the time per QP is the median over a variant's passes.
    progress
        Show tqdm bars for the preparation, the warm-up and the timed passes.

    Returns
    -------
    list of dict
        One row per path, variant and QP of the path (paths, then variants, in the given
        order), the columns of ``results.csv``.
    """
    robot = paths[0].test_set.robot
    walks = [[k for k, p in enumerate(paths) if k == 0 or runs_every_view(a.name)]
             for a in adapters]
    sets = _distinct_sets(paths)
    used = {id(ts): sorted({int(i) for p in paths if p.test_set is ts for i in p.indices})
            for ts in sets}
    data: list[dict[tuple[int, int], object]] = []
    for adapter, walk in zip(tqdm(adapters, desc=f"{robot}: preparing inputs", leave=False,
                                  disable=not progress), walks, strict=True):
        mine = {id(paths[k].test_set) for k in walk}
        data.append({(id(ts), i): adapter.prepare(ts.qps[i])
                     for ts in sets if id(ts) in mine for i in used[id(ts)]})
    warm = _warmup_indices(sets)
    bar = tqdm(adapters, desc=f"{robot}: warm-up (first calls, untimed)",
               leave=False, disable=not progress)
    for adapter, prepared in zip(bar, data, strict=True):
        bar.set_postfix_str(adapter.name)
        mine = [(k, i) for k, i in warm if (id(sets[k]), i) in prepared]
        keys = [(k, int(sets[k].sequence[i])) for k, i in mine]
        fresh = np.array([j == 0 or keys[j] != keys[j - 1] for j in range(len(keys))])
        _one_pass(adapter, [prepared[id(sets[k]), i] for k, i in mine], fresh)
    floors = {id(ts): KktFloor([ts.qps[i] for i in used[id(ts)]]) for ts in sets}
    # Freeze what exists now (prepared data, models): the collection before each pass then
    # walks only new objects (without this, 40 % of a run went into gc.collect).
    gc.collect()
    gc.freeze()
    try:
        return _timed_rounds(adapters, walks, data, paths, floors, used, repeats, progress)
    finally:
        gc.unfreeze()


def _timed(run, *args):
    """``run(*args)`` with the garbage collector off (collected just before)."""
    gc.collect()
    gc.disable()
    try:
        return run(*args)
    finally:
        gc.enable()


def _timed_rounds(
    adapters: Sequence[Adapter],
    walks: Sequence[Sequence[int]],
    data: Sequence[dict[tuple[int, int], object]],
    paths: Sequence[Path],
    floors: dict[int, KktFloor],
    used: dict[int, list[int]],
    repeats: int,
    progress: bool,
) -> list[dict[str, object]]:
    """``repeats`` rounds of one pass per adapter and path, then one of each floor; the
    rows of every path, variant and QP."""
    robot = paths[0].test_set.robot
    times = {(a, k): np.zeros((repeats, len(paths[k])))
             for a, walk in enumerate(walks) for k in walk}
    floor_times = {key: np.zeros((repeats, len(ids))) for key, ids in used.items()}
    first: dict[tuple[int, int], list[SolveOutcome]] = {}
    bar = tqdm(total=repeats * sum(len(paths[k]) for walk in walks for k in walk),
               desc=f"{robot}: timing {repeats} passes", leave=False, disable=not progress)
    for r in range(repeats):
        for k, path in enumerate(paths):
            for a, (adapter, prepared) in enumerate(zip(adapters, data, strict=True)):
                if k not in walks[a]:
                    continue
                items = [prepared[id(path.test_set), int(i)] for i in path.indices]
                outcomes = _timed(_one_pass, adapter, items, path.fresh)
                times[a, k][r] = [o.time for o in outcomes]
                first.setdefault((a, k), outcomes)
                bar.update(len(path))
        for key, floor in floors.items():
            floor_times[key][r] = _timed(floor.time_pass)
    bar.close()
    rows = []
    for k, path in enumerate(paths):
        key = id(path.test_set)
        position = {i: j for j, i in enumerate(used[key])}
        kkt = [(float(np.median(floor_times[key][:, position[int(i)]])),
                floors[key].residuals[position[int(i)]]) for i in path.indices]
        for a, adapter in enumerate(adapters):
            if k in walks[a]:
                rows += _rows(adapter.name, path, times[a, k], first[a, k], kkt)
    return rows


def _rows(
    name: str,
    path: Path,
    times: np.ndarray,
    first: Sequence[SolveOutcome],
    kkt: Sequence[tuple[float, float]],
) -> list[dict[str, object]]:
    """One result row per QP of ``path`` for variant ``name``, from its pass times and
    first outcomes."""
    ts = path.test_set
    tick = ticks(ts)
    changed = contact_changes(path)
    rows = []
    for j, (i, o) in enumerate(zip(path.indices, first, strict=True)):
        qp = ts.qps[i]
        m = qp_metrics(qp, o.x, ts.x_ref[i])
        rows.append(
            {
                "robot": ts.robot,
                "scenario": ts.scenario,
                "view": path.view,
                "qp": int(i),
                "sequence": int(ts.sequence[i]),
                "tick": int(tick[i]),
                "n": qp.n,
                "m": qp.A.shape[0],
                "contacts": qp.n_contacts,
                "stance": "+".join(ts.stance[i]),
                "contact_change": bool(changed[j]),
                "solver": name,
                "time": float(np.median(times[:, j])),
                "time_min": float(np.min(times[:, j])),
                "iterations": o.iterations,
                "status": o.status,
                "reported": o.success,
                "success": o.success and m.accurate,
                **asdict(m),
                "dsytrf_time": kkt[j][0],
                "dsytrf_equality_residual": kkt[j][1],
                "u": o.x[qp.layout["u"]],
            }
        )
    return rows
