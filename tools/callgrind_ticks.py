"""Instructions per control tick of fccqp's solves, counted by callgrind.

What: the instructions (callgrind's ``Ir``) that ``fccqp.Solver.solve`` executes per QP
on the benchmark's whole-body-control QPs of go2 and talos_reduced (``--all``; solo12
and anymal_c with ``--robot``), for the realtime and default presets, warm along the
benchmark's sequences and cold; with a digest of the answers (iterations, statuses,
polished flags, bit-exact ``x``).

Why: wall time on a shared machine varies by 10-50 % between runs; instruction counts
are deterministic, so they can hold a change to "within +3 % of before". Run this
driver on the revision before and after a change (same QPs, settings and driver) and
compare the tables; equal answer digests say the change did not alter the answers.

How it counts:

- QPs: the benchmark's test set of the ``--full`` preset (scenario ``mix``, seed 0, 400
  QPs in 4 sequences of 100 ticks, dt 2 ms), loaded from ``benchmarks/.cache`` of this
  driver's checkout (generated and cached there by the benchmark's code when missing,
  a few seconds), the first ``--n-qps`` of them (default all 400). The QPs' digest is
  printed: equal digests, equal QPs.
- Settings: ``fccqp.Settings()`` (``default``) and ``fccqp.Settings.realtime(budget)``
  (``realtime``) with ``--budget`` 100 s by default instead of the preset's 2 ms: under
  valgrind, ~50x slower, the 2 ms budget would stop solves wherever the clock happens to
  be and the counts and answers would change from run to run. A finite budget takes
  the same timed code path (clock reads, reserves, the warm rho) but one this large
  never stops a solve. (The previous team's ``Settings.realtime(1.0)`` is too tight
  here: under valgrind on a loaded machine a go2 solve took 1.2 s, a cold talos one
  17 s, and the learned reserve can move the stop to half the budget.) The driver
  prints the longest solve under valgrind and warns when it exceeds a quarter of the
  budget (raise ``--budget`` then, on both revisions).
- Modes, as ``benchmarks.harness`` runs fccqp: first an uncounted warm-up (the first 5
  QPs and the first QP of each other problem size, as the harness's ``WARMUP_QPS``; it
  allocates the workspace of each structure), then one counted pass over the QPs in
  order with one ``Solver``: ``warm`` resets it at each sequence boundary only (the
  benchmark's timed pass), ``cold`` calls ``Solver.reset()`` before every QP, ``coarse``
  solves every ``--stride``-th QP of each sequence from its first (default 10), warm
  from the previous kept QP and reset at each sequence boundary (the benchmark's
  "every 10th" view, ``benchmarks.views.coarse_path``).
- Only the solve calls count: each counted solve is called through
  ``contextvars.Context.run``, whose C function (``context_run`` in libpython) is
  callgrind's ``--toggle-collect`` with ``--collect-atstart=no``. The count is thus the
  whole user-facing call (argument checks in ``solver.py``, the compiled
  ``Workspace.solve``, the ``Result``), plus the few hundred instructions of
  ``Context.run`` itself; the share of the compiled ``admm.Workspace.solve`` (inclusive,
  from ``callgrind_annotate``) is printed beside it. Loading, warm-up, resets and the
  garbage collector (frozen and disabled over the pass, as in the harness) are outside.
- ``--per-tick``: callgrind dumps its counts after each counted solve
  (``--dump-after``), and the saved JSON holds per tick its instructions, iterations,
  status and polished flag (``per_tick``), to split a cell into the ticks a change
  serves and those it does not.
- ``--cut K`` (realtime only): the 2 ms clock's cut without wall time. Through the
  test hook ``fccqp.iteration.cut_after``, a run stops after ``K`` ADMM iterations as
  if its clock had passed the deadline (``--cut-polish C``: ``C`` fewer when its warm
  polish was tried and failed, the time that polish took), and ends as a clock-cut run
  does: the final polish only within ``POLISH_GATE``, restoration otherwise, the
  successor warm from that point. The setup, the factorizations and the polishes are
  not counted against the cut: ``K`` stands for what is left of 2 ms after a tick's
  fixed costs (2 ms ~ 8M instructions on these machines). ``--cut 100 --cut-polish
  60`` put the talos realtime warm ticks that the cut ends at 5-17M instructions,
  median 8.2M (notes/performance-history.md, "clock").
- ``--eliminate all|slacks``: the QPs reduced by the equalities' free block
  (``tools/elimination_study.py``: every free entry and row, or the slack entries and
  their rows kept) are solved instead; the reduction and the recovery of the original
  ``x`` happen outside the counted calls (price them apart), the saved answers are the
  recovered ``x``, judged as below.
- ``--cache-sim``: callgrind also simulates the caches and the branch predictors
  (``--cache-sim=yes --branch-sim=yes``, about 2x slower), and the table gives per tick
  the L1 data misses (reads plus writes, ``D1mr + D1mw``) and the mispredicted branches
  (conditional plus indirect, ``Bcm + Bim``) beside the instructions: what wall time
  pays beyond the instructions (a 32 KB L1, valgrind's model of the machine's caches).
  ``callgrind_annotate --show=D1mr,D1mw,Bcm <file>`` gives them by function.
- Exactness: the parent judges each answer as the benchmark does
  (``benchmarks.metrics.exact_share``): SOLVED with every joint's torque within 5 % of
  its limit of the set's reference ``x_ref`` (a tight exact-cone solve); the table's
  ``exact`` column counts those ticks.
- One BLAS thread (``threadpoolctl`` plus ``OPENBLAS_NUM_THREADS=1`` etc.),
  ``PYTHONHASHSEED=0``. Note that valgrind reports its own CPU (OpenBLAS picks its
  kernels for it), so the counts are those of valgrind's CPU, not of the machine's.

fccqp is taken from the Python path: to measure another checkout, build it in place and
put it first, e.g. ``PYTHONPATH=/tmp/baseline/src:/tmp/baseline``; the driver prints
``fccqp.__file__``, its git revision, and warns when a ``.pyx`` is newer than its
compiled module (a stale build). Run (the venv's python; valgrind on the PATH)::

    python tools/callgrind_ticks.py --robot go2 --preset realtime --mode warm
    python tools/callgrind_ticks.py --all --jobs 2 --save /tmp/after.json \\
        --compare /tmp/before.json          # 8 runs, a Markdown table, % vs before

``--all`` runs go2 and talos_reduced x realtime/default x warm/cold: about 20 CPU
minutes (talos cold the longest, ~6). Repeated runs agree within ~0.01 %. The callgrind
files are kept (``--out-dir``, printed) for ``callgrind_annotate``.
"""

