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
 * times (callgrind, talos' 64-row systems: see tuning.LU_LOOP_ROWS and notes/tuning.md),
 * and two trailing columns at a time as fccqp_cholesky's (fccqp_rank4_update2, the same
 * bits; a column with nothing to subtract is skipped and pairs with the next one).
 *
 * fccqp_cholesky: Cholesky factor L L' of the lower triangle of a column-major n x n
 * matrix (leading dimension ld) in place; returns 0 at a pivot that is not positive.
 * Right-looking in panels of FCCQP_LU_PANEL columns like fccqp_lu, the trailing columns
 * updated two at a time (fccqp_rank4_update2: the panel's four columns loaded once for
 * both, each entry's operations unchanged, so the same bits): talos' warm polish
 * factors 68-76 rows two or three times a tick, and the pairs took its cell from
 * 2.173M to 2.113M instructions a tick (callgrind). For the polish's
 * Schur complements (go2: 34 rows) dpotrf took 26k instructions a call, most of it in
 * its recursion's dtrsm / dsyrk set-up (callgrind; see polish_schur).
 *
 * fccqp_matvec_t: out = M' y for a row-major rows x cols M with leading dimension ld
 * (out aliases neither input, as BLAS requires): four scaled rows of M added to out per
 * pass, a loop over contiguous entries that vectorizes without reassociating a sum.
 * 2.1k instructions a call against dgemv's 2.8k on go2's A' y and P y (callgrind); M x
 * goes to fccqp_matvec below (dgemv's dot-product kernel took 3.2k against 3.7k for a
 * loop in four explicit lanes, but its interface and driver cost more than that).
 * fccqp_cholesky also factors, through _blas.cholesky up to order CHOLESKY_LOOP_ROWS
 * (dpotrf above), the Schur backend's, the reduced table's, the Gram matrices' and
 * polish_schur's factors.
 *
 * fccqp_sparse_rank_update: T += Y_R' Y_R (lower triangle) over a few sparse rows of
 * Y, a fused multiply-add per nonzero pair, row after row (schur.pyx says why in that
 * order); fccqp_sparse_rank_clear zeroes what it wrote. Fused multiply-adds are exact
 * roundings, the same bits whether the AVX2 copy's instruction or the baseline's libm
 * call computes them.
 *
 * fccqp_spd_solve: (A + shift I) x = b for a tiny k x k positive definite A, row-major
 * with leading dimension lda (Anderson's Gram matrix, k <= its memory, read where its
 * products are kept, no copy): b becomes x, M (k x k, row-major; A itself with lda = k)
 * the Cholesky factor's lower triangle; returns 0 at a pivot that is not positive. The
 * operations and their order are those of plain loops (tests/test_anderson.py holds them), whatever k;
 * for k up to 10 (the default memory) the loops are unrolled in full for that k (a copy
 * per k, chosen by a switch): rolled, their trip counts (0 to k - 1, changing at every
 * row) cost a mispredicted branch per inner loop in callgrind's model, 40 a call, and
 * the solve took a third more time in perf's samples of a cold go2 tick
 * (notes/performance-history.md, "ipc"). Not cloned: a fused multiply-add would change
 * the bits.
 *
 * fccqp_slot_products: for each stored slot l (a row of Anderson's df, two_s entries),
 * to_new[l] = newest' row_l and to_f[l] = row_l' f; each sum in four lanes over the
 * entries (explicit lanes, so the same bits on every CPU), two slots per pass sharing the
 * loads of newest and f. In index order, one chain of additions per sum, they took 1.9k
 * of anderson_step's 5.9k instructions a call on a cold go2 tick (callgrind; eight
 * chains side by side, four slots a pass). fccqp_sum_squares sums v'v the same way.
 *
 * fccqp_slot_combination: out = sum over the stored slots l of coefficient[l] row_l,
 * each entry's terms added in slot order from 0.0 (the bits of one pass per slot), four
 * slots per pass over out, which is loaded and stored once per pass: Anderson's step
 * (dG + dF) gamma, 1.3k instructions a call one slot per pass.
 *
 * fccqp_fixed_point_residual, fccqp_point_differences, fccqp_extrapolate: Anderson's
 * loops over the 2s entries of its point, in C for the restrict pointers that let them
 * vectorize (Cython's pointers into its structs may alias, and stayed scalar).
 *
 * Anderson's kernels above (not fccqp_spd_solve, whose unrolled chains gain nothing from
 * vectors) have an AVX2 copy built without contraction into fused multiply-adds
 * (FCCQP_EXACT_CLONES), so both copies round alike. On a cold go2 tick anderson_step
 * went from 5.9k to 2.9k instructions a call with them (notes/tuning.md, "anderson3").
 *
 * fccqp_symmetric_copy, fccqp_checked_copy, fccqp_scale_rows, fccqp_ruiz_maxima and
 * fccqp_row_spans: the per-solve passes over P and A of the validation scan, the
 * rescaling, the equilibration's passes and the rows' spans. They keep running maxima
 * or skip zeros, which GCC does not vectorize (a float max is not associative once NaN
 * is allowed, not without -ffast-math), so they are written in four lanes (fccqp_v4).
 * Per go2 solve (callgrind, 200 ticks of Settings.realtime(inf)): the scan went from
 * 82k to 42k instructions and the rescaling from 62k to 48k; in wall time (one process
 * each, passes alternated, Zen) the rescaling and spans from 11.5 to 5.7 us; the scan,
 * which is the first read of the caller's arrays, stayed at 10-11 us. fccqp_ruiz_maxima,
 * run 4 times per equilibration, is also cloned: a go2 pass took about 35k instructions
 * in Cython's loops, 34k in the baseline copy and 24k in the AVX2 one (callgrind).
 * The scan's, the rescaling's and the spans' passes have a 32-byte copy where the CPU
 * has AVX2 (the block "Every solve's passes" below); the spans' halves are cloned too.
 */
#ifndef FCCQP_KERNELS_H
#define FCCQP_KERNELS_H

#include <math.h>
#include <string.h>

/* ifuncs need glibc (math.h above defines __GLIBC__ there); musl gets one copy. The AVX2
 * copy is picked by the CPU's features: x86-64-v3 (AVX2, FMA) where GCC 12+ dispatches on
 * it, AVX2 alone otherwise. Not "arch=haswell", which GCC dispatches on the CPU model:
 * every other CPU (Zen, Skylake and later) ran the baseline copy, and callgrind, which
 * reports a Haswell, measured the other one. */
#if defined(__x86_64__) && defined(__GLIBC__) && defined(__GNUC__) && !defined(__clang__) \
    && __GNUC__ >= 12
#define FCCQP_CLONES __attribute__((target_clones("arch=x86-64-v3", "default")))
#elif defined(__x86_64__) && defined(__GLIBC__) && (defined(__GNUC__) || defined(__clang__))
#define FCCQP_CLONES __attribute__((target_clones("avx2", "default")))
#else
#define FCCQP_CLONES
#endif

/* Kernels with sums of products (Anderson's, the rows' spans) get the AVX2 copy with GCC
 * only, where it can be built without fused multiply-adds: both copies round alike */
#if defined(__GNUC__) && !defined(__clang__)
#define FCCQP_EXACT_CLONES FCCQP_CLONES __attribute__((optimize("fp-contract=off")))
#else
#define FCCQP_EXACT_CLONES
#endif

#define FCCQP_LU_PANEL 4

/* Four lanes of doubles for the per-solve passes (fccqp_symmetric_copy and the three
 * after it). With GCC / clang two vectors of two (vector extensions): the width SSE2 and
 * NEON have, so that the baseline build needs no clone; four lanes in one 32-byte vector
 * were 30 % faster in an AVX2 clone but 4x slower in the baseline, where GCC lowers
 * their comparisons to scalars. Elsewhere a struct the helpers loop over. The running
 * maxima use maxpd where there is SSE2 (one instruction; a compare and a blend else), and
 * fccqp_max4(acc, x) skips a NaN x: the passes flag NaN with a comparison instead. Flags
 * are lane masks, or-ed and read once at the end. */
#if defined(__GNUC__) || defined(__clang__)
/* forced, so that no caller keeps a helper out of line and passes the halves through
 * memory (measured the same as plain inline with GCC 12) */
#define FCCQP_LANE_OP static inline __attribute__((always_inline))
typedef double fccqp_v2 __attribute__((vector_size(16)));
typedef long long fccqp_m2 __attribute__((vector_size(16)));
typedef struct { fccqp_v2 lo, hi; } fccqp_v4;
typedef struct { fccqp_m2 lo, hi; } fccqp_flags4;
#define FCCQP_LANE(v, k) ((k) < 2 ? (v).lo[(k) & 1] : (v).hi[(k) & 1])
#if defined(__SSE2__)
#include <emmintrin.h>
FCCQP_LANE_OP fccqp_v2 fccqp_max2(fccqp_v2 acc, fccqp_v2 x)
{
    return (fccqp_v2)_mm_max_pd((__m128d)x, (__m128d)acc);   /* x > acc ? x : acc */
}
#else
FCCQP_LANE_OP fccqp_v2 fccqp_max2(fccqp_v2 acc, fccqp_v2 x)
{
    fccqp_m2 larger = x > acc;
    return (fccqp_v2)(((fccqp_m2)x & larger) | ((fccqp_m2)acc & ~larger));
}
#endif
FCCQP_LANE_OP fccqp_v2 fccqp_abs2(fccqp_v2 a)
{
    return (fccqp_v2)((fccqp_m2)a & (fccqp_m2){0x7fffffffffffffffLL, 0x7fffffffffffffffLL});
}
FCCQP_LANE_OP fccqp_v4 fccqp_load4(const double *p)
{
    fccqp_v4 v;
    memcpy(&v.lo, p, sizeof v.lo);
    memcpy(&v.hi, p + 2, sizeof v.hi);
    return v;
}
FCCQP_LANE_OP void fccqp_store4(double *p, fccqp_v4 v)
{
    memcpy(p, &v.lo, sizeof v.lo);
    memcpy(p + 2, &v.hi, sizeof v.hi);
}
FCCQP_LANE_OP fccqp_v4 fccqp_splat4(double x)
{
    fccqp_v4 r = {{x, x}, {x, x}};
    return r;
}
FCCQP_LANE_OP fccqp_v4 fccqp_set4(double a, double b, double c, double d)
{
    fccqp_v4 r = {{a, b}, {c, d}};
    return r;
}
#define FCCQP_HALVES(lo_value, hi_value) \
    fccqp_v4 r = {lo_value, hi_value};   \
    return r;
FCCQP_LANE_OP fccqp_v4 fccqp_add4(fccqp_v4 a, fccqp_v4 b) { FCCQP_HALVES(a.lo + b.lo, a.hi + b.hi) }
FCCQP_LANE_OP fccqp_v4 fccqp_sub4(fccqp_v4 a, fccqp_v4 b) { FCCQP_HALVES(a.lo - b.lo, a.hi - b.hi) }
FCCQP_LANE_OP fccqp_v4 fccqp_mul4(fccqp_v4 a, fccqp_v4 b) { FCCQP_HALVES(a.lo * b.lo, a.hi * b.hi) }
FCCQP_LANE_OP fccqp_v4 fccqp_abs4(fccqp_v4 a) { FCCQP_HALVES(fccqp_abs2(a.lo), fccqp_abs2(a.hi)) }
FCCQP_LANE_OP fccqp_v4 fccqp_max4(fccqp_v4 acc, fccqp_v4 x)
{
    FCCQP_HALVES(fccqp_max2(acc.lo, x.lo), fccqp_max2(acc.hi, x.hi))
}
FCCQP_LANE_OP fccqp_v4 fccqp_where_nonzero4(fccqp_v4 a, fccqp_v4 x)   /* a != 0 ? x : 0 */
{
    fccqp_v2 zero = {0.0, 0.0};
    FCCQP_HALVES((fccqp_v2)((fccqp_m2)x.lo & (a.lo != zero)),
                 (fccqp_v2)((fccqp_m2)x.hi & (a.hi != zero)))
}
FCCQP_LANE_OP fccqp_flags4 fccqp_no_flags4(void)
{
    fccqp_flags4 f = {{0, 0}, {0, 0}};
    return f;
}
FCCQP_LANE_OP fccqp_flags4 fccqp_flag_unequal4(fccqp_flags4 f, fccqp_v4 a, fccqp_v4 b)
{
    f.lo |= a.lo != b.lo;
    f.hi |= a.hi != b.hi;
    return f;
}
FCCQP_LANE_OP fccqp_flags4 fccqp_flag_beyond4(fccqp_flags4 f, fccqp_v4 a, double limit)
{   /* flags a lane where not a <= limit: beyond it, or NaN */
    fccqp_v2 l = {limit, limit};
    f.lo |= ~(a.lo <= l);
    f.hi |= ~(a.hi <= l);
    return f;
}
FCCQP_LANE_OP int fccqp_any4(fccqp_flags4 f)
{
    fccqp_m2 both = f.lo | f.hi;
    return (both[0] | both[1]) != 0;
}
#else
#define FCCQP_LANE_OP static inline
typedef struct { double lane[4]; } fccqp_v4;
typedef struct { int lane[4]; } fccqp_flags4;
#define FCCQP_LANE(v, k) ((v).lane[k])
#define FCCQP_LANEWISE(type, expression) \
    type r; for (int k = 0; k < 4; k++) r.lane[k] = (expression); return r;
FCCQP_LANE_OP fccqp_v4 fccqp_load4(const double *p) { FCCQP_LANEWISE(fccqp_v4, p[k]) }
FCCQP_LANE_OP void fccqp_store4(double *p, fccqp_v4 v)
{
    for (int k = 0; k < 4; k++)
        p[k] = v.lane[k];
}
FCCQP_LANE_OP fccqp_v4 fccqp_splat4(double x) { FCCQP_LANEWISE(fccqp_v4, x) }
FCCQP_LANE_OP fccqp_v4 fccqp_set4(double a, double b, double c, double d)
{
    fccqp_v4 r = {{a, b, c, d}};
    return r;
}
FCCQP_LANE_OP fccqp_v4 fccqp_add4(fccqp_v4 a, fccqp_v4 b) { FCCQP_LANEWISE(fccqp_v4, a.lane[k] + b.lane[k]) }
FCCQP_LANE_OP fccqp_v4 fccqp_sub4(fccqp_v4 a, fccqp_v4 b) { FCCQP_LANEWISE(fccqp_v4, a.lane[k] - b.lane[k]) }
FCCQP_LANE_OP fccqp_v4 fccqp_mul4(fccqp_v4 a, fccqp_v4 b) { FCCQP_LANEWISE(fccqp_v4, a.lane[k] * b.lane[k]) }
FCCQP_LANE_OP fccqp_v4 fccqp_abs4(fccqp_v4 a) { FCCQP_LANEWISE(fccqp_v4, fabs(a.lane[k])) }
FCCQP_LANE_OP fccqp_v4 fccqp_max4(fccqp_v4 acc, fccqp_v4 x)
{
    FCCQP_LANEWISE(fccqp_v4, x.lane[k] > acc.lane[k] ? x.lane[k] : acc.lane[k])
}
FCCQP_LANE_OP fccqp_v4 fccqp_where_nonzero4(fccqp_v4 a, fccqp_v4 x)
{
    FCCQP_LANEWISE(fccqp_v4, a.lane[k] != 0.0 ? x.lane[k] : 0.0)
}
FCCQP_LANE_OP fccqp_flags4 fccqp_no_flags4(void) { FCCQP_LANEWISE(fccqp_flags4, 0) }
FCCQP_LANE_OP fccqp_flags4 fccqp_flag_unequal4(fccqp_flags4 f, fccqp_v4 a, fccqp_v4 b)
{
    FCCQP_LANEWISE(fccqp_flags4, f.lane[k] | (a.lane[k] != b.lane[k]))
}
FCCQP_LANE_OP fccqp_flags4 fccqp_flag_beyond4(fccqp_flags4 f, fccqp_v4 a, double limit)
{
    FCCQP_LANEWISE(fccqp_flags4, f.lane[k] | !(a.lane[k] <= limit))
}
FCCQP_LANE_OP int fccqp_any4(fccqp_flags4 f)
{
    return (f.lane[0] | f.lane[1] | f.lane[2] | f.lane[3]) != 0;
}
#endif
FCCQP_LANE_OP double fccqp_largest4(fccqp_v4 v, double x)   /* max(x, lanes of v) */
{
    for (int k = 0; k < 4; k++)
        x = FCCQP_LANE(v, k) > x ? FCCQP_LANE(v, k) : x;
    return x;
}
FCCQP_LANE_OP double fccqp_sum4(fccqp_v4 v)
{
    return (FCCQP_LANE(v, 0) + FCCQP_LANE(v, 1)) + (FCCQP_LANE(v, 2) + FCCQP_LANE(v, 3));
}

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

/* fccqp_rank4_update on two columns at once, c0 with u = a, c1 with u = b: each
 * entry's operations are fccqp_rank4_update's, the loads of the four panel columns
 * shared by the two. */
static inline void fccqp_rank4_update2(double *restrict c0, double *restrict c1,
                                       const double *restrict l0, const double *restrict l1,
                                       const double *restrict l2, const double *restrict l3,
                                       const double *restrict a, const double *restrict b,
                                       int from, int to)
{
    for (int i = from; i < to; i++) {
        double x0 = l0[i], x1 = l1[i], x2 = l2[i], x3 = l3[i];
        c0[i] -= a[0] * x0 + a[1] * x1 + a[2] * x2 + a[3] * x3;
        c1[i] -= b[0] * x0 + b[1] * x1 + b[2] * x2 + b[3] * x3;
    }
}

/* U12 of one trailing column of fccqp_lu's panel: its four entries at the panel's rows
 * (u, updated in place) solved with the panel's unit lower triangle, copied into v */
static inline __attribute__((always_inline)) void fccqp_lu_u12(
    double *u, double a10, double a20, double a30, double a21, double a31, double a32,
    double v[4])
{
    v[0] = u[0];
    v[1] = u[1] - a10 * v[0];
    v[2] = u[2] - a20 * v[0] - a21 * v[1];
    v[3] = u[3] - a30 * v[0] - a31 * v[1] - a32 * v[2];
    u[1] = v[1], u[2] = v[2], u[3] = v[3];
}

/* whether a column's U12 has anything to subtract (a zero one is skipped, which keeps
 * the sign of a zero entry) */
static inline int fccqp_nonzero4(const double v[4])
{
    return v[0] != 0.0 || v[1] != 0.0 || v[2] != 0.0 || v[3] != 0.0;
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
        if (end == n)
            break;   /* only the last panel can be narrower, and nothing trails it */
        /* the trailing columns: U12, then the update; the panel's unit lower triangle
         * held in registers (in generic loops over it, 6.3k of go2's 23k instructions a
         * factorization, callgrind) */
        const double *l0 = T + (long)k0 * n, *l1 = l0 + n, *l2 = l1 + n;
        double a10 = l0[k0 + 1], a20 = l0[k0 + 2], a30 = l0[k0 + 3];
        double a21 = l1[k0 + 2], a31 = l1[k0 + 3], a32 = l2[k0 + 3];
        int j = end;
        for (; j + 1 < n; j += 2) {
            double *c0 = T + (long)j * n, *c1 = c0 + n;
            double a[4], b[4];
            fccqp_lu_u12(c0 + k0, a10, a20, a30, a21, a31, a32, a);
            fccqp_lu_u12(c1 + k0, a10, a20, a30, a21, a31, a32, b);
            if (fccqp_nonzero4(a) && fccqp_nonzero4(b))
                fccqp_rank4_update2(c0, c1, l0, l1, l2, l2 + n, a, b, end, n);
            else if (fccqp_nonzero4(a))
                fccqp_rank4_update(c0, l0, l1, l2, l2 + n, a[0], a[1], a[2], a[3], end, n);
            else if (fccqp_nonzero4(b))
                fccqp_rank4_update(c1, l0, l1, l2, l2 + n, b[0], b[1], b[2], b[3], end, n);
        }
        if (j < n) {
            double *column = T + (long)j * n;
            double a[4];
            fccqp_lu_u12(column + k0, a10, a20, a30, a21, a31, a32, a);
            if (fccqp_nonzero4(a))
                fccqp_rank4_update(column, l0, l1, l2, l2 + n, a[0], a[1], a[2], a[3], end, n);
        }
    }
    return 1;
}

