"""The augmented seat plant of Fig. 2: partition, block structure, nominal and perturbed maps.

Independent route: the weighted nominal seat is rebuilt here at each frequency from
``seat_model`` (tested against eq. 1 in test_seat_model.py), the Padé form of eq. (8)
and the weights, and compared with the plant's frequency response; perturbed channels
are closed by a complex upper LFT written out in this file.
"""

import control
import numpy as np
import pytest

from lmi_suspension.errors import NonFiniteError, ParameterError
from lmi_suspension.lti import lft
from lmi_suspension.seat import SeatParameters, seat_model
from lmi_suspension.seat.augmented import (BUMP_PEAK_VELOCITY, SeatDesignOptions,
                                           seat_augmented_plant)
from lmi_suspension.seat.uncertainty import close_upper
from lmi_suspension.seat.weights import wk_weight

FREQS = np.logspace(-1, 3.5, 25)


@pytest.fixture(scope="module")
def full():
    return seat_augmented_plant()


@pytest.fixture(scope="module")
def delay_only():
    return seat_augmented_plant(SeatDesignOptions(include_parametric=False, include_paper=False,
                                                  force_rolloff_ratio=10.0))


def upper_lft_matrix(M, Delta):
    """F_u(M, Δ) for a complex matrix M whose first Δ.shape[0] inputs / Δ.shape[1]
    outputs are the perturbation channels."""
    r, c = Delta.shape
    M11, M12, M21, M22 = M[:c, :r], M[:c, r:], M[c:, :r], M[c:, r:]
    return M22 + M21 @ Delta @ np.linalg.solve(np.eye(c) - M11 @ Delta, M12)


def test_bump_peak_velocity_matches_eq_32():
    # z0 = a/2 (1 - cos(2π V0 t / l)): peak of z0' is a π V0 / l, a = 0.1, l = 2, V0 = 30 km/h.
    t = np.linspace(0, 0.24, 20001)
    V0 = 30 / 3.6
    zdot = 0.05 * (2 * np.pi * V0 / 2) * np.sin(2 * np.pi * V0 * t / 2)
    assert BUMP_PEAK_VELOCITY == pytest.approx(zdot.max(), rel=1e-6)
    assert BUMP_PEAK_VELOCITY == pytest.approx(1.31, abs=0.005)


def test_blk_matches_the_partition(full):
    P, nmeas, ncon, blk = full
    assert (nmeas, ncon) == (2, 1)
    assert full.block_names == ("delay", "m3", "k1", "nb_AB", "nb_C1", "nb_C3", "performance")
    assert blk[-1].tolist() == [3, 3]
    # MATLAB convention: block i is r_i x c_i, M = F_l(P, K) is (Σ c_i) x (Σ r_i).
    n_in = sum(1 if r == -1 else r for r, c in blk)
    n_out = sum(1 if r == -1 else c for r, c in blk)
    assert P.ninputs == n_in + ncon
    assert P.noutputs == n_out + nmeas
    K = control.ss([[-50.0]], [[1.0, 1.0]], [[100.0]], [[0.0, 0.0]])
    M = lft(P, K)
    assert (M.noutputs, M.ninputs) == (n_out, n_in)
    assert P.input_labels[-4:] == ["w", "n1", "n2", "u"]
    assert P.output_labels[-5:] == ["e_acc", "e_force", "e_defl", "y1", "y2"]
    assert P.input_labels[0] == "p_delay" and P.output_labels[0] == "q_delay"


def test_plant_is_minimal(full):
    # seat 6 + Wk 4 + Padé 1 + delay weight 2: nothing uncontrollable or unobservable added.
    assert full.P.nstates == 6 + 4 + 1 + 2
    assert control.minreal(full.P, verbose=False).nstates == full.P.nstates
    assert np.all(full.P.poles().real < 0)


