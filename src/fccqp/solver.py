"""The user-facing solver: argument conversion, the reuse decision and the errors.

Everything numeric happens in one compiled call per solve,
:meth:`fccqp.admm.Workspace.solve`, which returns the :class:`~fccqp.result.Result`;
this module converts the arguments, decides whether the previous solve's workspace fits
the new problem's structure, and acts on the codes the call returns instead (a new
workspace when the bounds changed the structure, the error that names the argument).
Problems whose KKT matrix exceeds :data:`fccqp.settings.MAX_DENSE_KKT_ROWS` rows, and
every problem with ``kkt_backend="sparse"``, take the sparse path instead, before
anything is densified: the same compiled call on a workspace that holds ``P`` and ``A``
in compressed columns (:meth:`Solver._solve_sparse`).
"""

from __future__ import annotations

import time
from collections.abc import Sequence

import numpy as np

from fccqp import admm, auxiliary
from fccqp.cones import Cone, ConeArrays, flatten_cones
from fccqp.fast_checks import dense_arguments, dense_vector_within, same_cones
from fccqp.problem import check_cone_bounds, convert, raise_finding
from fccqp.result import Result
from fccqp.settings import MAX_DENSE_KKT_ROWS, Settings
from fccqp.status import Status
from fccqp.tuning import AUXILIARY_TIME, MAX_ENTRY
from fccqp.validation import structure_scan

LOG_ROWS = 1024
"""Most lines of the verbose log kept per solve (one every ``tuning.LOG_INTERVAL``
iterations, the first and the last)."""
EIGENVALUE_DENSE_LIMIT = 2000
"""Largest ``n`` whose smallest eigenvalue of ``P`` a non-convexity error computes with a
dense ``eigvalsh``; ARPACK above."""
KEPT_WORKSPACES = 4
"""Workspaces a :class:`Solver` keeps for structures it left, so that a return to one
(a controller whose contact set comes back) allocates nothing and, with
``settings.warm_start``, starts from that structure's last answer: on talos_reduced
(124 variables, 68 rows) a new workspace took 0.35-4 ms, most of a 2 ms budget, against
the microseconds of the return to a kept one."""
UNANSWERED = (Status.MAX_ITER_REACHED, Status.NUMERICAL_ERROR)
"""The statuses of a run that gave no answer, which, without a time limit, gets the
stalled run's certificates and second tries (:meth:`Solver._stalled`). A
NUMERICAL_ERROR is also the run whose iterate passed and whose returned point did not:
with ``P`` of 1e18 the reduced form's final ``A x = b`` correction moved a cone block
of size 3e-11 outside its cone by 5e-12, beyond the scaled-units guard, where the
full form ends SOLVED (fuzz extreme_data:2100247)."""
NO_GUESS = (None, None, None)
"""The ``(x0, y0, z0)`` of a solve without an initial guess (:func:`_guess`)."""


