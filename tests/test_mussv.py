"""Tests of ``mussv``: known values, two routes, certificates, errors.

Reference values come from µ theory (σ̄ for one full block, ρ for one repeated complex
scalar, ρ ≤ µ ≤ σ̄, exactness of the D bound for ≤ 3 full blocks), from the SLICOT
AB13MD documented example, from slycot's AB13MD wrapper (an independent
implementation) and from independent computations inside the tests.
"""


import time

import control
import numpy as np
import pytest
import scipy.optimize

from lmi_suspension.errors import DimensionError, InputError, NonFiniteError
from lmi_suspension.mu import (
    BlockStructure,
    MussvOptions,
    MussvResult,
    mussv,
    plot_dscales,
    plot_mu,
)
from lmi_suspension.mu.bounds import _block_labels, _fast_upper, _perron_logd, _power_lower

LMI_COLD = MussvOptions(lmi_warm_start=False)


def crandn(rng, *shape):
    return rng.standard_normal(shape) + 1j * rng.standard_normal(shape)


def lmi_certified_bound(M, res):
    """Smallest β with M* X_L M + j(G M - M* G*) ⪯ β² X_R for the returned scalings.

    Recomputed here with numpy from ``res.D_left``, ``res.D_right``, ``res.G``: an
    independent check that the reported upper bound is certified.
    """
    XL = res.D_left.conj().T @ res.D_left
    XR = res.D_right.conj().T @ res.D_right
    H = M.conj().T @ XL @ M + 1j * (res.G @ M - M.conj().T @ res.G.conj().T)
    Rinv = np.linalg.inv(np.linalg.cholesky(XR))
    K = Rinv @ H @ Rinv.conj().T
    return np.sqrt(max(np.linalg.eigvalsh((K + K.conj().T) / 2)[-1], 0.0))


def assert_lower_certified(M, res):
    """The returned Δ is destabilising and lower = 1/σ̄(Δ)."""
    if res.lower == 0:
        return
    Delta = res.delta
    assert np.linalg.svd(np.eye(M.shape[0]) - M @ Delta, compute_uv=False)[-1] < 1e-7
    assert res.lower == pytest.approx(1 / np.linalg.norm(Delta, 2), rel=1e-12)
    # Δ has the structure (zero off the block diagonal, real blocks real).
    s = res.blk
    mask = np.zeros(Delta.shape, dtype=bool)
    for b, rs, cs in zip(s.blocks, s.row_slices(), s.col_slices()):
        mask[cs, rs] = True
        if b.is_real:
            assert np.allclose(Delta[cs, rs].imag, 0) and np.allclose(Delta[cs, rs], Delta[cs, rs][0, 0] * np.eye(b.rows))
    assert np.all(Delta[~mask] == 0)


# ------------------------------------------------------------------ textbook values
@pytest.mark.parametrize("shape", [(3, 3), (2, 4), (4, 2)])
def test_single_full_block_is_max_singular_value(shape):
    rng = np.random.default_rng(10)
    M = crandn(rng, *shape)
    res = mussv(M, [[shape[1], shape[0]]])  # Δ is r×c with M c×r
    sigma = np.linalg.svd(M, compute_uv=False)[0]
    assert res.upper == pytest.approx(sigma, rel=1e-10)
    assert res.lower == pytest.approx(sigma, rel=1e-8)
    assert_lower_certified(M, res)


def test_single_repeated_complex_scalar_is_spectral_radius():
    rng = np.random.default_rng(11)
    # Diagonalisable with a known spectrum, so ρ is known exactly.
    T = crandn(rng, 4, 4)
    lam = np.array([0.3 + 1j, -0.7 + 1j, 0.5 + 3j, 0.5 - 3j])
    M = T @ np.diag(lam) @ np.linalg.inv(T)
    rho = np.max(np.abs(lam))
    res = mussv(M, [[4, 0]])
    assert res.method == "lmi"
    assert res.upper == pytest.approx(rho, rel=1e-5)
    assert res.lower == pytest.approx(rho, rel=1e-10)
    assert lmi_certified_bound(M, res) <= res.upper * (1 + 1e-9)
    assert_lower_certified(M, res)


