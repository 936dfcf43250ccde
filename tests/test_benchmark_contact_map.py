"""The previous answer carried across a contact change by the contact points
(benchmarks/contact_map.py), and the adapters that hand it to fccqp and DAQP."""

from __future__ import annotations

import numpy as np
import pytest
from benchmarks.contact_map import ContactMaps, carried, contact_map
from benchmarks.exact_solvers import FccqpAdapter, carried_guess
from benchmarks.robots import contact_point_names, load_robot
from benchmarks.testsets import MIX, generate_test_set, load, save
from benchmarks.wbc_qp import TaskCommands, WbcQP, build_wbc_qp

import fccqp


def _standing_qp(name: str, stance: tuple[str, ...]) -> WbcQP:
    """QP at the SRDF posture, at rest, with the feet ``stance`` down."""
    robot = load_robot(name)
    model = robot.model
    feet = [foot.name for foot in robot.config.feet if foot.name in stance]
    contacts = [fid for foot in feet for fid in robot.contact_frames[foot]]
    commands = TaskCommands(com=np.zeros(3), base_angular=np.zeros(3),
                            posture=np.zeros(model.nv - 6))
    return build_wbc_qp(model, model.createData(), robot.q0, np.zeros(model.nv), commands,
                        contacts, robot.config.mu, hand=robot.hand_frame,
                        hand_dim=robot.config.hand_dim)


def _lifted_and_down(name: str) -> tuple[WbcQP, WbcQP]:
    """The QPs with the robot's second foot lifted and with every foot down."""
    feet = tuple(foot.name for foot in load_robot(name).config.feet)
    return _standing_qp(name, feet[:1] + feet[2:]), _standing_qp(name, feet)


def test_generated_and_loaded_qps_name_their_contact_points_alike(tmp_path):
    generated = generate_test_set("solo12", MIX, 40, seed=3, seq_len=10)
    save(generated, tmp_path / "set.npz")
    loaded = load(tmp_path / "set.npz")
    for i, stance in enumerate(generated.stance):
        names = contact_point_names("solo12", stance)
        assert len(names) == generated.qps[i].n_contacts
        assert generated.qps[i].contacts == names == loaded.qps[i].contacts


@pytest.mark.parametrize("name", ["solo12", "talos_reduced"])
def test_map_pairs_the_entries_and_rows_of_the_points_that_stay(name):
    """The same state with a foot put down: the kept entries' cost and constraint
    coefficients are the previous ones, the new foot's entries are marked new."""
    lifted, down = _lifted_and_down(name)
    cmap = contact_map(lifted, down)
    kept, was = np.flatnonzero(cmap.variables >= 0), cmap.variables[cmap.variables >= 0]
    rows, rows_were = np.flatnonzero(cmap.rows >= 0), cmap.rows[cmap.rows >= 0]
    new_points = down.n_contacts - lifted.n_contacts
    assert down.n - kept.size == 6 * new_points
    assert down.A.shape[0] - rows.size == 3 * new_points
    np.testing.assert_array_equal(down.P[np.ix_(kept, kept)], lifted.P[np.ix_(was, was)])
    np.testing.assert_array_equal(down.q[kept], lifted.q[was])
    np.testing.assert_array_equal(down.A[np.ix_(rows, kept)], lifted.A[np.ix_(rows_were, was)])
    np.testing.assert_array_equal(down.b[rows], lifted.b[rows_were])
    back = contact_map(down, lifted)   # the foot lifted again: every entry was there
    assert np.all(back.variables >= 0) and np.all(back.rows >= 0)
    np.testing.assert_array_equal(cmap.variables[back.variables], np.arange(lifted.n))


def test_carried_vector_is_zero_on_new_entries():
    np.testing.assert_array_equal(carried(np.array([5.0, 6.0, 7.0]), np.array([2, -1, 0])),
                                  [7.0, 0.0, 5.0])


def test_map_needs_named_contact_points():
    lifted, down = _lifted_and_down("solo12")
    anonymous = WbcQP(down.P, down.q, down.A, down.b, down.lb, down.ub, down.cone_starts,
                      down.mus, down.normals, down.layout, down.nv)
    with pytest.raises(ValueError, match="qp has 4 contacts but 0 named"):
        contact_map(lifted, anonymous)


def test_fccqp_adapter_starts_a_contact_change_from_the_carried_answer():
    """At the change the guess is the previous answer on the new layout; on the same
    contact points there is none (the solver's own warm start)."""
    lifted, down = _lifted_and_down("solo12")
    solver = fccqp.Solver()
    before = solver.solve(*FccqpAdapter("fccqp", fccqp.Settings()).prepare(lifted).arguments)
    maps = ContactMaps()
    guess = carried_guess(maps, (lifted, before), down)
    kept = contact_map(lifted, down).variables >= 0
    np.testing.assert_array_equal(guess["x0"][kept], before.x[contact_map(lifted, down)
                                                               .variables[kept]])
    assert np.all(guess["x0"][~kept] == 0) and guess["y0"].shape == (down.A.shape[0],)
    assert carried_guess(maps, (down, before), down) == {}
    assert carried_guess(maps, None, down) == {}
    adapter = FccqpAdapter("fccqp", fccqp.Settings())
    for qp in (lifted, down):
        assert adapter.solve(adapter.prepare(qp)).success


def test_daqp_adapter_carries_its_multipliers_across_a_contact_change():
    pytest.importorskip("daqp")
    from benchmarks.pyramid_solvers import DaqpAdapter

    lifted, down = _lifted_and_down("go2")
    adapter = DaqpAdapter("daqp")
    assert adapter.solve(adapter.prepare(lifted)).success
    _, lam = adapter._previous
    start = adapter._dual_start(down)
    cmap = contact_map(lifted, down)
    assert start.shape == (down.n + down.A.shape[0] + 5 * down.n_contacts,)
    pyramid = start[down.n + down.A.shape[0]:].reshape(-1, 5)
    before = lam[lifted.n + lifted.A.shape[0]:].reshape(-1, 5)
    for point, was in enumerate(cmap.points):
        np.testing.assert_array_equal(pyramid[point], before[was] if was >= 0 else 0.0)
    assert adapter.solve(adapter.prepare(down)).success
