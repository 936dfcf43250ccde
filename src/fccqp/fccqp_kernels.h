/* Small dense kernels compiled twice, for AVX2 + FMA and for the baseline x86-64 (SSE2),
 * the copy picked at load time by the CPU (GCC / clang target_clones, an ifunc): the
 * rest of the core is built for the baseline, so that a wheel runs on every x86-64.
 * Elsewhere (other compilers, other C libraries, other architectures) there is one
 * baseline copy.
 *
 * fccqp_lu: LU with partial pivoting of a column-major n x n matrix in place, pivots
 * 1-based as LAPACK's dgetrf leaves them for dgetrs; returns 0 at a zero pivot, else 1.
 * Right-looking in panels of FCCQP_LU_PANEL columns, as dgetrf blocks: a panel is
 * factored one column at a time (rows swapped in full), then each trailing column gets
 * the panel's four updates in one pass, which loads and stores it once instead of four
 * times (callgrind, talos' 64-row systems: see polish_table.LU_LOOP_ROWS).
 *
 * fccqp_cholesky: Cholesky factor L L' of the lower triangle of a column-major n x n
 * matrix (leading dimension ld) in place; returns 0 at a pivot that is not positive.
 * Right-looking in panels of FCCQP_LU_PANEL columns like fccqp_lu. For the polish's
 * Schur complements (go2: 34 rows) dpotrf took 26k instructions a call, most of it in
 * its recursion's dtrsm / dsyrk set-up (callgrind; see polish_schur).
 *
 * fccqp_matvec_t: out = M' y for a row-major rows x cols M with leading dimension ld
 * (out aliases neither input, as BLAS requires): four scaled rows of M added to out per
 * pass, a loop over contiguous entries that vectorizes without reassociating a sum.
 * 2.1k instructions a call against dgemv's 2.8k on go2's A' y and P y (callgrind); M x
 * stays with dgemv, whose dot-product kernel took 3.2k against 3.7k for a loop in four
 * explicit lanes. fccqp_cholesky also factors polish_schur's d x d cone blocks.
 */
#ifndef FCCQP_KERNELS_H
#define FCCQP_KERNELS_H

#include <math.h>

/* ifuncs need glibc (math.h above defines __GLIBC__ there); musl gets one copy */
#if defined(__x86_64__) && defined(__GLIBC__) && (defined(__GNUC__) || defined(__clang__))
#define FCCQP_CLONES __attribute__((target_clones("arch=haswell", "default")))
#else
#define FCCQP_CLONES
#endif

#define FCCQP_LU_PANEL 4

/* c[i] -= u0 l0[i] + u1 l1[i] + u2 l2[i] + u3 l3[i] for i in [from, to): four pivots'
 * updates of one trailing column in one pass (c is none of the l's) */
static inline void fccqp_rank4_update(double *restrict c, const double *restrict l0,
                                      const double *restrict l1, const double *restrict l2,
                                      const double *restrict l3, double u0, double u1,
                                      double u2, double u3, int from, int to)
{
    for (int i = from; i < to; i++)
        c[i] -= u0 * l0[i] + u1 * l1[i] + u2 * l2[i] + u3 * l3[i];
}

