"""Startup cost of fccqp: `import fccqp`, then the first solve, in fresh processes.

Run ``python benchmarks/startup.py [--runs N]``; it prints the median over ``N`` fresh
interpreters (numba's kernel cache warm: one untimed run first fills it).
"""

from __future__ import annotations

import argparse
import statistics
import subprocess
import sys

_PROBE = """
import time
t0 = time.perf_counter()
import fccqp
t1 = time.perf_counter()
import numpy as np
P = np.diag([1.0, 1.0, 1e-3, 1e-3, 1e-3])
A = np.array([[1.0, 0, -1, 0, 0], [0, 1, 0, -1, 0], [0, 0, 0, 0, 1]])
lb, ub = np.array([-6, -6] + [-np.inf] * 3), np.array([6, 6] + [np.inf] * 3)
fccqp.solve(P, [-8.0, 0, 0, 0, 0], A, [0.0, 0, 10], lb, ub, [fccqp.FrictionCone(2, 0.5)])
t2 = time.perf_counter()
print(t1 - t0, t2 - t1)
"""


def main() -> None:
    """Time ``import fccqp`` and the first solve over fresh interpreters; print medians."""
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--runs", type=int, default=10, help="fresh processes (default 10)")
    runs = parser.parse_args().runs
    if runs < 1:
        parser.error("--runs must be >= 1")
    samples = []
    for _ in range(runs + 1):
        out = subprocess.run([sys.executable, "-c", _PROBE], capture_output=True, text=True)
        out.check_returncode()
        samples.append(tuple(float(v) for v in out.stdout.split()))
    imports, solves = zip(*samples[1:], strict=True)
    print(f"import fccqp: median {statistics.median(imports):.3f} s over {runs} processes")
    print(f"first solve:  median {statistics.median(solves):.3f} s (numba cache warm)")


if __name__ == "__main__":
    main()
