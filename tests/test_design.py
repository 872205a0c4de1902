"""Tests of the robust seat design (lmi_suspension.seat.design).

The design runs once per module (D-K iteration, tens of seconds: marked slow). Every
µ figure is checked against a computation that did not produce it: the µ lower bound
(a destabilising perturbation found by power iteration) must not exceed the certified
upper bound, and closed-loop stability with the exact delay (Nyquist, closed_loop_stable)
is cross-checked by the poles of a high-order Padé loop. Time-domain figures come from
the exact-delay simulation (simulate).
"""

import control
import numpy as np
import pytest

from lmi_suspension.seat import (bump, closed_loop_stable, seat_model, simulate,
                                 stability_delay_margin)
from lmi_suspension.seat.augmented import DEFAULT_DESIGN
from lmi_suspension.seat.design import SeatMuDesign, design_mu_controller, design_nominal_hinf

pytestmark = pytest.mark.slow

#: Passive bump peak z̈3, m/s² (simulate(None, bump()), the project's passive reference).
PASSIVE_PEAK = 26.47
#: Physical limit of the bump, m/s²: bump_limit(bump(), dt=2e-3) as reproduce computes it
#: (6.16409; the LP itself is tested in test_limit.py).
BUMP_LIMIT = 6.164


@pytest.fixture(scope="module")
def design():
    return design_mu_controller(rng=np.random.default_rng(0))


@pytest.fixture(scope="module")
def bump_runs(design):
    road = bump()
    return {d: simulate(design.K, road, delay=d).metrics() for d in (0.0, 0.025)}


def test_result_type_and_names(design):
    assert isinstance(design, SeatMuDesign)
    assert design.K.input_labels == ["x1", "x3"]
    assert design.K.output_labels == ["u"]
    # Units: the plant's measurement outputs are x1, x3 in metres and its control is the
    # force in newtons (eq. 1), so the controller's DC gain maps m -> N: an independent
    # check is that K equals the musyn controller on the same plant signals.
    K0 = design.musyn.K
    w = np.array([1.0, 30.0])
    assert np.allclose(design.K(1j * w), K0(1j * w))
    assert design.aug.P.output_labels[-2:] == ["y1", "y2"]
    assert design.aug.P.input_labels[-1] == "u"


def test_mu_bounds_consistent(design):
    # Lower bound (a perturbation that attains it) never exceeds the certified upper bound.
    assert design.mu_lower_peak <= design.mu_peak * (1 + 1e-6)
    assert np.all(design.mu_lower <= design.mu_upper * (1 + 1e-6))
    assert design.mu_peak == pytest.approx(float(np.max(design.mu_upper)))


def test_mu_certified_below_one(design):
    """Issue 6 target: robust performance, µ upper bound < 1 on the dense grid, over the
    synthesised structure (delay cover 0–25 ms + performance block). Measured 2026-11-23:
    0.854 (0.881 and 0.940 with the previous weights). The bound is recomputed here from the
    controller alone (lft + mussv on a grid of 200 points, a route independent of musyn's
    D-K bookkeeping), and the dense grid must reach well beyond the delay's corner
    (1/25 ms = 40 rad/s) on both sides."""
    from lmi_suspension import lft, mussv

    assert design.mu_peak < 1.0
    assert design.omega.min() <= 0.1 and design.omega.max() >= 3000.0
    omega = np.logspace(-1, 3.5, 200)
    M = lft(design.aug.P, design.musyn.K, design.aug.nmeas, design.aug.ncon)(1j * omega)
    again = mussv(M, design.aug.blk, omega=omega, rng=np.random.default_rng(1))
    assert np.max(again.upper) < 1.0
    assert np.max(again.lower) <= np.max(again.upper) * (1 + 1e-6)
    # The design grid's peak is not a grid artefact: both grids agree to 2 %.
    assert np.max(again.upper) == pytest.approx(design.mu_peak, rel=0.02)


def test_robust_performance_with_the_paper_uncertainty(design):
    """µ of the designed controller with the paper's norm-bounded blocks (δ = 0.02) added
    to the delay cover.  Measured 2026-11-23: 0.854 as designed, 0.901 with E_B = 0 (as
    printed), 3.20 with the reconstructed E_B (δ per newton on the seat row, which L1
    spreads onto the occupant's rows too: a direct force path to the body that the
    actuator does not have; not designed for).  Independent checks: each lower bound (a perturbation attaining it) stays below
    its upper bound, and adding blocks can only raise µ."""
    from lmi_suspension.seat.design import analyse_uncertainty

    own, printed, reconstructed = analyse_uncertainty(design.K, rng=np.random.default_rng(2))
    for check in (own, printed, reconstructed):
        assert check.mu_lower_peak <= check.mu_peak * (1 + 1e-6)
    assert own.mu_peak == pytest.approx(design.mu_peak, rel=0.02)
    assert {"nb_AB", "nb_C1", "nb_C3"} <= set(printed.block_names)
    assert own.mu_peak <= printed.mu_peak * (1 + 1e-6) <= reconstructed.mu_peak * (1 + 2e-6)
    # robust performance for every perturbation of the paper's set with E_B as printed
    assert printed.mu_peak < 1.0


