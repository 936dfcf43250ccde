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

from fccqp.result import Result
from fccqp.rho_rule import RhoTrial   # re-exported: the sparse path imports it from here
from fccqp.status import Status

from cpython.buffer cimport PyBuffer_Release
from libc.math cimport isfinite

from fccqp cimport engine
from fccqp._dense cimport fill
from fccqp._types cimport Problem
from fccqp.anderson cimport anderson_reset
from fccqp.blas_threads cimport enter, leave
from fccqp.certificates cimport CERTIFIED, primal_candidate
from fccqp.engine cimport CONE_ENTRY, Engine, Run, fccqp_now
from fccqp.fast_checks cimport hold_dense, hold_float64
from fccqp.kkt cimport AUTO, LDL_FULL, LDL_REDUCED, SCHUR_REDUCED
from fccqp.matrices cimport dense
from fccqp.scaled_run cimport scaled_run, unscaled_answer
from fccqp.termination cimport Residuals
from fccqp.tuning cimport FIXED_RHO_SCALE, RESERVE_DECAY, RESTART_MIN_ITER
from fccqp.validation cimport (BOUNDED, FIXED_BOUND, SCAN_OK, UNBOUNDED, Finding, bound_kind,
                               scan_and_copy)
from fccqp.verdict cimport unbounded

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
constrained or fixed entries, or a bound on a cone entry): the caller rescans them
(:func:`fccqp.validation.structure_scan`) and makes a new workspace."""
NOT_DENSE = -4
"""An input array is not a C-contiguous float64 numpy array of the workspace's shape
(:meth:`Workspace.solve` with ``checked=False``): the caller converts the arguments."""
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
            "auto": AUTO}
"""``Settings.kkt_backend`` names and their codes (see :mod:`fccqp.kkt`)."""
BACKEND_NAMES = {code: name for name, code in BACKENDS.items()}


cdef class Workspace:
    """Every array of a solve, allocated once for a problem structure.

    The structure is the sizes, the constrained entries, the entries with ``lb == ub``
    and the cone blocks; :class:`fccqp.Solver` builds a new workspace when it changes.
    Between solves the workspace keeps the user's last ``P`` and ``A`` (to detect
    reuse), their scaling and factorization, and the last solution (for a warm start).
    """

    cdef list _arrays
    cdef Engine e
    cdef Finding found
    cdef object _keep

    def __init__(self, Py_ssize_t n, Py_ssize_t m, constrained, cones, fixed, order,
                 settings, Py_ssize_t log_rows):
        """Allocate for ``n`` variables, ``m`` rows, the ``constrained`` entries (intp,
        ascending), ``cones`` (the tuple of :class:`fccqp.cones.ConeArrays` with offsets
        into ``constrained``), the boolean mask ``fixed`` of constrained entries with
        ``lb == ub``, the Schur ``order`` and a :class:`fccqp.Settings`."""
        cdef Py_ssize_t s = len(constrained), N = n + m, memory = settings.anderson_memory
        cdef Py_ssize_t k, j
        cdef Engine* e = &self.e
        self._arrays = []
        kind, offset, dim, mu, normal = cones
        # private copies: update_cones writes into them, and the caller's arrays may be
        # shared (fccqp.cones memoizes one ConeArrays per distinct set of cones)
        self._keep = (np.array(constrained, dtype=np.intp),
                      np.array(kind, dtype=np.intp),
                      np.array(offset, dtype=np.intp),
                      np.array(dim, dtype=np.intp),
                      np.array(mu, dtype=np.float64),
                      np.array(normal, dtype=np.float64).reshape(-1),
                      np.array(order, dtype=np.intp),
                      np.zeros(max(len(kind), 1), dtype=np.intp))
        cdef Py_ssize_t[::1] c_view = self._keep[0], kind_v = self._keep[1]
        cdef Py_ssize_t[::1] offset_v = self._keep[2], dim_v = self._keep[3]
        cdef Py_ssize_t[::1] order_v = self._keep[6], start_v = self._keep[7]
        cdef double[::1] mu_v = self._keep[4], normal_v = self._keep[5]
        p = &e.prob
        p.n, p.m, p.s = n, m, s
        p.constrained = &c_view[0] if s else NULL
        p.cones.count = len(kind)
        if p.cones.count:
            p.cones.kind, p.cones.offset, p.cones.dim = &kind_v[0], &offset_v[0], &dim_v[0]
            p.cones.mu, p.cones.normal = &mu_v[0], &normal_v[0]
            for k in range(p.cones.count):
                start_v[k] = c_view[offset_v[k]]
        e.user.block_start = &start_v[0]
        cdef char* in_cone = <char*>self._new(s)
        for k in range(p.cones.count):
            for j in range(offset_v[k], offset_v[k] + dim_v[k]):
                in_cone[j] = 1
        p.in_cone = in_cone
        p.P, p.A = dense(self._new(n * n), n, n), dense(self._new(m * n), m, n)
        p.q, p.b = self._new(n), self._new(m)
        p.lo, p.hi, p.D, p.E = self._new(s), self._new(s), self._new(n), self._new(m)
        p.span = self._new(m)
        p.c = 1.0
        u = &e.user
        u.P, u.A = dense(self._new(n * n), n, n), dense(self._new(m * n), m, n)
        u.q, u.b = self._new(n), self._new(m)
        u.lb, u.ub = self._new(n), self._new(n)
        e.fact.rho_scale = self._new(s)
        for k in range(s):
            e.fact.rho_scale[k] = FIXED_RHO_SCALE if fixed[k] else 1.0
        u.entry_kind = <char*>self._new(n)
        for k in range(s):
            u.entry_kind[c_view[k]] = (CONE_ENTRY if in_cone[k] else
                                       FIXED_BOUND if fixed[k] else BOUNDED)
        e.scaling.d, e.scaling.e = self._new(n), self._new(m)
        e.scaling.reference, e.scaling.norms = self._new(N), self._new(N)
        it = &e.it
        it.x, it.nu, it.z, it.y = self._new(n), self._new(m), self._new(s), self._new(s)
        it.x_prev, it.nu_prev = self._new(n), self._new(m)
        it.z_prev, it.y_prev = self._new(s), self._new(s)
        it.relaxed, it.rho_vec = self._new(s), self._new(s)
        w = &e.work
        w.rhs, w.sol = self._new(N), self._new(N)
        cdef Py_ssize_t wide = max(n, m)
        w.vec_n, w.vec_n2, w.vec_n3 = self._new(wide), self._new(wide), self._new(wide)
        w.vec_s, w.vec_s2, w.vec_m = self._new(s), self._new(s), self._new(m)
        w.vec_m2 = self._new(m)
        e.certs.gram = self._new(m * m)
        w.guess_point, w.guess_codes = self._new(s), <char*>self._new(s)
        e.certs.direction, w.saved, e.certs.cert = self._new(n), self._new(N + s), self._new(N)
        e.prev.x, e.prev.y, e.prev.z = self._new(n), self._new(m), self._new(n)
        kk = &e.fact.kkt
        kk.ldl.N = <int>N
        kk.ldl.K = self._new(N * N)
        kk.ldl.ipiv = <int*>self._new_int(N)
        kk.ldl.lwork = <int>(64 * N)
        kk.ldl.work, kk.ldl.residual = self._new(64 * N), self._new(N)
        kk.ldl.Ax, kk.ldl.ATnu = self._new(m), self._new(n)
        kk.schur.n, kk.schur.m = <int>n, <int>m
        kk.schur.L, kk.schur.LS, kk.schur.Y = self._new(n * n), self._new(m * m), self._new(n * m)
        kk.schur.G, kk.schur.free_ready = self._new(m * m), False
        kk.schur.base_order = &order_v[0]
        kk.schur.order = <Py_ssize_t*>self._new_int(n)
        kk.schur.coupled = <char*>self._new(n)
        kk.schur.dense = <int>n
        kk.schur.perm, kk.schur.dx, kk.schur.r = self._new(n), self._new(n), self._new(n)
        kk.schur.ATnu, kk.schur.dnu, kk.schur.Ax = self._new(n), self._new(m), self._new(m)
        kk.schur.X, kk.schur.Wnu, kk.schur.M = self._new(n * s), self._new(m * s), self._new(s * s)
        kk.R, kk.work = self._new(N * s), self._new(N)
        red = &e.red
        red.W, red.W_S, red.base = self._new(N * s), self._new(s * s), self._new(N)
        red.u, red.u_prev, red.v, red.v_prev = self._new(s), self._new(s), self._new(s), self._new(s)
        red.xs = self._new(s)
        aa = &e.aa
        aa.capacity = <int>memory
        aa.dg, aa.df = self._new(memory * 2 * s), self._new(memory * 2 * s)
        aa.g, aa.f, aa.g_new, aa.f_new = self._new(2 * s), self._new(2 * s), self._new(2 * s), self._new(2 * s)
        aa.plain, aa.gram, aa.gamma = self._new(2 * s + 1), self._new(memory * memory), self._new(memory)
        aa.products = self._new(memory * memory)
        anderson_reset(aa, False)
        rs = &e.rest
        rs.pinned = <char*>self._new(s)
        rs.target, rs.projected = self._new(s), self._new(s)
        rs.positions, rs.entries = <Py_ssize_t*>self._new_int(s), <Py_ssize_t*>self._new_int(s)
        rs.W_T, rs.gram, rs.step = self._new(N * s), self._new(s * s), self._new(s)
        rs.start, rs.point = self._new(N), self._new(N)
        pol = &e.pol
        pol.active = <char*>self._new(s)
        pol.dropped = <char*>self._new(s)
        pol.index, pol.free = <Py_ssize_t*>self._new_int(n), <Py_ssize_t*>self._new_int(n)
        pol.boundary = <Py_ssize_t*>self._new_int(s)
        pol.g, pol.lam, pol.hess = self._new(s), self._new(s), self._new(s * s)
        pol.K, pol.ipiv = self._new((N + s) * (N + s)), <int*>self._new_int(N + s)
        pol.lwork = <int>(64 * (N + s))
        pol.work = self._new(64 * (N + s))
        pol.rhs, pol.step = self._new(N + s), self._new(N + s)
        pol.x, pol.nu, pol.y = self._new(n), self._new(m), self._new(s)
        pol.x_prev, pol.nu_prev = self._new(n), self._new(m)
        pol.grad, pol.ATnu, pol.Ax = self._new(n), self._new(n), self._new(m)
        pol.T, pol.tpiv = self._new(4 * s * s), <int*>self._new_int(2 * s)
        pol.tr, pol.du = self._new(2 * s), self._new(2 * s)
        pol.full, pol.dfull = self._new(N), self._new(N)
        pol.schur_only = pol.schur_failed = False
        ps = &pol.schur
        ps.ready = False
        ps.order, ps.coupled = <Py_ssize_t*>self._new_int(n), <char*>self._new(n)
        ps.L, ps.root, ps.Y = self._new(n * n), self._new(n), self._new(n * (m + s))
        ps.SU, ps.S = self._new(m * m), self._new((m + s) * (m + s))
        ps.block = self._new(s * s)
        ps.rowvar, ps.block_row = <Py_ssize_t*>self._new_int(n), <Py_ssize_t*>self._new_int(s)
        ps.inv_root = self._new(n)
        ps.t, ps.t2, ps.u = self._new(n), self._new(n), self._new(m + s)
        e.unscaled.x, e.unscaled.y, e.unscaled.z = self._new(n), self._new(m), self._new(n)
        e.log.capacity = log_rows
        e.log.rows = self._new(5 * log_rows)
        e.log.count = 0
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
        e.prev.exists = u.has_matrices = e.fact.certified = e.scaling.done = False
        e.prev.has_rho = False
        e.prev.polished = e.prev.from_polished = e.equalities_missed = False
        e.unscaled.current = False
        e.fact.factored_rho = -1.0
        e.clock.final_reserve = e.clock.pass_time = 0.0

    cdef double* _new(self, Py_ssize_t size):
        """A zeroed array of ``size`` doubles (at least one) that lives with ``self``."""
        array = np.zeros(max(size, 1))
        self._arrays.append(array)
        cdef double[::1] view = array
        return &view[0]

    cdef void* _new_int(self, Py_ssize_t size):
        """An array of ``size`` pointer-sized integers that lives with ``self``."""
        array = np.zeros(max(size, 1), dtype=np.intp)
        self._arrays.append(array)
        cdef Py_ssize_t[::1] view = array
        return &view[0]

    def update_cones(self, mu, normal):
        """New friction coefficients and normals for the same cone blocks."""
        self._keep[4][:] = mu
        self._keep[5][:] = np.asarray(normal, dtype=np.float64).reshape(-1)

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
        of 4.5e14 beside a cone pinned outside itself, explained away an exact one)."""
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
            if primal_candidate(p, x, e.work.vec_m, e.work.vec_s, e.opt.eps_prim_inf,
                                e.work.vec_n, e.work.vec_n2) != CERTIFIED:
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
    def log_lines(self):
        """Rows ``(iteration, prim, dual, gap, rho)`` of the last solve's log."""
        cdef Py_ssize_t i, j
        return [tuple(self.e.log.rows[5 * i + j] for j in range(5))
                for i in range(self.e.log.count)]

    def solve(self, P, q, A, b, lb, ub, x0, bint warm, double start_time, cert_out,
              bint checked=True):
        """Validate, scale, run ADMM and unscale; return the :class:`fccqp.Result`, or
        the code of what the caller must do instead.

        ``P, q, A, b, lb, ub`` are C-contiguous float64 arrays of the workspace's shapes
        (as :func:`fccqp.problem.convert` or :func:`fccqp.fast_checks.dense_arguments`
        leave them); with ``checked=False`` they are the caller's arguments as they came,
        and the code is ``NOT_DENSE`` when one is not such an array. ``x0`` (None or a
        float64 vector) overrides the warm start; ``warm`` asks for a start from the
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
        counts 7k fewer instructions of 706k (callgrind).
        """
        cdef Py_ssize_t n = self.e.prob.n, m = self.e.prob.m
        cdef Py_buffer views[11]
        cdef Py_ssize_t rows[11]
        cdef Py_ssize_t columns[11]
        cdef int held = 0, count = 10 if x0 is None else 11, i, code
        cdef Run run
        x_out, y_out, z_out = np.empty(n), np.empty(m), np.empty(n)
        cdef tuple arrays = (P, q, A, b, lb, ub, x_out, y_out, z_out, cert_out, x0)
        rows[:] = [n, n, m, m, n, n, n, m, n, n + m, n]
        columns[:] = [n, -1, n, -1, -1, -1, -1, -1, -1, -1, -1]   # -1: a vector
        try:
            for i in range(count):   # the outputs, 6 to 9, are written
                if i < 6 and not checked:
                    if not hold_dense(arrays[i], &views[i], rows[i], columns[i]):
                        return NOT_DENSE
                elif not hold_float64(arrays[i], &views[i], rows[i], columns[i], 6 <= i <= 9):
                    raise ValueError(f"expected a C-contiguous float64 array of {rows[i]} rows")
                held += 1
            code = self._run(<const double*>views[0].buf, <const double*>views[1].buf,
                             <const double*>views[2].buf, <const double*>views[3].buf,
                             <const double*>views[4].buf, <const double*>views[5].buf,
                             <const double*>views[10].buf if x0 is not None else NULL, warm,
                             start_time, <double*>views[6].buf, <double*>views[7].buf,
                             <double*>views[8].buf, <double*>views[9].buf, &run)
        finally:
            for i in range(held):
                PyBuffer_Release(&views[i])
        if code < engine.SOLVED:
            return code
        return self._result(&run, x_out, y_out, z_out, cert_out, start_time)

    cdef object _result(self, const Run* run, x, y, z, cert_out, double start_time):
        """The :class:`fccqp.Result` of a finished run (see ``Result.gap`` and
        ``Result.certificate`` for the infeasible statuses)."""
        cdef Residuals* r = &self.e.res
        certificate = None
        if run.status == engine.PRIMAL_INFEASIBLE:
            certificate = cert_out.copy()
        elif run.status == engine.DUAL_INFEASIBLE:
            certificate = cert_out[:self.e.prob.n].copy()
        return Result._of({
            "x": x, "y": y, "z": z, "status": STATUS_BY_CODE[run.status],
            "obj": r.objective, "iterations": run.iterations, "prim_res": r.prim,
            "dual_res": r.dual, "setup_time": run.setup_time,
            "solve_time": fccqp_now() - start_time, "rho": run.rho,
            "factorizations": run.factorizations, "certificate": certificate,
            "backend": BACKEND_NAMES[run.backend],
            "gap": r.gap if certificate is None else float("nan"), "polished": run.polished,
        })

    cdef int _run(self, const double* P, const double* q, const double* A, const double* b,
                  const double* lb, const double* ub, const double* x0, bint warm,
                  double start_time, double* x_out, double* y_out, double* z_out,
                  double* cert_out, Run* out) except -9:
        """:meth:`solve` on the held buffers: the run's status, with ``out`` filled, or
        one of the codes below ``SOLVED``."""
        cdef Engine* e = &self.e
        cdef Py_ssize_t n = e.prob.n, m = e.prob.m
        cdef bint same = e.user.has_matrices
        cdef Run run
        cdef long spent
        cdef int factored
        e.clock.marks[0] = fccqp_now()
        with nogil:
            self.found = scan_and_copy(
                P, q, A if m else NULL, b if m else NULL, lb, ub, n, m, e.user.P.values,
                e.user.q, e.user.A.values, e.user.b, e.user.lb, e.user.ub, &same)
        if self.found.code != SCAN_OK:
            e.user.has_matrices = False
            return engine.BAD_NUMBERS
        if not self._same_structure(lb, ub):
            e.user.has_matrices = False
            return engine.NEW_STRUCTURE
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
                run = scaled_run(e, same, x0, warm and e.prev.exists, start_time)
                if run.status != engine.NOT_CONVEX_QP:
                    unscaled_answer(e, &run, x_out, y_out if m else NULL, z_out, cert_out)
                e.opt.max_iter = max_iter
                if restartable and (run.status == engine.MAX_ITER
                                    or run.status == engine.NUMERICAL_ERROR):
                    e.opt.max_iter = max_iter - run.iterations
                    spent, factored = run.iterations, run.factorizations
                    run = scaled_run(e, False, NULL, False, start_time)
                    e.opt.max_iter = max_iter
                    run.iterations += spent
                    run.factorizations += factored
                    if run.status != engine.NOT_CONVEX_QP:
                        unscaled_answer(e, &run, x_out, y_out if m else NULL, z_out, cert_out)
                e.clock.marks[5] = fccqp_now()
                e.clock.final_reserve *= RESERVE_DECAY
                if e.iterated:   # learn what the final step after the iterations costs
                    e.clock.final_reserve = max(e.clock.final_reserve,
                                                e.clock.marks[5] - e.clock.marks[4])
        finally:
            leave()
        if run.status == engine.NOT_CONVEX_QP:
            e.user.has_matrices = e.prev.exists = e.fact.certified = False
            return engine.NOT_CONVEX_QP
        out[0] = run
        return run.status

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
