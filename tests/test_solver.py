"""The solver against Clarabel, the KKT conditions, and its statuses."""

import math
import os
import subprocess
import sys
import textwrap
import time

import numpy as np
import pytest

import fccqp
from fccqp import FrictionCone, SecondOrderCone, Status
from problems import random_problem
from reference import clarabel_solve
from verify import Problem, Tolerances, verify_solution

pytestmark = pytest.mark.usefixtures("every_kkt_backend")
"""Every test on every KKT backend (tests/conftest.py)."""

TIGHT = dict(eps_abs=1e-8, eps_rel=1e-8, max_iter=20000)
TIGHT_TOLERANCES = Tolerances.of(**TIGHT)


@pytest.mark.parametrize("seed", range(8))
def test_matches_clarabel_on_random_problems(seed):
    problem = random_problem(seed, soc_dim=4 if seed % 2 else 0)
    reference = clarabel_solve(*problem)
    result = fccqp.solve(*problem, **TIGHT)
    assert result.status is Status.SOLVED
    # Clarabel's x can be off by 1e-5 on near-degenerate instances while its
    # objective is not better than ours: compare x loosely, objective and KKT tightly.
    np.testing.assert_allclose(result.x, reference.x, atol=1e-4)
    assert result.obj - reference.obj <= 1e-7 * (1 + abs(reference.obj))
    verify_solution(problem, result, TIGHT_TOLERANCES)


@pytest.mark.parametrize("seed", range(4))
def test_default_settings_reach_tolerance_and_report_true_residuals(seed):
    problem = P, q, A, b, lb, ub, cones = random_problem(
        seed, psd_rank=10, n=40, m=10, n_cones=4, n_box=8
    )
    reference = clarabel_solve(*problem)
    result = fccqp.solve(*problem)
    assert result.status is Status.SOLVED
    # residuals, gap and the claimed prim_res / dual_res, against data-only scales
    verify_solution(problem, result, Tolerances(factor=1.0))
    assert abs(result.obj - reference.obj) <= 1e-3 * (1 + abs(reference.obj))


def test_rank_deficient_equalities():
    problem = random_problem(3, duplicate_rows=3)
    reference = clarabel_solve(*problem)
    result = fccqp.solve(*problem, **TIGHT)
    assert result.status is Status.SOLVED
    np.testing.assert_allclose(result.x, reference.x, atol=1e-5)
    verify_solution(problem, result, TIGHT_TOLERANCES)


def test_nearly_dependent_equalities_stay_exact(kkt_backend):
    P, q, A, b, lb, ub, cones = random_problem(4)
    A = np.vstack([A, A[0] + 1e-9 * np.random.default_rng(0).standard_normal(A.shape[1])])
    result = fccqp.solve(P, q, A, np.append(b, b[0]), lb, ub, cones)
    assert result.status is Status.SOLVED
    verify_solution((P, q, A, np.append(b, b[0]), lb, ub, cones), result)


def test_equalities_exact_at_every_budget():
    problem = random_problem(5, m=12)
    P, q, A, b = problem[:4]
    for budget in (1, 2, 3, 7, 15):
        result = fccqp.solve(*problem, max_iter=budget)
        assert result.iterations == budget
        verify_solution(problem, result)


def test_warm_start_with_changed_b_keeps_equalities_exact():
    P, q, A, b, lb, ub, cones = random_problem(6)
    solver = fccqp.Solver(max_iter=3)
    solver.solve(P, q, A, b, lb, ub, cones)
    b2 = b + 0.5
    result = solver.solve(P, q, A, b2, lb, ub, cones)
    verify_solution((P, q, A, b2, lb, ub, cones), result, Tolerances.of(max_iter=3))


def test_solution_without_active_constraints_takes_one_factorization():
    P, q, A, b, lb, ub, cones = random_problem(7, n_cones=0)
    result = fccqp.solve(P, q, A, b)
    assert result.status is Status.SOLVED
    verify_solution((P, q, A, b), result)
    assert (result.iterations, result.factorizations) == (0, 1)
    assert np.abs(result.z).max() == 0.0


def test_warm_start_cuts_iterations_on_nearby_problems():
    P, q, A, b, lb, ub, cones = random_problem(8, n=40, m=10, n_cones=4, n_box=8)
    rng = np.random.default_rng(1)
    warm, cold = fccqp.Solver(), []
    warm_iterations = []
    for _ in range(10):
        q = q + 0.02 * rng.standard_normal(q.shape)
        warm_iterations.append(warm.solve(P, q, A, b, lb, ub, cones).iterations)
        cold.append(fccqp.solve(P, q, A, b, lb, ub, cones).iterations)
    assert sum(warm_iterations[1:]) < 0.6 * sum(cold[1:])


@pytest.mark.parametrize("factor", [1.02, 1e3])
def test_warm_start_on_changed_matrices_matches_a_cold_solve(factor):
    # a warm start keeps the previous equilibration while the new data's norms stay
    # near what it gave (fccqp.scaling.rescale) and equilibrates anew past that
    P, q, A, b, lb, ub, cones = random_problem(10, n=40, m=10, n_cones=4, n_box=8)
    solver = fccqp.Solver(**TIGHT)
    solver.solve(P, q, A, b, lb, ub, cones)
    scale = np.ones(P.shape[0])
    scale[-10:] = factor   # free entries: their bounds stay as they are
    P2, A2 = scale[:, None] * P * scale[None, :], A * scale[None, :]
    problem = (P2 + P2.T) / 2, q * scale, A2, b, lb, ub, cones
    warm = solver.solve(*problem)
    reference = clarabel_solve(*problem)
    assert warm.status is Status.SOLVED
    assert abs(warm.obj - reference.obj) <= 1e-6 * (1 + abs(reference.obj))
    verify_solution(problem, warm, TIGHT_TOLERANCES)


