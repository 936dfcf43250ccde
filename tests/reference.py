"""Independent reference solutions and checks for the tests.

:func:`clarabel_solve` solves the same problem with Clarabel (an interior-point
solver with exact second-order cones) at tight tolerance; :func:`kkt_violation`
recomputes optimality conditions of a returned primal-dual pair from scratch.
"""

from __future__ import annotations

from dataclasses import dataclass

import clarabel
import numpy as np
import scipy.sparse as sp

import fccqp
from fccqp.cones import FRICTION, flatten_cones


@dataclass
class Reference:
    status: str
    x: np.ndarray | None
    obj: float | None


def tangent_basis(normal: np.ndarray) -> np.ndarray:
    """Two orthonormal vectors spanning the plane orthogonal to ``normal``."""
    helper = np.eye(3)[np.argmin(np.abs(normal))]
    t1 = np.cross(normal, helper)
    t1 /= np.linalg.norm(t1)
    return np.vstack([t1, np.cross(normal, t1)])


def clarabel_solve(P, q, A=None, b=None, lb=None, ub=None, cones=(), tol=1e-10) -> Reference:
    """Solve the fccqp problem with Clarabel; return its status and solution."""
    P = np.asarray(P, float)
    n = P.shape[0]
    rows, rhs, kinds = [], [], []
    if A is not None and np.shape(A)[0] > 0:
        rows.append(np.asarray(A, float))
        rhs.append(np.asarray(b, float))
        kinds.append(clarabel.ZeroConeT(np.shape(A)[0]))
    eye = np.eye(n)
    box_rows, box_rhs = [], []
    for i in range(n):
        if lb is not None and np.isfinite(lb[i]):
            box_rows.append(-eye[i])
            box_rhs.append(-lb[i])
        if ub is not None and np.isfinite(ub[i]):
            box_rows.append(eye[i])
            box_rhs.append(ub[i])
    if box_rows:
        rows.append(np.array(box_rows))
        rhs.append(np.array(box_rhs))
        kinds.append(clarabel.NonnegativeConeT(len(box_rows)))
    flat = flatten_cones(cones, n)
    for k in range(flat.count):
        s, d = flat.offset[k], flat.dim[k]
        block = np.zeros((d, n))
        if flat.kind[k] == FRICTION:
            normal = flat.normal[k]
            block[0, s : s + 3] = flat.mu[k] * normal
            block[1:, s : s + 3] = tangent_basis(normal)
        else:
            block[:, s : s + d] = np.eye(d)
        rows.append(-block)
        rhs.append(np.zeros(d))
        kinds.append(clarabel.SecondOrderConeT(int(d)))
    if not rows:
        rows, rhs = [np.zeros((0, n))], [np.zeros(0)]
    settings = clarabel.DefaultSettings()
    settings.verbose = False
    settings.tol_gap_abs = settings.tol_gap_rel = settings.tol_feas = tol
    settings.tol_ktratio = 1e-8
    solver = clarabel.DefaultSolver(
        sp.csc_matrix(np.triu(P)), np.asarray(q, float), sp.csc_matrix(np.vstack(rows)),
        np.concatenate(rhs), kinds, settings,
    )
    sol = solver.solve()
    status = str(sol.status)
    if status in ("Solved", "AlmostSolved"):
        x = np.array(sol.x)
        return Reference("solved", x, float(0.5 * x @ P @ x + np.dot(q, x)))
    if "PrimalInfeasible" in status:
        return Reference("primal_infeasible", None, None)
    if "DualInfeasible" in status:
        return Reference("dual_infeasible", None, None)
    return Reference(status, None, None)


def cone_distance(x: np.ndarray, cones, n: int) -> float:
    """Largest distance of a cone block of ``x`` to its cone."""
    flat = flatten_cones(cones, n)
    worst = 0.0
    for k in range(flat.count):
        s, d = flat.offset[k], flat.dim[k]
        block = x[s : s + d]
        if flat.kind[k] == FRICTION:
            fn = flat.normal[k] @ block
            tangential = np.linalg.norm(block - fn * flat.normal[k])
            excess = tangential - flat.mu[k] * fn
            worst = max(worst, excess / np.sqrt(1 + flat.mu[k] ** 2))
        else:
            worst = max(worst, (np.linalg.norm(block[1:]) - block[0]) / np.sqrt(2))
    return max(worst, 0.0)


def kkt_violation(P, q, A, b, lb, ub, cones, result: fccqp.Result) -> dict[str, float]:
    """Recompute primal feasibility, stationarity and complementarity of a result."""
    P = np.asarray(P, float)
    n = P.shape[0]
    x, y, z = result.x, result.y, result.z
    lb = np.full(n, -np.inf) if lb is None else np.asarray(lb, float)
    ub = np.full(n, np.inf) if ub is None else np.asarray(ub, float)
    A = np.zeros((0, n)) if A is None else np.asarray(A, float)
    b = np.zeros(0) if b is None else np.asarray(b, float)
    stationarity = P @ x + q + A.T @ y + z
    box = np.isfinite(lb) | np.isfinite(ub)
    flat = flatten_cones(cones, n)
    # box duals: z <= 0 unless at upper bound, z >= 0 unless at lower bound
    scale = 1 + np.abs(x)
    at_lower = np.abs(x - lb) <= 1e-4 * scale
    at_upper = np.abs(x - ub) <= 1e-4 * scale
    sign_error = np.where(box & ~at_upper, np.maximum(z, 0), 0) + np.where(
        box & ~at_lower, np.maximum(-z, 0), 0
    )
    complementarity = 0.0
    for k in range(flat.count):
        s, d = flat.offset[k], flat.dim[k]
        complementarity = max(complementarity, abs(x[s : s + d] @ z[s : s + d]))
    dual_cone = []
    for k in range(flat.count):
        dual = fccqp.FrictionCone(0, 1 / flat.mu[k], flat.normal[k]) if flat.kind[k] == FRICTION \
            else fccqp.SecondOrderCone(0, int(flat.dim[k]))
        block = -z[flat.offset[k] : flat.offset[k] + flat.dim[k]]
        dual_cone.append(cone_distance(block, [dual], block.shape[0]))
    return {
        "equality": float(np.max(np.abs(A @ x - b), initial=0.0)),
        "box": float(np.max(np.maximum(lb - x, 0) + np.maximum(x - ub, 0), initial=0.0)),
        "cone": cone_distance(x, cones, n),
        "stationarity": float(np.max(np.abs(stationarity))),
        "box_dual_sign": float(np.max(sign_error, initial=0.0)),
        "cone_dual": float(max(dual_cone, default=0.0)),
        "cone_complementarity": complementarity,
    }
