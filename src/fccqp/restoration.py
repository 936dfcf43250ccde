"""Feasibility restoration of the returned iterate, compiled with numba.

ADMM's ``x`` meets the equalities at every iterate but the box and the cones only in
the limit: after a 15-iteration budget a torque can exceed its limit or a contact
force leave its friction cone. The restoration pins the offending entries at their
projection and lets everything else respond through the KKT matrix of the x-update:

    x' = x + W_T d,   W_TT d = t_T - x_T,

where ``T`` holds the constrained entries that violate (whole cone blocks),
``t = P_C(x_S)`` their nearest feasible values, and ``W_T`` the KKT responses to unit
right-hand sides on ``T`` (columns of the reduced form's table, or ``|T|`` solves with
the full form's factorization). ``x'`` is the x-update that ADMM would compute with
``x_T`` held at ``t_T``: every column of ``W`` lies in the null space of ``A``, so the
equalities still hold, and the free and unpinned entries keep the optimality of the
x-update. If an unpinned entry ends up violating, it joins ``T`` and the step is redone
from ``x``. ``W_TT`` is positive definite exactly when the other entries can absorb any
move of ``x_T``; otherwise the restoration gives up. An entry that joins ``T`` late is
pinned at its value in ``x``, which was feasible.

Pinning only the violators matters: pinning every constrained entry (or moving all of
them to ADMM's slack ``z``) was measured on the WBC sets to raise the median cost
excess over the optimum 1000-fold, because the accelerations must then absorb every
difference of torques and forces.
"""

import numpy as np
from numba import njit

from fccqp import kkt
from fccqp.projections import project_constraint_set
from fccqp.schur import cholesky, cholesky_solve

VIOLATION_TOLERANCE = 1e-12
"""An entry violates when its projection moves it by more than this (relative)."""


@njit(cache=True)
def _pin_violators(p, x, pinned):
    """Mark in ``pinned`` the constrained entries of ``x`` that the projection moves
    (whole cone blocks). Returns whether any was not pinned yet, and the projection."""
    s = p.constrained.shape[0]
    x_S = np.empty(s)
    for j in range(s):
        x_S[j] = x[p.constrained[j]]
    projected = np.empty(s)
    project_constraint_set(x_S, p.lo, p.hi, p.cones, projected)
    moved = np.zeros(s, dtype=np.bool_)
    for j in range(s):
        moved[j] = abs(projected[j] - x_S[j]) > VIOLATION_TOLERANCE * max(1.0, abs(x_S[j]))
    kind, offset, dim, mu, normal = p.cones
    for k in range(kind.shape[0]):
        a, e = offset[k], offset[k] + dim[k]
        if moved[a:e].any():
            moved[a:e] = True
    new = False
    for j in range(s):
        if moved[j] and not pinned[j]:
            pinned[j] = True
            new = True
    return new, projected


@njit(cache=True)
def _columns(p, w, sigma, reduced, pinned_entries, positions):
    """KKT responses ``W_T`` to unit right-hand sides on the pinned entries, and
    whether they reached the refinement tolerance."""
    if reduced:
        return np.asfortranarray(w.W[:, positions]), True
    columns = np.zeros((positions.shape[0], w.K.shape[0])).T  # Fortran order
    exact = kkt.solve_unit_columns(w.K, w.ipiv, p.P, p.A, p.E, sigma, p.constrained,
                                   w.rho_vec, pinned_entries, columns)
    return columns, exact


@njit(cache=True)
def restore(p, w, sigma, reduced):
    """Replace ``w.x`` and ``w.nu`` by the restored point; return False if impossible.

    ``p`` is the scaled problem and ``w`` the workspace of :mod:`fccqp.admm`, holding
    the factorization the iteration used (``reduced`` says which form). On False,
    ``w`` is untouched. ``A x = b`` holds up to the rounding of the update, which the
    caller removes with one refined solve.
    """
    n, s = p.P.shape[0], p.constrained.shape[0]
    start = np.concatenate((w.x, w.nu))
    pinned = np.zeros(s, dtype=np.bool_)
    violating, target = _pin_violators(p, w.x, pinned)
    if not violating:
        return True
    point = start
    while violating:  # each pass pins at least one more entry, so at most s passes
        positions = np.flatnonzero(pinned)
        entries = p.constrained[positions]
        W_T, exact = _columns(p, w, sigma, reduced, entries, positions)
        t = positions.shape[0]
        gram = np.empty((t, t)).T  # Fortran order
        step = np.empty(t)
        for a in range(t):
            step[a] = target[positions[a]] - start[entries[a]]
            for c in range(t):
                gram[a, c] = W_T[entries[a], c]
        if not (exact and cholesky(gram)):
            return False
        cholesky_solve(gram, step)
        point = start + W_T @ step
        violating = _pin_violators(p, point[:n], pinned)[0]
    w.x[:] = point[:n]
    w.nu[:] = point[n:]
    return True
