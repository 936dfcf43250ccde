"""Does scipy's bundled OpenBLAS spin threads for KKT-sized calls, and what stops it?

Measures, for symmetric matrices of the sizes of fccqp's KKT systems, the median time of
the LAPACK/BLAS calls the compiled core will make through ``scipy.linalg.cython_lapack``
/ ``cython_blas`` (here through ``scipy.linalg.lapack`` / ``blas``, which wrap the same
``libscipy_openblas`` symbols), unloaded and with CPU-bound background processes, under:

- ``default``: OpenBLAS's own thread count (the number of cores);
- ``limit1``: inside ``threadpoolctl.threadpool_limits(1)`` (set once, outside the loop);
- ``set1``: ``scipy_openblas_set_num_threads(1)`` before each call and the previous
  count restored after it, through ctypes (what a compiled core could do per solve).

Also times the set/get pair itself through ctypes and, if ``gcc`` is found, from C.
Run ``python notes/blas_threads.py [--sizes 60 90 130 200] [--load 3]``; the background
processes stop themselves after ``--max-seconds`` and are killed at exit anyway.
"""

from __future__ import annotations

import argparse
import ctypes
import os
import shutil
import statistics
import subprocess
import sys
import tempfile
import time
from collections.abc import Callable

import numpy as np
import threadpoolctl
from scipy.linalg import blas, lapack

_SPIN = "import time\nt = time.time() + {seconds}\nwhile time.time() < t: pass\n"


def scipy_openblas() -> tuple[ctypes.CDLL, dict]:
    """The OpenBLAS that scipy.linalg links (not numpy's 64-bit-integer copy), and its info."""
    infos = threadpoolctl.ThreadpoolController().info()
    for info in infos:
        if info.get("internal_api") == "openblas" and "scipy.libs" in info["filepath"]:
            return ctypes.CDLL(info["filepath"]), info
    raise RuntimeError(f"no scipy OpenBLAS among {infos}")


def thread_symbols(lib: ctypes.CDLL) -> dict[str, bool]:
    """Which of the usual thread-count setters/getters the library exports."""
    names = [
        "openblas_set_num_threads",
        "openblas_get_num_threads",
        "openblas_set_num_threads_local",
        "scipy_openblas_set_num_threads",
        "scipy_openblas_get_num_threads",
        "scipy_openblas_set_num_threads_",
        "scipy_openblas_get_num_threads_",
        "scipy_openblas_set_num_threads64_",
        "scipy_openblas_get_num_threads64_",
        "scipy_openblas_get_config",
        "scipy_openblas_get_parallel",
        "goto_set_num_threads",
        "scipy_goto_set_num_threads",
        "openblas_set_threads_callback_function",
    ]
    return {name: hasattr(lib, name) for name in names}


def start_load(count: int, seconds: float) -> list[subprocess.Popen]:
    """``count`` CPU-bound interpreters that exit by themselves after ``seconds``."""
    code = _SPIN.format(seconds=seconds)
    return [subprocess.Popen([sys.executable, "-c", code]) for _ in range(count)]


def stop_load(procs: list[subprocess.Popen]) -> None:
    """Kill the background processes this script started (by their own handles)."""
    for p in procs:
        if p.poll() is None:
            p.kill()
    for p in procs:
        p.wait()


def _sym_indefinite(n: int, rng: np.random.Generator) -> np.ndarray:
    """A KKT-like quasi-definite matrix [[P, A'], [A, -r I]] with 2/3 of rows primal."""
    nx = (2 * n) // 3
    m = n - nx
    M = rng.standard_normal((nx, nx))
    P = M @ M.T + np.eye(nx)
    A = rng.standard_normal((m, nx))
    K = np.block([[P, A.T], [A, -np.eye(m)]])
    return np.asfortranarray(K)


