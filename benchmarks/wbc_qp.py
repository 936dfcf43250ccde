"""The whole-body-control QP of the FCCQP paper (section 4, eq. 10), built with Pinocchio.

Decision variables, in this order (see :attr:`WbcQP.layout`)::

    x = [vdot (nv), u (nu = nv - 6), lambda_h (nh), eps (3k), lambda_c (3k)]

for ``k`` active contact points. The QP is

    minimize    1/2 x'Px + q'x
    subject to  A x = b,  lb <= x <= ub,  lambda_c,i in F(mu_i, n_i)  for each contact i

with the equalities (stacked in this order)

    M vdot + h = B u + Jh' lambda_h + Jc' lambda_c     dynamics            (nv rows)
    Jh vdot    = -Jhdot v + a_h                        holonomic           (nh rows)
    Jc vdot + eps = -Jcdot v + a_c                     soft contact        (3k rows)

where ``a_h`` and ``a_c`` are optional reference accelerations (zero in the paper; the
scenarios use them for Baumgarte stabilization). The cost is the sum of weighted
task-space acceleration errors ``1/2 ||J_i vdot + Jdot_i v - ydd_cmd_i||^2_W`` (CoM, base
orientation, point tasks for swing feet or hands, joint posture) plus a diagonal
regularization on every block: heavy on ``eps`` (contacts are soft but should hold),
light on ``lambda_c`` and ``lambda_h`` so that ``P`` is positive definite on all variables.
Bounds are finite only on ``u`` (the URDF effort limits); contact forces are world-aligned
``[fx, fy, fz]`` with the ground normal last for flat ground.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, field

import clarabel
import numpy as np
import pinocchio as pin
from numpy.typing import ArrayLike
from scipy import sparse

__all__ = [
    "ReferenceSolveError",
    "TaskCommands",
    "WbcQP",
    "Weights",
    "build_wbc_qp",
    "clarabel_problem",
    "solve_reference",
    "solve_tight_reference",
    "tangent_basis",
]

_LWA = pin.ReferenceFrame.LOCAL_WORLD_ALIGNED
_LOCAL = pin.ReferenceFrame.LOCAL


_FLAT_FRAME = (np.array([1.0, 0.0, 0.0]), np.array([0.0, 1.0, 0.0]), np.array([0.0, 0.0, 1.0]))
for _axis in _FLAT_FRAME:
    _axis.flags.writeable = False


def tangent_basis(normal: ArrayLike) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Orthonormal frame ``(t1, t2, n)`` with ``n`` the unit normal.

    For ``n = (0, 0, 1)`` this gives ``t1 = x``, ``t2 = y``, so flat-ground cones use the
    world axes and the pyramids below are the usual axis-aligned ones.
    """
    n = np.asarray(normal, dtype=float)
    if n[0] == 0.0 and n[1] == 0.0 and n[2] > 0.0:  # flat ground: the same frame, faster
        return _FLAT_FRAME
    n = n / np.linalg.norm(n)
    a = np.array([1.0, 0.0, 0.0]) if abs(n[0]) < 0.9 else np.array([0.0, 1.0, 0.0])
    t1 = a - (a @ n) * n
    t1 /= np.linalg.norm(t1)
    return t1, np.cross(n, t1), n


def _readonly(a: ArrayLike, dtype: type = float) -> np.ndarray:
    out = np.array(a, dtype=dtype)
    out.flags.writeable = False
    return out


