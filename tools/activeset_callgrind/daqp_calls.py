"""DAQP solves of the benchmark's pyramid QPs, one callgrind dump per solve.

For QPs 10, 20, ..., 90 of each robot's cached test set: DAQP cold; the previous QP
cold (to get its multipliers); the QP warm from them (``dual_start``, the warm path);
QP ``i - 10`` cold; the QP warm from its multipliers (the every-10th path). The calls'
order, iterations and sizes go to ``--out`` (JSON); run under callgrind with a dump
after each ``daqp_quadprog`` (DAQP's C entry point), the n-th dump is the n-th call::

    valgrind --tool=callgrind --collect-atstart=no --toggle-collect=daqp_quadprog \\
        --dump-after=daqp_quadprog --callgrind-out-file=/tmp/daqp.%p \\
        python tools/activeset_callgrind/daqp_calls.py go2 talos_reduced

(the counts are DAQP's solve alone, without its Python wrapper).
"""

import argparse
import json

import daqp
import numpy as np
from benchmarks import testsets
from benchmarks.pyramid_solvers import DaqpAdapter
from threadpoolctl import threadpool_limits


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("robots", nargs="+")
    parser.add_argument("--cache", default="/tmp/fullrun/benchmarks/.cache")
    parser.add_argument("--out", default="/tmp/daqp_calls.json")
    args = parser.parse_args()
    out = []
    with threadpool_limits(1):
        for robot in args.robots:
            ts = testsets.load(
                f"{args.cache}/{robot}-mix-seed0-n400-len100-dt0.002-gen2.npz")
            ad = DaqpAdapter("daqp")
            for i in range(10, 100, 10):
                d = ad.prepare(ts.qps[i]).arguments
                size = d[0].shape[0]
                _, _, _, info = daqp.solve(*d)
                out.append((robot, i, "cold", int(info["iterations"]), size))
                for back, mode in ((1, "warm"), (10, "coarse")):
                    before = ad.prepare(ts.qps[i - back]).arguments
                    _, _, _, info0 = daqp.solve(*before)
                    out.append((robot, i - back, f"prev{back}", int(info0["iterations"]), size))
                    if before[0].shape == d[0].shape:
                        _, _, _, info = daqp.solve(*d, dual_start=np.array(info0["lam"]))
                        out.append((robot, i, mode, int(info["iterations"]), size))
    with open(args.out, "w") as fh:
        json.dump(out, fh)


if __name__ == "__main__":
    main()
