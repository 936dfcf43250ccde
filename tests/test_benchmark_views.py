"""The report's views: which QPs each path holds, where the solver is reset, which ticks
change contacts, and that a generated set records its stance."""

from __future__ import annotations

import numpy as np
import pytest
from benchmarks.testsets import TestSet, generate_test_set, load, save
from benchmarks.views import (
    CONTACT_CHANGE,
    coarse_path,
    cold_path,
    contact_changes,
    runs_every_view,
    ticks,
    view_rows,
    warm_path,
)

FEET = ("LF", "LH", "RF", "RH")


def _set(sequence: list[int], stance: list[tuple[str, ...]] | None = None) -> TestSet:
    n = len(sequence)
    return TestSet("solo12", "mix", 0, 0.002, [None] * n, [None] * n, np.array(sequence),
                   2, tuple(stance) if stance is not None else ())


def test_ticks_count_from_each_sequence_start():
    ts = _set([0, 0, 0, 1, 1, 2, 2, 2, 2])
    np.testing.assert_array_equal(ticks(ts), [0, 1, 2, 0, 1, 0, 1, 2, 3])


def test_warm_cold_and_coarse_paths():
    ts = _set([0] * 12 + [1] * 7)
    warm = warm_path(ts)
    np.testing.assert_array_equal(warm.indices, np.arange(19))
    assert np.flatnonzero(warm.fresh).tolist() == [0, 12]
    assert cold_path(ts).fresh.all()
    fifth = coarse_path(ts, 5)
    assert fifth.indices.tolist() == [0, 5, 10, 12, 17]
    assert fifth.fresh.tolist() == [True, False, False, True, False]
    assert fifth.view == "every 5th"
    assert coarse_path(ts, 10).indices.tolist() == [0, 10, 12]


def test_contact_changes_are_mid_sequence_stance_changes():
    """A new stance within a sequence is a contact change; the first QP of a sequence is
    not, whatever the previous sequence's stance."""
    lifted = FEET[:3]
    stance = [FEET, FEET, lifted, lifted, FEET, lifted, lifted]
    ts = _set([0, 0, 0, 0, 0, 1, 1], stance)
    assert np.flatnonzero(contact_changes(warm_path(ts))).tolist() == [2, 4]
    assert not contact_changes(cold_path(ts)).any()  # every QP is a fresh start there
    # The every-2nd path compares kept QPs: 0 (FEET), 2 (lifted), 4 (FEET); 5 restarts.
    changed = contact_changes(coarse_path(ts, 2))
    assert changed.tolist() == [False, True, True, False]


def test_a_set_without_stance_has_no_contact_view():
    with pytest.raises(ValueError, match="records no stance"):
        contact_changes(warm_path(_set([0, 0])))


def test_the_contact_view_selects_warm_contact_changes():
    rows = [{"view": "warm", "contact_change": False}, {"view": "warm", "contact_change": True},
            {"view": "cold", "contact_change": False}]
    assert view_rows(rows, CONTACT_CHANGE) == [rows[1]]
    assert view_rows(rows, "cold") == [rows[2]]


def test_sweeps_and_qpsolvers_calls_run_the_warm_view_only():
    assert runs_every_view("fccqp-realtime") and runs_every_view("daqp-pyr4")
    assert not runs_every_view("daqp-pyr4-loose") and not runs_every_view("qpsolvers:osqp")


def test_generated_set_records_stance_through_save_and_load(tmp_path):
    """contact_switch lifts one foot or trots: the stance changes mid-sequence."""
    ts = generate_test_set("solo12", "contact_switch", 12, seed=0, seq_len=12)
    assert len(ts.stance) == 12 and all(set(s) <= set(FEET) for s in ts.stance)
    assert contact_changes(warm_path(ts)).sum() == 1
    save(ts, tmp_path / "set.npz")
    assert load(tmp_path / "set.npz").stance == ts.stance
