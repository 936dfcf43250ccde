# cython: language_level=3
"""C-level views of the problem and the cone blocks, shared by the compiled kernels.

The kernels take raw pointers into arrays that the Python layer allocated once per
problem structure (:class:`fccqp.admm.Workspace`): nothing is allocated in a solve.
``P`` and ``A`` are :c:type:`fccqp.matrices.Matrix`: the algorithm reads them through
that contract's operations.
"""

from fccqp.matrices cimport Matrix

cdef struct Cones:
    # Disjoint cone blocks of the constrained-entry vector; fccqp.cone_dispatch lists the
    # kinds and their operations.
    Py_ssize_t count
    const Py_ssize_t* kind      # kind code (fccqp.cone_dispatch, fccqp.cones.KINDS)
    const Py_ssize_t* offset    # into the constrained-entry vector, not into x
    const Py_ssize_t* dim
    const double* mu            # a scalar parameter per cone: the friction coefficient
    const double* normal        # count x 3, a vector parameter: the unit normal of a friction cone


cdef struct Problem:
    # The equilibrated problem min 1/2 x'Px + q'x  s.t.  Ax = b, x_S in C (see scaling).
    Py_ssize_t n, m, s          # variables, equality rows, constrained entries
    Matrix P                    # n x n, symmetric
    double* q
    Matrix A                    # m x n
    double* b
    const Py_ssize_t* constrained   # the s entries S of x with a bound or in a cone
    const char* in_cone         # s flags: the constrained entry belongs to a cone block
    double* lo                  # bounds of x_S (s entries, +-inf where absent)
    double* hi
    double* span                # m: range of each row's A x over the box (termination.row_spans)
    Cones cones
    double* D                   # x = D x_scaled
    double* E                   # equality rows were multiplied by E
    double c                    # the cost was multiplied by c


cdef struct Iterates:
    # ADMM's iterate on the scaled problem: x (n), nu (m), slack z and multiplier y (s),
    # their values before the last step, and the penalty per constrained entry.
    double* x
    double* nu
    double* z
    double* y
    double* x_prev
    double* nu_prev
    double* z_prev
    double* y_prev
    double* relaxed     # s scratch: the over-relaxed x_S
    double* rho_vec
