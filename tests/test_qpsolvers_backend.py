"""fccqp through qpsolvers: reference problems, dual conventions, inputs, registration."""

import dataclasses
import re
import subprocess
import sys
import textwrap
from pathlib import Path

import numpy as np
import pytest
import qpsolvers
import scipy.sparse as sp
from qpsolvers import ParamError, Problem, problems, solve_problem, solve_qp

import fccqp
from fccqp.qpsolvers_backend import fccqp_solve_qp, register
from verify import Tolerances, from_qpsolvers, verify_solution

pytestmark = pytest.mark.usefixtures("every_kkt_backend")
BEFORE_ANY_BACKEND = pytest.mark.kkt_backends(
    "auto", reason="settings, arguments and registration checked before a backend is chosen")
IN_A_SUBPROCESS = pytest.mark.kkt_backends(
    "auto", reason="runs in a new Python process, outside the fixture")

TIGHT = dict(eps_abs=1e-9, eps_rel=1e-9, max_iter=100_000)
DEFAULT_EPS = fccqp.Settings().eps_abs


def sparse_least_squares(n: int):
    """qpsolvers' sparse least-squares problem, which ships without a solution."""

    def getter():
        problem = Problem(*problems.get_sparse_least_squares(n))
        return problem, qpsolvers.Solution(problem)

    getter.__name__ = f"get_sparse_least_squares({n})"
    return getter


REFERENCE_PROBLEMS = [
    problems.get_qpsut01,
    problems.get_qpsut02,
    problems.get_qpsut03,
    problems.get_qpsut04,
    problems.get_qpsut05,
    problems.get_qptest,
    problems.get_qpgurdu,
    problems.get_qpgurabs,
    problems.get_qpgureq,
    sparse_least_squares(10),
    sparse_least_squares(50),
]
NON_UNIQUE_DUALS = {"get_qpsut02"}
"""Problems whose active constraints are linearly dependent (see the test below)."""
WRONG_SIGN_REFERENCE_DUALS = {"get_qpsut04": "y"}
"""Reference duals shipped with the wrong sign (see the test below)."""


def reference(getter):
    """The problem and its solution: qpsolvers' own, completed by ProxQP at 1e-12.

    Some getters ship no ``x`` or no duals; ProxQP (dense, to 1e-12 in primal and
    dual residuals) fills those in, so those cases skip when proxsuite is missing.
    Clarabel is not used here: on the sparse least-squares problem it stops 8e-6
    away in ``x`` (an objective difference of 1e-10, within its gap tolerance).
    """
    problem, solution = getter()
    if getter.__name__ in WRONG_SIGN_REFERENCE_DUALS:
        name = WRONG_SIGN_REFERENCE_DUALS[getter.__name__]
        setattr(solution, name, -getattr(solution, name))
    solution.y = np.empty(0) if problem.A is None else solution.y
    solution.z = np.empty(0) if problem.G is None else solution.z
    if problem.lb is None and problem.ub is None:
        solution.z_box = np.empty(0)
    missing = [name for name in ("x", "y", "z", "z_box") if getattr(solution, name) is None]
    if missing:
        pytest.importorskip("proxsuite")
        proxqp = solve_problem(problem, solver="proxqp", eps_abs=1e-12, eps_rel=0.0)
        assert proxqp.found
        for name in missing:
            setattr(solution, name, getattr(proxqp, name))
    return problem, solution


def magnitude(problem: Problem, solution) -> float:
    """Scale of the problem at its solution, as in OSQP's relative tolerances."""
    P, q, G, h, A, b, lb, ub = problem.unpack()
    x = solution.x
    terms = [1.0, np.abs(q).max(), np.abs(P @ x).max(), np.abs(x).max()]
    if A is not None:
        terms += [np.abs(A.T @ solution.y).max(), np.abs(b).max()]
    if G is not None:
        terms += [np.abs(G.T @ solution.z).max(), np.abs(h).max()]
    if solution.z_box.size:
        terms.append(np.abs(solution.z_box).max())
    return float(max(terms))