def test_a_solver_follows_bounds_that_change_structure():
    # the workspace checks each solve's bounds against the structure it was made for
    P, q, A, b, lb, ub, cones = random_problem(11, n=40, m=10, n_cones=4, n_box=8)
    free = np.flatnonzero(~np.isfinite(lb) & ~np.isfinite(ub))
    free = free[free >= 12 + 8]   # after the four cones and the boxes
    boxed = np.flatnonzero(np.isfinite(lb))
    solver = fccqp.Solver(**TIGHT)
    lb2, ub2 = lb.copy(), ub.copy()
    lb2[free[0]], ub2[free[0]] = -0.1, 0.1          # a free entry gets a box
    lb3, ub3 = lb.copy(), ub.copy()
    lb3[boxed[0]] = ub3[boxed[0]] = 0.5 * (lb[boxed[0]] + ub[boxed[0]])   # a box is fixed
    for bounds in ((lb, ub), (lb2, ub2), (lb3, ub3), (lb, ub)):
        problem = P, q, A, b, *bounds, cones
        result = solver.solve(*problem)
        assert result.status is Status.SOLVED
        assert abs(result.obj - clarabel_solve(*problem).obj) <= 1e-6 * (1 + abs(result.obj))
        verify_solution(problem, result, TIGHT_TOLERANCES)
    bad_lb = lb.copy()
    bad_lb[cones[0].start] = -1.0
    with pytest.raises(ValueError, match=rf"x\[{cones[0].start}\] is in a cone block"):
        solver.solve(P, q, A, b, bad_lb, ub, cones)
    again = solver.solve(P, q, A, b, lb, ub, cones)   # the solver is still sound
    assert again.status is Status.SOLVED
    verify_solution((P, q, A, b, lb, ub, cones), again, TIGHT_TOLERANCES)
    # a fixed value beyond INFINITE_BOUND: the workspace reads the structure as the
    # structure scan does (a bound, fixed), so the next solves reuse it
    lb4, ub4 = lb.copy(), ub.copy()
    lb4[free[1]] = ub4[free[1]] = 1e21
    capped = fccqp.Solver(max_iter=30)
    for _ in range(2):
        assert isinstance(capped.solve(P, q, A, b, lb4, ub4, cones).status, Status)


DENSE_PATH_KEEPS = ("auto", "schur_reduced", "ldl_reduced", "ldl_full")
"""The backends whose solver keeps the workspaces of structures it left (the sparse path
keeps one workspace, and a return there allocates a new one and starts cold)."""


def assert_as_solved_again(problem, result):
    """``result`` is SOLVED and, bit for bit, what a solver that just solved ``problem``
    answers on it again: a warm start from the kept workspace's last answer."""
    solver = fccqp.Solver()
    solver.solve(*problem)
    again = solver.solve(*problem)
    assert result.iterations == again.iterations and result.status is Status.SOLVED
    np.testing.assert_array_equal(result.x, again.x)


def assert_as_after_a_reset(problem, result):
    """``result`` is SOLVED and, bit for bit, what a solver that solved ``problem`` and
    was reset answers on it: a cold start in a kept workspace."""
    reset = fccqp.Solver()
    reset.solve(*problem)
    reset.reset()
    after_reset = reset.solve(*problem)
    assert result.iterations == after_reset.iterations and result.status is Status.SOLVED
    np.testing.assert_array_equal(result.x, after_reset.x)


def two_structures():
    """Two problems of different sizes, their cones as a control loop passes them: a
    tuple of specs with Python numbers."""
    def plain(cone):
        return FrictionCone(cone.start, float(cone.mu),
                            None if cone.normal is None else tuple(map(float, cone.normal)))

    return tuple((*problem[:6], tuple(map(plain, problem[6]))) for problem in (
        random_problem(31, n=30, m=8, n_cones=3, n_box=6),
        random_problem(32, n=24, m=6, n_cones=2, n_box=4)))


@pytest.mark.kkt_backends(*DENSE_PATH_KEEPS, reason="the dense path's kept workspaces")
def test_a_return_to_a_structure_reuses_its_workspace_and_its_last_answer():
    # a controller whose contact set changes and comes back: the solver keeps the
    # workspaces it left (solver.KEPT_WORKSPACES), and a return starts from the last
    # answer of that structure, the same answer bit for bit as a solver that solved it
    # just before; through the general path (new bounds, then back)
    first = random_problem(21, n=30, m=8, n_cones=3, n_box=6)
    others = [random_problem(22 + k, n=24 + 2 * k, m=6, n_cones=2, n_box=4) for k in range(6)]
    P, q, A, b, lb, ub, cones = first
    lb_fixed, ub_fixed = lb.copy(), ub.copy()
    boxed = np.flatnonzero(np.isfinite(lb))[0]
    lb_fixed[boxed] = ub_fixed[boxed] = 0.5 * (lb[boxed] + ub[boxed])
    fixed = P, q, A, b, lb_fixed, ub_fixed, cones
    solver = fccqp.Solver()
    solver.solve(*first)
    kept = solver._workspace
    for problem in (others[0], fixed, first):   # a new size, new bounds, back
        again = solver.solve(*problem)
    assert solver._workspace is kept
    assert_as_solved_again(first, again)
    verify_solution(first, again)
    for problem in others:   # more structures than it keeps: the oldest go
        solver.solve(*problem)
    assert len(solver._kept) == fccqp.solver.KEPT_WORKSPACES
    assert solver.solve(*first).status is Status.SOLVED


@pytest.mark.kkt_backends(*DENSE_PATH_KEEPS, reason="the dense path's kept workspaces")
def test_a_contact_set_that_comes_back_takes_its_kept_workspace_directly(monkeypatch):
    # two contact sets in turn: the return finds the kept workspace by its last cones and
    # the arguments' shapes, without the general path's conversion and structure scan,
    # and starts from its last answer, bit for bit
    first, second = two_structures()
    solver = fccqp.Solver()
    solver.solve(*first)
    kept = solver._workspace
    solver.solve(*second)

    def no_conversion(*arguments):
        raise AssertionError("the return converted its arguments")

    monkeypatch.setattr(fccqp.solver, "convert", no_conversion)
    again = solver.solve(*first)
    assert solver._workspace is kept
    back = solver.solve(*second)
    monkeypatch.undo()
    assert_as_solved_again(first, again)
    assert_as_solved_again(second, back)
    verify_solution(first, again)
    verify_solution(second, back)


def other_friction(problem, scale):
    """``problem`` with every friction coefficient times ``scale`` (new terrain)."""
    cones = tuple(FrictionCone(c.start, c.mu * scale, c.normal) for c in problem[6])
    return (*problem[:6], cones)


def general_path(problem):
    """``problem`` with its cones in a list: the general path takes any sequence of
    specs, the compiled switch (``Workspace.switch``) only the control loop's tuple."""
    return (*problem[:6], list(problem[6]))


