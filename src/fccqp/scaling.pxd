# cython: language_level=3
from fccqp._types cimport Cones

cdef double equilibrate(double* P, double* q, double* A, double* b, Py_ssize_t n,
                        Py_ssize_t m, const Py_ssize_t* block_start,
                        const Py_ssize_t* block_dim, Py_ssize_t blocks, Py_ssize_t iterations,
                        double* D, double* E, double* d, double* e) noexcept nogil
cdef void scaled_norms(const double* P_s, const double* A_s, Py_ssize_t n, Py_ssize_t m,
                       double c, double* norms) noexcept nogil
cdef bint rescale(const double* P, const double* q, const double* A, const double* b,
                  Py_ssize_t n, Py_ssize_t m, const double* D, const double* E,
                  const double* reference, double* norms, double* P_s, double* q_s,
                  double* A_s, double* b_s, double* c) noexcept nogil
cdef void scale_start(const double* x, const double* y, const double* z, double rho,
                      const double* D, const double* E, double c, Py_ssize_t n, Py_ssize_t m,
                      Py_ssize_t s, const Py_ssize_t* constrained, const double* lo,
                      const double* hi, Cones cones, double* x_s, double* nu_s, double* y_s,
                      double* z_s) noexcept nogil
cdef void unscale(const double* x_s, const double* nu_s, const double* y_s, const double* D,
                  const double* E, double c, Py_ssize_t n, Py_ssize_t m, Py_ssize_t s,
                  const Py_ssize_t* constrained, double* x, double* y,
                  double* z) noexcept nogil