def test_rho_le_mu_le_sigma_random():
    rng = np.random.default_rng(12)
    blk = [[1, 1], [2, 2], [1, 1]]
    for _ in range(5):
        M = crandn(rng, 4, 4)
        res = mussv(M, blk, rng=rng)
        rho = np.max(np.abs(np.linalg.eigvals(M)))
        sigma = np.linalg.norm(M, 2)
        assert rho * (1 - 1e-9) <= res.lower <= res.upper <= sigma * (1 + 1e-12)


def test_invariance_under_commuting_scalings():
    rng = np.random.default_rng(13)
    s = BlockStructure.from_blk([[2, 1], [1, 2], [1, 1]])
    M = crandn(rng, *s.shape_M)
    DL, DR = s.d_scalings([5.0, 0.1, 1.0])
    M2 = DL @ M @ np.linalg.inv(DR)
    r1, r2 = mussv(M, s), mussv(M2, s)
    assert r2.upper == pytest.approx(r1.upper, rel=1e-6)
    assert r2.lower == pytest.approx(r1.lower, rel=1e-6)


def test_invariance_with_hermitian_scaling_of_repeated_scalar():
    rng = np.random.default_rng(14)
    s = BlockStructure.from_blk([[2, 0], [1, 1]])
    M = crandn(rng, 3, 3)
    H = crandn(rng, 2, 2)
    DL, DR = s.d_scalings([H @ H.conj().T + np.eye(2), 1.0])
    r1 = mussv(M, s)
    r2 = mussv(DL @ M @ np.linalg.inv(DR), s)
    assert r2.upper == pytest.approx(r1.upper, rel=1e-4)
    assert r1.lower <= r1.upper and r2.lower <= r2.upper


@pytest.mark.parametrize(
    "blk,shape",
    [([[1, 1], [1, 1]], (2, 2)), ([[2, 2], [1, 1], [1, 1]], (4, 4)), ([[1, 2], [2, 1], [1, 1]], (4, 4)),
     ([[3, 2], [1, 2]], (4, 4))],
)
def test_three_or_fewer_full_blocks_bounds_meet(blk, shape):
    # For at most three full complex blocks the D upper bound equals µ (Doyle 1982),
    # so the independently computed lower bound must meet it.
    rng = np.random.default_rng(15)
    for _ in range(4):
        M = crandn(rng, *shape)
        res = mussv(M, blk, rng=rng)
        assert res.lower == pytest.approx(res.upper, rel=1e-3)
        assert_lower_certified(M, res)
        DL, DR = res.D_left, res.D_right
        assert np.linalg.norm(DL @ M @ np.linalg.inv(DR), 2) <= res.upper * (1 + 1e-9)


@pytest.mark.parametrize("blk,shape", [([[2, 2], [1, 1], [1, 1]], (4, 4)), ([[1, 1]] * 4 + [[2, 2]], (6, 6)),
                                       ([[1, 2], [2, 1], [1, 1]], (4, 4))])
def test_fast_path_agrees_with_lmi(blk, shape):
    rng = np.random.default_rng(16)
    for _ in range(3):
        M = crandn(rng, *shape)
        fast = mussv(M, blk, method="fast")
        lmi = mussv(M, blk, method="lmi", options=LMI_COLD)
        assert fast.method == "fast" and lmi.method == "lmi"
        # both are certified upper bounds of the same infimum
        assert fast.upper == pytest.approx(lmi.upper, rel=1e-4)
        assert lmi_certified_bound(M, lmi) <= lmi.upper * (1 + 1e-9)


def test_fast_optimiser_matches_scipy_bfgs():
    # The hand-written BFGS must reach what scipy's BFGS reaches on the same function.
    rng = np.random.default_rng(17)
    s = BlockStructure.from_blk([[1, 1]] * 4 + [[2, 2]])
    rl, cl = _block_labels(s)
    for _ in range(3):
        M = crandn(rng, 6, 6)
        x0 = _perron_logd(M, s, rl, cl)
        ours, _, _ = _fast_upper(M, s, rl, cl, [x0], MussvOptions())

        def f(x, M=M):
            logd = np.append(x, 0.0)
            return np.log(np.linalg.norm(np.exp(logd[rl])[:, None] * M * np.exp(-logd[cl])[None, :], 2))

        ref = scipy.optimize.minimize(f, x0[:-1], method="Nelder-Mead",
                                      options={"xatol": 1e-10, "fatol": 1e-13, "maxiter": 20000})
        assert ours <= np.exp(ref.fun) * (1 + 1e-6)