def assert_close(actual, expected, atol, name):
    assert actual.shape == np.shape(expected), (name, actual.shape, np.shape(expected))
    error = float(np.abs(actual - expected).max(initial=0.0))
    assert error <= atol, f"{name}: error {error:.3g} > {atol:.3g}"


@pytest.mark.parametrize(
    "settings, eps",
    [pytest.param(TIGHT, 1e-9, id="tight"), pytest.param({}, DEFAULT_EPS, id="default")],
)
@pytest.mark.parametrize("getter", REFERENCE_PROBLEMS, ids=lambda g: g.__name__)
def test_reference_problems(getter, settings, eps):
    """x within 30 eps * scale, duals within 100 eps * scale of the reference.

    fccqp stops when its residuals are within eps_abs + eps_rel * scale; errors in
    x and in the duals are those residuals times the problem's conditioning, and
    have stayed 3x (qpsut03, whose shipped x has 8 digits) to 100x below these
    bounds while the core was being tuned.
    """
    problem, ref = reference(getter)
    solution = solve_problem(problem, solver="fccqp", **settings)
    assert solution.found, solution.extras
    verify_solution(*from_qpsolvers(problem, solution), Tolerances.of(**settings))
    scale = magnitude(problem, ref)
    # fccqp stops on eps_abs + eps_rel * scale for the slack form; qpsolvers' own
    # residuals of the translated duals are within a small factor of its own.
    assert solution.primal_residual() <= 10 * eps * scale
    assert solution.dual_residual() <= 10 * eps * scale
    # The gap is a sum over all constraints of residual * multiplier.
    duals = np.concatenate([ref.y, ref.z, ref.z_box])
    gap_bound = 10 * eps * scale * (np.abs(duals).sum() + np.abs(ref.x).sum() + 1)
    assert solution.duality_gap() <= gap_bound
    assert_close(solution.x, ref.x, 30 * eps * scale, "x")
    ref_obj = problem.q @ ref.x + 0.5 * ref.x @ (problem.P @ ref.x)
    assert abs(solution.obj - ref_obj) <= gap_bound
    if getter.__name__ in NON_UNIQUE_DUALS:
        return
    for name in ("y", "z", "z_box"):
        assert_close(getattr(solution, name), getattr(ref, name), 100 * eps * scale, name)


def test_qpsut02_duals_are_not_unique():
    """Why qpsut02's duals are checked through residuals only.

    At its solution the two equality rows and the two active bounds are linearly
    dependent (rank 3 for 4 rows), so many (y, z_box) satisfy the KKT conditions;
    qpsolvers marks its reference duals "YMMV".
    """
    problem, ref = problems.get_qpsut02()
    active = np.vstack([problem.A, np.eye(4)[[1, 2]]])
    assert np.linalg.matrix_rank(active) == 3
    solution = solve_problem(problem, solver="fccqp", **TIGHT)
    assert solution.is_optimal(1e-6)


def test_qpsut04_reference_y_has_the_wrong_sign():
    """qpsolvers 4.13 ships y = 1/3 + 0.01 for qpsut04; stationarity needs its negative.

    With P = I, q = 0.01, A = [1 1 1], G = I inactive and x = 1/3: the first row of
    P x + q + A'y + G'z = 0 reads 1/3 + 0.01 + y = 0.
    """
    problem, ref = problems.get_qpsut04()
    assert ref.dual_residual() == pytest.approx(2 * (1 / 3 + 0.01))
    ref.y = -ref.y
    assert ref.dual_residual() < 1e-15
    solution = solve_problem(problem, solver="fccqp", **TIGHT)
    assert_close(solution.y, ref.y, 1e-9, "y")


@pytest.mark.parametrize("getter", REFERENCE_PROBLEMS[:6], ids=lambda g: g.__name__)
def test_empty_constraint_blocks_are_empty_arrays(getter):
    problem, _ = getter()
    solution = solve_problem(problem, solver="fccqp")
    for name, present in [
        ("y", problem.A is not None),
        ("z", problem.G is not None),
        ("z_box", problem.lb is not None or problem.ub is not None),
    ]:
        value = getattr(solution, name)
        assert isinstance(value, np.ndarray)
        assert (value.size > 0) == present, name


