"""Count the compiled presolve and recovery (``presolve.pyx``) under callgrind.

Build in place, then run under valgrind; only ``Context.run`` is collected, so the
count is the presolve and the recovery of the ``--qps`` QPs of a robot's full set (each
a ``def`` call into the compiled module, a few hundred instructions of call overhead)::

    cd tools/elimination_callgrind && cythonize -i -3 presolve.pyx && cd -
    valgrind --tool=callgrind --collect-atstart=no --toggle-collect=context_run \\
        --dump-after=context_run --callgrind-out-file=/tmp/pre.cg \\
        python tools/elimination_callgrind/run.py --robot go2 --kind slacks

Each QP's presolve and recovery are separate dumps (``/tmp/pre.cg.1``, ``.2``, ...:
presolve of QP 1, recovery of QP 1, ...). Without valgrind the script checks the compiled
reduction against ``tools/elimination_study.py``'s.
"""

import argparse
import contextvars
import sys
from pathlib import Path

import numpy as np
from threadpoolctl import threadpool_limits

HERE = Path(__file__).resolve().parent
sys.path[:0] = [str(HERE), str(HERE.parent)]
from elimination_study import NAMES, ROOT, eliminate, load_set  # noqa: E402
from presolve import Presolve  # noqa: E402


def main() -> None:
    parser = argparse.ArgumentParser()
    parser.add_argument("--robot", default="go2")
    parser.add_argument("--kind", choices=("all", "slacks"), default="slacks")
    parser.add_argument("--qps", type=int, nargs="+", default=[0, 100, 200, 300])
    args = parser.parse_args()
    threadpool_limits(1)
    qps, _ = load_set(args.robot, ROOT / "benchmarks" / ".cache")
    run = contextvars.copy_context().run
    for i in args.qps:
        d = qps[i]
        e = eliminate(*(d[k] for k in NAMES[:7]), keep_slacks=args.kind == "slacks")
        work = Presolve(e.free, e.kept, e.rows, e.rest)
        P, A = np.asfortranarray(d["P"]), np.asfortranarray(d["A"])
        q, b = d["q"], d["b"]
        x, y = np.zeros(P.shape[0]), np.zeros(A.shape[0])
        xc, yr = d["x_ref"][e.kept].copy(), np.zeros(e.rest.size)
        assert run(work.presolve, P, q, A, b) == 0
        assert run(work.recover, P, q, A, b, xc, yr, x, y) == 0
        print(f"QP {i}: n' {e.kept.size}, m' {e.rest.size}; relative differences P' "
              f"{gap(work.Pr, e.P):.1e}, q'' {gap(work.qr, e.q):.1e}, A' {gap(work.Ar, e.A):.1e}"
              f", x {gap(x, d['x_ref']):.1e}")


def gap(a: np.ndarray, b: np.ndarray) -> float:
    """``max |a - b| / (1 + max |b|)``."""
    return float(np.abs(a - b).max(initial=0) / (1 + np.abs(b).max(initial=0)))


if __name__ == "__main__":
    main()
