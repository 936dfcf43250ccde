# cython: language_level=3, boundscheck=False, wraparound=False, cdivision=True, initializedcheck=False
"""The arrays of a :class:`fccqp.admm.Workspace`, one function per storage of ``P`` and
``A`` (:mod:`fccqp.matrices`).

Every array is allocated once per problem structure and lives with the workspace
(:class:`Arrays`); the C state (:c:type:`fccqp.engine.Engine`) points into them.
:func:`common_arrays` allocates what every storage needs (vectors of sizes ``n``,
``m``, ``s``, ``n + m``, Anderson's memory, the log); :func:`dense_arrays` the
matrices in row-major storage and everything sized by their products: the ``(n +
m)^2`` LDL' matrix, the Schur factors, the reduced form's table and the restoration's
columns (``(n + m) x s``), the polish's ``(n + m + s)^2`` matrix and its Schur and
table forms, the certificate cleaning's ``A A'``; :func:`csc_arrays` the matrices in
compressed columns, their ``SparseKKT`` and the polish's compressed-column arrays
(:func:`fccqp.polish_csc.arrays`, its curvature terms included), and none of the
dense-only arrays (their pointers stay NULL: the code that reads them does not run on
compressed columns).
On large_friction (5002 KKT rows) the dense set was 3.2 GB, the compressed one 8 MB.
"""

import numpy as np

from libc.string cimport memset

from fccqp.engine cimport Engine
from fccqp.kkt cimport SPARSE_LDL
from fccqp.matrices cimport csc, dense
from fccqp.polish_csc cimport bind
from fccqp.polish_schur cimport PolishSchur
from fccqp.tuning cimport GUESS_PASSES

from fccqp.polish_csc import arrays as polish_arrays


cdef enum:
    ALIGNMENT = 8   # doubles: each array starts on a 64-byte boundary (a cache line)
    CHUNK = 4096    # doubles (32 KB) per chunk of zeros the smaller arrays are carved from
    POOL = 262144   # doubles (2 MB, a huge page) per pool the chunks are carved from
    POOLED = 32768  # doubles (256 KB): the largest array taken from a pool
    SPARE_POOLS = 2  # released pools kept zeroed for the next workspaces: 4 MB at most

cdef extern from *:
    """
    #if defined(__linux__)
    #include <stdint.h>
    #include <sys/mman.h>
    /* size bytes of zeros on a 2 MB boundary, on a transparent huge page where the
       kernel gives one; NULL where none can be mapped */
    static void *fccqp_huge_region(size_t size)
    {
        size_t huge = (size_t)2 << 20;
        char *raw = mmap(NULL, size + huge, PROT_READ | PROT_WRITE,
                         MAP_PRIVATE | MAP_ANONYMOUS, -1, 0);
        char *aligned;
        if (raw == MAP_FAILED)
            return NULL;
        aligned = (char *)(((uintptr_t)raw + huge - 1) & ~(uintptr_t)(huge - 1));
        if (aligned > raw)
            munmap(raw, aligned - raw);
        if (raw + huge > aligned)
            munmap(aligned + size, raw + huge - aligned);
    #ifdef MADV_HUGEPAGE
        madvise(aligned, size, MADV_HUGEPAGE);
    #endif
        return aligned;
    }
    static void fccqp_huge_free(void *region, size_t size) { munmap(region, size); }
    #else
    static void *fccqp_huge_region(size_t size) { (void)size; return NULL; }
    static void fccqp_huge_free(void *region, size_t size) { (void)region; (void)size; }
    #endif
    """
    void* fccqp_huge_region(size_t size)
    void fccqp_huge_free(void* region, size_t size)


cdef class _Pool:
    """``POOL`` zeroed doubles on a 2 MB boundary (a transparent huge page where the
    kernel gives one), from which the arrays of workspaces are carved in turn, never
    twice: released when the last :class:`Arrays` carved from it goes, to the spares
    (zeroed again, at most ``SPARE_POOLS``) that the next pools are taken from, else
    unmapped.

    A contact change solves in a workspace that the ticks of the other contact set have
    not touched for a while; on pages of 4 KB its arrays spread over dozens of pages,
    each a TLB miss (a nested page walk under a hypervisor). On one huge page shared
    with the other workspaces of the process, go2's contact tick took about 5 us less
    (notes/performance-history.md, "contactentry"). A new region's first write faults
    its huge page in: the kernel zeroes 2 MB, and where the THP ``defrag`` policy is
    ``madvise`` (this machine) it may compact memory first, 0.2-16 ms inside the solve
    that wrote it (notes/performance-history.md, "firstsolve"). A spare was faulted in
    before; zeroing what was carved of it on release is a ``memset``."""

    cdef double* start
    cdef Py_ssize_t used   # doubles carved

    def __dealloc__(self):
        global _spare_count
        if self.start == NULL:
            return
        if _spare_count < SPARE_POOLS:
            memset(self.start, 0, self.used * sizeof(double))
            _spare[_spare_count] = self.start
            _spare_count += 1
        else:
            fccqp_huge_free(self.start, POOL * sizeof(double))