class _Structure:
    """What a workspace was allocated for, kept up to date in place by
    :func:`fccqp.validation.structure_scan`: the constrained entries, the fixed ones
    and the cone blocks' offsets among them, for ``n`` variables and ``m`` rows. The
    workspace checks the bounds against it in every solve and asks for a rescan
    (``admm.STRUCTURE_CHANGED``) when they moved.

    :attr:`key` is what a workspace for it is made of (a solver's settings are fixed):
    equal keys, interchangeable workspaces. It is made by each :meth:`update` (the cone
    blocks, the rest of it, do not change) and read as an attribute: a contact change
    reads two, and a method's frame there, run cold after a stretch of ticks of another
    structure, cost about 0.5 us each (notes/performance-history.md, "contactentry")."""

    __slots__ = ("n", "m", "count", "constrained", "fixed", "relocated", "_cones",
                 "certificate", "last_cones", "key")

    def __init__(self, n: int, m: int, cones: ConeArrays) -> None:
        self.n, self.m, self.count, self._cones = n, m, 0, cones
        self.constrained, self.fixed = np.empty(n, np.intp), np.empty(n, np.uint8)
        self.relocated = np.empty(cones.count, np.intp)
        self.certificate = np.empty(n + m)  # copied into the Result only when infeasible
        self.last_cones: object = None   # the cones argument last solved in its workspace
        self.key: tuple[object, ...] = ()   # made by update

    @property
    def cones(self) -> ConeArrays:
        """The cone blocks with the friction of the workspace's last solve: those of
        :attr:`last_cones`, flattened when first asked for after :meth:`friction_of`."""
        if self._cones is None:
            self._cones = flatten_cones(self.last_cones, self.n)
        return self._cones

    @cones.setter
    def cones(self, flat: ConeArrays) -> None:
        self._cones = flat

    def friction_of(self, cones: object) -> None:
        """Record that the workspace now holds the friction of ``cones``, validated cone
        specs on its blocks (:meth:`fccqp.admm.Workspace.switch`), flattened only when
        :attr:`cones` is asked for: a switch that solves needs no flat form."""
        self._cones, self.last_cones = None, cones

    def update(self, lb: np.ndarray, ub: np.ndarray) -> bool:
        """Scan the bounds and make :attr:`key`; True when the constrained or fixed
        entries changed."""
        count, changed, member = structure_scan(
            lb, ub, self.cones.offset, self.cones.dim, self.constrained, self.fixed,
            self.relocated, self.count)
        check_cone_bounds(member, lb, ub)
        cones, self.count = self.cones, count
        self.key = (self.n, self.m, self.constrained[:count].tobytes(),
                    self.fixed[:count].tobytes(), cones.kind.tobytes(),
                    cones.offset.tobytes(), cones.dim.tobytes())
        return changed

    def workspace(self, settings: Settings) -> admm.Workspace:
        """A workspace for this structure: it copies the arrays it is given, and orders
        the Schur backend's entries itself."""
        cones = self.cones
        cone_arrays = (cones.kind, self.relocated, cones.dim, cones.mu, cones.normal)
        log_rows = LOG_ROWS if settings.verbose else 0
        return admm.Workspace(self.n, self.m, self.constrained[: self.count], cone_arrays,
                              self.fixed[: self.count], None, settings, log_rows)


