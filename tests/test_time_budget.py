"""A finite ``time_limit`` is the budget of a long run (issue 30, Maros-Meszaros).

Three mechanisms of :mod:`fccqp.iteration`, each judged by :func:`verify.verify_solution`:
the iteration cap extends while the run converges or is on course to its tolerance
within the time left (``_extend``); the early polish runs
from ``TIMED_EARLY_POLISH`` iterations on; a run stopped at its cap (not by the clock)
is polished whatever its distance to tolerance. The problems are small LP-like QPs
(``P`` of rank 2 and norm ~1e-2, boxes on every entry, four equalities) on which ADMM
crawls at tolerance 1e-7; before these mechanisms a timed run stopped at ``max_iter``
where the same run without a time limit was solved.
"""

from __future__ import annotations

import numpy as np
import pytest
from fccqp.iteration import charge_rho_changes
from fccqp.tuning import AUXILIARY_TIME, TIMED_EARLY_POLISH

import fccqp
from fccqp import Status, auxiliary
from verify import Tolerances, verify_solution

pytestmark = pytest.mark.usefixtures("every_kkt_backend")
"""Every test on every KKT backend (tests/conftest.py)."""

EPS = dict(eps_abs=1e-7, eps_rel=1e-7)


def flat_qp(seed: int) -> tuple[np.ndarray, ...]:
    """``(P, q, A, b, lb, ub)``: 20 boxed entries, 4 consistent equalities, a rank-2
    ``P`` of small norm (nearly an LP)."""
    rng = np.random.default_rng(seed)
    n, m = 20, 4
    F = rng.standard_normal((n, 2))
    P = F @ F.T * 1e-3
    q = rng.standard_normal(n)
    A = rng.standard_normal((m, n))
    b = A @ rng.uniform(-1, 1, n)
    lb = -rng.uniform(1, 2, n)
    ub = rng.uniform(1, 2, n)
    return P, q, A, b, lb, ub


def test_a_converging_run_under_a_time_limit_goes_past_max_iter():
    """Unpolished, this QP needs 371 iterations; with ``max_iter`` 185 a run without a
    time limit stops at the cap (where the stalled path takes over), one with a time
    limit is still halving its distance to tolerance there and goes on to SOLVED."""
    problem = flat_qp(4)
    solver = fccqp.Solver(polish=False, max_iter=185, **EPS)
    solver._stalled_certificates = False
    capped = solver.solve(*problem)
    assert capped.status is Status.MAX_ITER_REACHED and capped.iterations == 185
    timed = fccqp.solve(*problem, polish=False, max_iter=185, time_limit=100.0, **EPS)
    assert timed.status is Status.SOLVED, timed.status
    assert timed.iterations > 185
    verify_solution(problem, timed, Tolerances.of(**EPS))


def test_a_timed_run_on_course_to_its_tolerance_goes_past_a_cap_it_does_not_halve_in():
    """Unpolished with ``max_iter`` 50, this QP's distance to tolerance stops halving in
    every 25 iterations after 125, but it still falls at a rate that reaches the
    tolerance long before a 100 s limit: the cap extends and the run ends SOLVED at the
    371 iterations of an uncapped run (QSCAGR7 of Maros-Meszaros: SOLVED at 76,000
    iterations in 13 s of its 1000, stopped at 8,000 before)."""
    problem = flat_qp(4)
    solver = fccqp.Solver(polish=False, max_iter=50, time_limit=100.0, **EPS)
    solver._stalled_certificates = False
    timed = solver.solve(*problem)
    assert timed.status is Status.SOLVED, timed.status
    assert timed.iterations > 125
    verify_solution(problem, timed, Tolerances.of(**EPS))


def test_a_short_time_limit_keeps_a_cap_the_distance_does_not_halve_in():
    """The same run with less than ``AUXILIARY_TIME`` of limit (a control tick's kind of
    budget) is not judged by its course: it stops where its distance stopped halving,
    unsolved."""
    problem = flat_qp(4)
    solver = fccqp.Solver(polish=False, max_iter=50, time_limit=0.5 * AUXILIARY_TIME, **EPS)
    solver._stalled_certificates = False
    capped = solver.solve(*problem)
    assert capped.status is Status.MAX_ITER_REACHED, capped.status


def test_an_untimed_run_stopped_at_its_cap_goes_on_from_where_it_stopped():
    """The same QP without a time limit and ``max_iter`` 250 (a cap worth halving,
    ``RESTART_MIN_ITER``): the run that stopped there, still halving its distance to
    tolerance, is continued once from its own iterate and rho (a cold retry would stop
    at 250 again), and it ends SOLVED within the continuation's 250 iterations,
    counted."""
    problem = flat_qp(4)
    result = fccqp.solve(*problem, polish=False, max_iter=250, **EPS)
    assert result.status is Status.SOLVED
    assert 250 < result.iterations <= 2 * 250
    verify_solution(problem, result, Tolerances.of(**EPS))