from __future__ import annotations

import argparse
import concurrent.futures
import contextlib
import hashlib
import json
import os
import re
import shutil
import subprocess
import sys
import tempfile
import time
from collections import Counter
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
"""The checkout this driver lives in: its ``benchmarks`` generates and caches the QPs."""
ROBOTS = ("go2", "talos_reduced")
"""The robots of ``--all``: a small quadruped and the humanoid."""
EXTRA_ROBOTS = ("solo12", "anymal_c")
"""Robots ``--robot`` also takes (the same cached mix sets), outside ``--all``'s 12 cells."""
PRESETS = ("realtime", "default")
MODES = ("warm", "cold", "coarse")
SCENARIO, SEED, N_QPS, SEQ_LEN, DT = "mix", 0, 400, 100, 0.002
"""The test set: that of ``python -m benchmarks --full`` (benchmarks.presets.PRESETS)."""
WARMUP_QPS = 5
"""As ``benchmarks.harness.WARMUP_QPS``."""
TOGGLE = "context_run"
"""The C function of ``contextvars.Context.run`` in CPython (3.10-3.13)."""
COMPILED = re.compile(r"__pyx_pw_5fccqp_4admm_9Workspace_\d+solve\b")
"""The Python wrapper of the Cython ``fccqp.admm.Workspace.solve``."""
THREAD_ENV = ("OPENBLAS_NUM_THREADS", "OMP_NUM_THREADS", "MKL_NUM_THREADS",
              "BLIS_NUM_THREADS")


# --- the QPs (shared by the parent and the child under valgrind: numpy only) ---------------

def set_path(robot: str, cache: Path) -> Path:
    """The cached test set of ``robot``, generated by the benchmark's code when missing."""
    if str(ROOT) not in sys.path:
        sys.path.insert(0, str(ROOT))   # this checkout's benchmarks, whatever PYTHONPATH says
    from benchmarks.cache import cache_path, cached_test_set

    cached_test_set(cache, robot, SCENARIO, N_QPS, SEED, seq_len=SEQ_LEN, dt=DT,
                    report=lambda line: print(line, file=sys.stderr))
    return cache_path(cache, robot, SCENARIO, N_QPS, SEED, SEQ_LEN, DT)


