"""Feasibility study of an active-set path with exact friction cones (issue #29).

Not part of the package: a numpy prototype that answers "can an active-set method with
exact cones, started cold from the equality-constrained solution or warm from the
previous kept tick's active set, reach the exact answer in few enough cheap steps to
cost about one warm tick?" on the benchmark's cached whole-body-control QPs.

The QP is ``min 1/2 x'Px + q'x`` s.t. ``Ax = b``, ``lb <= x <= ub`` (finite entries
only), each force block ``x_k`` in its friction cone ``K_k`` (``||t|| <= mu n'x_k``).
Two methods, both counted in KKT passes, active-set changes and a flop model:

``pdas``
    Primal-dual active set / semismooth Newton on ``x = Pi(x - c u)`` with ``u = Px +
    q + A'y`` on the constrained entries (what fccqp's polish does, but with unlimited
    passes): a box entry is free or at a bound, a cone block free, at its apex or on
    its boundary, where it contributes its tangent plane ``g'x_k = 0`` (``phi`` is
    positively homogeneous, so the plane passes through the apex) and the curvature
    ``lam H(v)`` of the Lagrangian at the last boundary point ``v``. Each pass solves
    one KKT system; the next guess is the region of ``x - c u``. No progress guarantee.
``dual``
    A Goldfarb-Idnani dual active-set method in KKT form on the box plus *cuts* of the
    cones: the cut of a block ``x_k`` outside ``K_k`` is the supporting half-space
    ``(x_k - Pi(x_k))' z <= 0`` (valid for all of ``K_k``, violated by ``x_k``).
    Every step raises the dual objective (a full step adds a constraint, a partial one
    drops a blocking one), so the method terminates on the polyhedral outer
    approximation, and new cuts are added until the exact cones hold to ``CONE_TOL``.
    Cold it starts from the equality-constrained solution (empty working set); warm
    from the previous kept tick's working set (its bounds and cuts), from which the
    rows with negative multipliers are dropped first.

DAQP (4-facet inner pyramid, as the benchmark calls it) runs on the same paths for its
iteration counts. Run::

    PYTHONPATH=src:. python tools/activeset_study.py --robots go2 talos_reduced \
        --save /tmp/activeset-study.json

The cost model (flops): a factorization of an ``N``-row KKT matrix ``N^3/3``, a rank-one
update or a solve ``N^2``; ``pdas`` is priced both refactoring each pass and as updates
of a base factorization, ``dual`` as updates (one per working-set change, plus a solve).
"""

from __future__ import annotations

import argparse
import glob
import json
from dataclasses import dataclass, field

import numpy as np
from benchmarks import testsets, views
from benchmarks.metrics import qp_metrics
from benchmarks.pyramid_solvers import DaqpAdapter

CONE_TOL = 1e-9
"""Cone violation ``max(0, ||t|| - mu n'f)`` accepted, relative to ``1 + max |f|``."""

BOX_TOL = 1e-9
"""Bound violation accepted, relative to ``1 + max |bound|``."""

DUAL_TOL = 1e-9
"""Wrong-signed multiplier accepted, relative to ``1 + ||q||_inf``."""

MAX_PASSES = 30
"""Passes (pdas) or working-set changes / 4 (dual) before a run counts as failed."""


NEWTON_COSINE = 0.9
"""A cone's cut is relinearized (Newton) rather than joined by a new cut when the two
normals' cosine exceeds this: far from the solution (or at an apex, which needs several
cuts) a rotating single plane cycles."""


NEWTON_STEPS = 40
"""Steps after which the dual method stops relinearizing and only cuts (a guard against
the cycles that Newton steps, which are not dual ascent steps, can make)."""


@dataclass
class Qp:
    """The dense data: box entries ``box`` with finite ``lo``/``hi``, cone blocks."""

    P: np.ndarray
    q: np.ndarray
    A: np.ndarray
    b: np.ndarray
    box: np.ndarray
    lo: np.ndarray
    hi: np.ndarray
    starts: np.ndarray
    mus: np.ndarray
    normals: np.ndarray

    @property
    def n(self) -> int:
        return self.q.size

    @property
    def m(self) -> int:
        return self.b.size


