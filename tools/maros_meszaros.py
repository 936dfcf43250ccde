"""qpbenchmark's ``maros_meszaros_dense`` test set, judged by qpbenchmark's criterion.

Usage::

    python tools/maros_meszaros.py --data DIR [--settings low_accuracy mid_accuracy]
        [--solvers fccqp osqp daqp clarabel piqp] [--problems NAME ...] [--out CSV]
    python tools/maros_meszaros.py --from-csv CSV [CSV ...]      # summary only

``DIR`` holds the ``.mat`` files of the qpsolvers/maros_meszaros_qpbenchmark repository
(its ``data/`` folder, or the repository itself). Nothing here is fetched or cached.

What is reproduced from qpbenchmark (2.7.1) and the test-set repository:

* Problems: ``MarosMeszaros.load_problem_from_mat_file`` (infinity at 1e20, ``A = [C;
  I]``, rows with ``u - l < 1e-10`` become equalities, the others two one-sided rows of
  ``G x <= h`` without the infinite ones) and ``MarosMeszarosDense.__iter__``: keep the
  problems with ``n <= 1000`` variables and ``m_G + m_A + n <= 1000`` constraints
  (``count_constraints``), converted to dense matrices: 62 of the 138.
* Settings: ``TestSet.define_solver_settings``: ``eps_abs`` 1e-3 (``low_accuracy``) or
  1e-6 (``mid_accuracy``), ``eps_rel`` 0, the time limit given to the solvers that take
  one. The keyword names per solver come from qpbenchmark's ``SolverSettings`` when
  qpbenchmark is installed, else from the copy in :data:`SOLVER_KWARGS`. qpbenchmark
  has no entry for fccqp; it gets ``eps_abs``, ``eps_rel=0`` and ``time_limit`` (the
  OSQP treatment), and ``--fccqp key=value`` adds further fields of ``fccqp.Settings``.
* Time limit: ``MarosMeszaros.define_tolerances(runtime=1000.0)``, 1000 s.
* Success (``Results.build_success_rate_df``): ``found`` and primal residual, dual
  residual and duality gap (``qpsolvers.Solution.primal_residual`` and the others)
  each strictly below the settings' tolerance (1e-3 or 1e-6). The runtime is not part
  of it. Correct (``build_correct_rate_df``): ``found`` equals success.
* Runtime: ``qpsolvers.solve_problem`` timed by ``perf_counter`` as in
  ``utils.time_solve_problem`` (a sparse-only solver gets its sparse matrices first,
  untimed). Its shifted geometric mean (``Report``: shift 10, a not-found result counts
  the time limit) is printed in seconds and as a ratio to the best solver.

Each solve runs in a worker process; one that takes ``--watchdog`` seconds (default
1.2 x the time limit) is killed and recorded as not found (qpbenchmark would wait).

A *wrong claim*: fccqp reports PRIMAL_INFEASIBLE or DUAL_INFEASIBLE (every problem of
the set has an optimum), or any solver says ``found`` (fccqp: SOLVED) while the
criterion rejects its point. Every row records fccqp's git revision at the worker's
start, with a digest of ``git diff HEAD -- src`` when the tree is dirty.
"""

from __future__ import annotations

import argparse
import csv
import hashlib
import math
import multiprocessing as mp
import subprocess
import sys
import time
import warnings
from pathlib import Path

import numpy as np

SETTINGS_EPS = {"low_accuracy": 1e-3, "mid_accuracy": 1e-6, "high_accuracy": 1e-9}
"""``eps_abs`` and residual tolerance of qpbenchmark's settings (``eps_rel`` is 0)."""
TIME_LIMIT = 1000.0
"""``MarosMeszaros.define_tolerances(runtime=1000.0)``."""
SHIFT = 10.0
"""Shift of the shifted geometric mean in qpbenchmark's report."""
MAX_VARIABLES = 1000
MAX_CONSTRAINTS = 1000
"""``MarosMeszarosDense.__iter__``: ``nb_variables <= 1000 and nb_constraints <= 1000``."""
INFEASIBLE = ("primal_infeasible", "dual_infeasible")
COLUMNS = [
    "problem", "settings", "solver", "n", "m", "found", "success", "runtime",
    "primal_residual", "dual_residual", "duality_gap", "status", "iterations",
    "point_primal_residual", "point_dual_residual", "point_duality_gap",
    "fccqp_prim_res", "fccqp_dual_res", "error", "fccqp_rev",
]


