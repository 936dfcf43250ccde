# cython: language_level=3, boundscheck=False, wraparound=False, cdivision=True, initializedcheck=False
"""The ``SPARSE_LDL`` backend of :mod:`fccqp.kkt`: the compiled core's calls into
:class:`fccqp.sparse_kkt.SparseKKT` (``qdldl`` through its Python API).

``handle`` is the workspace's ``SparseKKT`` (a ``PyObject*`` that the workspace owns;
see :mod:`fccqp.workspace_arrays`). Each call takes the GIL for the factorization or
the refined solve: ``qdldl``'s Python API costs about 10 us a call, against
factorizations and solves of milliseconds at the sizes this backend serves (the KKT
matrix above ``fccqp.settings.MAX_DENSE_KKT_ROWS`` rows), which is why it is not
linked as a C library (``notes/one-algorithm.md``).
"""

import numpy as np

from fccqp.sparse_equalities import hold_equalities
from fccqp.sparse_kkt import FactorizationError


cdef int sparse_factor(void* handle, Py_ssize_t s, double sigma,
                       const double* rho_vec) noexcept nogil:
    """Factor the KKT matrix for ``sigma`` and the ``s`` penalties ``rho_vec``; the number
    of negative pivots (its inertia), or -1 when ``qdldl`` broke down."""
    with gil:
        rho = np.asarray(<double[:s]><double*>rho_vec) if s else np.empty(0)
        try:
            return (<object>handle).factor(sigma, rho)
        except FactorizationError:
            return -1


cdef void sparse_solve(void* handle, Py_ssize_t N, const double* rhs, double* sol) noexcept nogil:
    """``sol`` := the refined solution for ``rhs`` (``N = n + m`` entries each)."""
    with gil:
        np.asarray(<double[:N]>sol)[:] = (<object>handle).solve(
            np.asarray(<double[:N]><double*>rhs))


cdef void sparse_hold_equalities(void* handle, Py_ssize_t n, Py_ssize_t m, double* x,
                                 const double* b) noexcept nogil:
    """Project ``x`` (``n`` scaled entries) onto ``A x = b`` over the handle's scaled
    ``A`` (:func:`fccqp.sparse_equalities.hold_equalities`)."""
    with gil:
        kkt = <object>handle
        hold_equalities(kkt.A, kkt.E, np.asarray(<double[:n]>x),
                        np.asarray(<double[:m]><double*>b))


cdef bint sparse_gram_factor(void* handle) noexcept nogil:
    """Factor ``A A'`` of the handle's scaled ``A``, regularized
    (:meth:`fccqp.sparse_kkt.SparseKKT.factor_gram`); False when that fails."""
    with gil:
        return (<object>handle).factor_gram()


cdef void sparse_gram_solve(void* handle, Py_ssize_t m, double* v) noexcept nogil:
    """``v`` (``m`` entries) := the solve of the factor of :func:`sparse_gram_factor`
    for ``v``."""
    with gil:
        view = np.asarray(<double[:m]>v)
        view[:] = (<object>handle).solve_gram(view)


cdef bint sparse_column_gram_factor(void* handle, Py_ssize_t m, double* rows) noexcept nogil:
    """Factor the handle's Gram matrix with the columns' scale taken out, ``rows`` (``m``
    entries) := its row norms (:meth:`fccqp.sparse_kkt.SparseKKT.factor_column_gram`);
    False when that fails."""
    with gil:
        return (<object>handle).factor_column_gram(np.asarray(<double[:m]>rows))


cdef void sparse_column_gram_solve(void* handle, Py_ssize_t m, double* v) noexcept nogil:
    """``v`` (``m`` entries) := the solve of the factor of
    :func:`sparse_column_gram_factor` for ``v``."""
    with gil:
        view = np.asarray(<double[:m]>v)
        view[:] = (<object>handle).solve_column_gram(view)
