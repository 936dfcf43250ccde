"""Bad input raises a clear error that names the argument."""

import numpy as np
import pytest

import fccqp
from fccqp import FrictionCone, SecondOrderCone

pytestmark = pytest.mark.usefixtures("every_kkt_backend")
BEFORE_ANY_BACKEND = pytest.mark.kkt_backends(
    "auto", reason="settings and arguments checked before a backend is chosen")

P = np.eye(6)
q = np.ones(6)
A = np.ones((2, 6))
b = np.ones(2)


def solve(**changes):
    args = dict(P=P, q=q, A=A, b=b, lb=None, ub=None, cones=())
    args.update(changes)
    return fccqp.solve(**args)


BAD_INPUT = [
    (dict(P=np.eye(5)), ValueError, "q must have 5 entries"),
    (dict(P=np.ones((6, 5))), ValueError, "P must be square"),
    (dict(P=np.ones(6)), ValueError, "P must be 2-dimensional"),
    (dict(P=np.triu(np.ones((6, 6)))), ValueError, "P must be symmetric"),
    (dict(P=np.diag([1, 1, np.nan, 1, 1, 1])), ValueError, "P contains NaN or inf"),
    (dict(P=np.diag([1, 1, np.inf, 1, 1, 1])), ValueError, "P contains NaN or inf"),
    (dict(P=[["a"] * 6] * 6), TypeError, "P must be a numeric matrix"),
    (dict(q=np.ones(5)), ValueError, "q must have 6 entries"),
    (dict(q=np.ones((2, 6))), ValueError, "q must be a vector"),
    (dict(q=np.full(6, np.nan)), ValueError, "q contains NaN"),
    (dict(A=np.ones((2, 5))), ValueError, "A must have 6 columns"),
    (dict(A=np.full((2, 6), np.inf)), ValueError, "A contains NaN or inf"),
    (dict(b=np.ones(3)), ValueError, "b must have 2 entries"),
    (dict(b=np.array([1.0, np.inf])), ValueError, "b contains NaN or inf"),
    (dict(b=None), ValueError, "A and b must be given together"),
    (dict(lb=np.ones(6), ub=np.zeros(6)), ValueError, r"lb > ub at index 0"),
    (dict(lb=np.full(6, np.nan)), ValueError, "lb contains NaN"),
    (dict(ub=np.ones(4)), ValueError, "ub must have 6 entries"),
    (dict(lb=np.full(6, np.inf)), ValueError, r"lb may not be \+inf"),
    (dict(cones=[FrictionCone(0, 0.0)]), ValueError, r"cones\[0\].mu must be finite and > 0"),
    (dict(cones=[FrictionCone(0, -1.0)]), ValueError, r"cones\[0\].mu"),
    (dict(cones=[FrictionCone(0, np.nan)]), ValueError, r"cones\[0\].mu"),
    (dict(cones=[FrictionCone(0, np.inf)]), ValueError, r"cones\[0\].mu"),
    (dict(cones=[FrictionCone(0, "a")]), TypeError, r"cones\[0\].mu must be a real number"),
    (dict(cones=[FrictionCone(4, 0.5)]), ValueError, r"cones\[0\] covers x\[4:7\], outside"),
    (dict(cones=[FrictionCone(-1, 0.5)]), ValueError, r"outside x of length 6"),
    (
        dict(cones=[FrictionCone(0, 0.5), SecondOrderCone(2, 3)]),
        ValueError, r"cones\[0\] \(x\[0:3\]\) overlaps cones\[1\]",
    ),
    (dict(cones=[SecondOrderCone(0, 1)]), ValueError, r"cones\[0\].dim must be >= 2"),
    (dict(cones=[SecondOrderCone(0.5, 2)]), TypeError, r"cones\[0\].start must be an integer"),
    (dict(cones=[FrictionCone(0, 0.5, (0, 0, 2))]), ValueError, "normal must be a unit vector"),
    (dict(cones=[FrictionCone(0, 0.5, (0, 0, 0))]), ValueError, "normal must be a unit vector"),
    (dict(cones=[FrictionCone(0, 0.5, (0, 1))]), ValueError, "normal must have 3 entries"),
    (dict(cones=[FrictionCone(0, 0.5, (0, np.nan, 1))]), ValueError, "normal contains NaN"),
    (dict(cones=["cone"]), TypeError, r"cones\[0\] must be a FrictionCone or SecondOrderCone"),
    (
        dict(cones=[FrictionCone(0, 0.5)], ub=np.full(6, 10.0)),
        ValueError, r"x\[0\] is in a cone block and has a finite bound",
    ),
    (dict(P=-np.eye(6)), ValueError, "P is not positive semidefinite"),
    # types: object arrays (even of numbers), None, complex, ragged lists
    (dict(P=np.eye(6).astype(object)), TypeError, "P must be a numeric matrix, got dtype object"),
    (dict(P=None), TypeError, "P must be a numeric matrix"),
    (dict(P=[[1.0, 2.0], [3.0]]), TypeError, "P must be a numeric matrix"),
    (dict(P=np.eye(6) + 0j), TypeError, "P must be real"),
    (dict(q=np.ones(6).astype(object)), TypeError, "q must be a numeric vector, got dtype object"),
    (dict(q=None), TypeError, "q must be a numeric vector"),
    (dict(q=np.ones(6) + 0j), TypeError, "q must be real"),
    (dict(A=np.ones((2, 6)).astype(object)), TypeError, "A must be a numeric matrix"),
    (dict(A=np.ones((2, 6)) + 0j), TypeError, "A must be real"),
    (dict(b=np.ones(2).astype(object)), TypeError, "b must be a numeric vector"),
    (dict(b=np.ones(2) + 0j), TypeError, "b must be real"),
    (dict(lb=np.zeros(6).astype(object)), TypeError, "lb must be a numeric vector"),
    (dict(ub=np.ones(6) + 0j), TypeError, "ub must be real"),
    # shapes
    (dict(P=np.zeros((0, 0)), q=np.zeros(0), A=None, b=None), ValueError,
     "P must have at least one row"),
    (dict(A=np.ones(6)), ValueError, "A must be 2-dimensional"),
    (dict(b=np.ones((2, 2))), ValueError, "b must be a vector"),
    (dict(lb=np.zeros((1, 1, 6))), ValueError, "lb must be a vector"),
    # magnitudes beyond 1e20
    (dict(P=np.diag([1e21, 1, 1, 1, 1, 1])), ValueError, "P has an entry of magnitude"),
    (dict(q=np.full(6, -1e21)), ValueError, r"q has an entry of magnitude 1e\+21"),
    (dict(A=np.full((2, 6), 1e21)), ValueError, r"A has an entry of magnitude 1e\+21"),
    (dict(b=np.full(2, 1e21)), ValueError, r"b has an entry of magnitude 1e\+21"),
    # bounds
    (dict(ub=np.full(6, -np.inf)), ValueError, r"ub\[0\] = -inf: lb may not be \+inf and ub"),
    (dict(ub=np.full(6, np.nan)), ValueError, "ub contains NaN"),
    (
        dict(cones=[FrictionCone(3, 0.5)], lb=np.full(6, -1.0)),
        ValueError, r"x\[3\] is in a cone block and has a finite bound \(lb\[3\] = -1.0",
    ),
    # cones
    (dict(cones=None), TypeError, "cones must be a sequence of FrictionCone or SecondOrderCone"),
    (dict(cones=5), TypeError, "cones must be a sequence"),
    (dict(cones="cone"), TypeError, "cones must be a sequence"),
    (dict(cones=[FrictionCone(True, 0.5)]), TypeError, r"cones\[0\].start must be an integer"),
    (dict(cones=[SecondOrderCone(0, 2.0)]), TypeError, r"cones\[0\].dim must be an integer"),
    (dict(cones=[FrictionCone(0, True)]), TypeError, r"cones\[0\].mu must be a real number"),
    (dict(cones=[FrictionCone(0, 0.5j)]), TypeError, r"cones\[0\].mu must be a real number"),
    (
        dict(cones=[FrictionCone(0, 0.5, ("a", "b", "c"))]),
        TypeError, r"cones\[0\].normal must be 3 real numbers",
    ),
    (
        dict(cones=[FrictionCone(0, 0.5, (0, 0, 1j))]),
        TypeError, r"cones\[0\].normal must be 3 real numbers",
    ),
    (dict(cones=[FrictionCone(0, 0.5, (0, 0, np.inf))]), ValueError, "normal contains NaN or inf"),
    (
        dict(cones=[SecondOrderCone(0, 2), FrictionCone(3, 0.5), SecondOrderCone(4, 2)]),
        ValueError, r"cones\[1\] \(x\[3:6\]\) overlaps cones\[2\]",
    ),
]