def _copy_kwargs(eps: float, time_limit: float) -> dict[str, dict[str, object]]:
    """qpbenchmark 2.7.1 ``SolverSettings`` for ``set_eps_abs(eps)``, ``set_eps_rel(0)``,
    ``set_time_limit`` and the low/mid settings' ``check_duality_gap``."""
    return {
        "clarabel": {"tol_feas": eps, "tol_gap_abs": eps, "tol_gap_rel": 0.0},
        "daqp": {"dual_tol": eps, "primal_tol": eps},
        "highs": {"dual_feasibility_tolerance": eps, "primal_feasibility_tolerance": eps,
                  "time_limit": time_limit},
        "osqp": {"eps_abs": eps, "eps_rel": 0.0, "time_limit": time_limit},
        "piqp": {"eps_abs": eps, "eps_duality_gap_abs": eps, "eps_rel": 0.0,
                 "eps_duality_gap_rel": 0.0, "check_duality_gap": True},
        "proxqp": {"eps_abs": eps, "eps_duality_gap_abs": eps, "eps_rel": 0.0,
                   "eps_duality_gap_rel": 0.0, "check_duality_gap": True},
        "quadprog": {},
        "scs": {"eps_abs": eps, "eps_rel": 0.0, "time_limit_secs": time_limit},
    }


SOLVER_KWARGS = _copy_kwargs
"""The built-in copy of qpbenchmark's solver keywords (used without qpbenchmark)."""


def solver_kwargs(settings: str, time_limit: float,
                  fccqp_extra: dict[str, object]) -> tuple[dict[str, dict], str]:
    """Keyword arguments per solver for ``settings``, and where they come from."""
    eps = SETTINGS_EPS[settings]
    try:
        from qpbenchmark.solver_settings import SolverSettings
        from qpbenchmark.version import get_version
    except ImportError:
        table, source = SOLVER_KWARGS(eps, time_limit), "built-in copy of qpbenchmark 2.7.1"
    else:
        # TestSet.define_solver_settings, for the low/mid/high accuracy settings
        s = SolverSettings()
        s.set_eps_abs(eps)
        s.set_eps_rel(0.0)
        s.set_param("piqp", "check_duality_gap", True)
        s.set_param("proxqp", "check_duality_gap", True)
        s.set_time_limit(time_limit)
        table = {name: dict(s[name]) for name in s.solvers}
        for name in table:   # qpoases: its predefined options are not our concern
            table[name].pop("predefined_options", None)
        source = f"qpbenchmark {get_version()} SolverSettings"
    table["fccqp"] = {"eps_abs": eps, "eps_rel": 0.0, "time_limit": time_limit,
                      **fccqp_extra}
    return table, source


# --------------------------------------------------------------------------- problems


def load_problem(path: Path):
    """``MarosMeszaros.load_problem_from_mat_file`` and ``convert_problem_from_double_sided``
    as a ``qpsolvers.Problem`` (sparse), with its constraint count."""
    import qpsolvers
    import scipy.io as spio
    import scipy.sparse as spa

    mat_dict = spio.loadmat(str(path))
    P = mat_dict["P"].astype(float).tocsc()
    q = mat_dict["q"].T.flatten().astype(float)
    A = mat_dict["A"].astype(float).tocsc()
    l = mat_dict["l"].T.flatten().astype(float)  # noqa: E741 (qpbenchmark's name)
    u = mat_dict["u"].T.flatten().astype(float)
    n = mat_dict["n"].T.flatten().astype(int)[0]
    m = mat_dict["m"].T.flatten().astype(int)[0]
    assert A.shape == (m, n)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        A[A > +9e19] = +np.inf
        A[A < -9e19] = -np.inf
    l[l > +9e19] = +np.inf
    u[u > +9e19] = +np.inf
    l[l < -9e19] = -np.inf
    u[u < -9e19] = -np.inf
    lb, ub = l[-n:], u[-n:]
    C, l_c, u_c = A[:-n], l[:-n], u[:-n]

    bounds_are_equal = u_c - l_c < 1e-10
    eq_rows = np.asarray(bounds_are_equal).nonzero()
    A_eq = C[eq_rows]
    b = u_c[eq_rows]
    ineq_rows = np.asarray(np.logical_not(bounds_are_equal)).nonzero()
    G = spa.vstack([C[ineq_rows], -C[ineq_rows]], format="csc")
    h = np.hstack([u_c[ineq_rows], -l_c[ineq_rows]])
    h_finite = h < np.inf
    if not h_finite.all():
        G = G[h_finite]
        h = h[h_finite]
    problem = qpsolvers.Problem(
        P, q,
        G if G.size > 0 else None, h if h.size > 0 else None,
        A_eq if A_eq.size > 0 else None, b if b.size > 0 else None,
        lb, ub,
    )
    # MarosMeszaros.count_constraints: box constraints once, from the lower bounds
    count = sum(M.shape[0] for M in (problem.G, problem.A, problem.lb) if M is not None)
    return problem, int(count)