@dataclass(frozen=True, eq=False)
class WbcQP:
    """One whole-body-control QP with exact friction cones (arrays are read-only).

    Attributes
    ----------
    P : (n, n) ndarray
        Dense symmetric positive definite cost matrix of ``1/2 x'Px + q'x``.
    q : (n,) ndarray
        Linear cost.
    A, b : (m, n), (m,) ndarray
        Equalities ``A x = b`` (dynamics, holonomic, soft contact rows, in that order).
    lb, ub : (n,) ndarray
        Bounds, ``-inf``/``+inf`` where free; finite only on ``u``.
    cone_starts : (k,) int ndarray
        Index in ``x`` of each contact's ``fx``; the cone variables are
        ``x[s:s+3] = [fx, fy, fz]`` and the starts are contiguous (the ``lambda_c`` block).
    mus : (k,) ndarray
        Friction coefficient of each contact.
    normals : (k, 3) ndarray
        Unit contact normal of each contact in the same (world-aligned) coordinates as
        the force; ``(0, 0, 1)`` on flat ground, where the cone is
        ``||(fx, fy)|| <= mu fz``. In general ``||f - (n.f) n|| <= mu n.f``.
    layout : dict[str, slice]
        Slices of ``x``: ``vdot``, ``u``, ``lambda_h``, ``eps``, ``lambda_c``.
    nv : int
        Number of generalized velocities of the robot.
    contacts : tuple of str
        Name of each contact point, one per cone in order (``"<foot>_<i>"``, the frames
        of :func:`benchmarks.robots.load_robot`); empty where not known. A caller that
        carries an answer across a contact change matches the points by these
        (:mod:`benchmarks.contact_map`).
    """

    P: np.ndarray
    q: np.ndarray
    A: np.ndarray
    b: np.ndarray
    lb: np.ndarray
    ub: np.ndarray
    cone_starts: np.ndarray
    mus: np.ndarray
    normals: np.ndarray
    layout: dict[str, slice]
    nv: int
    contacts: tuple[str, ...] = ()

    def __post_init__(self) -> None:
        for name in ("P", "q", "A", "b", "lb", "ub", "mus", "normals"):
            object.__setattr__(self, name, _readonly(getattr(self, name)))
        object.__setattr__(self, "cone_starts", _readonly(self.cone_starts, np.int64))
        n = self.q.shape[0]
        if self.P.shape != (n, n) or self.A.shape[1] != n or self.A.shape[0] != self.b.shape[0]:
            raise ValueError(
                f"inconsistent shapes: P {self.P.shape}, q {self.q.shape}, "
                f"A {self.A.shape}, b {self.b.shape}"
            )

    @property
    def n(self) -> int:
        """Number of variables."""
        return int(self.q.shape[0])

    @property
    def n_contacts(self) -> int:
        """Number of contact points (friction cones)."""
        return int(self.cone_starts.shape[0])

    def forces(self, x: np.ndarray) -> np.ndarray:
        """Contact forces of ``x`` as a ``(k, 3)`` array."""
        return np.asarray(x)[self.layout["lambda_c"]].reshape(-1, 3)

    def pyramid(self, facets: int = 4, inner: bool = True) -> tuple[np.ndarray, np.ndarray]:
        """Linearized friction cones as rows ``G x <= h``, for pyramid-based solvers.

        Each contact gets ``facets`` rows ``c_j.f - mu' (n.f) <= 0`` with facet directions
        ``c_j = cos(2 pi j/N) t1 + sin(2 pi j/N) t2`` and one row ``-n.f <= 0``. The inner
        (inscribed) pyramid uses ``mu' = mu cos(pi/N)`` -- ``mu/sqrt(2)`` on ``|fx|, |fy|``
        for 4 facets -- so every pyramid-feasible force is cone-feasible; the outer one
        uses ``mu' = mu`` and lets the tangential force reach ``mu fz / cos(pi/N)``.
        """
        if facets < 3:
            raise ValueError(f"a pyramid needs at least 3 facets, got {facets}")
        angles = 2.0 * np.pi * np.arange(facets) / facets
        shrink = np.cos(np.pi / facets) if inner else 1.0
        rows = facets + 1
        G = np.zeros((rows * self.n_contacts, self.n))
        for i, (s, mu, normal) in enumerate(
            zip(self.cone_starts, self.mus, self.normals, strict=True)
        ):
            t1, t2, nrm = tangent_basis(normal)
            block = np.cos(angles)[:, None] * t1 + np.sin(angles)[:, None] * t2
            G[rows * i : rows * i + facets, s : s + 3] = block - mu * shrink * nrm
            G[rows * i + facets, s : s + 3] = -nrm
        return G, np.zeros(G.shape[0])

    def cone_violation(self, x: np.ndarray) -> float:
        """Largest ``max(0, ||f_t|| - mu f_n)`` over contacts, in newtons (0 if none)."""
        if self.n_contacts == 0:
            return 0.0
        f = self.forces(x)
        fn = np.einsum("ij,ij->i", f, self.normals)
        ft = np.linalg.norm(f - fn[:, None] * self.normals, axis=1)
        return float(max(0.0, np.max(ft - self.mus * fn)))

    def bound_violation(self, x: np.ndarray) -> float:
        """Largest violation of ``lb <= x <= ub`` (0 if within bounds)."""
        x = np.asarray(x)
        return float(max(0.0, np.max(self.lb - x), np.max(x - self.ub)))

    def equality_residual(self, x: np.ndarray) -> float:
        """``||A x - b||_inf``."""
        return float(np.max(np.abs(self.A @ np.asarray(x) - self.b), initial=0.0))

    def objective(self, x: np.ndarray) -> float:
        """``1/2 x'Px + q'x``."""
        x = np.asarray(x)
        return float(0.5 * x @ self.P @ x + self.q @ x)