@pytest.mark.parametrize("changes, error, message", BAD_INPUT)
def test_bad_input(changes, error, message):
    with pytest.raises(error, match=message):
        solve(**changes)


@pytest.mark.parametrize("changes, error, message", BAD_INPUT)
def test_bad_input_after_a_solve(changes, error, message):
    """A solver with a workspace checks a second problem's arrays on its fast path
    (fccqp.fast_checks): the errors are those of a first solve."""
    solver = fccqp.Solver()
    solver.solve(P, q, A, b)
    args = dict(P=P, q=q, A=A, b=b, lb=None, ub=None, cones=())
    args.update(changes)
    with pytest.raises(error, match=message):
        solver.solve(**args)


@pytest.mark.parametrize("convert", [
    lambda v: v.tolist(),
    lambda v: v.astype(np.float32),
    lambda v: v.astype(">f8"),
    lambda v: np.asfortranarray(v) if v.ndim == 2 else v,
    lambda v: np.repeat(v, 2, axis=-1)[..., ::2],   # strided
    lambda v: v.reshape(-1, 1) if v.ndim == 1 else v,   # column vectors
])
def test_arrays_the_fast_path_does_not_take_are_converted(convert):
    """Arguments that are not C-contiguous float64 arrays of the workspace's shapes go
    through fccqp.problem.convert on a warm solver too, and give the same answer."""
    rng = np.random.default_rng(3)
    M = rng.standard_normal((6, 6))
    data = dict(P=M @ M.T + np.eye(6), q=rng.standard_normal(6), A=rng.standard_normal((2, 6)),
                b=rng.standard_normal(2), lb=-np.ones(6), ub=np.ones(6))
    reference = fccqp.Solver(warm_start=False)
    expected = reference.solve(**data)
    reference.solve(**data)
    solver = fccqp.Solver(warm_start=False)
    solver.solve(**data)
    got = solver.solve(**{name: convert(value) for name, value in data.items()})
    assert got.status is expected.status is fccqp.Status.SOLVED
    np.testing.assert_allclose(got.x, expected.x, atol=1e-6)