def _convert(problem, dense: bool):
    """``qpbenchmark.Problem.to_dense`` (``dense``) or ``to_sparse``."""
    import qpsolvers
    import scipy.sparse as spa

    def convert(M):
        if M is None or isinstance(M, np.ndarray) == dense:
            return M
        return M.toarray().astype(float) if dense else spa.csc_matrix(M)

    return qpsolvers.Problem(convert(problem.P), problem.q, convert(problem.G), problem.h,
                             convert(problem.A), problem.b, problem.lb, problem.ub)


def mat_files(data: Path) -> dict[str, Path]:
    """``NAME -> path`` of the ``.mat`` files in ``data`` or ``data/data``."""
    if (data / "data").is_dir():
        data = data / "data"
    files = {p.stem: p for p in sorted(data.glob("*.mat"))}
    empty = [name for name, p in files.items() if p.stat().st_size == 0]
    for name in empty:   # a snapshot may hold a large file as an empty placeholder
        print(f"warning: {files.pop(name)} is empty, skipped", file=sys.stderr)
    return files


def dense_subset(files: dict[str, Path]) -> dict[str, tuple[int, int]]:
    """``NAME -> (n, constraints)`` of the problems of ``maros_meszaros_dense``."""
    subset = {}
    for name, path in files.items():
        problem, count = load_problem(path)
        n = problem.P.shape[0]
        if n <= MAX_VARIABLES and count <= MAX_CONSTRAINTS:
            subset[name] = (n, count)
    return subset


# ----------------------------------------------------------------------------- worker


def fccqp_revision() -> str:
    """``git rev-parse --short HEAD`` of fccqp's checkout, ``+dirty(<digest>)`` when
    ``git status --short src`` is not empty; ``""`` outside a git checkout."""
    try:
        import fccqp

        where = Path(fccqp.__file__).resolve().parent

        def git(*args: str) -> str:
            return subprocess.run(["git", "-C", str(where), *args], capture_output=True,
                                  text=True, check=True).stdout

        top = git("rev-parse", "--show-toplevel").strip()
        rev = git("rev-parse", "--short", "HEAD").strip()
        status = subprocess.run(["git", "-C", top, "status", "--short", "src"],
                                capture_output=True, text=True, check=True).stdout
        if status.strip():
            diff = subprocess.run(["git", "-C", top, "diff", "HEAD", "--", "src"],
                                  capture_output=True, text=True, check=True).stdout
            digest = hashlib.sha1((status + diff).encode()).hexdigest()[:8]
            rev += f"+dirty({digest})"
        return rev
    except Exception:   # noqa: BLE001 (no git, no checkout: the revision is unknown)
        return ""


def _residuals(solution) -> tuple[float, float, float]:
    return (float(solution.primal_residual()), float(solution.dual_residual()),
            float(solution.duality_gap()))


