# cython: language_level=3, boundscheck=False, wraparound=False, cdivision=True, initializedcheck=False
"""The one compiled call per solve: :class:`Workspace`.

:class:`Workspace` holds every array a solve touches, allocated once per problem
structure, and the C state of the solver (:c:type:`fccqp.engine.Engine`, one struct per
role); :meth:`Workspace.solve` validates the numbers, then scales, runs and unscales
(:mod:`fccqp.scaled_run`) without allocating and without the GIL. The iteration is
:mod:`fccqp.iteration`; its factorizations :mod:`fccqp.factorization`, its verdicts
:mod:`fccqp.verdict`, the acceptance of a polished or restored point
:mod:`fccqp.acceptance`, the rho rule :mod:`fccqp.rho_rule`.
"""

import numpy as np

from fccqp.cones import FrictionCone
from fccqp.result import Result
from fccqp.status import Status

cimport numpy as cnp
from cpython.buffer cimport PyBuffer_Release
from cpython.object cimport PyObject_GenericSetAttr
from libc.math cimport INFINITY, fabs, isfinite
from libc.string cimport memcpy

from fccqp cimport engine
from fccqp._dense cimport copy, fill
from fccqp._types cimport Cones, Problem
from fccqp.anderson cimport anderson_reset
from fccqp.blas_threads cimport enter, leave
from fccqp.certificates cimport CERTIFIED, primal_candidate
from fccqp.engine cimport CONE_ENTRY, Clock, Engine, Run, fccqp_now
from fccqp.cone_dispatch cimport FRICTION
from fccqp.fast_checks cimport hold_dense, hold_float64
from fccqp.kkt cimport AUTO, LDL_FULL, LDL_REDUCED, SCHUR_REDUCED, SPARSE_LDL
from fccqp.matrices cimport Matrix, csc, mark_diagonal_tail
from fccqp.scaled_run cimport scaled_run, unscaled_answer
from fccqp.termination cimport Residuals
from fccqp.tuning cimport FIXED_RHO_SCALE, MAX_ENTRY, RESERVE_DECAY, RESTART_MIN_ITER
from fccqp.validation cimport (BOUNDED, FIXED_BOUND, NEW_PATTERN, SCAN_OK, UNBOUNDED, Finding,
                               bound_kind, scan_and_copy, scan_and_copy_csc)
from fccqp.verdict cimport unbounded
from fccqp.workspace_arrays cimport Arrays, common_arrays, csc_arrays, dense_arrays

cnp.import_array()

# Run codes, mapped to fccqp.Status in fccqp.solver (one table).
SOLVED, SOLVED_INACCURATE = engine.SOLVED, engine.INACCURATE
MAX_ITER, TIME_LIMIT = engine.MAX_ITER, engine.TIME_LIMIT
PRIMAL_INFEASIBLE, DUAL_INFEASIBLE = engine.PRIMAL_INFEASIBLE, engine.DUAL_INFEASIBLE
NUMERICAL_ERROR = engine.NUMERICAL_ERROR
NOT_CONVEX_CODE = engine.NOT_CONVEX_QP
"""The KKT inertia shows that the QP is not convex."""
BAD_DATA = engine.BAD_NUMBERS
"""The validation scan found bad numbers (see ``Workspace.finding``)."""
STRUCTURE_CHANGED = engine.NEW_STRUCTURE
"""The bounds no longer have the structure the workspace was made for (another set of
constrained or fixed entries, or a bound on a cone entry), or compressed-column ``P``
and ``A`` another pattern: the caller rescans them
(:func:`fccqp.validation.structure_scan`) and makes a new workspace."""
NOT_DENSE = -4
"""An input array is not a C-contiguous float64 numpy array of the workspace's shape
(:meth:`Workspace.solve` with ``checked=False``): the caller converts the arguments."""
FITS_CURRENT = True
""":meth:`Workspace.switch`'s answer when the arguments fit the workspace's own shapes."""

cdef enum:
    # Workspace.doubt's bits
    PRIMAL_LENT = 1
    DUAL_LENT = 2
DOUBT_PRIMAL, DOUBT_DUAL = PRIMAL_LENT, DUAL_LENT
"""``Workspace.doubt``'s bits: the set test, the dual test passed on lent tolerances."""
STATUS_BY_CODE = {
    SOLVED: Status.SOLVED,
    SOLVED_INACCURATE: Status.SOLVED_INACCURATE,
    MAX_ITER: Status.MAX_ITER_REACHED,
    TIME_LIMIT: Status.TIME_LIMIT_REACHED,
    PRIMAL_INFEASIBLE: Status.PRIMAL_INFEASIBLE,
    DUAL_INFEASIBLE: Status.DUAL_INFEASIBLE,
    NUMERICAL_ERROR: Status.NUMERICAL_ERROR,
}
"""The run codes as statuses: the only place they meet."""

BACKENDS = {"schur_reduced": SCHUR_REDUCED, "ldl_reduced": LDL_REDUCED, "ldl_full": LDL_FULL,
            "auto": AUTO, "sparse": SPARSE_LDL}
"""``Settings.kkt_backend`` names and their codes (see :mod:`fccqp.kkt`)."""
BACKEND_NAMES = {code: name for name, code in BACKENDS.items()}