@dataclass(frozen=True)
class TaskCommands:
    """Commanded task-space accelerations ``ydd_cmd`` (feedback terms included).

    Attributes
    ----------
    com
        CoM acceleration (3,), world frame; ``None`` for no CoM task.
    base_angular
        Base angular acceleration (3,), world frame; ``None`` for no orientation task.
    points
        Point tasks (swing feet, hands): frame id -> world-frame acceleration (3,).
    posture
        Joint accelerations of the actuated joints (nu,); ``None`` for no posture task.
    """

    com: np.ndarray | None = None
    base_angular: np.ndarray | None = None
    points: dict[int, np.ndarray] = field(default_factory=dict)
    posture: np.ndarray | None = None


@dataclass(frozen=True)
class Weights:
    """Diagonal cost weights (task errors in m/s^2 or rad/s^2, forces in N, torques in Nm).

    ``eps`` is heavy so that contacts hold unless the tasks are infeasible; ``lambda_c``
    is light (it only makes ``P`` definite); ``lambda_h`` is larger so that a humanoid
    holding a handle does not hang its weight on its (weak) wrist joints.
    """

    com: float = 100.0
    base_angular: float = 10.0
    points: float = 100.0
    posture: float = 0.1
    vdot: float = 1e-4
    u: float = 1e-4
    eps: float = 1e4
    lambda_c: float = 1e-6
    lambda_h: float = 1e-3


def _frame_terms(
    model: pin.Model, data: pin.Data, fid: int, dim: int
) -> tuple[np.ndarray, np.ndarray]:
    """Jacobian and drift ``Jdot v`` of a frame, after first- and second-order kinematics.

    ``dim == 3``: the frame origin's LOCAL_WORLD_ALIGNED linear Jacobian and classical
    acceleration at ``vdot = 0`` (the time derivative of the point's world velocity).
    ``dim == 6``: the LOCAL Jacobian and spatial acceleration at ``vdot = 0`` (the time
    derivative of the body twist), which is what a rigid grasp keeps at zero.
    """
    if dim == 3:
        J = pin.getFrameJacobian(model, data, fid, _LWA)[:3]
        drift = pin.getFrameClassicalAcceleration(model, data, fid, _LWA).linear
    else:
        J = pin.getFrameJacobian(model, data, fid, _LOCAL)
        drift = pin.getFrameAcceleration(model, data, fid, _LOCAL).vector
    return J, np.array(drift)


