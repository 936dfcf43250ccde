"""LAPACK/BLAS kernels at one KKT size, each called once, for callgrind's counts.

Calibrates the study's flop model to instructions (valgrind's CPU, scipy's OpenBLAS,
one thread)::

    valgrind --tool=callgrind --callgrind-out-file=/tmp/kern-84.cg \\
        python tools/activeset_callgrind/kernels.py 84
    python tools/activeset_callgrind/calls.py /tmp/kern-84.cg scipy_dsytrf_ \\
        scipy_dpotrf_ scipy_dtrsv_ scipy_dsyr_ scipy_dgemv_

The symmetric indefinite matrix has a negative identity block in its last third, as a
KKT matrix has; ``dsytrf``'s pivoting depends on the numbers, so its count is that of
this matrix, not of every KKT matrix of that size.
"""

import sys

import numpy as np
from scipy.linalg import blas, lapack
from threadpoolctl import threadpool_limits


def main(size: int) -> None:
    rng = np.random.default_rng(0)
    B = rng.standard_normal((size, size))
    S = B @ B.T + size * np.eye(size)
    K = np.asfortranarray(S.copy())
    third = size // 3
    K[size - third:, size - third:] = -np.eye(third)
    L = np.asfortranarray(np.linalg.cholesky(S))
    v = rng.standard_normal(size)
    with threadpool_limits(1):
        lapack.dsytrf(K)
        lapack.dpotrf(np.asfortranarray(S))
        blas.dtrsv(L, v, lower=1)
        blas.dsyr(1.0, v, a=np.asfortranarray(S.copy()), lower=1, overwrite_a=1)
        blas.dgemv(1.0, L, v)


if __name__ == "__main__":
    main(int(sys.argv[1]))
