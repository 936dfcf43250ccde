"""The test-set cache: a miss generates and stores, a hit loads, a new generator
version invalidates."""

from __future__ import annotations

import numpy as np
import pytest
from benchmarks import testsets
from benchmarks.cache import cache_path, cached_test_set

ARGS = ("solo12", "mix", 3, 5)  # robot, scenario, QPs, seed


def _get(folder):
    messages: list[str] = []
    ts, hit = cached_test_set(folder, *ARGS, seq_len=2, report=messages.append)
    return ts, hit, messages


def test_miss_then_hit_round_trips_the_set(tmp_path):
    first, hit, messages = _get(tmp_path)
    assert not hit and "generated" in messages[0]
    assert cache_path(tmp_path, *ARGS[:2], 3, 5, 2, 0.002).exists()
    second, hit, messages = _get(tmp_path)
    assert hit and "loaded from cache" in messages[0]
    assert second.generator_version == testsets.GENERATOR_VERSION
    np.testing.assert_array_equal(first.sequence, second.sequence)
    for a, b, xa, xb in zip(first.qps, second.qps, first.x_ref, second.x_ref, strict=True):
        np.testing.assert_array_equal(a.P, b.P)
        np.testing.assert_array_equal(a.A, b.A)
        np.testing.assert_array_equal(xa, xb)


def test_other_parameters_miss(tmp_path):
    _get(tmp_path)
    _, hit = cached_test_set(tmp_path, "solo12", "mix", 3, 6, seq_len=2, report=lambda _: None)
    assert not hit


def test_new_generator_version_invalidates(tmp_path, monkeypatch: pytest.MonkeyPatch):
    _get(tmp_path)
    old = cache_path(tmp_path, *ARGS[:2], 3, 5, 2, 0.002)
    monkeypatch.setattr(testsets, "GENERATOR_VERSION", testsets.GENERATOR_VERSION + 1)
    new = cache_path(tmp_path, *ARGS[:2], 3, 5, 2, 0.002)
    assert new != old
    ts, hit, _ = _get(tmp_path)
    assert not hit and ts.generator_version == testsets.GENERATOR_VERSION
    # A stale file under the new name is caught by the version stored inside it.
    old.replace(new)
    _, hit, _ = _get(tmp_path)
    assert not hit
