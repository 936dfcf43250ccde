# cython: language_level=3
from cpython.object cimport Py_buffer

cdef bint hold_float64(object array, Py_buffer* view, Py_ssize_t rows, Py_ssize_t columns,
                       bint writable) except -1
cdef bint hold_dense(object value, Py_buffer* view, Py_ssize_t rows, Py_ssize_t columns)