@BEFORE_ANY_BACKEND
def test_dense_vector_within_accepts_only_finite_contiguous_float64_within_the_limit():
    from fccqp.fast_checks import dense_vector_within

    v = np.array([1.0, -2.0, 0.5])
    assert dense_vector_within(v, 3, 2.0)
    assert dense_vector_within(np.zeros(0), 0, 2.0)
    assert not dense_vector_within(v, 3, 1.5)   # -2 beyond the limit
    assert not dense_vector_within(np.array([1.0, np.nan, 0.0]), 3, 2.0)
    assert not dense_vector_within(np.array([np.inf, 0.0, 0.0]), 3, 1e20)
    assert not dense_vector_within(v, 4, 2.0)   # another size
    assert not dense_vector_within(np.zeros(6)[::2], 3, 2.0)
    assert not dense_vector_within(v.astype(np.float32), 3, 2.0)
    assert not dense_vector_within(v.reshape(3, 1), 3, 2.0)
    assert not dense_vector_within(v.tolist(), 3, 2.0)


@BEFORE_ANY_BACKEND
def test_dense_arguments_recognizes_only_contiguous_float64_of_the_shapes():
    from fccqp.fast_checks import dense_arguments

    M, v, Z, z = np.eye(3), np.zeros(3), np.zeros((1, 3)), np.zeros(1)
    assert dense_arguments(M, v, Z, z, v, v, 3, 1)
    assert dense_arguments(M, v, np.zeros((0, 3)), np.zeros(0), v, v, 3, 0)
    assert not dense_arguments(M, v, Z, z, v, v, 3, 2)   # other sizes
    assert not dense_arguments(M.T.copy(order="F"), v, Z, z, v, v, 3, 1)
    assert not dense_arguments(M, v.astype(np.float32), Z, z, v, v, 3, 1)
    assert not dense_arguments(M, v.astype(">f8"), Z, z, v, v, 3, 1)
    assert not dense_arguments(M, np.zeros(6)[::2], Z, z, v, v, 3, 1)
    assert not dense_arguments(M, v.reshape(3, 1), Z, z, v, v, 3, 1)
    assert not dense_arguments(M, v, Z, z, None, v, 3, 1)
    assert not dense_arguments(M.tolist(), v, Z, z, v, v, 3, 1)
    assert not dense_arguments(memoryview(M), v, Z, z, v, v, 3, 1)   # a buffer, no array
    subclass = type("Subclass", (np.ndarray,), {})
    assert not dense_arguments(M.view(subclass), v, Z, z, v, v, 3, 1)
    assert not dense_arguments(M, v, Z, z, v, v.astype(np.int64), 3, 1)