def nominal_reference(aug, s):
    """[w, n1, n2, u] -> [e_acc, e_force, e_defl, y1, y2] rebuilt from the pieces."""
    o = aug.options
    p = aug.params
    G = seat_model(p)(s)  # outputs z3dd, x1, x3, y1, y2; inputs w, u
    d = 0.5 * (p.delay_min + p.delay_max)
    Npade = (1 - s * d / 2) / (1 + s * d / 2) if o.include_delay else 1.0
    Wk = complex(wk_weight(o.wk_order, acc_ref=o.acc_ref)(s))
    if o.force_rolloff_ratio == 1.0:
        Wu = 1 / p.u_max
    else:
        wf, ra = o.force_rolloff_corner, o.force_rolloff_ratio
        Wu = (1 + s / wf) / (1 + s / (ra * wf)) / p.u_max
    R = np.zeros((5, 4), dtype=complex)
    R[0] = [Wk * G[0, 0] * o.w_scale, 0, 0, Wk * G[0, 1] * Npade]
    R[1] = [0, 0, 0, Wu]
    R[2] = [G[1, 0] * o.w_scale / p.z_max, 0, 0, G[1, 1] * Npade / p.z_max]
    R[3] = [G[3, 0] * o.w_scale, o.noise[0], 0, G[3, 1] * Npade]
    R[4] = [G[4, 0] * o.w_scale, 0, o.noise[1], G[4, 1] * Npade]
    return R


@pytest.mark.parametrize("which", ["full", "delay_only"])
def test_nominal_map_equals_the_weighted_seat_model(which, request):
    aug = request.getfixturevalue(which)
    npq = aug.n_unc_inputs
    nq = aug.n_unc_outputs
    if aug.options.include_parametric:
        assert aug.params.m3 == pytest.approx(2 / (1 / 30 + 1 / 70))
    for w in FREQS:
        s = 1j * w
        Pj = aug.P(s)
        np.testing.assert_allclose(Pj[nq:, npq:], nominal_reference(aug, s), rtol=1e-9,
                                   atol=1e-12)


def test_upper_and_lower_lft_commute(full):
    # Eq. (20): F_l(F_u(P, Δ), K) = F_u(F_l(P, K), Δ) for a constant Δ and a controller K.
    P, nmeas, ncon, blk = full
    rng = np.random.default_rng(11)
    r, c = full.n_unc_inputs, full.n_unc_outputs
    Delta = 0.3 * rng.standard_normal((r, c))
    K = control.ss([[-80.0]], [[1.0, -2.0]], [[500.0]], [[1000.0, 0.0]])
    left = lft(close_upper(P, Delta), K)
    right = close_upper(lft(P, K), Delta)
    np.testing.assert_allclose(left(1j * FREQS), right(1j * FREQS), rtol=1e-8, atol=1e-12)


@pytest.mark.parametrize("d", [0.0, 0.007, 0.025])
def test_delay_channel_reproduces_the_exact_delay(delay_only, d):
    aug = delay_only
    cover = aug.delay
    p = aug.params
    for w in (3.0, 40.0, 700.0):
        s = 1j * w
        delta = cover.delta_for(w, d)
        assert abs(delta) <= 1
        closed = upper_lft_matrix(aug.P(s), np.array([[delta]]))
        G = seat_model(p)(s)
        Wk = complex(wk_weight(4, acc_ref=aug.options.acc_ref)(s))
        # u -> e_acc and u -> y1 with the exact delay e^{-jωd}
        assert closed[0, 3] == pytest.approx(Wk * G[0, 1] * np.exp(-s * d), rel=1e-9)
        assert closed[3, 3] == pytest.approx(G[3, 1] * np.exp(-s * d), rel=1e-9)


def test_parametric_channels_reproduce_the_occupant_range(full):
    # δ_m3 = +1 -> m3 = 30 kg, δ_k1 = -1 -> k1 = 0.8 * 31000 N/m; other channels open.
    aug = full
    i_m3 = aug.P.input_labels.index("p_m3")
    i_k1 = aug.P.input_labels.index("p_k1")
    assert aug.P.output_labels.index("q_m3") == i_m3
    ref_p = SeatParameters(m3=30.0, k1=24800.0)
    for w in (2.0, 30.0, 300.0):
        s = 1j * w
        Delta = np.zeros((aug.n_unc_inputs, aug.n_unc_outputs))
        Delta[i_m3, i_m3], Delta[i_k1, i_k1] = 1.0, -1.0
        closed = upper_lft_matrix(aug.P(s), Delta)
        G = seat_model(ref_p)(s)
        d = 0.0125
        Npade = (1 - s * d / 2) / (1 + s * d / 2)
        assert closed[2, 0] == pytest.approx(G[1, 0] * aug.options.w_scale / 0.08, rel=1e-9)
        assert closed[3, 3] == pytest.approx(G[3, 1] * Npade, rel=1e-9)