def make_qp(wbc) -> Qp:
    box = np.flatnonzero(np.isfinite(wbc.lb) | np.isfinite(wbc.ub))
    return Qp(np.asarray(wbc.P), np.asarray(wbc.q), np.asarray(wbc.A), np.asarray(wbc.b),
              box, np.asarray(wbc.lb)[box], np.asarray(wbc.ub)[box],
              np.asarray(wbc.cone_starts), np.asarray(wbc.mus), np.asarray(wbc.normals))


# --- cone geometry (the friction cone about a unit normal) -------------------------------

def split(v, nrm):
    fn = nrm @ v
    t = v - fn * nrm
    return fn, t, float(np.linalg.norm(t))


def project(v, mu, nrm):
    fn, t, a = split(v, nrm)
    if a <= mu * fn:
        return v.copy()
    if mu * a <= -fn:
        return np.zeros(3)
    nf = (mu * a + fn) / (1.0 + mu * mu)
    return nf * nrm + (mu * nf / a) * t


def violation(v, mu, nrm):
    fn, _, a = split(v, nrm)
    return max(0.0, a - mu * fn)


def plane(v, mu, nrm):
    """Unit gradient of ``phi = ||t|| - mu n'f`` at ``v`` (off the axis)."""
    fn, t, a = split(v, nrm)
    return (t / a - mu * nrm) / np.sqrt(1.0 + mu * mu)


def curvature(v, mu, nrm):
    """Hessian of the normalized ``phi`` at ``v``: rank one, ``w w' / (||t|| s)``."""
    fn, t, a = split(v, nrm)
    if a <= 0:
        return np.zeros((3, 3))
    w = np.cross(nrm, t / a)
    return np.outer(w, w) / (a * np.sqrt(1.0 + mu * mu))


def in_dual(u, mu, nrm, tol):
    """Distance of ``u`` to the dual cone (slope ``1/mu``) below ``tol``."""
    fn, _, a = split(u, nrm)
    return max(0.0, mu * a - fn) / np.sqrt(1 + mu * mu) <= tol


# --- helpers ----------------------------------------------------------------------------

def kkt_solve(K, rhs):
    return np.linalg.solve(K, rhs)


def eq_solution(qp: Qp):
    """The equality-constrained minimizer ``(x, y)`` and its KKT size."""
    n, m = qp.n, qp.m
    K = np.block([[qp.P, qp.A.T], [qp.A, np.zeros((m, m))]])
    s = kkt_solve(K, np.r_[-qp.q, qp.b])
    return s[:n], s[n:], n + m


def optimal(qp: Qp, x, u) -> bool:
    """KKT conditions of the exact problem at ``x`` with constrained duals ``u``."""
    scale_x = 1.0 + np.max(np.abs(x))
    scale_u = 1.0 + np.max(np.abs(qp.q))
    bnd = 1.0 + np.max(np.abs(np.r_[qp.lo, qp.hi]))
    xb, ub_ = x[qp.box], u[qp.box]
    if np.any(xb < qp.lo - BOX_TOL * bnd) or np.any(xb > qp.hi + BOX_TOL * bnd):
        return False
    at_lo = xb <= qp.lo + 1e-7 * bnd
    at_hi = xb >= qp.hi - 1e-7 * bnd
    free = ~(at_lo | at_hi)
    if np.any(np.abs(ub_[free]) > DUAL_TOL * scale_u):
        return False
    if np.any(ub_[at_lo] < -DUAL_TOL * scale_u) or np.any(ub_[at_hi] > DUAL_TOL * scale_u):
        return False
    for s, mu, nrm in zip(qp.starts, qp.mus, qp.normals, strict=True):
        v, w = x[s:s + 3], u[s:s + 3]
        if violation(v, mu, nrm) > CONE_TOL * scale_x:
            return False
        if not in_dual(w, mu, nrm, DUAL_TOL * scale_u):
            return False
        if abs(v @ w) > 1e-7 * scale_x * scale_u:
            return False
    return True


@dataclass
class Run:
    """One solve's counts."""

    ok: bool = False
    passes: int = 0
    changes: int = 0
    sizes: list = field(default_factory=list)
    flops_refactor: float = 0.0
    flops_update: float = 0.0
    x: np.ndarray | None = None
    state: object = None
    point: object = None


