# cython: language_level=3, boundscheck=False, wraparound=False, cdivision=True, initializedcheck=False
"""Rho adaptation: OSQP's rule, the trial of the small moves it keeps asking for, and
a guard against lowering rho under a runaway iterate (:mod:`fccqp.iteration` calls it,
on either storage of the matrices).
"""

from libc.math cimport INFINITY, sqrt

from fccqp.termination cimport Residuals
from fccqp.tuning cimport RHO_MAX, RHO_MIN, RHO_PERSISTENCE, RHO_RUNAWAY


cdef double rho_trial(TrialState* trial, double rho, double new_rho, double worst,
                      double tolerance) noexcept nogil:
    """The rho to take, given OSQP's proposal ``new_rho`` and the larger relative
    residual ``worst`` at this update: ``new_rho`` when it moves rho by more than
    ``tolerance``. A smaller move, by more than the tolerance's square root, is made when
    the rule asked for it, the same way, at ``RHO_PERSISTENCE`` updates in a row while
    ``worst`` did not halve; it is undone (and none made again in the run) when over the
    next ``RHO_PERSISTENCE`` updates ``worst`` falls by less than it did over the streak."""
    cdef double half = sqrt(tolerance), old
    cdef int side = 1 if new_rho > rho * half else (-1 if new_rho < rho / half else 0)
    if new_rho > rho * tolerance or new_rho < rho / tolerance:
        trial.side = trial.count = 0
        trial.old_rho = 0.0
        return new_rho
    if trial.old_rho > 0.0:   # a move on trial
        trial.count += 1
        if trial.count == 1:
            trial.start = worst
        elif trial.count == RHO_PERSISTENCE:
            old, trial.old_rho = trial.old_rho, 0.0
            trial.side = trial.count = 0
            if worst / trial.start > trial.progress:
                trial.locked = True
                return old
        return rho
    if trial.locked or side == 0 or side != trial.side:
        trial.side, trial.count, trial.start = side, 1, worst
        return rho
    trial.count += 1
    if trial.count < RHO_PERSISTENCE:
        return rho
    trial.side = trial.count = 0
    if worst <= 0.5 * trial.start:
        return rho
    trial.progress = worst / trial.start
    trial.old_rho = rho
    return new_rho


cdef void trial_reset(TrialState* trial) noexcept nogil:
    trial.side = trial.count = 0
    trial.old_rho = trial.start = trial.progress = 0.0
    trial.locked = False
    trial.lowered_scale = trial.lowered_prim = INFINITY


cdef double new_rho(const Residuals* r, double rho, TrialState* trial,
                    double tolerance) noexcept nogil:
    """OSQP's rule: rho *= sqrt(relative primal / relative dual residual), clipped,
    when that moves it by more than ``tolerance`` (``adaptive_rho_tolerance``); a
    smaller move that the rule keeps asking for is tried (:func:`rho_trial`).

    Rho is not lowered while the iterate runs away infeasibly: since rho was last
    lowered, the primal residual's scale (the size of ``A x`` and ``z``) has grown
    more than ``RHO_RUNAWAY``-fold and the primal residual at least as fast. The
    relative primal residual divides by that scale, so an iterate running away along a
    near-recession direction makes a growing primal residual look no larger; the rule
    would go on lowering rho, which weakens the constraints and lets the iterate run
    further, down to rho's floor, where the run orbits far from the solution. An
    iterate that grows while its primal residual does not (an optimum far away, as
    with a tiny ``P``) keeps the rule's rho."""
    cdef double prim = r.prim_s / max(r.prim_scale_s, 1e-30)
    cdef double dual = r.dual_s / max(r.dual_scale_s, 1e-30)
    cdef double proposal = min(max(rho * sqrt(prim / max(dual, 1e-30)), RHO_MIN), RHO_MAX)
    if (proposal < rho and r.prim_scale_s > RHO_RUNAWAY * trial.lowered_scale
            and prim >= trial.lowered_prim):
        proposal = rho
    cdef double taken = rho_trial(trial, rho, proposal, max(prim, dual), tolerance)
    if taken < rho:
        trial.lowered_scale, trial.lowered_prim = r.prim_scale_s, prim
    return taken
