"""A stalled run under a long time limit gets the certificates and retries of an untimed
one (issue 30): the guard is the time left (``fccqp.tuning.AUXILIARY_TIME``), not having
a limit. Under qpbenchmark's 1000 s on Maros-Meszaros the other KKT form, the larger rho
and the least-distance certificate were off, which untimed had solved four more problems.
"""

from __future__ import annotations

import time

import pytest
from fccqp.tuning import AUXILIARY_TIME

import fccqp
from fccqp import Status, auxiliary
from reference import clarabel_solve
from test_verdicts import capped_friction_cone, solve_verified


@pytest.mark.parametrize("backend", ["auto", "ldl_full", "sparse"])
def test_a_stall_with_time_left_is_certified(backend):
    """Cut at 300 iterations, the capped friction cone stalls; with 100 s of time limit
    the least-distance QP certifies it as without a limit (below ``AUXILIARY_TIME`` the
    run returns MAX_ITER_REACHED, tests/test_verdicts.py)."""
    problem = capped_friction_cone(0.3, 1e-3, 0.3)
    result = solve_verified(problem, kkt_backend=backend, max_iter=300, time_limit=100.0)
    assert result.status is Status.PRIMAL_INFEASIBLE
    assert clarabel_solve(*problem.args()).status == "primal_infeasible"


def test_a_stall_with_time_left_is_solved_again():
    """The fuzzer's ``extreme_data:500215`` stalls for 4000 iterations in both KKT
    forms; with 100 s of time limit the stalled path runs as without a limit (the
    continuation, the other form, a larger rho), and the answer is verified."""
    from fuzzing import Case

    problem = Case.of("extreme_data", 500215).scenario().problem
    result = solve_verified(problem, time_limit=100.0)
    assert result.status is Status.SOLVED
    assert result.iterations > fccqp.Settings().max_iter   # the stall, then the answer


def test_the_retries_stop_at_the_deadline():
    """The auxiliary solves share the run's budget: with the deadline passed, no retry
    runs and the stall stays unanswered."""
    problem = capped_friction_cone(0.3, 1e-3, 0.3)
    settings = fccqp.Settings(max_iter=300, time_limit=AUXILIARY_TIME / 2)
    stalled = fccqp.Solver(settings).solve(*problem.args())
    assert stalled.status is Status.MAX_ITER_REACHED
    again = auxiliary.solved_again(fccqp.Solver, settings, stalled,
                                   problem.args(), True,
                                   deadline=time.perf_counter())
    assert again is None