# --- (a) primal-dual active set / semismooth Newton with exact cones --------------------

FREE, LOWER, UPPER, APEX, BOUNDARY = 0, 1, 2, 3, 4


def pdas(qp: Qp, x, u, lam_prev, c_box, c_cone, count_base: bool) -> Run:
    """Semismooth Newton from the point ``(x, u)`` (``u`` the constrained duals) and the
    boundary multipliers ``lam_prev`` (dict cone -> lam) for the curvature terms."""
    n, m = qp.n, qp.m
    run = Run()
    box_code = np.zeros(qp.box.size, dtype=int)
    cone_code = np.zeros(qp.starts.size, dtype=int)
    points = [None] * qp.starts.size
    lam = dict(lam_prev)
    base = n + m
    if count_base:
        run.flops_update += base ** 3 / 3
    previous_rows = None
    for _ in range(MAX_PASSES):
        # the guess from (x, u)
        w = x[qp.box] - c_box * u[qp.box]
        new_box = np.where(w < qp.lo, LOWER, np.where(w > qp.hi, UPPER, FREE))
        new_cone = np.zeros_like(cone_code)
        for k, (s, mu, nrm) in enumerate(zip(qp.starts, qp.mus, qp.normals, strict=True)):
            v = x[s:s + 3] - c_cone * u[s:s + 3]
            fn, _, a = split(v, nrm)
            if a <= mu * fn:
                new_cone[k] = FREE
            elif mu * a <= -fn:
                new_cone[k] = APEX
            else:
                new_cone[k] = BOUNDARY
                # the boundary point: that of x itself when it has one (the term
                # -c lam_old H x of u would turn the plane by c lam / ||t|| times
                # the tangential error), else that of x - c u
                p = project(x[s:s + 3], mu, nrm)
                points[k] = p if split(p, nrm)[2] > 0 else project(v, mu, nrm)
                g = plane(points[k], mu, nrm)
                if k not in lam:
                    lam[k] = max(0.0, -g @ u[s:s + 3])
        run.changes += int(np.sum(new_box != box_code) + np.sum(new_cone != cone_code))
        box_code, cone_code = new_box, new_cone
        # the KKT system of the guess
        rows, rhs = [], []
        Pk = qp.P.copy()
        for i, j in enumerate(qp.box):
            if box_code[i] != FREE:
                r = np.zeros(n)
                r[j] = 1.0
                rows.append(r)
                rhs.append(qp.lo[i] if box_code[i] == LOWER else qp.hi[i])
        bnd = []
        for k, (s, mu, nrm) in enumerate(zip(qp.starts, qp.mus, qp.normals, strict=True)):
            if cone_code[k] == APEX:
                for d in range(3):
                    r = np.zeros(n)
                    r[s + d] = 1.0
                    rows.append(r)
                    rhs.append(0.0)
            elif cone_code[k] == BOUNDARY:
                r = np.zeros(n)
                r[s:s + 3] = plane(points[k], mu, nrm)
                rows.append(r)
                rhs.append(0.0)
                bnd.append(k)
                Pk[s:s + 3, s:s + 3] += lam.get(k, 0.0) * curvature(points[k], mu, nrm)
        C = np.array(rows).reshape(-1, n)
        nc = C.shape[0]
        K = np.block([[Pk, qp.A.T, C.T], [qp.A, np.zeros((m, m + nc))],
                      [C, np.zeros((nc, m + nc))]])
        sol = kkt_solve(K, np.r_[-qp.q, qp.b, rhs])
        x = sol[:n]
        y = sol[n:n + m]
        nu = sol[n + m:]
        u = qp.P @ x + qp.q + qp.A.T @ y
        # boundary multipliers: the plane rows are the last len(bnd) of C
        for i, k in enumerate(bnd):
            lam[k] = float(nu[nc - len(bnd) + i])
        fixed = int(np.sum(box_code != FREE)) + 3 * int(np.sum(cone_code == APEX))
        reduced = n - fixed + m + len(bnd)
        augmented = n + m + nc
        run.sizes.append(reduced)
        run.passes += 1
        run.flops_refactor += reduced ** 3 / 3 + reduced ** 2
        # updates: each row added or removed, and each boundary block's plane and
        # curvature (two rank-one changes when they moved), plus the solve
        key = set(tuple(np.round(r, 12)) for r in C)
        delta = len(key ^ previous_rows) if previous_rows is not None else nc
        delta += 2 * len(bnd)
        previous_rows = key
        run.flops_update += delta * augmented ** 2 + augmented ** 2
        if optimal(qp, x, u):
            run.ok = True
            break
    run.x = x
    run.state = (x, u, {k: v for k, v in lam.items() if cone_code[k] == BOUNDARY})
    return run