# Dual signs: minimize 1/2 ||x - c||^2 with c outside the feasible set, so that
# exactly one kind of constraint is active and its multiplier is known in closed form.
@pytest.mark.parametrize(
    "constraints, c, x, duals",
    [
        # x0 >= 1 holds x0 up from c0 = -2: z_box = c - x = -3 < 0 at a lower bound.
        (dict(lb=np.array([1.0, -5.0])), [-2.0, 0.0], [1.0, 0.0], dict(z_box=[-3.0, 0.0])),
        (dict(ub=np.array([1.0, 5.0])), [3.0, 0.0], [1.0, 0.0], dict(z_box=[2.0, 0.0])),
        (
            dict(G=np.array([[1.0, 1.0]]), h=np.array([1.0])),
            [2.0, 2.0],
            [0.5, 0.5],
            dict(z=[1.5]),
        ),
        (
            dict(G=np.array([[-1.0, 0.0]]), h=np.array([-1.0])),  # x0 >= 1 as a G row
            [-2.0, 0.0],
            [1.0, 0.0],
            dict(z=[3.0]),
        ),
        (
            dict(A=np.array([[1.0, 1.0]]), b=np.array([1.0])),
            [2.0, 2.0],
            [0.5, 0.5],
            dict(y=[1.5]),
        ),
    ],
    ids=["lower box", "upper box", "G row", "G row as lower bound", "equality"],
)
def test_dual_signs_follow_qpsolvers(constraints, c, x, duals):
    """With P = I, q = -c: x - c + A'y + G'z + z_box = 0 fixes every multiplier."""
    problem = Problem(np.eye(2), -np.asarray(c), **constraints)
    solution = solve_problem(problem, solver="fccqp", **TIGHT)
    assert solution.found
    verify_solution(*from_qpsolvers(problem, solution), Tolerances.of(**TIGHT))
    assert_close(solution.x, x, 1e-7, "x")
    for name, value in duals.items():
        assert_close(getattr(solution, name), np.asarray(value), 1e-7, name)
    assert solution.dual_residual() <= 1e-8
    if solution.z.size:
        assert (solution.z >= 0).all()


def test_every_bound_active_at_once():
    """Lower box, upper box, a G row and an equality all active in one problem."""
    c = np.array([-3.0, 4.0, 2.0, 2.0, 0.0])
    G = np.array([[0.0, 0.0, 1.0, 1.0, 0.0]])
    A = np.array([[0.0, 0.0, 0.0, 0.0, 1.0]])
    lb = np.array([-1.0, -np.inf, -np.inf, -np.inf, -np.inf])
    ub = np.array([np.inf, 2.0, np.inf, np.inf, np.inf])
    problem = Problem(np.eye(5), -c, G, np.array([1.0]), A, np.array([1.0]), lb, ub)
    solution = solve_problem(problem, solver="fccqp", **TIGHT)
    assert_close(solution.x, np.array([-1.0, 2.0, 0.5, 0.5, 1.0]), 1e-7, "x")
    assert_close(solution.z_box, np.array([-2.0, 2.0, 0.0, 0.0, 0.0]), 1e-7, "z_box")
    assert_close(solution.z, np.array([1.5]), 1e-7, "z")
    assert_close(solution.y, np.array([-1.0]), 1e-7, "y")
    assert solution.is_optimal(1e-7)


def parallel_rows(scale: float) -> Problem:
    """``min 1/2 (x0^2 + x2^2) - x1`` in a box, under ``x0 + x1 <= 3`` and the same row
    times ``scale``, ``scale (x0 + x1) <= scale``: only the small row is active, so
    ``x = (-1, 2, 0)`` and its multiplier is ``1 / scale``."""
    g = np.array([1.0, 1.0, 0.0])
    return Problem(np.diag([1.0, 0.0, 1.0]), np.array([0.0, -1.0, 0.0]),
                   np.vstack([g, scale * g]), np.array([3.0, scale]),
                   lb=np.full(3, -5.0), ub=np.full(3, 5.0))


