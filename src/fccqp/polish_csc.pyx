# cython: language_level=3, boundscheck=False, wraparound=False, cdivision=True, initializedcheck=False
"""The polish's KKT system for a problem stored in compressed columns, factored by qdldl.

:mod:`fccqp.polish` solves each guess's regularized KKT system

    [ P_FF + delta I + H   A_F'       G'        ]
    [ A_F                  -delta I             ]
    [ G                               -delta I  ]

(``F`` the free entries of ``x``, ``G`` one tangent-plane row per boundary cone block,
``H`` those blocks' curvature terms). On dense ``P`` and ``A`` it is assembled for
``dsytrf`` (``polish_kkt._assemble``, ``delta = POLISH_DELTA``); here, where they are CSC
(:mod:`fccqp.matrices`), the same blocks are assembled as the compressed columns of the
upper triangle and factored by ``qdldl`` (its Python API, with the GIL: a call costs
about 10 us, small beside a factorization of the sizes that take the sparse path).
The matrix is quasi-definite (positive definite top-left block on a convex problem,
``-delta I`` below), so an LDL' factorization without pivoting exists in qdldl's
fill-reducing order; but without pivoting its rounding grows like ``1 / delta``, so
``delta`` is ``POLISH_CSC_DELTA`` (1e-8) rather than the dense ``1e-12``: on an LP (``P =
0``: the top-left block is ``delta I``) the solves of an active set that the dense
backends' polish accepts were lost below it, and the polish's refinement against the
unregularized system (``polish_kkt.refine``) removes the larger bias, factoring again with a
smaller ``delta`` where a free block's curvature lies below it. Where ``delta`` lies
below the rounding of the largest entry, SuperLU factors the matrix with partial
pivoting instead (:func:`polish_csc_factor`).

Column ``c < |F|`` of the upper triangle is column ``F_c`` of ``P`` restricted to the
free rows up to the diagonal (``P``'s full symmetric pattern makes its columns its
rows), plus ``delta`` on the diagonal and, for an entry of a boundary block, the block's
curvature on the block's rows (a block's entries are consecutive unknowns); column
``|F| + i`` is row ``i`` of ``A`` on the free columns (from a transposed pattern of
``A`` made once per structure), then ``-delta``; column ``|F| + m + k`` is boundary block
``k``'s plane on its entries, then ``-delta``. Rows ascend in every column, no entry
twice. :func:`arrays` sizes every array from the patterns of ``P`` and ``A`` and the
cone blocks, once per structure: a guess allocates nothing beyond what qdldl's
factorization and solve allocate themselves. It also holds the polish's curvature terms
(``Polish.hess``) for CSC problems, ``n`` times the largest cone dimension where the
dense workspace has ``s x s`` (``s <= n`` constrained entries): ``polish`` points
``Polish.hess`` there.
"""

from cpython.ref cimport PyObject
from libc.float cimport DBL_EPSILON as EPSILON

import numpy as np

from fccqp._types cimport Problem
from fccqp.matrices cimport Matrix