# --- (b) dual active set (Goldfarb-Idnani in KKT form) with box rows and cone cuts ------

def most_violated(qp: Qp, x, cuts):
    """The most violated constraint as (row, rhs, key, violation): bounds, existing
    cuts, new cuts of the exact cones; ``None`` when all hold."""
    n = qp.n
    bnd = 1.0 + np.max(np.abs(np.r_[qp.lo, qp.hi]))
    best = None
    xb = x[qp.box]
    for i, j in enumerate(qp.box):
        for sign, lim in ((-1.0, qp.lo[i]), (1.0, qp.hi[i])):
            viol = sign * (xb[i] - lim)
            if viol > BOX_TOL * bnd and (best is None or viol / bnd > best[3]):
                r = np.zeros(n)
                r[j] = sign
                best = (r, sign * lim, ("box", i, sign), viol / bnd)
    scale_x = 1.0 + np.max(np.abs(x))
    for k, (s, mu, nrm) in enumerate(zip(qp.starts, qp.mus, qp.normals, strict=True)):
        v = x[s:s + 3]
        viol = violation(v, mu, nrm)
        if viol > CONE_TOL * scale_x and (best is None or viol / scale_x > best[3]):
            d = v - project(v, mu, nrm)
            d /= np.linalg.norm(d)
            r = np.zeros(n)
            r[s:s + 3] = d
            best = (r, 0.0, ("cut", k, len(cuts)), viol / scale_x)
    return best


