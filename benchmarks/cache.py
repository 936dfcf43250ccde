"""Generated test sets cached as npz files, so that a second run skips the generation.

A cache entry is one :func:`benchmarks.testsets.save` file whose name holds everything
that determines the set: robot, scenario, seed, size, sequence length, controller
period and :data:`benchmarks.testsets.GENERATOR_VERSION`. Bumping the version (any
change of the generator that changes its QPs) makes every old entry a miss; the version
is also stored in the file and checked on load, so a renamed file cannot pass for a
current one.
"""

from __future__ import annotations

import os
from collections.abc import Callable
from pathlib import Path

from benchmarks import testsets
from benchmarks.testsets import TestSet, generate_test_set, load, save

__all__ = ["DEFAULT_CACHE", "cache_path", "cached_test_set"]

DEFAULT_CACHE = Path(__file__).resolve().parent / ".cache"
"""Default cache folder (ignored by git)."""


def cache_path(
    folder: Path, robot: str, scenario: str, n_qps: int, seed: int, seq_len: int, dt: float,
) -> Path:
    """The file a test set with these parameters is cached in (current generator version)."""
    version = testsets.GENERATOR_VERSION
    name = f"{robot}-{scenario}-seed{seed}-n{n_qps}-len{seq_len}-dt{dt:g}-gen{version}.npz"
    return folder / name


def cached_test_set(
    folder: Path,
    robot: str,
    scenario: str,
    n_qps: int,
    seed: int,
    *,
    seq_len: int,
    dt: float = 0.002,
    verbose: bool = False,
    report: Callable[[str], None] = print,
) -> tuple[TestSet, bool]:
    """Load the test set from ``folder`` or generate and store it; say which happened.

    Returns the set and whether it came from the cache. ``report`` receives one line
    naming the file (load or write).
    """
    path = cache_path(folder, robot, scenario, n_qps, seed, seq_len, dt)
    if path.exists():
        test_set = load(path)
        if test_set.generator_version == testsets.GENERATOR_VERSION:
            report(f"{robot}: test set loaded from cache {path}")
            return test_set, True
    test_set = generate_test_set(
        robot, scenario, n_qps, seed, dt=dt, seq_len=seq_len, verbose=verbose
    )
    folder.mkdir(parents=True, exist_ok=True)
    partial = path.with_suffix(f".{os.getpid()}.tmp.npz")
    save(test_set, partial)
    partial.replace(path)  # atomic: a run cut short leaves no half-written entry
    report(f"{robot}: test set generated and cached as {path}")
    return test_set, False