@BEFORE_ANY_BACKEND
def test_plain_arrays_of_other_shapes_are_refused_without_numpy_buffers():
    """A contact switch tries the caller's arrays against workspaces of other sizes
    (fast_checks' _hold_plain_ndarray refuses them from their fields): numpy's buffer,
    which caches a format record on the array it serves, is not asked for them."""
    import tracemalloc

    from fccqp.fast_checks import dense_arguments

    def arrays() -> tuple[np.ndarray, ...]:
        return np.zeros((5, 5)), np.zeros(5), np.zeros((2, 5)), np.zeros(2), np.zeros(5), \
            np.zeros(5)

    def kept_by(n: int, m: int) -> int:   # bytes a call leaves allocated
        fresh = arrays()
        before = tracemalloc.get_traced_memory()[0]
        dense_arguments(*fresh, n, m)
        return tracemalloc.get_traced_memory()[0] - before

    tracemalloc.start()
    try:
        fitting = [kept_by(5, 2) for _ in range(3)]
        others = [kept_by(4, 2) for _ in range(3)] + [kept_by(5, 3) for _ in range(3)]
    finally:
        tracemalloc.stop()
    assert set(others) == set(fitting)


@BEFORE_ANY_BACKEND
def test_held_arrays_are_released_and_read_only_ones_read():
    """The solve holds its plain numpy arguments from their fields (fast_checks'
    _hold_plain_ndarray): each hold's reference is given back, a read-only argument is
    read as a writable one, and answers do not depend on which way an array was held."""
    import sys

    P, q = np.array([[2.0, 0.5], [0.5, 1.0]]), np.array([1.0, -1.0])
    A, b = np.array([[1.0, 1.0]]), np.array([1.0])
    lb, ub = np.full(2, -10.0), np.full(2, 10.0)
    solver = fccqp.Solver()
    first = solver.solve(P, q, A, b, lb, ub, [])
    counts = [sys.getrefcount(v) for v in (P, q, A, b, lb, ub)]
    for _ in range(20):
        solver.solve(P, q, A, b, lb, ub, [], x0=first.x, y0=first.y, z0=first.z)
    assert [sys.getrefcount(v) for v in (P, q, A, b, lb, ub)] == counts
    frozen = [v.copy() for v in (P, q, A, b, lb, ub)]
    for v in frozen:
        v.flags.writeable = False
    held = fccqp.Solver().solve(*frozen, [])
    swapped = fccqp.Solver().solve(P.astype(">f8"), q, A.astype(">f8"), b, lb, ub, [])
    assert held.status == swapped.status == first.status == fccqp.Status.SOLVED
    np.testing.assert_array_equal(held.x, first.x)
    np.testing.assert_array_equal(swapped.x, first.x)


