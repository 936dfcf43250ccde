"""Sizes of the two benchmark runs, shared by the benchmark, the qpbenchmark export and the
documentation (``tests/test_benchmark_report.py`` checks that ``--help`` and
docs/benchmarks.md give these sizes)."""

from __future__ import annotations

from dataclasses import dataclass

__all__ = ["PRESETS", "Preset"]


@dataclass(frozen=True)
class Preset:
    """Sizes of a run: QPs per robot, ticks per sequence, timing passes."""

    n_qps: int
    seq_len: int
    repeats: int


PRESETS: dict[str, Preset] = {
    # 4 sequences of 15 ticks: one of each scenario of the mix; every variant and view (the
    # coarse views walk the full preset's sets), test sets generated, in about 3 minutes of
    # CPU time: within 5 minutes on 2 cores.
    "quick": Preset(n_qps=60, seq_len=15, repeats=3),
    # 4 sequences of 100 ticks (the generator's default length).
    "full": Preset(n_qps=400, seq_len=100, repeats=10),
}