def carried(solver, problem, last):
    """``solver``'s answer to ``problem`` from the guess of the previous answer ``last``
    cut or padded to its sizes, as a caller carries it across a contact change."""
    n, m = problem[0].shape[0], problem[2].shape[0]
    return solver.solve(*problem, x0=np.resize(last.x, n), y0=np.resize(last.y, m),
                        z0=np.resize(last.z, n))


@pytest.mark.kkt_backends(*DENSE_PATH_KEEPS, reason="the dense path's kept workspaces")
def test_a_guessed_switch_onto_other_friction_takes_the_kept_workspace_without_a_scan(
        monkeypatch):
    # contact changes onto other terrain, the caller's guess given: the kept workspace
    # of the same sizes and cone blocks is made current with the new friction, without
    # the general path's new structure and scan, and answers bit for bit as the general
    # path does; when it was made for other bounded entries (a fixed one), its solve
    # asks for a rescan and the general path's new workspace answers
    first, second = two_structures()
    P, q, A, b, lb, ub, cones = first
    lb_fixed, ub_fixed = lb.copy(), ub.copy()
    boxed = np.flatnonzero(np.isfinite(lb))[0]
    lb_fixed[boxed] = ub_fixed[boxed] = 0.5 * (lb[boxed] + ub[boxed])
    switches = (other_friction(first, 0.8), other_friction(second, 1.2),
                (P, q, A, b, lb_fixed, ub_fixed, cones))
    general = fccqp.Solver()
    monkeypatch.setattr(general, "_switch", lambda *arguments: None)
    expected = [carried(general, general_path(second), general.solve(*first))]
    for problem in switches:
        expected.append(carried(general, general_path(problem), expected[-1]))
    monkeypatch.undo()

    def no_scan(*arguments):
        raise AssertionError("the switch scanned the bounds")

    solver = fccqp.Solver()
    answers = [carried(solver, second, solver.solve(*first))]
    made = [solver._workspace, *(w for _, w in solver._kept.values())]
    monkeypatch.setattr(fccqp.solver, "structure_scan", no_scan)
    for problem in switches[:2]:
        answers.append(carried(solver, problem, answers[-1]))
        assert any(w is solver._workspace for w in made)
    monkeypatch.undo()
    answers.append(carried(solver, switches[2], answers[-1]))
    for problem, answer, reference in zip((second, *switches), answers, expected,
                                          strict=True):
        assert answer.status is Status.SOLVED
        assert answer.iterations == reference.iterations
        np.testing.assert_array_equal(answer.x, reference.x)
        verify_solution(problem, answer)


def upright(problem):
    """``problem`` with its friction cones upright (no normal), as a walking robot's
    control loop passes them."""
    return (*problem[:6], tuple(FrictionCone(c.start, c.mu) for c in problem[6]))


@pytest.mark.kkt_backends(*DENSE_PATH_KEEPS, reason="the dense path's kept workspaces")
def test_a_guessed_switch_onto_upright_friction_builds_no_flat_cones(monkeypatch):
    # contact changes as a walking robot's controller makes them (upright friction cones
    # of Python numbers, the caller's guess) onto kept workspaces with other friction:
    # one compiled call chooses the workspace and writes the friction, without the flat
    # form of the cones; the answers, and that of a later solve of the same workspace
    # with its first friction again (the general path, which then needs the flat form
    # of the friction the switch wrote), are the general path's bit for bit
    first, second = (upright(problem) for problem in two_structures())
    switches = (other_friction(first, 0.8), other_friction(second, 1.2))
    general = fccqp.Solver()
    expected = [carried(general, general_path(second), general.solve(*first))]
    for problem in (*switches, second):
        expected.append(carried(general, general_path(problem), expected[-1]))

    def no_flattening(*arguments):
        raise AssertionError("the switch flattened the cones")

    solver = fccqp.Solver()
    answers = [carried(solver, second, solver.solve(*first))]
    monkeypatch.setattr(fccqp.solver, "flatten_cones", no_flattening)
    for problem in switches:
        answers.append(carried(solver, problem, answers[-1]))
    monkeypatch.undo()
    answers.append(carried(solver, second, answers[-1]))
    for problem, answer, reference in zip((second, *switches, second), answers, expected,
                                          strict=True):
        assert answer.status is Status.SOLVED
        assert answer.iterations == reference.iterations
        np.testing.assert_array_equal(answer.x, reference.x)
        verify_solution(problem, answer)


@pytest.mark.kkt_backends(*DENSE_PATH_KEEPS, reason="the dense path's kept workspaces")
def test_a_guessed_switch_is_checked_and_solved_in_one_compiled_call():
    # a contact change with the caller's guess onto a kept workspace: one compiled call
    # on the current workspace (Workspace.switch) checks the arrays, the guess and the
    # cones, solves, and returns the kept entry with its answer, the general path's bit
    # for bit; arrays of the current shapes are solved on it (no entry returned), and
    # anything the call does not take as it came (a guess beyond MAX_ENTRY, cones in a
    # list) is left to the general path: FITS_CURRENT where the arrays fit the current
    # workspace, None otherwise
    first, second = (upright(problem) for problem in two_structures())
    general = fccqp.Solver()
    expected = carried(general, general_path(first),
                       carried(general, general_path(second), general.solve(*first)))
    solver = fccqp.Solver()
    last = carried(solver, second, solver.solve(*first))
    current, entry = solver._workspace, next(iter(solver._kept.values()))
    x0, y0, z0 = np.resize(last.x, 30), np.resize(last.y, 8), np.resize(last.z, 30)

    def switch(problem, *guess):
        return current.switch(solver._structure, solver._kept, *problem, *guess, True,
                              time.perf_counter())

    assert switch(first, np.full_like(x0, 1e21), y0, z0) is None
    assert switch(general_path(first), x0, y0, z0) is None
    far = np.full_like(last.x, 1e21)
    assert switch(second, far, last.y, last.z) is fccqp.admm.FITS_CURRENT
    assert switch(general_path(second), last.x, last.y, last.z) is fccqp.admm.FITS_CURRENT
    found, answer = switch(second, last.x, last.y, last.z)
    assert found is None and answer.status is Status.SOLVED
    np.testing.assert_array_equal(answer.x, last.x)   # its own polished answer again
    found, answer = switch(first, x0, y0, z0)
    assert found is entry and not entry[1].arrived
    assert answer.status is Status.SOLVED and answer.iterations == expected.iterations
    np.testing.assert_array_equal(answer.x, expected.x)