# ------------------------------------------------------------------ SLICOT AB13MD
# SLICOT-Reference examples/AB13MD.dat: N=6, M=5 blocks, NBLOCK = 1 1 2 1 1,
# ITYPE = 1 1 2 2 2 (1 real, 2 complex); Z read row by row.  AB13MD.res documents
# the bound 0.4174753408D+02.
_AB13MD_ROWS = [
    [(-1, 6), (2, -3), (3, 8), (3, 8), (-5, -9), (-6, 2)],
    [(4, 2), (-2, 5), (-6, -7), (-4, 11), (8, -7), (12, -1)],
    [(5, -4), (-4, -8), (1, -3), (-6, 14), (2, -5), (4, 16)],
]
AB13MD_Z = np.array([[complex(*e) for e in row] for row in _AB13MD_ROWS * 2])
AB13MD_BLK = [[-1, 0], [-1, 0], [2, 2], [1, 1], [1, 1]]
AB13MD_BOUND = 41.74753408


def test_slicot_ab13md_example():
    res = mussv(AB13MD_Z, AB13MD_BLK, method="lmi")
    assert res.method == "lmi"
    assert res.upper == pytest.approx(AB13MD_BOUND, rel=1e-6)
    assert lmi_certified_bound(AB13MD_Z, res) <= res.upper * (1 + 1e-9)
    assert 0 < res.lower <= res.upper
    assert_lower_certified(AB13MD_Z, res)


def test_slycot_ab13md_independent_route():
    slycot = pytest.importorskip("slycot")
    rng = np.random.default_rng(18)
    for Z, nblock, itype, blk in [
        (AB13MD_Z, [1, 1, 2, 1, 1], [1, 1, 2, 2, 2], AB13MD_BLK),
        (crandn(rng, 4, 4), [1, 2, 1], [2, 2, 1], [[1, 1], [2, 2], [-1, 0]]),
    ]:
        bound, *_ = slycot.ab13md(Z, np.array(nblock), np.array(itype))
        res = mussv(Z, blk, method="lmi")
        assert res.upper == pytest.approx(bound, rel=1e-5)
        assert mussv(Z, blk).method == "ab13md"      # what "auto" takes here


def test_ab13md_method_gives_the_documented_bound_with_checked_scalings():
    """``method="ab13md"``: SLICOT's documented example value, and the returned scalings
    certify the returned bound (recomputed here with numpy)."""
    pytest.importorskip("slycot")
    res = mussv(AB13MD_Z, AB13MD_BLK, method="ab13md")
    assert res.method == "ab13md"
    assert res.upper == pytest.approx(AB13MD_BOUND, rel=1e-6)
    assert lmi_certified_bound(AB13MD_Z, res) <= res.upper * (1 + 1e-9)
    assert_lower_certified(AB13MD_Z, res)


def test_ab13md_method_agrees_with_the_lmi_on_a_mixed_sweep():
    """Two routes to one D-G bound on a 4-frequency stack with real and complex blocks:
    AB13MD (SLICOT) and the Clarabel LMI, each certified by its own scalings."""
    pytest.importorskip("slycot")
    rng = np.random.default_rng(31)
    blk = [[-1, 0], [-1, 0], [1, 1], [2, 2]]
    M = crandn(rng, 5, 5, 4)
    ab = mussv(M, blk, method="ab13md")
    lmi = mussv(M, blk, method="lmi")
    assert ab.upper == pytest.approx(lmi.upper, rel=1e-5)
    for k in range(4):
        Mk = M[:, :, k]
        one = mussv(Mk, blk, method="ab13md")
        assert lmi_certified_bound(Mk, one) <= one.upper * (1 + 1e-9)
        assert one.upper == ab.upper[k]


def test_ab13md_block_map_takes_only_square_full_blocks_and_single_scalars():
    from lmi_suspension.mu.bounds import _ab13md_blocks

    nblock, itype = _ab13md_blocks(BlockStructure.coerce([[-1, 0], [1, 0], [2, 2]]))
    assert nblock.tolist() == [1, 1, 2] and itype.tolist() == [1, 2, 2]
    assert _ab13md_blocks(BlockStructure.coerce([[1, 2], [2, 1]])) is None   # 1 x 2 full
    assert _ab13md_blocks(BlockStructure.coerce([[-2, 0], [1, 1]])) is None  # repeated
    assert _ab13md_blocks(BlockStructure.coerce([[2, 0], [1, 1]])) is None   # repeated