cdef inline cnp.ndarray _empty(Py_ssize_t size):
    """``np.empty(size)`` through numpy's C API: the call through the module's attribute
    and its argument parsing took about 1k instructions an array, three a solve."""
    cdef cnp.npy_intp dims[1]
    dims[0] = size
    return cnp.PyArray_EMPTY(1, dims, cnp.NPY_DOUBLE, 0)


cdef cnp.ndarray _contiguous(object values, int typenum):
    """``values`` as a C-contiguous numpy array of ``typenum``: itself when it is one (a
    uint8 array stands for a bool one), else a converted copy. A new workspace reads
    seven such arrays; ``np.array`` and a typed memoryview each took about 5k
    instructions of a go2 workspace's 123k (callgrind)."""
    cdef int kind
    if cnp.PyArray_Check(values) and cnp.PyArray_IS_C_CONTIGUOUS(values):
        kind = cnp.PyArray_TYPE(values)
        if kind == typenum or (typenum == cnp.NPY_BOOL and kind == cnp.NPY_UINT8):
            return values
    return np.ascontiguousarray(values, dtype=cnp.PyArray_DescrFromType(typenum))


cdef double* _copy(Arrays a, cnp.ndarray values, Py_ssize_t size) except NULL:
    """A copy, carved from ``a``, of the first ``size`` entries of ``values`` (8-byte
    entries: doubles or intp; at least one entry carved)."""
    cdef double* out = a.new(size)
    if cnp.PyArray_SIZE(values) < size:
        raise ValueError("cone arrays of different lengths")
    if size:
        memcpy(out, cnp.PyArray_DATA(values), size * sizeof(double))
    return out


cdef Py_ssize_t* _base_order(Arrays a, Py_ssize_t n, const Py_ssize_t* constrained,
                             Py_ssize_t s, object order) except NULL:
    """The Schur backend's base order of the ``n`` entries, carved from ``a``: ``order``
    copied, or where it is None the free entries ascending, then the ``s`` entries of
    ``constrained`` (:func:`fccqp.schur.ordering`, whose numpy calls took 35k
    instructions of a go2 workspace's 123k)."""
    cdef Py_ssize_t* out = <Py_ssize_t*>a.new_int(n)
    cdef char* taken
    cdef Py_ssize_t k, lead = 0
    if order is not None:
        held = _contiguous(order, cnp.NPY_INTP)
        return <Py_ssize_t*>_copy(a, held, n)
    taken = <char*>a.new(n)
    for k in range(s):
        taken[constrained[k]] = 1
    for k in range(n):
        if not taken[k]:
            out[lead] = k
            lead += 1
    for k in range(s):
        out[lead + k] = constrained[k]
    return out


cdef object _new_result(dict fields):
    """A :class:`fccqp.Result` whose attributes are ``fields`` (all of them), as
    ``Result._of`` makes one but without an interpreted frame: the dict becomes the
    result's own, not copied into it."""
    result = object.__new__(Result)
    PyObject_GenericSetAttr(result, "__dict__", fields)
    return result


