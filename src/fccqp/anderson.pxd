# cython: language_level=3
from fccqp._types cimport Iterates

cdef struct Anderson:
    # Type-II Anderson acceleration of the map (z, y / rho) -> T(z, y / rho).
    int capacity            # memory (pairs of differences kept)
    double* dgf             # capacity x 2s, row per slot: dG + dF, the step's columns
    double* df              # capacity x 2s, row per slot: differences of f = T(g) - g
    double* g               # 2s: the previous g
    double* f               # 2s: the previous f
    double* g_new           # 2s scratch
    double* f_new           # 2s scratch
    double* plain           # 2s + 1: T of the last accelerated point, and its |f|
    double* products        # capacity x capacity: products[i, l] = df_i'df_l of stored slots
    double* gram            # capacity x capacity scratch
    double* gamma           # capacity scratch
    long stored             # pairs stored so far
    bint have_previous      # g and f hold the previous point
    bint accelerated        # the current point was extrapolated
    long wait               # plain steps left before accelerating again
    long rejections

cdef void anderson_reset(Anderson* a, bint keep_rejections) noexcept nogil
cdef void anderson_step(Anderson* a, Iterates* it, Py_ssize_t s) noexcept nogil
cdef bint solve_small_spd(double* M, double* b, int k) noexcept nogil
