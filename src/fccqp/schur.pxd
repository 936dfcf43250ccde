# cython: language_level=3
from fccqp._types cimport Problem

cdef struct Schur:
    # Cholesky factors of H = P + R (rows in `order`) and of S = A H^-1 A'.
    int n, m
    double* L            # n x n, Fortran
    double* LS           # m x m, Fortran
    double* Y            # n x m, Fortran: L^-1 A' (rows in order)
    const Py_ssize_t* base_order   # free entries first, the s constrained entries last
    Py_ssize_t* order    # base_order with the diagonal free entries moved behind the others
    int dense            # rows of the dense leading block of L; a diagonal tail follows
    bint free_ready      # the free rows of L and Y and G hold for this run's P and A
    double* G            # m x m, Fortran: Y_F' Y_F over the free rows (diagonal-tail split)
    double free_largest  # largest |entry| of H and A over the free rows (with free_ready)
    char* coupled        # n scratch: which rows of P have entries off the diagonal
    double* perm         # n scratch
    double* dx           # n scratch
    double* r            # n scratch
    double* ATnu         # n scratch
    double* dnu          # m scratch
    double* Ax           # m scratch
    double* X            # n x s scratch (unit columns)
    double* Wnu          # m x s scratch (unit columns; on the diagonal tail W_nu transposed)
    double* M            # s x s scratch (convexity test)
    int* nonzeros        # n x m: where constrained row j of Y can be nonzero, at j * m
    int* nonzero_count   # n: how many such places each constrained row has
    double* T            # m x m scratch: the constrained rows' share of S (zero between uses)
    double* tail_values  # m scratch: one row's nonzeros of Y

cdef void mark_coupled(const double* P, Py_ssize_t n, char* coupled) noexcept nogil
cdef bint schur_factor(Schur* f, const Problem* p, const double* rho_vec) noexcept nogil
cdef bint schur_certifies_convexity(Schur* f, const Problem* p, const double* rho_vec,
                                    double sigma) noexcept nogil
cdef void schur_solve_once(Schur* f, const Problem* p, const double* rhs,
                           double* sol) noexcept nogil
cdef void schur_solve(Schur* f, const Problem* p, const double* rho_vec, const double* rhs,
                      double* sol) noexcept nogil
cdef void schur_unit_columns(Schur* f, const Problem* p, double* W, double* W_S) noexcept nogil
