"""Sanity of the WBC test-set generator: shapes, cost, constraints, physics, files."""

from __future__ import annotations

import numpy as np
import pinocchio as pin
import pytest
from benchmarks import wbc_qp
from benchmarks.exact_solvers import fccqp_arguments
from benchmarks.robots import ROBOTS, load_robot
from benchmarks.testsets import (
    MIX,
    active_flags,
    active_fraction,
    generate_test_set,
    load,
    save,
)
from benchmarks.wbc_qp import (
    REFERENCE_TOLERANCES,
    ReferenceSolveError,
    TaskCommands,
    WbcQP,
    build_wbc_qp,
    solve_reference,
    solve_tight_reference,
)

import fccqp

_LWA = pin.ReferenceFrame.LOCAL_WORLD_ALIGNED


def _standing_qp(name: str, v: np.ndarray | None = None) -> tuple[WbcQP, float]:
    """QP at the SRDF posture with zero task commands, and the robot's weight (N)."""
    robot = load_robot(name)
    model = robot.model
    contacts = [fid for ids in robot.contact_frames.values() for fid in ids]
    commands = TaskCommands(
        com=np.zeros(3), base_angular=np.zeros(3), posture=np.zeros(model.nv - 6)
    )
    qp = build_wbc_qp(
        model,
        model.createData(),
        robot.q0,
        np.zeros(model.nv) if v is None else v,
        commands,
        contacts,
        robot.config.mu,
        hand=robot.hand_frame,
        hand_dim=robot.config.hand_dim,
    )
    return qp, pin.computeTotalMass(model) * 9.81


@pytest.fixture(scope="module")
def small_set():
    return generate_test_set("solo12", MIX, 40, seed=3, seq_len=10)


@pytest.mark.parametrize("name", sorted(ROBOTS))
def test_shapes_layout_and_cost(name):
    qp, _ = _standing_qp(name)
    robot = load_robot(name)
    k = sum(len(ids) for ids in robot.contact_frames.values())
    nh = robot.config.hand_dim if robot.hand_frame is not None else 0
    nv = robot.model.nv
    assert qp.n == nv + (nv - 6) + nh + 6 * k
    assert qp.A.shape == (nv + nh + 3 * k, qp.n)
    sizes = {key: s.stop - s.start for key, s in qp.layout.items()}
    assert sizes == {"vdot": nv, "u": nv - 6, "lambda_h": nh, "eps": 3 * k, "lambda_c": 3 * k}
    assert qp.layout["lambda_c"].stop == qp.n
    np.testing.assert_array_equal(qp.cone_starts, qp.layout["lambda_c"].start + 3 * np.arange(k))
    np.testing.assert_array_equal(qp.P, qp.P.T)
    assert np.linalg.eigvalsh(qp.P).min() > 0.0
    finite = np.isfinite(qp.ub)
    assert np.flatnonzero(finite).tolist() == list(range(nv, 2 * nv - 6))
    assert np.all(qp.ub[finite] < 1e3)  # placeholders such as solo12's 1000 Nm replaced


@pytest.mark.parametrize("name", sorted(ROBOTS))
def test_rank_is_reported_without_crashing(name):
    qp, _ = _standing_qp(name)
    rank = np.linalg.matrix_rank(qp.A)
    assert 0 < rank <= qp.A.shape[0]
    x = solve_reference(qp)
    assert qp.equality_residual(x) < 1e-8 * max(1.0, np.abs(qp.b).max())


@pytest.mark.parametrize("name", sorted(ROBOTS))
def test_gravity_support_is_feasible(name):
    """Standing still: contact (and handle) forces inside the cones carry the weight."""
    qp, weight = _standing_qp(name)
    x = solve_reference(qp)
    assert qp.cone_violation(x) < 1e-7
    assert qp.bound_violation(x) < 1e-7
    assert np.abs(x[qp.layout["eps"]]).max() < 1e-3
    assert np.abs(x[qp.layout["vdot"]][:6]).max() < 0.01  # the base does not fall
    vertical = qp.forces(x)[:, 2].sum()
    if qp.layout["lambda_h"].stop > qp.layout["lambda_h"].start:
        # The handle takes part of the weight; its force enters the dynamics as Jh' lambda_h.
        assert 0.5 * weight < vertical < 1.5 * weight
    else:
        assert vertical == pytest.approx(weight, rel=1e-3)