class Solver:
    """ADMM solver for QPs with equalities, a box and friction / second-order cones.

    A ``Solver`` keeps its workspace between :meth:`solve` calls. With
    ``settings.warm_start`` each solve starts from the previous primal and dual
    solution and rho; when ``P``, ``A``, the constrained entries and rho are
    unchanged the scaling and the KKT factorization are reused as well. When the sizes,
    the cone blocks or which entries are bounded or fixed change, the solve starts cold
    in a workspace for the new structure; the last :data:`KEPT_WORKSPACES` ones are kept,
    so that a structure that comes back (a contact set) allocates nothing and starts
    warm from its own last answer. :meth:`reset` makes every next start cold.

    Parameters
    ----------
    settings : Settings, optional
        Defaults to ``Settings()``.
    **overrides
        Fields of :class:`Settings` to change, e.g. ``Solver(max_iter=100)``.
    """

    def __init__(self, settings: Settings | None = None, **overrides: object) -> None:
        if settings is not None and not isinstance(settings, Settings):
            raise TypeError(f"settings must be a fccqp.Settings, got {type(settings).__name__}")
        self._settings = (settings or Settings()).replace(**overrides)
        self._structure: _Structure | None = None
        self._workspace: admm.Workspace | None = None
        # structures left and their workspaces, oldest first
        self._kept: dict[tuple[object, ...], tuple[_Structure, admm.Workspace]] = {}
        self._sparse: tuple | None = None   # (its key, the sparse path's workspace)
        self._cones: object = None   # the cones argument of the last dense solve
        self._stalled_certificates = True   # False in fccqp.auxiliary's own solves

    @property
    def settings(self) -> Settings:
        """The settings of every solve, fixed for the solver's life: its workspaces are
        built for them (Anderson memory, log, backend), so a new ``Solver`` takes others."""
        return self._settings

    @settings.setter
    def settings(self, value: object) -> None:
        raise AttributeError(
            "Solver.settings cannot be changed: the solver's workspaces are built for its "
            "settings; make a new fccqp.Solver(settings) instead")

    def reset(self) -> None:
        """Forget the previous solves: the next one starts cold, and so does the first
        solve of each structure left before (the kept workspaces' answers). A workspace
        keeps its scaling, which new data share while their norms stay within its drift
        (:func:`fccqp.scaling.rescale`)."""
        if self._workspace is not None:
            self._workspace.forget()
        for _, w in self._kept.values():
            w.forget()
        if self._sparse is not None:
            self._sparse[1].forget()

    def solve(
        self,
        P: object,
        q: object,
        A: object = None,
        b: object = None,
        lb: object = None,
        ub: object = None,
        cones: Sequence[Cone] = (),
        *,
        x0: object = None,
        y0: object = None,
        z0: object = None,
    ) -> Result:
        """Solve ``min 1/2 x'Px + q'x  s.t.  A x = b, lb <= x <= ub, x[block] in cone``.

        Parameters
        ----------
        P : (n, n) array_like or scipy.sparse matrix
            Symmetric cost matrix (densified if sparse, unless the problem takes the
            sparse path); the QP must be convex on the null space of ``A`` (see
            docs/formulation.md).
        q : (n,) array_like
            Linear cost.
        A, b : (m, n) and (m,) array_like, optional
            Equality constraints, held to factorization accuracy at every iterate.
        lb, ub : (n,) array_like, optional
            Bounds, ``-inf``/``+inf`` (or beyond ``1e20`` in magnitude) where absent.
            Entries of cone blocks must be free.
        cones : sequence of FrictionCone or SecondOrderCone
            Disjoint cone blocks of ``x``.
        x0 : (n,) array_like, optional
            Primal initial guess; overrides the warm start from the previous solve.
        y0, z0 : (m,) and (n,) array_like, optional
            Dual guesses beside ``x0``, in the conventions of :attr:`Result.y` and
            :attr:`Result.z` (a missing one is zero), as OSQP's ``warm_start(x, y)``:
            the solve then starts from ``(x0, y0, z0)`` as a warm start from the
            previous answer does, at the rho of this structure's last solve
            (``settings.rho`` on a new one), trying first the polish on the guess's
            active set. Solving a problem again from its own :class:`Result`'s ``x, y,
            z`` takes no ADMM iteration when that result was polished. A caller whose
            problem changed size (a contact made or broken) passes the previous
            answer mapped onto the new variables and rows; such a guess, carried from
            another structure than the last solve's, is polished first from ``x0`` with
            nothing held (its multipliers serve ADMM's start, not the polish's first
            guess: the new stance releases some of what they hold).

        Returns
        -------
        Result
            Only ``Status.SOLVED`` means that the returned point meets the tolerances.
            ``Result.backend`` is ``"sparse"`` when the problem took the sparse path:
            ``settings.kkt_backend == "sparse"``, or a KKT matrix (``n + m`` rows) above
            :data:`fccqp.settings.MAX_DENSE_KKT_ROWS`.

        Raises
        ------
        ValueError, TypeError
            On malformed input, naming the argument, and when the QP is not convex
            (detected from the inertia of the KKT matrix).
        ImportError
            When the problem takes the sparse path and ``qdldl`` is not installed.
        """
        start = time.perf_counter()
        settings = self._settings
        w, structure = self._workspace, self._structure
        sparse = settings.kkt_backend == "sparse"
        guessless = x0 is None and y0 is None and z0 is None
        switched = None
        dense = w is not None and not sparse
        if dense:
            if guessless and not same_cones(cones, self._cones):   # a contact change, or
                # other cones: the kept workspace whose last solve had these, if one did
                returning, its_structure = self._returning(cones, P, q, A, b, lb, ub)
                if returning is not None:
                    w, structure = returning, its_structure
            # every tick through the compiled call a contact change's guess takes, so that
            # its code runs warm there (anymal_c's contact tick 5 % faster in lockstep, the
            # warm ticks unchanged; notes/performance-history.md, "onecall")
            switched = w.switch(structure, self._kept, P, q, A, b, lb, ub, cones, x0, y0, z0,
                                settings.warm_start, start)
            if switched is admm.FITS_CURRENT and guessless and same_cones(cones, self._cones):
                # the control loop with other cones than upright friction: as they came
                out = w.solve(P, q, A, b, lb, ub, None, settings.warm_start, start,
                              structure.certificate, False)
                if (type(out) is Result and not settings.verbose
                        and out.status not in UNANSWERED and not w.doubt):
                    return out
                return self._result(out, P, q, A, b, lb, ub, NO_GUESS, start)
        if switched is admm.FITS_CURRENT:
            n, m = structure.n, structure.m   # the arrays fit as they are
            flat = flatten_cones(cones, n)   # memoized: the same object for the same cones
        elif switched is not None:   # solved on this workspace or on a kept one
            entry, out = switched
            if entry is not None:   # a kept one: the switch kept the current one in its place
                structure, w = entry
                self._structure, self._workspace = entry
            self._cones = cones
            structure.friction_of(cones)   # their flat form made when asked for
            if (type(out) is Result and not w.doubt and not settings.verbose
                    and (out.status is Status.SOLVED or guessless and entry is None
                         and out.status not in UNANSWERED)):
                return out   # the control loop's answer, without _result
            return self._result(out, P, q, A, b, lb, ub, NO_GUESS if x0 is None
                                else (x0, y0, z0), start)
        elif dense and (flat := self._switch(cones, P, q, A, b, lb, ub)) is not None:
            w, structure = self._workspace, self._structure   # a kept one they fit
            n, m = structure.n, structure.m
        else:
            n, m = _rows(P), _rows(A)
            if sparse or n + m > MAX_DENSE_KKT_ROWS:
                return self._solve_sparse(P, q, A, b, lb, ub, cones, (x0, y0, z0), start)
            # a structure switch's arrays, taken as they are when they fit their own shapes
            if not (n and dense_arguments(P, q, A, b, lb, ub, n, m)):
                P, q, A, b, lb, ub = convert(P, q, A, b, lb, ub)
                n, m = P.shape[0], A.shape[0]
            flat = flatten_cones(cones, n)
        self._cones = cones
        guess = _guess(x0, y0, z0, n, m)
        if w is None or (structure.n, structure.m) != (n, m) or not flat.same_blocks(
                structure.cones):
            structure = _Structure(n, m, flat)
            structure.update(lb, ub)
            w = self._adopt(structure)
        elif flat is not structure.cones:
            w.update_cones(flat.mu, flat.normal)
        structure.cones, structure.last_cones = flat, cones
        out = w.solve(P, q, A, b, lb, ub, guess[0], settings.warm_start, start,
                      structure.certificate, True, *guess[1:])
        return self._result(out, P, q, A, b, lb, ub, guess, start)

    def _returning(self, cones: object, P: object, q: object, A: object, b: object,
                   lb: object, ub: object) -> tuple[admm.Workspace | None, _Structure | None]:
        """The kept workspace whose last solve had the cones ``cones`` (the same values,
        :func:`fccqp.fast_checks.same_cones`) and the shapes of the arguments as they
        came, made current (it starts from its last answer, as :meth:`_adopt` would
        start it), with its structure; ``(None, None)`` when none is. The general path
        (conversion, a structure scan, two keys, new structure arrays) took 87k
        instructions per go2 switch beside a 1.43M cold solve (callgrind). The solve
        still checks the bounds against the workspace's structure, and
        ``STRUCTURE_CHANGED`` leads to a new workspace as on the general path."""
        for key, (structure, w) in self._kept.items():
            if (same_cones(cones, structure.last_cones)
                    and dense_arguments(P, q, A, b, lb, ub, structure.n, structure.m)):
                self._make_current(key, structure, w)
                self._cones = cones
                return w, structure
        return None, None

    def _switch(self, cones: object, P: object, q: object, A: object, b: object,
                lb: object, ub: object) -> ConeArrays | None:
        """The flattened ``cones`` once the kept workspace whose shapes the arguments fit
        as they came and whose cone blocks are those of ``cones`` is made current, as
        :meth:`_returning` makes one current, with the friction coefficients and normals
        of ``cones`` (the terrain's may differ); None when no kept workspace is such. A
        contact change with a caller's guess, or onto other friction, lands here. The
        general path (a new structure's arrays, its scan, two keys, numpy's writes of the
        friction) costs solo12 6 us when the interpreter runs it warm, 38 us when it runs
        once after a stretch of ticks of another structure, as a contact change does
        (notes/performance-history.md, "contactwall"). The solve checks the bounds
        against the workspace's structure, and ``STRUCTURE_CHANGED`` leads to the general
        path's new structure (:meth:`_result`)."""
        for key, (structure, w) in self._kept.items():
            if dense_arguments(P, q, A, b, lb, ub, structure.n, structure.m):
                flat = flatten_cones(cones, structure.n)
                if flat.same_blocks(structure.cones):
                    self._make_current(key, structure, w)
                    if flat is not structure.cones:
                        w.update_cones(flat.mu, flat.normal)
                        structure.cones = flat
                    return flat
        return None

    def _make_current(self, key: tuple, structure: _Structure, w: admm.Workspace) -> None:
        """Make the kept workspace ``w`` of ``structure`` (kept under ``key``) current,
        keeping the current one (a switch: there is one) in its place, so that the
        number kept stays within :data:`KEPT_WORKSPACES`; a guess given to its next solve
        comes from another structure (``Workspace.arrived``). The swap is spelled out
        here, without :meth:`_keep_current`'s frame and bound: on a contact change the
        interpreter runs this once after a stretch of ticks of another structure, cold,
        where each frame costs about 0.5 us (notes/performance-history.md,
        "contactentry")."""
        kept = self._kept
        del kept[key]
        kept[self._structure.key] = (self._structure, self._workspace)
        self._structure, self._workspace = structure, w
        w.arrived = True

    def _keep_current(self) -> None:
        """Keep the current workspace with its structure (:data:`KEPT_WORKSPACES`)."""
        if self._workspace is not None:
            self._kept[self._structure.key] = (self._structure, self._workspace)
            while len(self._kept) > KEPT_WORKSPACES:
                del self._kept[next(iter(self._kept))]

    def _result(self, out: Result | int, P: np.ndarray, q: np.ndarray, A: np.ndarray,
                b: np.ndarray, lb: np.ndarray, ub: np.ndarray, guess: tuple,
                start: float) -> Result:
        """The :class:`Result` of the dense solve that returned ``out``: ``out`` itself,
        after a new workspace and a second solve (from the same ``guess``, the
        ``(x0, y0, z0)`` of :func:`_guess`) when the bounds changed its structure, or
        the error the code says it found."""
        settings = self._settings
        w, structure = self._workspace, self._structure
        if type(out) is int and out == admm.STRUCTURE_CHANGED:   # the workspace's own scan
            structure = _Structure(structure.n, structure.m, structure.cones)
            structure.update(lb, ub)
            structure.last_cones = self._cones
            w = self._adopt(structure)
            out = w.solve(P, q, A, b, lb, ub, guess[0], settings.warm_start, start,
                          structure.certificate, True, *guess[1:])
        if type(out) is int and out == admm.BAD_DATA:
            raise_finding(w.finding, lb, ub)
        if type(out) is int:   # NOT_CONVEX_CODE, the only code left
            self._workspace = self._structure = None
            raise _not_convex(P)
        if out.status in UNANSWERED and _room(settings, start):
            resume = (P, q, A, b, lb, ub, None, True, start, structure.certificate, False)
            out = self._stalled(out, w, (P, q, A, b, lb, ub), self._cones, start, resume)
        elif w.doubt and self._stalled_certificates and _room(settings, start):
            out = self._doubted(out, w, (P, q, A, b, lb, ub), self._cones, start)
        elif (out.status is Status.PRIMAL_INFEASIBLE and self._stalled_certificates
              and settings.kkt_backend == "auto" and _room(settings, start)
              and auxiliary.weakly_separated(out, b, lb, ub)):
            again = auxiliary.solved_in_other_form(Solver, settings, out,
                                                   (P, q, A, b, lb, ub, self._cones),
                                                   start + settings.time_limit)
            if again is not None:   # this workspace holds no solution to start from
                w.forget()
                out = Result._of({**again.__dict__, "solve_time": time.perf_counter() - start})
        if settings.verbose:
            _print_log(w.log_lines, out)
        return out

    def _stalled(self, out: Result, workspace: admm.Workspace, arguments: tuple,
                 cones: object, start: float, resume: tuple) -> Result:
        """``out`` of a run that stalled (:data:`UNANSWERED`) in ``workspace`` on the
        problem of ``arguments`` (``P, q, A, b, lb, ub``): first the run goes on from
        where it stopped (:func:`_resumed`; ``resume``, the arguments of
        ``workspace.solve`` for it); when that too ends unanswered, the certificate that
        :func:`fccqp.auxiliary.stalled_certificate` finds for it, or the answer of a
        solve in the other KKT form (with ``kkt_backend="auto"`` on the dense path), at
        another rho or without equilibration (:func:`fccqp.auxiliary.solved_again`);
        their iterations and factorizations added. Either leaves no previous solution to
        start from: a certified problem as an infeasible run does, an answer from
        another solver because this workspace holds the stalled point."""
        out = _resumed(out, workspace, resume)
        if out.status not in UNANSWERED or not self._stalled_certificates:
            return out
        deadline = start + self._settings.time_limit   # the run's budget (_room)
        found = auxiliary.stalled_certificate(Solver, self._settings, workspace, *arguments,
                                              cones, deadline=deadline)
        if found is None:
            # the other form only where the form was fccqp's choice
            switch_form = self._settings.kkt_backend == "auto" and not workspace.compressed
            again = auxiliary.solved_again(Solver, self._settings, out,
                                           (*arguments, cones), switch_form, deadline)
            if again is not None:
                workspace.forget()
                return Result._of({
                    **again.__dict__,
                    "iterations": out.iterations + again.iterations,
                    "factorizations": out.factorizations + again.factorizations,
                    "solve_time": time.perf_counter() - start,
                })
        return out if found is None else _certified(out, found, workspace, start)

    def _doubted(self, out: Result, workspace: admm.Workspace, arguments: tuple,
                 cones: object, start: float) -> Result:
        """``out``, solved or inaccurate on tolerances that its entries' own units do
        not give it (:attr:`fccqp.admm.Workspace.doubt`), or the certificate that
        :func:`fccqp.auxiliary.stalled_certificate` finds for the problem instead: the
        primal one when the set test was lent, the dual one when the dual test was.

        Such a point meets the tolerances as documented, and the problem may still have
        no solution: cones pinned outside their sum by 1e-3 of their size beside an
        entry of 6.3e6, a ray whose descent ``q`` of 1e-9 lies below ``eps_abs`` (fuzz
        extreme_data 1182, 489). A certificate is judged relative to the data, not in
        its units, and proves that no point is a solution: it wins. Without a time
        limit or with its room (:func:`_room`), as for a stalled run; a feasible, bounded
        problem keeps ``out``."""
        found = auxiliary.stalled_certificate(
            Solver, self._settings, workspace, *arguments, cones,
            primal=bool(workspace.doubt & admm.DOUBT_PRIMAL),
            dual=bool(workspace.doubt & admm.DOUBT_DUAL),
            deadline=start + self._settings.time_limit)
        return out if found is None else _certified(out, found, workspace, start)

    def _adopt(self, structure: _Structure) -> admm.Workspace:
        """Make ``structure`` and a workspace for it current, keeping the current one
        (:data:`KEPT_WORKSPACES`): a kept workspace of the same structure is reused
        (with ``settings.warm_start`` it starts from its last answer, as a return through
        :meth:`_returning` does), otherwise a new one is allocated. A guess given to its
        next solve came from the current one's structure (``Workspace.arrived``), when
        there was one."""
        arrived = self._workspace is not None
        self._keep_current()
        kept = self._kept.pop(structure.key, None)
        if kept is None:
            w = structure.workspace(self._settings)
        else:
            w = kept[1]
            w.update_cones(structure.cones.mu, structure.cones.normal)
        w.arrived = arrived
        self._structure, self._workspace = structure, w
        return w

    def _solve_sparse(self, P: object, q: object, A: object, b: object, lb: object,
                      ub: object, cones: Sequence[Cone], given: tuple,
                      start: float) -> Result:
        """The sparse path: the arguments in compressed columns
        (:func:`fccqp.sparse_problem.convert`), solved by the same compiled call in a
        workspace that holds them so and factors with ``SPARSE_LDL``
        (:meth:`_sparse_workspace`); the same Result and errors as the dense path."""
        from fccqp import sparse_problem

        settings = self._settings
        data = sparse_problem.convert(P, q, A, b, lb, ub, cones)
        guess = _guess(*given, data.n, data.m)
        w = self._sparse_workspace(data, False)
        certificate = np.empty(data.n + data.m)
        arguments = (data.P.data, data.q, data.A.data, data.b, data.lb, data.ub, guess[0],
                     settings.warm_start, start, certificate, True, *guess[1:])
        out = w.solve(*arguments)
        if type(out) is int and out == admm.STRUCTURE_CHANGED:
            w = self._sparse_workspace(data, True)
            out = w.solve(*arguments)
        if type(out) is int and out == admm.BAD_DATA:
            raise_finding(w.finding, data.lb, data.ub)
        if type(out) is int:   # NOT_CONVEX_CODE, the only code left
            self._sparse = None
            raise _not_convex(data.P)
        if out.status in UNANSWERED and _room(settings, start):
            resume = (*arguments[:6], None, True, start, certificate)
            out = self._stalled(out, w, (data.P, data.q, data.A, data.b, data.lb, data.ub),
                                cones, start, resume)
        elif w.doubt and self._stalled_certificates and _room(settings, start):
            out = self._doubted(out, w, (data.P, data.q, data.A, data.b, data.lb, data.ub),
                                cones, start)
        if settings.verbose:
            _print_log(w.log_lines, out)
        return out

    def _sparse_workspace(self, data: object, renew: bool) -> admm.Workspace:
        """The compressed-column workspace for ``data`` (a
        :class:`fccqp.sparse_problem.SparseData`): the last one when its structure and
        its matrices' patterns are ``data``'s (and not ``renew``), else a new one, to
        which a guess comes from another structure (``Workspace.arrived``) when a
        workspace solved before it."""
        cones = data.cones
        key = (data.n, data.m, data.constrained.tobytes(), data.fixed.tobytes(),
               cones.kind.tobytes(), cones.offset.tobytes(), cones.dim.tobytes(),
               data.P.indptr.tobytes(), data.P.indices.tobytes(), data.A.indptr.tobytes(),
               data.A.indices.tobytes())
        if self._sparse is None or self._sparse[0] != key or renew:
            log_rows = LOG_ROWS if self._settings.verbose else 0
            patterns = (data.P.indptr, data.P.indices, data.A.indptr, data.A.indices)
            workspace = admm.Workspace(
                data.n, data.m, data.constrained, (cones.kind, cones.offset, cones.dim,
                                                   cones.mu, cones.normal),
                data.fixed, None, self._settings, log_rows, patterns)
            workspace.arrived = self._sparse is not None or self._workspace is not None
            self._sparse = (key, workspace)
        workspace = self._sparse[1]
        workspace.update_cones(cones.mu, cones.normal)
        return workspace