def load_qps(path: Path, n_qps: int) -> tuple[list[tuple[np.ndarray, ...]], np.ndarray]:
    """The first ``n_qps`` QPs of a cached set as ``(P, q, A, b, lb, ub, starts, mus,
    normals)``, and their sequence indices (the npz layout of benchmarks.testsets.save)."""
    names = ("P", "q", "A", "b", "lb", "ub", "cone_starts", "mus", "normals")
    with np.load(path, allow_pickle=False) as z:
        if n_qps > int(z["n_qps"]):
            raise SystemExit(f"{path} has {int(z['n_qps'])} QPs, asked for {n_qps}")
        qps = [tuple(z[f"qp{i}_{name}"] for name in names) for i in range(n_qps)]
        return qps, np.asarray(z["sequence"][:n_qps])


def qp_digest(qps: list[tuple[np.ndarray, ...]]) -> str:
    h = hashlib.sha256()
    for arrays in qps:
        for a in arrays:
            h.update(np.ascontiguousarray(a).tobytes())
    return h.hexdigest()[:12]


def tick_positions(sequence: np.ndarray) -> np.ndarray:
    """Each QP's position in its sequence (0 at a sequence's first QP), as
    ``benchmarks.views.ticks``."""
    seq = np.asarray(sequence)
    starts = np.r_[True, seq[1:] != seq[:-1]]
    first = np.maximum.accumulate(np.where(starts, np.arange(seq.size), 0))
    return np.arange(seq.size) - first


def warmup_indices(qps: list[tuple[np.ndarray, ...]]) -> list[int]:
    """As ``benchmarks.harness._warmup_indices``: the first few QPs, then the first QP
    of each problem size they do not have."""
    first = list(range(min(WARMUP_QPS, len(qps))))
    seen = {qps[i][0].shape + qps[i][2].shape for i in first}
    for i, qp in enumerate(qps):
        size = qp[0].shape + qp[2].shape
        if size not in seen:
            seen.add(size)
            first.append(i)
    return first


# --- the child: runs under callgrind ------------------------------------------------------

def child(args: argparse.Namespace) -> None:
    """Solve the QPs (only the counted solves go through ``Context.run``); write a JSON."""
    import contextvars
    import gc

    from threadpoolctl import threadpool_info, threadpool_limits

    import fccqp

    raw, sequence = load_qps(args.set, args.n_qps)
    if args.mode == "coarse":
        kept = np.flatnonzero(tick_positions(sequence) % args.stride == 0)
        raw, sequence = [raw[i] for i in kept], sequence[kept]
    flat = np.array([0.0, 0.0, 1.0])
    data = []
    for P, q, A, b, lb, ub, starts, mus, normals in raw:   # as benchmarks' fccqp_arguments
        cones = tuple(
            fccqp.FrictionCone(int(s), float(mu),
                               None if np.allclose(n, flat) else tuple(map(float, n)))
            for s, mu, n in zip(starts, mus, normals, strict=True))
        data.append((P, q, A, b, lb, ub, cones))
    reductions = [None] * len(raw)
    if args.eliminate:
        data, reductions = eliminated(raw, data, args.eliminate, fccqp)
    settings = (fccqp.Settings.realtime(args.budget) if args.preset == "realtime"
                else fccqp.Settings())
    if args.cut is not None:
        from fccqp.iteration import cut_after

        cut_after(args.cut, args.cut_polish)
    rows = []
    with threadpool_limits(limits=1):
        blas = [f"{i.get('internal_api')} {i.get('version')} {i.get('architecture', '')} "
                f"{i.get('num_threads')} thread(s)" for i in threadpool_info()]
        solver = fccqp.Solver(settings)
        previous = None
        solver.reset()
        for i in warmup_indices(raw):                  # uncounted: solve called directly
            if sequence[i] != previous:
                solver.reset()
                previous = sequence[i]
            solver.solve(*data[i])
        solver.reset()
        run = contextvars.copy_context().run
        gc.collect()
        gc.freeze()
        gc.disable()
        try:
            previous = None
            for item, seq, e, raw_qp in zip(data, sequence, reductions, raw, strict=True):
                if args.mode == "cold" or seq != previous:   # coarse: warm as warm
                    solver.reset()
                    previous = seq
                result = run(solver.solve, *item)       # counted
                x = result.x if e is None else recovered(e, raw_qp, result)
                rows.append((result.iterations, result.status.value, bool(result.polished),
                             x.tobytes(), result.setup_time + result.solve_time))
                del result
        finally:
            gc.enable()
            gc.unfreeze()
    answers = hashlib.sha256("".join(f"{it},{st},{int(po)}\n" for it, st, po, _, _ in rows)
                             .encode()).hexdigest()[:12]
    xs = hashlib.sha256(b"".join(r[3] for r in rows)).hexdigest()[:12]
    out = {
        "fccqp": fccqp.__file__, "blas": blas, "ticks": len(rows),
        "iterations": sum(r[0] for r in rows),
        "statuses": dict(Counter(r[1] for r in rows)),
        "polished": sum(r[2] for r in rows),
        "answers_digest": answers, "x_digest": xs,
        "longest_solve": max(r[4] for r in rows),
        "per_tick": [[it, st, int(po)] for it, st, po, _, _ in rows],
    }
    Path(args.json).write_text(json.dumps(out))
    np.savez(Path(args.json).with_suffix(".npz"), *(np.frombuffer(r[3]) for r in rows))