cdef class Workspace:
    """Every array of a solve, allocated once for a problem structure.

    The structure is the sizes, the constrained entries, the entries with ``lb == ub``
    and the cone blocks; :class:`fccqp.Solver` builds a new workspace when it changes.
    Between solves the workspace keeps the user's last ``P`` and ``A`` (to detect
    reuse), their scaling and factorization, and the last solution (for a warm start).
    """

    cdef Arrays _arrays
    cdef Engine e
    cdef Finding found
    cdef object _sparse_kkt   # SPARSE_LDL's SparseKKT, which e.fact.kkt.sparse points to
    cdef readonly bint compressed
    """``P`` and ``A`` are held in compressed columns (the sparse backend)."""
    cdef readonly int doubt
    """The last result is solved or inaccurate only on tolerances its entries' own units
    do not give it: ``DOUBT_PRIMAL`` (a cone block or box entry off C by more than
    ``eps_abs + eps_rel`` times its own size), plus ``DOUBT_DUAL`` (the cost's terms below
    ``eps_abs``, where any point passes the dual test); 0 otherwise (see
    ``acceptance.user_residuals``). Then :class:`fccqp.Solver` asks the auxiliary QPs
    for a certificate."""
    cdef readonly bint converging
    """The last run stopped at ``max_iter`` while still converging: its distance to
    tolerance shrank by ``fccqp.tuning.CONVERGING`` over the last half of the cap."""
    cdef public bint arrived
    """Set by :class:`fccqp.Solver` when this workspace becomes current after a solve of
    another structure, cleared by each solve: a primal-dual guess given to the next
    solve was carried from that structure (a contact change), and its polish starts from
    nothing held (:func:`fccqp.acceptance._polish_start`)."""

    def __init__(self, Py_ssize_t n, Py_ssize_t m, constrained, cones, fixed, order,
                 settings, Py_ssize_t log_rows, patterns=None):
        """Allocate for ``n`` variables, ``m`` rows, the ``constrained`` entries (intp,
        ascending), ``cones`` (the tuple of :class:`fccqp.cones.ConeArrays`' arrays with
        offsets into ``constrained``), the boolean mask ``fixed`` of constrained entries
        with ``lb == ub`` (or its uint8 form), the Schur ``order`` (None: the free entries
        ascending, then ``constrained``, as :func:`fccqp.schur.ordering` gives it) and a
        :class:`fccqp.Settings`; copied into the workspace's own arrays. With
        ``patterns``, ``(P colptr, P rowind, A colptr, A rowind)``, ``P`` (its full
        symmetric pattern) and ``A`` are held in compressed columns and factored by
        ``SPARSE_LDL`` (``order`` is then unused); :meth:`solve` takes their values."""
        cdef Engine* e = &self.e
        cdef Arrays a = Arrays()
        self._arrays = a
        self.compressed = patterns is not None
        kind, offset, dim, mu, normal = cones
        held = [_contiguous(v, t) for v, t in zip(
            (constrained, kind, offset, dim, mu, normal, fixed),
            (cnp.NPY_INTP, cnp.NPY_INTP, cnp.NPY_INTP, cnp.NPY_INTP, cnp.NPY_DOUBLE,
             cnp.NPY_DOUBLE, cnp.NPY_BOOL))]
        cdef Py_ssize_t s = cnp.PyArray_SIZE(held[0]), count = cnp.PyArray_SIZE(held[1])
        cdef Py_ssize_t k, j
        cdef const char* fixed_v = <const char*>cnp.PyArray_DATA(held[6])
        if cnp.PyArray_SIZE(held[6]) != s:
            raise ValueError("a fixed mask of another size than the constrained entries")
        p = &e.prob
        p.n, p.m, p.s = n, m, s
        # private copies: update_cones writes into them, and the caller's arrays may be
        # shared (fccqp.cones memoizes one ConeArrays per distinct set of cones)
        cdef Py_ssize_t* c_view = <Py_ssize_t*>_copy(a, held[0], s)
        p.constrained = c_view if s else NULL
        p.cones.count = count
        p.cones.kind = <Py_ssize_t*>_copy(a, held[1], count)
        p.cones.offset = <Py_ssize_t*>_copy(a, held[2], count)
        p.cones.dim = <Py_ssize_t*>_copy(a, held[3], count)
        p.cones.mu, p.cones.normal = _copy(a, held[4], count), _copy(a, held[5], 3 * count)
        cdef Py_ssize_t* start_v = <Py_ssize_t*>a.new_int(count)
        for k in range(count):
            start_v[k] = c_view[p.cones.offset[k]]
        e.user.block_start = start_v
        cdef char* in_cone = <char*>a.new(s)
        for k in range(count):
            for j in range(p.cones.offset[k], p.cones.offset[k] + p.cones.dim[k]):
                in_cone[j] = 1
        p.in_cone = in_cone
        common_arrays(self._arrays, e, settings.anderson_memory, log_rows)
        if self.compressed:
            self._sparse_kkt = csc_arrays(self._arrays, e, patterns,
                                          np.array(held[0], dtype=np.intp))
        else:
            dense_arrays(self._arrays, e, _base_order(a, n, c_view, s, order))
        for k in range(s):
            e.fact.rho_scale[k] = FIXED_RHO_SCALE if fixed_v[k] else 1.0
            e.user.entry_kind[c_view[k]] = (CONE_ENTRY if in_cone[k] else
                                            FIXED_BOUND if fixed_v[k] else BOUNDED)
        anderson_reset(&e.aa, False)
        o = &e.opt
        o.rho, o.sigma, o.alpha = settings.rho, settings.sigma, settings.alpha
        o.eps_abs, o.eps_rel = settings.eps_abs, settings.eps_rel
        o.eps_prim_inf, o.eps_dual_inf = settings.eps_prim_inf, settings.eps_dual_inf
        o.time_limit = settings.time_limit
        o.adaptive_rho_tolerance = settings.adaptive_rho_tolerance
        o.max_iter, o.check_termination = settings.max_iter, settings.check_termination
        o.min_iter = settings.min_iter
        o.adaptive_rho_interval, o.scaling = settings.adaptive_rho_interval, settings.scaling
        o.adaptive_rho, o.restore_feasibility = settings.adaptive_rho, settings.restore_feasibility
        o.polish, o.polish_refine_iter = settings.polish, settings.polish_refine_iter
        o.backend, o.anderson_memory = BACKENDS[settings.kkt_backend], settings.anderson_memory
        e.prev.exists = e.user.has_matrices = e.fact.certified = e.scaling.done = False
        e.scaling.kept = e.scaling.other_done = False
        e.prev.has_rho = False
        e.prev.polished = e.prev.from_polished = e.equalities_missed = False
        e.prev.guessed = False
        e.unscaled.current = False
        e.fact.factored_rho = -1.0
        e.clock.final_reserve = e.clock.pass_time = 0.0
        e.clock.tail_time = e.clock.rho_time = 0.0

    def update_cones(self, const double[::1] mu, const double[:, ::1] normal):
        """New friction coefficients and normals (one row of three per cone) for the same
        cone blocks, written into the workspace's own copies, which the kernels read. A
        contact change onto other friction calls it once, with the interpreter's and
        numpy's code cold, where numpy's slice assignments took 8-9 us of a solo12 or go2
        tick (notes/performance-history.md, "contactwall")."""
        cdef Cones* cones = &self.e.prob.cones
        cdef double* mu_out = <double*>cones.mu   # the workspace's own copies
        cdef double* normal_out = <double*>cones.normal
        cdef Py_ssize_t k, j
        if mu.shape[0] != cones.count or normal.shape[0] != cones.count or normal.shape[1] != 3:
            raise ValueError(f"expected {cones.count} friction coefficients and "
                             f"{cones.count} x 3 normals")
        for k in range(cones.count):
            mu_out[k] = mu[k]
            for j in range(3):
                normal_out[3 * k + j] = normal[k, j]

    def forget(self):
        """Drop the previous solution, so that the next solve starts cold."""
        self.e.prev.exists = False

    def judge_certificate(self, const double[::1] candidate, bint primal,
                          const double[::1] point=None):
        """The certificate ``candidate`` (user's units, ``Result.certificate``'s layout:
        ``(dy, dz)`` for ``primal``, else ``dx``), found outside the run (see
        :mod:`fccqp.auxiliary`), judged by the tests of the run's own candidates on the
        last solve's scaled problem; the certificate as it passed (the primal one's
        ``dz`` projected onto the polar), or None. A primal certificate's separation
        must exceed what its residual explains at ``point`` (user's units, with ``A x =
        b``; default the run's iterate, which on a run that diverges along a ray, ``q``
        of 4.5e14 beside a cone pinned outside itself, explained away an exact one, and
        which also asks what it explains at the data's scale) and in the box."""
        cdef Engine* e = &self.e
        cdef Problem* p = &e.prob
        cdef Py_ssize_t n = p.n, m = p.m, i, j
        cdef const double* x = e.it.x
        if candidate.shape[0] != (n + m if primal else n):
            raise ValueError("a certificate of the wrong size")
        if primal:
            if m == 0:
                return None
            if point is not None:
                if point.shape[0] != n:
                    raise ValueError("a point of the wrong size")
                for i in range(n):
                    e.work.vec_n3[i] = point[i] / p.D[i]
                x = e.work.vec_n3
            for i in range(m):
                e.work.vec_m[i] = candidate[i] / p.E[i]
            for j in range(p.s):
                i = p.constrained[j]
                e.work.vec_s[j] = candidate[m + i] * p.D[i]
            if primal_candidate(p, x, point is None, e.work.vec_m, e.work.vec_s,
                                e.opt.eps_prim_inf, e.work.vec_n, e.work.vec_n2) != CERTIFIED:
                return None
            fill(e.certs.cert, 0.0, n + m)
            for i in range(m):
                e.certs.cert[i] = e.work.vec_m[i] * p.E[i]
            for j in range(p.s):
                i = p.constrained[j]
                e.certs.cert[m + i] = e.work.vec_s[j] / p.D[i]
            return np.asarray(<double[:n + m]>e.certs.cert).copy()
        for i in range(n):
            e.certs.direction[i] = candidate[i] / p.D[i]
        if not unbounded(e):
            return None
        return np.asarray(<double[:n]>e.certs.cert).copy()

    @property
    def finding(self):
        """``(code, argument, index, value)`` of the last scan (see fccqp.validation)."""
        return self.found.code, self.found.argument, self.found.index, self.found.value

    @property
    def phase_times(self):
        """Seconds of the last solve's phases inside the compiled call: validation scan,
        scaling, start and factorization, iterations (with the polishing tried where
        ADMM converges before its budget), the final polishing or restoration and the
        unscaling (a phase the solve skipped shows 0)."""
        cdef int i
        return tuple(max(self.e.clock.marks[i + 1] - self.e.clock.marks[i], 0.0)
                     for i in range(5))

    @property
    def scaling(self):
        """``(D, E, c)`` of the last solve's scaled problem (:mod:`fccqp.scaling`): new
        arrays."""
        cdef Problem* p = &self.e.prob
        return (np.array(<double[:p.n]>p.D), np.array(<double[:p.m]>p.E) if p.m else
                np.empty(0), p.c)

    @property
    def log_lines(self):
        """Rows ``(iteration, prim, dual, gap, rho)`` of the last solve's log."""
        cdef Py_ssize_t i, j
        return [tuple(self.e.log.rows[5 * i + j] for j in range(5))
                for i in range(self.e.log.count)]

    def solve(self, P, q, A, b, lb, ub, x0, bint warm, double start_time, cert_out,
              bint checked=True, y0=None, z0=None):
        """Validate, scale, run ADMM and unscale; return the :class:`fccqp.Result`, or
        the code of what the caller must do instead.

        ``P, q, A, b, lb, ub`` are C-contiguous float64 arrays of the workspace's shapes
        (as :func:`fccqp.problem.convert` or :func:`fccqp.fast_checks.dense_arguments`
        leave them; on a :attr:`compressed` workspace ``P`` and ``A`` are the values of
        its patterns, scipy's ``data`` of :func:`fccqp.sparse_problem.convert`'s
        matrices); with ``checked=False`` they are the caller's arguments as they came,
        and the code is ``NOT_DENSE`` when one is not such an array. ``x0`` (None or a
        float64 vector) overrides the warm start; with ``y0`` and ``z0`` (float64 vectors
        of ``m`` and ``n`` entries, both or neither, only beside ``x0``) the guess is a
        primal-dual point that replaces the previous solution, polished (the run starts
        warm from it, with the warm polish from its active set, at the rho of the last
        solve, else ``settings.rho``); ``warm`` asks for a start from the
        previous solution (when there is one); ``start_time`` is the call's start on the
        clock of ``time.perf_counter``. ``cert_out`` (``m + n`` entries) receives an
        infeasibility certificate, which the result copies. The other codes are
        ``STRUCTURE_CHANGED``, ``BAD_DATA`` (see :attr:`finding`) and
        ``NOT_CONVEX_CODE``; the last two leave the previous solution untouched.

        The arrays are read through their buffers, held for the call: typed memoryview
        arguments made a memoryview object for each of the eleven, and holding the
        buffers instead saved 9k of a go2 tick's 1.13M instructions (callgrind). The
        result is built here, not in Python from a tuple of the run's figures: the
        interpreter runs from cold caches after the compiled solve, and there that took
        7-10 us of a 100 us go2 or solo12 tick (in flow); built here, a go2 tick
        counts 7k fewer instructions of 706k (callgrind). A plain numpy array is held
        from its fields (``fast_checks.hold_float64``), not through numpy's buffer.
        """
        cdef Py_ssize_t n = self.e.prob.n, m = self.e.prob.m
        cdef Py_buffer views[13]
        cdef Py_ssize_t rows[13]
        cdef Py_ssize_t columns[13]
        cdef int held = 0, count = 10 if x0 is None else (11 if z0 is None else 13), i, code
        cdef Run run
        x_out, y_out, z_out = _empty(n), _empty(m), _empty(n)
        cdef tuple arrays = (P, q, A, b, lb, ub, x_out, y_out, z_out, cert_out, x0, y0, z0)
        self._shapes(rows, columns)
        try:
            for i in range(count):   # the outputs, 6 to 9, are written
                if i < 6 and not checked:
                    if not hold_dense(arrays[i], &views[i], rows[i], columns[i]):
                        return NOT_DENSE
                elif not hold_float64(arrays[i], &views[i], rows[i], columns[i], 6 <= i <= 9):
                    raise ValueError(f"expected a C-contiguous float64 array of {rows[i]} rows")
                held += 1
            code = self._run_held(views, count, warm, start_time, &run)
        finally:
            for i in range(held):
                PyBuffer_Release(&views[i])
        return self._answer(code, &run, x_out, y_out, z_out, cert_out, start_time)

    def switch(self, current, dict kept, P, q, A, b, lb, ub, cones, x0, y0, z0, bint warm,
               double start_time):
        """The solve of a tick with a guess in one compiled call, on this (the current)
        workspace or, for a structure switch, on a kept one: ``(entry, out)``, ``out``
        what :meth:`solve` returns and ``entry`` the ``(structure, workspace)`` of
        ``kept`` (a solver's kept dense workspaces by key, oldest first) that took it,
        None where this one did (``current``: its structure); ``FITS_CURRENT`` when the
        arrays fit this workspace's shapes and the guess or the cones are for the
        general path; None when the general path decides (:meth:`fccqp.Solver.solve`),
        nothing solved or written.

        This workspace takes the arrays that fit its shapes as they came
        (:func:`fccqp.fast_checks.dense_arguments`), else the first kept workspace whose
        shapes they fit, when ``cones`` are upright friction cones on its blocks
        (:func:`_upright_friction`, which writes their friction into it) and when the
        guess is none, ``x0`` alone or all of ``x0, y0, z0``, each within ``MAX_ENTRY``
        (as :func:`fccqp.solver._guess` returns it unconverted); a kept workspace is
        marked ``arrived``; the workspace solves from the buffers held for those checks,
        its structure's ``certificate`` the certificate's output. Anything else, a kept
        workspace of other blocks first among those the shapes fit included, is the
        general path's, which flattens the cones and raises the errors. A kept entry
        that solved leaves ``kept`` and this workspace takes its place (under
        ``current``'s key), for the caller to make the entry current. A contact change
        runs this once
        after a stretch of ticks of another structure, with its code cold: it is a
        method beside :meth:`solve` and runs the holds every tick runs, its checks
        inlined, where a separate call choosing the workspace and then :meth:`solve`
        cost about 5 us more of anymal_c's 90 us contact tick, and where the general
        path's flattening, guess checks and :meth:`solve` took 6-10 us of a trot's 40-50
        us contact tick on the current workspace (notes/performance-history.md,
        "switchlayer", "End of session 36")."""
        cdef Workspace w = self
        cdef Py_buffer views[13]
        cdef Py_ssize_t rows[13]
        cdef Py_ssize_t columns[13]
        cdef int count = 10 if x0 is None else (11 if z0 is None else 13), held = 6, i, code
        cdef bint guessed = False
        cdef Run run
        cdef tuple arrays = (P, q, A, b, lb, ub)
        cdef object entry = None
        self._shapes(rows, columns)
        if not _hold_inputs(arrays, views, rows, columns):
            for entry in kept.values():
                w = (<tuple>entry)[1]
                w._shapes(rows, columns)
                if _hold_inputs(arrays, views, rows, columns):
                    break
            else:
                return None
        # the general path for what this one does not take: for this workspace, as the
        # arrays fit it, the path that keeps it (FITS_CURRENT)
        declined = FITS_CURRENT if w is self else None
        try:   # views 0 to 5 held, then the guess's (10 to 12), then the outputs' (6 to 9)
            guessed = _hold_guess(x0, y0, z0, views, rows)
            if not guessed:
                return declined
            x_out, y_out, z_out = _empty(rows[6]), _empty(rows[7]), _empty(rows[8])
            certificate = current.certificate if w is self else (<tuple>entry)[0].certificate
            outputs = (x_out, y_out, z_out, certificate)
            for i in range(6, 10):
                if not hold_float64(outputs[i - 6], &views[i], rows[i], -1, True):
                    raise ValueError(f"expected a C-contiguous float64 array of {rows[i]} rows")
                held += 1
            if not _upright_friction(cones, &w.e.prob.cones, w.e.user.block_start):
                return declined
            if w is not self:
                w.arrived = True
            code = w._run_held(views, count, warm, start_time, &run)
        finally:
            for i in range(held):
                PyBuffer_Release(&views[i])
            if guessed:
                for i in range(10, count):
                    PyBuffer_Release(&views[i])
        out = w._answer(code, &run, x_out, y_out, z_out, outputs[3], start_time)
        if w is not self:   # the entry leaves kept, this workspace takes its place
            del kept[(<tuple>entry)[0].key]
            kept[current.key] = (current, self)
        return entry, out

    cdef void _shapes(self, Py_ssize_t* rows, Py_ssize_t* columns) noexcept:
        """The rows and columns (-1: a vector) of :meth:`solve`'s thirteen arrays, in the
        order ``P, q, A, b, lb, ub``, the outputs ``x, y, z, certificate``, the guess
        ``x0, y0, z0``."""
        cdef Py_ssize_t n = self.e.prob.n, m = self.e.prob.m
        rows[:13] = [n, n, m, m, n, n, n, m, n, n + m, n, m, n]
        columns[:13] = [n, -1, n, -1, -1, -1, -1, -1, -1, -1, -1, -1, -1]
        if self.compressed:   # P and A: the values of the patterns
            rows[0], rows[2] = self.e.user.P.colptr[n], self.e.user.A.colptr[n]
            columns[0] = columns[2] = -1

    cdef int _run_held(self, Py_buffer* views, int count, bint warm, double start_time,
                       Run* run) except -9:
        """:meth:`_run` on the buffers of :meth:`solve`'s arrays held in ``views`` (in
        :meth:`_shapes`' order; ``count``: 10 without a guess, 11 with ``x0`` alone, 13
        with all three)."""
        return self._run(<const double*>views[0].buf, <const double*>views[1].buf,
                         <const double*>views[2].buf, <const double*>views[3].buf,
                         <const double*>views[4].buf, <const double*>views[5].buf,
                         <const double*>views[10].buf if count > 10 else NULL,
                         <const double*>views[11].buf if count == 13 else NULL,
                         <const double*>views[12].buf if count == 13 else NULL, warm,
                         start_time, <double*>views[6].buf, <double*>views[7].buf,
                         <double*>views[8].buf, <double*>views[9].buf, run)

    cdef object _answer(self, int code, const Run* run, x_out, y_out, z_out, cert_out,
                        double start_time):
        """What :meth:`solve` returns for a run that ended with ``code``: the code below
        ``SOLVED``, else the result of the run (its buffers released)."""
        if code < engine.SOLVED:
            return code
        result = self._result(run, x_out, y_out, z_out, cert_out, start_time)
        self._learn_final_step(run.polished)
        return result

    cdef void _learn_final_step(self, bint polished) noexcept:
        """Learn what the final step after the iterations cost, up to the result built
        (``final_reserve``; the result took 0.07 ms of talos' 2 ms ticks under load), and
        after an unpolished run what followed its polish (``tail_time``, decayed at each
        such run only: the ticks that end polished do not measure it)."""
        cdef Clock* clock = &self.e.clock
        cdef double now = fccqp_now()
        clock.final_reserve *= RESERVE_DECAY
        if self.e.iterated:
            clock.final_reserve = max(clock.final_reserve, now - clock.marks[4])
            if not polished:   # the largest of those lately, decayed at each
                clock.tail_time = max(RESERVE_DECAY * clock.tail_time, now - clock.polish_end)

    cdef object _result(self, const Run* run, x, y, z, cert_out, double start_time):
        """The :class:`fccqp.Result` of a finished run (see ``Result.gap`` and
        ``Result.certificate`` for the infeasible statuses)."""
        cdef Residuals* r = &self.e.res
        certificate = None
        self.doubt = 0
        self.converging = run.converging
        if run.status == engine.SOLVED or run.status == engine.INACCURATE:
            self.doubt = (PRIMAL_LENT if r.set_lent else 0) + (DUAL_LENT if r.dual_lent else 0)
        if run.status == engine.PRIMAL_INFEASIBLE:
            certificate = cert_out.copy()
        elif run.status == engine.DUAL_INFEASIBLE:
            certificate = cert_out[:self.e.prob.n].copy()
        return _new_result({
            "x": x, "y": y, "z": z, "status": STATUS_BY_CODE[run.status],
            "obj": r.objective, "iterations": run.iterations, "prim_res": r.prim,
            "dual_res": r.dual, "setup_time": run.setup_time,
            "solve_time": fccqp_now() - start_time, "rho": run.rho,
            "factorizations": run.factorizations, "certificate": certificate,
            "backend": BACKEND_NAMES[run.backend],
            "gap": r.gap if certificate is None else float("nan"), "polished": run.polished,
        })

    cdef int _run(self, const double* P, const double* q, const double* A, const double* b,
                  const double* lb, const double* ub, const double* x0, const double* y0,
                  const double* z0, bint warm, double start_time, double* x_out,
                  double* y_out, double* z_out, double* cert_out, Run* out) except -9:
        """:meth:`solve` on the held buffers: the run's status, with ``out`` filled, or
        one of the codes below ``SOLVED``. A primal-dual guess (``z0`` not NULL) becomes
        the previous solution only once the data passed its checks, so that a rejected
        call leaves the previous solution as it was."""
        cdef Engine* e = &self.e
        cdef Py_ssize_t n = e.prob.n, m = e.prob.m
        cdef bint same = e.user.has_matrices
        cdef Run run
        cdef long spent
        cdef int factored
        cdef Matrix P_in, A_in
        e.clock.marks[0] = fccqp_now()
        if self.compressed:   # the values over the workspace's patterns
            P_in = csc(<double*>P, e.user.P.colptr, e.user.P.rowind, n, n)
            A_in = csc(<double*>A, e.user.A.colptr, e.user.A.rowind, m, n)
            with nogil:
                self.found = scan_and_copy_csc(&P_in, q, &A_in, b if m else NULL, lb, ub,
                                               &e.user.P, e.user.q, &e.user.A, e.user.b,
                                               e.user.lb, e.user.ub, &same)
        else:
            with nogil:
                self.found = scan_and_copy(
                    P, q, A if m else NULL, b if m else NULL, lb, ub, n, m, e.user.P.values,
                    e.user.q, e.user.A.values, e.user.b, e.user.lb, e.user.ub, &same)
        if self.found.code != SCAN_OK:
            e.user.has_matrices = False
            return engine.NEW_STRUCTURE if self.found.code == NEW_PATTERN else engine.BAD_NUMBERS
        if not self._same_structure(lb, ub):
            e.user.has_matrices = False
            return engine.NEW_STRUCTURE
        if not (same or self.compressed):
            mark_diagonal_tail(&e.user.P)
        if z0 != NULL:
            self._take_guess(x0, y0, z0)
            x0, warm = NULL, True
        self.arrived = False
        cdef long max_iter = e.opt.max_iter
        # a start from the previous solution (or x0), with the previous scaling, that
        # has not succeeded in half the iterations gets a cold start with a new scaling
        # for the other half, as a fresh solve would have (a changed A once ran 4000
        # iterations warm, where a fresh solve needed none); not under a time limit,
        # which leaves no time for it, nor for budgets too small to split
        cdef bint restartable = ((x0 != NULL or (warm and e.prev.exists))
                                 and not isfinite(e.opt.time_limit)
                                 and max_iter >= RESTART_MIN_ITER)
        enter()   # single-threaded BLAS for this solve (see fccqp.blas_threads)
        try:
            with nogil:
                if restartable:
                    e.opt.max_iter = max_iter // 2
                run = scaled_run(e, same, x0, warm and e.prev.exists, True, start_time)
                # convexity is decided on P + sigma I in the scaled units: with a
                # scaling kept from other matrices a kept workspace rejected -3.9e-3 of
                # curvature on the null space of A (|P| up to 172) that a fresh solve's
                # scaling accepts (fuzz solver_reuse:211); a rejection there is decided
                # again as a fresh solve
                if run.status == engine.NOT_CONVEX_QP and e.scaling.kept:
                    e.opt.max_iter = max_iter
                    restartable = False
                    run = scaled_run(e, False, NULL, False, False, start_time)
                if run.status != engine.NOT_CONVEX_QP:
                    unscaled_answer(e, &run, x_out, y_out if m else NULL, z_out, cert_out)
                e.opt.max_iter = max_iter
                if restartable and (run.status == engine.MAX_ITER
                                    or run.status == engine.NUMERICAL_ERROR):
                    e.opt.max_iter = max_iter - run.iterations
                    spent, factored = run.iterations, run.factorizations
                    run = scaled_run(e, False, NULL, False, False, start_time)
                    e.opt.max_iter = max_iter
                    run.iterations += spent
                    run.factorizations += factored
                    if run.status != engine.NOT_CONVEX_QP:
                        unscaled_answer(e, &run, x_out, y_out if m else NULL, z_out, cert_out)
                e.clock.marks[5] = fccqp_now()
        finally:
            leave()
        if run.status == engine.NOT_CONVEX_QP:
            e.user.has_matrices = e.prev.exists = e.fact.certified = False
            return engine.NOT_CONVEX_QP
        out[0] = run
        return run.status

    cdef void _take_guess(self, const double* x0, const double* y0,
                          const double* z0) noexcept nogil:
        """Make the primal-dual guess ``(x0, y0, z0)`` (user's units) the previous
        solution, polished: the run then starts from it as a warm start from its own
        answer does, the warm polish first (on the guess's active set, or from its primal
        point with nothing held when the guess was carried from another structure,
        :attr:`arrived`, :func:`fccqp.acceptance._polish_start`; if that fails, ADMM
        starts from the guess or the cold start, :func:`fccqp.iteration._nearer_start`).
        Its rho is the last one this workspace ran at, else ``settings.rho``."""
        cdef Engine* e = &self.e
        copy(x0, e.prev.x, e.prob.n)
        copy(y0, e.prev.y, e.prob.m)
        copy(z0, e.prev.z, e.prob.n)
        if not e.prev.has_rho:
            e.prev.rho = e.opt.rho
        e.prev.exists = e.prev.polished = e.prev.guessed = True
        e.prev.carried = self.arrived

    cdef bint _same_structure(self, const double* lb, const double* ub) noexcept nogil:
        """Whether the user's new bounds bound, fix and leave free the entries they did at
        allocation, with no bound on a cone entry (:func:`fccqp.validation.bound_kind`,
        the rule of ``structure_scan``): one pass here instead of a separate call per
        solve (the control-loop case)."""
        cdef Py_ssize_t i
        cdef int kind
        for i in range(self.e.prob.n):
            kind = bound_kind(lb[i], ub[i])
            if kind == UNBOUNDED and self.e.user.entry_kind[i] == CONE_ENTRY:
                continue
            if kind != self.e.user.entry_kind[i]:
                return False
        return True


