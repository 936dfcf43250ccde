# cython: language_level=3
from cpython.object cimport Py_buffer

cdef bint hold_float64(object array, Py_buffer* view, Py_ssize_t rows, Py_ssize_t columns,
                       bint writable) except -1
cdef bint hold_dense(object value, Py_buffer* view, Py_ssize_t rows, Py_ssize_t columns)
cdef bint dense_shapes(object P, object q, object A, object b, object lb, object ub,
                       Py_ssize_t n, Py_ssize_t m)
cdef bint vector_within(object value, Py_ssize_t size, double limit)
cdef bint hold_within(object value, Py_buffer* view, Py_ssize_t size, double limit)
cdef bint upright_friction_on(object cones, Py_ssize_t count, const Py_ssize_t* kind,
                              const Py_ssize_t* start, double* mu, double* normal)