def dual_as(qp: Qp, working, newton: bool = False) -> Run:
    """Goldfarb-Idnani from the working set ``working`` (list of (row, rhs, key)).

    With ``newton`` (before :data:`NEWTON_STEPS` steps), a violated cone whose cuts in
    the working set are all near its new cut (:data:`NEWTON_COSINE`) is not cut again:
    its cuts are replaced by the tangent plane at the projection of its block, and its
    curvature ``lam H`` (``lam`` the cuts' multipliers' sum) joins the Hessian, and so
    for every other violated cone with near cuts (a Newton pass on those blocks,
    quadratic instead of the linear rate of cuts); then the working set's equality QP is
    solved again and negative multipliers are dropped.

    The KKT matrix of the working set is refactored here with numpy (prototype); the
    cost model counts one ``N^2`` update per change and one ``N^2`` solve per step
    (four rank-one updates for a relinearized plane and curvature).
    """
    n, m = qp.n, qp.m
    run = Run()
    W = list(working)
    Hc: dict = {}
    run.flops_update += (n + m) ** 3 / 3

    def kkt():
        C = np.array([r for r, _, _ in W]).reshape(-1, n)
        nc = C.shape[0]
        H = qp.P.copy()
        for k, Hk in Hc.items():
            s = qp.starts[k]
            H[s:s + 3, s:s + 3] += Hk
        K = np.block([[H, qp.A.T, C.T], [qp.A, np.zeros((m, m + nc))],
                      [C, np.zeros((nc, m + nc))]])
        run.sizes.append(n + m + nc)
        return K, nc

    def eqp():
        K, nc = kkt()
        s = kkt_solve(K, np.r_[-qp.q, qp.b, [h for _, h, _ in W]])
        run.flops_update += K.shape[0] ** 2
        return s[:n], s[n:n + m], s[n + m:]

    def drop(i):
        key = W.pop(i)[2]
        if key[0] == "cut":
            Hc.pop(key[1], None)
        run.changes += 1
        run.flops_update += (n + m + len(W)) ** 2

    def dual_feasible():
        # drop the most negative multiplier until none is (the start, and after a
        # Newton step on a cone)
        while True:
            x, y, lamw = eqp()
            if not W or lamw.min() >= 0:
                return x, y, lamw
            drop(int(np.argmin(lamw)))

    def relinearize(k, r_p):
        """Replace cone ``k``'s cuts by the plane ``r_p`` at the projection of its
        block, with the curvature weighted by their multipliers' sum; False (nothing
        done) unless every cut of ``k`` is near ``r_p`` and the projection is off the
        axis."""
        nonlocal lamw
        mine = [i for i, w in enumerate(W) if w[2][0] == "cut" and w[2][1] == k]
        s = qp.starts[k]
        v = project(x[s:s + 3], qp.mus[k], qp.normals[k])
        near = bool(mine) and all(W[i][0] @ r_p > NEWTON_COSINE for i in mine)
        if not (near and split(v, qp.normals[k])[2] > 0):
            return False
        lam_k = float(sum(lamw[i] for i in mine))
        for i in sorted(mine[1:], reverse=True):
            W.pop(i)
            lamw = np.delete(lamw, i)
        i = mine[0]
        W[i] = (r_p, 0.0, W[i][2])
        Hc[k] = lam_k * curvature(v, qp.mus[k], qp.normals[k])
        run.changes += len(mine)
        run.flops_update += (3 + len(mine)) * (n + m + len(W)) ** 2
        return True

    if W:
        run.flops_update += len(W) * (n + m + len(W)) ** 2
    x, y, lamw = dual_feasible()
    cuts: list = []
    steps = 0
    while steps < 200:
        new = most_violated(qp, x, cuts)
        if new is None:
            break
        r_p, h_p, key_p, _ = new
        if newton and steps >= NEWTON_STEPS:
            newton = False  # cycling: the cuts alone terminate
        if newton and key_p[0] == "cut" and relinearize(key_p[1], r_p):
            # a Newton pass: every other violated cone with near cuts moves too
            for k in range(qp.starts.size):
                s = qp.starts[k]
                v = x[s:s + 3]
                if k != key_p[1] and violation(v, qp.mus[k], qp.normals[k]) > 0:
                    d = v - project(v, qp.mus[k], qp.normals[k])
                    r = np.zeros(n)
                    r[s:s + 3] = d / np.linalg.norm(d)
                    relinearize(k, r)
            steps += 1
            x, y, lamw = dual_feasible()
            continue
        lam_p = 0.0
        while True:
            steps += 1
            K, nc = kkt()
            d = kkt_solve(K, np.r_[-r_p, np.zeros(m + nc)])
            run.flops_update += K.shape[0] ** 2
            dx, dlw = d[:n], d[n + m:]
            slope = r_p @ dx  # change of r_p'x per unit multiplier (<= 0)
            gap = r_p @ x - h_p
            t_full = gap / -slope if slope < -1e-14 * (1 + np.abs(r_p).max()) else np.inf
            t_dual, block = np.inf, -1
            for i in range(nc):
                if dlw[i] < -1e-14:
                    t = lamw[i] / -dlw[i]
                    if t < t_dual:
                        t_dual, block = t, i
            if not np.isfinite(min(t_full, t_dual)):
                run.x = x
                return run  # infeasible (a certificate's job)
            t = min(t_full, t_dual)
            x = x + t * dx
            lamw = lamw + t * dlw
            lam_p += t
            if t_full <= t_dual:
                W.append((r_p, h_p, key_p))
                lamw = np.r_[lamw, lam_p]
                run.changes += 1
                run.flops_update += K.shape[0] ** 2 + 2 * (n + m + nc)
                break
            had_curvature = W[block][2][0] == "cut" and W[block][2][1] in Hc
            drop(block)
            lamw = np.delete(lamw, block)
            if had_curvature:  # the Hessian changed: back to the working set's QP
                x, y, lamw = dual_feasible()
        if key_p[0] == "cut":
            cuts.append(key_p)
    # the duals of the final point, to verify the KKT conditions of the exact problem
    # (the curvature terms stay: they vanish at a converged boundary point, H v = 0)
    x, y, lamw = eqp()
    u = qp.P @ x + qp.q + qp.A.T @ y
    run.passes = steps
    run.ok = optimal(qp, x, u)
    run.x = x
    run.state = [w for w, lw in zip(W, lamw, strict=True) if lw > 0]
    run.point = (x, u, boundary_multipliers(qp, x, u))
    return run