def eliminated(raw: list, data: list, kind: str, fccqp: object) -> tuple[list, list]:
    """``--eliminate``: each QP's arguments reduced by ``tools/elimination_study.py``
    (``all``: every free entry and row; ``slacks``: the slack entries and their rows
    kept), and the reductions to recover ``x``; a QP that does not reduce stays."""
    from elimination_study import cones_of, eliminate

    out, reductions = [], []
    for qp, item in zip(raw, data, strict=True):
        e = eliminate(*qp[:7], keep_slacks=kind == "slacks")
        reductions.append(e)
        out.append(item if e is None else
                   (e.P, e.q, e.A, e.b, e.lb, e.ub, cones_of(fccqp, e.cone_starts, *qp[7:])))
    return out, reductions


def recovered(e: object, qp: tuple, result: object) -> np.ndarray:
    """The original problem's ``x`` from a reduced answer (uncounted)."""
    from elimination_study import recover

    return recover(e, *qp[:4], result.x, result.y, result.z)[0]


# --- the parent: launches valgrind, reads its counts ---------------------------------------

def revision(fccqp_file: str) -> str:
    """``git describe``-like revision of the checkout holding ``fccqp_file``."""
    folder = Path(fccqp_file).parent
    try:
        rev = subprocess.run(["git", "-C", str(folder), "rev-parse", "--short", "HEAD"],
                             capture_output=True, text=True, check=True).stdout.strip()
        dirty = subprocess.run(["git", "-C", str(folder), "status", "--porcelain",
                                "--untracked-files=no", "--", "."],
                               capture_output=True, text=True, check=True).stdout.strip()
    except (OSError, subprocess.CalledProcessError):
        return "unknown (not a git checkout)"
    return rev + (" + uncommitted changes in src/fccqp" if dirty else "")


def stale_modules(fccqp_file: str) -> list[str]:
    """The ``.pyx`` files of fccqp newer than their compiled module (or without one)."""
    folder = Path(fccqp_file).parent
    stale = []
    for pyx in sorted(folder.glob("*.pyx")):
        built = list(folder.glob(pyx.stem + ".*.so")) + list(folder.glob(pyx.stem + ".*.pyd"))
        if not built or max(b.stat().st_mtime for b in built) < pyx.stat().st_mtime:
            stale.append(pyx.name)
    return stale


