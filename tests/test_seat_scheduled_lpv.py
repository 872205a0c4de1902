"""The seat scheduled on the occupant mass by D-K around lpvsyn (issue 62, item 2, the
convex route): lmi_suspension/seat/scheduled_lpv.py."""

import json
import time
from dataclasses import replace

import control
import numpy as np
import pytest

from lmi_suspension.errors import ParameterError
from lmi_suspension.io import (
    load_controller,
    load_scheduled_controller,
    save_scheduled_controller,
)
from lmi_suspension.lti import freqresp, lft
from lmi_suspension.seat.params import SeatParameters
from lmi_suspension.seat.loop import loop_poles
from lmi_suspension.seat.scheduled_lpv import (
    SCHEDULED_DESIGN,
    SHIPPED_SCHEDULED,
    _balancing,
    _dstep,
    _fastest,
    _ScaledPlant,
    _within_radius,
    design_lpv_seat_controller,
    load_scheduled_seat,
    named_controller,
    scheduled_seat_plant,
)
from lmi_suspension.seat.simulate import closed_loop_stable

#: a reduced problem for the first tier: the delay cover of order 1, no floor-velocity
#: shaping, no element channels (10 states against the real design's 15)
SMALL = replace(SCHEDULED_DESIGN, include_parametric=False, delay_order=1, w_corner=None,
                w_rolloff=None)
REFINED = SHIPPED_SCHEDULED.parent / "mu_refined.json"


def test_dstep_reaches_the_closed_form_optimum():
    # M = [[0, b], [c, 0]] with a 1x1 uncertainty block and the performance block:
    # D M D^-1 = [[0, d b], [c / d, 0]], whose largest singular value max(d|b|, |c|/d)
    # is least, sqrt(|b c|), at d = sqrt(|c| / |b|) (by hand)
    b, c = 0.3, 12.0
    M = np.array([[[0.0, b], [c, 0.0]]] * 3, dtype=complex)
    x, f = _dstep([M], ([1], [1]), np.zeros(1))
    assert f == pytest.approx(np.sqrt(b * c), rel=1e-6)
    assert x[0] == pytest.approx(0.5 * np.log(c / b), abs=1e-3)


def test_scaled_plant_is_the_d_scaled_loop_in_fixed_coordinates():
    # the scaled plant's loop against the unscaled loop's response scaled by hand, with
    # log d interpolated linearly between the design masses by hand
    grid = np.array([30.0, 50.0, 70.0])
    logd = np.array([[0.5], [1.5], [-1.0]])
    T = _balancing(scheduled_seat_plant(50.0, SMALL).P)
    plant = _ScaledPlant(SMALL, None, grid, logd, T)
    K, _ = load_controller(REFINED)
    Kp = control.ss(K.A, K.B, K.C, K.D)
    omega = np.logspace(-1, 3, 25)
    m3 = 42.0
    d = np.exp(0.5 + (42.0 - 30.0) / 20.0 * 1.0)
    aug = scheduled_seat_plant(m3, SMALL)
    M = freqresp(lft(aug.P, Kp, 2, 1), omega)
    M[0, :, :] *= d
    M[:, 0, :] /= d
    Ms = freqresp(lft(plant(m3), Kp, 2, 1), omega)
    assert np.allclose(Ms, M, rtol=1e-8, atol=1e-10 * np.abs(M).max())


def test_typed_errors_are_quick():
    t0 = time.perf_counter()
    with pytest.raises(ParameterError, match="m3_range"):
        scheduled_seat_plant(42.0, replace(SCHEDULED_DESIGN, m3_range=(30.0, 70.0)))
    with pytest.raises(ParameterError, match="m3"):
        scheduled_seat_plant(-1.0)
    with pytest.raises(ParameterError, match="dscales"):
        design_lpv_seat_controller(SMALL, dscales="diagonal")
    with pytest.raises(ParameterError, match="grid"):
        design_lpv_seat_controller(SMALL, grid=[50.0])
    with pytest.raises(ParameterError, match="iterations"):
        design_lpv_seat_controller(SMALL, iterations=0)
    assert time.perf_counter() - t0 < 1.0


