/* Small dense kernels compiled twice, for AVX2 + FMA and for the baseline x86-64 (SSE2),
 * the copy picked at load time by the CPU (GCC / clang target_clones, an ifunc): the
 * rest of the core is built for the baseline, so that a wheel runs on every x86-64.
 * Elsewhere (other compilers, other C libraries, other architectures) there is one
 * baseline copy.
 *
 * fccqp_lu: LU with partial pivoting of a column-major n x n matrix in place, pivots
 * 1-based as LAPACK's dgetrf leaves them for dgetrs; returns 0 at a zero pivot, else 1.
 * Right-looking, one column at a time: the update of a column is a contiguous axpy.
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

FCCQP_CLONES
static int fccqp_lu(double *T, int n, int *piv)
{
    for (int k = 0; k < n; k++) {
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
        if (best != k) {
            for (int j = 0; j < n; j++) {
                double value = T[k + (long)j * n];
                T[k + (long)j * n] = T[best + (long)j * n];
                T[best + (long)j * n] = value;
            }
        }
        double inverse = 1.0 / pivot_column[k];
        for (int i = k + 1; i < n; i++)
            pivot_column[i] *= inverse;
        for (int j = k + 1; j < n; j++) {
            double *column = T + (long)j * n;
            double factor = column[k];
            if (factor != 0.0) {
                for (int i = k + 1; i < n; i++)
                    column[i] -= factor * pivot_column[i];
            }
        }
    }
    return 1;
}

#endif
