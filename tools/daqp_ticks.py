"""DAQP's instructions per warm control tick, counted by callgrind as fccqp's are.

What: the instructions (callgrind's ``Ir``) of each DAQP solve of a robot's benchmark
test set (the ``--full`` preset's, cached in ``benchmarks/.cache``), warm along its
sequences as the benchmark runs DAQP (``benchmarks.pyramid_solvers.DaqpAdapter``: the
4-facet inner pyramid, the previous QP's multipliers as ``dual_start``, carried across a
contact change; a new adapter at each sequence start), or with ``--stride K`` only every
K-th QP of each sequence from its first, each warm from the previous kept one (the
benchmark's "every K-th" view, ``benchmarks.views.coarse_path``, as
``callgrind_ticks.py --mode coarse --stride K``); p50 / p90 / p95 / p99 / max over
the ticks (nearest rank, numpy ``inverted_cdf``), and with ``--fccqp`` the same of a
``tools/callgrind_ticks.py --per-tick --save`` file and the ratios.

Why: issue #29 sets the tails' target as fccqp's realtime warm p95 against DAQP's warm
p95; instruction counts hold it without wall time's noise on a shared machine.

How it counts: each solve is called through ``contextvars.Context.run``, callgrind's
``--toggle-collect`` and ``--dump-after`` function, as ``callgrind_ticks.py`` counts
``Solver.solve``: the adapter's ``solve`` (its dual start, DAQP's Python wrapper and
its C solve), not ``prepare`` (the pyramid's matrices, built before the call). The
first ``WARMUP_QPS`` QPs are solved once uncounted first (imports, first calls).
"""

import argparse
import contextvars
import json
import os
import subprocess
import sys
import tempfile
from pathlib import Path

import numpy as np
from callgrind_ticks import ROOT, THREAD_ENV, TOGGLE, WARMUP_QPS, _totals, set_path, tick_positions

PERCENTILES = (50, 90, 95, 99)


def child(set_path_: Path, rows_file: Path, stride: int) -> None:
    """Solve every ``stride``-th QP of each sequence warm (the counted pass) and write
    each solve's iterations and success to ``rows_file``."""
    sys.path.insert(0, str(ROOT))
    from benchmarks import testsets
    from benchmarks.pyramid_solvers import DaqpAdapter
    from threadpoolctl import threadpool_limits

    ts = testsets.load(set_path_)
    rows = []
    with threadpool_limits(1):
        warmup = DaqpAdapter("daqp")
        for qp in ts.qps[:WARMUP_QPS]:
            warmup.solve(warmup.prepare(qp))
        adapter, sequence = None, None
        kept = np.flatnonzero(tick_positions(np.asarray(ts.sequence)) % stride == 0)
        for i in kept:
            qp = ts.qps[i]
            if ts.sequence[i] != sequence:
                adapter, sequence = DaqpAdapter("daqp"), ts.sequence[i]
            data = adapter.prepare(qp)
            outcome = contextvars.Context().run(adapter.solve, data)
            rows.append((outcome.iterations, bool(outcome.success)))
    rows_file.write_text(json.dumps(rows))


def measure(robot: str, cache: Path, out_dir: Path, valgrind: str,
            stride: int) -> tuple[np.ndarray, list]:
    """One callgrind run of :func:`child`; instructions per tick and the child's rows."""
    out = out_dir / f"daqp-{robot}.callgrind"
    rows_file = out_dir / f"daqp-{robot}.json"
    cmd = [valgrind, "--tool=callgrind", f"--callgrind-out-file={out}",
           "--collect-atstart=no", f"--toggle-collect={TOGGLE}", f"--dump-after={TOGGLE}",
           sys.executable, str(Path(__file__).resolve()), "--child", "--robot", robot,
           "--set", str(set_path(robot, cache)), "--rows", str(rows_file),
           "--stride", str(stride)]
    env = dict(os.environ, PYTHONHASHSEED="0", **dict.fromkeys(THREAD_ENV, "1"))
    run = subprocess.run(cmd, env=env, capture_output=True, text=True)
    if run.returncode:
        raise SystemExit(f"{robot}: valgrind failed:\n{run.stderr[-2000:]}")
    rows = json.loads(rows_file.read_text())
    ticks = np.array([_totals(out.with_name(f"{out.name}.{k}"))["Ir"]
                      for k in range(1, len(rows) + 1)], dtype=float)
    return ticks, rows


def spread(ticks: np.ndarray) -> str:
    """p50 / p90 / p95 / p99 / max of instructions per tick, in millions."""
    values = [np.percentile(ticks, p, method="inverted_cdf") for p in PERCENTILES]
    return " / ".join(f"{v / 1e6:.3f}" for v in [*values, ticks.max()]) + "M"


def main(argv: list[str] | None = None) -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--robot", required=True)
    parser.add_argument("--cache", type=Path, default=ROOT / "benchmarks" / ".cache")
    parser.add_argument("--stride", type=int, default=1,
                        help="solve every STRIDE-th QP of each sequence, each warm from the "
                        "previous kept one (default 1: every QP)")
    parser.add_argument("--fccqp", type=Path, help="a callgrind_ticks.py --per-tick --save "
                        "file of the same robot's pass (warm, or coarse at the same "
                        "--stride), to compare")
    parser.add_argument("--save", type=Path, help="write each tick's instructions, DAQP "
                        "iterations and success to this JSON file")
    parser.add_argument("--valgrind", default="valgrind")
    parser.add_argument("--child", action="store_true", help=argparse.SUPPRESS)
    parser.add_argument("--set", type=Path, help=argparse.SUPPRESS)
    parser.add_argument("--rows", type=Path, help=argparse.SUPPRESS)
    args = parser.parse_args(argv)
    if args.child:
        child(args.set, args.rows, args.stride)
        return
    with tempfile.TemporaryDirectory(prefix="daqp_ticks-") as tmp:
        ticks, rows = measure(args.robot, args.cache, Path(tmp), args.valgrind, args.stride)
    view = "warm" if args.stride == 1 else f"every {args.stride}th"
    print(f"{args.robot} DAQP {view}, {len(ticks)} ticks, p50 / p90 / p95 / p99 / max: "
          f"{spread(ticks)}, mean {ticks.mean() / 1e6:.4f}M; solved "
          f"{sum(ok for _, ok in rows)}, iterations {sum(it for it, _ in rows)}")
    if args.save:
        args.save.write_text(json.dumps(
            [[int(ir), it, ok] for ir, (it, ok) in zip(ticks, rows, strict=True)]))
    if args.fccqp:
        saved = next(iter(json.loads(args.fccqp.read_text()).values()))
        ours = np.array([row[3] for row in saved["per_tick"]], dtype=float)
        ratios = [np.percentile(ours, p, method="inverted_cdf")
                  / np.percentile(ticks, p, method="inverted_cdf") for p in PERCENTILES]
        print(f"{args.robot} fccqp ({args.fccqp.name}): {spread(ours)}; fccqp / DAQP "
              + ", ".join(f"p{p} {r:.2f}x" for p, r in zip(PERCENTILES, ratios, strict=True)))


if __name__ == "__main__":
    main()
