"""Tests of the seat simulator (exact delay, saturation), delay stability and Monte Carlo."""

import control
import numpy as np
import pytest
from scipy.integrate import solve_ivp

from lmi_suspension.errors import (DimensionError, DiscreteTimeError, NonFiniteError,
                                   ParameterError)
from lmi_suspension.seat.model import seat_matrices, seat_model
from lmi_suspension.seat.params import SeatParameters
from lmi_suspension.seat.roads import RoadInput, bump
from lmi_suspension.seat.simulate import (closed_loop_stable, loop_transfer, monte_carlo,
                                          simulate, simulate_force, stability_delay_margin)

SELECT_X1 = control.ss([], [], [], np.array([[1.0, 0.0]]))


def _on_x1(num, den):
    """A SISO controller acting on y1 = x1 only (test controllers, not designs)."""
    return control.series(SELECT_X1, control.ss(control.tf(num, den)))


# Test controllers: a stiff spring (static), a relative damper with a 1e4 rad/s pole
# (stiff), and an open-loop-unstable lead controller that the loop stabilises (P = 1).
K_SPRING = np.array([[60000.0, 0.0]])
K_DAMPER = _on_x1([2000.0, 0.0], [1e-4, 1.0])
K_UNSTABLE = _on_x1([5e4, 1e6], [1.0, -5.0])


def _pade_max_real_pole(K, d, order=12):
    """Independent route: rightmost closed-loop pole with a high-order Padé delay."""
    L0 = loop_transfer(K)
    if d > 0:
        num, den = control.pade(d, order)
        L0 = control.series(control.ss(control.tf(num, den)), L0)
    return float(np.max(control.feedback(L0, 1, sign=+1).poles().real))


@pytest.fixture(scope="module")
def bump_road():
    return bump(t_end=3.0, dt=1e-4)


@pytest.fixture(scope="module")
def passive(bump_road):
    return simulate(None, bump_road)


def test_passive_bump_is_stable_and_returns_to_rest():
    res = simulate(None, bump(t_end=6.0, dt=1e-3), dt=2e-4)
    assert res.stable
    # The slowest passive pole (from seat_model) sets the decay after the bump ends.
    slowest = np.min(-seat_model().poles().real)
    late = res.t > 5.5
    peak = np.max(np.abs(res.z3dd))
    decay = np.exp(-slowest * (5.5 - 0.24))
    assert decay < 1e-4
    assert np.max(np.abs(res.z3dd[late])) < 10 * decay * peak
    assert np.max(np.abs(res.x[late])) < 10 * decay * np.max(np.abs(res.x))
    assert np.all(res.u_applied == 0) and res.saturated_fraction == 0


def test_passive_matches_control_forced_response(passive, bump_road):
    # Independent route: python-control's own simulation of seat_model (FOH input).
    G = seat_model()
    fr = control.forced_response(G[:, 0], T=bump_road.t, U=bump_road.w)
    out = np.asarray(fr.outputs)
    z3dd = np.interp(bump_road.t, passive.t, passive.z3dd)
    x1 = np.interp(bump_road.t, passive.t, passive.x1)
    assert np.max(np.abs(z3dd - out[0])) < 1e-9 * np.max(np.abs(out[0]))
    assert np.max(np.abs(x1 - out[1])) < 1e-9 * np.max(np.abs(out[1]))
    # 'y2' is the cushion deflection x3 (measurement 2)
    x3 = np.interp(bump_road.t, passive.t, passive.x3)
    assert np.max(np.abs(x3 - out[4])) < 1e-9 * np.max(np.abs(out[4]))


def test_passive_discretisation_error_vs_solve_ivp():
    # Independent route: adaptive RK with tight tolerances on eq. (1) driven by the
    # analytic bump derivative; the simulator only sees w sampled every 1 ms (FOH).
    a, l, V0 = 0.1, 2.0, 30 / 3.6
    T = l / V0

    def w_exact(t):
        return 0.5 * a * 2 * np.pi * V0 / l * np.sin(2 * np.pi * V0 * t / l) if t <= T else 0.0

    M = seat_matrices()
    sol = solve_ivp(lambda t, x: M.A @ x + M.Bw[:, 0] * w_exact(t), (0, 1.5), np.zeros(6),
                    method="DOP853", rtol=1e-11, atol=1e-13, dense_output=True,
                    t_eval=np.arange(0, 1.5, 1e-3), max_step=1e-3)
    z_ref = M.C1 @ sol.y
    res = simulate(None, bump(t_end=1.5, dt=1e-3), dt=1e-4)
    z_sim = np.interp(sol.t, res.t, res.z3dd)
    # FOH of a sine sampled at 1 ms: relative error O((w dt)^2 / 8) ~ 1e-5
    assert np.max(np.abs(z_sim - z_ref.ravel())) < 1e-4 * np.max(np.abs(z_ref))