cdef class _Factor:
    """The assembled matrix as qdldl reads a ``scipy.sparse`` matrix (``data``,
    ``indices``, ``indptr``, ``shape``, ``nnz`` over :func:`arrays`' arrays, no copy),
    its factorization (qdldl's, or SuperLU's with pivoting; ``None`` after a zero pivot)
    and the stride of the curvature terms' storage."""

    cdef readonly object data, indices, indptr, shape
    cdef readonly Py_ssize_t nnz, hess_stride
    cdef object _colptr, _rhs, _solver, _solver_class, _pivoting_class

    def __init__(self, colptr, rowind, values, rhs, Py_ssize_t hess_stride):
        import qdldl
        from scipy.sparse.linalg import splu
        self._solver_class, self._pivoting_class = qdldl.Solver, splu
        self.hess_stride = hess_stride
        self._colptr, self.indices, self.data, self._rhs = colptr, rowind, values, rhs
        self.indptr, self.shape, self.nnz, self._solver = colptr[:1], (0, 0), 0, None

    cdef bint factor(self, Py_ssize_t size, Py_ssize_t nf, double delta) except -1:
        """Factor the leading ``size`` columns, regularized by ``delta``: by qdldl, or by
        SuperLU with partial pivoting where ``delta`` lies below the rounding of the
        largest curvature entry, those of the first ``nf`` columns (see
        :func:`polish_csc_factor`); False when the factorization meets a zero pivot."""
        self.indptr = self._colptr[:size + 1]
        self.shape = (size, size)
        self.nnz = self._colptr[size]
        self._solver = None
        try:
            if delta <= EPSILON * float(np.max(np.abs(self.data[:self._colptr[nf]]), initial=0.0)):
                self._solver = self._pivoting_class(self._symmetric())
            else:
                self._solver = self._solver_class(self, upper=True)
        except RuntimeError:   # qdldl's or SuperLU's report of a zero pivot
            return False
        return True

    cdef object _symmetric(self):
        """The whole symmetric matrix of the assembled upper triangle (``scipy.sparse``,
        compressed columns, a copy)."""
        import scipy.sparse as sp
        upper = sp.csc_matrix((np.array(self.data[:self.nnz]),
                               np.array(self.indices[:self.nnz]), np.array(self.indptr)),
                              shape=self.shape)
        return (upper + sp.triu(upper, 1, format="csc").T).tocsc()

    cdef void solve(self, Py_ssize_t size, double* v) except *:
        """``v`` := the factor's solution for the right-hand side in ``rhs[:size]``."""
        cdef double[::1] solution = self._solver.solve(self._rhs[:size])
        cdef Py_ssize_t i
        for i in range(size):
            v[i] = solution[i]