def _resumed(out: Result, workspace: admm.Workspace, resume: tuple) -> Result:
    """``out`` of a run that stopped at its iteration cap while still converging
    (``workspace.converging``), continued once from its own last iterate, rho and
    scaling (``workspace.solve(*resume)``, a warm start with up to ``max_iter`` more
    iterations, the run's own time limit from the same start): a run that converges
    linearly but slowly may be a few iterations from its tolerances there, where a
    cold retry would spend its whole cap again. The continuation's result, with both
    runs' iterations and factorizations; ``out`` itself for any other stall, or when
    the continuation ends in a numerical error or rests on tolerances lent to its
    entries (``workspace.doubt``)."""
    if out.status is not Status.MAX_ITER_REACHED or not workspace.converging:
        return out
    again = workspace.solve(*resume)
    if (type(again) is not Result or again.status is Status.NUMERICAL_ERROR
            or workspace.doubt):
        return out
    return Result._of({**again.__dict__,
                       "iterations": out.iterations + again.iterations,
                       "factorizations": out.factorizations + again.factorizations})


def _room(settings: Settings, start: float) -> bool:
    """Whether a solve started at ``start`` (``time.perf_counter``) has room for the
    auxiliary solves of a stalled or doubted run (:mod:`fccqp.auxiliary`): untimed, or
    with ``AUXILIARY_TIME`` seconds of its ``time_limit`` left, which those solves then
    share. A control tick's budget of milliseconds never has it, so a tick never pays
    for them; qpbenchmark's 1000 s on Maros-Meszaros does."""
    left = settings.time_limit - (time.perf_counter() - start)
    return left >= AUXILIARY_TIME


