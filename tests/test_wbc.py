"""fccqp on whole-body-control QPs built from a real robot model, against Clarabel."""

import numpy as np
import pytest

import fccqp
from verify import Problem, Tolerances, verify_solution

pytest.importorskip("pinocchio")
from benchmarks.testsets import generate_test_set  # noqa: E402

pytestmark = pytest.mark.usefixtures("every_kkt_backend")
"""Every test on every KKT backend (tests/conftest.py)."""


@pytest.fixture(scope="module")
def test_set():
    return generate_test_set("solo12", "mix", 12, seed=3)


def cones_of(qp):
    pairs = zip(qp.cone_starts, qp.mus, strict=True)
    return [fccqp.FrictionCone(int(s), float(mu)) for s, mu in pairs]


def problem_of(qp):
    return Problem.of(qp.P, qp.q, qp.A, qp.b, qp.lb, qp.ub, cones_of(qp))


def test_matches_clarabel_reference(test_set):
    for qp, x_ref in zip(test_set.qps, test_set.x_ref, strict=True):
        result = fccqp.solve(
            qp.P, qp.q, qp.A, qp.b, qp.lb, qp.ub, cones_of(qp),
            eps_abs=1e-9, eps_rel=1e-9, max_iter=20000,
        )
        assert result.status is fccqp.Status.SOLVED
        verify_solution(problem_of(qp), result, Tolerances.of(eps_abs=1e-9, eps_rel=1e-9))
        assert qp.equality_residual(result.x) <= 1e-9
        assert qp.cone_violation(result.x) <= 1e-6
        assert qp.bound_violation(result.x) <= 1e-6
        gap = qp.objective(result.x) - qp.objective(x_ref)
        assert gap <= 1e-7 * (1 + abs(qp.objective(x_ref)))
        u = qp.layout["u"]
        # torques carry a 1e-4 weight: a 1e-9 dual residual still leaves ~1e-2 Nm of play
        assert np.abs(result.x[u] - x_ref[u]).max() <= 0.05


def test_realtime_sequence_keeps_dynamics_exact(test_set):
    solver = fccqp.Solver(fccqp.Settings.realtime())
    for qp in test_set.qps:
        result = solver.solve(qp.P, qp.q, qp.A, qp.b, qp.lb, qp.ub, cones_of(qp))
        verify_solution(problem_of(qp), result, Tolerances.of(fccqp.Settings.realtime()))
        assert qp.equality_residual(result.x) <= 1e-9


def test_default_settings_solve_every_qp(test_set):
    solver = fccqp.Solver()
    for qp in test_set.qps:
        result = solver.solve(qp.P, qp.q, qp.A, qp.b, qp.lb, qp.ub, cones_of(qp))
        assert result.status is fccqp.Status.SOLVED
        verify_solution(problem_of(qp), result)


def test_a_settled_active_set_is_polished_before_admm_converges(test_set):
    """ADMM crawls along the weak torque and force directions after its active set has
    settled; the run polishes that active set at a scheduled check and ends there
    (tuning.EARLY_POLISH_GATE) instead of at ADMM's own convergence, which is where a run
    without polishing stops. The answers are those of the reference."""
    early = plain = 0
    for qp, x_ref in zip(test_set.qps, test_set.x_ref, strict=True):
        args = (qp.P, qp.q, qp.A, qp.b, qp.lb, qp.ub, cones_of(qp))
        result = fccqp.solve(*args)
        early += result.iterations
        plain += fccqp.solve(*args, polish=False).iterations
        assert result.status is fccqp.Status.SOLVED and result.polished
        verify_solution(problem_of(qp), result)
        gap = qp.objective(result.x) - qp.objective(x_ref)
        assert gap <= 1e-7 * (1 + abs(qp.objective(x_ref)))
    assert early <= 0.85 * plain   # 320 against 418 iterations


def test_a_cold_control_tick_polishes_its_active_set_once_it_has_settled(test_set):
    """Under a time limit a cold tick's ADMM iterate points to its final active set well
    before the tolerances pass; the run polishes that set once it has held as long as it
    took to form (tuning.SETTLE_ITERATIONS) and ends there, instead of at the check that
    the tolerances pass, where a run without polishing stops. The answers are exact."""
    timed = fccqp.Settings.realtime(10.0)   # a time limit that never binds here
    early = plain = 0
    for qp in test_set.qps:
        args = (qp.P, qp.q, qp.A, qp.b, qp.lb, qp.ub, cones_of(qp))
        result = fccqp.Solver(timed).solve(*args)
        early += result.iterations
        plain += fccqp.Solver(fccqp.Settings.realtime(10.0, polish=False)).solve(*args).iterations
        assert result.status is fccqp.Status.SOLVED and result.polished
        verify_solution(problem_of(qp), result, Tolerances.of(timed))
        assert qp.equality_residual(result.x) <= 1e-9
    assert early <= 0.8 * plain


def test_a_ticks_own_answer_given_back_as_the_guess_takes_no_iteration(test_set):
    """A control tick's polished answer given back as ``(x0, y0, z0)`` keeps its active
    set for the polish's first guess, as the solver's own warm start does: the same
    answer at 0 iterations. (Polished from nothing held, the guess needed an ADMM
    iteration on a third of solo12's ticks.)"""
    timed = fccqp.Settings.realtime(10.0)   # a time limit that never binds here
    for qp in test_set.qps:
        args = (qp.P, qp.q, qp.A, qp.b, qp.lb, qp.ub, cones_of(qp))
        first = fccqp.Solver(timed).solve(*args)
        again = fccqp.Solver(timed).solve(*args, x0=first.x, y0=first.y, z0=first.z)
        assert first.polished and again.status is fccqp.Status.SOLVED and again.polished
        assert again.iterations == 0
        np.testing.assert_allclose(again.x, first.x, rtol=1e-9, atol=1e-9)


def test_previous_answers_given_as_guesses_run_as_the_warm_start_does(test_set):
    """A controller that passes each tick's previous answer as ``(x0, y0, z0)`` (OSQP's
    ``warm_start(x, y)`` habit) runs the ADMM iterations of the solver's own warm start,
    not the many more of a polish that drops the answer's active set."""
    timed = fccqp.Settings.realtime(10.0)
    own, given = fccqp.Solver(timed), fccqp.Solver(timed)
    own_iterations = given_iterations = 0
    previous = None
    for qp in test_set.qps:
        args = (qp.P, qp.q, qp.A, qp.b, qp.lb, qp.ub, cones_of(qp))
        own_iterations += own.solve(*args).iterations
        guess = {} if previous is None else {"x0": previous.x, "y0": previous.y,
                                             "z0": previous.z}
        previous = given.solve(*args, **guess)
        given_iterations += previous.iterations
        assert previous.status is fccqp.Status.SOLVED
    assert given_iterations <= own_iterations + 5