@pytest.mark.parametrize("name", ["solo12", "talos_reduced"])
def test_drifts_match_finite_differences(name):
    """The rhs ``-Jdot v`` equals minus the derivative of ``J(q) v`` along ``vdot = 0``."""
    robot = load_robot(name)
    model = robot.model
    rng = np.random.default_rng(0)
    q = pin.integrate(model, robot.q0, 0.1 * rng.standard_normal(model.nv))
    v = rng.standard_normal(model.nv)
    qp, _ = _standing_qp(name, v)
    data = model.createData()
    contacts = [fid for ids in robot.contact_frames.values() for fid in ids]
    qp = build_wbc_qp(
        model,
        data,
        q,
        v,
        TaskCommands(),
        contacts,
        0.7,
        hand=robot.hand_frame,
        hand_dim=robot.config.hand_dim,
    )

    def velocities(qq: np.ndarray) -> np.ndarray:
        pin.computeJointJacobians(model, data, qq)
        pin.updateFramePlacements(model, data)
        rows = []
        if robot.hand_frame is not None:
            rows.append(
                pin.getFrameJacobian(model, data, robot.hand_frame, pin.ReferenceFrame.LOCAL)
            )
        rows += [pin.getFrameJacobian(model, data, fid, _LWA)[:3] for fid in contacts]
        return np.vstack(rows) @ v

    h = 1e-6
    fd = (
        velocities(pin.integrate(model, q, h * v)) - velocities(pin.integrate(model, q, -h * v))
    ) / (2 * h)
    np.testing.assert_allclose(-qp.b[qp.nv :], fd, atol=1e-5 * max(1.0, np.abs(fd).max()))


def test_reference_solutions_satisfy_the_constraints(small_set):
    for qp, x in zip(small_set.qps, small_set.x_ref, strict=True):
        scale = max(1.0, np.abs(qp.b).max())
        dyn = np.abs(qp.A[: qp.nv] @ x - qp.b[: qp.nv]).max()
        assert dyn < 1e-8 * scale
        assert qp.cone_violation(x) < 1e-6
        assert qp.bound_violation(x) < 1e-6


def test_reference_torques_are_those_of_an_exact_solution(small_set):
    """The stored references are tight enough to judge torques: they agree with fccqp's
    default answer (an active-set KKT solution) within 0.05 % of each joint's limit, where
    Clarabel stopped at 1e-9 is up to 0.14 % away on this set."""
    solver = fccqp.Solver()
    for qp, x in zip(small_set.qps, small_set.x_ref, strict=True):
        result = solver.solve(*fccqp_arguments(qp))
        assert result.status is fccqp.Status.SOLVED
        u = qp.layout["u"]
        assert np.max(np.abs(x[u] - result.x[u]) / qp.ub[u]) < 5e-4


def test_tight_reference_takes_the_tightest_tolerance_reached(monkeypatch):
    qp, _ = _standing_qp("solo12")
    asked = []

    def reaches(loosest):
        def solve(qp, tol):
            asked.append(tol)
            if tol < loosest:
                raise ReferenceSolveError(f"AlmostSolved at {tol:g}")
            return np.full(qp.n, tol)
        return solve

    monkeypatch.setattr(wbc_qp, "solve_reference", reaches(1e-10))
    assert solve_tight_reference(qp)[0] == 1e-10
    assert asked == [1e-12, 1e-11, 1e-10]
    monkeypatch.setattr(wbc_qp, "solve_reference", reaches(1e-8))
    with pytest.raises(ReferenceSolveError, match="1e-09"):
        solve_tight_reference(qp)
    assert REFERENCE_TOLERANCES[-1] == 1e-9


def test_deterministic_for_a_seed(small_set):
    again = generate_test_set("solo12", MIX, 40, seed=3, seq_len=10)
    for a, b in zip(small_set.qps, again.qps, strict=True):
        np.testing.assert_array_equal(a.P, b.P)
        np.testing.assert_array_equal(a.b, b.b)
    other = generate_test_set("solo12", MIX, 10, seed=4, seq_len=10)
    assert not np.array_equal(other.qps[-1].b, small_set.qps[9].b)
    assert sorted(set(small_set.sequence.tolist())) == [0, 1, 2, 3]