def _certified(out: Result, found: tuple, workspace: admm.Workspace, start: float) -> Result:
    """``out`` with the certificate ``found`` (``(status, certificate, iterations,
    factorizations)`` of :func:`fccqp.auxiliary.stalled_certificate`) as its status, the
    auxiliary solves' counts added; ``workspace`` forgets its point, as after an
    infeasible run."""
    status, certificate, iterations, factorizations = found
    workspace.forget()
    return Result._of({
        **out.__dict__, "status": status, "certificate": certificate,
        "iterations": out.iterations + iterations,
        "factorizations": out.factorizations + factorizations,
        "gap": float("nan"), "polished": False,
        "solve_time": time.perf_counter() - start,
    })


def _not_convex(P: object) -> ValueError:
    """The error for a QP whose KKT matrix has more negative pivots than ``A`` has rows:
    ``P`` has negative curvature on the null space of ``A``. It gives ``P``'s smallest
    eigenvalue, computed densely up to ``EIGENVALUE_DENSE_LIMIT`` entries and by ARPACK
    above (left out when ARPACK does not converge)."""
    message = "the QP is not convex: P has negative curvature on the null space of A"
    if P.shape[0] <= EIGENVALUE_DENSE_LIMIT:
        dense = P.toarray() if hasattr(P, "toarray") else np.asarray(P)
        smallest = np.linalg.eigvalsh((dense + dense.T) / 2)[0]
    else:
        from scipy.sparse.linalg import ArpackNoConvergence, eigsh
        try:
            smallest = eigsh((P + P.T) / 2, k=1, which="SA", return_eigenvectors=False)[0]
        except ArpackNoConvergence:
            return ValueError(f"{message} (the KKT matrix has more negative pivots than A "
                              "has rows)")
    return ValueError(f"{message} (P is not positive semidefinite: its smallest "
                      f"eigenvalue is {smallest:.3g})")