cdef inline bint _hold_inputs(tuple arrays, Py_buffer* views, const Py_ssize_t* rows,
                              const Py_ssize_t* columns):
    """Hold ``P, q, A, b, lb, ub`` (``arrays``) in ``views[:6]`` and return True when
    each is a dense array of the shape ``rows``, ``columns`` give it
    (:func:`fccqp.fast_checks.hold_dense`); False, holding nothing, otherwise."""
    cdef int i, k
    for i in range(6):
        if not hold_dense(arrays[i], &views[i], rows[i], columns[i]):
            for k in range(i):
                PyBuffer_Release(&views[k])
            return False
    return True


cdef inline bint _hold_within(object value, Py_buffer* view, Py_ssize_t size):
    """Hold ``value`` in ``view`` and return True when it is a vector
    :func:`fccqp.fast_checks.hold_dense` accepts, of ``size`` entries, each within
    ``MAX_ENTRY`` (a NaN is not); False, holding nothing, otherwise."""
    cdef const double* entries
    cdef Py_ssize_t i
    if not hold_dense(value, view, size, -1):
        return False
    entries = <const double*>view.buf
    for i in range(size):
        if not fabs(entries[i]) <= MAX_ENTRY:
            PyBuffer_Release(view)
            return False
    return True


cdef inline bint _hold_guess(x0, y0, z0, Py_buffer* views, const Py_ssize_t* rows):
    """Hold the guess ``(x0, y0, z0)`` in ``views[10:13]`` (as many as given) and return
    True when it is none, ``x0`` alone or all three, each a vector
    :func:`fccqp.solver._guess` takes as it came (its sizes ``rows[10:13]``); False,
    holding nothing, otherwise."""
    if x0 is None:
        return y0 is None and z0 is None
    if y0 is None and z0 is None:
        return _hold_within(x0, &views[10], rows[10])
    if y0 is None or z0 is None or not _hold_within(x0, &views[10], rows[10]):
        return False
    if not _hold_within(y0, &views[11], rows[11]):
        PyBuffer_Release(&views[10])
        return False
    if not _hold_within(z0, &views[12], rows[12]):
        PyBuffer_Release(&views[10])
        PyBuffer_Release(&views[11])
        return False
    return True