def boundary_multipliers(qp: Qp, x, u):
    """Each boundary block's multiplier ``-g'u`` at the solution (the curvature weights
    of a Newton warm start)."""
    lam = {}
    for k, (s, mu, nrm) in enumerate(zip(qp.starts, qp.mus, qp.normals, strict=True)):
        v = x[s:s + 3]
        fn, _, a = split(v, nrm)
        if a > 1e-9 * (1 + abs(fn)) and fn > 0:
            lam[k] = max(0.0, float(-plane(v, mu, nrm) @ u[s:s + 3]))
    return lam


# --- paths -------------------------------------------------------------------------------

def daqp_iterations(ts, path, adapter):
    out = []
    for idx, fresh in zip(path.indices, path.fresh, strict=True):
        if fresh:
            adapter.reset()
        o = adapter.solve(adapter.prepare(ts.qps[idx]))
        out.append(o.iterations if o.success else -1)
    return out


def record(run: Run, wbc, x_ref, method):
    met = qp_metrics(wbc, run.x, x_ref)
    return {
        "method": method,
        "ok": bool(run.ok),
        "torque_error_rel": met.torque_error_rel,
        "x_error": float(np.max(np.abs(run.x - x_ref)) / (1 + np.max(np.abs(x_ref)))),
        "passes": run.passes,
        "changes": run.changes,
        "max_size": max(run.sizes) if run.sizes else 0,
        "flops_refactor": run.flops_refactor,
        "flops_update": run.flops_update,
    }


def guarded_dual(qp: Qp, working, x0) -> Run:
    """``dual_as`` with Newton steps; a singular working-set KKT matrix (dependent rows,
    which the prototype does not resolve as DAQP does) counts as a failure at ``x0``."""
    try:
        return dual_as(qp, working, newton=True)
    except np.linalg.LinAlgError:
        return Run(x=x0, state=[])


def study(ts, paths, c_scale: float, everything: bool = True):
    rows = []
    for path in paths:
        daqp = daqp_iterations(ts, path, DaqpAdapter("daqp"))
        changed = views.contact_changes(path)
        prev_a = prev_b = prev_c = None
        prev_n = None
        for pos, (idx, fresh) in enumerate(zip(path.indices, path.fresh, strict=True)):
            wbc = ts.qps[idx]
            qp = make_qp(wbc)
            cold = fresh or prev_n != qp.n
            x0, y0, _ = eq_solution(qp)
            c_box = c_scale / np.maximum(np.diag(qp.P)[qp.box], 1e-12)
            forces = (qp.starts[:, None] + np.arange(3)).ravel()
            c_cone = c_scale / max(np.max(np.diag(qp.P)[forces]), 1e-12)
            b = guarded_dual(qp, [] if cold else prev_b, x0)
            if everything and cold:
                a = pdas(qp, x0, np.zeros(qp.n), {}, c_box, c_cone, count_base=True)
                a.flops_refactor += (qp.n + qp.m) ** 3 / 3
                bc = dual_as(qp, [])
            elif everything:
                xp, up, lamp = prev_a
                a = pdas(qp, xp, up, lamp, c_box, c_cone, count_base=True)
                bc = dual_as(qp, prev_c)
            base = {"robot": ts.robot, "view": path.view, "qp": int(idx), "cold": bool(cold),
                    "contact_change": bool(changed[pos]), "daqp_iterations": daqp[pos],
                    "n": qp.n, "m": qp.m}
            rows.append(base | record(b, wbc, ts.x_ref[idx], "dual+newton"))
            # the same run handed to a Newton polish (the existing polish's job): its
            # final point and duals guess the active set, pdas makes it exact
            p = (pdas(qp, *b.point, c_box, c_cone, count_base=False) if b.point is not None
                 else Run(x=b.x))
            joint = Run(ok=p.ok, passes=b.passes, changes=b.changes + p.changes,
                        sizes=b.sizes + p.sizes, flops_refactor=p.flops_refactor,
                        flops_update=b.flops_update + p.flops_refactor, x=p.x)
            rows.append(base | record(joint, wbc, ts.x_ref[idx], "dual+newton+polish")
                        | {"polish_passes": p.passes})
            if everything:
                rows.append(base | record(a, wbc, ts.x_ref[idx], "pdas"))
                rows.append(base | record(bc, wbc, ts.x_ref[idx], "dual cuts"))
            # the warm start of the next tick: each method's own state when it succeeded,
            # else the exact previous answer (what a fallback to ADMM would leave)
            prev_b, prev_n = b.state, qp.n
            if everything:
                exact = b.point if b.ok else None
                prev_a = a.state if a.ok else exact
                prev_c = bc.state
                if prev_a is None:
                    prev_n = None
    return rows