@pytest.mark.parametrize("scale", [1e-3, 2e-3])
def test_small_parallel_row_of_g_is_solved_with_its_large_multiplier(scale):
    """A row of ``G`` far smaller than 1 needs a multiplier far larger than the cost:
    solved at default settings to Clarabel's answer and duals."""
    problem = parallel_rows(scale)
    solution = solve_problem(problem, solver="fccqp")
    assert solution.extras["status"] is fccqp.Status.SOLVED
    verify_solution(*from_qpsolvers(problem, solution))
    clarabel = solve_problem(problem, solver="clarabel", tol_gap_abs=1e-10,
                             tol_gap_rel=1e-10, tol_feas=1e-10)
    for name, exact, atol in (("x", [-1.0, 2.0, 0.0], 1e-6),
                              ("z", [0.0, 1.0 / scale], 1e-6 / scale),
                              ("z_box", [0.0, 0.0, 0.0], 1e-6)):
        assert_close(getattr(solution, name), np.asarray(exact), atol, name)
        assert_close(getattr(solution, name), getattr(clarabel, name), atol, name)


@pytest.mark.parametrize("getter", [problems.get_qpsut01, problems.get_qpsut04, problems.get_qptest,
                                    problems.get_qpgurdu, problems.get_qpgureq],
                         ids=lambda g: g.__name__)
@pytest.mark.parametrize("seed", [0, 1])
def test_answer_does_not_depend_on_the_scale_of_the_rows(getter, seed):
    """Rows of ``G, h`` and ``A, b`` times factors from 1e-4 to 1e4 describe the same
    problem: the same iterations (the scaled problem is the same to rounding), the
    same ``x`` and ``z_box``, and ``z``, ``y`` divided by the factors."""
    problem, _ = getter()
    P, q, G, h, A, b, lb, ub = problem.unpack()
    rng = np.random.default_rng(seed)
    d_G = np.empty(0) if G is None else 10.0 ** rng.uniform(-4, 4, G.shape[0])
    d_A = np.empty(0) if A is None else 10.0 ** rng.uniform(-4, 4, A.shape[0])
    scaled = Problem(P, q, None if G is None else d_G[:, None] * G,
                     None if G is None else d_G * h, None if A is None else d_A[:, None] * A,
                     None if A is None else d_A * b, lb, ub)
    plain = solve_problem(problem, solver="fccqp")
    solution = solve_problem(scaled, solver="fccqp")
    assert plain.found and solution.found
    assert solution.extras["iterations"] == plain.extras["iterations"]
    verify_solution(*from_qpsolvers(scaled, solution))
    scale = magnitude(problem, plain)
    assert_close(solution.x, plain.x, 1e-9 * scale, "x")
    assert_close(solution.z_box, plain.z_box, 1e-9 * scale, "z_box")
    assert_close(solution.z * d_G, plain.z, 1e-9 * scale, "z")
    assert_close(solution.y * d_A, plain.y, 1e-9 * scale, "y")


@pytest.mark.parametrize("h0, status", [(0.5, fccqp.Status.SOLVED),
                                        (-0.5, fccqp.Status.PRIMAL_INFEASIBLE)],
                         ids=["0 <= h holds", "0 <= h fails"])
def test_zero_row_of_g_keeps_its_meaning(h0, status):
    """A zero row of ``G`` reads ``0 <= h``: no constraint when it holds (multiplier 0),
    an infeasible problem when it fails."""
    G = np.array([[0.0, 0.0], [1.0, 1.0]])
    problem = Problem(np.eye(2), -np.array([2.0, 2.0]), G, np.array([h0, 1.0]))
    solution = solve_problem(problem, solver="fccqp", **TIGHT)
    assert solution.extras["status"] is status
    verify_solution(*from_qpsolvers(problem, solution), Tolerances.of(**TIGHT))
    if solution.found:
        assert_close(solution.x, np.array([0.5, 0.5]), 1e-7, "x")
        assert_close(solution.z, np.array([0.0, 1.5]), 1e-7, "z")