def test_shaped_disturbance_column():
    # w -> [e_acc, e_defl, y1]: the seat's ż0 column times w_scale · s/(s + ω_c) ·
    # ω_r²/(s² + √2 ω_r s + ω_r²), written out here (nominal plant, no uncertainty).
    o = SeatDesignOptions(include_delay=False, include_parametric=False, include_paper=False,
                          w_scale=0.4, w_corner=13.5, w_rolloff=50.0)
    aug = seat_augmented_plant(o)
    iw = aug.P.input_labels.index("w")
    p = aug.params
    for w in (0.5, 13.5, 50.0, 400.0):
        s = 1j * w
        Wd = 0.4 * s / (s + 13.5) * 50.0 ** 2 / (s ** 2 + np.sqrt(2) * 50.0 * s + 50.0 ** 2)
        G = seat_model(p)(s)
        Wk = complex(wk_weight(o.wk_order, acc_ref=o.acc_ref)(s))
        col = aug.P(s)[:, iw]
        np.testing.assert_allclose(col[[0, 2, 3]], [Wk * G[0, 0] * Wd, G[1, 0] * Wd / p.z_max,
                                                    G[3, 0] * Wd], rtol=1e-9)
    # A second-order Butterworth low pass is 1/√2 at its corner.
    lo = seat_augmented_plant(o).P(1j * 50.0)[3, iw] / seat_model(p)(1j * 50.0)[3, 0]
    assert abs(lo) == pytest.approx(0.4 * 50 / abs(50j + 13.5) / np.sqrt(2), rel=1e-9)


def test_options_select_the_blocks():
    none = seat_augmented_plant(SeatDesignOptions(include_delay=False, include_parametric=False,
                                                  include_paper=False))
    assert none.blk.tolist() == [[3, 3]]
    assert none.P.input_labels == ["w", "n1", "n2", "u"]
    assert none.P.nstates == 6 + 4
    cplx = seat_augmented_plant(SeatDesignOptions(include_delay=False, include_paper=False,
                                                  parametric_complex=True,
                                                  stiffness=("k1", "k3"), wk_order=2))
    assert cplx.blk.tolist() == [[1, 1]] * 3 + [[3, 3]]
    assert cplx.block_names == ("m3", "k1", "k3", "performance")
    assert cplx.P.nstates == 6 + 2


@pytest.mark.parametrize("kwargs, err", [
    (dict(acc_ref=-1.0), ParameterError),
    (dict(noise=(1e-4, -1e-4)), ParameterError),
    (dict(noise=(1e-4,)), ParameterError),
    (dict(u_max=0.0), ParameterError),
    (dict(z_max=float("nan")), NonFiniteError),
    (dict(w_scale=float("inf")), NonFiniteError),
    (dict(w_rolloff=0.0), ParameterError),
    (dict(w_corner=-1.0), ParameterError),
    (dict(delay_min=0.03, delay_max=0.02), ParameterError),
    (dict(delay_min=-0.01), ParameterError),
    (dict(force_rolloff_ratio=0.5), ParameterError),
    (dict(m3_range=(70.0, 30.0)), ParameterError),
    (dict(wk_order=7), ParameterError),
    (dict(delay_order=5), ParameterError),
    (dict(include_delay="yes"), ParameterError),
])
def test_options_reject_bad_values(kwargs, err):
    with pytest.raises(err):
        SeatDesignOptions(**kwargs)


def test_delay_range_from_params_is_checked():
    # SeatParameters itself refuses a reversed range; options may override one end.
    with pytest.raises(ParameterError):
        seat_augmented_plant(SeatDesignOptions(delay_min=0.03, include_parametric=False,
                                               include_paper=False))


def test_caller_arguments_are_not_mutated():
    opts = SeatDesignOptions(include_paper=False, include_parametric=False)
    params = SeatParameters()
    aug = seat_augmented_plant(opts, params)
    assert aug.options is opts and params == SeatParameters()
    with pytest.raises(TypeError):
        seat_augmented_plant(options={"acc_ref": 1.0})