@BEFORE_ANY_BACKEND
def test_upright_friction_arrays_flatten_only_valid_upright_friction_specs():
    from fccqp.fast_checks import upright_friction_arrays

    specs = (FrictionCone(6, 0.5), FrictionCone(0, 0.25), FrictionCone(3, 1.5))
    expected = (np.zeros(3, np.int64), np.array([6, 0, 3]), np.full(3, 3),
                np.array([0.5, 0.25, 1.5]), np.tile([0.0, 0.0, 1.0], (3, 1)))
    got = upright_friction_arrays(specs, 9)
    for array, value in zip(got, expected, strict=True):
        assert array.dtype == value.dtype and array.shape == value.shape
        assert np.array_equal(array, value) and not array.flags.writeable
    for others in [(FrictionCone(0, 1),), (FrictionCone(0, 0.5, (0.0, 0.0, 1.0)),),
                   (FrictionCone(True, 0.5),), (FrictionCone(0, np.float64(0.5)),),
                   (FrictionCone(0, 0.0),), (FrictionCone(0, float("nan")),),
                   (FrictionCone(0, float("inf")),), (FrictionCone(7, 0.5),),
                   (FrictionCone(-1, 0.5),), (FrictionCone(2**70, 0.5),),
                   (FrictionCone(0, 0.5), FrictionCone(2, 0.5)), (SecondOrderCone(0, 3),)]:
        assert upright_friction_arrays(others, 9) is None


@BEFORE_ANY_BACKEND
@pytest.mark.parametrize(
    "overrides, message",
    [
        (dict(foo=1), "unknown setting.*foo"),
        (dict(rho=0.0), r"rho must lie in \(0, inf\)"),
        (dict(rho=np.nan), r"rho must lie in \(0, inf\), got nan"),
        (dict(rho=1j), "rho must be a real number"),
        (dict(sigma=None), "sigma must be a real number"),
        (dict(alpha=2.0), r"alpha must lie in \(0, 2\)"),
        (dict(eps_abs=-1.0), r"eps_abs must lie in \[0, inf\)"),
        (dict(eps_abs=0.0, eps_rel=0.0), "cannot both be 0"),
        (dict(max_iter=0), r"max_iter must lie in \[1, 2147483647\]"),
        (dict(max_iter=2**31), r"max_iter must lie in \[1, 2147483647\]"),
        (dict(anderson_memory=101), r"anderson_memory must lie in \[0, 100\]"),
        (dict(check_termination=True), "check_termination must be an integer"),
        (dict(max_iter=1.5), "max_iter must be an integer"),
        (dict(time_limit=-1.0), r"time_limit must lie in \(0, inf\]"),
        (dict(adaptive_rho="yes"), "adaptive_rho must be a bool"),
        (dict(verbose=None), "verbose must be a bool"),
        (dict(polish=1), "polish must be a bool"),
        (dict(sigma=0.0), r"sigma must lie in \(0, inf\)"),
        (dict(rho=np.inf), r"rho must lie in \(0, inf\), got inf"),
        (dict(alpha=True), "alpha must be a real number"),
        (dict(eps_rel=np.inf), r"eps_rel must lie in \[0, inf\)"),
        (dict(eps_prim_inf=0.0), r"eps_prim_inf must lie in \(0, inf\)"),
        (dict(eps_dual_inf=-1.0), r"eps_dual_inf must lie in \(0, inf\)"),
        (dict(adaptive_rho_tolerance=1.0), r"adaptive_rho_tolerance must lie in \(1, inf\)"),
        (dict(time_limit=np.nan), r"time_limit must lie in \(0, inf\], got nan"),
        (dict(min_iter=-1), r"min_iter must lie in \[0, 2147483647\]"),
        (dict(min_iter=2**31), r"min_iter must lie in \[0, 2147483647\]"),
        (dict(check_termination=2**31), r"check_termination must lie in \[1, 2147483647\]"),
        (dict(check_termination=0), r"check_termination must lie in \[1, 2147483647\]"),
        (dict(adaptive_rho_interval=2**31),
         r"adaptive_rho_interval must lie in \[1, 2147483647\]"),
        (dict(scaling=101), r"scaling must lie in \[0, 100\]"),
        (dict(scaling=-1), r"scaling must lie in \[0, 100\]"),
        (dict(scaling=4.0), "scaling must be an integer"),
        (dict(anderson_memory=-1), r"anderson_memory must lie in \[0, 100\]"),
        (dict(polish_refine_iter=101), r"polish_refine_iter must lie in \[0, 100\]"),
        (dict(kkt_backend="dense"), "kkt_backend must be one of auto"),
        (dict(kkt_backend=None), "kkt_backend must be one of auto"),
    ],
)
def test_bad_settings(overrides, message):
    with pytest.raises((ValueError, TypeError), match=message):
        solve(**overrides)