def test_auto_leaves_a_lone_real_scalar_to_the_lmi():
    """µ of one real scalar is 0 where M has no real eigenvalue, which no finite
    scaling certifies: "auto" keeps the LMI (and the exact lower bound) there."""
    assert mussv(np.array([[1 + 1j]]), [[-1, 0]]).method == "lmi"


def test_ab13md_refuses_structures_it_does_not_take():
    pytest.importorskip("slycot")
    rng = np.random.default_rng(32)
    with pytest.raises(InputError, match="ab13md"):
        mussv(crandn(rng, 3, 3), [[-2, 0], [1, 1]], method="ab13md")   # repeated real
    with pytest.raises(InputError, match="ab13md"):
        mussv(crandn(rng, 3, 2), [[1, 2], [1, 1]], method="ab13md")    # 1 × 2 full block


@pytest.mark.parametrize("failure", ["raises", "claims too little", "D varies in a block"])
def test_ab13md_failure_falls_back_to_the_lmi(monkeypatch, caplog, failure):
    """An injected AB13MD failure (an exception, a value its scalings do not certify, or
    scalings outside the structure) gives the LMI's bound at that frequency, and says
    so."""
    slycot = pytest.importorskip("slycot")
    real = slycot.ab13md

    def broken(Z, nblock, itype, *args):
        if failure == "raises":
            raise slycot.exceptions.SlycotArithmeticError("injected", 5)
        bound, d, g, x = real(Z, nblock, itype, *args)
        if failure == "D varies in a block":
            d = np.array(d, dtype=float)
            # inside the 2 x 2 full block (rows 2 and 3), too little for the
            # certificate to notice: only the structure check refuses it
            d[2] *= 1.0 + 1e-7
            return bound, d, g, x
        return 0.5 * bound, d, g, x

    monkeypatch.setattr(slycot, "ab13md", broken)
    rng = np.random.default_rng(33)
    blk = [[-1, 0], [1, 1], [2, 2]]
    M = crandn(rng, 4, 4)
    with caplog.at_level("INFO", logger="lmi_suspension.mu.bounds"):
        res = mussv(M, blk, method="ab13md")
    lmi = mussv(M, blk, method="lmi")
    assert res.upper == pytest.approx(lmi.upper, rel=1e-9)
    assert lmi_certified_bound(M, res) <= res.upper * (1 + 1e-9)
    assert "LMI bound was used there" in caplog.text


def test_ab13md_warm_start_has_slycots_layout():
    """The warm start built from one log scaling per block is what AB13MD itself
    returns as ``x`` after a cold call (its D part: squared scalings relative to the
    first block), from the D that call returned."""
    slycot = pytest.importorskip("slycot")
    from lmi_suspension.mu.bounds import _ab13md_x0

    nblock, itype = np.array([1, 1, 2, 1, 1]), np.array([1, 1, 2, 2, 2])
    _, d, _, x = slycot.ab13md(AB13MD_Z, nblock, itype)
    starts = np.cumsum(nblock) - nblock
    x0 = _ab13md_x0(np.log(np.asarray(d)[starts]), itype)
    m = nblock.size
    assert x0.shape == x.shape
    np.testing.assert_allclose(x0[:m - 1], x[:m - 1], rtol=1e-9)
    assert np.all(x0[m - 1:] == 0)


@pytest.mark.parametrize("slow", ["cold call", "every call"])
def test_ab13md_that_does_not_return_is_stopped(monkeypatch, caplog, slow):
    """AB13MD's loops have no iteration bound (one cold call on the seat took 63 s, a
    warm-started one did not return in 300 s).  Injected: AB13MD that sleeps 60 s on a
    cold call (or on every call).  mussv stops it at its limit (here 0.5 s), starts it
    again from the Perron scaling, and past that takes the LMI; either way the bound is
    certified and the call returns in seconds."""
    slycot = pytest.importorskip("slycot")
    import lmi_suspension.mu.bounds as bounds

    real = slycot.ab13md

    def sleepy(Z, nblock, itype, *x):
        if slow == "every call" or not x:
            time.sleep(60.0)
        return real(Z, nblock, itype, *x)

    monkeypatch.setattr(slycot, "ab13md", sleepy)
    monkeypatch.setattr(bounds, "_AB13MD_SECONDS", 0.5)
    M = AB13MD_Z
    t0 = time.perf_counter()
    with caplog.at_level("INFO", logger="lmi_suspension.mu.bounds"):
        res = mussv(M, AB13MD_BLK, method="ab13md")
    assert time.perf_counter() - t0 < 20.0
    assert "did not return within 0.5 s" in caplog.text
    assert lmi_certified_bound(M, res) <= res.upper * (1 + 1e-9)
    if slow == "cold call":
        # the warm start reaches SLICOT's documented value as well
        assert res.upper == pytest.approx(AB13MD_BOUND, rel=1e-6)
        assert "LMI bound was used" not in caplog.text
    else:
        assert res.upper == pytest.approx(mussv(M, AB13MD_BLK, method="lmi").upper, rel=1e-9)
        assert "LMI bound was used there" in caplog.text