@pytest.mark.parametrize(
    "G, h, q, lb, status",
    [
        (np.array([[1e-3, 1e-3], [1.0, 0.0]]), np.array([-1e-3, 5.0]), np.ones(2),
         np.zeros(2), fccqp.Status.PRIMAL_INFEASIBLE),
        (np.array([[-1e3, 1e3], [0.0, 1e-3]]), np.array([1.0, 1.0]), -np.ones(2),
         None, fccqp.Status.DUAL_INFEASIBLE),
    ],
    ids=["x0 + x1 <= -1 at 1e-3 against x >= 0", "x1 <= x0 at 1e3, unbounded along x0"],
)
def test_infeasibility_certificate_is_in_the_users_units(G, h, q, lb, status):
    """Rows of ``G`` far from 1: the certificate of the slack form checks on the user's
    rows."""
    problem = Problem(np.zeros((2, 2)) if lb is None else np.eye(2), q, G, h, lb=lb)
    solution = solve_problem(problem, solver="fccqp")
    assert solution.extras["status"] is status
    verify_solution(*from_qpsolvers(problem, solution))


@pytest.mark.parametrize(
    "to_sparse", [sp.csc_matrix, sp.csc_array], ids=["csc_matrix", "csc_array"]
)
def test_sparse_inputs_give_the_dense_answer(to_sparse):
    problem, _ = problems.get_qpsut01()
    dense = solve_problem(problem, solver="fccqp", **TIGHT)
    sparse_problem = Problem(
        to_sparse(problem.P), problem.q, to_sparse(problem.G), problem.h,
        to_sparse(problem.A), problem.b, problem.lb, problem.ub,
    )
    sparse = solve_problem(sparse_problem, solver="fccqp", **TIGHT)
    for name in ("x", "y", "z", "z_box"):
        np.testing.assert_array_equal(getattr(sparse, name), getattr(dense, name))
    assert sparse.is_optimal(1e-7)


def test_solve_qp_matches_the_backend_function():
    problem, ref = problems.get_qpsut01()
    x = solve_qp(*problem.unpack(), solver="fccqp", **TIGHT)
    np.testing.assert_array_equal(x, fccqp_solve_qp(*problem.unpack(), **TIGHT))
    assert_close(x, ref.x, 1e-7, "x")


def test_settings_are_passed_through():
    problem, _ = problems.get_qpsut01()
    solution = solve_problem(problem, solver="fccqp", max_iter=3, adaptive_rho=False, rho=0.5,
                             polish=False)
    assert not solution.found
    assert solution.extras["status"] is fccqp.Status.MAX_ITER_REACHED
    assert solution.extras["iterations"] == 3
    assert solution.extras["rho"] == 0.5
    assert solution.x is not None  # the last iterate, for whoever wants it
    assert solve_qp(*problem.unpack(), solver="fccqp", max_iter=3, polish=False) is None


def test_extras_report_the_solve():
    problem, _ = problems.get_qpsut01()
    solution = solve_problem(problem, solver="fccqp")
    extras = solution.extras
    assert extras["status"] is fccqp.Status.SOLVED
    assert extras["iterations"] > 0
    assert extras["prim_res"] <= 1e-3 and extras["dual_res"] <= 1e-3
    assert 0 < extras["setup_time"] <= extras["solve_time"]
    assert extras["rho"] > 0 and extras["factorizations"] >= 1
    assert solution.build_time >= 0 and solution.solve_time >= extras["solve_time"]


