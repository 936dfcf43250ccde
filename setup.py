"""Build the compiled core: one extension module per .pyx beside the Python modules.

LAPACK and BLAS come from ``scipy.linalg.cython_lapack`` / ``cython_blas`` at run time,
so nothing is linked here; a C compiler, Cython, scipy's .pxd files and numpy's headers
(read by ``fast_checks`` and ``admm``) are needed at build time (pyproject.toml's build
requirements).
"""

from pathlib import Path

import numpy
from Cython.Build import cythonize
from setuptools import Extension, setup

MODULES = sorted(path.stem for path in Path("src/fccqp").glob("*.pyx"))

# Python's own CFLAGS carry -fwrapv (CPython relies on signed wrap-around); the compiled
# core does not, and without it gcc may assume that int index arithmetic does not wrap
# (go2 cold ticks 3-4 % less wall time, warm 3 %, the same bits: notes/performance-history.md)
COMPILE_ARGS = ["-O3", "-fno-wrapv"]

extensions = [
    Extension(f"fccqp.{name}", [f"src/fccqp/{name}.pyx"],
              include_dirs=["src/fccqp", numpy.get_include()],
              depends=["src/fccqp/fccqp_kernels.h", "src/fccqp/fccqp_clock.h"],
              define_macros=[("NPY_NO_DEPRECATED_API", "NPY_1_7_API_VERSION")],
              extra_compile_args=COMPILE_ARGS)
    for name in MODULES
]

setup(
    ext_modules=cythonize(
        extensions,
        include_path=["src"],
        compiler_directives={"language_level": 3},
        quiet=True,
    ),
)
