"""Study of eliminating the free entries that the equalities determine (issue #29).

Not part of the package: numpy/scipy, to answer "does solving the problem reduced by
the equalities pay?" on the benchmark's cached whole-body-control QPs.

The QP is ``min 1/2 x'Px + q'x`` s.t. ``Ax = b``, ``lb <= x <= ub``, cone blocks. An
entry is *free* when it has no finite bound and is in no cone block; the rest are
*constrained* (``c``). When the equalities' free block ``K = A[:, free]`` is square and
well conditioned (pivoted LU, reciprocal condition estimate above ``RCOND_MIN``), every
free entry and every row goes:

    x_f = w - W x_c,    w = K^-1 b,    W = K^-1 A_c,    Z_f = -W,
    min 1/2 x_c' P' x_c + q'' x_c  over the box and the cones, no equality rows,
    P' = Z_f' P_ff Z_f + Z_f' P_fc + P_cf Z_f + P_cc,
    q'' = q_c + Z_f' (P_ff w + q_f) + P_cf w.

Recovery: ``x_f`` from the formula, then one step of iterative refinement on ``K``
(``x_f += K^-1 (b - A x)``) when the residual is above rounding; the multipliers ``y``
of the rows from stationarity on the free entries, ``K' y = -(P x + q)_f``; ``z`` of the
constrained entries is the reduced problem's (``z_f = 0``). Stationarity on the
constrained entries then holds to the reduced problem's own dual residual, since
``Z_f' = -A_c' K^-T``.

Each robot's full test set (400 QPs) is solved reduced with fccqp, realtime and
default presets (a budget that never stops a solve, as tools/callgrind_ticks.py),
warm along the sequences, cold (``Solver.reset()`` before every QP) and coarse (every
10th QP of each sequence, warm from the previous kept one), beside the same solves of
the original problem; each answer is judged as the benchmark judges it (SOLVED and
every torque within 5 % of its limit of the set's exact reference ``x_ref``) and by
the original problem's KKT residuals::

    PYTHONPATH=src:. python tools/elimination_study.py [--robots go2 ...] [--save F.json]
"""

from __future__ import annotations

import argparse
import json
import sys
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import scipy.linalg as sl

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT / "tools"))
from callgrind_ticks import set_path, tick_positions  # noqa: E402

ROBOTS = ("solo12", "anymal_c", "go2", "talos_reduced")
RCOND_MIN = 1e-10
"""Reciprocal 1-norm condition estimate of ``K`` below which the elimination is refused."""
FLAT = np.array([0.0, 0.0, 1.0])
KINDS = ("original", "all", "slacks kept")
NAMES = ("P", "q", "A", "b", "lb", "ub", "cone_starts", "mus", "normals")


@dataclass
class Elimination:
    """The reduction of one QP: what to solve and how to come back."""

    free: np.ndarray            # indices of the eliminated entries
    kept: np.ndarray            # indices of the entries that stay (the reduced x)
    rows: np.ndarray            # the rows that eliminate them
    rest: np.ndarray            # the rows that stay (rows of the reduced problem)
    lu: tuple                   # scipy's pivoted LU of K
    w: np.ndarray               # K^-1 b
    W: np.ndarray               # K^-1 A_c
    rcond: float
    P: np.ndarray               # reduced problem: P', q'', A', b', lb, ub, cone starts
    q: np.ndarray
    A: np.ndarray
    b: np.ndarray
    lb: np.ndarray
    ub: np.ndarray
    cone_starts: np.ndarray


def free_entries(n: int, lb: np.ndarray, ub: np.ndarray, starts: np.ndarray) -> np.ndarray:
    """Mask of the entries with no finite bound and in no cone block (3 entries each)."""
    free = np.isinf(lb) & np.isinf(ub)
    for s in starts:
        free[int(s):int(s) + 3] = False
    return free


def slack_entries(A: np.ndarray, mask: np.ndarray) -> np.ndarray:
    """Mask of the free entries whose column of ``A`` has one nonzero (a row's slack)."""
    return mask & (np.count_nonzero(A, axis=0) == 1)


