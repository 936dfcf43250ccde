# cython: language_level=3
from libc.math cimport isfinite

from fccqp._types cimport Iterates, Problem

cdef struct Residuals:
    # Residuals of an iterate in the user's units, the scales of their relative
    # tolerances, and the scaled values that rho adaptation balances.
    double prim, dual, gap      # prim = max(prim_eq, prim_set), the reported value
    double objective            # 1/2 x'Px + q'x (set for the returned point)
    double prim_eq, prim_set    # ||A x - b|| and the distance of x_S to C (or to w)
    double prim_eq_scale, prim_set_scale
    double prim_scale, dual_scale, gap_scale   # prim_scale: the larger of the two
    double prim_s, dual_s, prim_scale_s, dual_scale_s
    double set_s, set_scale_s   # x_S - w and the size of x_S, w in scaled units, uncapped
    double box_excess           # box entries: largest |x_i - w_i| - SCALED_VIOLATION x size
                                # (box_entry_size), in scaled units
    double compl, compl_scale   # the returned point's (acceptance.user_residuals): the
                                # largest complementarity of a box entry or cone block,
                                # and max(|x'Px|, |q'x|); 0 and 0 on iterates
    bint eq_rounding            # the returned point's: every row that misses its tolerance
                                # is within EQUALITY_EXACT of its terms (False on iterates)
    bint set_lent, dual_lent    # the returned point's (acceptance.user_residuals): a cone
                                # block or box entry misses C by more than eps_abs + eps_rel
                                # x its own size (user's or scaled units); the dual residual
                                # passes only through eps_abs
    bint finite

cdef void residuals(const Problem* p, const Iterates* it, double* Ax, double* ATnu,
                    double* Px, Residuals* r) noexcept nogil
cdef bint converged(const Residuals* r, double eps_abs, double eps_rel) noexcept nogil
cdef double distance(const Residuals* r, double eps_abs, double eps_rel) noexcept nogil
cdef bint nearly_converged(const Residuals* r, double eps_abs, double eps_rel,
                           double factor) noexcept nogil
cdef double gap_scale(double xPx, double qx, double terms) noexcept nogil
cdef void row_spans(Problem* p, double* width) noexcept nogil
cdef double box_support(const Problem* p, const double* y, double* terms) noexcept nogil


cdef inline double box_entry_size(double scale, double width) noexcept nogil:
    """The size a box entry's violation is judged against (``Residuals.box_excess``): its
    ``scale`` (value), or the box's ``width`` where that is finite and larger."""
    return max(scale, width) if isfinite(width) else scale