@BEFORE_ANY_BACKEND
def test_settings_argument_must_be_settings():
    with pytest.raises(TypeError, match="settings must be a fccqp.Settings"):
        fccqp.Solver(settings={"rho": 1.0})


def test_bad_initial_guess():
    with pytest.raises(ValueError, match="x0 must be a finite vector of 6 entries"):
        fccqp.Solver().solve(P, q, A, b, x0=np.ones(3))


@pytest.mark.parametrize(
    "x0, error, message",
    [
        (np.full(6, np.nan), ValueError, "x0 must be a finite vector of 6 entries"),
        (np.full(6, 1e21), ValueError, r"x0 has an entry beyond 1e\+20"),
        (np.ones(6).astype(object), TypeError, "x0 must be a real numeric vector"),
        (np.ones(6) + 0j, TypeError, "x0 must be a real numeric vector"),
        ("abcdef", TypeError, "x0 must be a real numeric vector"),
    ],
)
def test_bad_initial_guesses(x0, error, message):
    with pytest.raises(error, match=message):
        fccqp.Solver().solve(P, q, A, b, x0=x0)


@pytest.mark.parametrize(
    "guess, error, message",
    [
        ({"y0": np.ones(4)}, ValueError, "y0 must be a finite vector of 2 entries"),
        ({"z0": np.full(6, np.inf)}, ValueError, "z0 must be a finite vector of 6 entries"),
        ({"y0": np.full(2, -1e21)}, ValueError, r"y0 has an entry beyond 1e\+20"),
        ({"z0": np.ones(6) + 0j}, TypeError, "z0 must be a real numeric vector"),
        ({"y0": "ab"}, TypeError, "y0 must be a real numeric vector"),
    ],
)
def test_bad_dual_guesses(guess, error, message):
    with pytest.raises(error, match=message):
        fccqp.Solver().solve(P, q, A, b, x0=np.zeros(6), **guess)


@pytest.mark.parametrize("dual", ["y0", "z0"])
def test_dual_guess_without_x0(dual):
    guess = {"y0": np.zeros(2), "z0": np.zeros(6)}[dual]
    with pytest.raises(ValueError, match="y0 and z0 are dual guesses beside x0"):
        fccqp.solve(P, q, A, b, **{dual: guess})


@BEFORE_ANY_BACKEND
@pytest.mark.parametrize(
    "call, error, message",
    [
        (lambda: fccqp.Settings.realtime(0.0), ValueError, r"budget must lie in \(0, inf\]"),
        (lambda: fccqp.Settings.realtime(np.nan), ValueError, "budget must lie in"),
        (lambda: fccqp.Settings.realtime("2e-3"), TypeError, "budget must be a real number"),
        (lambda: fccqp.Settings.realtime(foo=1), ValueError, "unknown setting.*foo"),
        (lambda: fccqp.Settings().replace(bar=1), ValueError, "unknown setting.*bar"),
        (lambda: fccqp.Solver(baz=1), ValueError, "unknown setting.*baz"),
    ],
)
def test_bad_presets_and_overrides(call, error, message):
    with pytest.raises(error, match=message):
        call()


@BEFORE_ANY_BACKEND
def test_integer_settings_take_their_largest_value():
    settings = fccqp.Settings(max_iter=2**31 - 1, min_iter=2**31 - 1,
                              check_termination=2**31 - 1, adaptive_rho_interval=2**31 - 1,
                              scaling=100, anderson_memory=100, polish_refine_iter=100)
    assert settings.max_iter == fccqp.settings.INT_MAX == 2**31 - 1
    assert settings.scaling == fccqp.settings.MAX_SCALING == 100


