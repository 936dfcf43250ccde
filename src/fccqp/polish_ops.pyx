# cython: language_level=3, boundscheck=False, wraparound=False, cdivision=True, initializedcheck=False
"""The polish (:mod:`fccqp.polish`) from Python, for the tests.

:func:`polish_point` polishes a given iterate of a problem whose ``P`` and ``A`` are
dense arrays (each guess assembled for ``dsytrf``) or ``scipy.sparse`` matrices (each
guess assembled in compressed columns for qdldl, :mod:`fccqp.polish_csc`), so that the
tests hold the compressed-column arm to the dense arm on the same iterate. The problem is
taken as the polish sees the scaled one (no equilibration), without the reduced form's
table; with ``schur``, each guess by the Schur complement of :mod:`fccqp.polish_schur`
where it applies. Not on any solve's path.
"""

from libc.math cimport INFINITY

import numpy as np

from fccqp._types cimport Iterates, Problem
from fccqp.matrices cimport CSC
from fccqp.matrix_ops cimport Held
from fccqp.polish cimport Polish, polish, polish_prepare
from fccqp.polish_csc cimport bind
from fccqp.tuning cimport GUESS_PASSES, WARM_GUESS_PASSES
from fccqp.workspace_arrays cimport Arrays, polish_schur_arrays

from fccqp.polish_csc import arrays


cdef class _Arrays:
    """Zeroed arrays that live as long as this object, and pointers into them."""
    cdef list held

    def __init__(self):
        self.held = []

    cdef double* new(self, Py_ssize_t size, values=None):
        array = np.zeros(max(size, 1))
        if values is not None:
            array[:size] = values
        self.held.append(array)
        cdef double[::1] view = array
        return &view[0]

    cdef Py_ssize_t* new_int(self, Py_ssize_t size, values=None):
        array = np.zeros(max(size, 1), dtype=np.intp)
        if values is not None:
            array[:size] = values
        self.held.append(array)
        cdef Py_ssize_t[::1] view = array
        return &view[0]


