"""Which DAQP call is fastest along the benchmark's sequences: ``daqp.solve`` warm started
with the previous QP's multipliers (``dual_start``, what the benchmark times) or a
persistent ``daqp.Model`` updated with each QP's data and solved from its own working set.

``python notes/daqp_model.py [--robots R ...] [--qps N] [--passes K]``: the 4-facet inner
pyramid of the ``mix`` test set (seed 0) of each robot, along its sequences (both start
afresh at each sequence and on a size change), the two calls alternating pass by pass in
one process with one BLAS thread; prints the median over QPs of each QP's median time.
"""

from __future__ import annotations

import argparse
import time

import daqp
import numpy as np
from benchmarks.solvers import make_adapter
from benchmarks.testsets import generate_test_set
from threadpoolctl import threadpool_limits


def _solve_pass(adapter, data, sequence) -> list[float]:
    out, previous = [], None
    for item, seq in zip(data, sequence, strict=True):
        if seq != previous:
            adapter.reset()
            previous = seq
        out.append(adapter.solve(item).time)
    return out


def _model_pass(data, sequence) -> list[float]:
    out, previous, model, shape = [], None, None, None
    for (H, f, A, bu, bl, sense), seq in zip(data, sequence, strict=True):
        start = time.perf_counter()
        if seq != previous or A.shape != shape:
            model = daqp.Model()
            model.setup(H, f, A, bu, bl, sense)
        else:
            model.update(H, f, A, bu, bl, sense)
        _, _, exitflag, _ = model.solve()
        out.append(time.perf_counter() - start)
        if exitflag != 1:
            raise RuntimeError(f"daqp.Model exit flag {exitflag}")
        previous, shape = seq, A.shape
    return out


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--robots", nargs="+", default=["go2", "talos_reduced"])
    parser.add_argument("--qps", type=int, default=400)
    parser.add_argument("--passes", type=int, default=5)
    args = parser.parse_args()
    with threadpool_limits(limits=1):
        for robot in args.robots:
            ts = generate_test_set(robot, "mix", args.qps, seed=0)
            adapter = make_adapter("daqp-pyr4")
            data = [adapter.prepare(qp) for qp in ts.qps]
            times = {"solve + dual_start": [], "Model + update": []}
            for _ in range(args.passes):
                times["solve + dual_start"].append(_solve_pass(adapter, data, ts.sequence))
                times["Model + update"].append(_model_pass(data, ts.sequence))
            for name, passes in times.items():
                per_qp = np.median(np.array(passes), axis=0)
                print(f"{robot}: {name}: median {1e6 * np.median(per_qp):.0f} us, "
                      f"p99 {1e6 * np.percentile(per_qp, 99, method='inverted_cdf'):.0f} us")


if __name__ == "__main__":
    main()
