"""Independent reference solutions for the tests.

:func:`clarabel_solve` solves the same problem with Clarabel (an interior-point
solver with exact second-order cones) at tight tolerance, on :func:`clarabel_form`:
the problem in Clarabel's conic form, which also maps Clarabel's duals back to fccqp's
convention. Checks of a returned point live in :mod:`verify`.
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


@dataclass(frozen=True)
class ClarabelForm:
    """An fccqp problem as Clarabel's ``min 1/2 x'Px + q'x  s.t.  A x + s = b, s in K``.

    The rows of ``A`` are the equalities (zero cone), then one row per finite bound
    (``-x_i + s = -lb_i``, ``x_i + s = ub_i``, nonnegative cone), then each cone block
    as ``-B x + s = 0`` with ``s`` in a second-order cone (``B`` the identity on a
    second-order block, ``[mu n'; tangent basis]`` on a friction block).
    """

    P: sp.csc_matrix
    """Upper triangle of ``P``."""
    q: np.ndarray
    A: sp.csc_matrix
    b: np.ndarray
    cones: list
    """Clarabel's cone list, in row order."""
    equalities: int
    """Number of equality rows, which come first."""

    def duals(self, z: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Clarabel's dual ``z`` as fccqp's ``(y, z)``.

        Clarabel's stationarity ``P x + q + A'z = 0`` is fccqp's ``P x + q + A_eq'y +
        z_fccqp = 0`` with ``y`` the equality rows' part and ``z_fccqp`` the other rows'
        part mapped back through their ``A`` rows; a lower bound row (``-e_i``) then gives
        ``z_i <= 0``, an upper one ``z_i >= 0``, and on a cone block ``-z_block = B'z_c``
        lies in the dual cone because ``z_c`` lies in the (self-dual) second-order cone.
        """
        z = np.asarray(z, float)
        m = self.equalities
        return z[:m].copy(), np.asarray(self.A[m:].T @ z[m:]).reshape(-1)


def clarabel_form(P, q, A=None, b=None, lb=None, ub=None, cones=()) -> ClarabelForm:
    """The fccqp problem in Clarabel's form (see :class:`ClarabelForm`)."""
    P = np.asarray(P, float)
    n = P.shape[0]
    rows, rhs, kinds = [], [], []
    if A is not None and np.shape(A)[0] > 0:
        rows.append(np.asarray(A, float))
        rhs.append(np.asarray(b, float))
        kinds.append(clarabel.ZeroConeT(np.shape(A)[0]))
    equalities = sum(r.shape[0] for r in rows)
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
    return ClarabelForm(sp.csc_matrix(np.triu(P)), np.asarray(q, float),
                        sp.csc_matrix(np.vstack(rows)), np.concatenate(rhs), kinds, equalities)


def clarabel_sparse_form(P, q, A, b, lb, ub, cones):
    """``(P, q, G, h, cones)`` for Clarabel from sparse data whose cones are friction
    cones about the z axis (:func:`clarabel_form` builds dense matrices, too large for
    the sparse path's problems)."""
    n = q.shape[0]
    eye = sp.eye(n, format="csr")
    low, high = np.flatnonzero(np.isfinite(lb)), np.flatnonzero(np.isfinite(ub))
    rows = [A, -eye[low], eye[high]]
    kinds = [clarabel.ZeroConeT(A.shape[0]), clarabel.NonnegativeConeT(len(low) + len(high))]
    for cone in cones:   # ||(x, y)|| <= mu z
        f = cone.start
        rows.append(-sp.csr_matrix(([cone.mu, 1.0, 1.0], ([0, 1, 2], [f + 2, f, f + 1])),
                                   shape=(3, n)))
        kinds.append(clarabel.SecondOrderConeT(3))
    rhs = np.concatenate([b, -lb[low], ub[high], np.zeros(3 * len(cones))])
    return sp.triu(P, format="csc"), q, sp.vstack(rows, format="csc"), rhs, kinds


def clarabel_solve(P, q, A=None, b=None, lb=None, ub=None, cones=(), tol=1e-10) -> Reference:
    """Solve the fccqp problem with Clarabel; return its status and solution."""
    P = np.asarray(P, float)
    form = clarabel_form(P, q, A, b, lb, ub, cones)
    settings = clarabel.DefaultSettings()
    settings.verbose = False
    settings.tol_gap_abs = settings.tol_gap_rel = settings.tol_feas = tol
    settings.tol_ktratio = 1e-8
    solver = clarabel.DefaultSolver(form.P, form.q, form.A, form.b, form.cones, settings)
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