def polish_point(P, q, A, b, lb, ub, cones, x, nu, y, z, long newton_steps=5, bint schur=False,
                 bint from_iterate=False, bint warm=False, bint bare=False):
    """Polish the iterate ``(x, nu, z, y)`` of ``min 1/2 x'Px + q'x`` s.t. ``A x = b``,
    ``lb <= x <= ub``, ``x`` in ``cones`` (a :class:`fccqp.cones.ConeArrays` over ``x``).

    ``y`` and ``z`` (``n`` entries) are the multipliers and slacks of the entries of ``x``
    (read on the constrained entries: a finite bound or a cone). ``P`` and ``A`` are both
    dense arrays or both ``scipy.sparse`` matrices (``P`` with its full symmetric
    pattern). With ``schur`` (dense ``P`` and ``A``), the Schur complement is set up
    first; with ``from_iterate`` the passes step from ``x`` on, as from ADMM's iterate;
    with ``warm`` it is polished as a warm polish is (``WARM_GUESS_PASSES`` guesses, the
    hopeless crawl given up: :func:`fccqp.polish.polish`); with ``bare`` as a polish from
    no multipliers is (``bare_start``: a carried guess's, whose ``y`` the caller zeroes).
    Returns a dict: ``ok`` (the polish's verdict), ``x``, ``nu``, ``y`` (``n`` entries,
    zero off the constrained entries), ``active`` (the final guess's code per
    constrained entry), ``passes``, ``factorizations``, ``schur`` (whether the Schur
    complement was set up) and ``bordered`` (whether the last factorization was its
    bordered one).
    """
    cdef Held Ph = Held(P), Ah = Held(A)
    cdef Arrays schur_storage = Arrays()   # the Schur polish's, kept to the end
    cdef Py_ssize_t n = Ph.M.rows, m = Ah.M.rows, j
    if Ph.M.cols != n or Ah.M.cols != n:
        raise ValueError(f"P must be n x n and A m x n, got {P.shape} and {A.shape}")
    if (Ph.M.kind == CSC) != (Ah.M.kind == CSC):
        raise TypeError("P and A must be both dense or both scipy.sparse")
    lb, ub = np.asarray(lb, np.float64), np.asarray(ub, np.float64)
    cone_entry = np.zeros(n, bool)
    cone_entry[cones.members] = True
    constrained = np.flatnonzero(np.isfinite(lb) | np.isfinite(ub) | cone_entry)
    position = np.full(n, -1, np.intp)
    position[constrained] = np.arange(constrained.size)
    cdef Py_ssize_t s = constrained.size, count = cones.count, N = n + m + s
    cdef _Arrays a = _Arrays()
    cdef Problem p
    p.n, p.m, p.s, p.P, p.A = n, m, s, Ph.M, Ah.M
    p.q, p.b = a.new(n, q), a.new(m, b)
    p.constrained = a.new_int(s, constrained)
    cdef char* in_cone = <char*>a.new_int(s)
    for j in range(s):
        in_cone[j] = cone_entry[constrained[j]]
    p.in_cone = in_cone
    p.lo, p.hi = a.new(s, lb[constrained]), a.new(s, ub[constrained])
    p.span, p.D, p.E, p.c = a.new(m), a.new(n, 1.0), a.new(m, 1.0), 1.0
    p.cones.count, p.cones.kind, p.cones.dim = count, a.new_int(count, cones.kind), a.new_int(count, cones.dim)
    p.cones.offset = a.new_int(count, position[np.asarray(cones.offset, np.intp)])
    p.cones.mu, p.cones.normal = a.new(count, cones.mu), a.new(3 * count, np.ravel(cones.normal))
    cdef Iterates it
    it.x, it.nu = a.new(n, x), a.new(m, nu)
    it.y, it.z = a.new(s, np.asarray(y)[constrained]), a.new(s, np.asarray(z)[constrained])
    cdef Polish w
    w.active, w.dropped, w.blocked = <char*>a.new(s), <char*>a.new(s), <char*>a.new(s)
    w.bare, w.kept_plane = <char*>a.new(s), a.new(s)
    w.index, w.free, w.boundary = a.new_int(n), a.new_int(n), a.new_int(s)
    w.g, w.lam, w.hess = a.new(s), a.new(s), a.new(s * s)
    w.K, w.ipiv = a.new(N * N), <int*>a.new_int(N)
    w.lwork, w.work = <int>(64 * N), a.new(64 * N)
    w.rhs, w.step = a.new(N), a.new(N)
    w.x, w.nu, w.y, w.x_prev, w.nu_prev = a.new(n), a.new(m), a.new(s), a.new(n), a.new(m)
    w.chord_start = a.new(n + m + 2 * s)
    w.grad, w.ATnu, w.Ax = a.new(n), a.new(n), a.new(m)
    w.schur.ready = w.schur_only = w.schur_failed = False
    w.guess_passes = WARM_GUESS_PASSES if warm else GUESS_PASSES
    w.warm = warm
    w.bare_start = bare
    w.schur.L = NULL   # no Schur storage: every guess is assembled
    w.schur.bordered = False
    if schur:
        polish_schur_arrays(schur_storage, &w.schur, n, m, s)
        polish_prepare(&w, &p)
    if Ph.M.kind == CSC:
        held = arrays(n, m, np.asarray(Ph.colptr), np.asarray(Ph.rowind),
                      np.asarray(Ah.colptr), np.asarray(Ah.rowind), cones.dim)
        bind(&w.csc, held)
    cdef int factorizations = 0
    ok = polish(&w, &p, &it, newton_steps, &factorizations, NULL, NULL, NULL, INFINITY, 0.0,
                from_iterate)
    result_y = np.zeros(n)
    result_y[constrained] = [w.y[j] for j in range(s)]
    return {"ok": bool(ok), "x": np.array([w.x[j] for j in range(n)]),
            "nu": np.array([w.nu[j] for j in range(m)]), "y": result_y,
            "active": np.array([w.active[j] for j in range(s)], np.int8),
            "passes": w.passes, "factorizations": factorizations,
            "schur": bool(w.schur.ready), "bordered": bool(w.schur.bordered)}