def _cone_problem():
    """Two torques, a contact force in a friction cone and a second-order block, with
    the cones binding: the targets of ``q`` lie outside them."""
    n = 8
    P_c = np.diag([1.0, 1.0, 1e-2, 1e-2, 1e-2, 1.0, 1.0, 1.0])
    q_c = np.array([-8.0, 0.0, 0.0, 0.0, 0.0, 0.0, -3.0, -4.0])
    A_c = np.zeros((3, n))
    A_c[0, [0, 2]] = 1.0, -1.0
    A_c[1, [1, 3]] = 1.0, -1.0
    A_c[2, 4] = 1.0
    b_c = np.array([0.0, 0.0, 10.0])
    lb_c = np.array([-6.0, -6.0] + [-np.inf] * 6)
    ub_c = np.array([6.0, 6.0] + [np.inf] * 6)
    return P_c, q_c, A_c, b_c, lb_c, ub_c


@pytest.mark.parametrize("cone", [
    FrictionCone(2, 0.5),
    FrictionCone(2, 0.5, (0.0, 0.6, 0.8)),
    SecondOrderCone(5, 3),
])
def test_a_single_cone_is_a_one_element_list(cone):
    """``cones=cone`` is accepted and means ``cones=[cone]`` (docs/api.md), cold and on
    a warm Solver that alternates between the two spellings."""
    data = _cone_problem()
    listed = fccqp.solve(*data, cones=[cone])
    single = fccqp.solve(*data, cones=cone)
    assert listed.status is single.status is fccqp.Status.SOLVED
    np.testing.assert_array_equal(single.x, listed.x)
    np.testing.assert_array_equal(single.z, listed.z)
    solver, reference = fccqp.Solver(), fccqp.Solver()
    for spelling in ([cone], cone, (cone,), cone):
        got, expected = solver.solve(*data, cones=spelling), reference.solve(*data, cones=[cone])
        assert got.status is expected.status is fccqp.Status.SOLVED
        np.testing.assert_array_equal(got.x, expected.x)


def test_rounding_asymmetry_is_accepted():
    noisy = P + 1e-14 * np.triu(np.ones((6, 6)), 1)
    assert solve(P=noisy).status is fccqp.Status.SOLVED


@BEFORE_ANY_BACKEND
def test_time_limit_infinity_is_default():
    assert fccqp.Settings().time_limit == np.inf


@pytest.mark.parametrize("n", [1, 3, 4, 5, 9])
def test_the_compiled_scan_sees_every_entry(n):
    """The workspace's scan of ``P`` and ``A`` (fccqp_kernels.h: four entries a step,
    then a remainder) finds a bad entry wherever it sits, and sees a change of any one
    pair of ``P`` or entry of ``A`` (a missed one would reuse the old scaling and
    factorization, and ADMM would solve the old problem)."""
    rng = np.random.default_rng(n)
    M = rng.standard_normal((n, n))
    P0, q0 = M @ M.T + np.eye(n), rng.standard_normal(n)
    A0, b0 = rng.standard_normal((1, n)), rng.standard_normal(1)
    solver = fccqp.Solver(eps_abs=1e-9, eps_rel=1e-9, polish=False)

    def check_change(Pk, Ak):
        solver.solve(P0, q0, A0, b0)   # the workspace holds P0, A0
        result = solver.solve(Pk, q0, Ak, b0)
        reference = fccqp.solve(Pk, q0, Ak, b0, eps_abs=1e-9, eps_rel=1e-9).x
        assert result.status is fccqp.Status.SOLVED
        np.testing.assert_allclose(result.x, reference, atol=1e-6)

    for i in range(n):
        for j in range(i, n):
            changed = P0.copy()
            changed[i, j] = changed[j, i] = P0[i, j] + 0.5 * (1 + (i == j))
            check_change(changed, A0)
        changed = A0.copy()
        changed[0, i] += 1.0
        check_change(P0, changed)
    for i in range(n):
        for j in range(n):
            for value, message in [(np.nan, "P contains NaN or inf"),
                                   (np.inf, "P contains NaN or inf"),
                                   (1e21, "P has an entry of magnitude 1e\\+21")]:
                bad = P0.copy()
                bad[i, j] = bad[j, i] = value
                with pytest.raises(ValueError, match=message):
                    solver.solve(bad, q0, A0, b0)
        for value in (np.nan, -np.inf, 1e21):
            bad = A0.copy()
            bad[0, i] = value
            with pytest.raises(ValueError, match="A contains NaN or inf|A has an entry"):
                solver.solve(P0, q0, bad, b0)
    asymmetric = P0.copy()
    asymmetric[n - 1, 0] += 1e-3
    if n > 1:
        with pytest.raises(ValueError, match="P must be symmetric"):
            solver.solve(asymmetric, q0, A0, b0)


