# cython: language_level=3, boundscheck=False, wraparound=False, cdivision=True, initializedcheck=False
"""The elimination's presolve and recovery as compiled code, to count their instructions.

Not part of the package: the arithmetic of ``tools/elimination_study.py``'s
``eliminate`` and ``recover`` (dense, column-major, LAPACK/BLAS from scipy), with the
gathers of the blocks from the full ``P`` and ``A`` by index, on preallocated arrays:

    presolve: gather K = A[rows, free], A_c = A[rows, kept], P_ff, P_fc, P_cc, the rest
              rows' A[rest, free], A[rest, kept]; dgetrf(K); dgetrs: [W | w] = K^-1 [A_c | b_rows];
              T = P_ff [W | w] (dgemm); P' = P_cc + W' T_W - P_fc' W - W' P_fc (dgemm, dgemm;
              both skipped when the gather found ``P_fc = 0``, as on the benchmark's QPs);
              q'' = q_c - W'(T_w + q_f) + P_fc' w; A' = A[rest, kept] - A[rest, free] W;
              b' = b_rest - A[rest, free] w.
    recover:  x_f = w - W x_c; r = b_rows - A[rows] x; x_f += K^-1 r (one refinement);
              g = P x + q + A[rest]' y_rest; y_rows = -K^-T g_f.
"""

from scipy.linalg.cython_blas cimport dgemm, dgemv
from scipy.linalg.cython_lapack cimport dgetrf, dgetrs


cdef bint gather(const double[::1, :] M, const int[::1] r, const int[::1] c,
                 double[::1, :] out) noexcept nogil:
    """``out = M[r, c]``; True when a gathered entry is nonzero."""
    cdef int i, j
    cdef bint nonzero = False
    for j in range(c.shape[0]):
        for i in range(r.shape[0]):
            out[i, j] = M[r[i], c[j]]
            nonzero = nonzero or out[i, j] != 0.0
    return nonzero


cdef void gemm(char ta, char tb, int m, int n, int k, double alpha, double* a, int lda,
               double* b, int ldb, double beta, double* c, int ldc) noexcept nogil:
    dgemm(&ta, &tb, &m, &n, &k, &alpha, a, &lda, b, &ldb, &beta, c, &ldc)


