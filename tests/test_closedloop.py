"""The closed-loop MuJoCo benchmark: model agreement with Pinocchio and a standing smoke run."""

from __future__ import annotations

import numpy as np
import pinocchio as pin
import pytest

mujoco = pytest.importorskip("mujoco")

from benchmarks.cli import main  # noqa: E402
from benchmarks.closedloop.metrics import summarize  # noqa: E402
from benchmarks.closedloop.model import build_sim_model  # noqa: E402
from benchmarks.closedloop.scenarios import Phase, Scenario, make_scenario  # noqa: E402
from benchmarks.closedloop.simulate import run  # noqa: E402
from benchmarks.robots import load_robot  # noqa: E402
from benchmarks.testsets import CLOSEDLOOP, generate_test_set  # noqa: E402

_LWA = pin.ReferenceFrame.LOCAL_WORLD_ALIGNED


def _relative(a: np.ndarray, b: np.ndarray) -> float:
    return float(np.max(np.abs(a - b)) / np.max(np.abs(b)))


@pytest.mark.parametrize("name", ["go2", "solo12", "talos_reduced"])
def test_mujoco_model_agrees_with_pinocchio(name: str) -> None:
    """Mass matrix, bias forces and contact Jacobians agree to 1e-6 at 5 random states.

    MuJoCo's free-joint velocity has its linear part in the world frame, so its matrices
    are mapped with ``v_mj = T v_pin``: ``M = T' M_mj T``, and the bias also carries the
    ``M_mj dT/dt v`` term of that change of coordinates.
    """
    robot = load_robot(name)
    sim = build_sim_model(robot, 0.7, 0.001)
    model, pdata = robot.model, robot.model.createData()
    data = mujoco.MjData(sim.model)
    rng = np.random.default_rng(0)
    for _ in range(5):
        q = pin.integrate(model, robot.q0, rng.normal(scale=0.5, size=model.nv))
        v = rng.normal(size=model.nv)
        sim.set_state(data, q, v)
        q_back, v_back = sim.to_pinocchio(data)
        np.testing.assert_allclose(q_back, q, atol=1e-12)
        np.testing.assert_allclose(v_back, v, atol=1e-12)
        T = sim.velocity_map(data)
        M_mj = np.zeros((model.nv, model.nv))
        mujoco.mj_fullM(sim.model, data, M_mj)
        M = pin.crba(model, pdata, q)
        M = np.triu(M) + np.triu(M, 1).T
        assert _relative(T.T @ M_mj @ T, M) < 1e-6
        drift = np.zeros(model.nv)  # d/dt of (R v_lin) at zero acceleration
        drift[:3] = T[:3, :3] @ np.cross(v[3:6], v[:3])
        h = pin.nonLinearEffects(model, pdata, q, v)
        assert _relative(T.T @ (data.qfrc_bias + M_mj @ drift), h) < 1e-6
        pin.computeJointJacobians(model, pdata, q)
        pin.updateFramePlacements(model, pdata)
        for foot, frames in robot.contact_frames.items():
            for fid, geom in zip(frames, sim.foot_geoms[foot], strict=True):
                jac_p, jac_r = np.zeros((3, model.nv)), np.zeros((3, model.nv))
                mujoco.mj_jacGeom(sim.model, data, jac_p, jac_r, geom)
                J = pin.getFrameJacobian(model, pdata, fid, _LWA)[:3]
                assert _relative(jac_p @ T, J) < 1e-6
                np.testing.assert_allclose(data.geom_xpos[geom], pdata.oMf[fid].translation,
                                           atol=1e-12)


def test_standing_smoke_run_keeps_go2_up() -> None:
    """go2 stands 0.2 s at 500 Hz with fccqp's realtime preset: every answer applied, upright."""
    robot = load_robot("go2")
    feet = tuple(f.name for f in robot.config.feet)
    scenario = Scenario("stand", "go2", (Phase(0.2, feet),), floor_mu=0.7)
    trace = run(build_sim_model(robot, 0.7, 0.001), scenario, "fccqp-realtime", 0.002)
    summary = summarize(trace)
    assert summary.completed and summary.ticks == 100
    assert summary.failed == 0
    assert summary.com_max < 0.01
    assert np.all(np.asarray(trace.n_contacts) == 4)


def test_lift_scenario_switches_contacts() -> None:
    """The quadruped lift drops one foot's cone from the stance and puts it back."""
    robot = load_robot("go2")
    scenario = make_scenario(robot, "lift", 0.7)
    stances = [len(scenario.reference(t).stance) for t in np.arange(0.0, scenario.duration, 0.01)]
    assert set(stances) == {3, 4}
    assert stances[0] == stances[-1] == 4
    with pytest.raises(ValueError, match="known"):
        make_scenario(robot, "shift", 0.7)


def test_closedloop_test_set_logs_windows_around_events() -> None:
    """The ``closedloop`` test set: QPs from the MuJoCo loop, references that solve them.

    Seed 2 draws early events (the first push at 0.5 s, the lift's weight shift at 1 s),
    so the loop runs only about 750 ticks before and between the windows.
    """
    ts = generate_test_set("go2", CLOSEDLOOP, 6, 2, seq_len=3)
    assert len(ts) == 6 and ts.scenario == CLOSEDLOOP
    assert list(ts.sequence) == [0, 0, 0, 1, 1, 1]
    assert len(ts.stance) == 6 and all(len(s) in (3, 4) for s in ts.stance)
    for qp, x in zip(ts.qps, ts.x_ref, strict=True):
        assert qp.equality_residual(x) < 1e-6 and qp.cone_violation(x) < 1e-6


def test_cli_writes_report_csv_and_cdf(tmp_path) -> None:
    """``python -m benchmarks closedloop`` with one short run writes every output file."""
    report = main(["closedloop", "--scenarios", "stand", "--solvers", "fccqp-realtime",
                   "--fractions", "--out", str(tmp_path)])
    text = report.read_text()
    assert "| stand | fccqp-realtime | yes |" in text
    assert "python -m benchmarks closedloop --scenarios stand" in text
    assert (tmp_path / "cdf_go2_500hz.png").exists()
    assert (tmp_path / "results.csv").read_text().count("\n") == 2
