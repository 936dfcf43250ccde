"""Solver statuses."""

from enum import Enum


class Status(Enum):
    """Outcome of a solve.

    Only :attr:`SOLVED` means every residual is within the requested tolerances.
    """

    SOLVED = "solved"
    """Primal residual, dual residual and duality gap of the returned point are within
    ``eps_abs + eps_rel * scale``, the scales taken from the problem data."""
    SOLVED_INACCURATE = "solved_inaccurate"
    """A budget ran out with residuals within 10x the tolerances."""
    MAX_ITER_REACHED = "max_iter_reached"
    """``max_iter`` iterations ran without reaching (10x) tolerance."""
    TIME_LIMIT_REACHED = "time_limit_reached"
    """``time_limit`` seconds passed without reaching (10x) tolerance."""
    PRIMAL_INFEASIBLE = "primal_infeasible"
    """A certificate of primal infeasibility was found (see ``Result.certificate``)."""
    DUAL_INFEASIBLE = "dual_infeasible"
    """A certificate of dual infeasibility (an unbounded direction) was found."""
    NUMERICAL_ERROR = "numerical_error"
    """The iterates stopped being finite (overflow in extreme data or settings): the
    returned point is the last finite one and carries no guarantee."""

    def is_solved(self) -> bool:
        """True for :attr:`SOLVED` only."""
        return self is Status.SOLVED

    def is_infeasible(self) -> bool:
        """True when a primal or dual infeasibility certificate was found."""
        return self in (Status.PRIMAL_INFEASIBLE, Status.DUAL_INFEASIBLE)