cdef double* _spare[SPARE_POOLS]   # zeroed regions of released pools
cdef int _spare_count = 0
cdef _Pool _pool = None   # the pool new arrays are carved from


cdef _Pool _new_pool():
    """A pool over a spare region when there is one, else over a new mapping; None
    where none can be mapped (not Linux, or ``mmap`` refused)."""
    global _spare_count
    cdef _Pool pool = _Pool()
    if _spare_count:
        _spare_count -= 1
        pool.start = _spare[_spare_count]
    else:
        pool.start = <double*>fccqp_huge_region(POOL * sizeof(double))
        if pool.start == NULL:
            return None
    return pool


cdef void _fault_in(_Pool pool) noexcept:
    """Write a zero into every 4 KB page of ``pool``: its pages (its huge page, where
    the kernel gives one) are faulted in now rather than by the first solve that
    carves it."""
    cdef volatile double* start = pool.start
    cdef Py_ssize_t k
    for k in range(0, POOL, 512):
        start[k] = 0.0


cdef double* _pooled(Arrays owner, Py_ssize_t size) except? NULL:
    """``size`` zeroed doubles (at most ``POOL``) from the current pool, a new one when
    it has no room for them (:func:`_new_pool`), kept alive by ``owner``; NULL where no
    pool can be mapped."""
    global _pool
    cdef _Pool pool = _pool
    cdef double* out
    if pool is None or pool.used + size > POOL:
        pool = _new_pool()
        if pool is None:
            return NULL
        _pool = pool
    owner.kept.append(pool)   # once per chunk carved: a pool may be listed several times
    out = pool.start + pool.used
    pool.used += size
    return out


_pool = _new_pool()   # at import (fccqp.Solver's first use): faulted in outside any solve
if _pool is not None:
    _fault_in(_pool)