def test_closed_loop_without_delay_matches_linear_feedback(bump_road):
    # Independent route: the continuous-time closed loop built by control.feedback.
    # Only the zero-order hold of the force differs: error O(h).
    M = seat_matrices()
    # plant with inputs [w, u] and outputs [z3dd, x1, y1, y2]; the loop is u = K y
    P = control.ss(M.A, np.hstack([M.Bw, M.B]), np.vstack([M.C1, M.C2, M.C3]),
                   np.zeros((4, 2)))
    cl = _close_loop(P, K_DAMPER)
    fr = control.forced_response(cl, T=bump_road.t, U=bump_road.w)
    res = simulate(K_DAMPER, bump_road, u_max=np.inf)
    z = np.interp(bump_road.t, res.t, res.z3dd)
    ref = np.asarray(fr.outputs).ravel()
    assert np.max(np.abs(z - ref)) < 5e-3 * np.max(np.abs(ref))
    # and halving the step halves the error (first order in h)
    res2 = simulate(K_DAMPER, bump_road, u_max=np.inf, dt=5e-5)
    z2 = np.interp(bump_road.t, res2.t, res2.z3dd)
    e1, e2 = np.max(np.abs(z - ref)), np.max(np.abs(z2 - ref))
    assert 1.6 < e1 / e2 < 2.4


def _close_loop(P, K):
    """w -> z3dd of P (inputs [w, u], outputs [z3dd, x1, y1, y2]) with u = K [y1, y2]."""
    K = control.ss(K)
    Ap, Bp, Cp = P.A, P.B, P.C
    Cy = Cp[2:4]
    A = np.block([[Ap + Bp[:, 1:2] @ K.D @ Cy, Bp[:, 1:2] @ K.C],
                  [K.B @ Cy, K.A]])
    B = np.vstack([Bp[:, 0:1], np.zeros((K.nstates, 1))])
    C = np.hstack([Cp[0:1], np.zeros((1, K.nstates))])
    return control.ss(A, B, C, 0)


def test_delay_line_is_exact(bump_road):
    d = 0.0123
    res = simulate(np.array([[20000.0, 0.0]]), bump_road, delay=d, u_max=np.inf)
    steps = round(d / res.dt)
    assert steps * res.dt == pytest.approx(d, rel=1e-12) and res.dt <= 1e-4
    assert np.all(res.u_applied[:steps] == 0)
    assert np.array_equal(res.u_applied[steps:], res.u_command[:-steps])
    # u_command is the static gain times x1
    assert np.allclose(res.u_command, 20000.0 * res.x1, rtol=1e-12, atol=1e-9)
    assert res.delay == d


def test_saturation_is_honoured(bump_road):
    res = simulate(K_SPRING, bump_road, delay=0.005, u_max=200.0)
    assert np.max(np.abs(res.u_applied)) <= 200.0
    clipped = np.abs(res.u_applied) == 200.0
    assert res.saturated_fraction == pytest.approx(
        np.mean(np.abs(np.r_[np.zeros(50), res.u_command[:-50]]) > 200.0))
    assert clipped.any()
    m = res.metrics()
    assert m.peak_u == pytest.approx(200.0)
    # the command is what the controller asks, before the clipping
    assert m.peak_u_command == np.max(np.abs(res.u_command)) > 200.0
    assert m.saturation_time == pytest.approx(res.saturated_fraction * res.t[-1])
    # the default limit is params.u_max
    assert simulate(K_SPRING, bump(t_end=0.5)).u_max == SeatParameters().u_max


def test_metrics_fields(passive):
    m = passive.metrics()
    assert m.peak_z3dd == pytest.approx(np.max(np.abs(passive.z3dd)))
    assert m.peak_x1 == pytest.approx(np.max(np.abs(passive.x1)))
    assert m.x1_within_limit == (m.peak_x1 <= 0.08)
    assert 0 < m.weighted_rms_z3dd < m.peak_z3dd and m.vdv_z3dd > 0 and m.stable


def test_simulate_force_zero_equals_passive(passive, bump_road):
    res = simulate_force(np.zeros(passive.t.size), bump_road, dt=passive.dt)
    assert np.allclose(res.z3dd, passive.z3dd, rtol=0, atol=1e-12)


@pytest.mark.parametrize("kwargs, err", [
    (dict(delay=-0.01), ParameterError),
    (dict(delay=float("nan")), NonFiniteError),
    (dict(delay=0.01, dt=3e-4), ParameterError),      # 0.01 / 3e-4 is not an integer
    (dict(u_max=-5.0), ParameterError),
    (dict(u_max=float("nan")), NonFiniteError),
    (dict(params="not params"), ParameterError),
])
def test_bad_simulation_arguments(kwargs, err):
    with pytest.raises(err):
        simulate(K_SPRING, bump(t_end=0.2), **kwargs)


def test_bad_controllers_and_roads():
    road = bump(t_end=0.2)
    with pytest.raises(DiscreteTimeError):
        simulate(control.ss(0.5, [[1.0, 0.0]], 1.0, [[0.0, 0.0]], dt=0.01), road)
    with pytest.raises(DimensionError):
        simulate(np.array([[1.0, 2.0, 3.0]]), road)
    with pytest.raises(NonFiniteError):
        simulate(np.array([[np.nan, 0.0]]), road)
    with pytest.raises(ParameterError):
        simulate(None, {"t": [0, 1], "w": [0, 0]})
    with pytest.raises(NonFiniteError):
        simulate(None, RoadInput(road.t, road.z0, np.where(road.t > 0.1, np.nan, road.w)))
    with pytest.raises(DiscreteTimeError):
        closed_loop_stable(control.ss(0.5, [[1.0, 0.0]], 1.0, [[0.0, 0.0]], dt=0.01), 0.0)


