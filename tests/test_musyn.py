"""µ-synthesis by D-K iteration (musyn)."""

import dataclasses

import control
import numpy as np
import pytest

from lmi_suspension.errors import AssumptionError, DimensionError, ParameterError
from lmi_suspension.examples import skogestad_distillation
from lmi_suspension.lti import lft
from lmi_suspension.mu import MusynOptions, mussv, musyn
from lmi_suspension.synthesis import hinfsyn


@pytest.fixture(scope="module")
def distillation_design():
    ex = skogestad_distillation()
    records = []
    omega = np.logspace(-3, 3, 61)  # the grid of dkpy's example of the same problem
    res = musyn(ex.P, ex.nmeas, ex.ncon, ex.blk, omega=omega,
                options=MusynOptions(max_iter=3, method="riccati"),
                callback=records.append)
    return ex, res, records


@pytest.mark.slow
def test_distillation_improves_on_the_open_source_plateau(distillation_design):
    """Skogestad & Postlethwaite (2005), Sec. 8.12.4, Table 8.1 problem.

    References: the first K-step is the plain H∞ problem, whose optimum S&P report as
    γ ≈ 1.18; MATLAB's musyn brings µ below 1, the open-source peer (dkpy) stalls near
    1.04 (both as quoted in this project's issue #5).  Measured here: 1.1792 after the
    first iteration, 1.0291 after three.  The MATLAB level is NOT reached yet: the K-step
    on the D-scaled plant (a weight pole at -1e-6 rad/s) is where both of our routes lose
    accuracy; this test pins what is achieved so that regressions show.
    """
    ex, res, _ = distillation_design
    assert res.history[0].mu_peak == pytest.approx(1.18, rel=0.01)
    assert res.mu_peak < 1.04
    # lower <= upper everywhere, and for three complex full blocks µ's upper bound is
    # tight, so the two bounds agree closely at the peak (independent certificate).
    assert np.all(res.mu.lower <= res.mu.upper * (1 + 1e-9))
    assert res.mu_lower_peak >= 0.97 * res.mu_peak
    # The returned closed loop is lft(P, K) and stable.
    np.testing.assert_allclose(res.CL(1j * 0.3), lft(ex.P, res.K)(1j * 0.3), rtol=1e-9)
    assert np.all(res.CL.poles().real < 0)


@pytest.mark.slow
def test_history_and_best_iterate(distillation_design):
    _, res, records = distillation_design
    assert list(records) == list(res.history)  # the callback saw every iteration
    peaks = [h.mu_peak for h in res.history]
    assert res.best_iteration == int(np.argmin(peaks)) + 1
    assert all(h.seconds_k > 0 and h.seconds_d > 0 for h in res.history)
    # For a stable, minimum-phase D fit the certified γ of the scaled loop bounds µ at
    # every frequency, so it is never below the grid peak of the next D-step.
    for h in res.history:
        assert h.gamma >= h.mu_peak * (1 - 1e-3)
    # The dense-grid peak of the returned controller is close to its design-grid peak
    assert res.mu_peak >= peaks[res.best_iteration - 1] * (1 - 1e-6)
    assert res.mu_peak <= peaks[res.best_iteration - 1] * 1.05
    K, CL, mu_peak, info = res
    assert info is res and mu_peak == res.mu_peak


def singular_plant():
    """SISO plant 1/(s+1) with input multiplicative uncertainty 0.2 and a noise-free
    measurement y = G (u + u_del): D21 = 0, so the Riccati assumptions fail."""
    G = control.ss(control.tf([1], [1, 1]))
    wp = control.ss(control.tf([0.5, 0.5], [1, 0.01]))
    # inputs [u_del, w, u] outputs [y_del, z, y]
    A = np.block([[G.A, np.zeros((1, 1))], [wp.B @ G.C, wp.A]])
    B = np.block([[G.B, np.zeros((1, 1)), G.B], [np.zeros((1, 1)), wp.B, np.zeros((1, 1))]])
    C = np.block([[np.zeros((1, 2))], [wp.D @ G.C, wp.C], [G.C, np.zeros((1, 1))]])
    D = np.array([[0.0, 0.0, 0.2], [0.0, wp.D[0, 0], 0.0], [0.0, 0.0, 0.0]])
    return control.ss(A, B, C, D)


def test_singular_k_step_needs_the_lmi():
    P = singular_plant()
    with pytest.raises(AssumptionError):
        hinfsyn(P, 1, 1, method="riccati")
    # "best" tries both routes each K-step; Riccati fails here, so the LMI carries it.
    res = musyn(P, 1, 1, [[1, 1], [1, 1]], omega=np.logspace(-3, 3, 40),
                options=MusynOptions(max_iter=3, method="best"))
    assert np.all(res.CL.poles().real < 0)
    assert res.mu_lower_peak <= res.mu_peak
    # independent check of the reported peak: mussv on the returned closed loop
    w = res.peak_omega
    again = mussv(res.CL(1j * w), [[1, 1], [1, 1]])
    assert again.upper == pytest.approx(res.mu_peak, rel=1e-3)


def test_blk_must_fit_the_plant():
    ex = skogestad_distillation()
    with pytest.raises(DimensionError, match="block structure"):
        musyn(ex.P, ex.nmeas, ex.ncon, [[1, 1], [2, 2]])


def test_options_are_validated_and_frozen():
    with pytest.raises(ParameterError):
        MusynOptions(max_iter=0)
    with pytest.raises(ParameterError):
        MusynOptions(method="newton")
    opts = MusynOptions()
    with pytest.raises(dataclasses.FrozenInstanceError):
        opts.max_iter = 3