# ------------------------------------------------------------------ real blocks
def test_single_repeated_real_scalar_is_largest_real_eigenvalue():
    rng = np.random.default_rng(19)
    T = crandn(rng, 4, 4)
    lam = np.array([2.5, -1.0, 0.5 + 3j, 0.5 - 3j])  # |complex| > 2.5: ρ is not µ here
    M = T @ np.diag(lam) @ np.linalg.inv(T)
    res = mussv(M, [[-4, 0]])
    assert res.lower == pytest.approx(2.5, rel=1e-10)
    assert res.upper == pytest.approx(2.5, rel=1e-5)
    assert_lower_certified(M, res)


def test_single_repeated_real_scalar_no_real_eigenvalue_gives_zero():
    rng = np.random.default_rng(20)
    T = crandn(rng, 3, 3)
    M = T @ np.diag([1 + 1j, -2 + 0.5j, 3j]) @ np.linalg.inv(T)
    res = mussv(M, [[-3, 0]])
    assert res.lower == 0.0
    assert res.upper <= 1e-6 * np.linalg.norm(M, 2)


@pytest.mark.parametrize("m,expected", [(2.0, 2.0), (-3.0, 3.0), (1 + 1j, 0.0)])
def test_scalar_real_block(m, expected):
    res = mussv(np.array([[m]]), [[-1, 0]])
    assert res.lower == pytest.approx(expected, abs=1e-9)
    assert res.upper == pytest.approx(expected, abs=1e-6)


def _seat_matrix(name):
    """A matrix of the seat's mixed-µ loop and its structure (tests/data: where it came
    from is written in the file)."""
    import json
    from pathlib import Path

    data = json.loads((Path(__file__).parent / "data" / "seat_mixed_mu_matrices.json")
                      .read_text())
    m = data["matrices"][name]
    return np.array(m["re"]) + 1j * np.array(m["im"]), data["blk"]


@pytest.mark.slow
def test_lmi_bound_resolves_scalings_that_span_many_decades():
    """On this matrix of the seat's loop the scalings that certify a bound near µ span
    more than 13 decades.  The margin problem alone stalled at 1.20 (its margin is
    measured against X_R ⪯ I, so those scalings' margin is below the solver's
    tolerance), and SLICOT's AB13MD stops at 0.901 (computed here).  Passes in the
    frame of the previous scalings reach 0.408 (measured 2026-11-28, Haswell) against
    a lower bound of 0.400 (M[1, 1] ≈ -0.4 is real to 1e-6: a real parameter's own loop);
    0.5 leaves room for other paths and kernels, and both 0.901 and 1.20 fail it."""
    slycot = pytest.importorskip("slycot")
    M, blk = _seat_matrix("b")
    ab_bound, *_ = slycot.ab13md(M, np.ones(8, dtype=int), np.array([2] + [1] * 7))
    assert ab_bound > 0.9
    res = mussv(M, blk, method="lmi", rng=np.random.default_rng(0))
    assert lmi_certified_bound(M, res) <= res.upper * (1 + 1e-9)
    assert_lower_certified(M, res)
    assert 0.39 < res.lower <= res.upper < 0.5