def eliminate(P, q, A, b, lb, ub, starts, keep_slacks: bool = False) -> Elimination | None:
    """The reduced problem, or None when the free block is not square and well conditioned.

    ``keep_slacks``: the slack entries and their rows stay (the rows become rows of the
    reduced problem), only the other free entries go, by the rows without a slack."""
    n = P.shape[0]
    mask = free_entries(n, lb, ub, starts)
    rows = np.arange(A.shape[0])
    if keep_slacks:
        slacks = slack_entries(A, mask)
        rows = np.flatnonzero(np.count_nonzero(A[:, slacks], axis=1) == 0)
        mask &= ~slacks
    free, kept = np.flatnonzero(mask), np.flatnonzero(~mask)
    if free.size != rows.size or free.size == 0:
        return None
    K = A[np.ix_(rows, free)]
    lu = sl.lu_factor(K, check_finite=False)
    rcond = float(sl.lapack.dgecon(lu[0], np.linalg.norm(K, 1), norm="1")[0])
    if not rcond > RCOND_MIN:
        return None
    rest = np.setdiff1d(np.arange(A.shape[0]), rows)
    Ac = A[np.ix_(rows, kept)]
    w = sl.lu_solve(lu, b[rows], check_finite=False)
    W = sl.lu_solve(lu, Ac, check_finite=False)
    Pff, Pfc, Pcc = P[np.ix_(free, free)], P[np.ix_(free, kept)], P[np.ix_(kept, kept)]
    PffW = Pff @ W
    cross = Pfc.T @ W
    Pr = W.T @ PffW - cross - cross.T + Pcc
    Pr = 0.5 * (Pr + Pr.T)
    qr = q[kept] - W.T @ (Pff @ w + q[free]) + Pfc.T @ w
    position = np.searchsorted(kept, np.asarray(starts, dtype=np.int64))
    Ar = A[np.ix_(rest, kept)] - A[np.ix_(rest, free)] @ W
    br = b[rest] - A[np.ix_(rest, free)] @ w
    return Elimination(free, kept, rows, rest, lu, w, W, rcond, Pr, qr, Ar, br,
                       lb[kept], ub[kept], position)


def recover(e: Elimination, P, q, A, b, xc: np.ndarray, yr: np.ndarray, zc: np.ndarray):
    """``x``, ``y``, ``z`` of the original problem from the reduced answer ``(xc, yr,
    zc)`` (``x_f`` refined once on ``K`` when the eliminated rows miss by more than
    rounding)."""
    n = P.shape[0]
    x = np.empty(n)
    x[e.kept] = xc
    x[e.free] = e.w - e.W @ xc
    r = b[e.rows] - A[e.rows] @ x
    if np.max(np.abs(r)) > 1e-14 * (1 + np.max(np.abs(b[e.rows]))):
        x[e.free] += sl.lu_solve(e.lu, r, check_finite=False)
    y = np.empty(A.shape[0])
    y[e.rest] = yr
    g = P @ x + q + A[e.rest].T @ yr
    y[e.rows] = -sl.lu_solve(e.lu, g[e.free], trans=1, check_finite=False)
    z = np.zeros(n)
    z[e.kept] = zc
    return x, y, z


def kkt_residuals(P, q, A, b, x, y, z) -> tuple[float, float]:
    """Relative equality residual ``||Ax - b|| / (1 + ||b||)`` and dual residual
    ``||Px + q + A'y + z|| / (1 + ||q||)`` (infinity norms)."""
    eq = np.max(np.abs(A @ x - b), initial=0.0) / (1 + np.max(np.abs(b), initial=0.0))
    dual = np.max(np.abs(P @ x + q + A.T @ y + z)) / (1 + np.max(np.abs(q)))
    return float(eq), float(dual)


def cones_of(fccqp, starts, mus, normals) -> tuple:
    return tuple(fccqp.FrictionCone(int(s), float(mu),
                                    None if np.allclose(nrm, FLAT) else tuple(map(float, nrm)))
                 for s, mu, nrm in zip(starts, mus, normals, strict=True))


def load_set(robot: str, cache: Path) -> tuple[list[dict], np.ndarray]:
    """The 400 QPs of a robot's full set with their reference and torque slice."""
    from benchmarks.testsets import LAYOUT_NAMES

    path = set_path(robot, cache)
    with np.load(path, allow_pickle=False) as z:
        qps = []
        for i in range(int(z["n_qps"])):
            d = {k: z[f"qp{i}_{k}"] for k in NAMES}
            d["x_ref"] = z[f"qp{i}_x_ref"]
            d["u"] = slice(*(int(v) for v in z[f"qp{i}_layout"][LAYOUT_NAMES.index("u")]))
            qps.append(d)
        return qps, np.asarray(z["sequence"])


def torque_error(d: dict, x: np.ndarray) -> float:
    """Largest torque error relative to the joint's limit (benchmarks.metrics' measure)."""
    u = d["u"]
    return float(np.max(np.abs(x[u] - d["x_ref"][u]) / d["ub"][u], initial=0.0))


def pass_indices(sequence: np.ndarray, mode: str, stride: int) -> np.ndarray:
    if mode == "coarse":
        return np.flatnonzero(tick_positions(sequence) % stride == 0)
    return np.arange(sequence.size)