@pytest.mark.kkt_backends(*DENSE_PATH_KEEPS, reason="the dense path's kept workspaces")
def test_a_guessed_tick_of_the_current_shapes_answers_as_the_general_path():
    # a trot's swap of stances keeps the sizes: the caller's guess on the current
    # workspace is solved by the compiled call (Workspace.switch) without the general
    # path's flattening and checks, with its answers bit for bit, onto other friction
    # too
    problem = upright(two_structures()[1])
    moved = (problem[0], problem[1] + 0.05, *problem[2:])
    other = other_friction(moved, 0.8)
    solvers = fccqp.Solver(), fccqp.Solver()
    answers = []
    for solver, path in zip(solvers, (lambda p: p, general_path), strict=True):
        last = solver.solve(*path(problem))
        answers.append([carried(solver, path(p), last) for p in (moved, other, problem)])
    for fast, general in zip(*answers, strict=True):
        assert fast.status is Status.SOLVED
        assert fast.iterations == general.iterations
        np.testing.assert_array_equal(fast.x, general.x)
        np.testing.assert_array_equal(fast.y, general.y)
        np.testing.assert_array_equal(fast.z, general.z)


@pytest.mark.kkt_backends(*DENSE_PATH_KEEPS, reason="the dense path's kept workspaces")
@pytest.mark.parametrize("bad, error, message", [
    ({"x0": np.nan}, ValueError, "x0 must be a finite vector of 24 entries"),
    ({"y0": 1e21}, ValueError, r"y0 has an entry beyond 1e\+20"),
    ({"z0": None}, None, None),   # a dual guess without z0: zero, as documented
])
def test_a_guessed_switch_checks_the_guess_before_it_writes_the_friction(bad, error,
                                                                        message):
    # a switch's guess that the compiled call does not take as it came goes to the
    # general path, which raises the error naming the argument (or takes it) before
    # the kept workspace is touched: a later switch onto other friction answers as a
    # solver that never saw the bad guess
    first, second = (upright(problem) for problem in two_structures())
    other = other_friction(second, 0.8)

    def guessed(last, **change):
        guess = {"x0": np.resize(last.x, 24), "y0": np.resize(last.y, 6),
                 "z0": np.resize(last.z, 24)}
        for name, value in change.items():
            guess[name] = None if value is None else np.full_like(guess[name], value)
        return guess

    reference = fccqp.Solver()
    carried(reference, second, reference.solve(*first))
    expected = reference.solve(*other, **guessed(reference.solve(*first)))
    solver = fccqp.Solver()
    carried(solver, second, solver.solve(*first))
    answer = solver.solve(*first)
    if error is None:
        assert solver.solve(*second, **guessed(answer, **bad)).status is Status.SOLVED
        return
    with pytest.raises(error, match=message):
        solver.solve(*second, **guessed(answer, **bad))
    again = solver.solve(*other, **guessed(answer))
    assert again.iterations == expected.iterations
    np.testing.assert_array_equal(again.x, expected.x)


@pytest.mark.kkt_backends(*DENSE_PATH_KEEPS, reason="the dense path's kept workspaces")
def test_after_a_reset_a_return_to_a_kept_structure_starts_cold():
    # the cold view resets before every QP: reset() forgets the kept workspaces'
    # answers too, so a structure left before the reset starts cold when it comes back
    first, second = two_structures()
    solver = fccqp.Solver()
    solver.solve(*first)
    solver.solve(*second)
    solver.reset()
    assert_as_after_a_reset(first, solver.solve(*first))


@pytest.mark.kkt_backends(*DENSE_PATH_KEEPS, reason="the dense path's kept workspaces")
def test_a_cold_start_after_a_reset_keeps_the_scaling_until_the_data_drift():
    # the scaling is the structure's: a cold start rescales new data with the last
    # equilibration as a warm one does, and equilibrates data that left its drift
    P, q, A, b, lb, ub, cones = random_problem(9)
    nearby = (P * 1.01, q, A * 0.99, b, lb, ub, cones)
    far = (P * 1e3, q, A * 1e-3, b, lb, ub, cones)
    solver = fccqp.Solver()
    solver.solve(P, q, A, b, lb, ub, cones)
    D, E, _ = solver._workspace.scaling
    solver.reset()
    assert solver.solve(*nearby).status is Status.SOLVED
    kept_D, kept_E, _ = solver._workspace.scaling
    np.testing.assert_array_equal(kept_D, D)
    np.testing.assert_array_equal(kept_E, E)
    solver.reset()
    assert solver.solve(*far).status is Status.SOLVED
    fresh = fccqp.Solver()
    fresh.solve(*far)
    np.testing.assert_array_equal(solver._workspace.scaling[0], fresh._workspace.scaling[0])
    assert not np.array_equal(fresh._workspace.scaling[0], D)


@pytest.mark.kkt_backends(*DENSE_PATH_KEEPS, reason="the dense path's kept workspaces")
def test_data_that_come_back_take_the_other_kept_scaling():
    # two stances of one structure (a trot's) alternate: each rescales with the
    # equilibration its own data gave, kept beside the current one; a third stance
    # equilibrates anew and the last one becomes the other. Each stance comes back a
    # little moved, so that only a kept scaling gives its first D, E bit for bit
    P, q, A, b, lb, ub, cones = random_problem(9)

    def stance(factor, moved=1.0):
        return (P * factor * moved, q, A / factor / moved, b, lb, ub, cones)

    solver = fccqp.Solver()

    def scaling_after(problem):
        result = solver.solve(*problem)
        assert result.status is Status.SOLVED
        verify_solution(problem, result)
        return solver._workspace.scaling[:2]

    def fresh_scaling(problem):
        fresh = fccqp.Solver()
        fresh.solve(*problem)
        return fresh._workspace.scaling[:2]

    first, second = scaling_after(stance(1.0)), scaling_after(stance(1e3))
    assert not np.array_equal(first[0], second[0])
    for problem, kept in [(stance(1.0, 1.01), first), (stance(1e3, 0.99), second),
                          (stance(1.0, 0.98), first)]:
        for got, expected in zip(scaling_after(problem), kept, strict=True):
            np.testing.assert_array_equal(got, expected)
    third = stance(1e-3)
    np.testing.assert_array_equal(scaling_after(third)[0], fresh_scaling(third)[0])
    np.testing.assert_array_equal(scaling_after(stance(1.0, 1.02))[0], first[0])
    again = stance(1e3, 1.02)   # the second's was dropped: equilibrated anew
    np.testing.assert_array_equal(scaling_after(again)[0], fresh_scaling(again)[0])
    assert not np.array_equal(fresh_scaling(again)[0], second[0])
    solver.reset()   # a reset keeps the structure's scalings, as it keeps the current one
    np.testing.assert_array_equal(scaling_after(stance(1.0, 0.99))[0], first[0])


