"""The test hook :func:`fccqp.iteration.cut_after`: a clock that counts iterations.

``tools/callgrind_ticks.py --cut`` measures the realtime preset's clock cut under
valgrind with it, so a cut run must end as one the wall clock stopped (TIME_LIMIT,
the final step's rules), only a timed run may be cut, and removing the cut must give
back the uncut run. The problem is ``test_time_budget``'s nearly-LP QP that needs 371
iterations unpolished.
"""

from __future__ import annotations

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