def summary(rows):
    out = []
    keys = sorted({(r["robot"], r["view"], r["method"]) for r in rows})
    for robot, view, method in keys:
        for sel, label in ((lambda r: True, view),
                           (lambda r: r["contact_change"], "contact change")):
            rs = [r for r in rows if r["robot"] == robot and r["view"] == view
                  and r["method"] == method and sel(r)]
            if not rs or (label == "contact change" and view != "warm"):
                continue
            ok = np.array([r["ok"] for r in rs])
            exact = np.array([r["torque_error_rel"] <= 0.05 for r in rs])
            passes = np.array([r["passes"] for r in rs])
            changes = np.array([r["changes"] for r in rs])
            fu = np.array([r["flops_update"] for r in rs])
            fr = np.array([r["flops_refactor"] for r in rs])
            dq = np.array([r["daqp_iterations"] for r in rs])
            xe = np.array([r["x_error"] for r in rs])
            pp = np.array([r.get("polish_passes", 0) for r in rs])
            out.append(
                f"| {robot} | {label} | {method} | {len(rs)} | {100 * ok.mean():.1f} % | "
                f"{100 * exact.mean():.1f} % | {np.median(xe):.1e} / {np.max(xe):.1e} | "
                f"{np.median(passes):.0f} / {np.percentile(passes, 95):.0f} / {passes.max()} | "
                f"{np.median(changes):.0f} / {np.percentile(changes, 95):.0f} | "
                f"{np.median(fu) / 1e3:.0f}k / {np.percentile(fu, 95) / 1e3:.0f}k | "
                f"{np.median(fr) / 1e3:.0f}k | {np.median(pp):.0f} / {np.percentile(pp, 95):.0f} | "
                f"{np.median(dq):.0f} / {np.percentile(dq, 95):.0f} |")
    head = ("| robot | view | method | QPs | KKT-optimal | torque <= 5 % | x error med / max | "
            "passes med / p95 / max | changes med / p95 | flops (updates) med / p95 | "
            "flops (refactor) med | polish passes med / p95 | DAQP iterations med / p95 |\n|"
            + "---|" * 13)
    return "\n".join([head, *out])


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--robots", nargs="+", default=["go2", "talos_reduced"])
    parser.add_argument("--cache", default="/tmp/fullrun/benchmarks/.cache")
    parser.add_argument("--qps", type=int, default=400, help="first QPs of each set")
    parser.add_argument("--every", type=int, default=1,
                        help="keep every k-th of those QPs (the cold view of a sample)")
    parser.add_argument("--c-scale", type=float, default=1.0,
                        help="semismooth Newton's c as a multiple of 1/diag(P)")
    parser.add_argument("--views", nargs="+", default=["cold", "every 10th", "warm"])
    parser.add_argument("--save", default=None)
    parser.add_argument("--newton-only", action="store_true",
                        help="run dual+newton alone (not pdas and the cuts-only dual)")
    args = parser.parse_args()
    rows = []
    for robot in args.robots:
        (path,) = glob.glob(f"{args.cache}/{robot}-mix-seed0-n400-*gen2.npz")
        ts = testsets.load(path)
        keep = np.arange(min(args.qps, len(ts)))[::args.every]
        all_paths = {"cold": views.cold_path(ts), "every 10th": views.coarse_path(ts, 10),
                     "warm": views.warm_path(ts)}
        paths = []
        for v in args.views:
            p = all_paths[v]
            sel = np.isin(p.indices, keep)
            paths.append(views.Path(p.view, ts, p.indices[sel], p.fresh[sel]))
        rows += study(ts, paths, args.c_scale, not args.newton_only)
        print(summary([r for r in rows if r["robot"] == robot]), flush=True)
    if args.save:
        with open(args.save, "w") as fh:
            json.dump(rows, fh)


if __name__ == "__main__":
    main()