def build_wbc_qp(
    model: pin.Model,
    data: pin.Data,
    q: np.ndarray,
    v: np.ndarray,
    commands: TaskCommands,
    contacts: Sequence[int],
    mu: float | ArrayLike,
    *,
    hand: int | None = None,
    hand_dim: int = 6,
    contact_acc: np.ndarray | None = None,
    hand_acc: np.ndarray | None = None,
    normals: np.ndarray | None = None,
    weights: Weights | None = None,
) -> WbcQP:
    """Build the QP of eq. (10) at state ``(q, v)``.

    Parameters
    ----------
    model, data
        Pinocchio model with a free-flyer root (the first 6 velocities are unactuated,
        the remaining ``nv - 6`` are actuated one-to-one) and its data (overwritten).
    q, v
        Configuration (nq,) and velocity (nv,).
    commands
        Task commands; tasks set to ``None`` or absent are not in the cost.
    contacts
        Frame ids of the active contact points (3D point contacts).
    mu
        Friction coefficient, one for all or one per contact.
    hand, hand_dim
        Frame id of a hand holding a fixed handle, and 3 (point) or 6 (rigid grasp).
    contact_acc, hand_acc
        Reference accelerations ``a_c`` (3k,) and ``a_h`` (nh,) added to the right-hand
        sides of the contact and holonomic rows; zero by default (the paper's eq. 10).
    normals
        Contact normals (k, 3), world frame; flat ground ``(0, 0, 1)`` by default.
    weights
        Cost weights; :class:`Weights` defaults if ``None``.
    """
    w = weights or Weights()
    nv, k = model.nv, len(contacts)
    nu, nh, nc = nv - 6, (hand_dim if hand is not None else 0), 3 * len(contacts)
    sizes = {"vdot": nv, "u": nu, "lambda_h": nh, "eps": nc, "lambda_c": nc}
    layout, start = {}, 0
    for name, size in sizes.items():
        layout[name] = slice(start, start + size)
        start += size
    n = start

    # Second-order kinematics at vdot = 0: the drifts Jdot v of every task and contact.
    zero = np.zeros(nv)
    pin.forwardKinematics(model, data, q, v, zero)
    pin.updateFramePlacements(model, data)
    pin.computeJointJacobians(model, data, q)
    contact_terms = [_frame_terms(model, data, fid, 3) for fid in contacts]
    point_terms = {fid: _frame_terms(model, data, fid, 3) for fid in commands.points}
    hand_terms = _frame_terms(model, data, hand, hand_dim) if hand is not None else None
    J_base = pin.getJointJacobian(model, data, 1, _LWA)[3:]
    base_drift = np.array(pin.getClassicalAcceleration(model, data, 1, _LWA).angular)
    pin.centerOfMass(model, data, q, v, zero)
    com_drift = np.array(data.acom[0])
    J_com = pin.jacobianCenterOfMass(model, data, q, False)
    M = pin.crba(model, data, q)
    M = np.triu(M) + np.triu(M, 1).T
    h = pin.nonLinearEffects(model, data, q, v)

    # Cost: sum of 1/2 ||J vdot + drift - ydd||^2_W plus diagonal regularization.
    P = np.zeros((n, n))
    qv = np.zeros(n)
    vd = layout["vdot"]
    tasks: list[tuple[np.ndarray, np.ndarray, np.ndarray, float]] = []
    if commands.com is not None:
        tasks.append((J_com, com_drift, commands.com, w.com))
    if commands.base_angular is not None:
        tasks.append((J_base, base_drift, commands.base_angular, w.base_angular))
    for fid, acc in commands.points.items():
        tasks.append((*point_terms[fid], acc, w.points))
    if commands.posture is not None:
        tasks.append((np.eye(nv)[6:], np.zeros(nu), commands.posture, w.posture))
    for J, drift, ydd, wt in tasks:
        P[vd, vd] += wt * J.T @ J
        qv[vd] += wt * J.T @ (drift - np.asarray(ydd, dtype=float))
    for name in sizes:
        idx = np.arange(n)[layout[name]]
        P[idx, idx] += getattr(w, name)
    P = 0.5 * (P + P.T)  # exactly symmetric, not just up to rounding

    # Equalities.
    Jc = np.vstack([J for J, _ in contact_terms]) if k else np.zeros((0, nv))
    drift_c = np.concatenate([d for _, d in contact_terms]) if k else np.zeros(0)
    A = np.zeros((nv + nh + nc, n))
    b = np.zeros(nv + nh + nc)
    A[:nv, vd] = M
    A[6:nv, layout["u"]] = -np.eye(nu)
    A[:nv, layout["lambda_c"]] = -Jc.T
    b[:nv] = -h
    if hand_terms is not None:
        Jh, drift_h = hand_terms
        A[:nv, layout["lambda_h"]] = -Jh.T
        A[nv : nv + nh, vd] = Jh
        b[nv : nv + nh] = -drift_h + (0.0 if hand_acc is None else hand_acc)
    rows = slice(nv + nh, nv + nh + nc)
    A[rows, vd] = Jc
    A[rows, layout["eps"]] = np.eye(nc)
    b[rows] = -drift_c + (0.0 if contact_acc is None else contact_acc)

    lb = np.full(n, -np.inf)
    ub = np.full(n, np.inf)
    lb[layout["u"]] = -model.effortLimit[6:]
    ub[layout["u"]] = model.effortLimit[6:]
    mus = np.broadcast_to(np.asarray(mu, dtype=float), (k,))
    nrm = np.tile([0.0, 0.0, 1.0], (k, 1)) if normals is None else np.asarray(normals, float)
    nrm = nrm / np.linalg.norm(nrm, axis=1, keepdims=True) if k else nrm.reshape(0, 3)
    starts = layout["lambda_c"].start + 3 * np.arange(k)
    names = tuple(model.frames[fid].name for fid in contacts)
    return WbcQP(P, qv, A, b, lb, ub, starts, mus, nrm, layout, nv, names)