def test_a_stalled_runs_retry_stopped_at_its_cap_goes_on_from_where_it_stopped():
    """The retries of a stalled run (:func:`fccqp.auxiliary.solved_again`: cold, at
    another rho, unequilibrated) are continued as the run itself is (the test above):
    with ``max_iter`` 250 the first retry of this QP stops at its cap still halving its
    distance to tolerance and ends SOLVED within its continuation; without the
    continuation no retry gave an answer."""
    problem = flat_qp(4)
    stopped = fccqp.Solver(polish=False, max_iter=100, **EPS)
    stopped._stalled_certificates = False
    cut = stopped.solve(*problem)
    assert cut.status is Status.MAX_ITER_REACHED
    settings = fccqp.Settings(polish=False, max_iter=250, **EPS)
    again = auxiliary.solved_again(fccqp.Solver, settings, cut, (*problem, ()), False)
    assert again is not None and again.status is Status.SOLVED
    assert 250 < again.iterations <= 2 * 250
    verify_solution(problem, again, Tolerances.of(**EPS))


def test_a_long_timed_run_polishes_early_as_an_untimed_one():
    """ADMM crawls here for thousands of iterations after its active set settled; the
    early polish ends the run at 3060 iterations without a time limit, and now with one
    (it ran into ``max_iter`` before)."""
    problem = flat_qp(83)
    untimed = fccqp.solve(*problem, **EPS)
    timed = fccqp.solve(*problem, time_limit=100.0, **EPS)
    assert untimed.status is Status.SOLVED and untimed.polished
    assert TIMED_EARLY_POLISH <= untimed.iterations < fccqp.Settings().max_iter
    assert timed.status is Status.SOLVED and timed.polished
    assert timed.iterations == untimed.iterations
    verify_solution(problem, timed, Tolerances.of(**EPS))


def test_a_timed_run_stopped_at_its_cap_is_polished_as_an_untimed_one():
    """At ``max_iter`` 1000 this run is not halving its distance any more, so the cap
    holds; its residuals are beyond ``POLISH_GATE`` times the tolerances, which under a
    time limit used to skip the final polish (MAX_ITER_REACHED, unpolished). That gate is
    for runs the clock stops: one stopped by its cap is polished, and here the polish
    is exact, as without a time limit."""
    problem = flat_qp(50)
    untimed = fccqp.solve(*problem, max_iter=1000, **EPS)
    timed = fccqp.solve(*problem, max_iter=1000, time_limit=100.0, **EPS)
    assert untimed.status is Status.SOLVED and untimed.polished
    assert timed.status is Status.SOLVED and timed.polished, timed.status
    assert timed.iterations == 1000
    verify_solution(problem, timed, Tolerances.of(**EPS))


def test_an_extended_cap_polishes_as_an_untimed_run_at_its_cap():
    """Without a time limit this run ends at ``max_iter`` 200, polished and SOLVED; under
    one it was still halving its distance there, so the cap grew and it ran to 800
    iterations (PRIMALC8 of Maros-Meszaros: solved at 4000 untimed, past 90 s timed).
    Each extension now first tries that polish, kept when it solves."""
    problem = flat_qp(2)
    untimed = fccqp.solve(*problem, max_iter=200, **EPS)
    timed = fccqp.solve(*problem, max_iter=200, time_limit=100.0, **EPS)
    assert untimed.status is Status.SOLVED and untimed.polished
    assert untimed.iterations == 200
    assert timed.status is Status.SOLVED and timed.polished, timed.status
    assert timed.iterations == 200
    verify_solution(problem, timed, Tolerances.of(**EPS))


def test_iterations_past_the_time_limit_run_at_the_rho_they_reached():
    """The iterations that ``min_iter`` forces past the time limit change rho no more: a
    change there (a factorization) ends after the run's deadline and only lengthens the
    overrun. They factor as often as a run that never adapts rho; untimed, this QP's
    run changes rho within them."""
    problem = flat_qp(3)
    settings = dict(polish=False, max_iter=200, **EPS)
    fixed = fccqp.solve(*problem, adaptive_rho=False, **settings)
    untimed = fccqp.solve(*problem, **settings)
    assert untimed.factorizations > fixed.factorizations
    late = fccqp.solve(*problem, min_iter=200, time_limit=1e-9, **settings)
    assert late.status is Status.SOLVED
    assert late.factorizations == fixed.factorizations


def test_a_change_of_rho_that_overran_the_time_limit_bars_no_later_change():
    """Each change of rho counted 100 s longer than it took (a preempted factorization,
    ``charge_rho_changes``) past a 10 s limit: rho still changes in the runs' early
    iterations, and the answers, iterations and factorizations are those of uncharged
    runs, in the same run and after a ``reset()``. Counted whole, the first change's
    time barred every later change of the workspace."""
    problem = flat_qp(3)
    settings = dict(polish=False, max_iter=200, time_limit=10.0, **EPS)
    runs = []
    for charge in (0.0, 100.0):
        solver = fccqp.Solver(**settings)
        charge_rho_changes(charge)
        try:
            first = solver.solve(*problem)
            solver.reset()
            runs.append((first, solver.solve(*problem)))
        finally:
            charge_rho_changes(0.0)
    assert runs[0][0].factorizations >= 3   # two changes at least: the second one is barred
    for plain, charged in zip(*runs, strict=True):
        assert charged.status is plain.status is Status.SOLVED
        assert (charged.iterations, charged.factorizations) == (plain.iterations,
                                                                plain.factorizations)
        np.testing.assert_array_equal(charged.x, plain.x)
