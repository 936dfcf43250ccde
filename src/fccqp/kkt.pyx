# cython: language_level=3, boundscheck=False, wraparound=False, cdivision=True, initializedcheck=False
"""The linear-system contract of the x-update, over the two dense backends and the
sparse one.

Every backend solves the KKT system of the x-update,

    [ P + sigma I + R   A' ] [x ]   [r]
    [ A                 0  ] [nu] = [b],      R = diag(rho on constrained entries),

through four calls: :func:`kkt_factor` (for given P, A, sigma, rho), :func:`kkt_solve`
(one refined right-hand side; :func:`kkt_solve_once` for callers that refine),
:func:`kkt_unit_columns` (responses to unit right-hand sides on chosen entries, the
restoration's columns; :func:`kkt_table` on the constrained ones, the reduced form's
table) and :func:`kkt_convexity` (is the QP convex?). The backends are :mod:`fccqp.schur`
(Cholesky, needs ``P + R`` positive definite and ``A`` of full row rank; the reduced
form, and the cold start of a run that will iterate in it) and :mod:`fccqp.ldl`
(quasi-definite LDL', any ``A``), and for compressed columns :mod:`fccqp.kkt_sparse`
(``SPARSE_LDL``: qdldl's quasi-definite LDL' of the full form, which does not serve
:func:`kkt_unit_columns`: the reduced form's table and the restoration's columns are
``(n + m) x s``, too large at its sizes). ``sigma`` is 0 in the reduced forms.
"""

from fccqp._types cimport Problem
from fccqp.kkt_sparse cimport sparse_factor, sparse_solve
from fccqp.ldl cimport ldl_factor, ldl_solve, ldl_unit_columns
from fccqp.matrices cimport CSC
from fccqp.schur cimport (schur_certifies_convexity, schur_factor, schur_solve, schur_solve_once,
                         schur_unit_columns)


cdef int kkt_factor(KKT* k, const Problem* p, int backend, double sigma,
                    const double* rho_vec) noexcept nogil:
    """Factor with ``backend`` (not AUTO). The LDL' inertia rejects a matrix with more
    than ``m`` negative eigenvalues (``P + R`` not convex on the null space of ``A``)."""
    cdef int negative
    k.backend = backend
    k.sigma = sigma
    if backend == SCHUR_REDUCED:
        return FACTORED if schur_factor(&k.schur, p, rho_vec) else UNAVAILABLE
    if backend == SPARSE_LDL:
        negative = sparse_factor(k.sparse, p.s, sigma, rho_vec)
    else:
        negative = ldl_factor(&k.ldl, p, sigma, rho_vec)
    if negative < 0 or (negative < p.m and backend == LDL_REDUCED):
        return UNAVAILABLE   # the reduced form needs P + R definite on the null space of A
    return NOT_CONVEX if negative > p.m else FACTORED


cdef void kkt_solve(KKT* k, const Problem* p, const double* rho_vec, const double* rhs,
                    double* sol) noexcept nogil:
    """Solve for ``rhs`` into ``sol`` with the backend factored last, refined."""
    if k.backend == SCHUR_REDUCED:
        schur_solve(&k.schur, p, rho_vec, rhs, sol)
    elif k.backend == SPARSE_LDL:
        sparse_solve(k.sparse, p.n + p.m, rhs, sol)
    else:
        ldl_solve(&k.ldl, p, k.sigma, rho_vec, rhs, sol)


cdef void kkt_solve_once(KKT* k, const Problem* p, const double* rho_vec, const double* rhs,
                         double* sol) noexcept nogil:
    """:func:`kkt_solve` for a caller that refines against its own residual: the Schur
    backend's factorization is of the system itself, and one unrefined solve is then
    enough (on talos' warm polish the refinement had doubled the cost of each of its
    KKT solves); the LDL' backend, regularized by ``delta``, still refines."""
    if k.backend == SCHUR_REDUCED:
        schur_solve_once(&k.schur, p, rhs, sol)
    elif k.backend == SPARSE_LDL:
        sparse_solve(k.sparse, p.n + p.m, rhs, sol)
    else:
        ldl_solve(&k.ldl, p, k.sigma, rho_vec, rhs, sol)


cdef bint kkt_unit_columns(KKT* k, const Problem* p, const double* rho_vec,
                           const Py_ssize_t* entries, int count, double* W) noexcept nogil:
    """Fill ``W`` (Fortran, ``(n + m) x count``) with the responses to ``[e_i; 0]``,
    ``i`` in ``entries``. The Schur backend serves only ``entries`` = all of the
    constrained entries, in order; ``SPARSE_LDL`` none (False, ``W`` untouched). False
    when refinement missed its tolerance."""
    if k.backend == SCHUR_REDUCED:
        schur_unit_columns(&k.schur, p, W, NULL)
        return True
    if k.backend == SPARSE_LDL:
        return False
    return ldl_unit_columns(&k.ldl, p, k.sigma, rho_vec, entries, count, W, k.R, k.work)


cdef bint kkt_table(KKT* k, const Problem* p, const double* rho_vec, double* W,
                    double* W_S) noexcept nogil:
    """:func:`kkt_unit_columns` on the constrained entries into ``W``, and ``W``'s rows on
    them into ``W_S`` (row-major ``s x s``: the Schur backend writes them as it forms
    them). False as :func:`kkt_unit_columns`."""
    cdef Py_ssize_t s = p.s, N = p.n + p.m, i, j
    if k.backend == SCHUR_REDUCED:
        schur_unit_columns(&k.schur, p, W, W_S)
        return True
    if not kkt_unit_columns(k, p, rho_vec, p.constrained, <int>s, W):
        return False
    for j in range(s):
        for i in range(s):
            W_S[j * s + i] = W[p.constrained[j] + i * N]
    return True


cdef int kkt_convexity(KKT* k, const Problem* p, double sigma, const double* rho_vec,
                       bint schur_factored) noexcept nogil:
    """Decide whether the QP is convex: ``P + sigma I`` positive semidefinite on the null
    space of ``A`` (FACTORED) or not (NOT_CONVEX).

    A Schur factorization just computed (``schur_factored``) proves the common case for free (``P``
    positive semidefinite); otherwise the penalty-free KKT matrix is factored with
    LDL' (qdldl's on compressed columns) and its inertia decides. That overwrites an
    LDL' factorization (not a Schur one), so a caller iterating with LDL' certifies
    first and factors afterwards.
    """
    if schur_factored and schur_certifies_convexity(&k.schur, p, rho_vec, sigma):
        return FACTORED
    cdef int negative
    if p.P.kind == CSC:
        k.backend = SPARSE_LDL
        negative = sparse_factor(k.sparse, p.s, sigma, _zeros(k, p.s))
    else:
        negative = ldl_factor(&k.ldl, p, sigma, _zeros(k, p.s))
    if negative < 0:
        return NOT_CONVEX
    return NOT_CONVEX if negative > p.m else FACTORED


cdef inline const double* _zeros(KKT* k, Py_ssize_t s) noexcept nogil:
    """``s`` zeros in the scratch ``work`` (a penalty vector of zero)."""
    cdef Py_ssize_t i
    for i in range(s):
        k.work[i] = 0.0
    return k.work