# Settings tried in turn when Clarabel stops short of a tight tolerance (AlmostSolved):
# the default, a smaller static regularization, then no equilibration.
_RETRIES: tuple[dict[str, object], ...] = (
    {},
    {"static_regularization_constant": 1e-10},
    {"equilibrate_enable": False},
)


# Tolerances a test set's reference is solved to, tightest first (solve_tight_reference).
REFERENCE_TOLERANCES = (1e-12, 1e-11, 1e-10, 1e-9)


class ReferenceSolveError(RuntimeError):
    """Clarabel did not solve a QP to the requested tolerance."""


def clarabel_problem(
    qp: WbcQP,
) -> tuple[sparse.csc_matrix, np.ndarray, sparse.csc_matrix, np.ndarray, list[object]]:
    """Clarabel's data ``(P, q, G, h, cones)`` for ``qp`` with exact friction cones.

    Clarabel's form is ``G x + s = h, s in K``: the equalities are a zero cone, each
    finite bound a nonnegative row, and each contact the cone
    ``(mu n.f, t1.f, t2.f) in SOC(3)``. ``P`` is the upper triangle, as Clarabel wants.
    """
    rows = [qp.A]
    rhs = [qp.b]
    cones: list[object] = [clarabel.ZeroConeT(qp.A.shape[0])]
    eye = np.eye(qp.n)
    up, lo = np.flatnonzero(np.isfinite(qp.ub)), np.flatnonzero(np.isfinite(qp.lb))
    if up.size + lo.size:
        rows += [eye[up], -eye[lo]]
        rhs += [qp.ub[up], -qp.lb[lo]]
        cones.append(clarabel.NonnegativeConeT(up.size + lo.size))
    for s, mu, normal in zip(qp.cone_starts, qp.mus, qp.normals, strict=True):
        t1, t2, nrm = tangent_basis(normal)
        block = np.zeros((3, qp.n))
        block[:, s : s + 3] = -np.vstack([mu * nrm, t1, t2])
        rows.append(block)
        rhs.append(np.zeros(3))
        cones.append(clarabel.SecondOrderConeT(3))
    P = sparse.csc_matrix(np.triu(qp.P))
    return P, np.array(qp.q), sparse.csc_matrix(np.vstack(rows)), np.concatenate(rhs), cones


def solve_reference(qp: WbcQP, tol: float = 1e-9) -> np.ndarray:
    """Solve ``qp`` with Clarabel and exact second-order friction cones.

    The data come from :func:`clarabel_problem`. At very tight tolerances Clarabel
    sometimes stops at ``AlmostSolved``; the solve is then retried with the settings
    of ``_RETRIES``.

    Raises
    ------
    ReferenceSolveError
        If the status is not ``Solved`` (the test set would carry a wrong reference).
    """
    P, q, G, h, cones = clarabel_problem(qp)
    statuses = []
    for retry in _RETRIES:
        settings = clarabel.DefaultSettings()
        settings.verbose = False
        settings.tol_gap_abs = settings.tol_gap_rel = settings.tol_feas = tol
        for key, value in retry.items():
            setattr(settings, key, value)
        sol = clarabel.DefaultSolver(P, q, G, h, cones, settings).solve()
        if str(sol.status) == "Solved":
            return np.array(sol.x)
        statuses.append(str(sol.status))
    raise ReferenceSolveError(f"Clarabel statuses {statuses} at tol {tol}")


def solve_tight_reference(qp: WbcQP) -> np.ndarray:
    """``qp`` solved by :func:`solve_reference` at the tightest of
    :data:`REFERENCE_TOLERANCES` that Clarabel reaches: the reference a test set's answers
    are judged against.

    The WBC cost regularizes contact forces and torques lightly, so an objective within
    1e-6 of the optimum can hold torques several percent of a joint's limit away from the
    optimum's. Clarabel stopped at 1e-9 is that far on some solo12 QPs, farther than the
    solvers it judges; at 1e-10 to 1e-12, which it reaches on every QP of the benchmark's
    sets, it agrees with an exact active-set solution to 0.15 % of the limits.

    Raises
    ------
    ReferenceSolveError
        If not even the loosest tolerance is reached.
    """
    for tol in REFERENCE_TOLERANCES[:-1]:
        try:
            return solve_reference(qp, tol)
        except ReferenceSolveError:
            continue
    return solve_reference(qp, REFERENCE_TOLERANCES[-1])
