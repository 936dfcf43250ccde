"""The CVXPY plugin: answers, duals and statuses against CVXPY + Clarabel.

Every comparison solves the same CVXPY problem with Clarabel (tolerance 1e-8) and with
FCCQP at ``eps_abs = eps_rel = 1e-8`` and checks the objective, every variable and the
dual value of every constraint (both parts of SOC duals) to a tolerance relative to
the size of the reference values.
"""

from __future__ import annotations

import re
from collections.abc import Callable
from pathlib import Path

import cvxpy as cp
import numpy as np
import pytest
from benchmarks.cvxpy_overhead import WbcQP, cvxpy_problem, linear_costs, wbc_qp

import fccqp
from fccqp_cvxpy import FCCQP, FCCQPSolver
from fccqp_cvxpy.translation import Translation
from verify import Problem, Tolerances, verify_solution

pytestmark = pytest.mark.usefixtures("every_kkt_backend", "default_instance_on_the_backend")


@pytest.fixture(scope="module")
def default_instance_on_the_backend(every_kkt_backend):
    """``FCCQP``, the instance the plugin builds at import (and registers under its
    name), takes the default settings of ``every_kkt_backend``'s backend too; the
    instances the tests build do by themselves."""
    with pytest.MonkeyPatch.context() as patch:
        patch.setattr(FCCQP, "settings", fccqp.Settings())
        yield


TIGHT = {"eps_abs": 1e-8, "eps_rel": 1e-8, "max_iter": 100_000}
TIGHTER = {**TIGHT, "eps_abs": 1e-10, "eps_rel": 1e-10}
CLARABEL_TIGHT = {"tol_gap_abs": 1e-11, "tol_gap_rel": 1e-11, "tol_feas": 1e-11}
"""For the WBC QP, whose tiny curvature on torques and forces (1e-3, 1e-4) makes the
primal sensitive to the objective: at the default 1e-8 gap Clarabel's own torques are
off by 3e-4."""
RTOL = 2e-5
"""Agreement required with Clarabel, relative to the largest reference entry (or 1)."""


def _verify(problem: cp.Problem, options: dict | None = None) -> None:
    """fccqp's result keeps its status's promise on the translated problem."""
    stats = problem.solver_stats.extra_stats
    t = stats["translation"]
    translated = Problem.of(t.P, t.q, t.A, t.b, t.lb, t.ub, t.cones)
    verify_solution(translated, stats["result"], Tolerances.of(**(options or {})))


def _values(problem: cp.Problem) -> dict[str, object]:
    values: dict[str, object] = {"objective": problem.value}
    for k, variable in enumerate(problem.variables()):
        values[f"variable {k} {variable.name()}"] = np.array(variable.value, copy=True)
    for k, constraint in enumerate(problem.constraints):
        dual = constraint.dual_value
        parts = dual if isinstance(dual, list) else [dual]
        for j, part in enumerate(parts):
            values[f"dual {k}.{j} {type(constraint).__name__}"] = np.array(part, copy=True)
    return values


def _compare(
    problem: cp.Problem, options: dict | None = None, reference: dict | None = None
) -> Translation:
    """Solve with Clarabel and FCCQP, assert agreement, return FCCQP's translation."""
    problem.solve(solver="CLARABEL", **(reference or {}))
    assert problem.status == cp.OPTIMAL
    expected = _values(problem)
    problem.solve(solver=FCCQP, **(options or TIGHT))
    assert problem.status == cp.OPTIMAL
    _verify(problem, options or TIGHT)
    got = _values(problem)
    assert got.keys() == expected.keys()
    for key, reference in expected.items():
        scale = max(1.0, float(np.max(np.abs(reference))))
        np.testing.assert_allclose(got[key], reference, rtol=0, atol=RTOL * scale, err_msg=key)
    return problem.solver_stats.extra_stats["translation"]


def _rng(seed: int) -> np.random.Generator:
    return np.random.default_rng(seed)