def test_initvals_is_the_primal_start():
    """initvals reaches the solver as x0; it is primal only, so it speeds little up.

    The multipliers still start at zero, so from the exact solution a solve takes
    about as many iterations as from a cold start; only its first iterates are closer.
    """
    problem, _ = problems.get_qpgurdu()
    cold = solve_problem(problem, solver="fccqp", **TIGHT)
    # without polishing, which would make both one-iteration solves exact
    one_cold = solve_problem(problem, solver="fccqp", max_iter=1, polish=False)
    one_warm = solve_problem(problem, solver="fccqp", max_iter=1, initvals=cold.x, polish=False)
    assert np.abs(one_warm.x - cold.x).max() < np.abs(one_cold.x - cold.x).max()
    warm = solve_problem(problem, solver="fccqp", initvals=cold.x, **TIGHT)
    assert warm.found
    assert_close(warm.x, cold.x, 1e-7, "x")


@BEFORE_ANY_BACKEND
@pytest.mark.parametrize(
    "kwargs, name",
    [
        (dict(tolerance=1e-3), "tolerance"),
        (dict(eps_abs=1e-6, solver_verbose=True), "solver_verbose"),
    ],
)
def test_unknown_setting_raises_param_error(kwargs, name):
    problem, _ = problems.get_qpsut01()
    with pytest.raises(ParamError, match=name) as info:
        solve_problem(problem, solver="fccqp", **kwargs)
    assert isinstance(info.value.__cause__, ValueError)


@BEFORE_ANY_BACKEND
def test_invalid_setting_value_raises_param_error():
    problem, _ = problems.get_qpsut01()
    with pytest.raises(ParamError, match="max_iter"):
        solve_problem(problem, solver="fccqp", max_iter=0)


@pytest.mark.parametrize(
    "constraints",
    [
        dict(G=np.array([[1.0, 0.0]]), h=np.array([-1.0]), lb=np.zeros(2)),
        dict(G=np.array([[1.0, 0.0], [-1.0, 0.0]]), h=np.array([-1.0, -1.0])),
        dict(A=np.array([[1.0, 1.0]]), b=np.array([5.0]), ub=np.ones(2)),
    ],
    ids=["G against lb", "two G rows", "equality against ub"],
)
def test_infeasible_problem_is_not_found(constraints):
    P, q = np.eye(2), np.ones(2)
    problem = Problem(P, q, **constraints)
    solution = solve_problem(problem, solver="fccqp")
    assert solution.found is False
    assert solution.extras["status"] is fccqp.Status.PRIMAL_INFEASIBLE
    verify_solution(*from_qpsolvers(problem, solution))
    assert solution.x is None and solution.z is None
    assert solve_qp(P, q, **constraints, solver="fccqp") is None


P2, Q2, G2, H2 = np.eye(2), np.ones(2), np.array([[1.0, 1.0]]), np.array([1.0])


@pytest.mark.parametrize(
    "changes, error, message",
    [
        (dict(G=np.ones((1, 3))), ValueError, "G must have 2 columns"),
        (dict(G=np.ones(3)), ValueError, "G must have 2 columns"),
        (dict(h=np.ones(2)), ValueError, "G has 1 rows but h has 2"),
        (dict(G=np.array([[1.0, np.nan]])), ValueError, "G contains NaN"),
        (dict(h=np.array([np.nan])), ValueError, "h contains NaN"),
        (dict(h=np.array([-np.inf])), ValueError, "h\\[0\\] is -inf"),
        (dict(G=[["a", "b"]]), TypeError, "G must be numeric"),
        (dict(q=np.ones(3)), ValueError, "q must have 2 entries"),
        (dict(P=np.array([[1.0, np.nan], [np.nan, 1.0]])), ValueError, "P contains NaN"),
        (dict(lb=np.array([1.0, 0.0]), ub=np.zeros(2)), ValueError, "lb > ub at index 0"),
        (dict(A=np.ones((1, 2)), b=np.ones(2)), ValueError, "b must have 1 entries"),
        (dict(initvals=np.ones(3)), ValueError, "initvals must be a finite vector of 2"),
        (dict(initvals=np.array([0.0, np.nan])), ValueError, "initvals"),
        (dict(initvals=["a", "b"]), TypeError, "initvals must be a numeric vector"),
    ],
)
def test_bad_input_names_the_argument(changes, error, message):
    args = dict(P=P2, q=Q2, G=G2, h=H2)
    args.update(changes)
    with pytest.raises(error, match=message):
        solve_qp(**args, solver="fccqp")


