# cython: language_level=3
"""The control loop's way through argument validation, compiled.

A controller calls :meth:`fccqp.Solver.solve` with the same kinds of arguments every
tick: six contiguous float64 arrays of the workspace's sizes and a list of cone specs
like the last one. :func:`dense_arguments` recognizes the arrays from their buffers
without converting them, :func:`cone_key` builds :func:`fccqp.cones.flatten_cones`'
memo key, :func:`same_cones` tells when the specs are those of the last solve and
:func:`upright_friction_arrays` flattens new friction values (a contact change); they
decide what :func:`fccqp.problem.convert`'s fast path and the memo's key
function in Python did, without the interpreter's per-attribute work. After the compiled
solve the interpreter runs from cold caches, and there the two Python versions took 6.7
us and 8.0 us of a 150 us go2 tick (in flow, medians of interleaved rounds). Anything
they do not recognize takes the Python path, which converts or raises the error that
names the argument.
"""

from cpython.buffer cimport (PyBUF_C_CONTIGUOUS, PyBUF_FORMAT, PyBUF_WRITABLE, PyBuffer_Release,
                            PyObject_GetBuffer)

from libc.math cimport INFINITY, fabs
from libc.stdint cimport int64_t

cimport numpy as cnp

import numpy as np
from numpy import ndarray

cnp.import_array()

cdef object _FRICTION = None
cdef object _SECOND_ORDER = None


cdef inline void _load_kinds():
    """Look the cone classes up once: fccqp.cones imports this module."""
    global _FRICTION, _SECOND_ORDER
    if _FRICTION is None:
        from fccqp.cones import FrictionCone, SecondOrderCone
        _FRICTION, _SECOND_ORDER = FrictionCone, SecondOrderCone


cdef extern from "Python.h":
    ctypedef struct PyBufferProcs:
        void* bf_releasebuffer
    ctypedef struct BufferType "PyTypeObject":
        PyBufferProcs* tp_as_buffer

cdef extern from *:
    """
    /* view->obj = a new reference to owner (Cython would release view's old, unset obj) */
    static inline void fccqp_buffer_owner(Py_buffer *view, PyObject *owner)
    {
        Py_INCREF(owner);
        view->obj = owner;
    }
    """
    void fccqp_buffer_owner(Py_buffer* view, object owner)


cdef bint _NDARRAY_RELEASES = (<BufferType*>ndarray).tp_as_buffer.bf_releasebuffer != NULL
"""Whether numpy's arrays release their buffers themselves (then every hold asks numpy)."""


cdef enum:
    # _hold_plain_ndarray's answers
    PLAIN_HELD = 1
    PLAIN_REFUSED = 0   # a plain array numpy would give a buffer of, of another shape
    PLAIN_ASK = -1      # anything else: numpy's buffer decides


cdef int _hold_plain_ndarray(object array, Py_buffer* view, Py_ssize_t rows,
                             Py_ssize_t columns, bint writable):
    """Fill ``view`` from the fields of ``array`` and return ``PLAIN_HELD`` when it is a
    numpy array (not a subclass) that :func:`hold_float64` accepts, on which numpy's own
    buffer would succeed: C-contiguous native float64 of the shape asked for and, when
    writable, writeable and owning its data (a view may warn on write, which numpy's
    buffer does). ``PLAIN_REFUSED``, holding nothing, for such an array of another
    number of dimensions or shape, which numpy's buffer would give and
    :func:`hold_float64` then refuse; ``PLAIN_ASK`` for anything else. ``PyBuffer_Release``
    releases a held view as it releases numpy's (numpy keeps no per-buffer state:
    ``_NDARRAY_RELEASES``). numpy's buffer costs about 500 instructions a hold (its cached
    format record), and a solve holds 10 to 13 arrays, a contact switch 23: 13.9k of go2's
    contact tick (callgrind). A switch tries the arrays against workspaces of other sizes
    first, and there numpy's buffer code, which no other tick runs, took about 30 cache
    lines of code fetched cold (callgrind's cache model, notes/performance-history.md,
    "contactentry")."""
    if _NDARRAY_RELEASES or type(array) is not ndarray:
        return PLAIN_ASK
    cdef cnp.ndarray a = <cnp.ndarray>array
    cdef int flags = cnp.PyArray_FLAGS(a), ndim = cnp.PyArray_NDIM(a)
    cdef cnp.npy_intp* dims = cnp.PyArray_DIMS(a)
    if not (flags & cnp.NPY_ARRAY_C_CONTIGUOUS and cnp.PyArray_TYPE(a) == cnp.NPY_DOUBLE
            and cnp.PyArray_ISNOTSWAPPED(a)):
        return PLAIN_ASK
    if writable and not (flags & cnp.NPY_ARRAY_WRITEABLE and flags & cnp.NPY_ARRAY_OWNDATA):
        return PLAIN_ASK
    if not (ndim == (1 if columns < 0 else 2) and dims[0] == rows
            and (columns < 0 or dims[1] == columns)):
        return PLAIN_REFUSED
    fccqp_buffer_owner(view, array)
    view.buf = cnp.PyArray_DATA(a)
    view.len = rows * (1 if columns < 0 else columns) * 8
    view.itemsize = 8
    view.readonly = not (flags & cnp.NPY_ARRAY_WRITEABLE)
    view.ndim = ndim
    view.format = b"d"
    view.shape = view.strides = view.suboffsets = NULL
    view.internal = NULL
    return PLAIN_HELD


