# cython: language_level=3
from fccqp._types cimport Iterates, Problem
from fccqp.kkt cimport KKT

cdef struct Reduced:
    # The KKT response on the constrained entries, tabulated once per factorization.
    double* W       # (n + m) x s, Fortran: responses to unit right-hand sides on S
    double* W_S     # s x s, row-major: the rows of W on S
    double* base    # n + m: the response to (-q, b)
    double* u       # x = base + W u (u relaxed like x)
    double* u_prev
    double* v       # nu = (base + W v)_nu, v = rho z - y of the last step
    double* v_prev
    double* xs      # s scratch
    Py_ssize_t hint # the entry that failed near_convergence's gate last (tested first)
    bint x_prev_due # x_prev, nu_prev not formed since the last materialize
    bint nu_prev_due

cdef bint reduced_table(Reduced* r, KKT* k, const Problem* p, const double* rho_vec) noexcept nogil
cdef void reduced_start(Reduced* r, const Problem* p, Iterates* it) noexcept nogil
cdef void reduced_step(Reduced* r, const Problem* p, Iterates* it, double alpha,
                       bint relax_x) noexcept nogil
cdef bint near_convergence(Reduced* r, const Problem* p, Iterates* it, double eps_p,
                           double eps_d) noexcept nogil
cdef void materialize(Reduced* r, const Problem* p, Iterates* it) noexcept nogil
cdef void materialize_x_prev(Reduced* r, const Problem* p, Iterates* it) noexcept nogil
cdef void materialize_nu_prev(Reduced* r, const Problem* p, Iterates* it) noexcept nogil
cdef void reduced_rebase(Reduced* r, const Problem* p, const double* old_rho,
                         const double* new_rho) noexcept nogil