FCCQP_CLONES
static int fccqp_lu(double *T, int n, int *piv)
{
    for (int k0 = 0; k0 < n; k0 += FCCQP_LU_PANEL) {
        int end = k0 + FCCQP_LU_PANEL < n ? k0 + FCCQP_LU_PANEL : n;
        for (int k = k0; k < end; k++) {   /* the panel, one column at a time */
            double *pivot_column = T + (long)k * n;
            int best = k;
            double largest = fabs(pivot_column[k]);
            for (int i = k + 1; i < n; i++) {
                if (fabs(pivot_column[i]) > largest) {
                    largest = fabs(pivot_column[i]);
                    best = i;
                }
            }
            piv[k] = best + 1;
            if (largest == 0.0)
                return 0;
            if (best != k) {   /* whole rows: the trailing columns get the swap now */
                for (int j = 0; j < n; j++) {
                    double value = T[k + (long)j * n];
                    T[k + (long)j * n] = T[best + (long)j * n];
                    T[best + (long)j * n] = value;
                }
            }
            double inverse = 1.0 / pivot_column[k];
            for (int i = k + 1; i < n; i++)
                pivot_column[i] *= inverse;
            for (int j = k + 1; j < end; j++) {
                double *column = T + (long)j * n;
                double factor = column[k];
                if (factor != 0.0) {
                    for (int i = k + 1; i < n; i++)
                        column[i] -= factor * pivot_column[i];
                }
            }
        }
        const double *l0 = T + (long)k0 * n;
        for (int j = end; j < n; j++) {   /* the trailing columns: U12, then the update */
            double *column = T + (long)j * n;
            for (int a = k0 + 1; a < end; a++)
                for (int b = k0; b < a; b++)
                    column[a] -= T[a + (long)b * n] * column[b];
            if (end - k0 == FCCQP_LU_PANEL) {
                double u0 = column[k0], u1 = column[k0 + 1], u2 = column[k0 + 2];
                double u3 = column[k0 + 3];
                if (u0 != 0.0 || u1 != 0.0 || u2 != 0.0 || u3 != 0.0)
                    fccqp_rank4_update(column, l0, l0 + n, l0 + 2 * (long)n, l0 + 3 * (long)n,
                                       u0, u1, u2, u3, end, n);
            } else {
                for (int b = k0; b < end; b++) {
                    const double *l = T + (long)b * n;
                    double u = column[b];
                    if (u != 0.0) {
                        for (int i = end; i < n; i++)
                            column[i] -= u * l[i];
                    }
                }
            }
        }
    }
    return 1;
}

FCCQP_CLONES
static int fccqp_cholesky(double *M, int n, int ld)
{
    for (int k0 = 0; k0 < n; k0 += FCCQP_LU_PANEL) {
        int end = k0 + FCCQP_LU_PANEL < n ? k0 + FCCQP_LU_PANEL : n;
        for (int k = k0; k < end; k++) {   /* the panel, one column at a time */
            double *pivot_column = M + (long)k * ld;
            double pivot = pivot_column[k];
            if (!(pivot > 0.0))
                return 0;
            pivot = sqrt(pivot);
            pivot_column[k] = pivot;
            double inverse = 1.0 / pivot;
            for (int i = k + 1; i < n; i++)
                pivot_column[i] *= inverse;
            for (int j = k + 1; j < end; j++) {
                double *column = M + (long)j * ld;
                double factor = pivot_column[j];
                for (int i = j; i < n; i++)
                    column[i] -= factor * pivot_column[i];
            }
        }
        const double *l0 = M + (long)k0 * ld;
        for (int j = end; j < n; j++) {   /* the trailing columns: the panel's updates */
            double *column = M + (long)j * ld;
            if (end - k0 == FCCQP_LU_PANEL) {
                fccqp_rank4_update(column, l0, l0 + ld, l0 + 2 * (long)ld, l0 + 3 * (long)ld,
                                   l0[j], l0[ld + j], l0[2 * (long)ld + j],
                                   l0[3 * (long)ld + j], j, n);
            } else {
                for (int b = k0; b < end; b++) {
                    const double *l = M + (long)b * ld;
                    double factor = l[j];
                    for (int i = j; i < n; i++)
                        column[i] -= factor * l[i];
                }
            }
        }
    }
    return 1;
}


FCCQP_CLONES
static void fccqp_matvec_t(const double *restrict M, int ld, const double *restrict y,
                           double *restrict out, int rows, int cols)
{
    for (int j = 0; j < cols; j++)
        out[j] = 0.0;
    int i = 0;
    for (; i + 4 <= rows; i += 4) {
        const double *r0 = M + (long)i * ld, *r1 = r0 + ld, *r2 = r1 + ld, *r3 = r2 + ld;
        double y0 = y[i], y1 = y[i + 1], y2 = y[i + 2], y3 = y[i + 3];
        for (int j = 0; j < cols; j++)
            out[j] += (y0 * r0[j] + y1 * r1[j]) + (y2 * r2[j] + y3 * r3[j]);
    }
    for (; i < rows; i++) {
        const double *r0 = M + (long)i * ld;
        double y0 = y[i];
        for (int j = 0; j < cols; j++)
            out[j] += y0 * r0[j];
    }
}

#endif