def measure(robot: str, preset: str, mode: str, path: Path, qps: str,
            args: argparse.Namespace, out_dir: Path) -> dict:
    """One callgrind run; its counts and the child's digest."""
    label = _key({"robot": robot, "preset": preset, "mode": mode, "stride": args.stride,
                  "cut": args.cut if preset == "realtime" else None,
                  "cut_polish": args.cut_polish, "eliminate": args.eliminate})
    out = out_dir / f"{label}.callgrind"
    js = out_dir / f"{label}.json"
    cmd = [args.valgrind, "--tool=callgrind", f"--callgrind-out-file={out}",
           "--collect-atstart=no", f"--toggle-collect={TOGGLE}",
           *([f"--dump-after={TOGGLE}"] if args.per_tick else []),
           *(["--cache-sim=yes", "--branch-sim=yes"] if args.cache_sim else []),
           sys.executable, str(Path(__file__).resolve()), "--child", "--set", str(path),
           "--robot", robot, "--preset", preset, "--mode", mode,
           "--n-qps", str(args.n_qps), "--stride", str(args.stride),
           "--budget", repr(args.budget), "--json", str(js),
           *(["--eliminate", args.eliminate] if args.eliminate else []),
           *(["--cut", str(args.cut), "--cut-polish", str(args.cut_polish)]
             if args.cut is not None else [])]
    env = dict(os.environ, PYTHONHASHSEED="0", **dict.fromkeys(THREAD_ENV, "1"))
    start = time.perf_counter()
    with open(out_dir / f"{label}.log", "w") as log:
        proc = subprocess.Popen(cmd, env=env, stdout=log, stderr=subprocess.STDOUT)
        _, status, usage = os.wait4(proc.pid, 0)     # the child's own CPU time
        proc.returncode = os.waitstatus_to_exitcode(status)
    seconds = time.perf_counter() - start
    if proc.returncode:
        raise SystemExit(f"{label}: valgrind failed, see {out_dir / (label + '.log')}")
    result = json.loads(js.read_text())
    with np.load(js.with_suffix(".npz"), allow_pickle=False) as answers:
        xs = [answers[f"arr_{k}"] for k in range(len(result["per_tick"]))]
    result["exact_ticks"] = exact_ticks(path, args, mode, result["per_tick"], xs)
    result["exact"] = sum(result["exact_ticks"])
    events = _totals(out)
    if args.per_tick:   # out holds the rest after the last dump: nothing counted
        dumps = [_totals(out.with_name(f"{out.name}.{k}"))
                 for k in range(1, len(result["per_tick"]) + 1)]
        events = Counter()
        for row, dump in zip(result["per_tick"], dumps, strict=True):
            row.append(dump.get("Ir"))
            events.update(dump)
    total = events.get("Ir")
    if not total:
        raise SystemExit(f"{label}: no instructions collected in {out} (is {TOGGLE} "
                         "in this Python's symbols?)")
    compiled = None
    with contextlib.suppress(OSError, subprocess.CalledProcessError):
        annotate = subprocess.run(["callgrind_annotate", "--inclusive=yes", str(out)],
                                  capture_output=True, text=True, check=True).stdout
        for line in annotate.splitlines():
            if COMPILED.search(line):
                compiled = int(line.split()[0].replace(",", ""))
                break
    result.update(robot=robot, preset=preset, mode=mode, stride=args.stride,
                  eliminate=args.eliminate,
                  cut=args.cut if preset == "realtime" else None, cut_polish=args.cut_polish,
                  instructions=total, **_misses(events),
                  compiled=compiled, seconds=seconds, cpu=usage.ru_utime + usage.ru_stime,
                  qps=qps, callgrind=str(out))
    return result


def exact_ticks(path: Path, args: argparse.Namespace, mode: str, rows: list,
                xs: list[np.ndarray]) -> list[int]:
    """Per counted tick, 1 when its answer is exact as the benchmark counts it
    (``benchmarks.metrics.exact_share``): SOLVED, and every joint's torque within
    ``TORQUE_LIMIT_SHARE`` of its limit of the set's reference."""
    if str(ROOT) not in sys.path:
        sys.path.insert(0, str(ROOT))
    from benchmarks.metrics import TORQUE_LIMIT_SHARE
    from benchmarks.testsets import LAYOUT_NAMES

    with np.load(path, allow_pickle=False) as z:
        sequence = np.asarray(z["sequence"][:args.n_qps])
        kept = (np.flatnonzero(tick_positions(sequence) % args.stride == 0)
                if mode == "coarse" else np.arange(args.n_qps))
        flags = []
        for row, x, i in zip(rows, xs, kept, strict=True):
            u = slice(*(int(v) for v in z[f"qp{i}_layout"][LAYOUT_NAMES.index("u")]))
            error = np.max(np.abs(x[u] - z[f"qp{i}_x_ref"][u]) / z[f"qp{i}_ub"][u],
                           initial=0.0)
            flags.append(int(row[1] == "solved" and bool(error <= TORQUE_LIMIT_SHARE)))
    return flags


