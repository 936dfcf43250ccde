"""The sparse path as a backend of the compiled core: its workspace holds ``P`` and ``A``
in compressed columns and none of the dense backends' arrays, and factors with
``SPARSE_LDL`` (issue 28, stage 2)."""

from __future__ import annotations

import tracemalloc

import numpy as np

import fccqp
from fccqp import Status, sparse_problem
from problems import large_problem
from verify import verify_solution


def test_large_friction_workspace_allocates_under_50_mb():
    """large_friction (5002 KKT rows): the dense workspace's LDL' matrix, tables and
    polish matrix came to 3.2 GB; the compressed one holds vectors, the patterns and
    the polish's compressed-column arrays (8 MB)."""
    P, q, A, b, lb, ub, cones = large_problem(5000)
    data = sparse_problem.convert(P, q, A, b, lb, ub, cones)
    solver = fccqp.Solver(kkt_backend="sparse")
    tracemalloc.start()
    try:
        workspace = solver._sparse_workspace(data, False)
        _, peak = tracemalloc.get_traced_memory()
    finally:
        tracemalloc.stop()
    assert workspace.compressed
    assert peak < 50e6, peak


def test_large_friction_is_solved_by_the_compiled_core():
    problem = large_problem(5000)
    result = fccqp.solve(*problem)
    assert result.backend == "sparse"
    assert result.status is Status.SOLVED
    verify_solution(problem, result)


def test_a_new_pattern_takes_a_new_workspace_and_the_same_one_is_kept():
    P, q, A, b, lb, ub, cones = large_problem(60)
    solver = fccqp.Solver(kkt_backend="sparse")
    first = solver.solve(P, q, A, b, lb, ub, cones)
    kept = solver._sparse[1]
    again = solver.solve(P, q + 0.01, A, b, lb, ub, cones)
    assert solver._sparse[1] is kept
    P2 = P.tolil()
    P2[0, 5] = P2[5, 0] = 0.01
    other = solver.solve(P2.tocsc(), q, A, b, lb, ub, cones)
    assert solver._sparse[1] is not kept
    for result in (first, again, other):
        assert result.status is Status.SOLVED
    assert np.isfinite(other.obj)
