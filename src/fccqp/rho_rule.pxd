# cython: language_level=3
from fccqp.termination cimport Residuals

cdef struct TrialState:
    # The rho rule's memory within a run: a rho move smaller than adaptive_rho_tolerance,
    # asked for again and again (rho_trial), and the runaway guard's mark (new_rho).
    int side          # +1 (up) or -1 (down): the way the current streak asks; 0: none
    int count         # updates in the streak, or since the move on trial
    double start      # larger relative residual at the streak's (or the trial's) first
    double progress   # its fall over the streak that made the move (a factor below 1)
    double old_rho    # the rho before the move on trial; 0 when none is
    bint locked       # a move was undone: none is tried again in this run
    double lowered_scale  # primal residual's scale when rho was last lowered; INFINITY: never
    double lowered_prim   # relative primal residual then

cdef double rho_trial(TrialState* trial, double rho, double new_rho, double worst,
                      double tolerance) noexcept nogil
cdef void trial_reset(TrialState* trial) noexcept nogil
cdef double new_rho(const Residuals* r, double rho, TrialState* trial,
                    double tolerance) noexcept nogil