def solve_one(path: Path, solver: str, kwargs: dict[str, object]) -> dict[str, object]:
    """Solve one problem as ``qpbenchmark.utils.time_solve_problem`` does and measure."""
    import qpsolvers

    problem, _ = load_problem(path)
    problem = _convert(problem, dense=True)   # MarosMeszarosDense yields to_dense()
    if solver in qpsolvers.sparse_solvers and solver not in qpsolvers.dense_solvers:
        problem = _convert(problem, dense=False)   # untimed, as in time_solve_problem
    row: dict[str, object] = {"error": ""}
    start = time.perf_counter()
    try:
        solution = qpsolvers.solve_problem(problem, solver=solver, **kwargs)
    except Exception as exn:  # noqa: BLE001 (qpbenchmark catches every exception too)
        solution = qpsolvers.Solution(problem)
        row["error"] = f"{type(exn).__name__}: {exn}"[:200]
    row["runtime"] = time.perf_counter() - start
    found = bool(solution.found)
    row["found"] = found
    row["primal_residual"], row["dual_residual"], row["duality_gap"] = _residuals(solution)
    # the same residuals of the returned point whether or not the solver claims it
    if solution.x is not None:
        solution.found = True
        with np.errstate(all="ignore"):
            point = _residuals(solution)
        solution.found = found
    else:
        point = (math.inf, math.inf, math.inf)
    row["point_primal_residual"], row["point_dual_residual"], row["point_duality_gap"] = point
    extras = solution.extras if isinstance(solution.extras, dict) else {}
    status = extras.get("status")
    row["status"] = getattr(status, "value", "" if status is None else str(status))
    row["iterations"] = extras.get("iterations", "")
    # fccqp's own residuals (of its slack form, scaled as its termination test)
    row["fccqp_prim_res"] = extras.get("prim_res", "") if solver == "fccqp" else ""
    row["fccqp_dual_res"] = extras.get("dual_res", "") if solver == "fccqp" else ""
    return row


def _worker(conn) -> None:
    """Serve ``(path, solver, kwargs)`` requests until ``None``."""
    import fccqp  # noqa: F401 (registers the qpsolvers backend)

    warnings.simplefilter("ignore")   # solvers' "maximum iterations reached" and such
    rev = fccqp_revision()
    while True:
        task = conn.recv()
        if task is None:
            return
        row = solve_one(*task)
        row["fccqp_rev"] = rev
        conn.send(row)


class Worker:
    """A solver process, restarted after a crash or a watchdog kill."""

    def __init__(self) -> None:
        self.ctx = mp.get_context("spawn")
        self.proc = None
        self.conn = None

    def _start(self) -> None:
        self.conn, child = self.ctx.Pipe()
        self.proc = self.ctx.Process(target=_worker, args=(child,), daemon=True)
        self.proc.start()
        child.close()

    def stop(self) -> None:
        if self.proc is not None:
            if self.proc.is_alive():
                self.proc.kill()
            self.proc.join()
        self.proc = self.conn = None

    def run(self, task: tuple, watchdog: float) -> dict[str, object]:
        if self.proc is None:
            self._start()
        self.conn.send(task)
        start = time.perf_counter()
        # the first request also waits for the imports
        if self.conn.poll(watchdog + 30.0):
            try:
                return self.conn.recv()
            except EOFError:
                pass
            what = "worker died"
        else:
            what = f"killed after {time.perf_counter() - start:.0f} s"
        self.stop()
        return {"found": False, "runtime": time.perf_counter() - start,
                "primal_residual": math.inf, "dual_residual": math.inf,
                "duality_gap": math.inf, "point_primal_residual": math.inf,
                "point_dual_residual": math.inf, "point_duality_gap": math.inf,
                "status": "", "iterations": "", "error": what, "fccqp_rev": ""}


# ---------------------------------------------------------------------------- summary


def is_success(row: dict[str, object]) -> bool:
    """``Results.build_success_rate_df``'s ``found_and_valid``."""
    tol = SETTINGS_EPS[str(row["settings"])]
    return (_bool(row["found"]) and float(row["primal_residual"]) < tol
            and float(row["dual_residual"]) < tol and float(row["duality_gap"]) < tol)


def _bool(value: object) -> bool:
    return value is True or str(value) == "True"


