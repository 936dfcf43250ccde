"""Startup cost of fccqp: ``import fccqp``, then the first solve, in fresh processes.

Each run is a new interpreter (one subprocess per run). It times ``import fccqp``, then
the first ``fccqp.Solver(...).solve(...)``, then a second solve of the same QP as a
steady-state reference. The script reports the median over the runs. The very first
process is reported apart: it is the one that pays any one-time cost at first use, such as
filling a JIT cache or compiling, so on a fresh install it is what a new user sees.
Issue #12's targets are ``import fccqp`` under 0.15 s and the first solve under 0.35 s.

The QP is a small built-in one (two bounded variables and a 3-D friction cone), or, with
``--robot``, the first QP of ``generate_test_set(robot, "mix", 1, seed)``. That QP is built
in this process and handed to the children through a temporary ``.npz`` file, which they
read after the import is timed. Only the public API is used.

Run ``python -m benchmarks.startup [--runs 10] [--robot solo12] [--realtime]``.
"""

from __future__ import annotations

import argparse
import os
import statistics
import subprocess
import sys
import tempfile
from collections.abc import Sequence
from pathlib import Path

__all__ = ["PROBE", "main", "measure", "run_once"]

PROBE = r"""
import sys, time
t0 = time.perf_counter()
import fccqp
t1 = time.perf_counter()
import numpy as np
if sys.argv[1] != "-":
    with np.load(sys.argv[1], allow_pickle=False) as f:
        d = {k: f[k] for k in f.files}
    cones = [fccqp.FrictionCone(int(s), float(mu), tuple(map(float, n)))
             for s, mu, n in zip(d["cone_starts"], d["mus"], d["normals"])]
    args = (d["P"], d["q"], d["A"], d["b"], d["lb"], d["ub"], cones)
else:
    P = np.diag([1.0, 1.0, 1e-3, 1e-3, 1e-3])
    A = np.array([[1.0, 0, -1, 0, 0], [0, 1, 0, -1, 0], [0, 0, 0, 0, 1]])
    lb, ub = np.array([-6, -6] + [-np.inf] * 3), np.array([6, 6] + [np.inf] * 3)
    args = (P, np.array([-8.0, 0, 0, 0, 0]), A, np.array([0.0, 0, 10]), lb, ub,
            [fccqp.FrictionCone(2, 0.5)])
realtime = sys.argv[2] == "realtime"
t2 = time.perf_counter()
solver = fccqp.Solver(fccqp.Settings.realtime() if realtime else fccqp.Settings())
r = solver.solve(*args)
t3 = time.perf_counter()
solver.reset()
solver.solve(*args)
t4 = time.perf_counter()
print(t1 - t0, t3 - t2, t4 - t3, r.status.value)
"""
"""The child's script. Arguments: a QP ``.npz`` (or ``-`` for the built-in QP) and the preset.
It prints the import, first-solve and second-solve seconds, and the status."""


def _write_qp(robot: str, seed: int, path: Path) -> None:
    import numpy as np

    from benchmarks.testsets import MIX, generate_test_set

    qp = generate_test_set(robot, MIX, 1, seed).qps[0]
    names = ("P", "q", "A", "b", "lb", "ub", "cone_starts", "mus", "normals")
    np.savez(path, **{name: np.asarray(getattr(qp, name)) for name in names})


def run_once(qp_path: Path | None = None, realtime: bool = False) -> tuple[float, ...]:
    """One fresh interpreter: (import s, first solve s, second solve s); raises on failure."""
    preset = "realtime" if realtime else "default"
    argv = [sys.executable, "-c", PROBE, str(qp_path) if qp_path else "-", preset]
    out = subprocess.run(argv, capture_output=True, text=True, env=dict(os.environ))
    if out.returncode != 0:
        raise RuntimeError(f"probe failed:\n{out.stderr}")
    fields = out.stdout.split()
    return tuple(float(v) for v in fields[:3])


def measure(runs: int, qp_path: Path | None = None, realtime: bool = False) -> dict:
    """``runs + 1`` fresh processes: the first one apart, medians over the other ``runs``."""
    if runs < 1:
        raise ValueError("runs must be >= 1")
    samples = [run_once(qp_path, realtime) for _ in range(runs + 1)]
    imports, firsts, seconds = zip(*samples[1:], strict=True)
    return {
        "first_process": samples[0],
        "import": statistics.median(imports),
        "first_solve": statistics.median(firsts),
        "second_solve": statistics.median(seconds),
        "runs": runs,
    }


def main(argv: Sequence[str] | None = None) -> None:
    """Time ``import fccqp`` and the first solve over fresh interpreters; print medians."""
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--runs", type=int, default=10, help="fresh processes (default 10)")
    parser.add_argument("--robot", help="use the first QP of this robot's mix test set")
    parser.add_argument("--seed", type=int, default=0)
    parser.add_argument("--realtime", action="store_true", help="Settings.realtime()")
    args = parser.parse_args(argv)
    if args.runs < 1:
        parser.error("--runs must be >= 1")
    with tempfile.TemporaryDirectory() as tmp:
        path = None
        if args.robot:
            path = Path(tmp) / "qp.npz"
            _write_qp(args.robot, args.seed, path)
        res = measure(args.runs, path, args.realtime)
    qp = f"first QP of {args.robot}" if args.robot else "built-in 5-variable QP"
    preset = "Settings.realtime()" if args.realtime else "Settings()"
    first = res["first_process"]
    print(f"{qp}, {preset}, {args.runs} fresh processes (+1 first, reported apart)")
    print(f"{'':14s} {'median s':>9s} {'first process s':>16s} {'target s':>9s}")
    print(f"{'import fccqp':14s} {res['import']:9.3f} {first[0]:16.3f} {0.15:9.2f}")
    print(f"{'first solve':14s} {res['first_solve']:9.3f} {first[1]:16.3f} {0.35:9.2f}")
    print(f"{'second solve':14s} {res['second_solve']:9.4f} {first[2]:16.4f} {'':>9s}")


if __name__ == "__main__":
    main()