FACTORIZATIONS_AFTER_A_NEW_P = {"auto": 1, "schur_reduced": 1, "ldl_reduced": 2,
                                "ldl_full": 2, "sparse": 2}
"""Factorizations of a warm solve whose ``P`` changed (problems.random_problem(9), measured
at b11793f, with and without polish): the Schur backend's Cholesky of ``P + R`` is its
convexity test too; the LDL' backends and the sparse path take two."""


def test_reuses_factorization_when_matrices_unchanged(kkt_backend):
    P, q, A, b, lb, ub, cones = random_problem(9)
    solver = fccqp.Solver(adaptive_rho=False)
    solver.solve(P, q, A, b, lb, ub, cones)
    again = solver.solve(P, q + 0.01, A, b, lb, ub, cones)
    assert again.factorizations == 0
    assert again.status is Status.SOLVED
    verify_solution((P, q + 0.01, A, b, lb, ub, cones), again)
    changed = solver.solve(P * 1.01, q, A, b, lb, ub, cones)
    assert changed.factorizations == FACTORIZATIONS_AFTER_A_NEW_P[kkt_backend]


def test_reuse_after_a_solve_that_needed_no_iteration():
    """The cold start's equality-only factorization (LDL') must not be mistaken for
    rho's; the Schur start's is rho's own, which the next solve reuses."""
    P, q, A, b, lb, ub, cones = random_problem(7, n_cones=0)
    solver = fccqp.Solver()
    boxed = np.isfinite(lb)
    first = solver.solve(P, q, A, b, np.where(boxed, -100.0, lb), np.where(boxed, 100.0, ub))
    assert (first.iterations, first.factorizations) == (0, 1)
    tight = solver.solve(P, q, A, b, lb, ub, cones)  # same structure, active bounds now
    assert tight.status is Status.SOLVED
    verify_solution((P, q, A, b, lb, ub, cones), tight)
    if first.backend != "schur_reduced":
        assert tight.factorizations >= 1
    reference = clarabel_solve(P, q, A, b, lb, ub, cones)
    assert abs(tight.obj - reference.obj) <= 1e-4 * (1 + abs(reference.obj))


def test_matrix_changed_in_place_is_not_mistaken_for_the_previous():
    """A control loop may refill the same A array each tick: no stale factorization."""
    P, q, A, b, lb, ub, cones = random_problem(3)
    solver = fccqp.Solver()
    solver.solve(P, q, A, b, lb, ub, cones)
    A[0] *= 2.0
    b[:2] += (b[0], 0.3)
    result = solver.solve(P, q, A, b, lb, ub, cones)
    assert result.status is Status.SOLVED
    verify_solution((P, q, A, b, lb, ub, cones), result)


def test_x0_initial_guess():
    problem = random_problem(10)
    reference = clarabel_solve(*problem)
    result = fccqp.Solver().solve(*problem, x0=reference.x)
    assert result.status is Status.SOLVED
    verify_solution(problem, result)
    assert result.iterations < fccqp.solve(*problem).iterations


@pytest.mark.parametrize("backend", ["auto", "sparse"])
@pytest.mark.parametrize("seed", range(4))
def test_a_result_given_back_as_the_guess_takes_no_iteration(seed, backend):
    """A primal-dual guess starts warm with the polish on its active set, as a warm
    start from the solver's own answer does: the problem's own polished answer is
    answered again at once (its x alone, without the duals, is not)."""
    problem = random_problem(seed)
    first = fccqp.solve(*problem, kkt_backend=backend)
    assert first.status is Status.SOLVED and first.polished
    again = fccqp.solve(*problem, x0=first.x, y0=first.y, z0=first.z, kkt_backend=backend)
    assert again.status is Status.SOLVED and again.polished
    assert again.iterations == 0
    for name in "xyz":
        np.testing.assert_allclose(getattr(again, name), getattr(first, name), rtol=1e-9,
                                   atol=1e-12)
    assert fccqp.solve(*problem, x0=first.x, kkt_backend=backend).iterations > 0


def test_dual_guess_overrides_the_previous_answer_without_warm_start_setting():
    """Given duals, a solve starts from the guess even with ``warm_start=False`` (as
    OSQP's ``warm_start(x, y)`` does) and in a solver that has solved another problem."""
    problem, other = random_problem(5), random_problem(6)
    first = fccqp.solve(*problem)
    solver = fccqp.Solver(warm_start=False)
    solver.solve(*other)
    again = solver.solve(*problem, x0=first.x, y0=first.y, z0=first.z)
    assert again.status is Status.SOLVED and again.iterations == 0
    np.testing.assert_allclose(again.x, first.x, rtol=1e-9, atol=1e-12)


@pytest.mark.parametrize("seed", [7, 11, 15])   # most others: the polish is kept
def test_a_far_guess_whose_polish_fails_is_answered_from_the_cold_start(seed):
    """When the warm polish from a caller's guess fails, ADMM starts from the cold start
    unless the guess is much nearer the termination test: a guess far from the answer
    is then answered as the same problem without a guess is."""
    problem = random_problem(seed)
    cold = fccqp.solve(*problem)
    rng = np.random.default_rng(seed)
    n, m = problem[2].shape[1], problem[2].shape[0]
    far = fccqp.solve(*problem, x0=1e3 * rng.standard_normal(n),
                      y0=1e3 * rng.standard_normal(m), z0=1e3 * rng.standard_normal(n))
    assert far.status is Status.SOLVED
    assert far.iterations == cold.iterations
    np.testing.assert_array_equal(far.x, cold.x)


