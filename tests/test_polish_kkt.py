"""The polish's KKT residual norm (``fccqp_abs_max``) against ``_dense.inf_norm``'s loop,
bit for bit: NaN entries skipped, signed zeros and infinities, lengths with and without
a tail of fewer than four entries."""

import math

import numpy as np
import pytest
from fccqp.polish_kkt import abs_max_py


def _inf_norm(v):
    """``_dense.inf_norm`` as written: ``|v_i| > out`` keeps the larger, so a NaN is
    skipped."""
    out = 0.0
    for value in v:
        if abs(value) > out:
            out = abs(value)
    return out


@pytest.mark.parametrize("n", [0, 1, 3, 4, 5, 8, 11, 90])
def test_abs_max_matches_inf_norm(n):
    rng = np.random.default_rng(n)
    for _ in range(200):
        v = rng.standard_normal(n) * 10.0 ** rng.integers(-10, 10, n)
        special = rng.integers(0, 8, n)
        v[special == 0] = math.nan
        v[special == 1] = -0.0
        v[special == 2] = -math.inf if n % 2 else math.inf
        got, want = abs_max_py(np.ascontiguousarray(v)), _inf_norm(v)
        assert np.float64(got).tobytes() == np.float64(want).tobytes()


def test_abs_max_skips_nan_everywhere():
    assert abs_max_py(np.array([math.nan] * 7)) == 0.0
    assert abs_max_py(np.array([math.nan, -3.0, math.nan, 2.0, math.nan])) == 3.0