def kernels(n: int, rng: np.random.Generator) -> dict[str, Callable[[], object]]:
    """One zero-argument call per routine at size ``n``; inputs are restored untimed."""
    K = _sym_indefinite(n, rng)
    M = rng.standard_normal((n, n))
    S = np.asfortranarray(M @ M.T + n * np.eye(n))
    L = np.asfortranarray(np.linalg.cholesky(S))
    B = np.asfortranarray(rng.standard_normal((n, n)))
    b = np.asfortranarray(rng.standard_normal((n, 1)))
    lu, piv, _ = lapack.dsytrf(K, lwork=64 * n)
    work = np.empty_like(K, order="F")
    calls: dict[str, tuple[np.ndarray, Callable[[], object]]] = {
        "dsytrf(lwork default)": (K, lambda: lapack.dsytrf(work, overwrite_a=1)),
        "dsytrf(lwork=64n)": (K, lambda: lapack.dsytrf(work, lwork=64 * n, overwrite_a=1)),
        "dpotrf": (S, lambda: lapack.dpotrf(work, lower=1, overwrite_a=1)),
        "dtrsm(n x n rhs)": (B, lambda: blas.dtrsm(1.0, L, work, lower=1, overwrite_b=1)),
        "dtrsm(1 rhs)": (None, lambda: blas.dtrsm(1.0, L, b, lower=1)),
        "dsyrk(n x n)": (None, lambda: blas.dsyrk(1.0, B, trans=1)),
        "dgemv(n x n)": (None, lambda: blas.dgemv(1.0, B, b[:, 0])),
        "dsytrs(1 rhs)": (None, lambda: lapack.dsytrs(lu, piv, b)),
        "dpotrs(1 rhs)": (None, lambda: lapack.dpotrs(L, b, lower=1)),
        "LDL solve: dsytrf(64n)+30 dsytrs": (K, lambda: _ldl_like(work, b, n, lapack.dsytrf)),
    }
    out = {}
    for name, (source, call) in calls.items():
        if source is None:
            out[name] = call
        else:
            out[name] = _restoring(source, work, call)
    return out


def _ldl_like(work: np.ndarray, b: np.ndarray, n: int, dsytrf) -> None:
    """What the dense LDL' backend does in one ADMM solve: one factorization, 30 solves."""
    lu, piv, _ = dsytrf(work, lwork=64 * n, overwrite_a=1)
    for _ in range(30):
        lapack.dsytrs(lu, piv, b)


def _restoring(source: np.ndarray, work: np.ndarray, call: Callable[[], object]):
    def run() -> object:
        np.copyto(work, source)
        return call()

    run.restore = lambda: np.copyto(work, source)  # type: ignore[attr-defined]
    run.call = call  # type: ignore[attr-defined]
    return run


def times(fn: Callable[[], object], count: int, wrap=None) -> list[float]:
    """Seconds of ``count`` calls of ``fn``, its untimed input restore excluded."""
    restore = getattr(fn, "restore", None)
    call = getattr(fn, "call", fn)
    if wrap is not None:
        call = wrap(call)
    samples = []
    for _ in range(count):
        if restore is not None:
            restore()
        t0 = time.perf_counter()
        call()
        samples.append(time.perf_counter() - t0)
    return samples


def set1_wrapper(lib: ctypes.CDLL):
    """Wrap a call in set(1) ... restore(previous) through the scipy OpenBLAS setter."""
    setter, getter = lib.scipy_openblas_set_num_threads, lib.scipy_openblas_get_num_threads
    setter.restype, getter.restype = None, ctypes.c_int
    setter.argtypes = [ctypes.c_int]

    def wrap(call):
        def run():
            previous = getter()
            setter(1)
            try:
                return call()
            finally:
                setter(previous)

        return run

    return wrap