@pytest.mark.parametrize("seed", [425, 712])   # most other seeds: the guess polishes
def test_a_neighbours_answer_whose_polish_fails_is_answered_from_the_cold_start(seed):
    """A guess that is the answer of a neighbouring problem (``q`` and ``b`` moved, as
    from the previous tick) and fails its warm polish is nearer the termination test
    than the cold start, but not ``GUESS_LEAD`` times nearer: ADMM starts cold, and
    the answer is the problem's answer without a guess, bit for bit."""
    P, q, A, b, lb, ub, cones = problem = random_problem(seed)
    cold = fccqp.solve(*problem)
    rng = np.random.default_rng(100 + seed)
    neighbour = fccqp.solve(P, q + 3 * rng.standard_normal(q.shape), A,
                            b + rng.standard_normal(b.shape), lb, ub, cones)
    guessed = fccqp.solve(*problem, x0=neighbour.x, y0=neighbour.y, z0=neighbour.z)
    assert guessed.status is Status.SOLVED and guessed.iterations > 0
    assert guessed.iterations == cold.iterations
    np.testing.assert_array_equal(guessed.x, cold.x)


@pytest.mark.parametrize("seed", range(4))   # 4: on schur_reduced, 17 iterations
def test_a_carried_guess_holding_bounds_the_problem_releases_is_polished_without_iterations(
        seed):
    """A caller's guess carried from another structure (the solver's last solve had other
    sizes, as across a contact change) whose multipliers hold most bounds (the answer of
    the problem pushed against them, as a contact change leaves the previous stance's
    torque limits) is polished from nothing held, the bounds the problem needs added at
    once: the problem's answer at 0 iterations, where releasing one held bound a guess ran
    out of guesses and ADMM ran (as it does for the same guess in the same structure)."""
    rng = np.random.default_rng(seed)
    n = 24
    P, A, b = np.diag(1.0 + rng.random(n)), rng.standard_normal((2, n)), np.zeros(2)
    lb, ub = -np.ones(n), np.ones(n)
    pushed = fccqp.solve(P, 20 * np.ones(n), A, b, lb, ub)
    q = 0.1 * rng.standard_normal(n)
    q[:3] = -8.0   # three upper bounds active at the answer
    plain = fccqp.solve(P, q, A, b, lb, ub)
    solver = fccqp.Solver()
    solver.solve(P[1:, 1:], q[1:], A[:, 1:], b, lb[1:], ub[1:])   # another structure
    guessed = solver.solve(P, q, A, b, lb, ub, x0=pushed.x, y0=pushed.y, z0=pushed.z)
    assert np.sum(np.abs(pushed.x) == 1.0) > 12 and plain.iterations > 0
    assert guessed.status is Status.SOLVED and guessed.iterations == 0
    np.testing.assert_allclose(guessed.x, plain.x, rtol=0, atol=1e-12)
    same = fccqp.solve(P, q, A, b, lb, ub, x0=pushed.x, y0=pushed.y, z0=pushed.z)
    assert same.status is Status.SOLVED and same.iterations > 0


def test_box_infeasible():
    P = np.eye(3)
    q = np.zeros(3)
    A = np.array([[1.0, 1.0, 1.0]])
    result = fccqp.solve(P, q, A, [10.0], lb=-np.ones(3), ub=np.ones(3))
    assert result.status is Status.PRIMAL_INFEASIBLE
    assert clarabel_solve(P, q, A, [10.0], -np.ones(3), np.ones(3)).status == "primal_infeasible"
    verify_solution((P, q, A, [10.0], -np.ones(3), np.ones(3)), result)


def test_cone_infeasible():
    """The normal force must be negative: impossible inside a friction cone."""
    P = np.eye(3)
    q = np.zeros(3)
    A = np.array([[0.0, 0.0, 1.0]])
    result = fccqp.solve(P, q, A, [-1.0], cones=[FrictionCone(0, 0.5)])
    assert result.status is Status.PRIMAL_INFEASIBLE
    verify_solution((P, q, A, [-1.0], None, None, [FrictionCone(0, 0.5)]), result)


def test_inconsistent_equalities():
    P = np.eye(2)
    A = np.array([[1.0, 1.0], [2.0, 2.0]])
    result = fccqp.solve(P, np.zeros(2), A, [1.0, 3.0], lb=[-5, -5], ub=[5, 5])
    assert result.status is Status.PRIMAL_INFEASIBLE
    verify_solution((P, np.zeros(2), A, [1.0, 3.0], [-5, -5], [5, 5]), result)


def test_unbounded_lp():
    P = np.zeros((3, 3))
    q = np.array([-1.0, 0.0, 0.0])
    A = np.array([[0.0, 1.0, 1.0]])
    result = fccqp.solve(P, q, A, [1.0], lb=[0, 0, 0], ub=[np.inf, 1, 1])
    assert result.status is Status.DUAL_INFEASIBLE
    verify_solution((P, q, A, [1.0], [0, 0, 0], [np.inf, 1, 1]), result)
    assert result.certificate[0] > 0


def test_unbounded_along_cone():
    P = np.zeros((3, 3))
    q = np.array([0.0, 0.0, -1.0])
    result = fccqp.solve(P, q, cones=[SecondOrderCone(0, 3)])
    assert result.status is Status.DUAL_INFEASIBLE
    verify_solution((P, q, None, None, None, None, [SecondOrderCone(0, 3)]), result)


def test_lp_solution_matches_clarabel():
    rng = np.random.default_rng(3)
    n = 12
    A = rng.standard_normal((4, n))
    x_f = rng.uniform(0.1, 1, n)
    q = rng.uniform(0.1, 1, n)
    problem = (np.zeros((n, n)), q, A, A @ x_f, np.zeros(n), np.full(n, 2.0), ())
    reference = clarabel_solve(*problem)
    result = fccqp.solve(*problem, **TIGHT)
    assert result.status is Status.SOLVED
    verify_solution(problem, result, TIGHT_TOLERANCES)
    assert abs(result.obj - reference.obj) <= 1e-6 * (1 + abs(reference.obj))