def arrays(Py_ssize_t n, Py_ssize_t m, P_colptr, P_rowind, A_colptr, A_rowind, cone_dim):
    """The arrays of a :c:type:`PolishCSC` for ``P`` (``n x n``, full symmetric pattern)
    and ``A`` (``m x n``) in compressed columns (``*_colptr``, ``*_rowind``: intp, rows
    ascending in each column) and cone blocks of dimensions ``cone_dim``; hand the tuple
    to :func:`bind`. It holds the polish's curvature terms too: ``n`` (which bounds the
    constrained entries ``s``) times the largest cone dimension, where the dense
    workspace has ``s x s``. Raises ``ValueError`` naming the argument that does not
    fit."""
    P_colptr, P_rowind = np.asarray(P_colptr, np.intp), np.asarray(P_rowind, np.intp)
    A_colptr, A_rowind = np.asarray(A_colptr, np.intp), np.asarray(A_rowind, np.intp)
    dims = np.asarray(cone_dim, np.intp)
    for name, ptr in (("P_colptr", P_colptr), ("A_colptr", A_colptr)):
        if ptr.shape != (n + 1,):
            raise ValueError(f"{name} must have n + 1 = {n + 1} entries, got shape {ptr.shape}")
    nnz_P, nnz_A = int(P_colptr[n]), int(A_colptr[n])
    if P_rowind.shape[0] < nnz_P:
        raise ValueError(f"P_rowind must have {nnz_P} entries, got {P_rowind.shape[0]}")
    if A_rowind.shape[0] < nnz_A:
        raise ValueError(f"A_rowind must have {nnz_A} entries, got {A_rowind.shape[0]}")
    rows = A_rowind[:nnz_A]
    if nnz_A and (rows.min() < 0 or rows.max() >= m):
        raise ValueError(f"A_rowind must hold rows in [0, {m}), got {rows.min()}..{rows.max()}")
    order = np.argsort(rows, kind="stable")   # by row, columns ascending in each
    row_start = np.zeros(m + 1, np.intp)
    np.cumsum(np.bincount(rows, minlength=m), out=row_start[1:])
    row_col = np.repeat(np.arange(n, dtype=np.intp), np.diff(A_colptr))[order]
    size = n + m + dims.shape[0]
    capacity = nnz_P + n + nnz_A + m + int(np.sum(dims * (dims + 1) // 2 + dims + 1))
    if capacity >= 2 ** 31:
        raise ValueError(f"the polish's KKT matrix would have {capacity} entries, "
                         "more than qdldl's 32-bit indices hold")
    colptr = np.zeros(size + 1, np.int32)
    rowind = np.zeros(max(capacity, 1), np.int32)
    values = np.zeros(max(capacity, 1))
    rhs = np.zeros(max(size, 1))
    stride = max(int(dims.max(initial=1)), 1)
    held = (np.concatenate([row_start, [0]]), np.concatenate([row_col, [0]]),
            np.concatenate([order.astype(np.intp), [0]]), np.full(max(n, 1), -1, np.intp),
            colptr, rowind, values, rhs, np.zeros(max(n * stride, 1)))
    return held + (_Factor(colptr, rowind, values, rhs, stride),)


cdef void bind(PolishCSC* f, tuple arrays) except *:
    """Point ``f`` at the arrays of :func:`arrays` (the caller keeps the tuple alive)."""
    cdef Py_ssize_t[::1] row_start = arrays[0], row_col = arrays[1], row_entry = arrays[2]
    cdef Py_ssize_t[::1] block_of = arrays[3]
    cdef int[::1] colptr = arrays[4], rowind = arrays[5]
    cdef double[::1] values = arrays[6], rhs = arrays[7], hess = arrays[8]
    f.row_start, f.row_col, f.row_entry = &row_start[0], &row_col[0], &row_entry[0]
    f.block_of, f.colptr, f.rowind = &block_of[0], &colptr[0], &rowind[0]
    f.values, f.rhs, f.hess = &values[0], &rhs[0], &hess[0]
    f.hess_stride = (<_Factor>arrays[9]).hess_stride
    f.factor = <PyObject*>arrays[9]


cdef inline Py_ssize_t _push(PolishCSC* f, Py_ssize_t t, Py_ssize_t row,
                             double value) noexcept nogil:
    f.rowind[t] = <int>row
    f.values[t] = value
    return t + 1


cdef Py_ssize_t _free_column(PolishCSC* f, const Problem* p, Py_ssize_t col, Py_ssize_t jc,
                             const Py_ssize_t* index, const Py_ssize_t* boundary,
                             double delta, Py_ssize_t t) noexcept nogil:
    """Column ``col`` (free entry ``jc`` of ``x``) of the upper triangle from entry ``t``
    on: ``P``'s free rows above the diagonal, then the diagonal with ``delta`` or, in a
    boundary block, the block's rows with its curvature (added as ``_assemble`` adds
    them: ``P``, then ``delta``, then the curvature). Returns the next free entry."""
    cdef const Matrix* P = &p.P
    cdef Py_ssize_t k = P.colptr[jc], end = P.colptr[jc + 1], block = f.block_of[jc]
    cdef Py_ssize_t cone, o, d, start = jc, ii, jj, i
    cdef double value
    if block >= 0:
        cone = boundary[block]
        o, d = p.cones.offset[cone], p.cones.dim[cone]
        start = p.constrained[o]
    while k < end and P.rowind[k] < start:
        if index[P.rowind[k]] >= 0:
            t = _push(f, t, index[P.rowind[k]], P.values[k])
        k += 1
    if block < 0:
        value = P.values[k] if k < end and P.rowind[k] == jc else 0.0
        return _push(f, t, col, value + delta)
    jj = jc - start
    for ii in range(jj + 1):
        i = start + ii
        value = 0.0
        if k < end and P.rowind[k] == i:
            value = P.values[k]
            k += 1
        if ii == jj:
            value += delta
        t = _push(f, t, index[i], value + f.hess[o * f.hess_stride + jj * d + ii])
    return t


cdef void _assemble_csc(PolishCSC* f, const Problem* p, Py_ssize_t nf,
                        const Py_ssize_t* free, const Py_ssize_t* index,
                        const Py_ssize_t* boundary, Py_ssize_t nb, const double* g,
                        double delta) noexcept nogil:
    """The upper triangle of the guess's regularized KKT matrix into ``colptr``,
    ``rowind``, ``values`` (see the module's docstring)."""
    cdef Py_ssize_t m = p.m, col, i, j, k, o, d, start, t = 0
    cdef const Matrix* A = &p.A
    for k in range(nb):
        start = p.constrained[p.cones.offset[boundary[k]]]
        for j in range(p.cones.dim[boundary[k]]):
            f.block_of[start + j] = k
    for col in range(nf):
        f.colptr[col] = <int>t
        t = _free_column(f, p, col, free[col], index, boundary, delta, t)
    for i in range(m):
        f.colptr[nf + i] = <int>t
        for k in range(f.row_start[i], f.row_start[i + 1]):
            if index[f.row_col[k]] >= 0:
                t = _push(f, t, index[f.row_col[k]], A.values[f.row_entry[k]])
        t = _push(f, t, nf + i, -delta)
    for k in range(nb):
        f.colptr[nf + m + k] = <int>t
        o, d = p.cones.offset[boundary[k]], p.cones.dim[boundary[k]]
        start = p.constrained[o]
        for j in range(d):
            t = _push(f, t, index[start + j], g[o + j])
            f.block_of[start + j] = -1
        t = _push(f, t, nf + m + k, -delta)
    f.colptr[nf + m + nb] = <int>t


cdef bint polish_csc_factor(PolishCSC* f, const Problem* p, Py_ssize_t nf,
                            const Py_ssize_t* free, const Py_ssize_t* index,
                            const Py_ssize_t* boundary, Py_ssize_t nb,
                            const double* g, double delta) noexcept nogil:
    """Assemble and factor the KKT matrix of the guess (free entries ``free[:nf]``
    numbered by ``index``, boundary blocks ``boundary[:nb]`` with planes ``g`` as in
    :c:type:`fccqp.polish.Polish`, curvature in ``f.hess``) regularized by ``delta``
    (``POLISH_CSC_DELTA`` but where :mod:`fccqp.polish`'s refinement stalls); False when
    the factorization meets a zero pivot.

    qdldl factors without pivoting, its rounding growing like ``1 / delta`` beside the
    entries: where ``delta`` lies at or below ``DBL_EPSILON`` times the largest entry of
    the free entries' curvature (the first ``nf`` columns), the pivots ``-delta`` of rows
    eliminated before their columns are below the rounding of the entries they meet, and
    SuperLU factors the whole symmetric matrix with partial pivoting instead (``P`` of
    1e10 unscaled beside free entries that ``P`` does not touch, ``delta`` 1e-8: qdldl's
    corrections left the residual at the size of the right-hand side, SuperLU's reduced
    it to ``P x``'s rounding). Rows of ``A`` as large do not call for it: taken on the
    whole matrix, the test sent an unscaled least-distance QP with rows of 2e10 and a
    curvature of one to SuperLU, whose polish then lost an infeasibility certificate
    that qdldl's finds."""
    _assemble_csc(f, p, nf, free, index, boundary, nb, g, delta)
    with gil:
        return (<_Factor>f.factor).factor(nf + p.m + nb, nf, delta)


cdef void polish_csc_solve(PolishCSC* f, Py_ssize_t size, double* v) noexcept nogil:
    """``v[:size]`` := the last factorization's solution for ``v[:size]``."""
    cdef Py_ssize_t i
    for i in range(size):
        f.rhs[i] = v[i]
    with gil:
        (<_Factor>f.factor).solve(size, v)
