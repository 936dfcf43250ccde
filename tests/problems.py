"""Seeded random problems with cones and boxes, feasible by construction."""

from __future__ import annotations

import numpy as np
import scipy.sparse as sp

import fccqp


def random_problem(
    seed: int,
    n: int = 30,
    m: int = 8,
    n_cones: int = 3,
    n_box: int = 6,
    duplicate_rows: int = 0,
    psd_rank: int | None = None,
    soc_dim: int = 0,
):
    """Return ``(P, q, A, b, lb, ub, cones)``.

    Friction cones (every other one with a tilted normal) come first, then an
    optional second-order cone of size ``soc_dim``, then ``n_box`` boxed entries, then
    free entries (with a low-rank ``P``, plus unit curvature). ``b = A x_f`` for a point
    ``x_f`` inside every set. ``duplicate_rows`` appends multiples of the first rows of
    ``A`` (rank-deficient, consistent).
    """
    rng = np.random.default_rng(seed)
    rank = psd_rank or n
    M = rng.standard_normal((n, rank))
    P = M @ M.T / rank
    q = rng.standard_normal(n) * 3
    cones: list = []
    x_f = np.zeros(n)
    for k in range(n_cones):
        normal = None
        direction = np.array([0.0, 0.0, 1.0])
        if k % 2:
            v = rng.standard_normal(3)
            v[2] = abs(v[2]) + 1
            direction = v / np.linalg.norm(v)
            normal = tuple(direction)
        cones.append(fccqp.FrictionCone(3 * k, float(rng.uniform(0.2, 1.0)), normal))
        x_f[3 * k : 3 * k + 3] = direction * rng.uniform(0.5, 2)
    start = 3 * n_cones
    if soc_dim:
        cones.append(fccqp.SecondOrderCone(start, soc_dim))
        x_f[start] = 2.0
        start += soc_dim
    lb = np.full(n, -np.inf)
    ub = np.full(n, np.inf)
    box = np.arange(start, start + n_box)
    lb[box] = -rng.uniform(0.1, 1, n_box)
    ub[box] = rng.uniform(0.1, 1, n_box)
    x_f[box] = rng.uniform(lb[box], ub[box])
    free = np.arange(start + n_box, n)
    x_f[free] = rng.standard_normal(free.size)
    if psd_rank:  # curvature on the free entries keeps the problem bounded
        P[free, free] += 1.0
    A = rng.standard_normal((m, n))
    if duplicate_rows:
        A = np.vstack([A, 2.0 * A[:duplicate_rows]])
    return P, q, A, A @ x_f, lb, ub, cones


def large_problem(n: int, seed: int = 0):
    """A separable QP with a coupling row and a friction cone: ``n`` variables, a
    tridiagonal ``P``, two equalities, a box on most entries."""
    rng = np.random.default_rng(seed)
    main = rng.uniform(1.0, 2.0, n)
    P = sp.diags([main, -0.25 * np.ones(n - 1), -0.25 * np.ones(n - 1)], [0, 1, -1],
                 format="csc")
    q = rng.standard_normal(n)
    A = sp.csc_matrix(np.vstack([np.ones(n), np.r_[np.zeros(n - 1), 1.0]]))
    b = np.array([1.0, 2.0])
    lb, ub = np.full(n, -0.5), np.full(n, 0.5)
    lb[-3:], ub[-3:] = -np.inf, np.inf   # the cone's entries
    return P, q, A, b, lb, ub, [fccqp.FrictionCone(n - 3, 0.4)]


def mpc_problem(states: int = 12, inputs: int = 4, horizon: int = 100, seed: int = 0):
    """A linear MPC in sparse form: ``states`` states in [-5, 5], ``inputs`` inputs in
    [-0.3, 0.3]; variables ``(x_0..x_H, u_0..u_{H-1})``, ``x_{k+1} = Ad x_k + Bd u_k``,
    ``x_0`` given, cost ``sum x'Qx + u'Ru`` plus a terminal ``x'Qx``."""
    rng = np.random.default_rng(seed)
    Ad = rng.standard_normal((states, states))
    Ad *= 0.98 / max(abs(np.linalg.eigvals(Ad)))
    Bd = rng.standard_normal((states, inputs))
    nx, nu = states * (horizon + 1), inputs * horizon
    P = sp.block_diag([sp.eye(nx), 0.1 * sp.eye(nu)], format="csc")
    q = np.zeros(nx + nu)
    dynamics = sp.hstack([sp.kron(sp.eye(horizon, horizon + 1), Ad)
                          - sp.kron(sp.eye(horizon, horizon + 1, k=1), sp.eye(states)),
                          sp.kron(sp.eye(horizon), Bd)])
    start = sp.hstack([sp.eye(states, nx), sp.csr_matrix((states, nu))])
    A = sp.vstack([start, dynamics], format="csc")
    b = np.concatenate([rng.uniform(-3.0, 3.0, states), np.zeros(states * horizon)])
    lb = np.concatenate([np.full(nx, -5.0), np.full(nu, -0.3)])
    return P, q, A, b, lb, -lb, []