cdef class Arrays:
    """The numpy arrays and pools a workspace's C state points into, kept alive with it.

    The arrays of :func:`common_arrays` and :func:`dense_arrays` (about 150) are carved
    from a few zeroed chunks instead of one ``np.zeros`` each (an array larger than a
    chunk has its own), the chunks from pools shared by the process's workspaces
    (:class:`_Pool`): a new go2 workspace took
    1.12M instructions, 0.77M of them in numpy's allocation and a typed memoryview per
    array, beside a 1.43M cold solve (callgrind, the first solve of a contact set)."""

    def __init__(self):
        self.kept = []
        self.free, self.left = NULL, 0

    cdef double* new(self, Py_ssize_t size) except NULL:
        """A zeroed array of ``size`` doubles (at least one), aligned to a cache line; its
        chunk from a huge page's pool (:class:`_Pool`) up to ``POOLED`` doubles."""
        cdef Py_ssize_t need = (max(size, 1) + ALIGNMENT - 1) // ALIGNMENT * ALIGNMENT
        cdef Py_ssize_t total = (need if need > CHUNK else CHUNK) + ALIGNMENT, skip
        cdef double* out
        if need > self.left:
            out = _pooled(self, total) if total <= POOLED else NULL
            if out == NULL:
                out = self.adopt(np.zeros(total))
            skip = (ALIGNMENT - (<size_t>out // sizeof(double)) % ALIGNMENT) % ALIGNMENT
            if need > CHUNK:   # an array of its own: the chunk in use keeps its room
                return out + skip
            self.free, self.left = out + skip, total - skip
        out = self.free
        self.free += need
        self.left -= need
        return out

    cdef void* new_int(self, Py_ssize_t size) except NULL:
        """A zeroed array of ``size`` pointer-sized integers (at least one): carved as
        doubles, which are as wide or wider, and zero bits are the integer 0."""
        return self.new(size)

    cdef double* adopt(self, object array) except NULL:
        """Keep the float64 numpy ``array`` (at least one entry) and point into it."""
        self.kept.append(array)
        cdef double[::1] view = array
        return &view[0]


cdef void common_arrays(Arrays a, Engine* e, Py_ssize_t memory, Py_ssize_t log_rows) except *:
    """The vectors of every storage, for ``e.prob``'s sizes (``n``, ``m``, ``s`` set)."""
    cdef Py_ssize_t n = e.prob.n, m = e.prob.m, s = e.prob.s, N = n + m
    cdef Py_ssize_t wide = max(n, m)
    p = &e.prob
    p.q, p.b = a.new(n), a.new(m)
    p.lo, p.hi, p.D, p.E = a.new(s), a.new(s), a.new(n), a.new(m)
    p.span = a.new(m)
    p.c = 1.0
    u = &e.user
    u.q, u.b = a.new(n), a.new(m)
    u.lb, u.ub = a.new(n), a.new(n)
    e.fact.rho_scale = a.new(s)
    u.entry_kind = <char*>a.new(n)
    e.scaling.d, e.scaling.e = a.new(n), a.new(m)
    e.scaling.reference, e.scaling.norms = a.new(N), a.new(N)
    e.scaling.other_D, e.scaling.other_E = a.new(n), a.new(m)
    e.scaling.other_reference = a.new(N)
    e.scaling.other_done = False
    it = &e.it
    it.x, it.nu, it.z, it.y = a.new(n), a.new(m), a.new(s), a.new(s)
    it.x_prev, it.nu_prev = a.new(n), a.new(m)
    it.z_prev, it.y_prev = a.new(s), a.new(s)
    it.relaxed, it.rho_vec = a.new(s), a.new(s)
    w = &e.work
    w.rhs, w.sol = a.new(N), a.new(N)
    w.vec_n, w.vec_n2, w.vec_n3 = a.new(wide), a.new(wide), a.new(wide)
    w.vec_s, w.vec_s2, w.vec_m = a.new(s), a.new(s), a.new(m)
    w.vec_m2 = a.new(m)
    w.guess_point, w.guess_codes = a.new(s), <char*>a.new(s)
    e.certs.direction, w.saved, e.certs.cert = a.new(n), a.new(N + s), a.new(N)
    e.prev.x, e.prev.y, e.prev.z = a.new(n), a.new(m), a.new(n)
    kk = &e.fact.kkt
    kk.work = a.new(N)
    red = &e.red
    red.base = a.new(N)
    red.u, red.u_prev, red.v, red.v_prev = a.new(s), a.new(s), a.new(s), a.new(s)
    red.xs = a.new(s)
    aa = &e.aa
    aa.capacity = <int>memory
    aa.dgf, aa.df = a.new(memory * 2 * s), a.new(memory * 2 * s)
    aa.g, aa.f, aa.g_new, aa.f_new = a.new(2 * s), a.new(2 * s), a.new(2 * s), a.new(2 * s)
    aa.plain, aa.gram, aa.gamma = a.new(2 * s + 1), a.new(memory * memory), a.new(memory)
    aa.products = a.new(memory * memory)
    rs = &e.rest
    rs.pinned = <char*>a.new(s)
    rs.target, rs.projected = a.new(s), a.new(s)
    rs.positions, rs.entries = <Py_ssize_t*>a.new_int(s), <Py_ssize_t*>a.new_int(s)
    rs.step = a.new(s)
    rs.start, rs.point = a.new(N), a.new(N)
    pol = &e.pol
    pol.active = <char*>a.new(s)
    pol.dropped = <char*>a.new(s)
    pol.bare, pol.kept_plane = <char*>a.new(s), a.new(s)
    pol.blocked = <char*>a.new(s)
    pol.index, pol.free = <Py_ssize_t*>a.new_int(n), <Py_ssize_t*>a.new_int(n)
    pol.boundary = <Py_ssize_t*>a.new_int(s)
    pol.g, pol.lam = a.new(s), a.new(s)
    pol.ipiv = <int*>a.new_int(N + s)
    pol.rhs, pol.step = a.new(N + s), a.new(N + s)
    pol.x, pol.nu, pol.y = a.new(n), a.new(m), a.new(s)
    pol.x_prev, pol.nu_prev = a.new(n), a.new(m)
    pol.chord_start = a.new(n + m + 2 * s)
    pol.grad, pol.ATnu, pol.Ax = a.new(n), a.new(n), a.new(m)
    pol.tpiv = <int*>a.new_int(2 * s)
    pol.tr, pol.du = a.new(2 * s), a.new(2 * s)
    pol.full, pol.dfull = a.new(N), a.new(N)
    pol.schur_only = pol.schur_failed = False
    pol.guess_passes = GUESS_PASSES
    pol.warm = pol.bare_start = False
    pol.schur.ready = False   # dense_arrays gives it storage (polish_schur_arrays)
    e.unscaled.x, e.unscaled.y, e.unscaled.z = a.new(n), a.new(m), a.new(n)
    e.log.capacity = log_rows
    e.log.rows = a.new(5 * log_rows)
    e.log.count = 0


cdef void dense_arrays(Arrays a, Engine* e, Py_ssize_t* order) except *:
    """Row-major ``P`` and ``A`` (scaled and the user's) and the arrays sized by their
    products, for the dense backends (``order``: the Schur backend's base order)."""
    cdef Py_ssize_t n = e.prob.n, m = e.prob.m, s = e.prob.s, N = n + m
    p = &e.prob
    p.P, p.A = dense(a.new(n * n), n, n), dense(a.new(m * n), m, n)
    u = &e.user
    u.P, u.A = dense(a.new(n * n), n, n), dense(a.new(m * n), m, n)
    e.certs.gram = a.new(m * m)
    sp = &e.scaling.pattern   # ints in arrays of pointer-sized ones: room to spare
    sp.P_start, sp.P_index = <int*>a.new_int(n + 1), <int*>a.new_int(n * n)
    sp.A_start, sp.A_index = <int*>a.new_int(m + 1), <int*>a.new_int(m * n)
    kk = &e.fact.kkt
    kk.sparse = NULL
    kk.ldl.N = <int>N
    kk.ldl.K = a.new(N * N)
    kk.ldl.ipiv = <int*>a.new_int(N)
    kk.ldl.lwork = <int>(64 * N)
    kk.ldl.work, kk.ldl.residual = a.new(64 * N), a.new(N)
    kk.ldl.Ax, kk.ldl.ATnu = a.new(m), a.new(n)
    kk.schur.n, kk.schur.m = <int>n, <int>m
    kk.schur.L, kk.schur.LS, kk.schur.Y = a.new(n * n), a.new(m * m), a.new(n * m)
    kk.schur.G, kk.schur.free_ready = a.new(m * m), False
    kk.schur.base_order = order
    kk.schur.order = <Py_ssize_t*>a.new_int(n)
    kk.schur.coupled = <char*>a.new(n)
    kk.schur.dense = <int>n
    kk.schur.perm, kk.schur.dx, kk.schur.r = a.new(n), a.new(n), a.new(n)
    kk.schur.ATnu, kk.schur.dnu, kk.schur.Ax = a.new(n), a.new(m), a.new(m)
    kk.schur.X, kk.schur.Wnu, kk.schur.M = a.new(n * s), a.new(m * s), a.new(s * s)
    kk.schur.nonzeros = <int*>a.new_int(n * m)
    kk.schur.nonzero_count = <int*>a.new_int(n)
    kk.schur.T, kk.schur.tail_values = a.new(m * m), a.new(m)
    kk.R = a.new(N * s)
    e.red.W, e.red.W_S = a.new(N * s), a.new(s * s)
    e.work.mat_s = a.new(s * s)   # the cold start's small system (dense Schur only)
    e.rest.W_T, e.rest.gram = a.new(N * s), a.new(s * s)
    pol = &e.pol
    pol.hess = a.new(s * s)
    pol.K = a.new((N + s) * (N + s))
    pol.lwork = <int>(64 * (N + s))
    pol.work = a.new(64 * (N + s))
    pol.T = a.new(4 * s * s)
    polish_schur_arrays(a, &pol.schur, n, m, s)


cdef void polish_schur_arrays(Arrays a, PolishSchur* ps, Py_ssize_t n, Py_ssize_t m,
                              Py_ssize_t s) except *:
    """The storage of :mod:`fccqp.polish_schur`'s Schur-complement polish for ``n``
    entries, ``m`` rows and ``s`` constrained entries (dense ``P`` and ``A`` only)."""
    ps.order, ps.coupled = <Py_ssize_t*>a.new_int(n), <char*>a.new(n)
    ps.root, ps.inv_root = a.new(n), a.new(n)
    ps.rowvar, ps.block_row = <Py_ssize_t*>a.new_int(n), <Py_ssize_t*>a.new_int(s)
    ps.t, ps.t2, ps.u = a.new(n), a.new(n), a.new(m + s)
    ps.row_nz, ps.row_count = <int*>a.new_int(n * (m + s)), <int*>a.new_int(n)
    ps.nz_values = a.new(m + s)
    ps.entry_nz, ps.entry_values = <int*>a.new_int(n * m), a.new(n * m)
    ps.entry_count = <int*>a.new_int(n)
    ps.L, ps.Y = a.new(n * n), a.new(n * (m + s))
    ps.SU, ps.S = a.new(m * m), a.new((m + s) * (m + s))
    ps.block = a.new(s * s)
    ps.base, ps.bordered = 0, False   # BASE_NONE
    ps.border, ps.border_col = <Py_ssize_t*>a.new_int(s), <Py_ssize_t*>a.new_int(s)
    ps.cone_base = <char*>a.new(s)
    ps.S0, ps.LSC, ps.W = a.new(m * m), a.new(m * m), a.new(m * s)
    ps.arow, ps.SC, ps.diag0 = <Py_ssize_t*>a.new_int(m), a.new(m * m), a.new(m)
    ps.lead_rows, ps.lead_valid = <Py_ssize_t*>a.new_int(n), False
    ps.WW, ps.K, ps.Z, ps.T = a.new(s * s), a.new(s * s), a.new(s * s), a.new(s * s)


cdef Py_ssize_t* _index_copy(Arrays a, object values) except NULL:
    """A private intp copy of ``values`` (at least one entry), kept with the workspace."""
    cdef Py_ssize_t* out = <Py_ssize_t*>a.new_int(len(values))
    cdef Py_ssize_t[::1] source = values
    cdef Py_ssize_t k
    for k in range(source.shape[0]):
        out[k] = source[k]
    return out


cdef object csc_arrays(Arrays a, Engine* e, object patterns, object constrained):
    """``P`` (its full symmetric pattern) and ``A`` in compressed columns, scaled and the
    user's, over private copies of the ``patterns`` ``(P colptr, P rowind, A colptr, A
    rowind)``, and the ``SPARSE_LDL`` backend's :class:`fccqp.sparse_kkt.SparseKKT`
    over the scaled arrays (``constrained``: the intp array of the constrained
    entries), and the polish's arrays (:func:`fccqp.polish_csc.arrays`, bound to
    ``e.pol.csc``); returns the ``SparseKKT``, for the workspace to own. The dense-only
    arrays stay NULL (the workspace's Engine starts zeroed)."""
    import scipy.sparse as sp

    from fccqp.sparse_kkt import SparseKKT

    cdef Py_ssize_t n = e.prob.n, m = e.prob.m, k
    P_colptr, P_rowind, A_colptr, A_rowind = (np.array(v, dtype=np.intp) for v in patterns)
    cdef Py_ssize_t entries_P = P_colptr[n], entries_A = A_colptr[n]
    cdef Py_ssize_t* pc = _index_copy(a, P_colptr)
    cdef Py_ssize_t* pr = _index_copy(a, P_rowind)
    cdef Py_ssize_t* ac = _index_copy(a, A_colptr)
    cdef Py_ssize_t* ar = _index_copy(a, A_rowind)
    P_scaled, A_scaled = np.zeros(max(entries_P, 1)), np.zeros(max(entries_A, 1))
    p = &e.prob
    p.P = csc(a.adopt(P_scaled), pc, pr, n, n)
    p.A = csc(a.adopt(A_scaled), ac, ar, m, n)
    u = &e.user
    u.P = csc(a.new(entries_P), pc, pr, n, n)
    u.A = csc(a.new(entries_A), ac, ar, m, n)
    E = np.asarray(<double[:m]>p.E) if m else np.ones(0)
    kkt = SparseKKT(sp.csc_matrix((P_scaled[:entries_P], P_rowind, P_colptr), shape=(n, n)),
                    sp.csc_matrix((A_scaled[:entries_A], A_rowind, A_colptr), shape=(m, n)),
                    constrained, E)
    kk = &e.fact.kkt
    kk.sparse = <void*>kkt
    kk.backend = SPARSE_LDL
    e.fact.form = SPARSE_LDL
    held = polish_arrays(n, m, P_colptr, P_rowind, A_colptr, A_rowind,
                         [p.cones.dim[k] for k in range(p.cones.count)])
    a.kept.append(held)
    bind(&e.pol.csc, held)
    return kkt