def constrained_least_squares() -> cp.Problem:
    rng = _rng(1)
    M, y = rng.standard_normal((20, 8)), rng.standard_normal(20)
    x = cp.Variable(8)
    return cp.Problem(cp.Minimize(cp.sum_squares(M @ x - y)), [x >= 0, cp.sum(x) == 1])


def norm_constrained() -> cp.Problem:
    rng = _rng(2)
    C, D = rng.standard_normal((5, 3)), rng.standard_normal((5, 3))
    X = cp.Variable((5, 3))
    Y = cp.Variable((3, 4))
    radius = rng.uniform(0.2, 0.6, 5)
    objective = cp.sum_squares(X - 2 * C) + cp.sum(cp.multiply(D, X)) + cp.sum_squares(Y - 1)
    constraints = [
        cp.norm(X, 2, axis=1) <= radius,
        cp.SOC(np.full(4, 1.5), Y, axis=0),
        cp.sum(X) == 0.5,
    ]
    return cp.Problem(cp.Minimize(objective), constraints)


def portfolio() -> cp.Problem:
    rng = _rng(3)
    n, factors = 12, 3
    F = rng.standard_normal((n, factors))
    L = np.hstack([F, np.diag(rng.uniform(0.1, 0.3, n))])
    mu = rng.uniform(0.02, 0.15, n)
    w = cp.Variable(n)
    constraints = [cp.sum(w) == 1, w >= 0, w <= 0.3, cp.norm(L.T @ w) <= 0.6]
    return cp.Problem(cp.Maximize(mu @ w - 0.05 * cp.sum_squares(w)), constraints)


def linear_program() -> cp.Problem:
    rng = _rng(4)
    G, h, c = rng.standard_normal((10, 6)), rng.uniform(0.5, 1.5, 10), rng.standard_normal(6)
    x = cp.Variable(6)
    return cp.Problem(cp.Minimize(c @ x), [G @ x <= h, x >= -1, x <= 1])


def equality_bound_qp() -> cp.Problem:
    rng = _rng(5)
    R = rng.standard_normal((7, 7))
    P = R @ R.T + np.eye(7)
    q, E = 3 * rng.standard_normal(7), rng.standard_normal((2, 7))
    x = cp.Variable(7)
    constraints = [
        E @ x == [0.5, -0.5],
        x >= -0.4,
        x <= 0.5,
        x[0] <= 0.3,  # tighter than x <= 0.5: the two bounds merge
        2 * x[1] >= -0.6,  # a scaled bound
    ]
    return cp.Problem(cp.Minimize(0.5 * cp.quad_form(x, P) + q @ x), constraints)


PROBLEMS: dict[str, Callable[[], cp.Problem]] = {
    "constrained least squares": constrained_least_squares,
    "norm constrained": norm_constrained,
    "portfolio": portfolio,
    "linear program": linear_program,
    "equalities and bounds": equality_bound_qp,
}


@pytest.mark.parametrize("make", PROBLEMS.values(), ids=PROBLEMS.keys())
def test_matches_clarabel(make: Callable[[], cp.Problem]) -> None:
    _compare(make())


def test_simple_bounds_become_box_without_slacks() -> None:
    translation = _compare(equality_bound_qp())
    assert translation.num_slacks == 0
    assert translation.lb[0] == pytest.approx(-0.4) and translation.ub[0] == pytest.approx(0.3)
    assert translation.lb[1] == pytest.approx(-0.3)


def test_general_rows_become_slacks() -> None:
    translation = _compare(portfolio())
    # w >= 0 and w <= 0.3 are bounds; the SOC risk limit (dim 16) needs slacks
    assert translation.num_slacks == 1 + 12 + 3
    assert [type(c) for c in translation.cones] == [fccqp.SecondOrderCone]