def _with(v, i, value):
    changed = v.copy()
    changed[i] = value
    return changed


@BEFORE_ANY_BACKEND
@pytest.mark.parametrize("n", [1, 5, 9])
def test_the_compiled_scan_names_a_bad_vector_or_bound_entry_wherever_it_sits(n):
    """The scan's copies of ``q``, ``b`` and the bounds (fccqp_kernels.h: no branch on the
    data, the entry looked up afterwards) name the first bad entry at any position, and
    each bound's case as before."""
    P0, q0, A0, b0 = np.eye(n), np.ones(n), np.eye(n), np.zeros(n)
    lb0, ub0 = -np.ones(n), np.ones(n)
    solver = fccqp.Solver()
    solver.solve(P0, q0, A0, b0, lb0, ub0)

    def fails(message, q=q0, b=b0, lb=lb0, ub=ub0):
        with pytest.raises(ValueError, match=message):
            solver.solve(P0, q, A0, b, lb, ub)

    for i in range(n):
        fails(rf"q contains NaN or inf \(at index {i}\)", q=_with(q0, i, np.nan))
        fails(rf"q has an entry of magnitude 1e\+21 \(at index {i}\)", q=_with(q0, i, -1e21))
        fails(rf"b contains NaN or inf \(at index {i}\)", b=_with(b0, i, np.inf))
        fails(rf"lb contains NaN \(at index {i}\)", lb=_with(lb0, i, np.nan))
        fails(rf"ub contains NaN \(at index {i}\)", ub=_with(ub0, i, np.nan))
        fails(rf"lb > ub at index {i}", lb=_with(lb0, i, 2.0))
        fails(rf"lb\[{i}\] = inf", lb=_with(lb0, i, np.inf), ub=_with(ub0, i, np.inf))
        fails(rf"ub\[{i}\] = -inf", lb=_with(lb0, i, -np.inf), ub=_with(ub0, i, -np.inf))
        fails(rf"q contains NaN or inf \(at index {i}\)",
              q=_with(_with(q0, i, np.inf), n - 1, np.nan if i == n - 1 else 1e21))
    assert solver.solve(P0, q0, A0, b0, lb0, ub0).status is fccqp.Status.SOLVED


@BEFORE_ANY_BACKEND
def test_the_compiled_scan_sees_a_change_anywhere_in_a_long_A():
    """A change of any one entry of an ``A`` longer than the stretch the scan compares
    before it checks for a change (fccqp_kernels.h: it copies without comparing once one
    was seen) is seen: a missed one would solve the old problem."""
    rng = np.random.default_rng(3)
    n, m = 12, 8
    P0, q0 = np.eye(n), rng.standard_normal(n)
    A0, b0 = rng.standard_normal((m, n)), rng.standard_normal(m)
    solver = fccqp.Solver(eps_abs=1e-9, eps_rel=1e-9, polish=False)
    for k in range(m * n):
        changed = A0.copy()
        changed.flat[k] += 1.0
        solver.solve(P0, q0, A0, b0)   # the workspace holds A0
        result = solver.solve(P0, q0, changed, b0)
        reference = fccqp.solve(P0, q0, changed, b0, eps_abs=1e-9, eps_rel=1e-9).x
        assert result.status is fccqp.Status.SOLVED
        np.testing.assert_allclose(result.x, reference, atol=1e-6)
