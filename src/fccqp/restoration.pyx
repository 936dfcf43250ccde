# cython: language_level=3, boundscheck=False, wraparound=False, cdivision=True, initializedcheck=False
"""Feasibility restoration of the returned iterate.

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

from libc.math cimport fabs

from fccqp._blas cimport cholesky, cholesky_solve
from fccqp._types cimport Iterates, Problem
from fccqp.kkt cimport KKT, kkt_unit_columns
from fccqp.projections cimport proj_set
from fccqp.reduced cimport Reduced
from fccqp.tuning cimport VIOLATION_TOLERANCE


cdef bint _pin_violators(Restoration* r, const Problem* p, const double* x) noexcept nogil:
    """Mark in ``pinned`` the constrained entries of ``x`` that the projection moves
    (whole cone blocks); leave their projection in ``projected``. True if any was not
    pinned yet."""
    cdef Py_ssize_t s = p.s, j, k, a, e
    cdef bint moved, new = False
    for j in range(s):
        r.projected[j] = x[p.constrained[j]]
    proj_set(r.projected, p.lo, p.hi, p.cones, s, r.projected)
    for j in range(s):
        if fabs(r.projected[j] - x[p.constrained[j]]) > VIOLATION_TOLERANCE * max(
                1.0, fabs(x[p.constrained[j]])):
            if not r.pinned[j]:
                new = True
            r.pinned[j] = 2  # moved: its block is pinned below
    for k in range(p.cones.count):
        a = p.cones.offset[k]
        e = a + p.cones.dim[k]
        moved = False
        for j in range(a, e):
            moved = moved or r.pinned[j] == 2
        if moved:
            for j in range(a, e):
                if not r.pinned[j]:
                    new = True
                    r.pinned[j] = 1
    for j in range(s):
        if r.pinned[j] == 2:
            r.pinned[j] = 1
    return new


cdef bint restore(Restoration* r, KKT* k, Reduced* red, bint reduced, const Problem* p,
                  Iterates* it) noexcept nogil:
    """Replace ``it.x`` and ``it.nu`` by the restored point; False if impossible.

    ``k`` holds the factorization the iteration used (``reduced`` says whether
    ``red.W`` holds its table). On False the iterate is untouched. ``A x = b`` holds up
    to the rounding of the update, which the caller removes with one refined solve.
    """
    cdef Py_ssize_t n = p.n, m = p.m, s = p.s, N = n + m, j, i, a, c, t
    cdef bint exact
    for j in range(s):
        r.pinned[j] = 0
    if not _pin_violators(r, p, it.x):
        return True
    for j in range(s):
        r.target[j] = r.projected[j]
    for i in range(n):
        r.start[i] = it.x[i]
    for i in range(m):
        r.start[n + i] = it.nu[i]
    while True:  # each pass pins at least one more entry, so at most s passes
        t = 0
        for j in range(s):
            if r.pinned[j]:
                r.positions[t] = j
                r.entries[t] = p.constrained[j]
                t += 1
        if reduced:
            for c in range(t):
                for i in range(N):
                    r.W_T[i + c * N] = red.W[i + r.positions[c] * N]
            exact = True
        else:
            exact = kkt_unit_columns(k, p, it.rho_vec, r.entries, <int>t, r.W_T)
        if not exact:
            return False
        for a in range(t):
            r.step[a] = r.target[r.positions[a]] - r.start[r.entries[a]]
            for c in range(t):
                r.gram[a + c * t] = r.W_T[r.entries[a] + c * N]
        if not cholesky(r.gram, <int>t, <int>t):
            return False
        cholesky_solve(r.gram, <int>t, <int>t, r.step, 1, <int>t)
        for i in range(N):
            r.point[i] = r.start[i]
        for c in range(t):
            for i in range(N):
                r.point[i] += r.W_T[i + c * N] * r.step[c]
        if not _pin_violators(r, p, r.point):
            break
    for i in range(n):
        it.x[i] = r.point[i]
    for i in range(m):
        it.nu[i] = r.point[n + i]
    return True
