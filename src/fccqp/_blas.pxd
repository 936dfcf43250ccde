# cython: language_level=3
"""Column-major (Fortran) level-3 operations and Cholesky for the factorizations and
many-column products of the KKT backends, as one-line calls. Up to a measured order
(``TRSM_LOOP_ROWS``, ``SYRK_LOOP_ORDER``, ``CHOLESKY_LOOP_ROWS``) they run
``fccqp_kernels.h``'s blocked loops, since at whole-body control's sizes OpenBLAS'
packing and call set-up cost more than the arithmetic; above it, and for ``gemm``, they
call scipy's own OpenBLAS through ``scipy.linalg.cython_blas`` / ``cython_lapack``
(pointers, so nothing is linked at build time). Single vectors go through the loops of
``fccqp._dense``.
"""

from scipy.linalg.cython_blas cimport dgemm, dsyrk, dtrsm
from scipy.linalg.cython_lapack cimport dpotrf, dpotrs

from fccqp.tuning cimport CHOLESKY_LOOP_ROWS, SYRK_LOOP_ORDER, TRSM_LOOP_ROWS

cdef extern from "fccqp_kernels.h" nogil:
    int fccqp_cholesky(double* M, int n, int ld)
    int fccqp_syrk_lower(int n, int k, const double* A, int lda, double beta, double* C,
                         int ldc)
    void fccqp_trsm_left(char trans, const double* L, int n, int ld, double* B, int cols,
                         int ldb)


cdef inline void gemm(char ta, char tb, int m, int n, int k, double alpha, const double* a,
                      int lda, const double* b, int ldb, double beta, double* c,
                      int ldc) noexcept nogil:
    """``C = alpha op(A) op(B) + beta C``."""
    dgemm(&ta, &tb, &m, &n, &k, &alpha, <double*>a, &lda, <double*>b, &ldb, &beta, c, &ldc)


cdef inline void trsm(char side, char trans, int m, int n, const double* L, int ldl,
                      double* B, int ldb) noexcept nogil:
    """``B := op(L)^-1 B`` (side ``L``) or ``B op(L)^-1`` (side ``R``), ``L`` lower.

    Side ``L`` up to order ``TRSM_LOOP_ROWS`` by ``fccqp_trsm_left`` (fccqp_kernels.h):
    natively (one thread) 0.1-0.6x ``dtrsm``'s time at the Schur backend's shapes
    (go2's 18 and 30 rows, talos' 38 and 68), whose packing and SkylakeX kernels
    cost more than the solve; ``dtrsm`` above, where its blocking keeps ``L`` in cache."""
    cdef char lower = b"L", non_unit = b"N"
    cdef double one = 1.0
    if side == b"L" and m <= TRSM_LOOP_ROWS:
        fccqp_trsm_left(trans, L, m, ldl, B, n, ldb)
        return
    dtrsm(&side, &lower, &trans, &non_unit, &m, &n, &one, <double*>L, &ldl, B, &ldb)


cdef inline void syrk_t(int n, int k, const double* a, int lda, double beta, double* c,
                        int ldc) noexcept nogil:
    """Lower triangle of ``C = A' A + beta C`` (``A`` is ``k x n``).

    ``fccqp_syrk_lower`` (fccqp_kernels.h) up to order ``SYRK_LOOP_ORDER`` where the CPU
    has AVX2 and FMA and ``A`` at least an eighth as many rows as the order, ``dsyrk``
    otherwise: at these sizes OpenBLAS packs ``A`` on every call, and natively its
    SkylakeX ``dsyrk`` took 2.1 us for go2's 30 x 30 Schur complements from 30 rows
    against the kernel's 0.9 (12.0 against 6.9 for talos' 68 x 68)."""
    cdef char lower = b"L", trans = b"T"
    cdef double one = 1.0
    if n <= SYRK_LOOP_ORDER and fccqp_syrk_lower(n, k, a, lda, beta, c, ldc):
        return
    dsyrk(&lower, &trans, &n, &k, &one, <double*>a, &lda, &beta, c, &ldc)


cdef inline bint cholesky(double* M, int n, int ld) noexcept nogil:
    """Factor the lower triangle of ``M`` in place; False if not positive definite.

    ``fccqp_cholesky`` (fccqp_kernels.h) up to order ``CHOLESKY_LOOP_ROWS``, ``dpotrf``
    above: on a cold go2 tick the 304 ``dpotrf`` calls per 100 ticks took 4.7M
    instructions, most of them in its unblocked ``dpotf2``'s ``dgemv`` and ``dscal``
    calls (callgrind); natively, one thread, the loop takes 0.58-0.70x ``dpotrf``'s time
    up to order 64, 0.95x at 128, 1.02x at 192 and 1.6x at 1024, where ``dpotrf``'s
    blocking keeps the trailing matrix in cache."""
    cdef char lower = b"L"
    cdef int info = 0
    if n <= CHOLESKY_LOOP_ROWS:
        return fccqp_cholesky(M, n, ld) != 0
    dpotrf(&lower, &n, M, &ld, &info)
    return info == 0