def _wbc_in_cvxpy(qp: WbcQP, per_contact: bool) -> cp.Problem:
    """The benchmark QP written as a user would: separate variables, f as a matrix."""
    nv, nu, k = qp.nv, qp.nu, qp.contacts
    vdot, u, f = cp.Variable(nv), cp.Variable(nu), cp.Variable((k, 3))
    forces = cp.vec(f, order="C")
    blocks = (slice(0, nv), slice(nv, nv + nu), slice(nv + nu, None))
    Pv, Pu, Pf = (qp.P[s, s] for s in blocks)
    qv, qu, qf = (qp.q[s] for s in blocks)
    objective = (
        0.5 * cp.quad_form(vdot, Pv, assume_PSD=True) + qv @ vdot
        + 0.5 * Pu[0, 0] * cp.sum_squares(u) + qu @ u
        + 0.5 * Pf[0, 0] * cp.sum_squares(f) + qf @ forces
    )
    Av, Au, Af = (qp.A[:, s] for s in blocks)
    if per_contact:
        cones = [cp.SOC(qp.mu * f[i, 2], f[i, :2]) for i in range(k)]
    else:
        cones = [cp.SOC(qp.mu * f[:, 2], f[:, :2], axis=1)]
    constraints = [
        Av @ vdot + Au @ u + Af @ forces == qp.b,
        u <= qp.ub[nv:nv + nu],
        u >= qp.lb[nv:nv + nu],
        *cones,
    ]
    return cp.Problem(cp.Minimize(objective), constraints)


@pytest.mark.parametrize("per_contact", [False, True], ids=["axis=1", "per contact"])
def test_whole_body_control_maps_to_native_cones_and_box(per_contact: bool) -> None:
    qp = wbc_qp()
    translation = _compare(_wbc_in_cvxpy(qp, per_contact), TIGHTER, CLARABEL_TIGHT)
    assert translation.num_slacks == 0
    assert translation.b.shape == qp.b.shape  # only the user's equalities
    assert len(translation.cones) == qp.contacts
    assert all(isinstance(c, fccqp.FrictionCone) for c in translation.cones)
    assert all(c.mu == pytest.approx(qp.mu, rel=1e-14) for c in translation.cones)
    assert np.isfinite(translation.ub).sum() == np.isfinite(translation.lb).sum() == qp.nu
    native = fccqp.solve(qp.P, qp.q, qp.A, qp.b, qp.lb, qp.ub, qp.cones, **TIGHT)
    problem_value = _wbc_in_cvxpy(qp, per_contact)
    problem_value.solve(solver=FCCQP, **TIGHT)
    assert problem_value.value == pytest.approx(native.obj, rel=1e-7)


def test_whole_body_control_single_variable_is_the_native_problem() -> None:
    qp = wbc_qp()
    problem, _ = cvxpy_problem(qp)
    problem.solve(solver=FCCQP)
    translation = problem.solver_stats.extra_stats["translation"]
    assert np.array_equal(translation.perm, np.arange(qp.q.shape[0]))
    assert translation.cones == qp.cones
    native = fccqp.solve(qp.P, qp.q, qp.A, qp.b, qp.lb, qp.ub, qp.cones)
    assert problem.solver_stats.num_iters == native.iterations
    np.testing.assert_allclose(problem.variables()[0].value, native.x, rtol=0, atol=1e-9)


def test_cone_entries_out_of_order_are_permuted() -> None:
    f = cp.Variable(3)
    target = np.array([2.0, -1.0, 0.5])
    # t = 0.8 * f[0], tangential (f[2], f[1]): the block is x[[2, 1, 0]]
    cone = cp.SOC(0.8 * f[0], cp.hstack([f[2], f[1]]))
    objective = cp.sum_squares(f) - 2 * target @ f  # no auxiliary variables
    problem = cp.Problem(cp.Minimize(objective), [cone, f[0] <= 1])
    translation = _compare(problem)
    assert translation.num_slacks == 1  # the bound on a cone entry needs a slack
    assert translation.cones == (fccqp.FrictionCone(0, 0.8),)
    assert list(translation.perm) == [2, 1, 0]