def test_rho_is_not_lowered_while_the_iterate_runs_away_infeasibly():
    """An LP over two second-order cones (a CVXPY problem translated: two free slacks
    ``x_0, x_1`` in ``P``, six variables, two nonnegative and four cone slacks) whose
    iterate runs off along a near-recession direction. The primal residual grew with
    the iterate's size, so relative to it it looked small, and OSQP's rule lowered rho
    to its floor: MAX_ITER_REACHED on every backend, the iterate at 1e8 with the
    optimum at 1e2. Not lowering rho while the residual grows with the iterate
    (``tuning.RHO_RUNAWAY``) keeps the iterate where the polish answers."""
    columns = np.array([[-0.063, 0.305, -0.315, 0.366, 0.049, -0.028],
                        [0.065, -0.264, 0.047, -0.204, -0.061, -0.197],
                        [-0.025, -0.095, -0.044, 0.013, 0.09, 0.105],
                        [0.002, 0.006, 0.003, -0.001, -0.006, -0.007],
                        [-1.137, -1.338, -1.104, 0.545, 0.468, 0.847],
                        [-0.751, -0.156, -0.656, 0.951, -0.175, 1.252],
                        [0.878, 0.877, 0.12, -0.873, 0.251, -0.279],
                        [0.334, 1.394, 0.69, 0.373, 1.558, 1.224]])
    A = np.zeros((8, 14))
    A[:, 2:8] = columns
    A[:2, :2] = -np.eye(2)
    A[2:, 8:] = np.eye(6)
    q = np.zeros(14)
    q[2:8] = [-0.793, -0.327, 1.899, -0.46, -1.857, 0.828]
    b = [0.0, 0.0, 0.633, 0.329, 2.687, 2.535, -0.433, -0.533]
    lb = np.full(14, -np.inf)
    lb[8:10] = 0.0
    problem = (np.diag([1.0, 1.0] + [0.0] * 12), q, A, b, lb, np.full(14, np.inf),
               (SecondOrderCone(3, 4), SecondOrderCone(10, 4)))
    reference = clarabel_solve(*problem)
    result = fccqp.solve(*problem)
    assert result.status is Status.SOLVED
    verify_solution(problem, result)
    assert abs(result.obj - reference.obj) <= 1e-4 * (1 + abs(reference.obj))


def test_budget_statuses():
    problem = random_problem(11, psd_rank=10)   # polishing solves it from 2 iterations
    result = fccqp.solve(*problem, max_iter=2, eps_abs=1e-12, eps_rel=0.0, polish=False)
    assert result.status is Status.MAX_ITER_REACHED
    result = fccqp.solve(*problem, time_limit=1e-9, eps_abs=1e-12, eps_rel=0.0, polish=False)
    assert result.status is Status.TIME_LIMIT_REACHED
    verify_solution(problem, result)


def test_inaccurate_status_within_ten_times_tolerance():
    problem = random_problem(1)
    exact = fccqp.solve(*problem, **TIGHT)
    for budget in range(1, 200):
        result = fccqp.solve(*problem, max_iter=budget, eps_abs=1e-6, eps_rel=0.0)
        if result.status is not Status.MAX_ITER_REACHED:
            break
    assert result.status in (Status.SOLVED_INACCURATE, Status.SOLVED)
    if result.status is Status.SOLVED_INACCURATE:
        assert max(result.prim_res, result.dual_res) <= 1e-5
        assert max(result.prim_res, result.dual_res) > 1e-6
    assert np.abs(result.x - exact.x).max() < 1e-2


def test_realtime_preset_is_a_time_budget():
    assert fccqp.Settings.realtime().time_limit == fccqp.settings.REALTIME_BUDGET
    preset = fccqp.Settings.realtime(2e-3, eps_abs=1e-5)
    assert preset.time_limit == 2e-3 and preset.eps_abs == 1e-5 and preset.polish
    assert fccqp.Settings.realtime(math.inf).time_limit == math.inf
    for bad in (0.0, -1e-3, math.nan):
        with pytest.raises(ValueError, match="budget"):
            fccqp.Settings.realtime(bad)
    with pytest.raises(TypeError, match="budget"):
        fccqp.Settings.realtime("1 ms")


def test_realtime_preset_keeps_its_status_promise():
    settings = fccqp.Settings.realtime()
    problem = random_problem(2)
    verify_solution(problem, fccqp.solve(*problem, settings=settings), Tolerances.of(settings))


def test_nonconvex_objective_is_rejected():
    """No equalities: a negative eigenvalue of P is a non-convex QP (see item 18 in
    test_regressions for the null-space criterion); the error gives it on the sparse
    path too."""
    P = np.diag([1.0, -2.0, 1.0])
    with pytest.raises(ValueError, match="positive semidefinite.*-2"):
        fccqp.solve(P, np.zeros(3), lb=-np.ones(3), ub=np.ones(3))


def test_sparse_input_matches_dense():
    scipy_sparse = pytest.importorskip("scipy.sparse")
    P, q, A, b, lb, ub, cones = random_problem(12)
    dense = fccqp.solve(P, q, A, b, lb, ub, cones)
    sparse = fccqp.solve(
        scipy_sparse.csc_matrix(P), q, scipy_sparse.csc_array(A), b, lb, ub, cones
    )
    np.testing.assert_array_equal(dense.x, sparse.x)


def test_objective_and_timings_reported():
    P, q, A, b, lb, ub, cones = problem = random_problem(13)
    result = fccqp.solve(*problem)
    assert math.isclose(result.obj, 0.5 * result.x @ P @ result.x + q @ result.x)
    assert 0 < result.setup_time <= result.solve_time


def test_verbose_prints_log(capsys):
    fccqp.solve(*random_problem(14), verbose=True)
    out = capsys.readouterr().out
    assert "prim_res" in out and "status: solved" in out


def test_changing_friction_coefficients_leave_other_problems_alone():
    """One warm solver alternating between two friction coefficients on the same blocks,
    and fresh solves in between: every answer is that of its own problem. (The
    workspace once kept the memoized cone arrays themselves, so updating its friction
    coefficients rewrote those of every later solve with the other cones.)"""
    P, q, A, b, lb, ub, _ = random_problem(0, n_cones=0)
    problems = [
        (P, q, A, b, lb, ub, [FrictionCone(6, mu), FrictionCone(9, mu)]) for mu in (0.3, 0.9)
    ]
    expected = [fccqp.solve(*problem).x for problem in problems]
    solver = fccqp.Solver()
    for _ in range(3):
        for problem, x in zip(problems, expected, strict=True):
            np.testing.assert_allclose(solver.solve(*problem).x, x, atol=1e-6)
            np.testing.assert_allclose(fccqp.solve(*problem).x, x, atol=1e-6)