cdef inline bint _upright_friction(object cones, Cones* blocks, const Py_ssize_t* start):
    """Write the friction coefficients of ``cones`` into ``blocks`` with upright normals
    and return True when ``cones`` is a tuple of ``blocks.count`` friction cones as
    :func:`fccqp.fast_checks.upright_friction_arrays` takes them (an int ``start``, a
    float ``mu``, finite and positive, no normal), the ``k``-th starting at ``start[k]``
    where ``blocks`` has a friction cone: a workspace's blocks, already checked to lie
    inside ``x`` without overlap, which ``cones`` then has. False, nothing written, for
    anything else (the Python flattening takes it)."""
    cdef Py_ssize_t k, count = blocks.count
    cdef double value
    cdef double* mu = <double*>blocks.mu
    cdef double* normal = <double*>blocks.normal
    if type(cones) is not tuple or len(<tuple>cones) != count:
        return False
    for k in range(count):
        cone = (<tuple>cones)[k]
        if (type(cone) is not FrictionCone or cone.normal is not None
                or blocks.kind[k] != FRICTION):
            return False
        given_start, given_mu = cone.start, cone.mu
        if type(given_start) is not int or type(given_mu) is not float:
            return False
        value = given_mu
        if given_start != start[k] or not (value > 0 and value < INFINITY):
            return False
    for k in range(count):
        mu[k] = (<tuple>cones)[k].mu
        normal[3 * k], normal[3 * k + 1], normal[3 * k + 2] = 0.0, 0.0, 1.0
    return True