def _rows(matrix: object) -> int:
    """Rows of a matrix argument, read from its shape without converting it (0 for
    ``None`` or anything without a 2-D shape, which conversion then reports)."""
    if matrix is None:
        return 0
    try:
        shape = matrix.shape if hasattr(matrix, "shape") else np.shape(matrix)
    except (TypeError, ValueError):
        return 0
    return int(shape[0]) if len(shape) == 2 else 0


def _guess(x0: object, y0: object, z0: object, n: int, m: int) -> tuple:
    """The initial guess ``(x, y, z)`` of a solve as float64 vectors of ``n``, ``m`` and
    ``n`` entries: ``(None, None, None)`` without ``x0``; ``(x, None, None)`` for a
    primal guess; a dual guess left out is zero beside one given."""
    if x0 is None:
        if y0 is not None or z0 is not None:
            raise ValueError("y0 and z0 are dual guesses beside x0: give x0 too")
        return NO_GUESS
    x = _vector(x0, "x0", n)
    if y0 is None and z0 is None:
        return (x, None, None)
    y = np.zeros(m) if y0 is None else _vector(y0, "y0", m)
    return (x, y, np.zeros(n) if z0 is None else _vector(z0, "z0", n))


def _vector(value: object, name: str, size: int) -> np.ndarray:
    """The argument ``name`` as a finite float64 vector of ``size`` entries."""
    if dense_vector_within(value, size, MAX_ENTRY):   # as it came (a control loop's)
        return value
    try:
        vector = np.asarray(value)
    except (TypeError, ValueError) as exn:
        raise TypeError(f"{name} must be a numeric vector of {size} entries: {exn}") from exn
    if vector.dtype.kind not in "biuf":
        raise TypeError(f"{name} must be a real numeric vector of {size} entries, got dtype "
                        f"{vector.dtype}")
    vector = np.ascontiguousarray(vector, dtype=np.float64).reshape(-1)
    finite = f"{name} must be a finite vector of {size} entries"
    if vector.shape != (size,):
        raise ValueError(finite)
    if not np.abs(vector).max(initial=0.0) <= MAX_ENTRY:   # one pass: NaN fails it too
        if not np.all(np.isfinite(vector)):
            raise ValueError(finite)
        raise ValueError(f"{name} has an entry beyond {MAX_ENTRY:.0e} in magnitude")
    return vector


