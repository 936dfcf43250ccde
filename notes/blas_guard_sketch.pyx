# cython: language_level=3, boundscheck=False, wraparound=False
"""Proof of concept: find scipy's OpenBLAS thread setter from compiled code, no link."""
from posix.dlfcn cimport dlopen, dlsym, RTLD_NOW, RTLD_LOCAL
from libc.stdint cimport uint64_t
from posix.time cimport clock_gettime, timespec, CLOCK_MONOTONIC

cdef extern from "dlfcn.h":
    int RTLD_NOLOAD

ctypedef void (*set_t)(int) noexcept nogil
ctypedef int (*get_t)() noexcept nogil

cdef set_t _set = NULL
cdef get_t _get = NULL
cdef int _depth = 0
cdef int _saved = 0

def load(bytes path):
    """dlopen the already-loaded cython_lapack module and dlsym the setter/getter."""
    global _set, _get
    cdef void *h = dlopen(path, RTLD_NOW | RTLD_LOCAL | RTLD_NOLOAD)
    if h == NULL:
        return None
    for s, g in ((b"scipy_openblas_set_num_threads", b"scipy_openblas_get_num_threads"),
                 (b"openblas_set_num_threads", b"openblas_get_num_threads")):
        _set = <set_t>dlsym(h, s)
        _get = <get_t>dlsym(h, g)
        if _set != NULL and _get != NULL:
            return s.decode()
    _set = NULL
    _get = NULL
    return None

cdef inline void enter() noexcept nogil:
    global _depth, _saved
    if _set == NULL:
        return
    if _depth == 0:
        _saved = _get()
        if _saved != 1:
            _set(1)
    _depth += 1

cdef inline void leave() noexcept nogil:
    global _depth
    if _set == NULL:
        return
    _depth -= 1
    if _depth == 0 and _saved != 1:
        _set(_saved)

def current():
    return _get() if _get != NULL else -1

def inside():
    enter()
    try:
        return _get()
    finally:
        leave()

def cost(long loops):
    """ns per enter()+leave() pair."""
    cdef timespec a, b
    cdef long i
    clock_gettime(CLOCK_MONOTONIC, &a)
    with nogil:
        for i in range(loops):
            enter()
            leave()
    clock_gettime(CLOCK_MONOTONIC, &b)
    return ((b.tv_sec - a.tv_sec) * 1e9 + (b.tv_nsec - a.tv_nsec)) / loops
