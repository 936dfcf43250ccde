# cython: language_level=3
from fccqp.matrices cimport Matrix


cdef class Held:
    cdef Matrix M
    cdef double[::1] values
    cdef Py_ssize_t[::1] colptr, rowind