def ctypes_cost(lib: ctypes.CDLL, loops: int = 200_000) -> dict[str, float]:
    """ns per get, per set(1)+set(back) pair, and per get+set+set as a wrapper would do."""
    setter, getter = lib.scipy_openblas_set_num_threads, lib.scipy_openblas_get_num_threads
    setter.restype, getter.restype, setter.argtypes = None, ctypes.c_int, [ctypes.c_int]
    previous = getter()
    res = {}
    t0 = time.perf_counter_ns()
    for _ in range(loops):
        getter()
    res["ctypes get"] = (time.perf_counter_ns() - t0) / loops
    t0 = time.perf_counter_ns()
    for _ in range(loops):
        setter(1)
        setter(previous)
    res["ctypes set(1)+set(prev)"] = (time.perf_counter_ns() - t0) / loops
    t0 = time.perf_counter_ns()
    for _ in range(loops // 10):
        with threadpoolctl.threadpool_limits(1):
            pass
    res["threadpool_limits(1) enter+exit"] = (time.perf_counter_ns() - t0) / (loops // 10)
    return res


_C_PROBE = r"""
#include <dlfcn.h>
#include <stdio.h>
#include <time.h>
int main(int argc, char **argv) {
  void *h = dlopen(argv[1], RTLD_NOW | RTLD_LOCAL);
  if (!h) { fprintf(stderr, "%s\n", dlerror()); return 1; }
  void (*set)(int) = (void (*)(int))dlsym(h, "scipy_openblas_set_num_threads");
  int (*get)(void) = (int (*)(void))dlsym(h, "scipy_openblas_get_num_threads");
  if (!set || !get) return 2;
  const long loops = 10000000;
  struct timespec a, b;
  volatile int sink = 0;
  clock_gettime(CLOCK_MONOTONIC, &a);
  for (long i = 0; i < loops; i++) { int p = get(); set(1); set(p); sink += p; }
  clock_gettime(CLOCK_MONOTONIC, &b);
  printf("%.2f\n", ((b.tv_sec - a.tv_sec) * 1e9 + (b.tv_nsec - a.tv_nsec)) / loops);
  return 0;
}
"""


def c_cost(path: str) -> float | None:
    """ns per get+set(1)+set(prev) from C through dlsym'd pointers (None without gcc)."""
    gcc = shutil.which("gcc")
    if gcc is None:
        return None
    with tempfile.TemporaryDirectory() as tmp:
        src, exe = os.path.join(tmp, "probe.c"), os.path.join(tmp, "probe")
        with open(src, "w") as f:
            f.write(_C_PROBE)
        subprocess.run([gcc, "-O2", src, "-o", exe, "-ldl"], check=True)
        out = subprocess.run([exe, path], capture_output=True, text=True, check=True)
    return float(out.stdout)


def main() -> None:
    """Measure and print the tables."""
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--sizes", type=int, nargs="+", default=[60, 90, 130, 200])
    parser.add_argument("--load", type=int, default=3, help="background processes")
    parser.add_argument("--reps", type=int, default=300)
    parser.add_argument("--budget", type=float, default=0.4, help="seconds per cell at most")
    parser.add_argument("--max-seconds", type=float, default=300.0)
    args = parser.parse_args()

    lib, info = scipy_openblas()
    print(
        f"{info['filepath']}\nversion {info['version']}, {info['threading_layer']}, "
        f"{info['num_threads']} threads, {info['architecture']}; cpus {os.cpu_count()}"
    )
    lib.scipy_openblas_get_config.restype = ctypes.c_char_p
    print("config:", lib.scipy_openblas_get_config().decode())
    print("exported:", ", ".join(k for k, v in thread_symbols(lib).items() if v))
    print("absent:  ", ", ".join(k for k, v in thread_symbols(lib).items() if not v))
    for k, v in ctypes_cost(lib).items():
        print(f"{k}: {v:.0f} ns")
    c = c_cost(info["filepath"])
    if c is not None:
        print(f"C get+set(1)+set(prev): {c:.1f} ns")

    rng = np.random.default_rng(0)
    per_size = {n: kernels(n, rng) for n in args.sizes}
    wrap = set1_wrapper(lib)

    def block(label: str, fn, count: int) -> list[float]:
        if label == "limit1":
            with threadpoolctl.threadpool_limits(1):
                return times(fn, count)
        return times(fn, count, wrap if label == "set1" else None)

    def sweep(labels: tuple[str, ...]) -> dict:
        """Configurations interleaved in blocks of 10 calls, so drift hits them alike."""
        res = {}
        for n, ks in per_size.items():
            for name, fn in ks.items():
                samples: dict[str, list[float]] = {lab: [] for lab in labels}
                deadline = time.perf_counter() + args.budget * len(labels)
                while len(samples[labels[0]]) < args.reps:
                    for lab in labels:
                        samples[lab] += block(lab, fn, 10)
                    if time.perf_counter() > deadline:
                        break
                for lab in labels:
                    res[lab, name, n] = samples[lab]
        return res

    unloaded = sweep(("default", "limit1"))
    procs = start_load(args.load, args.max_seconds)
    try:
        time.sleep(0.5)
        loaded = sweep(("default", "limit1", "set1"))
    finally:
        stop_load(procs)
    table = {f"unloaded {lab}": unloaded for lab in ("default", "limit1")}
    table.update({f"loaded {lab}": loaded for lab in ("default", "limit1", "set1")})

    names = list(next(iter(per_size.values())))
    print(f"\nmedian/p90/mean us; load = {args.load} busy processes on {os.cpu_count()} cpus")
    print(f"{'routine':33s} {'n':>4s} " + " ".join(f"{c:>21s}" for c in table))
    for name in names:
        for n in args.sizes:
            cells = []
            for col, res in table.items():
                s = res[col.split()[1], name, n]
                p90 = statistics.quantiles(s, n=10)[-1]
                med, mean = statistics.median(s), statistics.fmean(s)
                cells.append(f"{med * 1e6:7.0f}/{p90 * 1e6:6.0f}/{mean * 1e6:6.0f}")
            print(f"{name:33s} {n:4d} " + " ".join(cells))


if __name__ == "__main__":
    main()
