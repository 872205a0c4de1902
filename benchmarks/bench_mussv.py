"""Benchmarks of ``mussv`` upper bounds: fast path vs LMI path vs dkpy's SsvLmiBisection.

Run (all cases, about 10 minutes on 2 cores)::

    python -m pytest benchmarks/bench_mussv.py -p no:cacheprovider \
        --benchmark-columns=median,min,max,rounds --benchmark-sort=name

Problems: frequency responses of seeded random stable state-space systems (6 states)
with 3 full complex blocks, 4×4 (blk [[2,2],[1,1],[1,1]]) and 8×8
(blk [[4,4],[2,2],[2,2]]), at 61 and 500 log-spaced frequencies in [1e-2, 1e2] rad/s.
Each benchmark records in ``extra_info`` the largest relative deviation of its upper
bound from the exact LMI value (``mussv(method="lmi", lmi_warm_start=False)``).

Mixed real/complex (``test_mussv_mixed_upper``): a 5 × 5 system of the same kind with
blk [[-1,0],[-1,0],[1,1],[2,2]] at 61 frequencies, SLICOT's AB13MD against the LMI.
"""

from __future__ import annotations

import functools
import warnings

import control
import numpy as np
import pytest

from lmi_suspension.mu import MussvOptions, mussv

CASES = {
    "4x4": [[2, 2], [1, 1], [1, 1]],
    "8x8": [[4, 4], [2, 2], [2, 2]],
}
NFREQ = (61, 500)

UPPER_ONLY = MussvOptions(compute_lower=False)
LMI_COLD = MussvOptions(compute_lower=False, lmi_warm_start=False)


@functools.lru_cache(maxsize=None)
def problem(size: str, nf: int):
    """Seeded stable random system, evaluated on nf frequencies (rad/s)."""
    n_io = int(size.split("x")[0])
    rng = np.random.default_rng(2024 + n_io)
    A = rng.standard_normal((6, 6))
    A -= (np.max(np.linalg.eigvals(A).real) + 0.5) * np.eye(6)
    sys = control.ss(A, rng.standard_normal((6, n_io)), rng.standard_normal((n_io, 6)),
                     0.3 * rng.standard_normal((n_io, n_io)))
    w = np.logspace(-2, 2, nf)
    return sys(1j * w), w


@functools.lru_cache(maxsize=None)
def exact(size: str, nf: int) -> np.ndarray:
    """Exact LMI upper bound (the reference every method is compared with)."""
    M, w = problem(size, nf)
    return mussv(M, CASES[size], omega=w, method="lmi", options=LMI_COLD).upper


def _rounds(method: str, nf: int) -> int:
    if method == "fast":
        return 7
    return 3 if nf <= 61 else 1


@pytest.mark.parametrize("nf", NFREQ)
@pytest.mark.parametrize("size", list(CASES))
@pytest.mark.parametrize("method", ["fast", "lmi"])
def test_mussv_upper(benchmark, method, size, nf):
    M, w = problem(size, nf)
    opts = UPPER_ONLY if method == "fast" else LMI_COLD
    res = benchmark.pedantic(
        mussv, args=(M, CASES[size]), kwargs=dict(omega=w, method=method, options=opts),
        rounds=_rounds(method, nf), iterations=1, warmup_rounds=1 if method == "fast" else 0,
    )
    ref = exact(size, nf)
    dev = float(np.max(np.abs(res.upper / ref - 1)))
    benchmark.extra_info.update(max_rel_dev_vs_lmi=dev, upper_seconds=res.timings.upper)
    assert dev <= 1e-4


@pytest.mark.parametrize("nf", NFREQ)
@pytest.mark.parametrize("size", list(CASES))
def test_mussv_full_call(benchmark, size, nf):
    """Default call: fast upper bound plus the certified lower bound."""
    M, w = problem(size, nf)
    res = benchmark.pedantic(mussv, args=(M, CASES[size]), kwargs=dict(omega=w), rounds=3, iterations=1)
    benchmark.extra_info.update(max_gap_upper_lower=float(np.max(res.upper / res.lower - 1)))


@pytest.mark.parametrize("nf", NFREQ)
@pytest.mark.parametrize("size", list(CASES))
def test_dkpy_ssv_lmi_bisection(benchmark, size, nf):
    dkpy = pytest.importorskip("dkpy", reason="dkpy not installed (pip install dkpy)")
    M, w = problem(size, nf)
    solver = dkpy.SsvLmiBisection(n_jobs=None)  # single process, like mussv

    def run():
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            return solver.compute_ssv(M, CASES[size])

    mu, *_ = benchmark.pedantic(run, rounds=1, iterations=1)
    dev = float(np.max(np.abs(np.asarray(mu).ravel() / exact(size, nf) - 1)))
    benchmark.extra_info.update(max_rel_dev_vs_lmi=dev)


# ------------------------------------------------------------------ mixed real / complex
#: a mixed structure AB13MD takes: two real scalars, a 1 × 1 and a 2 × 2 complex block
MIXED = [[-1, 0], [-1, 0], [1, 1], [2, 2]]


@functools.lru_cache(maxsize=None)
def mixed_problem(nf: int):
    """Seeded stable random 5 × 5 system on nf frequencies (rad/s)."""
    rng = np.random.default_rng(2031)
    A = rng.standard_normal((6, 6))
    A -= (np.max(np.linalg.eigvals(A).real) + 0.5) * np.eye(6)
    sys = control.ss(A, rng.standard_normal((6, 5)), rng.standard_normal((5, 6)),
                     0.3 * rng.standard_normal((5, 5)))
    w = np.logspace(-2, 2, nf)
    return sys(1j * w), w


@functools.lru_cache(maxsize=None)
def mixed_lmi(nf: int):
    M, w = mixed_problem(nf)
    return mussv(M, MIXED, omega=w, method="lmi", options=LMI_COLD).upper


@pytest.mark.parametrize("method", ["ab13md", "lmi"])
def test_mussv_mixed_upper(benchmark, method):
    """Mixed real/complex upper bound, SLICOT's AB13MD against the Clarabel LMI (61
    frequencies); ``extra_info`` holds the largest ratio of its bound to the LMI's (the
    smaller, the tighter)."""
    pytest.importorskip("slycot")
    M, w = mixed_problem(61)
    res = benchmark.pedantic(mussv, args=(M, MIXED),
                             kwargs=dict(omega=w, method=method, options=LMI_COLD),
                             rounds=3 if method == "ab13md" else 1, iterations=1)
    ratio = res.upper / mixed_lmi(61)
    benchmark.extra_info.update(max_ratio_vs_lmi=float(np.max(ratio)),
                                min_ratio_vs_lmi=float(np.min(ratio)),
                                upper_seconds=res.timings.upper)
    # both are the D-G bound, each certified by its scalings: AB13MD is never looser
    assert np.max(ratio) <= 1 + 1e-5