cdef bint hold_float64(object array, Py_buffer* view, Py_ssize_t rows, Py_ssize_t columns,
                       bint writable) except -1:
    """Hold ``array``'s C-contiguous buffer (writable if asked) in ``view`` and return True
    when it is native float64 of ``rows`` entries, a ``rows x columns`` matrix when
    ``columns >= 0``; otherwise release it and return False. Raises where ``array`` has
    no such buffer (``TypeError``, ``BufferError``). The one rule for
    :func:`dense_arguments` and the buffers ``fccqp.admm.Workspace.solve`` holds; a
    plain numpy array is held, or refused for its shape, from its fields
    (:func:`_hold_plain_ndarray`)."""
    cdef int plain = _hold_plain_ndarray(array, view, rows, columns, writable)
    if plain != PLAIN_ASK:
        return plain == PLAIN_HELD
    PyObject_GetBuffer(array, view,
                       PyBUF_C_CONTIGUOUS | PyBUF_FORMAT | (PyBUF_WRITABLE if writable else 0))
    if (view.itemsize == 8 and view.format != NULL and view.format[0] == b"d"
            and view.format[1] == 0 and view.ndim == (1 if columns < 0 else 2)
            and view.shape[0] == rows and (columns < 0 or view.shape[1] == columns)):
        return True
    PyBuffer_Release(view)
    return False


cdef bint hold_dense(object value, Py_buffer* view, Py_ssize_t rows, Py_ssize_t columns):
    """Hold the buffer of ``value`` in ``view`` and return True when it is a numpy array
    (not a subclass, as :func:`fccqp.problem.convert` passes through) that
    :func:`hold_float64` accepts; False, holding nothing, otherwise."""
    if type(value) is not ndarray:
        return False
    try:
        return hold_float64(value, view, rows, columns, False)
    except (TypeError, ValueError, BufferError):   # no buffer, or not a contiguous one
        return False


cdef bint _is_dense(object value, Py_ssize_t rows, Py_ssize_t columns):
    """Whether :func:`hold_dense` would hold ``value`` (nothing stays held)."""
    cdef Py_buffer view
    if not hold_dense(value, &view, rows, columns):
        return False
    PyBuffer_Release(&view)
    return True


def dense_vector_within(value, Py_ssize_t size, double limit):
    """True when ``value`` is a vector that :func:`hold_dense` accepts, of ``size``
    entries, none beyond ``limit`` in magnitude (a NaN is not within it): a caller's
    guess as :func:`fccqp.solver._vector` would return it. Its numpy reduction took
    about 4 us a vector (``max`` with ``initial``), three per guess."""
    return vector_within(value, size, limit)


cdef bint vector_within(object value, Py_ssize_t size, double limit):
    """:func:`dense_vector_within`'s check, without its Python call."""
    cdef Py_buffer view
    cdef const double* entries
    cdef Py_ssize_t i
    cdef bint within = True
    if not hold_dense(value, &view, size, -1):
        return False
    entries = <const double*>view.buf
    for i in range(size):
        if not fabs(entries[i]) <= limit:
            within = False
            break
    PyBuffer_Release(&view)
    return within


def dense_arguments(P, q, A, b, lb, ub, Py_ssize_t n, Py_ssize_t m):
    """True when ``P, q, A, b, lb, ub`` are C-contiguous float64 arrays of the shapes
    ``(n, n), (n,), (m, n), (m,), (n,), (n,)``: what :func:`fccqp.problem.convert`
    would return unchanged. Their numbers are checked by the solve."""
    return dense_shapes(P, q, A, b, lb, ub, n, m)


cdef bint dense_shapes(object P, object q, object A, object b, object lb, object ub,
                       Py_ssize_t n, Py_ssize_t m):
    """:func:`dense_arguments`'s check, without its Python call."""
    return (_is_dense(P, n, n) and _is_dense(q, n, -1) and _is_dense(A, m, n)
            and _is_dense(b, m, -1) and _is_dense(lb, n, -1) and _is_dense(ub, n, -1))


