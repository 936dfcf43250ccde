# cython: language_level=3
from fccqp._types cimport Problem

cdef enum:
    BASE_NONE = 0
    BASE_READY = 1
    BASE_REFUSED = 2
    BASE_SINGULAR = 3

cdef enum:   # where a base (polish_schur.pyx, _build_base) keeps a cone block
    CONE_DIAGONAL = 0   # free, its rows in S0
    CONE_BORDERED = 1   # columns of W: free, on its boundary or at its apex in a guess
    CONE_HELD = 2       # at its apex, neither

cdef struct PolishSchur:
    # The polished QP's KKT system by Schur complement where P's structure allows it
    # (see polish_schur.pyx); set up once per solve, factored once per guess.
    bint ready              # set up for the current scaled P and A
    bint convex             # the set-up proved P positive semidefinite
    int dense               # leading rows of the unconstrained entries that P couples
    Py_ssize_t unconstrained    # entries without a bound or a cone (n - s)
    Py_ssize_t* order       # n: the unconstrained entries, coupled ones first
    char* coupled           # n: set-up scratch (1: P couples the entry, 2: constrained)
    double* L               # n x n (leading dense x dense used): Cholesky of P_DD + delta I
    double* root            # n: sqrt(P_ii + delta) of the entries P does not couple
    double* Y               # n x (m + s), column-major: L^-1 C', a row per free entry
    Py_ssize_t* rowvar      # n: the entry of x of each row of Y
    double* inv_root        # n: 1 / root of Y's diagonal rows (dense <= row < diag_end)
    Py_ssize_t* block_row   # s: the first row of Y of each bordered block
    int diag_end            # rows of Y before the bordered blocks'
    int rows                # rows of Y: the free entries of the factored guess
    int kept_rows           # Y's rows [unconstrained, kept_rows) hold the diagonal rows of
                            # rowvar's entries (written by a base of this solve, kept)
    double* SU              # m x m: the unconstrained entries' part of S, + delta I
    Py_ssize_t* arow        # m: the row of A of each of S's first m columns
    int lead                # S's leading columns, rows of A no cone entry touches (a
                            # multiple of 4): factored once per base (_build_base)
    double* S               # (m + s)^2: S of the last factored guess past S0's leading
                            # block, then its Cholesky (the leading block's is S0's)
    double* block           # s x s: a bordered block's Cholesky factor at block + offset * s
    double* t               # n scratch
    double* t2              # n scratch
    double* u               # m + s scratch
    int* row_nz             # n x (m + s): each row of Y's nonzero columns, increasing
    int* row_count          # n: how many (the diagonal and boundary rows)
    int* entry_nz           # n x m: a constrained entry's diagonal row's nonzero columns,
    double* entry_values    # n x m: and their values, kept from its first row in the solve
    int* entry_count        # n: their number, -1 before the solve writes the entry's row
    double* nz_values       # m + s scratch: a row's nonzero entries
    int size                # m + nb of the last factored guess
    # The cone blocks that a base borders, off their apex in a guess, come after the
    # base's rows of Y (polish_schur.pyx)
    char* cone_base         # s: CONE_DIAGONAL, CONE_BORDERED or CONE_HELD, by cone
    bint border_all         # the next base borders every cone block (a base was built in
                            # this solve, or the polish starts from no multipliers)
    Py_ssize_t* border      # s: the bordered blocks of the last factored guess, ascending
    int nborder             # their number
    int nbd                 # their entries: the bordered rows of Y
    Py_ssize_t* border_col  # s: the column of W of each bordered entry
    int ncone               # W's columns: the entries of the base's bordered cone blocks
    # The bordered factorization, which keeps the part of S that a guess's cone blocks
    # (free, on their boundary with their planes and curvature) do not change:
    bint bordered           # the last factored guess is bordered: a solve reads S0..T
    char base               # BASE_NONE, or S0, W, WW belong to Y's rows [unconstrained,
                            # diag_end) and cone_base (BASE_READY) or S0 of those was
                            # refused (BASE_REFUSED) or its leading block is not
                            # positive definite (BASE_SINGULAR)
    double base_largest     # S0's largest diagonal entry
    double lead_largest     # S0's largest diagonal entry in its leading block
    double lead_min         # S0's smallest squared pivot in its leading block
    double* S0              # m x m: Cholesky of SU + the free diagonal rows' Y'Y
    double* SC              # m x m (trailing block): S0's Schur complement of its leading
                            # block: LSC + the other free diagonal rows' Y'Y
    # S0's leading block, shared by the bases whose free diagonal rows that reach it
    # (lead_rows) are the same (_build_lead):
    bint lead_valid         # S0's leading columns, LSC and diag0 hold lead_rows' factor
    Py_ssize_t* lead_rows   # n: the entries of x of those rows, in Y's order
    int lead_count          # their number
    double* LSC             # m x m (trailing block): Schur complement of the leading block
                            # of SU + those rows' Y'Y (lower)
    double* diag0           # m: the diagonal of SU + those rows' Y'Y
    double* W               # (m - lead) x s: S0's factor^-1 A_B', a column per entry of
                            # a bordered cone, its trailing rows (the leading ones are zero)
    double* WW              # s x s: W'W
    double* K               # s x s: Cholesky of H_B + W'W on the bordered entries
    double* Z               # s x s: K's factor^-1 G', a column per boundary block
    double* T               # s x s: Cholesky of Z'Z + delta I (nb x nb)

cdef bint polish_schur_setup(PolishSchur* f, const Problem* p, double delta) noexcept nogil
cdef bint polish_schur_factor(PolishSchur* f, const Problem* p, const Py_ssize_t* index,
                              const Py_ssize_t* boundary, Py_ssize_t nb, const double* g,
                              const double* hess, double delta) noexcept nogil
cdef void polish_schur_solve(PolishSchur* f, const Problem* p, const Py_ssize_t* index,
                             Py_ssize_t nb, double* v) noexcept nogil