cdef class Presolve:
    """Workspace of one structure: index sets and every block, allocated once."""
    cdef int nf, nk, nr
    cdef public object free, kept, rows, rest
    cdef public object K, piv, Ww, Pff, Pfc, Pcc, T, Arf, Ark, Pr, qr, Ar, br, w, xf, r, g, y

    def __init__(self, free, kept, rows, rest):
        import numpy as np

        self.free, self.kept, self.rows, self.rest = (np.asarray(v, dtype=np.intc)
                                                      for v in (free, kept, rows, rest))
        self.nf, self.nk, self.nr = len(free), len(kept), len(rest)
        F = lambda a, b: np.zeros((a, b), order="F")
        self.K, self.Ww, self.T = F(self.nf, self.nf), F(self.nf, self.nk + 1), F(self.nf, self.nk + 1)
        self.Pff, self.Pfc, self.Pcc = F(self.nf, self.nf), F(self.nf, self.nk), F(self.nk, self.nk)
        self.Arf, self.Ark, self.Ar = F(self.nr, self.nf), F(self.nr, self.nk), F(self.nr, self.nk)
        self.Pr = F(self.nk, self.nk)
        self.piv = np.zeros(self.nf, dtype=np.intc)
        self.qr, self.br, self.w = np.zeros(self.nk), np.zeros(self.nr), np.zeros(self.nf)
        self.xf, self.r, self.g = np.zeros(self.nf), np.zeros(self.nf), np.zeros(len(free) + len(kept))
        self.y = np.zeros(self.nf)

    def presolve(self, double[::1, :] P, double[::1] q, double[::1, :] A, double[::1] b):
        """The reduced problem's P', q'', A', b' into the workspace; LAPACK's info."""
        cdef double[::1, :] K = self.K, Ww = self.Ww, T = self.T, Pff = self.Pff
        cdef double[::1, :] Pfc = self.Pfc, Pcc = self.Pcc, Arf = self.Arf, Ark = self.Ark
        cdef double[::1, :] Pr = self.Pr, Ar = self.Ar
        cdef double[::1] qr = self.qr, br = self.br
        cdef int[::1] free = self.free, kept = self.kept, rows = self.rows, rest = self.rest
        cdef int[::1] piv = self.piv
        cdef int nf = self.nf, nk = self.nk, nr = self.nr, nrhs = nk + 1, info = 0, i, j
        cdef char nt = b'N'
        cdef bint coupled
        with nogil:
            gather(A, rows, free, K)
            gather(A, rows, kept, Ww)
            for i in range(nf):
                Ww[i, nk] = b[rows[i]]
            gather(P, free, free, Pff)
            coupled = gather(P, free, kept, Pfc)
            gather(P, kept, kept, Pcc)
            gather(A, rest, free, Arf)
            gather(A, rest, kept, Ark)
            dgetrf(&nf, &nf, &K[0, 0], &nf, &piv[0], &info)
        if info != 0:
            return info
        with nogil:
            dgetrs(&nt, &nf, &nrhs, &K[0, 0], &nf, &piv[0], &Ww[0, 0], &nf, &info)
            gemm(b'N', b'N', nf, nrhs, nf, 1.0, &Pff[0, 0], nf, &Ww[0, 0], nf, 0.0, &T[0, 0], nf)
            for j in range(nk):                  # P' = P_cc + W' (P_ff W) - P_fc' W - W' P_fc
                for i in range(nk):
                    Pr[i, j] = Pcc[i, j]
            gemm(b'T', b'N', nk, nk, nf, 1.0, &Ww[0, 0], nf, &T[0, 0], nf, 1.0, &Pr[0, 0], nk)
            if coupled:
                gemm(b'T', b'N', nk, nk, nf, -1.0, &Pfc[0, 0], nf, &Ww[0, 0], nf, 1.0,
                     &Pr[0, 0], nk)
                gemm(b'T', b'N', nk, nk, nf, -1.0, &Ww[0, 0], nf, &Pfc[0, 0], nf, 1.0,
                     &Pr[0, 0], nk)
            for i in range(nf):                  # T_w + q_f, then q'' = q_c - W'(.) + P_fc' w
                T[i, nk] = T[i, nk] + q[free[i]]
            for j in range(nk):
                qr[j] = q[kept[j]]
                for i in range(nf):
                    qr[j] = qr[j] - Ww[i, j] * T[i, nk] + Pfc[i, j] * Ww[i, nk]
            if nr > 0:
                for j in range(nk):
                    for i in range(nr):
                        Ar[i, j] = Ark[i, j]
                gemm(b'N', b'N', nr, nk, nf, -1.0, &Arf[0, 0], nr, &Ww[0, 0], nf, 1.0, &Ar[0, 0], nr)
                for i in range(nr):
                    br[i] = b[rest[i]]
                    for j in range(nf):
                        br[i] = br[i] - Arf[i, j] * Ww[j, nk]
        return info

    def recover(self, double[::1, :] P, double[::1] q, double[::1, :] A, double[::1] b,
                double[::1] xc, double[::1] yr, double[::1] x, double[::1] y):
        """``x`` and ``y`` of the original problem from the reduced ``xc``, ``yr``."""
        cdef double[::1, :] K = self.K, Ww = self.Ww
        cdef double[::1] r = self.r, g = self.g, yf = self.y
        cdef int[::1] free = self.free, kept = self.kept, rows = self.rows, rest = self.rest
        cdef int[::1] piv = self.piv
        cdef int nf = self.nf, nk = self.nk, nr = self.nr, n = P.shape[0], m = A.shape[0]
        cdef int one = 1, info = 0, i, j
        cdef double a1 = 1.0, a0 = 0.0, s
        cdef char nt = b'N', tt = b'T'
        with nogil:
            for j in range(nk):
                x[kept[j]] = xc[j]
            for i in range(nf):                      # x_f = w - W x_c
                s = Ww[i, nk]
                for j in range(nk):
                    s = s - Ww[i, j] * xc[j]
                x[free[i]] = s
            for i in range(nf):                      # r = b_rows - A[rows] x
                s = b[rows[i]]
                for j in range(n):
                    s = s - A[rows[i], j] * x[j]
                r[i] = s
            dgetrs(&nt, &nf, &one, &K[0, 0], &nf, &piv[0], &r[0], &nf, &info)
            for i in range(nf):
                x[free[i]] = x[free[i]] + r[i]
            dgemv(&nt, &n, &n, &a1, &P[0, 0], &n, &x[0], &one, &a0, &g[0], &one)
            for i in range(nr):
                y[rest[i]] = yr[i]
            for i in range(nf):                      # -(P x + q + A[rest]' y_rest)_f
                s = g[free[i]] + q[free[i]]
                for j in range(nr):
                    s = s + A[rest[j], free[i]] * yr[j]
                yf[i] = -s
            dgetrs(&tt, &nf, &one, &K[0, 0], &nf, &piv[0], &yf[0], &nf, &info)
            for i in range(nf):
                y[rows[i]] = yf[i]
        return info