def wrong_claim(row: dict[str, object]) -> str:
    """Why ``row`` is a wrong claim, or ``""``."""
    if row["solver"] == "fccqp" and row["status"] in INFEASIBLE:
        return f"{row['status']} on a problem with an optimum"
    if _bool(row["found"]) and not is_success(row):
        return "found, rejected by the criterion"
    return ""


def shgeom(values: list[float], shift: float = SHIFT) -> float:
    """``qpbenchmark.shgeom.shgeom``."""
    v = np.asarray(values, dtype=float)
    return float(np.exp(np.sum(np.log(v + shift)) / len(v)) - shift)


def summarize(rows: list[dict[str, object]], time_limit: float) -> None:
    """Successes, correct rate, runtime shifted geometric mean and wrong claims."""
    keys = sorted({(str(r["settings"]), str(r["solver"])) for r in rows})
    for settings in sorted({k[0] for k in keys}):
        print(f"\n== {settings} (tolerance {SETTINGS_EPS[settings]:g}, time limit "
              f"{time_limit:g} s)")
        means = {}
        for _, solver in (k for k in keys if k[0] == settings):
            sel = [r for r in rows if r["settings"] == settings and r["solver"] == solver]
            means[solver] = shgeom([float(r["runtime"]) if _bool(r["found"]) else time_limit
                                    for r in sel])
        best = min(means.values())
        print(f"{'solver':10s} {'success':>9s} {'found':>6s} {'correct':>8s} "
              f"{'shgeom(s)':>10s} {'ratio':>7s}  revisions")
        for solver, mean in means.items():
            sel = [r for r in rows if r["settings"] == settings and r["solver"] == solver]
            ok = sum(is_success(r) for r in sel)
            found = sum(_bool(r["found"]) for r in sel)
            correct = sum(_bool(r["found"]) == is_success(r) for r in sel)
            revs = ",".join(sorted({str(r.get("fccqp_rev", "")) for r in sel} - {""}))
            print(f"{solver:10s} {ok:>4d}/{len(sel):<4d} {found:>6d} {correct:>4d}/{len(sel):<3d}"
                  f" {mean:10.3f} {mean / best:7.2f}  {revs if solver == 'fccqp' else ''}")
        fccqp = [r for r in rows if r["settings"] == settings and r["solver"] == "fccqp"]
        if fccqp:
            counts: dict[str, int] = {}
            for r in fccqp:
                counts[str(r["status"]) or "-"] = counts.get(str(r["status"]) or "-", 0) + 1
            print("fccqp statuses: " + ", ".join(f"{k} {v}" for k, v in sorted(counts.items())))
            failed = [f"{r['problem']}({r['status'] or r['error']})" for r in fccqp
                      if not is_success(r)]
            print(f"fccqp failures ({len(failed)}): " + " ".join(failed))
    claims = [(r, wrong_claim(r)) for r in rows]
    claims = [(r, why) for r, why in claims if why]
    print(f"\n== wrong claims ({len(claims)})")
    for r, why in claims:
        own = ""
        if r["solver"] == "fccqp" and str(r.get("fccqp_prim_res", "")) != "":
            own = (f"; fccqp's own prim_res {float(r['fccqp_prim_res']):.2e} dual_res "
                   f"{float(r['fccqp_dual_res']):.2e} after {r['iterations']} iterations")
        print(f"{r['solver']} {r['problem']} {r['settings']}: {why}; status "
              f"{r['status'] or '-'}, point residuals prim {float(r['point_primal_residual']):.2e}"
              f" dual {float(r['point_dual_residual']):.2e}"
              f" gap {float(r['point_duality_gap']):.2e}{own}")


# ------------------------------------------------------------------------------- main


def _parse_extra(items: list[str]) -> dict[str, object]:
    extra: dict[str, object] = {}
    for item in items:
        key, _, text = item.partition("=")
        for kind in (int, float):
            try:
                extra[key] = kind(text)
                break
            except ValueError:
                continue
        else:
            extra[key] = {"True": True, "False": False}.get(text, text)
    return extra


