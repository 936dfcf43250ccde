"""The ADMM iteration's C kernels (fccqp_kernels.h) against the plain loops they replace:
the reduced step's updates and the residuals' passes, bit for bit, at sizes with and
without a tail of fewer than four entries, with NaN, infinite bounds and cone entries."""

import math

import numpy as np
import pytest
from fccqp.reduced import step_kernels_py
from fccqp.termination import residual_passes_py

VIOLATION = 1e-2   # tuning.SCALED_VIOLATION


def _larger(acc, x):
    """Cython's ``max(acc, x)``: ``x > acc ? x : acc`` (a NaN ``x`` is skipped)."""
    return x if x > acc else acc


def _capped(size, span):
    return min(size, span) if span > 0.0 else size


def _reference_residuals(Ax, b, E, span, x, D, constrained, z, y, lo, hi, in_cone, Px, q,
                         ATnu, c):
    """termination.residuals' loops as they were written in Cython, in Python floats."""
    eq = eq_scale = prim = prim_scale = 0.0
    total = 0.0
    for i in range(len(Ax)):
        value = abs(Ax[i] - b[i])
        scale = _larger(abs(Ax[i]), abs(b[i]))
        eq, eq_scale = _larger(eq, value / E[i]), _larger(eq_scale, scale / E[i])
        prim, prim_scale = _larger(prim, value), _larger(prim_scale, _capped(scale, span[i]))
        total += value
    rows = [eq, eq_scale, prim, prim_scale, total]
    st = st_scale = e_prim = e_prim_scale = size = 0.0
    excess, total = -math.inf, 0.0
    for j, i in enumerate(constrained):
        value = abs(x[i] - z[j])
        scale = _larger(abs(x[i]), abs(z[j]))
        width = hi[j] - lo[j]
        st, st_scale = _larger(st, value * D[i]), _larger(st_scale, scale * D[i])
        e_prim = _larger(e_prim, value)
        e_prim_scale = _larger(e_prim_scale, _capped(scale, width))
        size = _larger(size, scale)
        if not in_cone[j]:
            entry = _larger(scale, width) if math.isfinite(width) else scale
            excess = _larger(excess, value - VIOLATION * entry)
        total += value + abs(y[j])
    entries = [st, st_scale, e_prim, e_prim_scale, size, excess, total]
    xPx = qx = scale_d = scale_s = 0.0
    grad = list(Px)
    for i in range(len(x)):
        xPx += x[i] * Px[i]
        qx += q[i] * x[i]
        terms = _larger(abs(Px[i]), abs(q[i]))
        scale_d = _larger(scale_d, terms * (1.0 / (c * D[i])))
        scale_s = _larger(scale_s, _larger(terms, abs(ATnu[i])))
        grad[i] = Px[i] + (q[i] + ATnu[i])
    dual = dual_s = total = 0.0
    for i in range(len(x)):
        value = abs(grad[i])
        dual, dual_s = _larger(dual, value / (c * D[i])), _larger(dual_s, value)
        total += value + abs(x[i])
    return rows, entries, [xPx, qx, scale_d, scale_s], grad, [dual, dual_s, total]


def _same(a, b):
    both_nan = math.isnan(a) and math.isnan(b)
    return both_nan or (a == b and math.copysign(1, a) == math.copysign(1, b))


def _data(rng, m, n, s, with_nan):
    Ax, b = rng.normal(size=m), rng.normal(size=m)
    E, D = rng.uniform(0.1, 10, size=m), rng.uniform(0.1, 10, size=n)
    span = rng.choice([-1.0, 0.0, 0.5, 3.0, math.inf], size=m)
    x, q, ATnu, Px = (rng.normal(size=n) for _ in range(4))
    constrained = np.sort(rng.choice(n, size=s, replace=False)).astype(np.intp)
    z, y = rng.normal(size=s), rng.normal(size=s)
    lo = rng.choice([-math.inf, -1.0, -0.2], size=s)
    hi = rng.choice([math.inf, 0.3, 2.0], size=s)
    in_cone = (rng.uniform(size=s) < 0.4).astype(np.int8)
    if with_nan:
        Ax[rng.integers(m)] = math.nan
        z[rng.integers(s)] = math.nan
        Px[rng.integers(n)] = math.nan
    return Ax, b, E, span, x, D, constrained, z, y, lo, hi, in_cone, Px, q, ATnu, 1.7