cdef tuple _one_key(object cone):
    """One spec's values and the types behind them (see :func:`cone_key`). The two
    kinds of the control loops are spelled out; any other spec (a kind of
    :data:`fccqp.cones.KINDS` without a line here) gives its fields' values and types
    in order, or itself where it has no ``__dict__`` (then :func:`fccqp.cones.flatten_cones`
    rejects it)."""
    cdef object kind = type(cone), start, mu, normal, dim
    if isinstance(cone, _FRICTION):
        start, mu, normal = cone.start, cone.mu, cone.normal
        if type(normal) is tuple:
            return kind, start, type(start), mu, type(mu), normal, tuple(map(type, normal))
        return kind, start, type(start), mu, type(mu), normal, type(normal)
    if isinstance(cone, _SECOND_ORDER):
        start, dim = cone.start, cone.dim
        return kind, start, type(start), dim, type(dim)
    try:
        fields = vars(cone)
    except TypeError:
        return kind, cone
    return kind, tuple(fields.items()), tuple(
        tuple(map(type, value)) if type(value) is tuple else type(value)
        for value in fields.values())


def cone_key(tuple cones, Py_ssize_t n):
    """``(n, key of each spec)``: the memo key of :func:`fccqp.cones.flatten_cones`.
    A spec's key holds its values and the types behind them, since specs that compare
    equal may differ in validity (``0.5 + 0j == 0.5``, ``2.0 == 2``). Hashing the key
    raises ``TypeError`` for an unhashable field (a numpy normal)."""
    _load_kinds()
    cdef list key = [n]
    for cone in cones:
        key.append(_one_key(cone))
    return tuple(key)


cdef inline bint _same_number(object a, object b):
    """Equal ints or equal floats (anything else, such as a numpy value that may change in
    place, is not recognized)."""
    return ((type(a) is float and type(b) is float) or (type(a) is int and type(b) is int)) \
        and a == b


cdef bint _same_normal(object a, object b):
    if a is None or b is None:
        return a is None and b is None
    if type(a) is not tuple or type(b) is not tuple or len(<tuple>a) != len(<tuple>b):
        return False
    for u, v in zip(<tuple>a, <tuple>b):
        if not _same_number(u, v):
            return False
    return True


def same_cones(cones, previous):
    """Whether the tuple ``cones`` holds specs of the same kinds and the same int and
    float values as the tuple ``previous`` (the last solve's, already validated): then
    its :func:`fccqp.cones.flatten_cones` is the last one, with no key to build and hash
    (a control loop rebuilds equal specs every tick; 3-5 us of a go2 tick in flow).
    False when unsure."""
    if type(cones) is not tuple or type(previous) is not tuple:
        return False
    cdef tuple now = <tuple>cones, before = <tuple>previous
    cdef Py_ssize_t k, count = len(now)
    if count != len(before):
        return False
    _load_kinds()
    for k in range(count):   # by index: zip's call and iteration took 1.4k instructions
        a, b = now[k], before[k]
        if type(a) is not type(b):
            return False
        if type(a) is _FRICTION:
            if not (_same_number(a.start, b.start) and _same_number(a.mu, b.mu)
                    and _same_normal(a.normal, b.normal)):
                return False
        elif type(a) is _SECOND_ORDER:
            if not (_same_number(a.start, b.start) and _same_number(a.dim, b.dim)):
                return False
        else:
            return False
    return True


def upright_friction_arrays(tuple cones, Py_ssize_t n):
    """``(kind, offset, dim, mu, normal)`` of :func:`fccqp.cones.flatten_cones` for
    ``cones`` that are all friction cones with an int ``start``, a float ``mu`` and no
    normal (the control loops' specs), checked as it checks them (a finite positive
    ``mu``, blocks inside ``x`` of ``n`` entries, no overlap); ``None`` for anything
    else, valid or not, which the Python flattening then takes and names. Its loop took
    14 us for four cones, paid on every new friction value (a contact change)."""
    _load_kinds()
    cdef Py_ssize_t k = len(cones), i, j, start
    cdef double mu
    # one block per dtype, read-only, its rows the arrays: two allocations, not five
    integers, reals = np.zeros((3, k), np.int64), np.zeros(4 * k)
    cdef int64_t[:, ::1] blocks = integers
    cdef double[::1] values = reals
    for i in range(k):
        cone = cones[i]
        if type(cone) is not _FRICTION or cone.normal is not None:
            return None
        given_start, given_mu = cone.start, cone.mu
        if type(given_start) is not int or type(given_mu) is not float:
            return None
        if not 0 <= given_start <= n - 3:   # compared as Python ints: no overflow
            return None
        start, mu = given_start, given_mu
        if not (mu > 0 and mu < INFINITY):
            return None
        for j in range(i):
            if blocks[1, j] < start + 3 and start < blocks[1, j] + 3:
                return None
        blocks[1, i], blocks[2, i] = start, 3
        values[i], values[k + 3 * i + 2] = mu, 1.0
    integers.flags.writeable = reals.flags.writeable = False
    return integers[0], integers[1], integers[2], reals[:k], reals[k:].reshape(k, 3)
