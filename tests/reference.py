"""Independent reference solutions for the tests.

:func:`clarabel_solve` solves the same problem with Clarabel (an interior-point
solver with exact second-order cones) at tight tolerance. Checks of a returned point
live in :mod:`verify`.
"""

from __future__ import annotations

from dataclasses import dataclass

import clarabel
import numpy as np
import scipy.sparse as sp

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