/* fccqp_cholesky's columns [0, stop) (stop a multiple of FCCQP_LU_PANEL, or n), their
 * updates applied to the trailing columns: these then hold the Schur complement of the
 * leading block, ready for fccqp_cholesky. */
static inline __attribute__((always_inline)) int fccqp_cholesky_columns(double *M, int n,
                                                                        int ld, int stop)
{
    for (int k0 = 0; k0 < stop; k0 += FCCQP_LU_PANEL) {
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
        if (end == n)
            break;   /* no trailing columns: the last panel */
        /* the trailing columns, two at a time */
        const double *l0 = M + (long)k0 * ld, *l1 = l0 + ld, *l2 = l1 + ld, *l3 = l2 + ld;
        int j = end;
        for (; j + 1 < n; j += 2) {
            double *c0 = M + (long)j * ld, *c1 = c0 + ld;
            double a[4] = {l0[j], l1[j], l2[j], l3[j]};
            double b[4] = {l0[j + 1], l1[j + 1], l2[j + 1], l3[j + 1]};
            c0[j] -= a[0] * l0[j] + a[1] * l1[j] + a[2] * l2[j] + a[3] * l3[j];
            fccqp_rank4_update2(c0, c1, l0, l1, l2, l3, a, b, j + 1, n);
        }
        if (j < n)
            fccqp_rank4_update(M + (long)j * ld, l0, l1, l2, l3, l0[j], l1[j], l2[j], l3[j],
                               j, n);
    }
    return 1;
}

FCCQP_CLONES
static int fccqp_cholesky(double *M, int n, int ld)
{
    return fccqp_cholesky_columns(M, n, ld, n);
}

/* fccqp_cholesky_columns as a function: polish_schur factors the rows that every guess
 * of a base shares once (fccqp_cholesky_lead), then only the rows its boundary blocks
 * touch, per guess. */
FCCQP_CLONES
static int fccqp_cholesky_lead(double *M, int n, int ld, int stop)
{
    return fccqp_cholesky_columns(M, n, ld, stop);
}


/* out += M' y for a row-major rows x cols M (leading dimension ld): four scaled rows
 * added per pass; the core of fccqp_matvec_t and fccqp_colmatvec (a column-major M's
 * columns are a row-major M's rows). */