def test_cone_specs_rebuilt_every_tick_are_read_anew():
    """A control loop passes a new tuple of equal specs each tick, which the solver
    recognizes without flattening them again (fccqp.fast_checks.same_cones); a changed
    coefficient or normal, a normal given as a numpy array and changed in place, and an
    int where a float was must all be seen."""
    P, q, A, b, lb, ub, _ = random_problem(1, n_cones=0)
    tilted = (0.0, 0.6, 0.8)
    normal = np.array([0.0, 0.0, 1.0])
    ticks = [
        (FrictionCone(6, 0.3), FrictionCone(9, 0.3)),
        (FrictionCone(6, 0.3), FrictionCone(9, 0.3)),
        (FrictionCone(6, 0.9), FrictionCone(9, 0.3)),
        (FrictionCone(6, 0.9), FrictionCone(9, 0.3, tilted)),
        (FrictionCone(6, 0.9, normal), FrictionCone(9, 0.3, tilted)),
        (FrictionCone(6, 1), FrictionCone(9, 0.3, tilted)),
        (FrictionCone(6, 1.0), SecondOrderCone(9, 3)),
    ]
    solver = fccqp.Solver()
    for k, cones in enumerate(ticks[:5] + [None] + ticks[5:]):
        if cones is None:   # the last tick's normal array, changed in place
            normal[:] = tilted
            cones = ticks[4]
        expected = fccqp.solve(P, q, A, b, lb, ub, cones).x
        np.testing.assert_allclose(solver.solve(P, q, A, b, lb, ub, cones).x, expected,
                                   atol=1e-6, err_msg=f"tick {k}")


def test_feasible_problem_with_dependent_rows_is_not_certified_infeasible():
    """A fuzz case: the dual step drifted along the null space of A' (duplicated rows)
    with b'dy at the size of what its residual explains, and passed for a certificate
    of a feasible problem. A certificate must separate by more than (A'dy + dz)'x."""
    problem = random_problem(593544, n=18, m=2, n_cones=2, n_box=6, duplicate_rows=2,
                             psd_rank=2)
    assert clarabel_solve(*problem).status == "solved"
    result = fccqp.solve(*problem, eps_abs=1e-7, eps_rel=1e-7)
    assert result.status is Status.SOLVED
    verify_solution(Problem.of(*problem), result, Tolerances.of(eps_abs=1e-7, eps_rel=1e-7))


def test_settings_of_a_solver_cannot_be_replaced():
    """The dense workspaces are built for the solver's settings, so an assignment that
    the next solves would silently ignore is refused by name."""
    solver = fccqp.Solver(max_iter=50)
    assert solver.settings.max_iter == 50
    with pytest.raises(AttributeError, match="Solver.settings"):
        solver.settings = fccqp.Settings(max_iter=5)
    assert solver.settings.max_iter == 50


_MARKED_KB = """
    import re
    import numpy as np
    np._core.multiarray._set_madvise_hugepage(False)
    import fccqp

    def marked_kb(field="Size"):
        text = open("/proc/self/smaps").read()
        blocks = re.split(r"\\n(?=[0-9a-f]+-[0-9a-f]+ )", text)
        return sum(int(re.search(rf"^{field}:\\s+(\\d+) kB", block, re.M).group(1))
                   for block in blocks if re.search(r"^VmFlags:.* hg", block, re.M))
"""
"""The start of the pool tests' programs: fccqp imported in a process whose numpy marks
none of its own memory for huge pages, and ``marked_kb``, the kB of the marked mappings
(``field``: their ``Size`` or their resident ``Rss``)."""


def _run_marked(code):
    """The stdout of ``code`` run after :data:`_MARKED_KB` in a new Python process."""
    program = textwrap.dedent(_MARKED_KB) + textwrap.dedent(code)
    result = subprocess.run([sys.executable, "-c", program], capture_output=True, text=True,
                            timeout=300)
    assert result.returncode == 0, result.stderr
    return result.stdout.split()


@pytest.mark.kkt_backends("auto", reason="the workspaces' memory, in a new Python process")
@pytest.mark.skipif(not os.path.isdir("/sys/kernel/mm/transparent_hugepage"),
                    reason="transparent huge pages (Linux's madvise) are not available")
def test_workspaces_are_carved_from_one_shared_huge_page_pool_faulted_in_at_import():
    """The arrays of a process's workspaces are carved from 2 MB pools marked for
    transparent huge pages (fccqp.workspace_arrays._Pool): the first is mapped and its
    pages written when the solver's modules are imported (``fccqp.Solver``'s first
    use), resident before any solve, and two small solvers share it."""
    out = _run_marked("""
        first, second = fccqp.Solver(), fccqp.Solver()
        before, resident = marked_kb(), marked_kb("Rss")
        first.solve(np.eye(3), np.ones(3), lb=-np.ones(3), ub=np.ones(3))
        second.solve(np.eye(4), np.ones(4), lb=-np.ones(4), ub=np.ones(4))
        print(before, resident, marked_kb())
    """)
    assert out == ["2048", "2048", "2048"]


@pytest.mark.kkt_backends("auto", reason="the workspaces' memory, in a new Python process")
@pytest.mark.skipif(not os.path.isdir("/sys/kernel/mm/transparent_hugepage"),
                    reason="transparent huge pages (Linux's madvise) are not available")
def test_released_pools_are_kept_zeroed_for_the_next_workspaces():
    """A pool whose workspaces are all gone is kept (two at most, zeroed), not unmapped,
    and the next pools are taken from it: after solvers that filled four pools are
    dropped, three stay mapped (the current one and two spares), the same solvers
    again map no more and give the same answers bit for bit (the spares were zeroed)."""
    out = _run_marked("""
        rng = np.random.default_rng(5)
        problems = []
        for k in range(12):
            n = 40 + k
            M = rng.standard_normal((n, n))
            problems.append((M @ M.T + np.eye(n), rng.standard_normal(n),
                             rng.standard_normal((3, n)), rng.standard_normal(3),
                             -np.ones(n), np.ones(n)))

        def answers():
            solvers = [fccqp.Solver() for _ in problems]
            xs = [s.solve(*p).x.tobytes() for s, p in zip(solvers, problems)]
            return xs, marked_kb()

        first, filled = answers()
        dropped = marked_kb()
        again, refilled = answers()
        print(filled >= 8192, dropped, refilled == filled, first == again)
    """)
    assert out == ["True", "6144", "True", "True"]