def _key(r: dict) -> str:
    """A run's name: robot-preset-mode, the coarse mode with its stride, the cut's K."""
    stride = r.get("stride", 10) if r["mode"] == "coarse" else ""
    cut = f"-cut{r['cut']}" if r.get("cut") is not None else ""
    polish = f"p{r['cut_polish']}" if cut and r.get("cut_polish") else ""
    eliminate = f"-elim{r['eliminate']}" if r.get("eliminate") else ""
    return f"{r['robot']}-{r['preset']}-{r['mode']}{stride}{cut}{polish}{eliminate}"


def _totals(path: Path) -> dict[str, int]:
    """The events a callgrind file counted, by name (``Ir``; with ``--cache-sim`` also
    ``D1mr``, ``Bcm``, ...)."""
    names, totals = [], {}
    for line in path.read_text().splitlines():
        if line.startswith("events:"):
            names = line.split()[1:]
        elif line.startswith(("summary:", "totals:")):
            totals = dict(zip(names, (int(v) for v in line.split()[1:]), strict=False))
    return totals


def _misses(events: dict[str, int]) -> dict[str, int]:
    """L1 data misses and mispredicted branches of ``--cache-sim``'s events (none
    without it)."""
    if "D1mr" not in events:
        return {}
    return {"d1_misses": events["D1mr"] + events["D1mw"],
            "mispredicts": events["Bcm"] + events["Bim"]}


def line_of(r: dict, before: dict | None) -> str:
    ticks = r["ticks"]
    share = f"{100 * r['compiled'] / r['instructions']:.1f} %" if r["compiled"] else "n/a"
    statuses = ", ".join(f"{k} {v}" for k, v in sorted(r["statuses"].items()))
    cells = [r["robot"], r["preset"], r["mode"], str(ticks),
             f"{r['instructions'] / ticks / 1e6:.4f}M", f"{r['instructions']:,}", share,
             f"{r['iterations']} ({r['iterations'] / ticks:.2f})", statuses,
             str(r["polished"]), f"{r['exact']} ({100 * r['exact'] / ticks:.0f} %)",
             f"`{r['answers_digest']}`", f"`{r['x_digest']}`"]
    if "d1_misses" in r:
        cells[5:5] = [f"{r['d1_misses'] / ticks / 1e3:.2f}k",
                      f"{r['mispredicts'] / ticks / 1e3:.2f}k"]
    if before is not None:
        old = before.get(_key(r))
        if old and old["ticks"] == ticks and old.get("qps") == r["qps"]:
            change = 100 * (r["instructions"] / old["instructions"] - 1)
            same = "same answers" if old["answers_digest"] == r["answers_digest"] else \
                "ANSWERS DIFFER"
            flag = " OVER +3 %" if change > 3 else ""
            cells.append(f"{change:+.2f} %{flag}; {same}")
        else:
            cells.append("n/a (other QPs)")
    return "| " + " | ".join(cells) + " |"


