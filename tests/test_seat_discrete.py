"""The seat designed at 1 kHz (issue 63, item 5): lmi_suspension.seat.discrete_design.

Reference values, each from a route the tested code does not use:
* the continuous loop's delay margin from python-control's ``stability_margins`` (phase
  margin over crossover frequency): the sampled loop with ``k`` samples of delay must turn
  unstable near ``margin / dt`` samples, which the exact integer-delay loops find;
* the discrete design's µ recomputed by ``mussv`` on the sampled closed loop's frequency
  response on the unit circle; its bump response by the sampled-data simulation with the
  exact delay (``seat.sampled.simulate_sampled``), not by the design's model.
"""

import control
import numpy as np
import pytest

from lmi_suspension.errors import ParameterError
from lmi_suspension.io import load_controller
from lmi_suspension.seat.discrete_design import (design_discrete_mu_controller,
                                                 integer_delay_radii,
                                                 sampled_augmented_plant)
from lmi_suspension.seat.model import seat_model
from lmi_suspension.seat.sampled import discretise_controller

DT = 1e-3


def _shipped(name="mu_refined"):
    from importlib import resources
    path = resources.files("lmi_suspension").joinpath("seat", "data", f"{name}.json")
    return load_controller(path)[0]


def test_integer_delays_turn_the_loop_unstable_at_the_continuous_delay_margin():
    K = _shipped()
    G = seat_model()
    Gyu = control.ss(G.A, G.B[:, 1:], G.C[3:5], np.zeros((2, 1)))
    # the loop at the force, u -> u, is K G (u = K y); python-control wants -L
    L = -control.series(Gyu, control.ss(K.A, K.B, K.C, K.D))
    _, pm, _, _, wgc, _ = control.stability_margins(L, returnall=True)
    # the delay the loop tolerates: the least phase margin over its gain crossover
    margin = min(np.deg2rad(p) % (2 * np.pi) / w for p, w in zip(pm, wgc))
    k_margin = margin / DT
    Kd = discretise_controller(K, DT)
    below, above = integer_delay_radii(Kd, [int(0.95 * k_margin), int(1.05 * k_margin) + 1])
    # a 5 % band: the hold adds half a sample and Tustin warps the controller slightly
    assert below < 1 < above
    # and every delay the board can have, 0-25 samples, is stable
    assert integer_delay_radii(Kd, np.arange(26)).max() < 1


def test_integer_delay_radii_refuse_what_is_not_a_whole_sample():
    Kd = control.ss([], [], [], [[0.0, 0.0]], DT)
    with pytest.raises(ParameterError):
        integer_delay_radii(Kd, [0.5])
    with pytest.raises(ParameterError):
        integer_delay_radii(control.ss([], [], [], [[0.0, 0.0]]), [1])
    P = sampled_augmented_plant(DT)
    assert P.P.dt == DT and P.P.nstates == sampled_augmented_plant(DT).P.nstates


@pytest.mark.slow  # 31 s on Zen 1 under Sandybridge (2026-12-02): the second tier
def test_the_seat_designed_at_1_khz():
    from lmi_suspension.lti import freqresp, lft
    from lmi_suspension.mu import mussv
    from lmi_suspension.seat.roads import bump
    from lmi_suspension.seat.sampled import simulate_sampled

    d = design_discrete_mu_controller(DT)
    assert d.K.dt == DT
    # µ recomputed on the sampled loop, on the unit circle
    CL = lft(d.aug.P, d.K, d.aug.nmeas, d.aug.ncon)
    w = np.linspace(0.1, 0.999 * np.pi / DT, 1500)
    mu = mussv(freqresp(CL, w), d.aug.blk)
    assert np.max(mu.upper) <= d.mu_peak * (1 + 1e-3)
    # measured 0.8698 (the continuous design Tustin-sampled: 0.9211 on the same plant)
    assert d.mu_peak < 1
    # stable at every whole-sample delay 0-25 ms, exactly
    assert len(d.delay_radii) == 26 and max(d.delay_radii) < 1
    # and the sampled-data loop on the bump with the exact delay stays stable
    for delay in (0.0, 0.025):
        assert simulate_sampled(d.K, bump(), delay=delay).stable


def test_the_shipped_1_khz_design_is_discrete_first_and_certified():
    from lmi_suspension.lti import freqresp, lft, tustin
    from lmi_suspension.mu import mussv
    from lmi_suspension.seat.routes import load_seat_design, route_named

    d = load_seat_design("discrete")
    assert d.primary == "discrete" and d.Kd.dt == DT
    assert route_named("discrete").name == "discrete"
    # K is the bilinear image of Kd: its Tustin map gives Kd back
    back = tustin(d.K, DT)
    z = np.exp(1j * np.array([0.3, 30.0, 3000.0]) * DT)
    np.testing.assert_allclose(np.asarray(back(z)), np.asarray(d.Kd(z)), rtol=1e-9)
    # µ of the sampled loop recomputed on the unit circle: the file's figure (0.8698)
    P = sampled_augmented_plant(DT)
    CL = lft(P.P, d.Kd, P.nmeas, P.ncon)
    w = np.geomspace(0.1, 0.999 * np.pi / DT, 400)
    mu = mussv(freqresp(CL, w), P.blk)
    assert np.max(mu.upper) <= d.figures["mu_peak_upper"] * (1 + 1e-3) < 1
    # every whole-sample delay 0-25 ms, exactly
    assert integer_delay_radii(d.Kd, np.arange(26)).max() < 1