def _print_log(lines: list[tuple[float, ...]], result: Result) -> None:
    """OSQP-style log: a header, one line every ``tuning.LOG_INTERVAL`` iterations, and
    the returned point's residuals (those of ``result``) as the last line."""
    print(f"{'iter':>6} {'prim_res':>10} {'dual_res':>10} {'gap':>10} {'rho':>9}")
    for it, prim, dual, gap, rho in lines:
        if it < result.iterations:
            print(f"{int(it):6d} {prim:10.3e} {dual:10.3e} {gap:10.3e} {rho:9.2e}")
    print(f"{result.iterations:6d} {result.prim_res:10.3e} {result.dual_res:10.3e} "
          f"{result.gap:10.3e} {result.rho:9.2e}")
    print(f"status: {result.status.value} after {result.iterations} iterations "
          f"({result.solve_time * 1e6:.0f} us, {result.backend} backend)")


def solve(
    P: object,
    q: object,
    A: object = None,
    b: object = None,
    lb: object = None,
    ub: object = None,
    cones: Sequence[Cone] = (),
    settings: Settings | None = None,
    *,
    x0: object = None,
    y0: object = None,
    z0: object = None,
    **overrides: object,
) -> Result:
    """Solve one QP in a new :class:`Solver`: from a cold start, or from the guess
    ``x0`` (``y0``, ``z0``); see :meth:`Solver.solve` for the arguments.

    ``settings`` and keyword ``overrides`` (fields of :class:`Settings`) configure
    the solve; an unknown keyword raises ``ValueError``.
    """
    return Solver(settings, **overrides).solve(P, q, A, b, lb, ub, cones, x0=x0, y0=y0, z0=z0)