@pytest.mark.parametrize(
    ("scale", "native"), [(1.0, fccqp.SecondOrderCone), (2.0, None)], ids=["unit", "scaled t"]
)
def test_second_order_cone_on_variables(scale: float, native: type | None) -> None:
    x = cp.Variable(5)
    target = np.array([0.5, 1.0, -2.0, 1.5, 0.3])
    problem = cp.Problem(cp.Minimize(cp.sum_squares(x - target)), [cp.SOC(scale * x[0], x[1:])])
    translation = _compare(problem)
    kinds = [type(c) for c in translation.cones]
    if native is None:  # a dim-5 cone with a scaled t is no fccqp cone: slacks
        assert kinds == [fccqp.SecondOrderCone] and translation.num_slacks == 5
    else:
        assert kinds == [native] and translation.num_slacks == 0


def test_soc_with_offset_uses_slacks() -> None:
    f = cp.Variable(3)
    cone = cp.SOC(0.5 * f[2] + 1, f[:2])
    problem = cp.Problem(cp.Minimize(cp.sum_squares(f - [3, 1, 0])), [cone])
    translation = _compare(problem)
    assert translation.num_slacks == 3


def _status(problem: cp.Problem) -> str:
    problem.solve(solver=FCCQP)
    _verify(problem)
    return problem.status


def test_infeasible() -> None:
    x = cp.Variable(3)
    assert _status(cp.Problem(cp.Minimize(cp.sum(x)), [cp.sum(x) >= 5, x <= 1])) == cp.INFEASIBLE
    crossed = cp.Problem(cp.Minimize(cp.sum_squares(x)), [x[0] >= 1, x[0] <= 0])
    assert _status(crossed) == cp.INFEASIBLE
    f = cp.Variable(3)
    cone = cp.Problem(cp.Minimize(cp.sum_squares(f)), [cp.SOC(0.6 * f[2], f[:2]), f[0] == 5,
                                                       f[2] == 1])
    assert _status(cone) == cp.INFEASIBLE
    assert cone.value == np.inf


def test_unbounded() -> None:
    x = cp.Variable(3)
    assert _status(cp.Problem(cp.Minimize(-x[0]), [x >= 0])) == cp.UNBOUNDED
    qp = cp.Problem(cp.Minimize(cp.sum_squares(x[1:]) - x[0]), [x[0] >= 0, x[1] <= 1])
    assert _status(qp) == cp.UNBOUNDED
    assert qp.value == -np.inf


@pytest.mark.parametrize(
    ("budget", "expected"),
    [
        ({"max_iter": 2, "adaptive_rho": False}, fccqp.Status.MAX_ITER_REACHED),
        ({"time_limit": 1e-9}, fccqp.Status.TIME_LIMIT_REACHED),
    ],
    ids=["max_iter", "time_limit"],
)
def test_budget_is_user_limit_with_last_iterate(budget: dict, expected: fccqp.Status) -> None:
    problem, _ = cvxpy_problem(wbc_qp())
    with pytest.warns(UserWarning, match="inaccurate"):
        problem.solve(solver=FCCQP, **budget)
    assert problem.solver_stats.extra_stats["result"].status is expected
    assert problem.status == cp.USER_LIMIT
    assert problem.variables()[0].value is not None
    assert all(c.dual_value is not None for c in problem.constraints)


def test_solver_stats() -> None:
    problem = equality_bound_qp()
    problem.solve(solver=FCCQP)
    stats = problem.solver_stats
    result = stats.extra_stats["result"]
    assert stats.solver_name == "FCCQP"
    assert isinstance(result, fccqp.Result)
    assert stats.num_iters == result.iterations > 0
    assert stats.solve_time == result.solve_time >= stats.setup_time == result.setup_time > 0