static inline __attribute__((always_inline)) void fccqp_add_scaled_rows(
    const double *restrict M, int ld, const double *restrict y, double *restrict out,
    int rows, int cols)
{
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

FCCQP_CLONES
static void fccqp_matvec_t(const double *restrict M, int ld, const double *restrict y,
                           double *restrict out, int rows, int cols)
{
    for (int j = 0; j < cols; j++)
        out[j] = 0.0;
    fccqp_add_scaled_rows(M, ld, y, out, rows, cols);
}

/* fccqp_matvec: out = M x for a row-major rows x cols M with leading dimension ld, where
 * the CPU has AVX2 and FMA (returns 1; else 0 and does nothing: the caller uses dgemv).
 * Four rows a pass sharing the loads of x, each row's dot product in four lanes of one
 * 32-byte vector (fused multiply-adds), the lanes summed (0 + 1) + (2 + 3), the last
 * cols % 4 entries added in order. A row's sum depends on that row and x only. Not a
 * target_clones pair: the same source with two 16-byte halves ran slower than dgemv in
 * both copies (go2's 30 x 54 A: 168 and 188 ns against 164), and 32-byte vectors in the
 * baseline copy 3x slower (484 ns). Natively (Zen 4, one thread, loop of calls,
 * /tmp/fusedcheck/bench.c) against scipy's dgemv: go2's A 30 x 54 125 against 164 ns,
 * P's block 20 x 54 83 against 121, the reduced table's 24 x 24 48 against 75; talos'
 * 68 x 124 578 against 618, 88 x 124 759 against 798. The instructions per call are
 * about dgemv's kernel's; what goes is the interface and driver (about 1.5k a call). */
#if defined(__x86_64__) && (defined(__GNUC__) || defined(__clang__))
#include <immintrin.h>

/* the four lanes' sum (0 + 1) + (2 + 3), then fma(row[j], x[j], sum) over the columns
 * from c4 on: intrinsics and fma() so that every row, four at a time or alone, rounds
 * the same (GCC vectorized the products of a plain tail in one place only) */
#define FCCQP_WIDE_ROW(acc, row, x, c4, cols, result)                                   \
    do {                                                                                \
        __m128d lo_ = _mm256_castpd256_pd128(acc), hi_ = _mm256_extractf128_pd(acc, 1); \
        double s_ = (_mm_cvtsd_f64(lo_) + _mm_cvtsd_f64(_mm_unpackhi_pd(lo_, lo_)))     \
                    + (_mm_cvtsd_f64(hi_) + _mm_cvtsd_f64(_mm_unpackhi_pd(hi_, hi_)));  \
        for (int j_ = (c4); j_ < (cols); j_++)                                          \
            s_ = fma((row)[j_], (x)[j_], s_);                                           \
        (result) = s_;                                                                  \
    } while (0)

__attribute__((target("avx2,fma")))
static void fccqp_matvec_wide(const double *restrict M, int ld, const double *restrict x,
                              double *restrict out, int rows, int cols)
{
    int c4 = cols & ~3;
    int i = 0;
    for (; i + 4 <= rows; i += 4) {
        const double *r0 = M + (long)i * ld, *r1 = r0 + ld, *r2 = r1 + ld, *r3 = r2 + ld;
        __m256d a0 = _mm256_setzero_pd(), a1 = a0, a2 = a0, a3 = a0;
        for (int j = 0; j < c4; j += 4) {
            __m256d xv = _mm256_loadu_pd(x + j);
            a0 = _mm256_fmadd_pd(_mm256_loadu_pd(r0 + j), xv, a0);
            a1 = _mm256_fmadd_pd(_mm256_loadu_pd(r1 + j), xv, a1);
            a2 = _mm256_fmadd_pd(_mm256_loadu_pd(r2 + j), xv, a2);
            a3 = _mm256_fmadd_pd(_mm256_loadu_pd(r3 + j), xv, a3);
        }
        FCCQP_WIDE_ROW(a0, r0, x, c4, cols, out[i]);
        FCCQP_WIDE_ROW(a1, r1, x, c4, cols, out[i + 1]);
        FCCQP_WIDE_ROW(a2, r2, x, c4, cols, out[i + 2]);
        FCCQP_WIDE_ROW(a3, r3, x, c4, cols, out[i + 3]);
    }
    for (; i < rows; i++) {
        const double *r0 = M + (long)i * ld;
        __m256d a0 = _mm256_setzero_pd();
        for (int j = 0; j < c4; j += 4)
            a0 = _mm256_fmadd_pd(_mm256_loadu_pd(r0 + j), _mm256_loadu_pd(x + j), a0);
        FCCQP_WIDE_ROW(a0, r0, x, c4, cols, out[i]);
    }
}

static inline int fccqp_matvec(const double *M, int ld, const double *x, double *out,
                               int rows, int cols)
{
    if (!(__builtin_cpu_supports("avx2") && __builtin_cpu_supports("fma")))
        return 0;
    fccqp_matvec_wide(M, ld, x, out, rows, cols);
    return 1;
}
#else
static inline int fccqp_matvec(const double *M, int ld, const double *x, double *out,
                               int rows, int cols)
{
    (void)M, (void)ld, (void)x, (void)out, (void)rows, (void)cols;
    return 0;
}
#endif

/* fccqp_colmatvec: out = M x + beta out for a column-major rows x cols M with leading
 * dimension ld (beta 0: out is not read), four scaled columns added per pass as
 * fccqp_matvec_t adds rows. Against dgemv ("N"), natively (bench.c above): the reduced
 * table's 84 x 24 115 against 242 ns (baseline copy 203), 24 x 24 46 against 95, talos'
 * 192 x 56 736 against 949. */
FCCQP_CLONES
static void fccqp_colmatvec(const double *restrict M, int ld, const double *restrict x,
                            double *restrict out, int rows, int cols, double beta)
{
    if (beta == 0.0) {
        for (int i = 0; i < rows; i++)
            out[i] = 0.0;
    } else if (beta != 1.0) {
        for (int i = 0; i < rows; i++)
            out[i] *= beta;
    }
    fccqp_add_scaled_rows(M, ld, x, out, cols, rows);
}

/* For each row j < rows of the column-major Y (leading dimension ld) and each pair
 * a >= b of its nonzero columns index[j m:j m + count[j]] (increasing): T[a + b m] =
 * fma(Y[j, a], Y[j, b], T[a + b m]); values is scratch of m doubles. */
FCCQP_CLONES
static void fccqp_sparse_rank_update(const double *restrict Y, int ld, int rows,
                                     const int *restrict index, const int *restrict count,
                                     int m, double *restrict T, double *restrict values)
{
    for (int j = 0; j < rows; j++) {
        const int *columns = index + (long)j * m;
        for (int k = 0; k < count[j]; k++)
            values[k] = Y[j + (long)columns[k] * ld];
        for (int k = 0; k < count[j]; k++) {
            double y = values[k];
            double *row = T + columns[k];
            for (int l = 0; l <= k; l++) {
                long at = (long)columns[l] * m;
                row[at] = fma(y, values[l], row[at]);
            }
        }
    }
}

/* Zero the entries of T that fccqp_sparse_rank_update wrote for the same rows. */
static void fccqp_sparse_rank_clear(int rows, const int *restrict index,
                                    const int *restrict count, int m, double *restrict T)
{
    for (int j = 0; j < rows; j++) {
        const int *columns = index + (long)j * m;
        for (int k = 0; k < count[j]; k++)
            for (int l = 0; l <= k; l++)
                T[columns[k] + (long)columns[l] * m] = 0.0;
    }
}

/* What fccqp_symmetric_copy and fccqp_checked_copy found: bits of their result */
#define FCCQP_NOT_FINITE 1   /* an entry NaN or infinite (symmetric copy), or beyond the limit */
#define FCCQP_CHANGED 2      /* out did not hold the result already */

/* The checked copy's scalar steps past the vector ones (entries i..k-1), shared by its
 * two-lane and 32-byte kernels: FCCQP_NOT_FINITE beyond limit, FCCQP_CHANGED where out
 * held another value. */
static inline __attribute__((always_inline)) int fccqp_checked_tail(
    const double *restrict v, long i, long k, double limit, double *restrict out)
{
    int found = 0;
    for (; i < k; i++) {
        if (!(fabs(v[i]) <= limit))
            found |= FCCQP_NOT_FINITE;
        if (out[i] != v[i])
            found |= FCCQP_CHANGED;
        out[i] = v[i];
    }
    return found;
}

/* The symmetric copy's scalar steps, shared by its two-lane and 32-byte kernels: the
 * diagonal entry of row i, and the pairs (i, j), (j, i) from j on past the vector steps
 * (FCCQP_NOT_FINITE, FCCQP_CHANGED as fccqp_symmetric_copy; *asymmetry the running
 * largest |P_ij - P_ji|). */
static inline __attribute__((always_inline)) int fccqp_symmetric_diagonal(
    const double *restrict row, double *restrict out_row, int i)
{
    int found = 0;
    double v = row[i];
    if (!(fabs(v) <= 1.7976931348623157e308))
        found |= FCCQP_NOT_FINITE;
    if (out_row[i] != v)
        found |= FCCQP_CHANGED;
    out_row[i] = v;
    return found;
}

static inline __attribute__((always_inline)) int fccqp_symmetric_tail(
    const double *restrict P, int n, int i, int j, double *restrict out, double *asymmetry)
{
    const double *row = P + (long)i * n;
    double *out_row = out + (long)i * n;
    int found = 0;
    for (; j < n; j++) {
        double u = row[j], l = P[(long)j * n + i], value = 0.5 * (u + l);
        double difference = fabs(u - l);
        if (!(difference <= 1.7976931348623157e308))
            found |= FCCQP_NOT_FINITE;
        *asymmetry = difference > *asymmetry ? difference : *asymmetry;
        if (out_row[j] != value)
            found |= FCCQP_CHANGED;
        out_row[j] = value;
        out[(long)j * n + i] = value;
    }
    return found;
}

/* out = (P + P') / 2 for a row-major n x n P; sizes[0] becomes the largest |entry| and
 * sizes[1] the largest |P_ij - P_ji|. FCCQP_NOT_FINITE flags an entry NaN or infinite,
 * or a pair whose difference is not finite (both beyond 1e308). out is symmetric on
 * entry, as this pass leaves it, so FCCQP_CHANGED compares its upper triangle.
 *
 * Two passes: the largest entry in memory order, then the pairs (i, j), (j, i) over the
 * upper triangle, four pairs to a step. P is the caller's array, often not in cache,
 * and the pairs read it down columns, a cache line per entry, which the prefetchers do
 * not follow; the first pass reads it in the order they do, so that the pairs find it
 * in cache (go2's 54 x 54 P from L3: 4-5 us, against 8-10 us for the pairs' pass
 * alone; notes/performance-history.md, "wallgap"). */
static int fccqp_symmetric_copy(const double *restrict P, int n, double *restrict out,
                                double sizes[2])
{
    fccqp_v4 half = fccqp_splat4(0.5), largest = fccqp_splat4(0.0), asymmetry = largest;
    fccqp_flags4 not_finite = fccqp_no_flags4(), changed = not_finite;
    double largest_1 = 0.0, asymmetry_1 = 0.0;
    int found = 0;
    long k = 0, entries = (long)n * n;
    for (; k + 4 <= entries; k += 4)
        largest = fccqp_max4(largest, fccqp_abs4(fccqp_load4(P + k)));
    for (; k < entries; k++)
        largest_1 = fabs(P[k]) > largest_1 ? fabs(P[k]) : largest_1;
    for (int i = 0; i < n; i++) {
        const double *row = P + (long)i * n;
        double *out_row = out + (long)i * n;
        found |= fccqp_symmetric_diagonal(row, out_row, i);
        int j = i + 1;
        for (; j + 4 <= n; j += 4) {
            const double *column = P + (long)j * n + i;
            fccqp_v4 upper = fccqp_load4(row + j);
            fccqp_v4 lower = fccqp_set4(column[0], column[n], column[2 * (long)n],
                                        column[3 * (long)n]);
            fccqp_v4 difference = fccqp_abs4(fccqp_sub4(upper, lower));
            fccqp_v4 value = fccqp_mul4(half, fccqp_add4(upper, lower));
            not_finite = fccqp_flag_beyond4(not_finite, difference, 1.7976931348623157e308);
            asymmetry = fccqp_max4(asymmetry, difference);
            changed = fccqp_flag_unequal4(changed, fccqp_load4(out_row + j), value);
            fccqp_store4(out_row + j, value);
            double *mirror = out + (long)j * n + i;
            mirror[0] = FCCQP_LANE(value, 0);
            mirror[n] = FCCQP_LANE(value, 1);
            mirror[2 * (long)n] = FCCQP_LANE(value, 2);
            mirror[3 * (long)n] = FCCQP_LANE(value, 3);
        }
        found |= fccqp_symmetric_tail(P, n, i, j, out, &asymmetry_1);
    }
    sizes[0] = fccqp_largest4(largest, largest_1);
    sizes[1] = fccqp_largest4(asymmetry, asymmetry_1);
    return found | (fccqp_any4(not_finite) ? FCCQP_NOT_FINITE : 0)
           | (fccqp_any4(changed) ? FCCQP_CHANGED : 0);
}

/* out = v for k entries; FCCQP_NOT_FINITE where an entry is not within [-limit, limit]
 * (NaN, infinite or too large), FCCQP_CHANGED where out did not hold v */
static int fccqp_checked_copy(const double *restrict v, long k, double limit,
                              double *restrict out)
{
    fccqp_flags4 beyond = fccqp_no_flags4(), changed = beyond;
    int found = 0;
    long i = 0;
    for (; i + 4 <= k; i += 4) {
        fccqp_v4 value = fccqp_load4(v + i);
        beyond = fccqp_flag_beyond4(beyond, fccqp_abs4(value), limit);
        changed = fccqp_flag_unequal4(changed, fccqp_load4(out + i), value);
        fccqp_store4(out + i, value);
    }
    found |= fccqp_checked_tail(v, i, k, limit, out);
    return found | (fccqp_any4(beyond) ? FCCQP_NOT_FINITE : 0)
           | (fccqp_any4(changed) ? FCCQP_CHANGED : 0);
}

/* out = diag(left) M diag(right) for a row-major rows x cols M (out aliases nothing);
 * row_max[i] = max_j |out_ij|, and where column_max is not NULL column_max[j] becomes
 * max(column_max[j], max_i |out_ij|). M, left and right are finite. */
static void fccqp_scale_rows(const double *restrict M, int rows, int cols,
                             const double *restrict left, const double *restrict right,
                             double *restrict out, double *restrict row_max,
                             double *restrict column_max)
{
    for (int i = 0; i < rows; i++) {
        const double *row = M + (long)i * cols;
        double *out_row = out + (long)i * cols;
        fccqp_v4 factor = fccqp_splat4(left[i]), largest = fccqp_splat4(0.0);
        double largest_1 = 0.0;
        int j = 0;
        for (; j + 4 <= cols; j += 4) {
            fccqp_v4 value = fccqp_mul4(fccqp_mul4(fccqp_load4(row + j), factor),
                                        fccqp_load4(right + j));
            fccqp_v4 size = fccqp_abs4(value);
            fccqp_store4(out_row + j, value);
            largest = fccqp_max4(largest, size);
            if (column_max)
                fccqp_store4(column_max + j, fccqp_max4(fccqp_load4(column_max + j), size));
        }
        for (; j < cols; j++) {
            double value = row[j] * left[i] * right[j], size = fabs(value);
            out_row[j] = value;
            largest_1 = size > largest_1 ? size : largest_1;
            if (column_max)
                column_max[j] = size > column_max[j] ? size : column_max[j];
        }
        row_max[i] = fccqp_largest4(largest, largest_1);
    }
}

/* The norms one Ruiz pass reads (fccqp.scaling.equilibrate) off the unscaled row-major P
 * (n x n) and A (m x n) under the scaling D, E so far:
 * column[j] = max(D_j max_i |P_ij| D_i, max_i (|A_ij| D_j) E_i) and
 * row[i] = (max_j |A_ij| D_j) E_i, each product in the order written (the loops this
 * replaces rounded them so). D, E are positive, P and A finite. */
FCCQP_CLONES
static void fccqp_ruiz_maxima(const double *restrict P, const double *restrict A, int n,
                              int m, const double *restrict D, const double *restrict E,
                              double *restrict column, double *restrict row)
{
    for (int j = 0; j < n; j++)
        column[j] = 0.0;
    for (int i = 0; i < n; i++) {   /* column maxima of |P| diag(D), row by row */
        const double *p_row = P + (long)i * n;
        fccqp_v4 weight = fccqp_splat4(D[i]);
        int j = 0;
        for (; j + 4 <= n; j += 4)
            fccqp_store4(column + j, fccqp_max4(fccqp_load4(column + j), fccqp_mul4(
                fccqp_abs4(fccqp_load4(p_row + j)), weight)));
        for (; j < n; j++) {
            double size = fabs(p_row[j]) * D[i];
            column[j] = size > column[j] ? size : column[j];
        }
    }
    for (int j = 0; j < n; j++)
        column[j] *= D[j];
    for (int i = 0; i < m; i++) {
        const double *a_row = A + (long)i * n;
        fccqp_v4 weight = fccqp_splat4(E[i]), largest = fccqp_splat4(0.0);
        double largest_1 = 0.0;
        int j = 0;
        for (; j + 4 <= n; j += 4) {
            fccqp_v4 size = fccqp_mul4(fccqp_abs4(fccqp_load4(a_row + j)), fccqp_load4(D + j));
            largest = fccqp_max4(largest, size);
            fccqp_store4(column + j, fccqp_max4(fccqp_load4(column + j),
                                                fccqp_mul4(size, weight)));
        }
        for (; j < n; j++) {
            double size = fabs(a_row[j]) * D[j], scaled = size * E[i];
            largest_1 = size > largest_1 ? size : largest_1;
            column[j] = scaled > column[j] ? scaled : column[j];
        }
        row[i] = fccqp_largest4(largest, largest_1) * E[i];
    }
}

/* span[i] = sum_j |A_ij| width_j over the entries with A_ij != 0 for a row-major rows x
 * cols A (a zero entry adds nothing even where the width is infinite); fccqp_row_spans
 * picks it or its 32-byte copy */
FCCQP_EXACT_CLONES
static void fccqp_row_spans_halves(const double *restrict A, int rows, int cols,
                                   const double *restrict width, double *restrict span)
{
    for (int i = 0; i < rows; i++) {
        const double *row = A + (long)i * cols;
        fccqp_v4 sum = fccqp_splat4(0.0);
        double sum_1 = 0.0;
        int j = 0;
        for (; j + 4 <= cols; j += 4) {
            fccqp_v4 a = fccqp_load4(row + j);
            sum = fccqp_add4(sum, fccqp_where_nonzero4(
                a, fccqp_mul4(fccqp_abs4(a), fccqp_load4(width + j))));
        }
        for (; j < cols; j++)
            if (row[j] != 0.0)
                sum_1 += fabs(row[j]) * width[j];
        span[i] = fccqp_sum4(sum) + sum_1;
    }
}


#if defined(__GNUC__) || defined(__clang__)
#define FCCQP_FORCE_INLINE static inline __attribute__((always_inline))
#define FCCQP_UNROLL _Pragma("GCC unroll 16")
#else
#define FCCQP_FORCE_INLINE static inline
#define FCCQP_UNROLL
#endif

/* fccqp_spd_solve's body; a constant k (after inlining) lets the compiler unroll it. Each
 * entry of A is read before the entry of M at its place is written: A may be M. */
FCCQP_FORCE_INLINE int fccqp_spd_solve_k(const double *A, int lda, double shift, double *M,
                                         double *restrict b, const int k)
{
    FCCQP_UNROLL
    for (int c = 0; c < k; c++) {
        double pivot = A[c * lda + c] + shift;
        FCCQP_UNROLL
        for (int t = 0; t < c; t++)
            pivot -= M[c * k + t] * M[c * k + t];
        if (!(pivot > 0.0))
            return 0;
        pivot = sqrt(pivot);
        M[c * k + c] = pivot;
        FCCQP_UNROLL
        for (int r = c + 1; r < k; r++) {
            double value = A[r * lda + c];
            FCCQP_UNROLL
            for (int t = 0; t < c; t++)
                value -= M[r * k + t] * M[c * k + t];
            M[r * k + c] = value / pivot;
        }
    }
    FCCQP_UNROLL
    for (int r = 0; r < k; r++) {
        double value = b[r];
        FCCQP_UNROLL
        for (int t = 0; t < r; t++)
            value -= M[r * k + t] * b[t];
        b[r] = value / M[r * k + r];
    }
    FCCQP_UNROLL
    for (int r = k - 1; r >= 0; r--) {
        double value = b[r];
        FCCQP_UNROLL
        for (int t = r + 1; t < k; t++)
            value -= M[t * k + r] * b[t];
        b[r] = value / M[r * k + r];
    }
    return 1;
}

static int fccqp_spd_solve(const double *A, int lda, double shift, double *M,
                           double *restrict b, int k)
{
    switch (k) {
    case 1: return fccqp_spd_solve_k(A, lda, shift, M, b, 1);
    case 2: return fccqp_spd_solve_k(A, lda, shift, M, b, 2);
    case 3: return fccqp_spd_solve_k(A, lda, shift, M, b, 3);
    case 4: return fccqp_spd_solve_k(A, lda, shift, M, b, 4);
    case 5: return fccqp_spd_solve_k(A, lda, shift, M, b, 5);
    case 6: return fccqp_spd_solve_k(A, lda, shift, M, b, 6);
    case 7: return fccqp_spd_solve_k(A, lda, shift, M, b, 7);
    case 8: return fccqp_spd_solve_k(A, lda, shift, M, b, 8);
    case 9: return fccqp_spd_solve_k(A, lda, shift, M, b, 9);
    case 10: return fccqp_spd_solve_k(A, lda, shift, M, b, 10);
    default: return fccqp_spd_solve_k(A, lda, shift, M, b, k);
    }
}

/* Four lanes in one 32-byte vector for Anderson's kernels (GCC / clang vector
 * extensions): one AVX2 instruction each in the AVX2 copy, two SSE2 ones in the
 * baseline (they add, multiply and move, never compare). Elsewhere a struct. */
#if defined(__GNUC__) || defined(__clang__)
typedef double fccqp_d4 __attribute__((vector_size(32)));
FCCQP_LANE_OP fccqp_d4 fccqp_dload(const double *p)
{
    fccqp_d4 v;
    memcpy(&v, p, sizeof v);
    return v;
}
FCCQP_LANE_OP void fccqp_dstore(double *p, fccqp_d4 v) { memcpy(p, &v, sizeof v); }
FCCQP_LANE_OP fccqp_d4 fccqp_dsplat(double x)
{
    fccqp_d4 r = {x, x, x, x};
    return r;
}
FCCQP_LANE_OP fccqp_d4 fccqp_dadd(fccqp_d4 a, fccqp_d4 b) { return a + b; }
FCCQP_LANE_OP fccqp_d4 fccqp_dmul(fccqp_d4 a, fccqp_d4 b) { return a * b; }
FCCQP_LANE_OP double fccqp_dsum(fccqp_d4 v) { return (v[0] + v[1]) + (v[2] + v[3]); }
#else
typedef struct { double lane[4]; } fccqp_d4;
FCCQP_LANE_OP fccqp_d4 fccqp_dload(const double *p) { FCCQP_LANEWISE(fccqp_d4, p[k]) }
FCCQP_LANE_OP void fccqp_dstore(double *p, fccqp_d4 v)
{
    for (int k = 0; k < 4; k++)
        p[k] = v.lane[k];
}
FCCQP_LANE_OP fccqp_d4 fccqp_dsplat(double x) { FCCQP_LANEWISE(fccqp_d4, x) }
FCCQP_LANE_OP fccqp_d4 fccqp_dadd(fccqp_d4 a, fccqp_d4 b) { FCCQP_LANEWISE(fccqp_d4, a.lane[k] + b.lane[k]) }
FCCQP_LANE_OP fccqp_d4 fccqp_dmul(fccqp_d4 a, fccqp_d4 b) { FCCQP_LANEWISE(fccqp_d4, a.lane[k] * b.lane[k]) }
FCCQP_LANE_OP double fccqp_dsum(fccqp_d4 v) { return (v.lane[0] + v.lane[1]) + (v.lane[2] + v.lane[3]); }
#endif


/* fccqp_slot_products for the rows r0 and r1 (out: newest' r0, r0' f, newest' r1, r1' f) */
FCCQP_FORCE_INLINE void fccqp_slot_pair_products(const double *restrict r0,
                                                 const double *restrict r1, long two_s,
                                                 const double *restrict newest,
                                                 const double *restrict f, double out[4])
{
    fccqp_d4 n0 = fccqp_dsplat(0.0), f0 = n0, n1 = n0, f1 = n0;
    long j = 0;
    for (; j + 4 <= two_s; j += 4) {
        fccqp_d4 w = fccqp_dload(newest + j), v = fccqp_dload(f + j);
        fccqp_d4 a = fccqp_dload(r0 + j), b = fccqp_dload(r1 + j);
        n0 = fccqp_dadd(n0, fccqp_dmul(w, a));
        f0 = fccqp_dadd(f0, fccqp_dmul(a, v));
        n1 = fccqp_dadd(n1, fccqp_dmul(w, b));
        f1 = fccqp_dadd(f1, fccqp_dmul(b, v));
    }
    out[0] = fccqp_dsum(n0), out[1] = fccqp_dsum(f0);
    out[2] = fccqp_dsum(n1), out[3] = fccqp_dsum(f1);
    for (; j < two_s; j++) {
        out[0] += newest[j] * r0[j];
        out[1] += r0[j] * f[j];
        out[2] += newest[j] * r1[j];
        out[3] += r1[j] * f[j];
    }
}

FCCQP_EXACT_CLONES
static void fccqp_slot_products(const double *restrict df, long two_s, int stored,
                                const double *restrict newest, const double *restrict f,
                                double *restrict to_new, double *restrict to_f)
{
    double out[4];
    for (int l = 0; l < stored; l += 2) {
        const double *row = df + l * two_s;
        /* an odd last slot is paired with itself */
        fccqp_slot_pair_products(row, l + 1 < stored ? row + two_s : row, two_s, newest, f,
                                 out);
        to_new[l] = out[0], to_f[l] = out[1];
        if (l + 1 < stored)
            to_new[l + 1] = out[2], to_f[l + 1] = out[3];
    }
}

/* fccqp_slot_combination's pass over count (1 to 4, constant once inlined) slots:
 * four entries at a time in lanes, each entry's terms added in slot order */
FCCQP_FORCE_INLINE void fccqp_add_slots(double *restrict out, const double *restrict rows,
                                        long two_s, const double *restrict coefficient,
                                        const int count)
{
    long j = 0;
    for (; j + 4 <= two_s; j += 4) {
        fccqp_d4 value = fccqp_dload(out + j);
        FCCQP_UNROLL
        for (int i = 0; i < count; i++)
            value = fccqp_dadd(value, fccqp_dmul(fccqp_dload(rows + i * two_s + j),
                                                 fccqp_dsplat(coefficient[i])));
        fccqp_dstore(out + j, value);
    }
    for (; j < two_s; j++) {
        double value = out[j];
        FCCQP_UNROLL
        for (int i = 0; i < count; i++)
            value += rows[i * two_s + j] * coefficient[i];
        out[j] = value;
    }
}

FCCQP_EXACT_CLONES
static void fccqp_slot_combination(const double *restrict rows, long two_s, int stored,
                                   const double *restrict coefficient, double *restrict out)
{
    for (long j = 0; j < two_s; j++)
        out[j] = 0.0;
    for (int l = 0; l < stored; l += 4) {
        const double *first = rows + l * two_s;
        switch (stored - l) {
        case 1: fccqp_add_slots(out, first, two_s, coefficient + l, 1); break;
        case 2: fccqp_add_slots(out, first, two_s, coefficient + l, 2); break;
        case 3: fccqp_add_slots(out, first, two_s, coefficient + l, 3); break;
        default: fccqp_add_slots(out, first, two_s, coefficient + l, 4);
        }
    }
}

/* Anderson's point after an ADMM step (s entries of z, of y): g = (z_prev, y_prev / rho)
 * and f = (z, y / rho) - g */
FCCQP_EXACT_CLONES
static void fccqp_fixed_point_residual(const double *restrict z_prev,
                                       const double *restrict y_prev,
                                       const double *restrict z, const double *restrict y,
                                       const double *restrict rho, long s,
                                       double *restrict g, double *restrict f)
{
    for (long j = 0; j < s; j++) {
        g[j] = z_prev[j];
        f[j] = z[j] - z_prev[j];
    }
    for (long j = 0; j < s; j++) {
        g[s + j] = y_prev[j] / rho[j];
        f[s + j] = y[j] / rho[j] - g[s + j];
    }
}

/* Anderson's differences between two points: df = f_new - f, dgf = (g_new - g) + df */
FCCQP_EXACT_CLONES
static void fccqp_point_differences(const double *restrict g_new,
                                    const double *restrict f_new, const double *restrict g,
                                    const double *restrict f, long two_s,
                                    double *restrict df, double *restrict dgf)
{
    for (long j = 0; j < two_s; j++) {
        double difference = f_new[j] - f[j];
        df[j] = difference;
        dgf[j] = (g_new[j] - g[j]) + difference;
    }
}

/* Anderson's extrapolation: plain = (z, y / rho), then (z, y) -= (step_z, step_y rho) */
FCCQP_EXACT_CLONES
static void fccqp_extrapolate(double *restrict z, double *restrict y,
                              const double *restrict rho, const double *restrict step,
                              long s, double *restrict plain)
{
    for (long j = 0; j < s; j++) {
        plain[j] = z[j];
        z[j] -= step[j];
    }
    for (long j = 0; j < s; j++) {
        plain[s + j] = y[j] / rho[j];
        y[j] -= step[s + j] * rho[j];
    }
}

/* v'v in four lanes (as fccqp_slot_pair_products sums) */
FCCQP_EXACT_CLONES
static double fccqp_sum_squares(const double *restrict v, long k)
{
    fccqp_d4 lanes = fccqp_dsplat(0.0);
    long j = 0;
    for (; j + 4 <= k; j += 4) {
        fccqp_d4 x = fccqp_dload(v + j);
        lanes = fccqp_dadd(lanes, fccqp_dmul(x, x));
    }
    double total = fccqp_dsum(lanes);
    for (; j < k; j++)
        total += v[j] * v[j];
    return total;
}

/* polish_schur's kernel.
 *
 * fccqp_trsm_lower: B := L^-1 B for the column-major lower n x n L (leading dimension
 * ld) and cols columns of B (leading dimension ldb), each column by
 * _blas.forward_substitution's steps (four pivots solved, then their four subtractions
 * from each entry below, in that order), four pivots at a time for every column, so
 * that their reciprocals and the block's entries are loaded once. go2 (callgrind, a
 * call): polish_schur_setup's 18 x 18 L and 30 columns 12.7k instructions against
 * dtrsm's 21.5k (most of it packing and set-up), the base's 30 x 30 S0 and 3-12
 * columns 4.5k against 10.5k.
 */
FCCQP_CLONES
static void fccqp_trsm_lower(const double *restrict L, int n, int ld, double *restrict B,
                             int cols, int ldb)
{
    int k = 0;
    for (; k + 4 <= n; k += 4) {
        const double *c0 = L + (long)k * ld, *c1 = c0 + ld, *c2 = c1 + ld, *c3 = c2 + ld;
        double r0 = 1.0 / c0[k], r1 = 1.0 / c1[k + 1], r2 = 1.0 / c2[k + 2];
        double r3 = 1.0 / c3[k + 3];
        for (int c = 0; c < cols; c++) {
            double *b = B + (long)c * ldb;
            double v0 = b[k] * r0;
            double b1 = b[k + 1] - c0[k + 1] * v0;
            double b2 = b[k + 2] - c0[k + 2] * v0;
            double b3 = b[k + 3] - c0[k + 3] * v0;
            double v1 = b1 * r1;
            b2 = b2 - c1[k + 2] * v1;
            b3 = b3 - c1[k + 3] * v1;
            double v2 = b2 * r2;
            b3 = b3 - c2[k + 3] * v2;
            double v3 = b3 * r3;
            b[k] = v0, b[k + 1] = v1, b[k + 2] = v2, b[k + 3] = v3;
            for (int i = k + 4; i < n; i++)
                b[i] = b[i] - c0[i] * v0 - c1[i] * v1 - c2[i] * v2 - c3[i] * v3;
        }
    }
    for (; k < n; k++) {
        const double *c0 = L + (long)k * ld;
        double r0 = 1.0 / c0[k];
        for (int c = 0; c < cols; c++) {
            double *b = B + (long)c * ldb;
            double v0 = b[k] * r0;
            b[k] = v0;
            for (int i = k + 1; i < n; i++)
                b[i] -= c0[i] * v0;
        }
    }
}

/* Every solve's passes over the caller's data, in one 32-byte vector of four lanes where
 * the CPU has AVX2, picked at each call: the validation scan's (fccqp_scan_symmetric,
 * fccqp_scan_copy for fccqp_symmetric_copy, fccqp_checked_copy) and the rescaling's
 * (fccqp_rescale_rows, fccqp_rescale_multiply for fccqp_scale_rows and a product by the
 * cost's factor) and the rows' spans (fccqp_row_spans for fccqp_row_spans_halves: 9.9k
 * -> 6.3k a go2 tick). The same operations lane by lane as the two-halves kernels, and none
 * that a compiler may fuse (target "avx2" has no FMA), so the same bits and flags: only
 * the instruction count differs. The halves in an AVX2 clone (target_clones) keep two
 * 16-byte operations and their moves a step. Per go2 warm tick (callgrind, 100 ticks):
 * the scan 46.4k instructions in the baseline copy, 35.5k in the clone of the halves and
 * 24.8k here; the rescaling 31.9k, 25.2k and 16.6k (notes/performance-history.md,
 * "scan"). */
#if defined(__x86_64__) && (defined(__GNUC__) || defined(__clang__))
#include <immintrin.h>
#define FCCQP_WIDE_SCAN 1
#define FCCQP_WIDE static inline __attribute__((target("avx2"), always_inline))

FCCQP_WIDE __m256d fccqp_wide_abs(__m256d x)
{
    return _mm256_and_pd(x, _mm256_castsi256_pd(_mm256_set1_epi64x(0x7fffffffffffffffLL)));
}

/* max(x, lanes of v), v never NaN */
FCCQP_WIDE double fccqp_wide_largest(__m256d v, double x)
{
    double lanes[4];
    _mm256_storeu_pd(lanes, v);
    for (int k = 0; k < 4; k++)
        x = lanes[k] > x ? lanes[k] : x;
    return x;
}

/* The pairs (i, j), (j, i) of row i from j = i + 1 while four remain, for
 * fccqp_symmetric_copy_wide; returns the j past them. With compare, the result is also
 * compared with what out held (*changed); once a change was found the caller's later rows
 * skip that comparison, a load, compare and or of a step's 30 instructions (a control
 * loop's P changes every tick). */
FCCQP_WIDE int fccqp_wide_pairs(const double *restrict P, int n, int i, double *restrict out,
                                __m256d *not_finite, __m256d *asymmetry, __m256d *changed,
                                const int compare)
{
    const __m256d half = _mm256_set1_pd(0.5), limit = _mm256_set1_pd(1.7976931348623157e308);
    const double *row = P + (long)i * n;
    double *out_row = out + (long)i * n;
    long stride = n, step = 4 * (long)n;
    int j = i + 1;
    const double *column = P + (long)j * n + i;
    double *mirror = out + (long)j * n + i;
    for (; j + 4 <= n; j += 4, column += step, mirror += step) {
        __m256d upper = _mm256_loadu_pd(row + j);
        __m256d lower = _mm256_set_pd(column[3 * stride], column[2 * stride], column[stride],
                                      column[0]);
        __m256d difference = fccqp_wide_abs(_mm256_sub_pd(upper, lower));
        __m256d value = _mm256_mul_pd(half, _mm256_add_pd(upper, lower));
        *not_finite = _mm256_or_pd(*not_finite, _mm256_cmp_pd(difference, limit, _CMP_NLE_UQ));
        *asymmetry = _mm256_max_pd(difference, *asymmetry);
        if (compare)
            *changed = _mm256_or_pd(*changed, _mm256_cmp_pd(_mm256_loadu_pd(out_row + j), value,
                                                            _CMP_NEQ_UQ));
        _mm256_storeu_pd(out_row + j, value);
        __m128d low = _mm256_castpd256_pd128(value), high = _mm256_extractf128_pd(value, 1);
        _mm_storel_pd(mirror, low);
        _mm_storeh_pd(mirror + stride, low);
        _mm_storel_pd(mirror + 2 * stride, high);
        _mm_storeh_pd(mirror + 3 * stride, high);
    }
    return j;
}

/* fccqp_symmetric_copy in 32-byte vectors; the mirror's column is walked by pointers */
__attribute__((target("avx2")))
static int fccqp_symmetric_copy_wide(const double *restrict P, int n, double *restrict out,
                                     double sizes[2])
{
    __m256d largest = _mm256_setzero_pd(), largest_b = largest, asymmetry = largest;
    __m256d not_finite = largest, changed = largest;
    double largest_1 = 0.0, asymmetry_1 = 0.0;
    int found = 0;
    long k = 0, entries = (long)n * n;
    for (; k + 8 <= entries; k += 8) {   /* two accumulators: one max a cycle */
        largest = _mm256_max_pd(fccqp_wide_abs(_mm256_loadu_pd(P + k)), largest);
        largest_b = _mm256_max_pd(fccqp_wide_abs(_mm256_loadu_pd(P + k + 4)), largest_b);
    }
    for (; k + 4 <= entries; k += 4)
        largest = _mm256_max_pd(fccqp_wide_abs(_mm256_loadu_pd(P + k)), largest);
    for (; k < entries; k++)
        largest_1 = fabs(P[k]) > largest_1 ? fabs(P[k]) : largest_1;
    largest = _mm256_max_pd(largest_b, largest);
    for (int i = 0; i < n; i++) {
        int j;
        found |= fccqp_symmetric_diagonal(P + (long)i * n, out + (long)i * n, i);
        if (found & FCCQP_CHANGED || _mm256_movemask_pd(changed))
            j = fccqp_wide_pairs(P, n, i, out, &not_finite, &asymmetry, &changed, 0);
        else
            j = fccqp_wide_pairs(P, n, i, out, &not_finite, &asymmetry, &changed, 1);
        found |= fccqp_symmetric_tail(P, n, i, j, out, &asymmetry_1);
    }
    sizes[0] = fccqp_wide_largest(largest, largest_1);
    sizes[1] = fccqp_wide_largest(asymmetry, asymmetry_1);
    return found | (_mm256_movemask_pd(not_finite) ? FCCQP_NOT_FINITE : 0)
           | (_mm256_movemask_pd(changed) ? FCCQP_CHANGED : 0);
}

/* fccqp_checked_copy in 32-byte vectors; out's old values are compared with v until a
 * change is found (tested every FCCQP_COMPARED entries), then only copied */
#define FCCQP_COMPARED 64
__attribute__((target("avx2")))
static int fccqp_checked_copy_wide(const double *restrict v, long k, double limit,
                                   double *restrict out)
{
    const __m256d bound = _mm256_set1_pd(limit);
    __m256d beyond = _mm256_setzero_pd(), changed = beyond;
    int found = 0;
    long i = 0;
    while (i + 4 <= k && !_mm256_movemask_pd(changed)) {
        long end = i + FCCQP_COMPARED < k ? i + FCCQP_COMPARED : k;
        for (; i + 4 <= end; i += 4) {
            __m256d value = _mm256_loadu_pd(v + i);
            beyond = _mm256_or_pd(beyond, _mm256_cmp_pd(fccqp_wide_abs(value), bound,
                                                        _CMP_NLE_UQ));
            changed = _mm256_or_pd(changed, _mm256_cmp_pd(_mm256_loadu_pd(out + i), value,
                                                          _CMP_NEQ_UQ));
            _mm256_storeu_pd(out + i, value);
        }
    }
    for (; i + 4 <= k; i += 4) {
        __m256d value = _mm256_loadu_pd(v + i);
        beyond = _mm256_or_pd(beyond, _mm256_cmp_pd(fccqp_wide_abs(value), bound, _CMP_NLE_UQ));
        _mm256_storeu_pd(out + i, value);
    }
    found |= fccqp_checked_tail(v, i, k, limit, out);
    return found | (_mm256_movemask_pd(beyond) ? FCCQP_NOT_FINITE : 0)
           | (_mm256_movemask_pd(changed) ? FCCQP_CHANGED : 0);
}

/* fccqp_scale_rows in 32-byte vectors */
__attribute__((target("avx2")))
static void fccqp_scale_rows_wide(const double *restrict M, int rows, int cols,
                                  const double *restrict left, const double *restrict right,
                                  double *restrict out, double *restrict row_max,
                                  double *restrict column_max)
{
    for (int i = 0; i < rows; i++) {
        const double *row = M + (long)i * cols;
        double *out_row = out + (long)i * cols;
        __m256d factor = _mm256_set1_pd(left[i]), largest = _mm256_setzero_pd();
        double largest_1 = 0.0;
        int j = 0;
        for (; j + 4 <= cols; j += 4) {
            __m256d value = _mm256_mul_pd(_mm256_mul_pd(_mm256_loadu_pd(row + j), factor),
                                          _mm256_loadu_pd(right + j));
            __m256d size = fccqp_wide_abs(value);
            _mm256_storeu_pd(out_row + j, value);
            largest = _mm256_max_pd(size, largest);
            if (column_max)
                _mm256_storeu_pd(column_max + j,
                                 _mm256_max_pd(size, _mm256_loadu_pd(column_max + j)));
        }
        for (; j < cols; j++) {
            double value = row[j] * left[i] * right[j], size = fabs(value);
            out_row[j] = value;
            largest_1 = size > largest_1 ? size : largest_1;
            if (column_max)
                column_max[j] = size > column_max[j] ? size : column_max[j];
        }
        row_max[i] = fccqp_wide_largest(largest, largest_1);
    }
}

/* fccqp_row_spans_halves in 32-byte vectors */
__attribute__((target("avx2")))
static void fccqp_row_spans_wide(const double *restrict A, int rows, int cols,
                                 const double *restrict width, double *restrict span)
{
    const __m256d zero = _mm256_setzero_pd();
    double lanes[4];
    for (int i = 0; i < rows; i++) {
        const double *row = A + (long)i * cols;
        __m256d sum = zero;
        double sum_1 = 0.0;
        int j = 0;
        for (; j + 4 <= cols; j += 4) {
            __m256d a = _mm256_loadu_pd(row + j);
            __m256d term = _mm256_mul_pd(fccqp_wide_abs(a), _mm256_loadu_pd(width + j));
            sum = _mm256_add_pd(sum, _mm256_and_pd(term, _mm256_cmp_pd(a, zero, _CMP_NEQ_UQ)));
        }
        for (; j < cols; j++)
            if (row[j] != 0.0)
                sum_1 += fabs(row[j]) * width[j];
        _mm256_storeu_pd(lanes, sum);
        span[i] = ((lanes[0] + lanes[1]) + (lanes[2] + lanes[3])) + sum_1;
    }
}

/* v *= factor for k entries, in 32-byte vectors */
__attribute__((target("avx2")))
static void fccqp_multiply_wide(double *restrict v, long k, double factor)
{
    __m256d f = _mm256_set1_pd(factor);
    long i = 0;
    for (; i + 4 <= k; i += 4)
        _mm256_storeu_pd(v + i, _mm256_mul_pd(_mm256_loadu_pd(v + i), f));
    for (; i < k; i++)
        v[i] *= factor;
}
#endif

/* fccqp_scale_rows, in 32-byte vectors where the CPU has AVX2 */
static inline void fccqp_rescale_rows(const double *M, int rows, int cols, const double *left,
                                      const double *right, double *out, double *row_max,
                                      double *column_max)
{
#ifdef FCCQP_WIDE_SCAN
    if (__builtin_cpu_supports("avx2")) {
        fccqp_scale_rows_wide(M, rows, cols, left, right, out, row_max, column_max);
        return;
    }
#endif
    fccqp_scale_rows(M, rows, cols, left, right, out, row_max, column_max);
}

/* v *= factor for k entries, in 32-byte vectors where the CPU has AVX2 */
static inline void fccqp_rescale_multiply(double *v, long k, double factor)
{
#ifdef FCCQP_WIDE_SCAN
    if (__builtin_cpu_supports("avx2")) {
        fccqp_multiply_wide(v, k, factor);
        return;
    }
#endif
    for (long i = 0; i < k; i++)
        v[i] *= factor;
}

/* span[i] = sum_j |A_ij| width_j over the entries with A_ij != 0 (fccqp_row_spans_halves),
 * in 32-byte vectors where the CPU has AVX2 */
static inline void fccqp_row_spans(const double *A, int rows, int cols, const double *width,
                                   double *span)
{
#ifdef FCCQP_WIDE_SCAN
    if (__builtin_cpu_supports("avx2")) {
        fccqp_row_spans_wide(A, rows, cols, width, span);
        return;
    }
#endif
    fccqp_row_spans_halves(A, rows, cols, width, span);
}

/* fccqp_symmetric_copy, in 32-byte vectors where the CPU has AVX2 */
static inline int fccqp_scan_symmetric(const double *P, int n, double *out, double sizes[2])
{
#ifdef FCCQP_WIDE_SCAN
    if (__builtin_cpu_supports("avx2"))
        return fccqp_symmetric_copy_wide(P, n, out, sizes);
#endif
    return fccqp_symmetric_copy(P, n, out, sizes);
}

/* fccqp_checked_copy, in 32-byte vectors where the CPU has AVX2 */
static inline int fccqp_scan_copy(const double *v, long k, double limit, double *out)
{
#ifdef FCCQP_WIDE_SCAN
    if (__builtin_cpu_supports("avx2"))
        return fccqp_checked_copy_wide(v, k, limit, out);
#endif
    return fccqp_checked_copy(v, k, limit, out);
}

/* The table polish's solve with its LU factor (polish_table.pyx).
 *
 * fccqp_lu_solve: b := A^-1 b from fccqp_lu's (or dgetrf's) factor of the column-major
 * n x n A, its pivots 1-based: the rows' interchanges in order, then L y = b (L unit
 * lower) and U x = y, each four pivots per pass over the entries left (one load and
 * store of each for four columns of the factor), the columns contiguous. It replaces
 * dgetrs, which took 6.1k instructions a call on go2's 24-28 rows through OpenBLAS'
 * level-2 driver (dtrsv, daxpy; callgrind, go2 realtime cold cell).
 */
FCCQP_CLONES
static void fccqp_lu_solve(const double *restrict T, int n, const int *restrict piv,
                           double *restrict b)
{
    for (int k = 0; k < n; k++) {
        int r = piv[k] - 1;
        if (r != k) {
            double value = b[k];
            b[k] = b[r];
            b[r] = value;
        }
    }
    int k = 0;
    for (; k + 4 <= n; k += 4) {   /* L y = b */
        const double *c0 = T + (long)k * n, *c1 = c0 + n, *c2 = c1 + n, *c3 = c2 + n;
        double v0 = b[k];
        double v1 = b[k + 1] - c0[k + 1] * v0;
        double v2 = b[k + 2] - c0[k + 2] * v0 - c1[k + 2] * v1;
        double v3 = b[k + 3] - c0[k + 3] * v0 - c1[k + 3] * v1 - c2[k + 3] * v2;
        b[k + 1] = v1, b[k + 2] = v2, b[k + 3] = v3;
        for (int i = k + 4; i < n; i++)
            b[i] = b[i] - c0[i] * v0 - c1[i] * v1 - c2[i] * v2 - c3[i] * v3;
    }
    for (; k < n; k++) {
        const double *c0 = T + (long)k * n;
        for (int i = k + 1; i < n; i++)
            b[i] -= c0[i] * b[k];
    }
    for (k = n; k >= 4; k -= 4) {   /* U x = y, columns k - 4 .. k - 1 */
        const double *c0 = T + (long)(k - 4) * n, *c1 = c0 + n, *c2 = c1 + n, *c3 = c2 + n;
        double v3 = b[k - 1] / c3[k - 1];
        double v2 = (b[k - 2] - c3[k - 2] * v3) / c2[k - 2];
        double v1 = (b[k - 3] - c3[k - 3] * v3 - c2[k - 3] * v2) / c1[k - 3];
        double v0 = (b[k - 4] - c3[k - 4] * v3 - c2[k - 4] * v2 - c1[k - 4] * v1) / c0[k - 4];
        b[k - 4] = v0, b[k - 3] = v1, b[k - 2] = v2, b[k - 1] = v3;
        for (int i = 0; i < k - 4; i++)
            b[i] = b[i] - c0[i] * v0 - c1[i] * v1 - c2[i] * v2 - c3[i] * v3;
    }
    for (; k > 0; k--) {
        const double *c0 = T + (long)(k - 1) * n;
        b[k - 1] /= c0[k - 1];
        for (int i = 0; i < k - 1; i++)
            b[i] -= c0[i] * b[k - 1];
    }
}

/* fccqp_syrk_lower: the lower triangle of C = A' A + beta C for a column-major k x n A
 * (leading dimension lda) and n x n C (ldc), beta 0 (C not read) or any other; A and C do
 * not overlap. Entry (a, b) is the dot product of columns a and b: row r of them in lane
 * r mod 4 of a 32-byte vector, fused multiply-adds in row order from 0.0 (the last k mod
 * 4 rows through a masked load), the lanes summed (0 + 1) + (2 + 3), then beta C added:
 * its bits depend on the two columns only, wherever the entry sits among the tiles.
 * Tiles of 4 x 3 entries (12 accumulators, the three columns' vectors and one of the
 * four others: the 16 ymm registers), a column's four sums reduced together by two
 * horizontal additions and a lane swap, stored as four adjacent entries of C; the first
 * tile of a block of three columns starts at its diagonal, whose entries above are
 * stored back unchanged.
 * Natively (AMD Zen 4, one thread, /tmp/gemm/bench2.c: CPU time per call, best of 60
 * batches) against scipy's OpenBLAS dsyrk, which runs its SkylakeX kernels and packs A
 * on every call: go2's 30 x 30 from 30 rows 0.88 against 2.10 us, from 14 rows 0.62
 * against 1.07; talos' 68 x 68 from 68 rows 6.9 against 12.1, from 27 3.9 against 5.1;
 * polish_schur's W'W (3-12 columns of 30 rows) 26-191 ns against 183-523 (its earlier
 * loop of dot products in 4 x 2 tiles with scalar reductions: 40-235). In 4 x 4 tiles
 * (spills) 0.77-1.08x dsyrk's time, in 4 x 2 0.57-0.97x. A tile's fixed cost (three
 * reductions, stores: about 30 cycles) does not shrink with k, while dsyrk's time does:
 * order 68 breaks even from 4 rows, 96 from 8, 128 from 14, 160 from 16, so the kernel
 * declines (returns 0) below n / FCCQP_SYRK_ORDER_PER_ROW rows, and _blas.syrk_t calls it
 * up to order tuning.SYRK_LOOP_ORDER (notes/tuning.md). It returns 0 as well where the
 * CPU lacks AVX2 or FMA: the caller goes to dsyrk. */
#if defined(__x86_64__) && (defined(__GNUC__) || defined(__clang__))
#include <immintrin.h>
#define FCCQP_SYRK_COLUMNS 3
#define FCCQP_SYRK_ORDER_PER_ROW 8
#define FCCQP_L3 static inline __attribute__((target("avx2,fma"), always_inline))

/* lanes 0 .. r - 1 set (all for r >= 4, none for r <= 0) */
FCCQP_L3 __m256i fccqp_first_lanes(long r)
{
    return _mm256_cmpgt_epi64(_mm256_set1_epi64x(r), _mm256_setr_epi64x(0, 1, 2, 3));
}

/* the lane sums (0 + 1) + (2 + 3) of a0 .. a3, in that order in one vector */
FCCQP_L3 __m256d fccqp_lane_sums(__m256d a0, __m256d a1, __m256d a2, __m256d a3)
{
    __m256d t0 = _mm256_hadd_pd(a0, a1), t1 = _mm256_hadd_pd(a2, a3);
    return _mm256_add_pd(_mm256_permute2f128_pd(t0, t1, 0x20),
                         _mm256_permute2f128_pd(t0, t1, 0x31));
}

/* s + beta old (beta 0: s) */
FCCQP_L3 __m256d fccqp_plus_beta(__m256d s, __m256d old, double beta)
{
    if (beta == 1.0)
        return _mm256_add_pd(old, s);
    return _mm256_add_pd(_mm256_mul_pd(_mm256_set1_pd(beta), old), s);
}

/* C[i + r, j + c] for r < 4, c < FCCQP_SYRK_COLUMNS, the entries with i + r < n and
 * i + r >= j + c; a column or row past n is read as column i or j, its sums dropped */
FCCQP_L3 void fccqp_syrk_tile(const double *A, long lda, int i, int j, int n, int k,
                              double beta, double *C, long ldc)
{
    enum { J = FCCQP_SYRK_COLUMNS };
    const double *a[4], *b[J];
    __m256d acc[4][J];
    for (int r = 0; r < 4; r++)
        a[r] = A + (i + r < n ? i + r : i) * lda;
    for (int c = 0; c < J; c++)
        b[c] = A + (j + c < n ? j + c : j) * lda;
    for (int r = 0; r < 4; r++)
        for (int c = 0; c < J; c++)
            acc[r][c] = _mm256_setzero_pd();
    int l = 0;
    for (; l + 4 <= k; l += 4) {
        __m256d y[J];
        for (int c = 0; c < J; c++)
            y[c] = _mm256_loadu_pd(b[c] + l);
        for (int r = 0; r < 4; r++) {
            __m256d x = _mm256_loadu_pd(a[r] + l);
            for (int c = 0; c < J; c++)
                acc[r][c] = _mm256_fmadd_pd(x, y[c], acc[r][c]);
        }
    }
    if (l < k) {
        __m256i rows = fccqp_first_lanes(k - l);
        __m256d y[J];
        for (int c = 0; c < J; c++)
            y[c] = _mm256_maskload_pd(b[c] + l, rows);
        for (int r = 0; r < 4; r++) {
            __m256d x = _mm256_maskload_pd(a[r] + l, rows);
            for (int c = 0; c < J; c++)
                acc[r][c] = _mm256_fmadd_pd(x, y[c], acc[r][c]);
        }
    }
    __m256i index = _mm256_setr_epi64x(i, i + 1, i + 2, i + 3);
    __m256i inside = _mm256_cmpgt_epi64(_mm256_set1_epi64x(n), index);
    for (int c = 0; c < J && j + c < n; c++) {
        double *out = C + i + (j + c) * ldc;
        __m256d s = fccqp_lane_sums(acc[0][c], acc[1][c], acc[2][c], acc[3][c]);
        __m256i above = _mm256_cmpgt_epi64(_mm256_set1_epi64x(j + c), index);
        if (i + 4 <= n) {   /* four rows of C: stored whole, those above the diagonal as read */
            __m256d old = i >= j + c && beta == 0.0 ? s : _mm256_loadu_pd(out);
            if (beta != 0.0)
                s = fccqp_plus_beta(s, old, beta);
            if (i < j + c)
                s = _mm256_blendv_pd(s, old, _mm256_castsi256_pd(above));
            _mm256_storeu_pd(out, s);
        } else {   /* the last rows of C, one at a time: vmaskmovpd's store is slow on AMD */
            __m256i keep = _mm256_andnot_si256(above, inside);
            double lanes[4];
            long long kept[4];
            if (beta != 0.0)
                s = fccqp_plus_beta(s, _mm256_maskload_pd(out, keep), beta);
            _mm256_storeu_pd(lanes, s);
            _mm256_storeu_si256((__m256i *)kept, keep);
            for (int r = 0; r < 4; r++)
                if (kept[r])
                    out[r] = lanes[r];
        }
    }
}

__attribute__((target("avx2,fma")))
static void fccqp_syrk_wide(int n, int k, const double *A, int lda, double beta, double *C,
                            int ldc)
{
    for (int j = 0; j < n; j += FCCQP_SYRK_COLUMNS)
        for (int i = j; i < n; i += 4)
            fccqp_syrk_tile(A, lda, i, j, n, k, beta, C, ldc);
}

static inline int fccqp_syrk_lower(int n, int k, const double *A, int lda, double beta,
                                   double *C, int ldc)
{
    if (n > FCCQP_SYRK_ORDER_PER_ROW * k
        || !(__builtin_cpu_supports("avx2") && __builtin_cpu_supports("fma")))
        return 0;
    fccqp_syrk_wide(n, k, A, lda, beta, C, ldc);
    return 1;
}
#else
static inline int fccqp_syrk_lower(int n, int k, const double *A, int lda, double beta,
                                   double *C, int ldc)
{
    (void)n, (void)k, (void)A, (void)lda, (void)beta, (void)C, (void)ldc;
    return 0;
}
#endif

/* Triangular solves with many right-hand sides for _blas.trsm and _blas.cholesky_solve:
 * fccqp_trsm_left(trans, L, n, ld, B, cols, ldb) is B := L^-1 B (trans 'N') or L'^-1 B
 * ('T') for the column-major lower n x n L (leading dimension ld) and the n x cols B
 * (leading dimension ldb). At the Schur backend's sizes (go2: 18 and 30 rows, 24-30
 * columns; talos: 38 and 68 rows, 56-68 columns) OpenBLAS' dtrsm spends most of its
 * time packing L and B, and natively runs SkylakeX's generic-C trsm kernels around its
 * dgemm kernel (8-11 % of a cold go2 tick's samples with their copies,
 * notes/performance-history.md, "coldwall"); one column at a time through the
 * substitution loops lost to it (wall 1.011): an entry of L has to serve several
 * columns of B from a register.
 *
 * Where the CPU has AVX2 and FMA (picked at each call), both solves are left-looking,
 * in blocks of rows whose triangle is solved in registers (fccqp_triangle):
 * - L^-1 B: blocks of eight rows (two vectors; the n % 8 rows first) by four columns,
 *   eight accumulators of fused multiply-adds over the solved rows above, a column of
 *   L loaded once for the four columns of B (a broadcast of each solved entry).
 * - L'^-1 B: blocks of four rows from the bottom (the n % 4 rows last) by two columns,
 *   each entry's sum over the solved rows below a dot product of a column of L with a
 *   column of B in four lanes (contiguous loads), the lanes added (0 + 1) + (2 + 3).
 * Every column of B goes through the same operations whatever the others, so its
 * result does not depend on the number of columns solved with it. Natively (Zen 4, one
 * thread, /tmp/trsm/bench.c in notes/performance-history.md, "trsm") against dtrsm:
 * go2's shapes 0.57-1.15 us against 3.1-3.5 us, talos' 3.3-9.9 us against 11-22 us.
 * Elsewhere fccqp_trsm_lower (above) and a dot product per entry. */
#if defined(__x86_64__) && (defined(__GNUC__) || defined(__clang__))
#define FCCQP_WIDE_TRSM 1
/* FCCQP_L3 and fccqp_first_lanes: the A'A kernel's, above */

FCCQP_L3 __m256d fccqp_rows_load(const double *p, int rows, int full, __m256i mask)
{
    return full ? _mm256_loadu_pd(p) : (rows > 0 ? _mm256_maskload_pd(p, mask)
                                                 : _mm256_setzero_pd());
}

FCCQP_L3 void fccqp_rows_store(double *p, __m256d v, int rows, int full, __m256i mask)
{
    if (full)
        _mm256_storeu_pd(p, v);
    else if (rows > 0)
        _mm256_maskstore_pd(p, mask, v);
}

/* the index (of 32-bit halves) that broadcasts lane r % 4 of a vector of doubles */
FCCQP_L3 __m256i fccqp_lane_index(int r)
{
    return _mm256_set1_epi64x((long long)(2 * (r & 3)) | ((long long)(2 * (r & 3) + 1) << 32));
}

FCCQP_L3 __m256d fccqp_broadcast_lane(__m256d v, __m256i index)
{
    return _mm256_castps_pd(_mm256_permutevar8x32_ps(_mm256_castpd_ps(v), index));
}

/* A block of rows (1-8) of the solve, shared by all the columns of B: in scaled[r] the
 * coupling of row r to the block's other rows that it updates, over its pivot (zero in
 * the lanes it does not update), the pivots' reciprocals, and the lanes' masks. The
 * block's triangle is then solved in registers: lane r is final when its turn comes,
 * its multiple of scaled[r] is subtracted from the lanes it updates (one broadcast and
 * one fused multiply-add on the chain), and the lanes are multiplied by their pivots'
 * reciprocals at the end. */
typedef struct {
    __m256d scaled[8][2], recip[2];
    __m256i lane[8], mask[2];
    int rows;
} fccqp_triangle;

/* rows i0:i0 + rows (1-8) of L^-1: row r updates the rows below it in the block (column
 * i0 + r of L below the diagonal) */
FCCQP_L3 void fccqp_forward_setup(const double *L, int ld, int i0, int rows,
                                       fccqp_triangle *t)
{
    int rows1 = rows > 4 ? rows - 4 : 0;
    double recip[8] = {1.0, 1.0, 1.0, 1.0, 1.0, 1.0, 1.0, 1.0};
    t->rows = rows;
    t->mask[0] = fccqp_first_lanes(rows - rows1);
    t->mask[1] = fccqp_first_lanes(rows1);
    for (int r = 0; r < rows; r++)
        recip[r] = 1.0 / L[i0 + r + (long)(i0 + r) * ld];
    t->recip[0] = _mm256_loadu_pd(recip);
    t->recip[1] = _mm256_loadu_pd(recip + 4);
    for (int r = 0; r < rows; r++) {
        const double *l = L + i0 + (long)(i0 + r) * ld;
        __m256d below0 = _mm256_castsi256_pd(_mm256_cmpgt_epi64(
            _mm256_setr_epi64x(0, 1, 2, 3), _mm256_set1_epi64x(r)));
        __m256d below1 = _mm256_castsi256_pd(_mm256_cmpgt_epi64(
            _mm256_setr_epi64x(4, 5, 6, 7), _mm256_set1_epi64x(r)));
        __m256d x = _mm256_set1_pd(recip[r]);
        t->scaled[r][0] = _mm256_mul_pd(_mm256_and_pd(_mm256_maskload_pd(l, t->mask[0]),
                                                      below0), x);
        t->scaled[r][1] = rows1 > 0 ? _mm256_mul_pd(_mm256_and_pd(
                                          _mm256_maskload_pd(l + 4, t->mask[1]), below1), x)
                                    : _mm256_setzero_pd();
        t->lane[r] = fccqp_lane_index(r);
    }
}

/* rows i0:i0 + t->rows of columns 0:C of B (L^-1 B), the rows above solved: eight rows
 * (two vectors) by four columns in eight accumulators over the solved rows k, each
 * column of L loaded once for the four columns of B */
FCCQP_L3 void fccqp_forward_block(const double *restrict L, int ld, double *restrict B,
                                       int ldb, int i0, int C, const fccqp_triangle *t,
                                       int full)
{
    int rows1 = t->rows > 4 ? t->rows - 4 : 0, rows0 = t->rows - rows1;
    __m256i m0 = t->mask[0], m1 = t->mask[1];
    __m256d a0[4], a1[4];
    for (int c = 0; c < C; c++) {
        a0[c] = fccqp_rows_load(B + i0 + (long)c * ldb, rows0, full, m0);
        a1[c] = fccqp_rows_load(B + i0 + 4 + (long)c * ldb, rows1, full, m1);
    }
    for (int k = 0; k < i0; k++) {
        const double *l = L + i0 + (long)k * ld;
        __m256d l0 = fccqp_rows_load(l, rows0, full, m0);
        __m256d l1 = fccqp_rows_load(l + 4, rows1, full, m1);
        for (int c = 0; c < C; c++) {
            __m256d x = _mm256_broadcast_sd(B + k + (long)c * ldb);
            a0[c] = _mm256_fnmadd_pd(l0, x, a0[c]);
            if (full || rows1 > 0)
                a1[c] = _mm256_fnmadd_pd(l1, x, a1[c]);
        }
    }
    for (int r = 0; r < t->rows; r++) {
        for (int c = 0; c < C; c++) {
            __m256d x = fccqp_broadcast_lane(r < 4 ? a0[c] : a1[c], t->lane[r]);
            if (r < 4)
                a0[c] = _mm256_fnmadd_pd(t->scaled[r][0], x, a0[c]);
            a1[c] = _mm256_fnmadd_pd(t->scaled[r][1], x, a1[c]);
        }
    }
    for (int c = 0; c < C; c++) {
        double *b = B + i0 + (long)c * ldb;
        fccqp_rows_store(b, _mm256_mul_pd(a0[c], t->recip[0]), rows0, full, m0);
        fccqp_rows_store(b + 4, _mm256_mul_pd(a1[c], t->recip[1]), rows1, full, m1);
    }
}

__attribute__((target("avx2,fma")))
static void fccqp_forward_wide(const double *restrict L, int n, int ld, double *restrict B,
                               int cols, int ldb)
{
    fccqp_triangle t;
    /* n % 8 rows first (if any): their block has no rows above it, so the masked loads
       of a partial block stay out of the loop over the solved rows */
    for (int i0 = 0, rows = n % 8 ? n % 8 : 8; i0 < n; i0 += rows, rows = 8) {
        int c = 0;
        fccqp_forward_setup(L, ld, i0, rows, &t);
        if (t.rows == 8) {
            for (; c + 4 <= cols; c += 4)
                fccqp_forward_block(L, ld, B + (long)c * ldb, ldb, i0, 4, &t, 1);
            for (; c < cols; c++)
                fccqp_forward_block(L, ld, B + (long)c * ldb, ldb, i0, 1, &t, 1);
        } else {
            for (; c + 4 <= cols; c += 4)
                fccqp_forward_block(L, ld, B + (long)c * ldb, ldb, i0, 4, &t, 0);
            for (; c < cols; c++)
                fccqp_forward_block(L, ld, B + (long)c * ldb, ldb, i0, 1, &t, 0);
        }
    }
}

/* rows i0:i0 + rows (1-4) of L'^-1: row r updates the rows above it in the block (row
 * i0 + r of L left of the diagonal) */
FCCQP_L3 void fccqp_backward_setup(const double *L, int ld, int i0, int rows,
                                        fccqp_triangle *t)
{
    double recip[4] = {1.0, 1.0, 1.0, 1.0};
    t->rows = rows;
    t->mask[0] = fccqp_first_lanes(rows);
    for (int r = 0; r < rows; r++)
        recip[r] = 1.0 / L[i0 + r + (long)(i0 + r) * ld];
    t->recip[0] = _mm256_loadu_pd(recip);
    for (int r = 0; r < rows; r++) {
        double row[4] = {0.0, 0.0, 0.0, 0.0};
        for (int j = 0; j < r; j++)
            row[j] = L[i0 + r + (long)(i0 + j) * ld];
        t->scaled[r][0] = _mm256_mul_pd(_mm256_loadu_pd(row), _mm256_set1_pd(recip[r]));
        t->lane[r] = fccqp_lane_index(r);
    }
}

/* rows i0:i0 + rows (= t->rows) of columns 0:C of B (L'^-1 B), the rows below solved
 * up to n (n - i0 - rows a multiple of 4): each entry's sum over those rows is a dot
 * product of a column of L with a column of B in four lanes, four rows by two columns
 * per pass */
FCCQP_L3 void fccqp_backward_block(const double *restrict L, int n, int ld,
                                        double *restrict B, int ldb, int i0, int rows,
                                        int C, const fccqp_triangle *t)
{
    int full = rows == 4;
    __m256d acc[4][2];
    for (int r = 0; r < 4; r++)
        for (int c = 0; c < C; c++)
            acc[r][c] = _mm256_setzero_pd();
    for (int k = i0 + rows; k < n; k += 4) {
        __m256d x[2];
        for (int c = 0; c < C; c++)
            x[c] = _mm256_loadu_pd(B + k + (long)c * ldb);
        for (int r = 0; r < rows; r++) {
            __m256d l = _mm256_loadu_pd(L + k + (long)(i0 + r) * ld);
            for (int c = 0; c < C; c++)
                acc[r][c] = _mm256_fmadd_pd(l, x[c], acc[r][c]);
        }
    }
    for (int c = 0; c < C; c++) {
        /* lane r of `dots`: (0 + 1) + (2 + 3) of acc[r][c] */
        __m256d t0 = _mm256_hadd_pd(acc[0][c], acc[1][c]);
        __m256d t1 = _mm256_hadd_pd(acc[2][c], acc[3][c]);
        __m256d dots = _mm256_add_pd(_mm256_permute2f128_pd(t0, t1, 0x20),
                                     _mm256_permute2f128_pd(t0, t1, 0x31));
        double *b = B + i0 + (long)c * ldb;
        __m256d s = _mm256_sub_pd(fccqp_rows_load(b, rows, full, t->mask[0]), dots);
        for (int r = rows - 1; r > 0; r--)
            s = _mm256_fnmadd_pd(t->scaled[r][0], fccqp_broadcast_lane(s, t->lane[r]), s);
        fccqp_rows_store(b, _mm256_mul_pd(s, t->recip[0]), rows, full, t->mask[0]);
    }
}

__attribute__((target("avx2,fma")))
static void fccqp_backward_wide(const double *restrict L, int n, int ld, double *restrict B,
                                int cols, int ldb)
{
    fccqp_triangle t;
    for (int top = n; top > 0; top -= 4) {   /* the block of rows top - 4:top, or 0:top */
        int i0 = top >= 4 ? top - 4 : 0, c = 0;
        fccqp_backward_setup(L, ld, i0, top - i0, &t);
        if (t.rows == 4) {   /* a constant 4 rows: the loops over them unrolled */
            for (; c + 2 <= cols; c += 2)
                fccqp_backward_block(L, n, ld, B + (long)c * ldb, ldb, i0, 4, 2, &t);
            for (; c < cols; c++)
                fccqp_backward_block(L, n, ld, B + (long)c * ldb, ldb, i0, 4, 1, &t);
        } else {
            for (; c + 2 <= cols; c += 2)
                fccqp_backward_block(L, n, ld, B + (long)c * ldb, ldb, i0, t.rows, 2, &t);
            for (; c < cols; c++)
                fccqp_backward_block(L, n, ld, B + (long)c * ldb, ldb, i0, t.rows, 1, &t);
        }
    }
}
#endif

/* B := L'^-1 B, one dot product per entry (the portable path) */
static void fccqp_backward_dots(const double *restrict L, int n, int ld, double *restrict B,
                                int cols, int ldb)
{
    for (int c = 0; c < cols; c++) {
        double *b = B + (long)c * ldb;
        for (int i = n - 1; i >= 0; i--) {
            const double *l = L + (long)i * ld;
            double s = b[i];
            for (int k = i + 1; k < n; k++)
                s -= l[k] * b[k];
            b[i] = s * (1.0 / l[i]);
        }
    }
}

static inline void fccqp_trsm_left(char trans, const double *L, int n, int ld, double *B,
                                   int cols, int ldb)
{
#ifdef FCCQP_WIDE_TRSM
    if (__builtin_cpu_supports("avx2") && __builtin_cpu_supports("fma")) {
        if (trans == 'N')
            fccqp_forward_wide(L, n, ld, B, cols, ldb);
        else
            fccqp_backward_wide(L, n, ld, B, cols, ldb);
        return;
    }
#endif
    if (trans == 'N')
        fccqp_trsm_lower(L, n, ld, B, cols, ldb);
    else
        fccqp_backward_dots(L, n, ld, B, cols, ldb);
}

/* termination.residuals' passes over the rows, the constrained entries and the variables:
 * their running maxima in four lanes (fccqp_v4; each lane's maximum skips NaN as the
 * loops' max did, so the lanes' maximum is the loops' maximum, whatever the order) and
 * divisions, comparisons and selections entry by entry as the loops had them. The sum
 * whose finiteness the residuals report (Residuals.finite) is summed in the lanes too:
 * its terms are magnitudes, so it is NaN or infinite in every order alike but within the
 * rounding of the largest double. The dual residual's sums (x'Px, q'x) stay in their
 * order, one chain each. Cython's loops took 14.7k of residuals' 30k instructions a call
 * on talos (callgrind, its realtime cold cell). */
#if defined(__GNUC__) || defined(__clang__)
#if defined(__SSE2__)
FCCQP_LANE_OP fccqp_v2 fccqp_min2(fccqp_v2 acc, fccqp_v2 x)
{
    return (fccqp_v2)_mm_min_pd((__m128d)x, (__m128d)acc);   /* x < acc ? x : acc */
}
#else
FCCQP_LANE_OP fccqp_v2 fccqp_min2(fccqp_v2 acc, fccqp_v2 x)
{
    fccqp_m2 smaller = x < acc;
    return (fccqp_v2)(((fccqp_m2)x & smaller) | ((fccqp_m2)acc & ~smaller));
}
#endif
FCCQP_LANE_OP fccqp_v2 fccqp_select2(fccqp_m2 mask, fccqp_v2 a, fccqp_v2 other)
{
    return (fccqp_v2)(((fccqp_m2)a & mask) | ((fccqp_m2)other & ~mask));
}
FCCQP_LANE_OP fccqp_v2 fccqp_positive_or2(fccqp_v2 a, fccqp_v2 other)   /* a > 0 ? a : other */
{
    fccqp_v2 zero = {0.0, 0.0};
    return fccqp_select2(a > zero, a, other);
}
FCCQP_LANE_OP fccqp_v2 fccqp_finite_or2(fccqp_v2 a, fccqp_v2 other)   /* a finite ? a : other */
{
    fccqp_v2 infinite = {INFINITY, INFINITY};
    return fccqp_select2(fccqp_abs2(a) < infinite, a, other);
}
FCCQP_LANE_OP fccqp_v4 fccqp_div4(fccqp_v4 a, fccqp_v4 b) { FCCQP_HALVES(a.lo / b.lo, a.hi / b.hi) }
FCCQP_LANE_OP fccqp_v4 fccqp_min4(fccqp_v4 acc, fccqp_v4 x)
{
    FCCQP_HALVES(fccqp_min2(acc.lo, x.lo), fccqp_min2(acc.hi, x.hi))
}
FCCQP_LANE_OP fccqp_v4 fccqp_positive_or4(fccqp_v4 a, fccqp_v4 other)
{
    FCCQP_HALVES(fccqp_positive_or2(a.lo, other.lo), fccqp_positive_or2(a.hi, other.hi))
}
FCCQP_LANE_OP fccqp_v4 fccqp_finite_or4(fccqp_v4 a, fccqp_v4 other)
{
    FCCQP_HALVES(fccqp_finite_or2(a.lo, other.lo), fccqp_finite_or2(a.hi, other.hi))
}
#else
FCCQP_LANE_OP fccqp_v4 fccqp_div4(fccqp_v4 a, fccqp_v4 b) { FCCQP_LANEWISE(fccqp_v4, a.lane[k] / b.lane[k]) }
FCCQP_LANE_OP fccqp_v4 fccqp_min4(fccqp_v4 acc, fccqp_v4 x)
{
    FCCQP_LANEWISE(fccqp_v4, x.lane[k] < acc.lane[k] ? x.lane[k] : acc.lane[k])
}
FCCQP_LANE_OP fccqp_v4 fccqp_positive_or4(fccqp_v4 a, fccqp_v4 other)
{
    FCCQP_LANEWISE(fccqp_v4, a.lane[k] > 0.0 ? a.lane[k] : other.lane[k])
}
FCCQP_LANE_OP fccqp_v4 fccqp_finite_or4(fccqp_v4 a, fccqp_v4 other)
{
    FCCQP_LANEWISE(fccqp_v4, isfinite(a.lane[k]) ? a.lane[k] : other.lane[k])
}
#endif

/* a size capped by a positive span (termination.pyx's docstring): min(size, span) where span > 0 */
FCCQP_LANE_OP fccqp_v4 fccqp_capped4(fccqp_v4 size, fccqp_v4 span)
{
    return fccqp_min4(size, fccqp_positive_or4(span, fccqp_splat4(INFINITY)));
}
FCCQP_LANE_OP double fccqp_capped(double size, double span)
{
    return span > 0.0 && span < size ? span : size;
}
FCCQP_LANE_OP double fccqp_larger(double acc, double x) { return x > acc ? x : acc; }

/* The rows: out = (max |Ax - b| / E, max max(|Ax|, |b|) / E, max |Ax - b|,
 * max capped(max(|Ax|, |b|), span), sum |Ax - b|) */
FCCQP_EXACT_CLONES
static void fccqp_row_residuals(const double *restrict Ax, const double *restrict b,
                                const double *restrict E, const double *restrict span,
                                long m, double out[5])
{
    fccqp_v4 zero = fccqp_splat4(0.0), eq = zero, eq_scale = zero, prim = zero;
    fccqp_v4 prim_scale = zero, total = zero;
    long i = 0;
    for (; i + 4 <= m; i += 4) {
        fccqp_v4 ax = fccqp_load4(Ax + i), bi = fccqp_load4(b + i), e = fccqp_load4(E + i);
        fccqp_v4 value = fccqp_abs4(fccqp_sub4(ax, bi));
        fccqp_v4 scale = fccqp_max4(fccqp_abs4(ax), fccqp_abs4(bi));
        eq = fccqp_max4(eq, fccqp_div4(value, e));
        eq_scale = fccqp_max4(eq_scale, fccqp_div4(scale, e));
        prim = fccqp_max4(prim, value);
        prim_scale = fccqp_max4(prim_scale, fccqp_capped4(scale, fccqp_load4(span + i)));
        total = fccqp_add4(total, value);
    }
    out[0] = fccqp_largest4(eq, 0.0), out[1] = fccqp_largest4(eq_scale, 0.0);
    out[2] = fccqp_largest4(prim, 0.0), out[3] = fccqp_largest4(prim_scale, 0.0);
    out[4] = fccqp_sum4(total);
    for (; i < m; i++) {
        double value = fabs(Ax[i] - b[i]), scale = fccqp_larger(fabs(Ax[i]), fabs(b[i]));
        out[0] = fccqp_larger(out[0], value / E[i]);
        out[1] = fccqp_larger(out[1], scale / E[i]);
        out[2] = fccqp_larger(out[2], value);
        out[3] = fccqp_larger(out[3], fccqp_capped(scale, span[i]));
        out[4] += value;
    }
}

/* The constrained entries (x_S = x[constrained] against the slack z): out = (max |x_S -
 * z| D, max max(|x_S|, |z|) D, max |x_S - z|, max capped(max(|x_S|, |z|), hi - lo),
 * max max(|x_S|, |z|), the box entries' max |x_S - z| - violation box_entry_size,
 * sum |x_S - z| + |y|); out[5] is -inf without a box entry */
FCCQP_EXACT_CLONES
static void fccqp_set_residuals(const double *restrict x, const double *restrict D,
                                const long *restrict constrained, const double *restrict z,
                                const double *restrict y, const double *restrict lo,
                                const double *restrict hi, const char *restrict in_cone,
                                double violation, long s, double out[7])
{
    fccqp_v4 zero = fccqp_splat4(0.0), set = zero, set_scale = zero, prim = zero;
    fccqp_v4 prim_scale = zero, size = zero, excess = fccqp_splat4(-INFINITY), total = zero;
    fccqp_v4 fraction = fccqp_splat4(violation);
    long j = 0;
    for (; j + 4 <= s; j += 4) {
        const long *c = constrained + j;
        fccqp_v4 xs = fccqp_set4(x[c[0]], x[c[1]], x[c[2]], x[c[3]]);
        fccqp_v4 d = fccqp_set4(D[c[0]], D[c[1]], D[c[2]], D[c[3]]);
        fccqp_v4 zj = fccqp_load4(z + j);
        fccqp_v4 width = fccqp_sub4(fccqp_load4(hi + j), fccqp_load4(lo + j));
        fccqp_v4 value = fccqp_abs4(fccqp_sub4(xs, zj));
        fccqp_v4 scale = fccqp_max4(fccqp_abs4(xs), fccqp_abs4(zj));
        /* box_entry_size: max(scale, width) where the width is finite, else scale; the
         * cones' entries give -inf (never the maximum) */
        fccqp_v4 entry = fccqp_max4(scale, fccqp_finite_or4(width, fccqp_splat4(-INFINITY)));
        fccqp_v4 cone = fccqp_set4(in_cone[j] ? -INFINITY : INFINITY,
                                   in_cone[j + 1] ? -INFINITY : INFINITY,
                                   in_cone[j + 2] ? -INFINITY : INFINITY,
                                   in_cone[j + 3] ? -INFINITY : INFINITY);
        set = fccqp_max4(set, fccqp_mul4(value, d));
        set_scale = fccqp_max4(set_scale, fccqp_mul4(scale, d));
        prim = fccqp_max4(prim, value);
        prim_scale = fccqp_max4(prim_scale, fccqp_capped4(scale, width));
        size = fccqp_max4(size, scale);
        excess = fccqp_max4(excess, fccqp_min4(fccqp_sub4(value, fccqp_mul4(fraction, entry)),
                                               cone));
        total = fccqp_add4(total, fccqp_add4(value, fccqp_abs4(fccqp_load4(y + j))));
    }
    out[0] = fccqp_largest4(set, 0.0), out[1] = fccqp_largest4(set_scale, 0.0);
    out[2] = fccqp_largest4(prim, 0.0), out[3] = fccqp_largest4(prim_scale, 0.0);
    out[4] = fccqp_largest4(size, 0.0), out[5] = fccqp_largest4(excess, -INFINITY);
    out[6] = fccqp_sum4(total);
    for (; j < s; j++) {
        double xj = x[constrained[j]], d = D[constrained[j]], width = hi[j] - lo[j];
        double value = fabs(xj - z[j]), scale = fccqp_larger(fabs(xj), fabs(z[j]));
        out[0] = fccqp_larger(out[0], value * d);
        out[1] = fccqp_larger(out[1], scale * d);
        out[2] = fccqp_larger(out[2], value);
        out[3] = fccqp_larger(out[3], fccqp_capped(scale, width));
        out[4] = fccqp_larger(out[4], scale);
        if (!in_cone[j])
            out[5] = fccqp_larger(out[5], value - violation * (isfinite(width)
                                                               ? fccqp_larger(scale, width)
                                                               : scale));
        out[6] += value + fabs(y[j]);
    }
}

/* The variables, before the multipliers of the constrained entries: out = (x'Px, q'x,
 * max max(|Px|, |q|) / (c D), max max(|Px|, |q|, |A'nu|)); Px becomes Px + (q + A'nu) */
FCCQP_EXACT_CLONES
static void fccqp_dual_scales(double *restrict Px, const double *restrict q,
                              const double *restrict ATnu, const double *restrict x,
                              const double *restrict D, double c, long n, double out[4])
{
    fccqp_v4 zero = fccqp_splat4(0.0), scale = zero, scale_s = zero, one = fccqp_splat4(1.0);
    fccqp_v4 cc = fccqp_splat4(c);
    double xPx = 0.0, qx = 0.0;
    long i = 0;
    for (i = 0; i < n; i++) {
        xPx += x[i] * Px[i];
        qx += q[i] * x[i];
    }
    for (i = 0; i + 4 <= n; i += 4) {
        fccqp_v4 px = fccqp_load4(Px + i), qi = fccqp_load4(q + i), at = fccqp_load4(ATnu + i);
        fccqp_v4 terms = fccqp_max4(fccqp_abs4(px), fccqp_abs4(qi));
        scale = fccqp_max4(scale, fccqp_mul4(terms, fccqp_div4(one, fccqp_mul4(cc, fccqp_load4(D + i)))));
        scale_s = fccqp_max4(scale_s, fccqp_max4(terms, fccqp_abs4(at)));
        fccqp_store4(Px + i, fccqp_add4(px, fccqp_add4(qi, at)));
    }
    out[0] = xPx, out[1] = qx;
    out[2] = fccqp_largest4(scale, 0.0), out[3] = fccqp_largest4(scale_s, 0.0);
    for (; i < n; i++) {
        double terms = fccqp_larger(fabs(Px[i]), fabs(q[i]));
        out[2] = fccqp_larger(out[2], terms * (1.0 / (c * D[i])));
        out[3] = fccqp_larger(out[3], fccqp_larger(terms, fabs(ATnu[i])));
        Px[i] += q[i] + ATnu[i];
    }
}

/* The gradient of the Lagrangian: out = (max |grad| / (c D), max |grad|,
 * sum |grad| + |x|) */
FCCQP_EXACT_CLONES
static void fccqp_dual_residual(const double *restrict grad, const double *restrict x,
                                const double *restrict D, double c, long n, double out[3])
{
    fccqp_v4 zero = fccqp_splat4(0.0), dual = zero, dual_s = zero, total = zero;
    fccqp_v4 cc = fccqp_splat4(c);
    long i = 0;
    for (; i + 4 <= n; i += 4) {
        fccqp_v4 value = fccqp_abs4(fccqp_load4(grad + i));
        dual = fccqp_max4(dual, fccqp_div4(value, fccqp_mul4(cc, fccqp_load4(D + i))));
        dual_s = fccqp_max4(dual_s, value);
        total = fccqp_add4(total, fccqp_add4(value, fccqp_abs4(fccqp_load4(x + i))));
    }
    out[0] = fccqp_largest4(dual, 0.0), out[1] = fccqp_largest4(dual_s, 0.0);
    out[2] = fccqp_sum4(total);
    for (; i < n; i++) {
        double value = fabs(grad[i]);
        out[0] = fccqp_larger(out[0], value / (c * D[i]));
        out[1] = fccqp_larger(out[1], value);
        out[2] += value + fabs(x[i]);
    }
}

/* reduced.near_convergence's row gate: out = (row' u, |row|' |u|), each sum in four lanes
 * (the gate's rounding bound holds for any order of the sums): a quarter of the
 * instructions of two scalar chains */
#if defined(__GNUC__) || defined(__clang__)
typedef long long fccqp_i4 __attribute__((vector_size(32)));
FCCQP_LANE_OP fccqp_d4 fccqp_dabs(fccqp_d4 a)
{
    fccqp_i4 magnitude = {0x7fffffffffffffffLL, 0x7fffffffffffffffLL, 0x7fffffffffffffffLL,
                          0x7fffffffffffffffLL};
    return (fccqp_d4)((fccqp_i4)a & magnitude);
}
#else
FCCQP_LANE_OP fccqp_d4 fccqp_dabs(fccqp_d4 a) { FCCQP_LANEWISE(fccqp_d4, fabs(a.lane[k])) }
#endif
FCCQP_EXACT_CLONES
static void fccqp_row_gate_sums(const double *restrict row, const double *restrict u, long s,
                                double out[2])
{
    fccqp_d4 sum = fccqp_dsplat(0.0), size = sum;
    long l = 0;
    for (; l + 4 <= s; l += 4) {
        fccqp_d4 term = fccqp_dmul(fccqp_dload(row + l), fccqp_dload(u + l));
        sum = fccqp_dadd(sum, term);
        size = fccqp_dadd(size, fccqp_dabs(term));
    }
    out[0] = fccqp_dsum(sum), out[1] = fccqp_dsum(size);
    for (; l < s; l++) {
        double term = row[l] * u[l];
        out[0] += term;
        out[1] += fabs(term);
    }
}

/* The reduced form's ADMM step (reduced.reduced_step) around its product x~_S = W_S v,
 * in C for the restrict pointers that let its loops vectorize (Cython's pointers into its
 * structs may alias, and its loops stayed scalar: 2.4k instructions a step on talos' 56
 * constrained entries, besides the product). Element by element, each entry's operations
 * in the order of the loops they replace, built without contraction into fused
 * multiply-adds (FCCQP_EXACT_CLONES): the same bits in both copies and as before.
 *
 * fccqp_step_start: the previous z, y, v, u kept, and v = rho z - y.
 * fccqp_step_relax: relaxed = alpha (base_S + x~_S) + (1 - alpha) z_prev (base_S
 * gathered through constrained), u = alpha_x v + (1 - alpha_x) u_prev, and z = relaxed
 * + y / rho clipped to [lo, hi] as projections.proj_set's box clips it (a cone entry's
 * infinite bounds leave it; its block is projected after).
 * fccqp_step_multipliers: y += rho (relaxed - z), after the cones' projection. */
FCCQP_EXACT_CLONES
static void fccqp_step_start(const double *restrict z, const double *restrict y,
                             const double *restrict rho, long s, double *restrict z_prev,
                             double *restrict y_prev, double *restrict v,
                             double *restrict v_prev, double *restrict u,
                             double *restrict u_prev)
{
    for (long j = 0; j < s; j++) {
        z_prev[j] = z[j];
        y_prev[j] = y[j];
        v_prev[j] = v[j];
        u_prev[j] = u[j];
        v[j] = rho[j] * z[j] - y[j];
    }
}

FCCQP_EXACT_CLONES
static void fccqp_step_relax(const double *restrict base, const long *restrict constrained,
                             const double *restrict xs, const double *restrict z_prev,
                             const double *restrict v, const double *restrict u_prev,
                             const double *restrict y, const double *restrict rho,
                             const double *restrict lo, const double *restrict hi,
                             double alpha, double alpha_x, long s,
                             double *restrict relaxed, double *restrict u, double *restrict z)
{
    double keep = 1.0 - alpha, keep_x = 1.0 - alpha_x;
    for (long j = 0; j < s; j++) {
        double r = alpha * (base[constrained[j]] + xs[j]) + keep * z_prev[j];
        double value = r + y[j] / rho[j];
        relaxed[j] = r;
        u[j] = alpha_x * v[j] + keep_x * u_prev[j];
        if (value < lo[j])
            value = lo[j];
        if (value > hi[j])
            value = hi[j];
        z[j] = value;
    }
}

FCCQP_EXACT_CLONES
static void fccqp_step_multipliers(const double *restrict rho,
                                   const double *restrict relaxed, const double *restrict z,
                                   long s, double *restrict y)
{
    for (long j = 0; j < s; j++)
        y[j] += rho[j] * (relaxed[j] - z[j]);
}

/* fccqp_mark_coupled (schur.pyx's mark_coupled, for the Schur backend and polish_schur):
 * coupled[i] = 1 where row i of the row-major n x n symmetric P has a nonzero (or NaN)
 * entry off its diagonal, else 0. From the strict lower triangle alone: row i's entries
 * left of the diagonal mark row i, and, P being symmetric, each one marks its column's
 * row too. The entries' bits shifted past the sign (so that -0.0 counts as zero) are
 * or-ed, by row and by column (FCCQP_COUPLED_CHUNK columns at a time on the stack), in
 * loops GCC vectorizes: go2 (54 rows) 6.6k instructions a call when every row was
 * scanned in full, talos (124) 24.3k (callgrind). */
#define FCCQP_COUPLED_CHUNK 256
FCCQP_CLONES
static void fccqp_mark_coupled(const double *P, int n, char *coupled)
{
    unsigned long long columns[FCCQP_COUPLED_CHUNK];
    memset(coupled, 0, (size_t)n);
    for (int c0 = 0; c0 < n; c0 += FCCQP_COUPLED_CHUNK) {
        int width = n - c0 < FCCQP_COUPLED_CHUNK ? n - c0 : FCCQP_COUPLED_CHUNK;
        memset(columns, 0, sizeof columns);
        for (int i = c0 + 1; i < n; i++) {
            const double *row = P + (long)i * n + c0;
            int count = i - c0 < width ? i - c0 : width;
            unsigned long long bits = 0;
            for (int j = 0; j < count; j++) {
                unsigned long long w;
                memcpy(&w, row + j, sizeof w);
                columns[j] |= w;
                bits |= w;
            }
            coupled[i] |= (char)((bits << 1) != 0);
        }
        for (int j = 0; j < width; j++)
            coupled[c0 + j] |= (char)((columns[j] << 1) != 0);
    }
}

/* The Schur backend's reduced table on the diagonal tail of H (schur.pyx,
 * _sparse_unit_columns): the rows of W_x whose rows of Y = L^-1 A' are as sparse as A's
 * columns (whole-body control: a torque's or slack's column has one nonzero, a contact
 * force's 5-12), formed from their nonzeros instead of the dense product Y W_nu: go2's 36
 * such rows have 92 nonzeros of 1080 (s = 24), talos' 86 have 303 of 5848 (s = 56).
 *
 * fccqp_transpose: T[i s + c] = M[i + c ld] for i < m, c < s (T row-major, m x s), so that
 * a row of W_nu is contiguous for the rows' sums.
 *
 * fccqp_sparse_table_rows: for each row j in [first, last) of the column-major Y (leading
 * dimension ldy), nonzero in the columns index[j m : j m + count[j]], and each c < s,
 *     W[dest[j] + c ldw] = (z - sum_k Y[j, i_k] WT[i_k s + c]) / L[j, j],
 * z = 1 / L[j, j] at c = j - unit (a constrained row's unit column) and 0 elsewhere, WT
 * from fccqp_transpose: each entry's terms subtracted from z in the nonzeros' order. The
 * rows j >= unit go also to rows[(j - unit) s + c] where rows is not NULL. Where
 * the CPU has AVX2 and FMA (picked at each call) a row's columns go in blocks of six
 * vectors held in registers, fused; the portable loops otherwise. */
#include <stddef.h>

static void fccqp_transpose_loop(const double *restrict M, long ld, int m, int s,
                                 double *restrict T)
{
    for (int i = 0; i < m; i++)
        for (int c = 0; c < s; c++)
            T[(long)i * s + c] = M[i + (long)c * ld];
}

static void fccqp_sparse_table_rows_loop(const double *restrict Y, int ldy, int first,
                                         int last, const int *restrict index,
                                         const int *restrict count, int m,
                                         const double *restrict WT, int s,
                                         const double *restrict L, int ldl, int unit,
                                         const ptrdiff_t *restrict dest,
                                         double *restrict W, long ldw,
                                         double *restrict rows)
{
    for (int j = first; j < last; j++) {
        const int *columns = index + (long)j * m;
        double pivot = L[j + (long)j * ldl];
        for (int c = 0; c < s; c++) {
            double acc = c == j - unit ? 1.0 / pivot : 0.0;
            for (int k = 0; k < count[j]; k++)
                acc -= Y[j + (long)columns[k] * ldy] * WT[(long)columns[k] * s + c];
            W[dest[j] + (long)c * ldw] = acc / pivot;
            if (rows && j >= unit)
                rows[(long)(j - unit) * s + c] = acc / pivot;
        }
    }
}

#ifdef FCCQP_WIDE_TRSM
#define FCCQP_WIDE_TABLE 1
/* FCCQP_L3 and fccqp_first_lanes: the A'A kernel's, above */

__attribute__((target("avx2,fma")))
static void fccqp_transpose_wide(const double *restrict M, long ld, int m, int s,
                                 double *restrict T)
{
    int i = 0;
    for (; i + 4 <= m; i += 4) {   /* 4 x 4 blocks: four columns in, four rows out */
        int c = 0;
        for (; c + 4 <= s; c += 4) {
            const double *p = M + i + (long)c * ld;
            __m256d t0 = _mm256_unpacklo_pd(_mm256_loadu_pd(p), _mm256_loadu_pd(p + ld));
            __m256d t1 = _mm256_unpackhi_pd(_mm256_loadu_pd(p), _mm256_loadu_pd(p + ld));
            __m256d t2 = _mm256_unpacklo_pd(_mm256_loadu_pd(p + 2 * ld),
                                            _mm256_loadu_pd(p + 3 * ld));
            __m256d t3 = _mm256_unpackhi_pd(_mm256_loadu_pd(p + 2 * ld),
                                            _mm256_loadu_pd(p + 3 * ld));
            double *q = T + (long)i * s + c;
            _mm256_storeu_pd(q, _mm256_permute2f128_pd(t0, t2, 0x20));
            _mm256_storeu_pd(q + s, _mm256_permute2f128_pd(t1, t3, 0x20));
            _mm256_storeu_pd(q + 2 * s, _mm256_permute2f128_pd(t0, t2, 0x31));
            _mm256_storeu_pd(q + 3 * s, _mm256_permute2f128_pd(t1, t3, 0x31));
        }
        for (; c < s; c++)
            for (int r = 0; r < 4; r++)
                T[(long)(i + r) * s + c] = M[i + r + (long)c * ld];
    }
    for (; i < m; i++)
        for (int c = 0; c < s; c++)
            T[(long)i * s + c] = M[i + (long)c * ld];
}

/* lanes 0 .. width - 1 of v at out[0], out[ld], ... (width 1 to 4) */
FCCQP_L3 void fccqp_store_strided(double *out, long ld, __m256d v, int width)
{
    __m128d lo = _mm256_castpd256_pd128(v), hi = _mm256_extractf128_pd(v, 1);
    _mm_storel_pd(out, lo);
    if (width > 1)
        _mm_storeh_pd(out + ld, lo);
    if (width > 2)
        _mm_storel_pd(out + 2 * ld, hi);
    if (width > 3)
        _mm_storeh_pd(out + 3 * ld, hi);
}

/* Columns per block of fccqp_sparse_table_rows_wide: six vectors of accumulators, the
 * broadcast factor and a loaded row fill the 16 registers (go2's s = 24 in one block) */
#define FCCQP_TABLE_VECTORS 6

/* fccqp_sparse_table_rows' columns c0 .. c0 + 4 V - 1 of row j, V vectors (a constant
 * where it is inlined), the last one's lanes masked by `last` (width `last_width`);
 * also at row[c0 ...] where row is not NULL */
FCCQP_L3 void fccqp_table_block(const double *Y, long ldy, int j, const int *columns,
                                int count, const double *WT, long s, int c0, int V,
                                __m256i last, int last_width, int diag, double pivot,
                                double *out, long ldw, double *row)
{
    __m256d acc[FCCQP_TABLE_VECTORS], p = _mm256_set1_pd(pivot);
    __m256d unit = _mm256_set1_pd(1.0 / pivot);
    __m256i at = _mm256_set1_epi64x((long long)diag - c0);
    for (int q = 0; q < V; q++) {   /* 1 / pivot in the lane of column diag, else 0 */
        __m256i lane = _mm256_setr_epi64x(4 * q, 4 * q + 1, 4 * q + 2, 4 * q + 3);
        acc[q] = _mm256_and_pd(unit, _mm256_castsi256_pd(_mm256_cmpeq_epi64(at, lane)));
    }
    for (int k = 0; k < count; k++) {
        __m256d y = _mm256_set1_pd(Y[j + (long)columns[k] * ldy]);
        const double *w = WT + (long)columns[k] * s + c0;
        for (int q = 0; q < V - 1; q++)
            acc[q] = _mm256_fnmadd_pd(y, _mm256_loadu_pd(w + 4 * q), acc[q]);
        acc[V - 1] = _mm256_fnmadd_pd(y, _mm256_maskload_pd(w + 4 * (V - 1), last),
                                      acc[V - 1]);
    }
    for (int q = 0; q < V; q++) {
        __m256d v = _mm256_div_pd(acc[q], p);
        int width = q < V - 1 ? 4 : last_width;
        fccqp_store_strided(out + (long)(c0 + 4 * q) * ldw, ldw, v, width);
        if (row && width == 4)
            _mm256_storeu_pd(row + c0 + 4 * q, v);
        else if (row)
            fccqp_store_strided(row + c0 + 4 * q, 1, v, width);
    }
}

__attribute__((target("avx2,fma")))
static void fccqp_sparse_table_rows_wide(const double *restrict Y, int ldy, int first,
                                         int last, const int *restrict index,
                                         const int *restrict count, int m,
                                         const double *restrict WT, int s,
                                         const double *restrict L, int ldl, int unit,
                                         const ptrdiff_t *restrict dest,
                                         double *restrict W, long ldw,
                                         double *restrict rows)
{
    enum { C = 4 * FCCQP_TABLE_VECTORS };
    for (int j = first; j < last; j++) {
        const int *columns = index + (long)j * m;
        double pivot = L[j + (long)j * ldl];
        double *out = W + dest[j];
        double *row = rows && j >= unit ? rows + (long)(j - unit) * s : NULL;
        for (int c0 = 0; c0 < s; c0 += C) {
            int width = s - c0 < C ? s - c0 : C, V = (width + 3) / 4;
            int last_width = width - 4 * (V - 1);
            __m256i mask = fccqp_first_lanes(last_width);
#define FCCQP_TABLE_BLOCK(vectors)                                                       \
    fccqp_table_block(Y, ldy, j, columns, count[j], WT, s, c0, vectors, mask, last_width, \
                      j - unit, pivot, out, ldw, row)
            switch (V) {
            case 6: FCCQP_TABLE_BLOCK(6); break;
            case 5: FCCQP_TABLE_BLOCK(5); break;
            case 4: FCCQP_TABLE_BLOCK(4); break;
            case 3: FCCQP_TABLE_BLOCK(3); break;
            case 2: FCCQP_TABLE_BLOCK(2); break;
            default: FCCQP_TABLE_BLOCK(1);
            }
#undef FCCQP_TABLE_BLOCK
        }
    }
}
#endif

static inline void fccqp_transpose(const double *M, long ld, int m, int s, double *T)
{
#ifdef FCCQP_WIDE_TABLE
    if (__builtin_cpu_supports("avx2") && __builtin_cpu_supports("fma")) {
        fccqp_transpose_wide(M, ld, m, s, T);
        return;
    }
#endif
    fccqp_transpose_loop(M, ld, m, s, T);
}

static inline void fccqp_sparse_table_rows(const double *Y, int ldy, int first, int last,
                                           const int *index, const int *count, int m,
                                           const double *WT, int s, const double *L,
                                           int ldl, int unit, const ptrdiff_t *dest,
                                           double *W, long ldw, double *rows)
{
#ifdef FCCQP_WIDE_TABLE
    if (__builtin_cpu_supports("avx2") && __builtin_cpu_supports("fma")) {
        fccqp_sparse_table_rows_wide(Y, ldy, first, last, index, count, m, WT, s, L, ldl,
                                     unit, dest, W, ldw, rows);
        return;
    }
#endif
    fccqp_sparse_table_rows_loop(Y, ldy, first, last, index, count, m, WT, s, L, ldl, unit,
                                 dest, W, ldw, rows);
}

/* Per-solve intake (fixedcost).
 *
 * fccqp_last_coupled_row: mark_diagonal_tail's search (matrices.pxd), the last row i of
 * the row-major n x n M with a nonzero (or NaN) entry left of its diagonal, -1 where no
 * row has one; each row's entries or-ed as fccqp_any_nonzero does (-0.0 is zero). The
 * Cython loop with a test per entry took 10.7k instructions a go2 tick (19 rows of
 * 35-53 entries read).
 */
/* Whether any of count doubles is nonzero (or NaN): their bits shifted past the sign
 * (so that -0.0 counts as zero) or-ed, with no branch per entry. */
FCCQP_FORCE_INLINE int fccqp_any_nonzero(const double *v, int count)
{
    unsigned long long bits = 0;
    for (int j = 0; j < count; j++) {
        unsigned long long w;
        memcpy(&w, v + j, sizeof w);
        bits |= w << 1;
    }
    return bits != 0;
}

FCCQP_CLONES
static int fccqp_last_coupled_row(const double *M, int n)
{
    for (int i = n - 1; i > 0; i--)
        if (fccqp_any_nonzero(M + (long)i * n, i))
            return i;
    return -1;
}

/* lb_out, ub_out = lb, ub (n entries), bounds of magnitude big or more as infinite; 1
 * where an entry's pair is not lb <= ub (a NaN, crossed) or has lb = +inf or ub = -inf,
 * which the validation then looks up (validation.pyx, _check_bounds), else 0. No branch
 * on the data: a test and a branch for each of the five cases took 1.1k instructions a
 * go2 tick. */
FCCQP_CLONES
static int fccqp_bounds_copy(const double *restrict lb, const double *restrict ub, long n,
                             double big, double *restrict lb_out, double *restrict ub_out)
{
    long bad = 0;
    for (long i = 0; i < n; i++) {
        double l = lb[i], u = ub[i];
        bad |= !(l <= u) | (l == INFINITY) | (u == -INFINITY);
        lb_out[i] = l > -big ? l : -INFINITY;
        ub_out[i] = u < big ? u : INFINITY;
    }
    return bad != 0;
}

/* fccqp_forward_vector, fccqp_backward_vector: b := L^-1 b and b := L'^-1 b for one
 * vector and the column-major lower triangle L (leading dimension ld), the loops of
 * _blas.pxd's forward_substitution and backward_substitution with the same operations in
 * the same order (the same bits: no contraction into fused multiply-adds), for the Schur
 * polish's solves (polish_schur.pyx). After each block of four solved entries the
 * entries below (above) it take their four updates in one pass; here four entries at a
 * time in AVX2: below, in the clone GCC vectorizes; above, where the four entries of a
 * column of L are adjacent and each entry's four come from different columns, by a 4 x 4
 * transpose of four columns' pieces. The Cython loops compile to scalar SSE2 (the
 * modules' baseline): on anymal_c's contact tick 360 the polish's sweeps over L, S0, K
 * and S took ~105k instructions of 775k (callgrind). */
FCCQP_EXACT_CLONES
static void fccqp_forward_vector(const double *restrict L, int n, int ld, double *restrict b)
{
    int k = 0;
    for (; k + 4 <= n; k += 4) {
        const double *c0 = L + (long)k * ld, *c1 = c0 + ld, *c2 = c1 + ld, *c3 = c2 + ld;
        double v0 = b[k] * (1.0 / c0[k]);
        b[k + 1] -= c0[k + 1] * v0;
        b[k + 2] -= c0[k + 2] * v0;
        b[k + 3] -= c0[k + 3] * v0;
        double v1 = b[k + 1] * (1.0 / c1[k + 1]);
        b[k + 2] -= c1[k + 2] * v1;
        b[k + 3] -= c1[k + 3] * v1;
        double v2 = b[k + 2] * (1.0 / c2[k + 2]);
        b[k + 3] -= c2[k + 3] * v2;
        double v3 = b[k + 3] * (1.0 / c3[k + 3]);
        b[k] = v0;
        b[k + 1] = v1;
        b[k + 2] = v2;
        b[k + 3] = v3;
        for (int i = k + 4; i < n; i++)
            b[i] = b[i] - c0[i] * v0 - c1[i] * v1 - c2[i] * v2 - c3[i] * v3;
    }
    for (; k < n; k++) {
        const double *c0 = L + (long)k * ld;
        double v0 = b[k] * (1.0 / c0[k]);
        b[k] = v0;
        for (int i = k + 1; i < n; i++)
            b[i] -= c0[i] * v0;
    }
}

/* b[i] -= L[k + 3, i] v3 + ... + L[k, i] v0 for i < k from `first` on, in that order */
static inline void fccqp_backward_above(const double *restrict L, long ld, int k, int first,
                                        double *restrict b, double v0, double v1, double v2,
                                        double v3)
{
    for (int i = first; i < k; i++) {
        const double *column = L + k + i * ld;
        b[i] = b[i] - column[3] * v3 - column[2] * v2 - column[1] * v1 - column[0] * v0;
    }
}

#if defined(__x86_64__) && (defined(__GNUC__) || defined(__clang__))
#include <immintrin.h>
/* fccqp_backward_above four entries at a time: rows k .. k + 3 of columns i .. i + 3 of
 * L transposed into four vectors of a row each, then two (AVX alone: multiplications
 * and subtractions, no fused multiply-add, as the scalar loop) */
__attribute__((target("avx2")))
static void fccqp_backward_above_avx2(const double *restrict L, long ld, int k,
                                      double *restrict b, double v0, double v1, double v2,
                                      double v3)
{
    __m256d w0 = _mm256_set1_pd(v0), w1 = _mm256_set1_pd(v1);
    __m256d w2 = _mm256_set1_pd(v2), w3 = _mm256_set1_pd(v3);
    int i = 0;
    for (; i + 4 <= k; i += 4) {
        const double *column = L + k + i * ld;
        __m256d c0 = _mm256_loadu_pd(column), c1 = _mm256_loadu_pd(column + ld);
        __m256d c2 = _mm256_loadu_pd(column + 2 * ld), c3 = _mm256_loadu_pd(column + 3 * ld);
        __m256d t0 = _mm256_unpacklo_pd(c0, c1), t1 = _mm256_unpackhi_pd(c0, c1);
        __m256d t2 = _mm256_unpacklo_pd(c2, c3), t3 = _mm256_unpackhi_pd(c2, c3);
        __m256d x = _mm256_loadu_pd(b + i);
        x = _mm256_sub_pd(x, _mm256_mul_pd(_mm256_permute2f128_pd(t1, t3, 0x31), w3));
        x = _mm256_sub_pd(x, _mm256_mul_pd(_mm256_permute2f128_pd(t0, t2, 0x31), w2));
        x = _mm256_sub_pd(x, _mm256_mul_pd(_mm256_permute2f128_pd(t1, t3, 0x20), w1));
        x = _mm256_sub_pd(x, _mm256_mul_pd(_mm256_permute2f128_pd(t0, t2, 0x20), w0));
        _mm256_storeu_pd(b + i, x);
    }
    if (i + 2 <= k) {   /* two entries: the transpose's halves */
        const double *column = L + k + i * ld;
        __m256d c0 = _mm256_loadu_pd(column), c1 = _mm256_loadu_pd(column + ld);
        __m256d t0 = _mm256_unpacklo_pd(c0, c1), t1 = _mm256_unpackhi_pd(c0, c1);
        __m128d x = _mm_loadu_pd(b + i);
        x = _mm_sub_pd(x, _mm_mul_pd(_mm256_extractf128_pd(t1, 1), _mm_set1_pd(v3)));
        x = _mm_sub_pd(x, _mm_mul_pd(_mm256_extractf128_pd(t0, 1), _mm_set1_pd(v2)));
        x = _mm_sub_pd(x, _mm_mul_pd(_mm256_castpd256_pd128(t1), _mm_set1_pd(v1)));
        x = _mm_sub_pd(x, _mm_mul_pd(_mm256_castpd256_pd128(t0), _mm_set1_pd(v0)));
        _mm_storeu_pd(b + i, x);
        i += 2;
    }
    fccqp_backward_above(L, ld, k, i, b, v0, v1, v2, v3);
}
#define FCCQP_BACKWARD_WIDE 1
#else
#define FCCQP_BACKWARD_WIDE 0
#endif

static void fccqp_backward_vector(const double *restrict L, int n, int ld, double *restrict b)
{
    int k = n;
#if FCCQP_BACKWARD_WIDE
    int wide = __builtin_cpu_supports("avx2");
#endif
    while (k >= 4) {
        k -= 4;   /* rows k + 3 (solved first) down to k */
        double v3 = b[k + 3] * (1.0 / L[k + 3 + (long)(k + 3) * ld]);
        b[k + 2] -= L[k + 3 + (long)(k + 2) * ld] * v3;
        b[k + 1] -= L[k + 3 + (long)(k + 1) * ld] * v3;
        b[k] -= L[k + 3 + (long)k * ld] * v3;
        double v2 = b[k + 2] * (1.0 / L[k + 2 + (long)(k + 2) * ld]);
        b[k + 1] -= L[k + 2 + (long)(k + 1) * ld] * v2;
        b[k] -= L[k + 2 + (long)k * ld] * v2;
        double v1 = b[k + 1] * (1.0 / L[k + 1 + (long)(k + 1) * ld]);
        b[k] -= L[k + 1 + (long)k * ld] * v1;
        double v0 = b[k] * (1.0 / L[k + (long)k * ld]);
        b[k] = v0;
        b[k + 1] = v1;
        b[k + 2] = v2;
        b[k + 3] = v3;
#if FCCQP_BACKWARD_WIDE
        if (wide) {
            fccqp_backward_above_avx2(L, ld, k, b, v0, v1, v2, v3);
            continue;
        }
#endif
        fccqp_backward_above(L, ld, k, 0, b, v0, v1, v2, v3);
    }
    for (k = k - 1; k >= 0; k--) {
        double v0 = b[k] * (1.0 / L[k + (long)k * ld]);
        b[k] = v0;
        for (int i = 0; i < k; i++)
            b[i] -= L[k + (long)i * ld] * v0;
    }
}


/* fccqp_abs_max: the largest |v[i]| of n entries (0 for none), NaN entries skipped as
 * _dense.inf_norm skips them (maxpd keeps its second operand, the running maximum, where
 * the first is NaN): the same value in any order, a maximum rounds nothing. Four entries
 * a compare where the CPU has AVX2, against inf_norm's compare and branch an entry: the
 * polish's KKT residual norm (polish_kkt.kkt_residual, about 90 entries on anymal_c). */
static inline double fccqp_abs_max_one(double a, double m)
{
    return fabs(a) > m ? fabs(a) : m;
}

#if defined(__x86_64__) && (defined(__GNUC__) || defined(__clang__))
__attribute__((target("avx2")))
static double fccqp_abs_max_wide(const double *restrict v, long n)
{
    __m256d sign = _mm256_set1_pd(-0.0), m = _mm256_setzero_pd();
    double lanes[4], out;
    long i = 0;
    for (; i + 4 <= n; i += 4)
        m = _mm256_max_pd(_mm256_andnot_pd(sign, _mm256_loadu_pd(v + i)), m);
    _mm256_storeu_pd(lanes, m);
    out = fccqp_abs_max_one(lanes[1], lanes[0]);
    out = fccqp_abs_max_one(lanes[2], out);
    out = fccqp_abs_max_one(lanes[3], out);
    for (; i < n; i++)
        out = fccqp_abs_max_one(v[i], out);
    return out;
}
#endif

static inline double fccqp_abs_max(const double *restrict v, long n)
{
    double out = 0.0;
#if defined(__x86_64__) && (defined(__GNUC__) || defined(__clang__))
    if (__builtin_cpu_supports("avx2"))
        return fccqp_abs_max_wide(v, n);
#endif
    for (long i = 0; i < n; i++)
        out = fccqp_abs_max_one(v[i], out);
    return out;
}

#endif