def _pade_loop_poles(K, delay, order=8):
    """Poles of the seat loop with an order-`order` Padé delay: independent of Nyquist."""
    G = seat_model()
    Gyu = control.ss(G.A, G.B[:, 1:], G.C[3:5], G.D[3:5, 1:])  # u -> [y1, y2]
    num, den = control.pade(delay, order) if delay > 0 else ([1.0], [1.0])
    Dly = control.ss(control.tf(num, den))
    Kss = control.ss(K.A, K.B, K.C, K.D)
    L = control.series(Gyu, Kss, Dly)  # SISO loop broken at the force
    # u = K y is fed back without sign change (eq. 1 convention): positive feedback.
    return control.feedback(L, 1, sign=+1).poles()


@pytest.mark.parametrize("delay", [0.0, 0.0125, 0.025])
def test_closed_loop_stable_two_routes(design, delay):
    assert closed_loop_stable(design.K, delay)
    assert np.max(_pade_loop_poles(design.K, delay).real) < 0


def test_delay_margin_beyond_the_interval(design):
    """Stability is kept on the whole interval 0–25 ms and lost at the reported margin
    (measured 2026-11-23: 0.216 s): the margin (crossing analysis) is checked by the
    Nyquist count just below and just above it, an independent route."""
    margin = stability_delay_margin(design.K)
    assert 0.025 < margin < 1.0
    assert closed_loop_stable(design.K, 0.98 * margin)
    assert not closed_loop_stable(design.K, 1.02 * margin)


@pytest.mark.parametrize("delay", [0.0, 0.025])
def test_bump_limits(bump_runs, delay):
    m = bump_runs[delay]
    assert m.stable
    assert m.peak_x1 <= 0.08
    assert m.peak_u <= 1500.0 + 1e-9


def test_nominal_controller_names():
    K = design_nominal_hinf(DEFAULT_DESIGN)
    assert K.input_labels == ["x1", "x3"] and K.output_labels == ["u"]
    assert closed_loop_stable(K, 0.0)


@pytest.mark.parametrize("delay", [0.0, 0.025])
def test_bump_comfort_half_of_passive(bump_runs, delay):
    """Issue 6 target: peak z̈3 on the bump at most half the passive peak (measured
    2026-11-23: 9.07 m/s² at 0 ms, 9.00 m/s² at 25 ms; passive 26.47 from an independent
    simulate(None, bump()) in this test)."""
    passive = simulate(None, bump()).metrics().peak_z3dd
    assert passive == pytest.approx(PASSIVE_PEAK, abs=0.01)
    assert bump_runs[delay].peak_z3dd <= passive / 2


@pytest.mark.parametrize("delay", [0.0, 0.025])
def test_bump_within_one_and_a_half_times_the_physical_limit(bump_runs, delay):
    """Issue 6 target: peak z̈3 on the bump at most 1.5 × the physical limit at the ends
    of the delay interval, where the peak is largest (measured 2026-11-23 with this test's
    step of 0.1 ms: 9.07 m/s² at 0 ms and 9.00 m/s² at 25 ms, i.e. 1.47 and 1.46 × the
    limit; reproduce's 0.2 ms step gives 9.07 and 9.02, and 7.35–8.72 m/s² in between on
    a 2.5 ms grid)."""
    assert bump_runs[delay].peak_z3dd <= 1.5 * BUMP_LIMIT


def test_nominal_hinf_ignoring_the_delay_is_lost_within_the_delay_range():
    # The comparison the paper motivates (a design that ignores the actuator delay): the
    # near-optimal nominal LMI controller is stable without delay but loses stability
    # well inside [0, 25 ms] (measured 2026-11-23: 0.53 ms); checked by the Nyquist count
    # on both sides of its margin, independently of the margin search.
    K = design_nominal_hinf(DEFAULT_DESIGN, method="lmi")
    margin = stability_delay_margin(K)
    assert 0.0 < margin < 0.025
    assert closed_loop_stable(K, 0.0) and closed_loop_stable(K, 0.9 * margin)
    assert not closed_loop_stable(K, 1.1 * margin)
    assert not closed_loop_stable(K, 0.025)