def main(argv: list[str] | None = None) -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--robot", choices=ROBOTS + EXTRA_ROBOTS, default="go2")
    parser.add_argument("--preset", choices=PRESETS, default="realtime")
    parser.add_argument("--mode", choices=MODES, default="warm")
    parser.add_argument("--all", action="store_true",
                        help="every robot x preset x mode, as a Markdown table")
    parser.add_argument("--stride", type=int, default=10,
                        help="the coarse mode's step between kept QPs (default 10)")
    parser.add_argument("--per-tick", action="store_true",
                        help="count each solve apart (callgrind --dump-after)")
    parser.add_argument("--n-qps", type=int, default=N_QPS,
                        help=f"the first N QPs of each set (default all {N_QPS})")
    parser.add_argument("--budget", type=float, default=100.0,
                        help="time budget of the realtime preset under valgrind (s, default "
                        "100: never binds)")
    parser.add_argument("--cut", type=int,
                        help="realtime: stop each run after this many iterations as the 2 ms "
                        "clock would (fccqp.iteration.cut_after; default no cut)")
    parser.add_argument("--cut-polish", type=int, default=0,
                        help="with --cut: this many fewer after a failed warm polish")
    parser.add_argument("--eliminate", choices=("all", "slacks"),
                        help="solve the QPs reduced by tools/elimination_study.py (every free "
                        "entry, or the slack entries and their rows kept); the reduction and "
                        "the recovery of x are not counted")
    parser.add_argument("--cache-sim", action="store_true",
                        help="also count L1 data misses and mispredicted branches per tick "
                        "(callgrind --cache-sim=yes --branch-sim=yes)")
    parser.add_argument("--jobs", type=int, default=1, help="callgrind runs at a time")
    parser.add_argument("--cache", type=Path, default=ROOT / "benchmarks" / ".cache",
                        help="cached test sets (default this checkout's benchmarks/.cache)")
    parser.add_argument("--out-dir", type=Path,
                        help="where the callgrind files go (default a new temporary folder)")
    parser.add_argument("--save", type=Path, help="write the results as JSON")
    parser.add_argument("--compare", type=Path,
                        help="a --save JSON of another revision: add a change column")
    parser.add_argument("--valgrind", default="valgrind")
    parser.add_argument("--child", action="store_true", help=argparse.SUPPRESS)
    parser.add_argument("--set", type=Path, help=argparse.SUPPRESS)
    parser.add_argument("--json", help=argparse.SUPPRESS)
    args = parser.parse_args(argv)
    if args.child:
        child(args)
        return
    if args.cut is not None and (args.cut < 0 or args.cut_polish < 0):
        parser.error("--cut and --cut-polish must be >= 0")
    if not 1 <= args.n_qps <= N_QPS:
        parser.error(f"--n-qps must be in 1..{N_QPS}")
    if shutil.which(args.valgrind) is None:
        raise SystemExit(f"{args.valgrind} not found")
    import fccqp

    print(f"fccqp: {fccqp.__file__} (revision {revision(fccqp.__file__)})")
    for name in stale_modules(fccqp.__file__):
        print(f"WARNING: {name} is newer than its compiled module: rebuild "
              "(python setup.py build_ext --inplace)")
    runs = ([(r, p, m) for r in ROBOTS for p in PRESETS for m in MODES] if args.all
            else [(args.robot, args.preset, args.mode)])
    paths, digests = {}, {}
    for robot in dict.fromkeys(r for r, _, _ in runs):
        paths[robot] = set_path(robot, args.cache)
        digests[robot] = qp_digest(load_qps(paths[robot], args.n_qps)[0])
        print(f"{robot}: first {args.n_qps} QPs of {paths[robot].name}, "
              f"digest {digests[robot]}")
    out_dir = args.out_dir or Path(tempfile.mkdtemp(prefix="callgrind_ticks-"))
    out_dir.mkdir(parents=True, exist_ok=True)
    print(f"callgrind files in {out_dir}; settings: default = fccqp.Settings(), realtime = "
          f"fccqp.Settings.realtime({args.budget!r})", flush=True)
    start = time.perf_counter()
    with concurrent.futures.ThreadPoolExecutor(max(1, args.jobs)) as pool:
        futures = [pool.submit(measure, *run, paths[run[0]], digests[run[0]], args, out_dir)
                   for run in runs]
        results = []
        for future in futures:
            r = future.result()
            results.append(r)
            print(f"{r['robot']} {r['preset']} {r['mode']}: {r['instructions']:,} instructions"
                  f" in {r['ticks']} solves, {r['instructions'] / r['ticks']:,.0f} per tick; "
                  f"{r['seconds']:.0f} s ({r['cpu']:.0f} s CPU)", flush=True)
    for r in results:
        if r["fccqp"] != fccqp.__file__:
            raise SystemExit(f"the child imported {r['fccqp']}, not {fccqp.__file__}")
    print(f"BLAS under valgrind: {'; '.join(results[0]['blas'])}")
    longest = max(r["longest_solve"] for r in results)
    print(f"longest solve under valgrind: {longest:.3f} s (realtime budget {args.budget} s)")
    if longest > args.budget / 4:
        print("WARNING: a solve took more than a quarter of the budget: raise --budget")
    before = json.loads(args.compare.read_text()) if args.compare else None
    head = ["robot", "preset", "mode", "ticks", "instr./tick", "instructions",
            "Workspace.solve", "iterations (mean)", "statuses", "polished", "exact", "answers",
            "x"]
    if args.cache_sim:
        head[5:5] = ["D1 misses/tick", "mispredicts/tick"]
    if before is not None:
        head.append(f"vs {args.compare.name}")
    print()
    print("| " + " | ".join(head) + " |")
    print("|" + "---|" * len(head))
    for r in results:
        print(line_of(r, before))
    print(f"\n{len(results)} callgrind run(s) in {time.perf_counter() - start:.0f} s, "
          f"{sum(r['cpu'] for r in results):.0f} s CPU")
    if args.save:
        args.save.write_text(json.dumps(
            {_key(r): r for r in results}, indent=1))


if __name__ == "__main__":
    main()