def test_lmi_margin_problem_retries_a_failed_solve(monkeypatch):
    """A margin problem whose solve fails at the default regularisation (injected here;
    on the seat's matrices Clarabel's factorisation failed at its first step) is solved
    again with more, and the bound is the one of an undisturbed run."""
    import cvxpy as cp

    rng = np.random.default_rng(21)
    blk = [[-1, 0], [2, 0], [1, 1]]
    M = crandn(rng, 4, 4)
    clean = mussv(M, blk, method="lmi", rng=np.random.default_rng(0))
    calls = []
    solve = cp.Problem.solve

    def flaky(self, *args, **kwargs):
        calls.append(kwargs.get("static_regularization_constant"))
        if calls[-1] is None:
            raise cp.error.SolverError("injected: factorisation failed")
        return solve(self, *args, **kwargs)

    monkeypatch.setattr(cp.Problem, "solve", flaky)
    res = mussv(M, blk, method="lmi", rng=np.random.default_rng(0))
    assert None in calls and 1e-7 in calls
    assert lmi_certified_bound(M, res) <= res.upper * (1 + 1e-9)
    assert res.upper == pytest.approx(clean.upper, rel=1e-5)


def test_mixed_bounds_ordered_and_certified():
    rng = np.random.default_rng(21)
    blk = [[-1, 0], [2, 0], [1, 1]]
    for _ in range(2):
        M = crandn(rng, 4, 4)
        res = mussv(M, blk, rng=rng)
        complex_mu = mussv(M, [[1, 0], [2, 0], [1, 1]])  # real ⊂ complex: µ_mixed ≤ µ_complex
        assert res.lower <= res.upper <= complex_mu.upper * (1 + 1e-6)
        assert lmi_certified_bound(M, res) <= res.upper * (1 + 1e-9)
        assert_lower_certified(M, res)


# ------------------------------------------------------------------ frequency sweeps
def _sweep(nf=7):
    rng = np.random.default_rng(22)
    A = rng.standard_normal((5, 5))
    A -= (np.max(np.linalg.eigvals(A).real) + 0.5) * np.eye(5)
    sys = control.ss(A, rng.standard_normal((5, 4)), rng.standard_normal((4, 5)), 0.3 * rng.standard_normal((4, 4)))
    w = np.logspace(-1, 1, nf)
    return sys, w


def test_stack_and_frd_inputs_agree():
    sys, w = _sweep()
    blk = [[2, 2], [1, 1], [1, 1]]
    stack = sys(1j * w)
    r_stack = mussv(stack, blk, omega=w)
    r_frd = mussv(control.frd(sys, w), blk)
    np.testing.assert_allclose(r_frd.upper, r_stack.upper, rtol=1e-12)
    np.testing.assert_allclose(r_frd.omega, w)
    assert r_stack.upper.shape == (w.size,) and r_stack.D_left.shape == (4, 4, w.size)
    assert r_stack.d_blocks.shape == (3, w.size)
    np.testing.assert_allclose(r_stack.d_blocks[-1], 1.0)  # normalised on the last full block
    k = int(np.argmax(r_stack.upper))
    assert r_stack.peak == r_stack.upper[k] and r_stack.peak_omega == w[k]
    # each frequency equals a separate single-matrix call (warm starts change nothing)
    for k in (0, w.size - 1):
        single = mussv(stack[:, :, k], blk)
        assert single.upper == pytest.approx(r_stack.upper[k], rel=1e-6)
        DL, DR = r_stack.D_left[:, :, k], r_stack.D_right[:, :, k]
        assert np.linalg.norm(DL @ stack[:, :, k] @ np.linalg.inv(DR), 2) <= r_stack.upper[k] * (1 + 1e-9)