cdef inline void forward_substitution(const double* L, int n, int ld, double* b) noexcept nogil:
    """``b := L^-1 b`` for the column-major lower triangle ``L``, column by column: each
    solved entry, multiplied by its pivot's reciprocal (which does not wait for ``b``,
    so that the division leaves the chain of dependent steps), is subtracted from the
    entries below it. Four columns at a time: their entries are solved in turn, then
    the four subtractions from each entry below them in one pass (each entry's in
    column order, as one column at a time would), which loads and stores it once."""
    cdef int i, k = 0
    cdef double v0, v1, v2, v3
    cdef const double* c0
    cdef const double* c1
    cdef const double* c2
    cdef const double* c3
    while k + 4 <= n:
        c0 = L + k * ld
        c1 = c0 + ld
        c2 = c1 + ld
        c3 = c2 + ld
        v0 = b[k] * (1.0 / c0[k])
        b[k + 1] -= c0[k + 1] * v0
        b[k + 2] -= c0[k + 2] * v0
        b[k + 3] -= c0[k + 3] * v0
        v1 = b[k + 1] * (1.0 / c1[k + 1])
        b[k + 2] -= c1[k + 2] * v1
        b[k + 3] -= c1[k + 3] * v1
        v2 = b[k + 2] * (1.0 / c2[k + 2])
        b[k + 3] -= c2[k + 3] * v2
        v3 = b[k + 3] * (1.0 / c3[k + 3])
        b[k], b[k + 1], b[k + 2], b[k + 3] = v0, v1, v2, v3
        for i in range(k + 4, n):
            b[i] = b[i] - c0[i] * v0 - c1[i] * v1 - c2[i] * v2 - c3[i] * v3
        k += 4
    for k in range(k, n):
        c0 = L + k * ld
        v0 = b[k] * (1.0 / c0[k])
        b[k] = v0
        for i in range(k + 1, n):
            b[i] -= c0[i] * v0


cdef inline void backward_substitution(const double* L, int n, int ld, double* b) noexcept nogil:
    """``b := L'^-1 b`` for the column-major lower triangle ``L``, from the last entry
    up: each solved entry, multiplied by its pivot's reciprocal, is subtracted from the
    entries above it (row ``k`` of ``L``). The entries above are independent sums, so a
    step waits for two multiplications and a subtraction, where a dot product per row of
    ``L'`` would wait for each of its subtractions in turn, the latest entry's first, and
    a division (go2's ``H``, n = 20: about 920 cycles of latency, 380 with the division
    in the chain, 180 without). Four rows at a time, as in
    :func:`forward_substitution`: their four entries of column ``i`` are adjacent."""
    cdef int i, k = n
    cdef double v0, v1, v2, v3
    cdef const double* column
    while k >= 4:
        k -= 4   # rows k + 3 (solved first) down to k
        v3 = b[k + 3] * (1.0 / L[k + 3 + (k + 3) * ld])
        b[k + 2] -= L[k + 3 + (k + 2) * ld] * v3
        b[k + 1] -= L[k + 3 + (k + 1) * ld] * v3
        b[k] -= L[k + 3 + k * ld] * v3
        v2 = b[k + 2] * (1.0 / L[k + 2 + (k + 2) * ld])
        b[k + 1] -= L[k + 2 + (k + 1) * ld] * v2
        b[k] -= L[k + 2 + k * ld] * v2
        v1 = b[k + 1] * (1.0 / L[k + 1 + (k + 1) * ld])
        b[k] -= L[k + 1 + k * ld] * v1
        v0 = b[k] * (1.0 / L[k + k * ld])
        b[k], b[k + 1], b[k + 2], b[k + 3] = v0, v1, v2, v3
        for i in range(k):
            column = L + k + i * ld
            b[i] = b[i] - column[3] * v3 - column[2] * v2 - column[1] * v1 - column[0] * v0
    for k in range(k - 1, -1, -1):
        v0 = b[k] * (1.0 / L[k + k * ld])
        b[k] = v0
        for i in range(k):
            b[i] -= L[k + i * ld] * v0


cdef inline void cholesky_solve_vector(const double* L, int n, int ld, double* b) noexcept nogil:
    """``b := (L L')^-1 b`` for one vector: forward then backward substitution on the
    column-major lower factor ``L``. Loops, not ``dpotrs``: for one right-hand side at
    n = 54 (go2's ``H``) ``dpotrs`` went through two ``dtrsm`` calls whose set-up cost
    more than the 3k multiply-adds (callgrind: the single-vector solves were a third of
    the Schur backend's instructions)."""
    forward_substitution(L, n, ld, b)
    backward_substitution(L, n, ld, b)


cdef inline void cholesky_solve(const double* L, int n, int ld, double* B, int columns,
                                int ldb) noexcept nogil:
    """``B := (L L')^-1 B`` for ``L`` from :func:`cholesky`: up to order
    ``TRSM_LOOP_ROWS`` one column by :func:`cholesky_solve_vector` and more by
    ``fccqp_trsm_left`` (``L^-1``, then ``L'^-1``), ``dpotrs`` above (see :func:`trsm`)."""
    cdef char lower = b"L"
    cdef int info = 0
    if n <= TRSM_LOOP_ROWS:
        if columns == 1:
            cholesky_solve_vector(L, n, ld, B)
        else:
            fccqp_trsm_left(b"N", L, n, ld, B, columns, ldb)
            fccqp_trsm_left(b"T", L, n, ld, B, columns, ldb)
        return
    dpotrs(&lower, &n, &columns, <double*>L, &ld, B, &ldb, &info)