def run(fccqp, qps, sequence, preset: str, mode: str, kind: str, stride: int,
        overrides: dict) -> dict:
    """One pass; per QP iterations, status, polished, torque error, KKT residuals."""
    settings = (fccqp.Settings.realtime(100.0) if preset == "realtime" else fccqp.Settings())
    settings = settings.replace(**overrides) if overrides else settings
    solver = fccqp.Solver(settings)
    rows, previous = [], None
    for i in pass_indices(sequence, mode, stride):
        d = qps[i]
        if mode == "cold" or sequence[i] != previous:
            solver.reset()
            previous = sequence[i]
        if kind != "original":
            e = d[kind]
            r = solver.solve(e.P, e.q, e.A, e.b, e.lb, e.ub,
                             cones_of(fccqp, e.cone_starts, d["mus"], d["normals"]))
            x, y, z = recover(e, d["P"], d["q"], d["A"], d["b"], r.x, r.y, r.z)
        else:
            r = solver.solve(d["P"], d["q"], d["A"], d["b"], d["lb"], d["ub"],
                             cones_of(fccqp, d["cone_starts"], d["mus"], d["normals"]))
            x, y, z = r.x, r.y, r.z
        eq, dual = kkt_residuals(d["P"], d["q"], d["A"], d["b"], x, y, z)
        rows.append((r.iterations, r.status.value, bool(r.polished), torque_error(d, x),
                     eq, dual))
    its = np.array([r[0] for r in rows])
    err = np.array([r[3] for r in rows])
    solved = np.array([r[1] == "solved" for r in rows])
    return {"qps": len(rows), "iterations": int(its.sum()), "it_median": float(np.median(its)),
            "it_p95": float(np.percentile(its, 95, method="inverted_cdf")),
            "solved": int(solved.sum()), "polished": int(sum(r[2] for r in rows)),
            "exact": int(np.sum(solved & (err <= 0.05))),
            "torque_err_p95": float(np.percentile(err, 95, method="inverted_cdf")),
            "torque_err_max": float(err.max()),
            "eq_res_max": float(max(r[4] for r in rows)),
            "dual_res_max": float(max(r[5] for r in rows))}


def structure(qps: list[dict], kind: str) -> str:
    """Sizes before and after, how many QPs reduce, K's reciprocal condition, and the
    reduced P's condition number (median)."""
    sizes = sorted({(d["P"].shape[0], d["A"].shape[0]) + ((d[kind].kept.size,
                     d[kind].rest.size) if d[kind] else ()) for d in qps})
    rconds = [d[kind].rcond for d in qps if d[kind]]
    conds = [np.linalg.cond(d[kind].P) for d in qps[::20] if d[kind]]
    return (f"{kind}: (n, m -> n', m') {sizes}; reduced {len(rconds)} of {len(qps)}; "
            f"rcond(K) min {min(rconds):.2e} median {np.median(rconds):.2e}; "
            f"cond(P') median {np.median(conds):.1e} (every 20th QP)")


def main(argv: list[str] | None = None) -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--robots", nargs="+", choices=ROBOTS, default=list(ROBOTS))
    parser.add_argument("--presets", nargs="+", choices=("realtime", "default"),
                        default=["realtime", "default"])
    parser.add_argument("--modes", nargs="+", choices=("warm", "cold", "coarse"),
                        default=["warm", "cold", "coarse"])
    parser.add_argument("--kinds", nargs="+", choices=KINDS, default=list(KINDS),
                        help="the original problem, every free entry eliminated, or the "
                        "slack entries and their rows kept")
    parser.add_argument("--stride", type=int, default=10)
    parser.add_argument("--cache", type=Path, default=ROOT / "benchmarks" / ".cache")
    parser.add_argument("--set", nargs="+", default=[], metavar="KEY=VALUE",
                        help="settings overrides (numbers), e.g. scaling=0")
    parser.add_argument("--save", type=Path)
    args = parser.parse_args(argv)
    overrides = {k: value(v)
                 for k, v in (item.split("=") for item in args.set)}
    from threadpoolctl import threadpool_limits

    import fccqp

    threadpool_limits(1)
    print(f"fccqp: {Path(fccqp.__file__).parent}")
    out = {}
    print("| robot | preset | mode | problem | QPs | its (med / p95) | SOLVED | polished | "
          "exact | torque err p95 / max | eq. res. max | dual res. max |")
    print("|---|---|---|---|---|---|---|---|---|---|---|---|")
    for robot in args.robots:
        qps, sequence = load_set(robot, args.cache)
        for d in qps:
            d["all"] = eliminate(*(d[k] for k in NAMES[:7]))
            d["slacks kept"] = eliminate(*(d[k] for k in NAMES[:7]), keep_slacks=True)
        for kind in KINDS[1:]:
            print(f"<!-- {robot}: {structure(qps, kind)} -->", flush=True)
        for preset in args.presets:
            for mode in args.modes:
                for kind in args.kinds:
                    s = run(fccqp, qps, sequence, preset, mode, kind, args.stride,
                            overrides)
                    out[f"{robot}-{preset}-{mode}-{kind}"] = s
                    print(f"| {robot} | {preset} | {mode} | {kind} | {s['qps']} | "
                          f"{s['iterations']} ({s['it_median']:g} / {s['it_p95']:g}) | "
                          f"{s['solved']} | {s['polished']} | {s['exact']} | "
                          f"{s['torque_err_p95']:.1e} / {s['torque_err_max']:.1e} | "
                          f"{s['eq_res_max']:.1e} | {s['dual_res_max']:.1e} |", flush=True)
    if args.save:
        args.save.write_text(json.dumps(out, indent=1))


def value(text: str) -> object:
    """A setting's value from the command line: a bool, an int, a float or a string."""
    if text in ("True", "False"):
        return text == "True"
    for kind in (int, float):
        try:
            return kind(text)
        except ValueError:
            pass
    return text


if __name__ == "__main__":
    main()