@pytest.mark.parametrize("blk", [[[2, 2], [2, 2], [2, 2]], [[1, 1]] * 4 + [[2, 2]], [[1, 1]] * 6])
def test_frequency_sweep_lower_bound(blk):
    """The lower bound of a sweep runs on all frequencies at once (full blocks).

    Checked at every frequency: its Δ is structured and destabilising with
    lower = 1/σ̄(Δ) (recomputed with numpy); for three full blocks it meets the upper
    bound (Doyle 1982); and it is never below the one-frequency-at-a-time power
    iteration warm-started along the sweep (the route used for other structures).
    """
    rng = np.random.default_rng(31)
    A = rng.standard_normal((6, 6))
    A -= (np.max(np.linalg.eigvals(A).real) + 0.3) * np.eye(6)
    sys = control.ss(A, rng.standard_normal((6, 6)), rng.standard_normal((6, 6)),
                     0.3 * rng.standard_normal((6, 6)))
    w = np.logspace(-2, 2, 60)
    stack = sys(1j * w)
    res = mussv(stack, blk, omega=w)
    struct = BlockStructure.coerce(blk)
    seq, starts, opts, g = np.zeros(w.size), [], MussvOptions(), np.random.default_rng(0)
    for k in range(w.size):
        seq[k], _, vecs = _power_lower(stack[:, :, k], struct, g, starts, opts, res.upper[k])
        starts = [vecs] if vecs is not None else starts
        one = MussvResult(upper=res.upper[k], lower=res.lower[k], omega=None,
                          D_left=None, D_right=None, G=None, d_blocks=None,
                          delta=res.delta[:, :, k], peak=None, peak_omega=None, blk=struct,
                          method=res.method, timings=None)
        assert_lower_certified(stack[:, :, k], one)
    assert np.all(res.lower <= res.upper)
    assert np.all(res.lower >= seq * (1 - 1e-9))
    if len(blk) <= 3:
        np.testing.assert_allclose(res.lower, res.upper, rtol=1e-6)


def test_result_is_frozen_and_unpacks():
    res = mussv(np.eye(2), [[1, 1], [1, 1]])
    upper, lower = res
    assert isinstance(res, MussvResult) and upper == res.upper and lower == res.lower
    with pytest.raises(AttributeError):
        res.upper = 0.0
    assert res.timings.total >= 0 and res.omega is None and res.peak_omega is None


def test_reproducible_and_no_global_rng_use():
    rng = np.random.default_rng(23)
    M = crandn(rng, 5, 5)
    blk = [[1, 1]] * 5  # > 3 blocks: lower bound depends on the random restarts
    state = np.random.get_state()[1].copy()
    r1 = mussv(M, blk, rng=np.random.default_rng(1))
    r2 = mussv(M, blk, rng=np.random.default_rng(1))
    r3 = mussv(M, blk)
    assert r1.lower == r2.lower and r1.upper == r2.upper
    assert r3.lower <= r3.upper
    np.testing.assert_array_equal(np.random.get_state()[1], state)


def test_does_not_mutate_input():
    M = np.array([[1.0, 2.0], [3.0, 4.0]], dtype=complex)
    copy = M.copy()
    mussv(M, [[1, 1], [1, 1]])
    np.testing.assert_array_equal(M, copy)


def test_zero_matrix():
    res = mussv(np.zeros((2, 2)), [[1, 1], [-1, 0]])
    assert res.upper == 0.0 and res.lower == 0.0


# ------------------------------------------------------------------ errors
def test_blk_not_fitting_M_names_both_sizes():
    with pytest.raises(DimensionError, match=r"3 x 2.*got M of size 2 x 2"):
        mussv(np.eye(2), [[1, 2], [1, 1]])


def test_nan_raises():
    M = np.eye(2)
    M[0, 1] = np.nan
    with pytest.raises(NonFiniteError):
        mussv(M, [[1, 1], [1, 1]])


def test_bad_arguments_raise_typed_errors():
    with pytest.raises(InputError):
        mussv(np.eye(2), [[1, 1], [1, 1]], method="bogus")
    with pytest.raises(InputError, match="fast"):
        mussv(np.eye(2), [[2, 0]], method="fast")
    with pytest.raises(InputError):
        mussv(np.eye(2), [[1, 1], [1, 1]], rng=0)
    with pytest.raises(DimensionError):
        mussv(np.ones((2, 2, 3)), [[1, 1], [1, 1]], omega=[1.0, 2.0])
    with pytest.raises(InputError):
        MussvOptions(rtol=-1.0)


# ------------------------------------------------------------------ plots
def test_plots_return_axes():
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    sys, w = _sweep(5)
    res = mussv(control.frd(sys, w), [[2, 2], [1, 1], [1, 1]])
    fig, (ax1, ax2) = plt.subplots(1, 2)
    assert plot_mu(res, ax=ax1) is ax1
    assert ax1.get_xscale() == "log" and len(ax1.get_lines()) == 2
    np.testing.assert_allclose(ax1.get_lines()[0].get_ydata(), res.upper)
    assert plot_dscales(res, ax=ax2) is ax2 and len(ax2.get_lines()) == 3
    with pytest.raises(InputError):
        plot_mu(mussv(np.eye(2), [[1, 1], [1, 1]]))
    plt.close(fig)
