# Tuning constants of the compiled core: the one definition of each, grouped by topic.
#
# Each is a C literal (a macro of the verbatim block below, which Cython copies into every
# module that cimports a name from here), so the compiler folds it into the code as
# it would a number written in place: no module variable to load, nothing set at import.
# Macros rather than ``static const`` variables, which -Wall would report as unused in
# every module that does not read all of them. One comment line each says what the
# constant does and why its value; notes/tuning.md has the measurements behind them.
# Python sees them as attributes of :mod:`fccqp.tuning` (tuning.pyx), built from these.
# A new constant: its #define here, its declaration below, its name in tuning.pyx.

cdef extern from *:
    """
    /* ---- Input validation (fccqp.validation) ---- */
    /* P asymmetric by more than this (relative) is rejected, not symmetrized: above rounding */
    #define FCCQP_SYMMETRY_TOLERANCE 1e-10
    /* largest |entry| of P, q, A, b, x0: Ruiz brings at most 1e20 of spread to unit scale */
    #define FCCQP_MAX_ENTRY 1e20
    /* bounds at or beyond this magnitude are no bounds (as in Clarabel's presolve) */
    #define FCCQP_INFINITE_BOUND 1e20

    /* ---- Scaling (fccqp.scaling) ---- */
    /* a pass counts norms below this as 1 (tiny ones are started first): OSQP's 1e-4 left a 1e-7 row */
    #define FCCQP_MIN_NORM 1e-8
    /* column norms are capped here, so one Ruiz pass changes a scale by at most 100x */
    #define FCCQP_MAX_NORM 1e4
    /* the cost is normalized only above this size: a near-zero cost is not blown up 1e4x */
    #define FCCQP_MIN_COST_NORM 1e-4
    /* rescale keeps an old scaling while every norm stays within this factor (~1 pass) */
    #define FCCQP_RESCALE_DRIFT 4.0
    /* Ruiz passes whose correction hit MAX_NORM's cap do not count, up to this many more */
    #define FCCQP_CAPPED_PASSES 20
    /* D's geometric mean below 1 / this: D up, E down by a power of two (as far as D P D <= 1) */
    #define FCCQP_GAUGE_LIMIT 1e3
    /* Ruiz passes walk P's and A's nonzeros, not every entry, when at most this share is nonzero */
    #define FCCQP_SPARSE_PASSES 0.5

    /* ---- Factorization of the ADMM KKT system (fccqp.ldl, fccqp.schur, fccqp.kkt) ---- */
    /* quasi-definite regularization of LDL's (2, 2) block (scaled): refinement removes it */
    #define FCCQP_KKT_DELTA 1e-13
    /* most iterative-refinement steps per solve, in every backend and in the polish */
    #define FCCQP_MAX_REFINE 5
    /* refine while ||A x - b|| (user units) > this max(1, ||b||, ||A x||): near rounding */
    #define FCCQP_KKT_REFINE_TOLERANCE 1e-13
    /* ADMM's Schur complement (fccqp.schur): a Cholesky pivot^2 below this times its largest diagonal, singular */
    #define FCCQP_RANK_TOLERANCE 1e-10
    /* S's largest diagonal above this times H's and A's largest entry: growth, go to LDL' */
    #define FCCQP_SCHUR_GROWTH 1e10
    /* reduced iteration when this * s fits the budget: s columns cost ~s/4 solves, x2 margin */
    #define FCCQP_REDUCED_COST 0.5

    /* ---- Cold start and equalities (fccqp.factorization, fccqp.verdict, fccqp.admm) ---- */
    /* proximal steps of the cold start's equality-constrained QP */
    #define FCCQP_EQUALITY_START_STEPS 3
    /* that QP is unbounded when sigma ||x_eq|| > this max(1, ||q||): test it as a direction */
    #define FCCQP_EQUALITY_START_LIMIT 1e-3
    /* beyond that limit, a ray only when the Schur start's last step keeps this of the one before */
    #define FCCQP_EQUALITY_START_RAY_STEP 0.9
    /* the cold start missing A x = b by more than this (relative): "auto" takes full form */
    #define FCCQP_EQUALITY_MISSED 1e-9
    /* a failed warm start restarts cold for the rest, and a run still converging at its
       cap is continued (fccqp.solver._resumed), only when max_iter is at least this */
    #define FCCQP_RESTART_MIN_ITER 200
    /* a caller's guess whose warm polish failed starts ADMM only if the cold start is this
       x farther from the tolerances: its stale multipliers cost more than they measure */
    #define FCCQP_GUESS_LEAD 4.0

    /* ---- Rho adaptation (fccqp.rho_rule, fccqp.admm) ---- */
    /* range of the adaptive rho */
    #define FCCQP_RHO_MIN 1e-6
    #define FCCQP_RHO_MAX 1e6
    /* rho multiplier on entries with lb == ub, which act as equalities (as in OSQP) */
    #define FCCQP_FIXED_RHO_SCALE 1e3
    /* a small rho move asked for this many updates in a row is tried (3 lost talos ticks) */
    #define FCCQP_RHO_PERSISTENCE 5
    /* rho is not lowered while, since its last lowering, the primal residual's scale
       grew more than this x and the relative primal residual did not fall */
    #define FCCQP_RHO_RUNAWAY 4.0

    /* ---- Anderson acceleration (fccqp.anderson, fccqp.iteration) ---- */
    /* steps rejected by the safeguard before a run gives up accelerating */
    #define FCCQP_MAX_REJECTIONS 3
    /* Tikhonov weight of the least-squares problem, relative to its largest diagonal */
    #define FCCQP_REGULARIZATION 1e-8
    /* weights of this norm or more are not used: the WBC sets' largest is 3.7e3 */
    #define FCCQP_MAX_WEIGHT_NORM 1e4
    /* acceleration stops after STALLS checks in a row above this x tolerance, not halving */
    #define FCCQP_STALL_FACTOR 1e3
    #define FCCQP_STALLS 2

    /* ---- Termination (fccqp.termination, fccqp.verdict, fccqp.iteration) ---- */
    /* a budget-stopped iterate within this multiple of the tolerances is SOLVED_INACCURATE */
    #define FCCQP_INACCURATE_FACTOR 10.0
    /* multiplier terms widen the gap's scale to at most this x max(|x'Px|, |q'x|) */
    #define FCCQP_GAP_TERMS_CAP 10.0
    /* a returned point's complementarity per box entry and cone block: within this x the
       gap's tolerance on max(|x'Px|, |q'x|) (x INACCURATE_FACTOR for SOLVED_INACCURATE) */
    #define FCCQP_COMPLEMENTARITY_FACTOR 10.0
    /* no solved claim while x_S misses C by eps_abs + this of x_S's size in scaled units */
    #define FCCQP_SCALED_VIOLATION 1e-2
    /* gated full checks back off 1, 3, 7, then this many iterations (one costs ~2.4) */
    #define FCCQP_GATED_CHECK_WAIT 8
    /* the verbose log keeps one line every this many iterations (as OSQP) */
    #define FCCQP_LOG_INTERVAL 25

    /* ---- Infeasibility certificates (fccqp.certificates, fccqp.verdict) ---- */
    /* a Farkas certificate separates by more than this of its terms (see EQUALITY_MISSED) */
    #define FCCQP_SEPARATION_FLOOR 1e-9
    /* and by this multiple of its residual: infeasible ones measured separate by >= 120x */
    #define FCCQP_DOMINANCE 100.0
    /* alternating cleaning steps per way: a 1e-4 gap's residual fell to 4e-12 after 30 */
    #define FCCQP_CLEANING_PASSES 30
    /* largest shift of a cleaning step on the box's support, relative to ||d_y|| */
    #define FCCQP_CLEANING_SHRINK 0.1
    /* the dual certificate's second balance bounds its column norms to 1/this..this */
    #define FCCQP_BALANCE_RANGE 1e8
    /* added to A A''s diagonal, relative to its largest entry, for dependent rows */
    #define FCCQP_GRAM_REGULARIZATION 1e-12
    /* no certificate is cleaned before this many iterations (doubling after each failure) */
    #define FCCQP_CLEANING_START 500
    /* cleaned only while the primal residual is above this x its tolerance */
    #define FCCQP_CLEANING_GATE 1.0
    /* the primal residual stalls (certificate tested, cleaned) if its last rate needs more than this x the run's iterations to its tolerance */
    #define FCCQP_CLEANING_HORIZON 1.0
    /* a least-distance QP solved again meets the Farkas test's eps_prim_inf this many times */
    #define FCCQP_AUXILIARY_MARGIN 10.0
    /* a problem that stalled in both KKT forms is solved again, cold, at this times Settings.rho and at 1 / this of it */
    #define FCCQP_STALL_RHO_FACTOR 1e3
    /* a primal certificate separating by less than this of its terms is checked in the other KKT form */
    #define FCCQP_WEAK_SEPARATION 1e-6

    /* ---- Polish (fccqp.polish*, fccqp.iteration, fccqp.acceptance) ---- */
    /* regularization of both diagonal blocks of the polishing KKT matrix (scaled) */
    #define FCCQP_POLISH_DELTA 1e-12
    /* the same for qdldl's factorization without pivoting (fccqp.polish_csc): 1e-12 lost LPs */
    #define FCCQP_POLISH_CSC_DELTA 1e-8
    /* the polish's Schur complement is singular below this pivot^2 / largest diagonal */
    #define FCCQP_POLISH_RANK_TOLERANCE 1e-14
    /* the bordered Schur factorization needs S0's pivot^2 / largest diagonal above this */
    #define FCCQP_POLISH_BORDER_TOLERANCE 1e-8
    /* a refinement stalled above this times its tolerance refactors with a smaller delta */
    #define FCCQP_POLISH_STALL_RESIDUAL 1e3
    /* that delta: this times the curvature the stalled refinement's contraction shows */
    #define FCCQP_POLISH_DELTA_CUT 1e-2
    /* refine the returned point while the KKT residual > this max(1, ||q||, ||b||) */
    #define FCCQP_POLISH_REFINE_TOLERANCE 1e-14
    /* a guess's solve and a Newton step's are refined only to this: the next step repeats the work */
    #define FCCQP_GUESS_TOLERANCE 1e-10
    /* most active sets per polish: 6 accepted an unsettled one, 10 cost 6 % more per tick */
    #define FCCQP_GUESS_PASSES 8
    /* most active sets per warm polish (from the previous tick's answer): 8 sent 3-9 % of
       the warm ticks to ADMM, most of them a few guesses short of settling */
    #define FCCQP_WARM_GUESS_PASSES 12
    /* most active sets for the final polish of a run stopped at max_iter (of at least
       RESTART_MIN_ITER): from a stalled iterate its active-set walk may need more */
    #define FCCQP_STALLED_GUESS_PASSES 32
    /* most active sets for the polish of an iterate that earned SOLVED under a time limit */
    #define FCCQP_SOLVED_GUESS_PASSES 16
    /* guesses of a warm polish tried again from its own cycling point: those kept took 1 */
    #define FCCQP_CYCLED_GUESS_PASSES 1
    /* a polish whose first this many guesses all violate a constraint gives up */
    #define FCCQP_FEASIBLE_PASSES 3
    /* a warm polish stepping from a feasible point gives up when more of its multipliers
       are wrong-signed than this times its guesses left (one is released a guess) */
    #define FCCQP_HOPELESS_RATE 2.0
    /* a free entry or block joins the active set when it violates by more than this */
    #define FCCQP_ACTIVE_TOLERANCE 1e-12
    /* Newton stops when every boundary block has |phi| <= this ||x_block|| */
    #define FCCQP_NEWTON_TOLERANCE 1e-13
    /* or when a refactorization did not reduce a miss below this (rounding's floor) */
    #define FCCQP_MISS_FLOOR 1e-11
    /* chord steps while the miss shrinks by CHORD_RATE and would meet the tolerance
       within CHORD_STEPS more: fewest instructions per tick measured */
    #define FCCQP_CHORD_RATE 0.25
    #define FCCQP_CHORD_STEPS 3
    /* P's diagonal below this x its largest: too singular for the Schur complement */
    #define FCCQP_PIVOT_TOLERANCE 1e-12
    /* the table's LU is singular when smallest / largest pivot is below this */
    #define FCCQP_PIVOT_RATIO 1e-13
    /* LU by the AVX2 loop up to this size, dgetrf above: measured faster up to talos' 64 */
    #define FCCQP_LU_LOOP_ROWS 64
    /* Cholesky by the loop up to this order, dpotrf above: the loop 0.58-0.95x up to 128 */
    #define FCCQP_CHOLESKY_LOOP_ROWS 128
    /* A'A by the AVX2 tiles up to this order (from order / 8 rows), dsyrk above: 0.45-0.95x */
    #define FCCQP_SYRK_LOOP_ORDER 128
    /* triangular solves by the loops up to this order, dtrsm / dpotrs above: 0.1-0.7x up to 128 */
    #define FCCQP_TRSM_LOOP_ROWS 128
    /* a correction skips the KKT solve when that residual is below this x the constraints' */
    #define FCCQP_MINOR_PART 1e-2
    /* a rejected polish: ADMM goes on at 10x tighter tolerances at most this many times */
    #define FCCQP_POLISH_RETRIES 2
    /* a polished residual below this x its tolerance counts as exact (rounding) */
    #define FCCQP_POLISH_EXACT 1e-3
    /* a polished point keeps A x = b within EQUALITY_SLACK x ADMM's residual, or below
       EQUALITY_EXACT x max(||A x||, ||b||): factorization accuracy */
    #define FCCQP_EQUALITY_SLACK 10.0
    #define FCCQP_EQUALITY_EXACT 1e-13
    /* polish early, at most EARLY_POLISH_TRIES times, at checks within EARLY_POLISH_GATE
       of the tolerances whose active set settled: 1e2 fewest instructions per tick */
    #define FCCQP_EARLY_POLISH_GATE 1e2
    #define FCCQP_EARLY_POLISH_TRIES 3

    /* ---- Restoration (fccqp.restoration, fccqp.acceptance) ---- */
    /* an entry violates when its projection moves it by more than this (relative) */
    #define FCCQP_VIOLATION_TOLERANCE 1e-12
    /* a restored point is kept if its primal residual < this x its scale (W_TT costs digits) */
    #define FCCQP_RESTORED_EQUALITY 1e-7

    /* ---- Time budget (fccqp.iteration, fccqp.admm) ---- */
    /* a timed run is polished only within this factor of the tolerances (else guess wrong) */
    #define FCCQP_POLISH_GATE 1e3
    /* the final step's reserve: its largest recent duration, decayed by this per solve */
    #define FCCQP_RESERVE_DECAY 0.5
    /* and at least this many polish guesses: a clock-stopped iterate's guess needs a fix */
    #define FCCQP_RESERVE_PASSES 2.0
    /* with a time limit the early polish runs from this iteration (no control tick runs so long) */
    #define FCCQP_TIMED_EARLY_POLISH 1000
    /* below that, a timed run looks at its active set every this many iterations and polishes
       one that held as long as it took to form: 1 and 3 equal cold iterations, 3 cheaper */
    #define FCCQP_SETTLE_ITERATIONS 3
    /* at most this many times a run (a failed try costs up to GUESS_PASSES guesses) */
    #define FCCQP_SETTLE_TRIES 3
    /* a change of rho counts at most this share of a timed run's iterations' time */
    #define FCCQP_RHO_TIME_SHARE 0.25
    /* with a time limit max_iter grows by half while the distance to tolerance shrinks this much */
    #define FCCQP_CONVERGING 0.5
    /* a stalled timed run gets its certificates and retries only with this many seconds left */
    #define FCCQP_AUXILIARY_TIME 1.0
    """
    # The declarations, in the order above; each type is the one the code computes with.
    # Input validation
    const double SYMMETRY_TOLERANCE "FCCQP_SYMMETRY_TOLERANCE"
    const double MAX_ENTRY "FCCQP_MAX_ENTRY"
    const double INFINITE_BOUND "FCCQP_INFINITE_BOUND"
    # Scaling
    const double MIN_NORM "FCCQP_MIN_NORM"
    const double MAX_NORM "FCCQP_MAX_NORM"
    const double MIN_COST_NORM "FCCQP_MIN_COST_NORM"
    const double RESCALE_DRIFT "FCCQP_RESCALE_DRIFT"
    const long CAPPED_PASSES "FCCQP_CAPPED_PASSES"
    const double GAUGE_LIMIT "FCCQP_GAUGE_LIMIT"
    const double SPARSE_PASSES "FCCQP_SPARSE_PASSES"
    # Factorization
    const double KKT_DELTA "FCCQP_KKT_DELTA"
    const int MAX_REFINE "FCCQP_MAX_REFINE"
    const double KKT_REFINE_TOLERANCE "FCCQP_KKT_REFINE_TOLERANCE"
    const double RANK_TOLERANCE "FCCQP_RANK_TOLERANCE"
    const double SCHUR_GROWTH "FCCQP_SCHUR_GROWTH"
    const double REDUCED_COST "FCCQP_REDUCED_COST"
    # Cold start and equalities
    const long EQUALITY_START_STEPS "FCCQP_EQUALITY_START_STEPS"
    const double EQUALITY_START_LIMIT "FCCQP_EQUALITY_START_LIMIT"
    const double EQUALITY_START_RAY_STEP "FCCQP_EQUALITY_START_RAY_STEP"
    const double EQUALITY_MISSED "FCCQP_EQUALITY_MISSED"
    const long RESTART_MIN_ITER "FCCQP_RESTART_MIN_ITER"
    const double GUESS_LEAD "FCCQP_GUESS_LEAD"
    # Rho adaptation
    const double RHO_MIN "FCCQP_RHO_MIN"
    const double RHO_MAX "FCCQP_RHO_MAX"
    const double FIXED_RHO_SCALE "FCCQP_FIXED_RHO_SCALE"
    const int RHO_PERSISTENCE "FCCQP_RHO_PERSISTENCE"
    const double RHO_RUNAWAY "FCCQP_RHO_RUNAWAY"
    # Anderson acceleration
    const long MAX_REJECTIONS "FCCQP_MAX_REJECTIONS"
    const double REGULARIZATION "FCCQP_REGULARIZATION"
    const double MAX_WEIGHT_NORM "FCCQP_MAX_WEIGHT_NORM"
    const double STALL_FACTOR "FCCQP_STALL_FACTOR"
    const int STALLS "FCCQP_STALLS"
    # Termination
    const double INACCURATE_FACTOR "FCCQP_INACCURATE_FACTOR"
    const double GAP_TERMS_CAP "FCCQP_GAP_TERMS_CAP"
    const double COMPLEMENTARITY_FACTOR "FCCQP_COMPLEMENTARITY_FACTOR"
    const double SCALED_VIOLATION "FCCQP_SCALED_VIOLATION"
    const long GATED_CHECK_WAIT "FCCQP_GATED_CHECK_WAIT"
    const long LOG_INTERVAL "FCCQP_LOG_INTERVAL"
    # Infeasibility certificates
    const double SEPARATION_FLOOR "FCCQP_SEPARATION_FLOOR"
    const double DOMINANCE "FCCQP_DOMINANCE"
    const double BALANCE_RANGE "FCCQP_BALANCE_RANGE"
    const int CLEANING_PASSES "FCCQP_CLEANING_PASSES"
    const double CLEANING_SHRINK "FCCQP_CLEANING_SHRINK"
    const double GRAM_REGULARIZATION "FCCQP_GRAM_REGULARIZATION"
    const long CLEANING_START "FCCQP_CLEANING_START"
    const double CLEANING_GATE "FCCQP_CLEANING_GATE"
    const double CLEANING_HORIZON "FCCQP_CLEANING_HORIZON"
    const double AUXILIARY_MARGIN "FCCQP_AUXILIARY_MARGIN"
    const double STALL_RHO_FACTOR "FCCQP_STALL_RHO_FACTOR"
    const double WEAK_SEPARATION "FCCQP_WEAK_SEPARATION"
    # Polish
    const double POLISH_DELTA "FCCQP_POLISH_DELTA"
    const double POLISH_CSC_DELTA "FCCQP_POLISH_CSC_DELTA"
    const double POLISH_RANK_TOLERANCE "FCCQP_POLISH_RANK_TOLERANCE"
    const double POLISH_BORDER_TOLERANCE "FCCQP_POLISH_BORDER_TOLERANCE"
    const double POLISH_STALL_RESIDUAL "FCCQP_POLISH_STALL_RESIDUAL"
    const double POLISH_DELTA_CUT "FCCQP_POLISH_DELTA_CUT"
    const double POLISH_REFINE_TOLERANCE "FCCQP_POLISH_REFINE_TOLERANCE"
    const double GUESS_TOLERANCE "FCCQP_GUESS_TOLERANCE"
    const int GUESS_PASSES "FCCQP_GUESS_PASSES"
    const int WARM_GUESS_PASSES "FCCQP_WARM_GUESS_PASSES"
    const int STALLED_GUESS_PASSES "FCCQP_STALLED_GUESS_PASSES"
    const int SOLVED_GUESS_PASSES "FCCQP_SOLVED_GUESS_PASSES"
    const int CYCLED_GUESS_PASSES "FCCQP_CYCLED_GUESS_PASSES"
    const int FEASIBLE_PASSES "FCCQP_FEASIBLE_PASSES"
    const double HOPELESS_RATE "FCCQP_HOPELESS_RATE"
    const double ACTIVE_TOLERANCE "FCCQP_ACTIVE_TOLERANCE"
    const double NEWTON_TOLERANCE "FCCQP_NEWTON_TOLERANCE"
    const double MISS_FLOOR "FCCQP_MISS_FLOOR"
    const double CHORD_RATE "FCCQP_CHORD_RATE"
    const int CHORD_STEPS "FCCQP_CHORD_STEPS"
    const double PIVOT_TOLERANCE "FCCQP_PIVOT_TOLERANCE"
    const double PIVOT_RATIO "FCCQP_PIVOT_RATIO"
    const int LU_LOOP_ROWS "FCCQP_LU_LOOP_ROWS"
    const int CHOLESKY_LOOP_ROWS "FCCQP_CHOLESKY_LOOP_ROWS"
    const int SYRK_LOOP_ORDER "FCCQP_SYRK_LOOP_ORDER"
    const int TRSM_LOOP_ROWS "FCCQP_TRSM_LOOP_ROWS"
    const double MINOR_PART "FCCQP_MINOR_PART"
    const int POLISH_RETRIES "FCCQP_POLISH_RETRIES"
    const double POLISH_EXACT "FCCQP_POLISH_EXACT"
    const double EQUALITY_SLACK "FCCQP_EQUALITY_SLACK"
    const double EQUALITY_EXACT "FCCQP_EQUALITY_EXACT"
    const double EARLY_POLISH_GATE "FCCQP_EARLY_POLISH_GATE"
    const int EARLY_POLISH_TRIES "FCCQP_EARLY_POLISH_TRIES"
    # Restoration
    const double VIOLATION_TOLERANCE "FCCQP_VIOLATION_TOLERANCE"
    const double RESTORED_EQUALITY "FCCQP_RESTORED_EQUALITY"
    # Time budget
    const double POLISH_GATE "FCCQP_POLISH_GATE"
    const double RESERVE_DECAY "FCCQP_RESERVE_DECAY"
    const double RESERVE_PASSES "FCCQP_RESERVE_PASSES"
    const long TIMED_EARLY_POLISH "FCCQP_TIMED_EARLY_POLISH"
    const long SETTLE_ITERATIONS "FCCQP_SETTLE_ITERATIONS"
    const int SETTLE_TRIES "FCCQP_SETTLE_TRIES"
    const double RHO_TIME_SHARE "FCCQP_RHO_TIME_SHARE"
    const double CONVERGING "FCCQP_CONVERGING"
    const double AUXILIARY_TIME "FCCQP_AUXILIARY_TIME"