def _git_state() -> str:
    rev = fccqp_revision()
    try:
        import fccqp

        top = Path(fccqp.__file__).resolve().parents[2]
        status = subprocess.run(["git", "-C", str(top), "status", "--short", "src"],
                                capture_output=True, text=True).stdout
    except Exception:  # noqa: BLE001
        status = ""
    return f"fccqp revision {rev or 'unknown'}" + (
        "\ngit status --short src:\n" + status.rstrip() if status.strip() else "")


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--data", type=Path, help="folder of the .mat files")
    parser.add_argument("--settings", nargs="+", default=["low_accuracy", "mid_accuracy"],
                        choices=sorted(SETTINGS_EPS))
    parser.add_argument("--solvers", nargs="+", default=["fccqp"])
    parser.add_argument("--problems", nargs="+", default=None)
    parser.add_argument("--out", type=Path, default=None, help="CSV written row by row")
    parser.add_argument("--time-limit", type=float, default=TIME_LIMIT)
    parser.add_argument("--watchdog", type=float, default=None,
                        help="kill a solve after this many seconds (1.2 x time limit)")
    parser.add_argument("--fccqp", nargs="*", default=[], metavar="KEY=VALUE",
                        help="extra fccqp.Settings fields")
    parser.add_argument("--from-csv", nargs="+", type=Path, default=None,
                        help="only summarize these CSV files")
    args = parser.parse_args(argv)

    if args.from_csv:
        rows = []
        for path in args.from_csv:
            with open(path, newline="") as f:
                rows += list(csv.DictReader(f))
        summarize(rows, args.time_limit)
        return 0
    if args.data is None:
        parser.error("--data is required")
    import qpsolvers

    import fccqp  # noqa: F401 (registers "fccqp" with qpsolvers)

    missing = [s for s in args.solvers if s not in qpsolvers.available_solvers]
    if missing:
        parser.error(f"solvers not available in qpsolvers: {missing}")
    files = mat_files(args.data)
    subset = dense_subset(files)
    names = sorted(subset)
    if args.problems:
        unknown = [p for p in args.problems if p not in subset]
        if unknown:
            parser.error(f"not in the dense subset: {unknown}")
        names = [p for p in names if p in args.problems]
    watchdog = args.watchdog or 1.2 * args.time_limit
    tables = {}
    for settings in args.settings:
        tables[settings], source = solver_kwargs(settings, args.time_limit,
                                                 _parse_extra(args.fccqp))
    print(f"maros_meszaros_dense: {len(subset)} problems of {len(files)} files in "
          f"{args.data}; running {len(names)}")
    print(f"solver keywords from {source}; fccqp: {tables[args.settings[0]]['fccqp']}")
    print(f"qpsolvers {qpsolvers.__version__}; python {sys.version.split()[0]}; "
          f"{time.strftime('%Y-%m-%d %H:%M:%S')}")
    print(f"fccqp from {Path(fccqp.__file__).parent}")
    print(_git_state(), flush=True)

    writer = None
    out = None
    if args.out:
        out = open(args.out, "w", newline="")
        writer = csv.DictWriter(out, fieldnames=COLUMNS)
        writer.writeheader()
    rows = []
    worker = Worker()
    try:
        for name in names:   # qpbenchmark's order: problem, solver, settings
            for solver in args.solvers:
                for settings in args.settings:
                    kwargs = tables[settings].get(solver, {})
                    row = worker.run((files[name], solver, kwargs), watchdog)
                    row.update(problem=name, settings=settings, solver=solver,
                               n=subset[name][0], m=subset[name][1])
                    row["success"] = is_success(row)
                    rows.append(row)
                    if writer:
                        writer.writerow({k: row.get(k, "") for k in COLUMNS})
                        out.flush()
                    flag = wrong_claim(row)
                    print(f"{name:10s} {settings:13s} {solver:9s} "
                          f"{'ok ' if row['success'] else 'no '}{float(row['runtime']):8.3f}s "
                          f"{row['status'] or ''} {row['error'] or ''}"
                          f"{'  WRONG CLAIM: ' + flag if flag else ''}", flush=True)
    finally:
        if worker.proc is not None:
            worker.conn.send(None)
            worker.proc.join(timeout=10)
            worker.stop()
        if out:
            out.close()
    summarize(rows, args.time_limit)
    print("\n" + _git_state())
    return 0


if __name__ == "__main__":
    sys.exit(main())
