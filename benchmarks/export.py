"""``python -m benchmarks export --qpbenchmark DIR``: the pyramid test set for qpbenchmark.

qpbenchmark (the qpsolvers project's benchmark tool) runs every solver qpsolvers knows
on a *test set*: a folder with the problems as ``data/<name>.npz`` (the arrays ``P, q,
G, h, A, b, lb, ub`` of ``qpsolvers.Problem.save``), a ``results/`` folder, and a Python
file whose class, named after the file in PascalCase, derives from
``qpbenchmark.TestSet`` and yields the problems. qpsolvers has no cones, so the
exported problems carry the 4-facet inner pyramid as ``G x <= h`` (the problem the
``qpsolvers:*`` variants solve). The script also adds fccqp to qpbenchmark's known
solvers with its tolerance per qpbenchmark setting, because qpbenchmark only runs the
solvers it has settings for. How to run it: docs/benchmarks.md.
"""

from __future__ import annotations

import argparse
from collections.abc import Sequence
from pathlib import Path

import numpy as np

from benchmarks.cache import DEFAULT_CACHE, cached_test_set
from benchmarks.presets import PRESETS
from benchmarks.robots import ROBOTS
from benchmarks.testsets import MIX, TestSet

__all__ = ["SCRIPT_NAME", "build_parser", "main", "write_qpbenchmark"]

SCRIPT_NAME = "wbc_pyramid_qpbenchmark.py"
"""File name of the test-set script; qpbenchmark expects the class ``WbcPyramidQpbenchmark``."""

_SCRIPT = '''"""Whole-body-control QPs of real robots with 4-facet inner friction pyramids.

Written by ``{command}`` from the fccqp repository: {description}.
"""

import os

from qpbenchmark.problem import Problem
from qpbenchmark.solver_settings import SolverSettings
from qpbenchmark.test_set import TestSet

try:
    import fccqp  # noqa: F401  (registers the "fccqp" backend of qpsolvers)
except ImportError:
    pass
else:
    SolverSettings.IMPLEMENTED_SOLVERS.add("fccqp")

# fccqp's tolerance for each of qpbenchmark's settings (None: fccqp's defaults).
FCCQP_EPS = {{"default": None, "low_accuracy": 1e-3, "mid_accuracy": 1e-6,
             "high_accuracy": 1e-9}}


class WbcPyramidQpbenchmark(TestSet):
    """Whole-body-control QPs ({description})."""

    @property
    def description(self) -> str:
        return "Whole-body-control QPs of legged robots, 4-facet inner friction pyramids."

    @property
    def title(self) -> str:
        return "Whole-body-control (pyramid) test set"

    @property
    def sparse_only(self) -> bool:
        return False

    def define_solver_settings(self) -> None:
        super().define_solver_settings()
        for name, settings in self.solver_settings.items():
            settings.set_param("fccqp", "time_limit", self.tolerances[name].runtime)
            if FCCQP_EPS.get(name) is not None:
                settings.set_param("fccqp", "eps_abs", FCCQP_EPS[name])
                settings.set_param("fccqp", "eps_rel", 0.0)

    def __iter__(self):
        data = os.path.join(os.path.dirname(os.path.abspath(__file__)), "data")
        for fname in sorted(os.listdir(data)):
            if fname.endswith(".npz"):
                yield Problem.load(os.path.join(data, fname))  # named after the file
'''


def problem_arrays(test_set: TestSet, i: int) -> dict[str, np.ndarray]:
    """QP ``i`` of ``test_set`` in qpsolvers' file layout, friction cones as a pyramid."""
    qp = test_set.qps[i]
    G, h = qp.pyramid(facets=4, inner=True)
    return {"P": qp.P, "q": qp.q, "G": G, "h": h, "A": qp.A, "b": qp.b, "lb": qp.lb, "ub": qp.ub}


def write_qpbenchmark(sets: Sequence[TestSet], folder: Path, command: str) -> Path:
    """Write ``sets`` as one qpbenchmark test set in ``folder``; return the script's path.

    Problems are named ``<robot>_<scenario>_seed<seed>_<index>``.
    """
    data = folder / "data"
    data.mkdir(parents=True, exist_ok=True)
    (folder / "results").mkdir(exist_ok=True)
    for ts in sets:
        for i in range(len(ts)):
            name = f"{ts.robot}_{ts.scenario}_seed{ts.seed}_{i:04d}"
            np.savez(data / f"{name}.npz", **problem_arrays(ts, i))
    description = ", ".join(f"{ts.robot} {ts.scenario} seed {ts.seed}: {len(ts)} QPs"
                            for ts in sets)
    script = folder / SCRIPT_NAME
    script.write_text(_SCRIPT.format(command=command, description=description))
    return script


def build_parser() -> argparse.ArgumentParser:
    """The parser of ``python -m benchmarks export``."""
    parser = argparse.ArgumentParser(
        prog="python -m benchmarks export",
        description="Write the pyramid version of the test sets as a qpbenchmark test set.",
    )
    parser.add_argument("--qpbenchmark", type=Path, required=True, metavar="DIR",
                        help="folder of the qpbenchmark test set (created)")
    parser.add_argument("--robots", nargs="+", choices=list(ROBOTS), default=list(ROBOTS),
                        metavar="ROBOT", help=f"robots (default all: {', '.join(ROBOTS)})")
    quick = PRESETS["quick"]
    parser.add_argument("--n-qps", type=int, default=quick.n_qps,
                        help=f"QPs per robot (default {quick.n_qps}, the quick preset's)")
    parser.add_argument("--seq-len", type=int, default=quick.seq_len,
                        help=f"ticks per sequence (default {quick.seq_len})")
    parser.add_argument("--seed", type=int, default=0, help="test-set seed (default 0)")
    parser.add_argument("--cache", type=Path, default=DEFAULT_CACHE,
                        help="folder of cached test sets (default benchmarks/.cache)")
    return parser


def main(argv: Sequence[str]) -> Path:
    """Export the test sets named by ``argv``; return the test-set script's path."""
    parser = build_parser()
    args = parser.parse_args(argv)
    if args.n_qps < 1 or args.seq_len < 1:
        parser.error("--n-qps and --seq-len must be positive")
    sets = [
        cached_test_set(args.cache, robot, MIX, args.n_qps, args.seed, seq_len=args.seq_len)[0]
        for robot in args.robots
    ]
    command = " ".join(["python -m benchmarks export", *argv])
    script = write_qpbenchmark(sets, args.qpbenchmark, command)
    print(f"wrote {sum(len(ts) for ts in sets)} problems and {script}")
    return script