def test_parameter_resolve_warm_starts() -> None:
    qp = wbc_qp()
    problem, q = cvxpy_problem(qp)
    first, second = linear_costs(qp, 2)
    q.value = first
    problem.solve(solver=FCCQP)
    assert problem.solver_stats.extra_stats["result"].factorizations > 0
    q.value = second
    problem.solve(solver=FCCQP)
    warm = problem.solver_stats.extra_stats
    cold = fccqp.solve(qp.P, second, qp.A, qp.b, qp.lb, qp.ub, qp.cones)
    assert warm["warm_started"]
    assert warm["result"].iterations < cold.iterations / 2
    assert warm["result"].factorizations == 0  # same P and A: factorization reused
    # both stop at the default tolerance, where a flat cost leaves x some play:
    # compare what the tolerance controls, the objective
    assert abs(problem.value - cold.obj) <= 1e-4 * (1 + abs(cold.obj))

    problem.solve(solver=FCCQP, warm_start=False)
    assert not problem.solver_stats.extra_stats["warm_started"]
    assert problem.solver_stats.num_iters == cold.iterations


def test_changed_options_start_cold() -> None:
    problem = equality_bound_qp()
    problem.solve(solver=FCCQP)
    problem.solve(solver=FCCQP, eps_abs=1e-7)
    assert not problem.solver_stats.extra_stats["warm_started"]


@pytest.mark.parametrize(
    ("options", "match"),
    [({"not_an_option": 1}, "not_an_option"), ({"max_iter": 0}, "max_iter")],
)
def test_bad_options_raise(options: dict, match: str) -> None:
    with pytest.raises(ValueError, match=match):
        equality_bound_qp().solve(solver=FCCQP, **options)


def test_bad_constructor_option_raises() -> None:
    with pytest.raises(ValueError, match="tolerance"):
        FCCQP(tolerance=1e-3)


@pytest.mark.parametrize("name", ["FCCQP", "fccqp"])
def test_lookup_by_name(name: str) -> None:
    problem = equality_bound_qp()
    problem.solve(solver=name)
    assert problem.status == cp.OPTIMAL
    assert problem.solver_stats.solver_name == "FCCQP"


def test_instances_compare_equal_and_keep_the_chain() -> None:
    assert FCCQP() == FCCQP == FCCQPSolver() and hash(FCCQP()) == hash(FCCQP)
    assert FCCQP(eps_abs=1e-7) != FCCQP
    assert FCCQP(eps_abs=1e-7)(eps_rel=1e-7).settings == fccqp.Settings(
        eps_abs=1e-7, eps_rel=1e-7)
    problem = equality_bound_qp()
    problem.solve(solver=FCCQP())
    chain = problem._cache.solving_chain
    problem.solve(solver=FCCQP())
    assert problem._cache.solving_chain is chain
    assert problem.solver_stats.extra_stats["warm_started"]


def test_cite() -> None:
    assert "FCCQP" in FCCQP.cite({}) and "Acosta" in FCCQP.cite({})


def test_docs_example_runs(capsys: pytest.CaptureFixture[str]) -> None:
    page = (Path(__file__).parents[1] / "docs" / "cvxpy.md").read_text()
    code = re.search(r"```python\n(.*?)```", page, re.S).group(1)
    exec(compile(code, "docs/cvxpy.md", "exec"), {})
    assert capsys.readouterr().out.startswith("optimal")


def _standard_tests():
    """CVXPY's own conformance tests that apply to fccqp (no integers, no SDP)."""
    helpers = pytest.importorskip("cvxpy.tests.solver_test_helpers")
    for group in (helpers.StandardTestLPs, helpers.StandardTestQPs, helpers.StandardTestSOCPs):
        for name in sorted(vars(group)):
            if name.startswith("test_") and not name.startswith("test_mi_") and name != "test_lp_7":
                yield pytest.param(getattr(group, name), id=f"{group.__name__}.{name}")


@pytest.mark.parametrize("check", list(_standard_tests()))
def test_cvxpy_standard_tests_pass_at_default_settings(check):
    """CVXPY's StandardTestLPs/QPs/SOCPs, as CVXPY runs them for its own solvers (lp_7
    needs the sdpap package for its reference)."""
    check(solver=FCCQP())
