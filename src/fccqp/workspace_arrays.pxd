# cython: language_level=3
from fccqp.engine cimport Engine
from fccqp.polish_schur cimport PolishSchur


cdef class Arrays:
    cdef list kept
    cdef double* free        # the unused rest of the current chunk
    cdef Py_ssize_t left     # its doubles
    cdef double* new(self, Py_ssize_t size) except NULL
    cdef void* new_int(self, Py_ssize_t size) except NULL
    cdef double* adopt(self, object array) except NULL


cdef void common_arrays(Arrays a, Engine* e, Py_ssize_t memory, Py_ssize_t log_rows) except *
cdef void dense_arrays(Arrays a, Engine* e, Py_ssize_t* order) except *
cdef void polish_schur_arrays(Arrays a, PolishSchur* ps, Py_ssize_t n, Py_ssize_t m,
                              Py_ssize_t s) except *
cdef object csc_arrays(Arrays a, Engine* e, object patterns, object constrained)