@pytest.mark.parametrize("K", [K_SPRING, K_DAMPER, K_UNSTABLE],
                         ids=["spring", "damper", "unstable-K"])
def test_closed_loop_stable_agrees_with_pade(K):
    margin = stability_delay_margin(K)
    assert 0 < margin < 0.1
    for d in (0.0, 0.003, 0.3 * margin, 0.8 * margin, 1.25 * margin, 2.0 * margin, 0.06):
        pade = _pade_max_real_pole(K, d)
        if abs(pade) < 0.05:
            continue  # too close to the boundary for the Padé model to be decisive
        assert closed_loop_stable(K, d) == (pade < 0), d


def test_unstable_controller_counts_open_loop_pole():
    # K_UNSTABLE has a pole at +5: closed-loop stable only because the loop encircles.
    assert np.max(control.ss(K_UNSTABLE).poles().real) == pytest.approx(5.0)
    assert closed_loop_stable(K_UNSTABLE, 0.0)
    # the same loop gain without the encirclement (controller sign flipped) is unstable
    assert not closed_loop_stable(-K_UNSTABLE, 0.0)


@pytest.mark.parametrize("K", [K_SPRING, K_DAMPER, K_UNSTABLE],
                         ids=["spring", "damper", "unstable-K"])
def test_delay_margin_equals_phase_margin_over_crossover(K):
    # Independent route: crossovers and phase margins from control.stability_margins of
    # the negative-feedback loop -L0; each crossover w_i with margin PM_i (mod 360 deg)
    # is destabilised by the delay PM_i / w_i, and the smallest one counts.
    gm, pm, sm, wpc, wgc, wms = control.stability_margins(-loop_transfer(K), returnall=True)
    expected = np.min(np.deg2rad(np.mod(pm, 360.0)) / wgc)
    assert stability_delay_margin(K) == pytest.approx(expected, rel=1e-5)


def test_delay_margin_edges():
    assert stability_delay_margin(-K_UNSTABLE) == 0.0          # unstable without delay
    assert stability_delay_margin(np.array([[100.0, 0.0]]), d_max=0.5) == np.inf
    with pytest.raises(ParameterError):
        stability_delay_margin(K_SPRING, d_max=-1.0)
    with pytest.raises(ParameterError):
        closed_loop_stable(K_SPRING, -0.01)


def test_time_simulation_diverges_beyond_margin_only():
    margin = stability_delay_margin(K_SPRING)   # ~28 ms
    road = bump(t_end=4.0, dt=1e-3)
    h = 5e-4
    below = round(0.7 * margin / h) * h
    above = round(1.3 * margin / h) * h
    ok = simulate(K_SPRING, road, delay=below, dt=h, u_max=np.inf)
    bad = simulate(K_SPRING, road, delay=above, dt=h, u_max=np.inf)
    assert ok.stable and not bad.stable
    assert ok.t.size == int(round(4.0 / h)) + 1


def test_monte_carlo_reproducible_and_worst_case():
    road = bump(t_end=0.6, dt=1e-3)
    kw = dict(n=3, delay=(0.0, 0.01), dt=2e-4)
    a = monte_carlo(K_SPRING, road, rng=np.random.default_rng(5), **kw)
    b = monte_carlo(K_SPRING, road, rng=np.random.default_rng(5), **kw)
    assert a.peak_z3dd.tolist() == b.peak_z3dd.tolist()
    assert all(30 <= p.m3 <= 70 for p in a.params)
    assert all(0.8 * 31000 <= p.k1 <= 1.2 * 31000 for p in a.params)
    assert a.worst.peak_z3dd == a.peak_z3dd.max()
    assert np.all((a.delays >= 0) & (a.delays <= 0.01))
    # each sample is reproducible by a direct simulation
    i = a.worst_index
    direct = simulate(K_SPRING, road, delay=a.delays[i], params=a.params[i], dt=2e-4)
    assert direct.metrics().peak_z3dd == pytest.approx(a.worst.peak_z3dd, rel=1e-12)
    with pytest.raises(ParameterError):
        monte_carlo(K_SPRING, road, n=2, rng=1)


def test_random_roads_do_not_trigger_divergence_flag():
    # Stationary random excitation of a stable loop: the energy-growth test must not fire.
    from lmi_suspension.seat.roads import iso8608_road, white_noise
    rng = np.random.default_rng(2)
    noise = white_noise(3.0, 1e-3, psd=1e-4, rng=rng)
    road = iso8608_road("D", 60.0, 3.0, 1e-3, rng=rng)
    assert simulate(np.array([[20000.0, 0.0]]), noise, delay=0.01, dt=2e-4).stable
    assert simulate(None, road, dt=2e-4).stable
