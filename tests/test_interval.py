"""µ upper bounds over frequency intervals (mu/interval.py)."""

import control
import numpy as np
import pytest
import scipy.optimize

from lmi_suspension.lti.norms import freqresp
from lmi_suspension.mu import interval_bound, mussv
from lmi_suspension.mu.interval import _Loop, _scalings


def _resonant(zeta):
    return control.ss(control.tf([1.0], [1.0, 2 * zeta, 1.0]))


def test_peak_between_grid_points_is_found():
    """One full block: µ = |M|.  For 1/(s² + 2ζs + 1) the peak is 1/(2ζ√(1-ζ²))
    (closed form) at ω = √(1-2ζ²); a grid that misses it reads 5.24 here."""
    zeta = 0.01
    M = _resonant(zeta)
    w = np.array([0.1, 0.5, 0.9, 1.2, 2.0, 10.0])
    mu = mussv(freqresp(M, w), [[1, 1]], omega=w)
    assert np.max(mu.upper) < 6.0
    cert = interval_bound(M, mu, w, rtol=1e-6)
    exact = 1.0 / (2 * zeta * np.sqrt(1 - zeta**2))
    assert cert.bound == pytest.approx(exact, rel=1e-5)
    assert cert.bound >= exact * (1 - 1e-9)  # a bound, never below the supremum
    assert 0.9 <= cert.omega <= 1.2
    assert cert.splits > 0 and cert.edges[0] == 0 and np.isinf(cert.edges[-1])
    assert set(w) <= set(cert.edges)


def test_grid_peak_is_kept_where_the_grid_scalings_certify_every_interval():
    """A well-damped loop on a dense grid: the bound is the grid's peak times 1 + rtol,
    with no split."""
    M = _resonant(0.7)
    w = np.logspace(-2, 2, 200)
    mu = mussv(freqresp(M, w), [[1, 1]], omega=w)
    cert = interval_bound(M, mu, w, rtol=1e-5)
    peak = float(np.max(mu.upper))
    assert cert.bound == pytest.approx(peak * (1 + 1e-5), rel=1e-12) and cert.splits == 0
    # independent: |M(jω)| sampled on a 20 000-point grid never exceeds the bound
    fine = np.logspace(-4, 4, 20000)
    assert np.max(np.abs(freqresp(M, fine)[0, 0])) <= cert.bound


def _mixed_loop():
    """A 3-state loop with a real scalar and a full complex block, drawn with a seeded
    generator; its µ peak sits between the points of a coarse grid."""
    rng = np.random.default_rng(7)
    A = np.diag([-0.05, -0.3, -2.0]) + np.array([[0, 1.0, 0], [-1.0, 0, 0], [0, 0, 0]])
    B = rng.standard_normal((3, 2))
    C = rng.standard_normal((2, 3))
    D = 0.1 * rng.standard_normal((2, 2))
    return control.ss(A, B, C, D), [[-1, 0], [1, 1]]


def test_hamiltonian_crossings_are_where_the_pointwise_level_crosses():
    """The KYP Hamiltonian of fixed (D, G) scalings has an eigenvalue jω exactly where
    the pointwise level (a generalized eigenvalue problem at that ω, no Hamiltonian)
    equals β: the crossings found by brentq on the pointwise level are eigenvalues."""
    M, blk = _mixed_loop()
    w0 = np.array([1.0])
    mu = mussv(freqresp(M, w0), blk, omega=w0, method="lmi")
    loop = _Loop(M)
    scal = _scalings(mu, 0)
    assert np.any(np.abs(scal[2]) > 0)  # a real block: G is not zero
    grid = np.logspace(-2, 2, 4000)
    lv = np.array([loop.level(x, scal) for x in grid])
    beta = 0.5 * (np.max(lv) + np.min(lv))
    sign = np.sign(lv - beta)
    idx = np.flatnonzero(sign[:-1] != sign[1:])
    assert idx.size >= 2
    ev = np.linalg.eigvals(loop.hamiltonian(beta, scal))
    for i in idx:
        wc = scipy.optimize.brentq(lambda x: loop.level(x, scal) - beta, grid[i], grid[i + 1],
                                   xtol=1e-14)
        assert np.min(np.abs(ev - 1j * wc)) <= 1e-6 * max(1.0, wc)


@pytest.mark.slow  # 21 s on Zen 1 (2026-12-02): the second tier
def test_mixed_bound_holds_between_grid_points():
    """Every pointwise LMI upper bound (the optimum over scalings at that ω) is at most
    the certified level: the interval's fixed scalings are feasible there.  And every
    lower bound (an explicit destabilising Δ) is below it."""
    M, blk = _mixed_loop()
    w = np.logspace(-2, 2, 8)  # no point at the resonance near 1 rad/s
    mu = mussv(freqresp(M, w), blk, omega=w, method="lmi")
    cert = interval_bound(M, mu, w, rtol=1e-6)
    fine = np.logspace(-2, 2, 161)
    dense = mussv(freqresp(M, fine), blk, omega=fine, method="lmi")
    assert np.max(dense.lower) <= cert.bound * (1 + 1e-9)
    assert np.max(dense.upper) <= cert.bound * (1 + 1e-5)  # the LMI's rtol is 1e-6
    assert cert.bound > np.max(mu.upper) * 1.01  # the coarse grid misses the peak


def test_bad_rtol_is_refused():
    from lmi_suspension.errors import ParameterError

    M = _resonant(0.7)
    w = np.logspace(-1, 1, 5)
    mu = mussv(freqresp(M, w), [[1, 1]], omega=w)
    for bad in (0.0, -1e-3, float("nan")):
        with pytest.raises(ParameterError):
            interval_bound(M, mu, w, rtol=bad)
