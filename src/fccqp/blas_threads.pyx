# cython: language_level=3
"""Single-threaded BLAS for the duration of a solve, whatever the process's setting.

The compiled core calls scipy's OpenBLAS (through ``scipy.linalg.cython_lapack`` and
``cython_blas``). At our sizes several of those calls go multithreaded (a triangular
solve with many right-hand sides from 1024 entries, ``dsyrk`` from order 76,
``dpotrf`` from order 128), and on a loaded machine a multithreaded call waits for a
worker the scheduler does not run: 28-226 ms instead of 0.02-0.4 ms, measured on 2
cores with three busy processes (notes in docs/performance.md). So each solve sets
OpenBLAS to one thread on entry and restores the previous count on exit: two calls of
about 20 ns through function pointers found with ``dlsym`` in the library that
``cython_lapack`` links, so nothing is linked at build time. A nesting counter,
changed with the GIL held, makes concurrent solves in several Python threads restore
the count once. While a solve runs, BLAS calls of the user's other threads run
single-threaded too (the count is process-wide). Where no OpenBLAS setter is found
(another BLAS, Windows), nothing is changed: :data:`GUARD` says which.
"""

import importlib

cdef extern from *:
    """
    #ifdef _WIN32
    static void* fccqp_find_symbol(const char* path, const char* name) { return 0; }
    #else
    #include <dlfcn.h>
    #ifndef RTLD_NOLOAD
    #define RTLD_NOLOAD 0
    #endif
    static void* fccqp_find_symbol(const char* path, const char* name) {
        void* handle = dlopen(path, RTLD_NOW | RTLD_LOCAL | RTLD_NOLOAD);
        return handle ? dlsym(handle, name) : 0;
    }
    #endif
    """
    void* fccqp_find_symbol(const char* path, const char* name)

ctypedef void (*set_threads_t)(int) noexcept nogil
ctypedef int (*get_threads_t)() noexcept nogil

cdef set_threads_t _set = NULL
cdef get_threads_t _get = NULL
cdef int _depth = 0
cdef int _saved = 1

_NAMES = (
    (b"scipy_openblas_set_num_threads", b"scipy_openblas_get_num_threads"),  # PyPI wheels
    (b"openblas_set_num_threads", b"openblas_get_num_threads"),  # a system OpenBLAS
)


def _load():
    global _set, _get
    # import_module, not "import scipy.linalg.cython_lapack": the attribute walk of the
    # latter would import all of scipy.linalg (see fccqp._scipy_lapack)
    path = importlib.import_module("scipy.linalg.cython_lapack").__file__.encode()
    for setter, getter in _NAMES:
        _set = <set_threads_t>fccqp_find_symbol(path, setter)
        _get = <get_threads_t>fccqp_find_symbol(path, getter)
        if _set != NULL and _get != NULL:
            return setter.decode()
    _set, _get = NULL, NULL
    return None


GUARD = _load()
"""Name of the OpenBLAS thread setter the guard uses, or None when there is none."""


cdef void enter() noexcept:
    """Set one thread (first entrant saves the count). Call with the GIL held."""
    global _depth, _saved
    if _set == NULL:
        return
    if _depth == 0:
        _saved = _get()
        if _saved != 1:
            _set(1)
    _depth += 1


cdef void leave() noexcept:
    """Restore the saved count (last to leave). Call with the GIL held."""
    global _depth
    if _set == NULL:
        return
    _depth -= 1
    if _depth == 0 and _saved != 1:
        _set(_saved)


def threads_inside_a_solve():
    """The OpenBLAS thread count a solve runs with (for tests), or -1 without a guard."""
    enter()
    try:
        return _get() if _get != NULL else -1
    finally:
        leave()


def threads():
    """The current OpenBLAS thread count, or -1 without a guard."""
    return _get() if _get != NULL else -1