def test_npz_round_trip_is_exact(small_set, tmp_path):
    path = tmp_path / "set.npz"
    save(small_set, path)
    back = load(path)
    assert (back.robot, back.scenario, back.seed, back.dt) == (
        small_set.robot,
        small_set.scenario,
        small_set.seed,
        small_set.dt,
    )
    np.testing.assert_array_equal(back.sequence, small_set.sequence)
    for a, b, xa, xb in zip(small_set.qps, back.qps, small_set.x_ref, back.x_ref, strict=True):
        for name in ("P", "q", "A", "b", "lb", "ub", "cone_starts", "mus", "normals"):
            np.testing.assert_array_equal(getattr(a, name), getattr(b, name))
        assert a.layout == b.layout and a.nv == b.nv
        np.testing.assert_array_equal(xa, xb)


@pytest.mark.parametrize("facets", [4, 8])
@pytest.mark.parametrize("tilted", [False, True])
def test_inner_pyramid_lies_inside_the_exact_cone(facets, tilted):
    qp, _ = _standing_qp("solo12")
    if tilted:
        normals = np.tile([0.2, -0.3, 1.0], (qp.n_contacts, 1))
        qp = WbcQP(
            **{k: getattr(qp, k) for k in ("P", "q", "A", "b", "lb", "ub", "cone_starts", "mus")},
            normals=normals / np.linalg.norm(normals, axis=1, keepdims=True),
            layout=qp.layout,
            nv=qp.nv,
        )
    G, h = qp.pyramid(facets)
    assert G.shape == ((facets + 1) * qp.n_contacts, qp.n)
    rng = np.random.default_rng(1)
    inside = 0
    for _ in range(500):
        x = np.zeros(qp.n)
        s = qp.cone_starts[rng.integers(qp.n_contacts)]
        x[s : s + 3] = rng.uniform(-1, 1, 3)
        if np.all(G @ x <= h):
            inside += 1
            assert qp.cone_violation(x) <= 1e-12
    assert inside > 0
    # A force on the exact cone boundary along a facet direction is outside the inner
    # pyramid and inside the outer one.
    x = np.zeros(qp.n)
    f = qp.mus[0] * np.array([1.0, 0.0, 0.0]) + np.array([0.0, 0.0, 1.0])
    if not tilted:
        x[qp.cone_starts[0] : qp.cone_starts[0] + 3] = f
        assert qp.cone_violation(x) <= 1e-12
        assert np.any(G @ x > 1e-12)
        G_out, h_out = qp.pyramid(facets, inner=False)
        assert np.all(G_out @ x <= h_out + 1e-12)


def test_violation_helpers():
    qp, _ = _standing_qp("solo12")
    x = np.zeros(qp.n)
    s = qp.cone_starts[1]
    x[s : s + 3] = [3.0, 4.0, 1.0]  # ||f_t|| = 5, mu f_n = 0.7
    assert qp.cone_violation(x) == pytest.approx(5.0 - 0.7)
    x[qp.layout["u"].start] = qp.ub[qp.layout["u"].start] + 0.5
    assert qp.bound_violation(x) == pytest.approx(0.5)
    assert qp.equality_residual(x) == pytest.approx(np.abs(qp.A @ x - qp.b).max())
    with pytest.raises(ValueError, match="inconsistent shapes"):
        WbcQP(
            qp.P,
            qp.q[:-1],
            qp.A,
            qp.b,
            qp.lb,
            qp.ub,
            qp.cone_starts,
            qp.mus,
            qp.normals,
            qp.layout,
            qp.nv,
        )


def test_bad_arguments_raise():
    with pytest.raises(ValueError, match="unknown scenario"):
        generate_test_set("solo12", "dance", 5, 0)
    with pytest.raises(KeyError, match="unknown robot"):
        load_robot("r2d2")


@pytest.mark.parametrize("name", sorted(ROBOTS))
def test_active_fraction_of_the_default_mix(name):
    """At least half the QPs of the default mix have an active cone or torque limit."""
    ts = generate_test_set(name, MIX, 200, seed=0)
    flags = [active_flags(qp, x) for qp, x in zip(ts.qps, ts.x_ref, strict=True)]
    assert any(c for c, _ in flags)
    assert active_fraction(ts) >= 0.5