@BEFORE_ANY_BACKEND
def test_incomplete_inequality_is_a_problem_error():
    # qpsolvers' own check, run before the backend (its message says "missing G").
    with pytest.raises(qpsolvers.ProblemError, match="incomplete inequality"):
        solve_qp(P2, Q2, G=G2, solver="fccqp")


def test_verbose_prints_the_iteration_log(capsys):
    problem, _ = problems.get_qpsut01()
    solve_problem(problem, solver="fccqp", verbose=True)
    out = capsys.readouterr().out
    assert "prim_res" in out and "status: solved" in out
    solve_problem(problem, solver="fccqp")
    assert capsys.readouterr().out == ""


@BEFORE_ANY_BACKEND
def test_registered_once_in_qpsolvers_lists():
    assert register() is True
    assert register() is True
    for names in (qpsolvers.available_solvers, qpsolvers.dense_solvers,
                  qpsolvers.sparse_solvers):
        assert names.count("fccqp") == 1
    assert qpsolvers.solvers.solve_function["fccqp"].__name__ == "fccqp_solve_problem"


def run_python(code: str) -> str:
    result = subprocess.run(
        [sys.executable, "-c", textwrap.dedent(code)], capture_output=True, text=True, timeout=300
    )
    assert result.returncode == 0, result.stderr
    return result.stdout


@IN_A_SUBPROCESS
def test_import_fccqp_first_then_qpsolvers():
    """``import fccqp`` leaves qpsolvers unimported; importing it later registers fccqp."""
    out = run_python(
        """
        import sys
        import fccqp
        from fccqp._import_hooks import _AfterImport
        assert "qpsolvers" not in sys.modules
        import qpsolvers
        from importlib.machinery import SourceFileLoader
        assert isinstance(qpsolvers.__loader__, SourceFileLoader)
        assert isinstance(qpsolvers.__spec__.loader, SourceFileLoader)
        assert not any(isinstance(f, _AfterImport) and f.name == "qpsolvers"
                       for f in sys.meta_path)
        import numpy as np
        one = np.ones((1, 1))
        x = qpsolvers.solve_qp(2 * one, -2 * one[0], one, 0.5 * one[0], solver="fccqp")
        print(qpsolvers.available_solvers.count("fccqp"), round(float(x[0]), 3))
        """
    )
    assert out.split() == ["1", "0.5"]


@IN_A_SUBPROCESS
def test_import_qpsolvers_first_then_fccqp():
    out = run_python(
        """
        import sys
        import qpsolvers
        import fccqp
        from fccqp._import_hooks import _AfterImport
        assert not any(isinstance(f, _AfterImport) for f in sys.meta_path)
        print(qpsolvers.available_solvers.count("fccqp"))
        """
    )
    assert out.split() == ["1"]


@IN_A_SUBPROCESS
def test_without_qpsolvers_registration_does_nothing():
    out = run_python(
        """
        import importlib.util, sys
        real = importlib.util.find_spec
        importlib.util.find_spec = lambda name, *a: None if name == "qpsolvers" else real(name, *a)
        before = list(sys.meta_path)
        import fccqp
        from fccqp.qpsolvers_backend import register
        assert sys.meta_path == before
        print(register())
        """
    )
    assert out.split() == ["False"]


DOC = Path(__file__).resolve().parents[1] / "docs" / "qpsolvers.md"


@IN_A_SUBPROCESS
def test_doc_example_runs():
    """The page's example, which asserts its own answer, runs as written."""
    run_python(DOC.read_text().split("```python\n")[1].split("```")[0])


@BEFORE_ANY_BACKEND
def test_doc_settings_table_matches_settings():
    rows = re.findall(r"^\| `(\w+)` \| .* \| `(.+)` \|$", DOC.read_text(), flags=re.MULTILINE)
    documented = {name: default for name, default in rows}
    actual = {f.name: repr(f.default) for f in dataclasses.fields(fccqp.Settings)}
    assert documented == actual