@pytest.mark.parametrize("m, n, s", [(1, 1, 1), (4, 8, 4), (7, 13, 6), (30, 54, 24), (68, 124, 57)])
@pytest.mark.parametrize("with_nan", [False, True])
def test_residual_passes_have_the_bits_of_the_loops(m, n, s, with_nan):
    """Each maximum and the dual residual's sums (x'Px, q'x) to the bit; the sums that
    only say whether the residuals are finite, to their finiteness (they are summed in
    lanes)."""
    rng = np.random.default_rng(m * 1000 + n + with_nan)
    data = _data(rng, m, n, s, with_nan)
    expected = _reference_residuals(*data)
    Px = data[12].copy()
    rows, entries, variables, dual = residual_passes_py(*data[:12], Px, *data[13:])
    # the last entry of rows, entries and dual is a sum of magnitudes
    for got, want, sums in ((rows, expected[0], 1), (entries, expected[1], 1),
                            (variables, expected[2], 0), (dual, expected[4], 1)):
        exact = len(got) - sums
        assert all(_same(g, w) for g, w in zip(got[:exact], want[:exact], strict=True))
        assert [math.isfinite(t) for t in got[exact:]] == [math.isfinite(t) for t in want[exact:]]
    assert all(_same(g, w) for g, w in zip(Px, expected[3], strict=True))


@pytest.mark.parametrize("s", [1, 3, 4, 24, 57])
@pytest.mark.parametrize("alpha, alpha_x", [(1.6, 1.6), (1.6, 1.0)])
def test_step_kernels_have_the_bits_of_the_loops(s, alpha, alpha_x):
    """The reduced step's updates element by element as its loops computed them, the
    clip to [lo, hi] as projections.proj_set's (a NaN stays NaN)."""
    rng = np.random.default_rng(s)
    n = 2 * s + 3
    z, y, v, u = (rng.normal(size=s) for _ in range(4))
    rho = rng.uniform(0.01, 100, size=s)
    base, xs = rng.normal(size=n), rng.normal(size=s)
    constrained = np.sort(rng.choice(n, size=s, replace=False)).astype(np.intp)
    lo = rng.choice([-math.inf, -1.0, -0.1], size=s)
    hi = rng.choice([math.inf, 1.0, 0.1], size=s)
    xs[s // 2] = math.nan
    zk, yk, vk, uk = z.copy(), y.copy(), v.copy(), u.copy()
    z_prev, y_prev, v_prev, u_prev, relaxed = step_kernels_py(zk, yk, rho, vk, uk, base,
                                                              constrained, xs, lo, hi,
                                                              alpha, alpha_x)
    for got, want in ((z_prev, z), (y_prev, y), (v_prev, v), (u_prev, u)):
        assert np.array_equal(got, want)
    want_v = rho * z - y
    want_relaxed = alpha * (base[constrained] + xs) + (1.0 - alpha) * z
    want_u = alpha_x * want_v + (1.0 - alpha_x) * u
    value = want_relaxed + y / rho
    value = np.where(value < lo, lo, value)
    want_z = np.where(value > hi, hi, value)
    want_y = y + rho * (want_relaxed - want_z)
    for got, want in ((vk, want_v), (relaxed, want_relaxed), (uk, want_u), (zk, want_z),
                      (yk, want_y)):
        assert np.array_equal(got, want, equal_nan=True)
