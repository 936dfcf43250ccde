"""The measurement scripts' core functions on a tiny input (no timing assertions)."""

from __future__ import annotations

import math

import pytest
from benchmarks import determinism, startup, under_load
from benchmarks.testsets import MIX, generate_test_set, save


@pytest.fixture(scope="module")
def tiny():
    """Four solo12 QPs in two warm sequences of two."""
    return generate_test_set("solo12", MIX, 4, 0, seq_len=2)


def test_cpu_load_starts_and_stops_its_processes() -> None:
    with under_load.cpu_load(2, max_seconds=30) as procs:
        assert len(procs) == 2
        assert all(p.poll() is None for p in procs)
    assert all(p.poll() is not None for p in procs)


def test_busy_cpus_is_a_cpu_count_or_none() -> None:
    busy = under_load.busy_cpus(0.05)
    assert busy is None or busy >= 0.0


def test_under_load_measures_each_state_and_skips_unknown(tiny) -> None:
    names = ["fccqp-realtime", "daqp-pyr4", "no-such-solver"]
    res = under_load.measure(tiny, names, rounds=2, load=1, max_seconds=30, warmup=1)
    assert "fccqp-realtime" in res.unloaded
    assert "no-such-solver" in res.skipped
    for name in res.unloaded:
        assert len(res.unloaded[name]) == len(res.loaded[name]) == len(tiny)
        assert math.isfinite(res.ratio(name)) and res.ratio(name) > 0
    table = under_load.format_table(res, 1)
    assert "fccqp-realtime" in table and "no-such-solver" in table
    assert isinstance(under_load.format_blas(under_load.blas_info()), str)


def test_under_load_needs_both_states(tiny) -> None:
    with pytest.raises(ValueError, match="rounds"):
        under_load.measure(tiny, ["fccqp-realtime"], rounds=1)


def test_same_sequence_is_bit_identical_in_process(tiny) -> None:
    a = determinism.run_sequence(tiny, "realtime")
    b = determinism.run_sequence(tiny, "realtime")
    assert len(a) == len(tiny)
    assert determinism.first_difference(a, b) is None
    assert determinism.digest(a) == determinism.digest(b)


def test_first_difference_names_the_field(tiny) -> None:
    a = determinism.run_sequence(tiny, "default")
    b = list(a)
    x, y, z, it, status = b[1]
    b[1] = (x, y, z, it + 1, status)
    assert determinism.first_difference(a, b) == "QP 1: iterations differs"
    assert determinism.digest(a) != determinism.digest(b)


def test_child_process_gives_the_same_digest(tiny, tmp_path) -> None:
    path = tmp_path / "set.npz"
    save(tiny, path)
    child = determinism.child_digests(path, ["realtime"])
    assert child["realtime"] == determinism.digest(determinism.run_sequence(tiny, "realtime"))


def test_allocations_report(tiny) -> None:
    al = determinism.allocations(tiny, "realtime")
    assert al.solves == len(tiny)
    assert al.result_array_bytes > 0
    assert al.peak_bytes >= al.result_array_bytes
    assert al.retained_blocks >= al.retained_python_blocks >= 0


def test_startup_probe_runs_in_a_fresh_process() -> None:
    imp, first, second = startup.run_once()
    assert imp > 0 and first > 0 and second > 0
    with pytest.raises(ValueError):
        startup.measure(0)