def _check_certificate(d, masses):
    """Every frozen loop at ``masses`` stable by the seat's own closed-loop poles, and
    the certified scaled norm re-computed by SLICOT's AB13DD (python-control's
    ``linfnorm``), not by this project's hinfnorm."""
    check = np.asarray(d.lpv.check_grid["m3"])
    for m in masses:
        K = named_controller(d.K, m)
        assert np.max(loop_poles(K, SeatParameters(m3=m)).real) < 0
        k = int(np.argmin(np.abs(check - m)))
        assert check[k] == m
        Ps = d.K.plant(m)
        CL = lft(Ps, control.ss(K.A, K.B, K.C, K.D), 2, 1)
        assert np.max(np.linalg.eigvals(CL.A).real) < 0
        peak, _ = control.linfnorm(CL)
        # AB13DD's own tolerance is 1e-10 relative; hinfnorm's 1e-9
        assert d.lpv.gamma_check[k] == pytest.approx(peak, rel=1e-6)
        assert peak <= d.lpv.gamma * (1 + 1e-6)


@pytest.fixture(scope="module")
def small():
    # 2 design masses, a constant pair X, Y (basis [1]) and one LPV step: 8-12 s
    return design_lpv_seat_controller(SMALL, grid=[40.0, 60.0], iterations=1,
                                      basis=lambda m3: [1.0], backoff=0.1)


def test_small_design_is_certified_by_independent_routes(small):
    d = small
    assert d.lpv.warnings == ()
    assert d.logd.shape == (2, 1) and np.all(np.isfinite(d.logd))
    _check_certificate(d, d.lpv.check_grid["m3"])
    # the level the controllers were formed at bounds every certified norm
    assert d.gamma <= d.lpv.gamma_lmi * 1.1 * (1 + 1e-6)


def test_a_larger_backoff_slows_the_poles_and_is_certified_anew(small):
    masses = [float(m) for m in small.lpv.check_grid["m3"]]
    assert _within_radius(small.lpv, 1e12, 0.1) is small.lpv
    f10 = _fastest(small.K, masses)
    f15 = _fastest(replace(small.K, backoff=0.15), masses)
    assert f15 < f10          # poles grow like 1/backoff (lpvsyn's BACKOFF docstring)
    res = _within_radius(small.lpv, 0.5 * (f10 + f15), 0.1)
    assert res.K.backoff == 0.15
    # certified anew: the norms at the new level, by SLICOT's AB13DD
    for k, m in enumerate(masses):
        Km = res.K.at(m3=m)
        CL = lft(res.K.plant(m), control.ss(Km.A, Km.B, Km.C, Km.D), 2, 1)
        assert res.gamma_check[k] == pytest.approx(control.linfnorm(CL)[0], rel=1e-6)
    assert np.all(res.inequality_check < 0)


def test_shipped_design_is_certified_and_stable(tmp_path):
    # 1-2 s: the shipped file's controllers at its 17 check masses
    K, meta = load_scheduled_seat()
    check = np.asarray(meta["check_grid"])
    for k, m in enumerate(check):
        Km = named_controller(K, m)
        seat = SeatParameters(m3=float(m))
        assert np.max(loop_poles(Km, seat).real) < 0
        assert closed_loop_stable(Km, 0.025, seat)
        CL = lft(K.plant(m), control.ss(Km.A, Km.B, Km.C, Km.D), 2, 1)
        # the saved certificate re-computed by SLICOT's AB13DD
        assert control.linfnorm(CL)[0] == pytest.approx(meta["gamma_check"][k], rel=1e-6)
    # the file's own round trip: loaded, saved again, loaded: the same numbers
    path = save_scheduled_controller(tmp_path / "again.json", K, metadata=meta)
    K2, _ = load_scheduled_controller(path)
    for m in check:
        a, b = K.at(m3=m), K2.at(m3=m)
        for x, y in zip((a.A, a.B, a.C, a.D), (b.A, b.B, b.C, b.D)):
            assert np.array_equal(x, y)
    assert json.loads(path.read_text())["metadata"]["gamma"] == meta["gamma"]
