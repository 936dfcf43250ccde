"""The test hook :func:`fccqp.iteration.cut_after`: a clock that counts iterations.

``tools/callgrind_ticks.py --cut`` measures the realtime preset's clock cut under
valgrind with it, so a cut run must end as one the wall clock stopped (TIME_LIMIT,
the final step's rules), only a timed run may be cut, and removing the cut must give
back the uncut run. The problem is ``test_time_budget``'s nearly-LP QP that needs 371
iterations unpolished.
"""

from __future__ import annotations

import numpy as np
import pytest
from fccqp.iteration import cut_after

import fccqp
from fccqp import Status
from test_time_budget import EPS, flat_qp
from verify import Tolerances, verify_solution


@pytest.fixture
def cut():
    """Set a cut for one test and remove it afterwards, whatever the test does."""
    yield cut_after
    cut_after(-1)


def test_a_cut_timed_run_stops_there_as_the_clock_would(cut):
    problem = flat_qp(4)
    cut(50)
    result = fccqp.solve(*problem, polish=False, time_limit=100.0, **EPS)
    assert result.status is Status.TIME_LIMIT_REACHED
    assert result.iterations == 50


def test_the_cut_spares_the_minimum_iterations_and_untimed_runs(cut):
    problem = flat_qp(4)
    cut(5)
    floor = fccqp.solve(*problem, polish=False, time_limit=100.0, min_iter=30, **EPS)
    assert floor.status is Status.TIME_LIMIT_REACHED and floor.iterations == 30
    untimed = fccqp.solve(*problem, polish=False, **EPS)
    assert untimed.status is Status.SOLVED and untimed.iterations > 300
    verify_solution(problem, untimed, Tolerances.of(**EPS))


def test_removing_the_cut_gives_the_uncut_run(cut):
    problem = flat_qp(4)
    before = fccqp.solve(*problem, polish=False, time_limit=100.0, **EPS)
    cut(50)
    cut(-1)
    after = fccqp.solve(*problem, polish=False, time_limit=100.0, **EPS)
    assert after.status is Status.SOLVED and after.iterations == before.iterations
    assert (after.x == before.x).all()


def boxed_beside_a_large_entry(seed: int) -> tuple[np.ndarray, ...]:
    """``(P, q, A, b, lb, ub)``: 11 entries boxed to +-1 and one to +-1e4 whose optimum
    lies near 5000, two equalities on the small entries. The large entry sets the
    scale of the set residual's relative tolerance, so a small entry 5 % outside its box
    passes the four tolerance tests at a factor far below ``POLISH_GATE`` while it fails
    the scaled guard of 1 % of its box."""
    rng = np.random.default_rng(seed)
    n = 12
    F = rng.standard_normal((n, n))
    P = F @ F.T + 0.01 * np.eye(n)
    q = rng.standard_normal(n) * 5
    q[-1] = -5e3 * P[-1, -1]
    A = rng.standard_normal((2, n))
    A[:, -1] = 0
    b = A @ rng.uniform(-0.5, 0.5, n)
    lb, ub = -np.ones(n), np.ones(n)
    lb[-1], ub[-1] = -1e4, 1e4
    return P, q, A, b, lb, ub


def test_a_clock_stop_near_convergence_is_polished_though_a_box_entry_misses_its_guard(cut):
    """Cut at 60 iterations, the iterate passes its four tolerance tests within
    ``POLISH_GATE`` while a small box entry is more than 1 % of its box outside it: the
    final polish runs (it used to wait for the guard, which only a status needs) and
    its answer is solved."""
    problem = boxed_beside_a_large_entry(0)
    cut(60)
    result = fccqp.Solver(fccqp.Settings.realtime(10.0)).solve(*problem)
    assert result.iterations == 60
    assert result.polished and result.status is Status.SOLVED
    verify_solution(problem, result, Tolerances.of(eps_abs=1e-4, eps_rel=1e-4))
