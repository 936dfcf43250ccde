"""Bad input raises a clear error that names the argument."""

import numpy as np
import pytest

import fccqp
from fccqp import FrictionCone, SecondOrderCone

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
    ],
)
def test_bad_settings(overrides, message):
    with pytest.raises((ValueError, TypeError), match=message):
        solve(**overrides)


def test_settings_argument_must_be_settings():
    with pytest.raises(TypeError, match="settings must be a fccqp.Settings"):
        fccqp.Solver(settings={"rho": 1.0})


def test_bad_initial_guess():
    with pytest.raises(ValueError, match="x0 must be a finite vector of 6 entries"):
        fccqp.Solver().solve(P, q, A, b, x0=np.ones(3))


def test_rounding_asymmetry_is_accepted():
    noisy = P + 1e-14 * np.triu(np.ones((6, 6)), 1)
    assert solve(P=noisy).status is fccqp.Status.SOLVED


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
