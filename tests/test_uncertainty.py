"""Uncertainty models of the seat: delay cover, the paper's norm-bounded set, parametric LFT.

References used below:
- Delay: the cover is checked by brute force, ``max_d |e^{-jωd} - N(jω)| / |N(jω)|`` on a
  2000 ω × 101 d grid computed here, not by the envelope formula of the module.
- Padé nominal: eq. (8) of the paper, ``(1 - s d/2)/(1 + s d/2)``, evaluated here.
- Parametric: the independent route is ``seat_model(SeatParameters(m3=..., k1=...))``
  (the hand derivation of eq. 1, tested in test_seat_model.py) at the range end points.
- Paper: L2, L3, E_A = δI as printed after Table 1, δ = 0.02.
- ISO 2631-1:1997 Table 3 (one-third-octave Wk factors) and MATLAB's documented
  ``makeweight(100, 10, 0.1) = (0.1 s + 9.95)/(s + 0.0995)`` for the weights.
"""

import control
import numpy as np
import pytest

from lmi_suspension.errors import DimensionError, NonFiniteError, ParameterError
from lmi_suspension.seat import SeatParameters, seat_matrices, seat_model
from lmi_suspension.seat.uncertainty import (close_upper, delay_envelope, delay_uncertainty,
                                             paper_norm_bounded, parametric_uncertainty)
from lmi_suspension.seat.weights import iso2631_wk, makeweight, wk_weight

OMEGA = np.logspace(-2, 5, 2000)
DELAYS = np.linspace(0.0, 0.025, 101)


def brute_envelope(N_resp, omega, delays):
    err = np.abs(np.exp(-1j * np.outer(omega, delays)) - N_resp[:, None])
    return err.max(axis=1) / np.abs(N_resp)


# --------------------------------------------------------------------------- weights
def test_makeweight_matches_matlab_documented_example():
    # MATLAB Answers 1947288: makeweight(100,10,0.1) returns (0.1 s + 9.95)/(s + 0.0995).
    W = makeweight(100, 10, 0.1)
    ref = control.tf([0.1, 9.95], [1, 0.0995])
    w = np.logspace(-3, 3, 50)
    np.testing.assert_allclose(W(1j * w), ref(1j * w), rtol=1e-3)


@pytest.mark.parametrize("order", [1, 2, 3, 5])
@pytest.mark.parametrize("dc, wc, hf, mag", [(0.5, 30.0, 4.0, 1.0), (100.0, 10.0, 0.1, 1.0),
                                             (0.0, 5.0, 2.0, 1.0), (3.0, 2.0, 0.0, 1.0),
                                             (0.1, 8.0, 10.0, 2.0)])
def test_makeweight_gains_and_butterworth_shape(dc, wc, hf, mag, order):
    W = makeweight(dc, wc, hf, order=order, mag=mag)
    assert abs(complex(W(0j))) == pytest.approx(dc, abs=1e-9 * max(dc, 1))
    assert abs(complex(W(1j * wc))) == pytest.approx(mag, rel=1e-9)
    assert float(W.D[0, 0]) == pytest.approx(hf, rel=1e-9, abs=1e-12)  # W(inf) = D
    assert np.all(W.poles().real < 0)
    if dc > 0 and hf > 0:
        assert np.all(W.zeros().real < 0)
    # Butterworth pattern: |W|^2 = (dc^2 + hf^2 x^2N)/(1 + x^2N), x = ω/ω0, monotone.
    w = np.logspace(-3, 3, 200) * wc
    g = np.abs(W(1j * w))
    assert np.all(np.diff(g) * np.sign(hf - dc) >= -1e-12)
    x2n = (dc ** 2 - mag ** 2) / (mag ** 2 - hf ** 2) * (w / wc) ** (2 * order)
    np.testing.assert_allclose(g ** 2, (dc ** 2 + hf ** 2 * x2n) / (1 + x2n), rtol=1e-8,
                               atol=1e-12 * max(dc, hf) ** 2)


@pytest.mark.parametrize("dc, hf", [(0.5, 0.9), (2.0, 3.0), (1.0, 5.0), (-1.0, 5.0)])
def test_makeweight_rejects_gains_not_bracketing_one(dc, hf):
    with pytest.raises(ParameterError):
        makeweight(dc, 10.0, hf)


def test_makeweight_rejects_bad_frequency_order_and_nan():
    with pytest.raises(ParameterError):
        makeweight(0.1, -1.0, 10)
    with pytest.raises(ParameterError):
        makeweight(0.1, 1.0, 10, order=0)
    with pytest.raises(NonFiniteError):
        makeweight(float("nan"), 1.0, 10)


def test_iso2631_wk_matches_the_standards_table():
    # ISO 2631-1:1997 Table 3, Wk weighting factors (x1000) at one-third-octave centres.
    table = {0.25: 182, 0.5: 418, 1.0: 482, 2.0: 531, 4.0: 967, 6.3: 1054, 8.0: 1036,
             12.5: 902, 16.0: 768, 25.0: 513, 50.0: 246, 100.0: 88.7}
    Wk = iso2631_wk()
    for f, v in table.items():
        assert abs(complex(Wk(2j * np.pi * f))) == pytest.approx(v / 1000, rel=0.01), f


# order 4 drops only the 0.4 Hz/100 Hz band limiting: 1.3 % at 1 Hz, less above
@pytest.mark.parametrize("order, tol", [(4, 0.015), (3, 0.15), (2, 0.15)])
def test_low_order_wk_follows_the_standard_in_the_comfort_band(order, tol):
    W = wk_weight(order, acc_ref=2.0)
    f = np.logspace(0, np.log10(25.0), 40)  # 1-25 Hz, where the seat modes lie
    ratio = np.abs(W(2j * np.pi * f)) * 2.0 / np.abs(iso2631_wk()(2j * np.pi * f))
    assert np.all(np.abs(ratio - 1) < tol)
    assert np.all(W.poles().real < 0) and np.all(W.zeros().real < 0)


def test_wk_weight_rejects_bad_arguments():
    with pytest.raises(ParameterError):
        wk_weight(5)
    with pytest.raises(ParameterError):
        wk_weight(acc_ref=0.0)


# --------------------------------------------------------------------------- delay
@pytest.fixture(scope="module", params=["pade", "none"])
def cover(request):
    return delay_uncertainty(0.0, 0.025, nominal=request.param, order=2)


def test_delay_weight_covers_every_delay_on_a_dense_grid(cover):
    Nr = np.asarray(cover.N(1j * OMEGA)).ravel()
    err = brute_envelope(Nr, OMEGA, DELAYS)
    Wmag = cover.bound(OMEGA)
    assert np.all(Wmag >= err)
    # The exact envelope is never below the sampled one and is tight against a finer grid.
    env = cover.envelope(OMEGA)
    assert np.all(env >= err - 1e-12)
    fine = brute_envelope(Nr, OMEGA, np.linspace(0.0, 0.025, 2001))
    np.testing.assert_allclose(env, fine, rtol=2e-3, atol=1e-12)
    # Tightness (measured 1.38 with the Padé nominal, 1.25 without).
    assert np.max(Wmag / env) < 1.45


def test_delay_weight_is_stable_and_minimum_phase(cover):
    assert np.all(cover.W.poles().real < 0)
    assert np.all(cover.W.zeros().real < 0)


def test_delay_nominal_is_the_first_order_pade_of_the_mid_delay():
    du = delay_uncertainty(0.0, 0.025, nominal="pade", order=1)
    d = 0.0125
    s = 1j * OMEGA
    np.testing.assert_allclose(np.asarray(du.N(s)).ravel(), (1 - s * d / 2) / (1 + s * d / 2),
                               rtol=1e-12)
    assert complex(delay_uncertainty(0.0, 0.025, nominal="none", order=1).N(1j)) == 1


def test_delta_for_reproduces_the_exact_delay_with_unit_bound(cover):
    rng = np.random.default_rng(7)
    for w, d in zip(10 ** rng.uniform(-2, 5, 50), rng.uniform(0, 0.025, 50)):
        delta = cover.delta_for(w, d)
        s = 1j * w
        value = complex(cover.N(s)) * (1 + complex(cover.W(s)) * delta)
        assert value == pytest.approx(np.exp(-s * d), abs=1e-12)
        assert abs(delta) <= 1.0


def test_delay_cover_of_a_fixed_nonzero_delay_and_higher_order():
    du = delay_uncertainty(0.01, 0.02, nominal="pade", order=3)
    Nr = np.asarray(du.N(1j * OMEGA)).ravel()
    err = brute_envelope(Nr, OMEGA, np.linspace(0.01, 0.02, 101))
    assert np.all(du.bound(OMEGA) >= err)


def test_envelope_formula_on_a_hand_case():
    # N = 1, d in [0, τ]: envelope is 2 sin(ωτ/2) up to ωτ = π, then 2.
    tau = 0.02
    w = np.array([1.0, 50.0, 100.0, 200.0, 1000.0])
    env = delay_envelope(w, 0.0, tau, np.ones_like(w))
    expected = np.where(w * tau < np.pi, 2 * np.sin(w * tau / 2), 2.0)
    np.testing.assert_allclose(env, expected, rtol=1e-12)


@pytest.mark.parametrize("kwargs, err", [
    (dict(d_min=-0.01, d_max=0.02), ParameterError),
    (dict(d_min=0.03, d_max=0.02), ParameterError),
    (dict(d_min=0.0, d_max=0.0), ParameterError),
    (dict(d_min=0.0, d_max=float("nan")), NonFiniteError),
    (dict(d_min=0.0, d_max=0.02, order=4), ParameterError),
    (dict(d_min=0.0, d_max=0.02, nominal="thiran"), ParameterError),
    (dict(d_min=0.0, d_max=0.02, margin=-0.1), ParameterError),
])
def test_delay_uncertainty_rejects_bad_input(kwargs, err):
    with pytest.raises(err):
        delay_uncertainty(**kwargs)


# --------------------------------------------------------------------------- paper
def test_paper_norm_bounded_matches_the_printed_parts():
    nb = paper_norm_bounded()
    d = 0.02
    np.testing.assert_array_equal(nb.L2, d * np.array([[0, 0, 0, 1, 1, 1]]))
    np.testing.assert_array_equal(nb.L3, d * np.array([[1, 0, 0, 0, 0, 0], [0, 0, 1, 0, 0, 0]]))
    for E in (nb.E_A, nb.E_C1, nb.E_C3):
        np.testing.assert_array_equal(E, d * np.eye(6))
    # E_B: printed empty; the pattern of B (the force acts on m1's row 2), δ e2
    np.testing.assert_array_equal(nb.E_B, d * np.array([[0.0], [1], [0], [0], [0], [0]]))


def test_reconstructed_L1_is_consistent_with_the_printed_fragments():
    L1 = paper_norm_bounded().L1 / 0.02
    # Kinematic rows 1, 3, 5 of A carry no uncertainty.
    assert not L1[[0, 2, 4]].any()
    # Printed columns 2..6 ("0 0 1 0 0" x2, "0 0 1 0 1" x2, "0 0 0 1 0 1"): each is the
    # reconstructed column with at most one entry lost.
    printed = [[0, 0, 1, 0, 0], [0, 0, 1, 0, 0], [0, 0, 1, 0, 1], [0, 0, 1, 0, 1],
               [0, 0, 0, 1, 0, 1]]
    for j, frag in enumerate(printed, start=1):
        col = L1[:, j].astype(int).tolist()
        candidates = [col] + [col[:i] + col[i + 1:] for i in range(6)]
        assert frag in candidates, (j, col, frag)
    # And L1 marks exactly the entries of A that move with the physical parameters.
    A1 = seat_matrices(SeatParameters()).A
    A2 = seat_matrices(SeatParameters(m1=16, m21=1.5, m22=8, m3=50, c1=900, c2=250,
                                      c3=1500, k1=30000, k2=19000, k3=45000)).A
    np.testing.assert_array_equal(L1 != 0, A1 != A2)


# L1 / δ as reconstructed in paper_norm_bounded's docstring (columns [0 1 0 0 0 0],
# [0 1 0 1 0 0] x2, [0 1 0 1 0 1], [0 0 0 1 0 1] x2), written out here; the test above
# checks the same pattern against the physics (the entries of A that move)
PATTERN = np.array([[0, 0, 0, 0, 0, 0],
                    [1, 1, 1, 1, 0, 0],
                    [0, 0, 0, 0, 0, 0],
                    [0, 1, 1, 1, 1, 1],
                    [0, 0, 0, 0, 0, 0],
                    [0, 0, 0, 1, 1, 1]], dtype=float)


def test_paper_perturbations_match_the_closed_form_and_are_tiny_next_to_A():
    """Reference: the paper's ΔA = L1 F E_A, ΔB = L1 F E_B, ΔC1 = L2 F E_C1,
    ΔC3 = L3 F E_C3 (eqs. 9, 16) with δ = 0.02, entry by entry from the literal patterns
    (E_A = E_C1 = E_C3 = δ I, E_B = δ e2, L2 = δ [0 0 0 1 1 1], L3 = δ [e1; e3]): for
    F = I the perturbations are δ² times the patterns, exactly; for a random contraction
    each entry is δ² Σ_k pattern[r, k] F[k, c], summed here in Python."""
    nb = paper_norm_bounded()
    d2 = 0.02**2
    dA, dB, dC1, dC3 = nb.perturbations(np.eye(6))
    np.testing.assert_allclose(dA, d2 * PATTERN, rtol=1e-15, atol=0)
    np.testing.assert_allclose(dB, d2 * PATTERN[:, [1]], rtol=1e-15, atol=0)
    np.testing.assert_allclose(dC1, d2 * np.array([[0, 0, 0, 1, 1, 1.0]]), rtol=1e-15, atol=0)
    np.testing.assert_allclose(dC3, d2 * np.array([[1.0, 0, 0, 0, 0, 0], [0, 0, 1, 0, 0, 0]]),
                               rtol=1e-15, atol=0)
    rng = np.random.default_rng(1)
    F = rng.standard_normal((6, 6))
    F /= np.linalg.norm(F, 2)
    dA, dB, dC1, dC3 = nb.perturbations(F)
    ref_A = [[d2 * sum(PATTERN[r, k] * F[k, c] for k in range(6)) for c in range(6)]
             for r in range(6)]
    ref_B = [[d2 * sum(PATTERN[r, k] * F[k, 1] for k in range(6))] for r in range(6)]
    ref_C1 = [[d2 * sum(F[k, c] for k in (3, 4, 5)) for c in range(6)]]
    ref_C3 = [[d2 * F[k, c] for c in range(6)] for k in (0, 2)]
    for got, ref in ((dA, ref_A), (dB, ref_B), (dC1, ref_C1), (dC3, ref_C3)):
        np.testing.assert_allclose(got, ref, rtol=1e-12, atol=1e-20)
    # "tiny": each entry is at most δ² times its row's pattern count (|F_kc| <= 1), i.e.
    # below 4 δ² = 1.6e-3, against |A| up to ~2e3; and not zero where the pattern is not
    assert np.all(np.abs(dA) <= d2 * PATTERN.sum(axis=1, keepdims=True) + 1e-18)
    A = seat_matrices().A
    assert np.abs(dA).max() < 1e-5 * np.abs(A).max()
    assert np.all(np.abs(dA[[1, 3, 5]]).max(axis=1) > 0.1 * d2)


def test_compressed_blocks_stay_inside_the_paper_set():
    nb = paper_norm_bounded()
    rng = np.random.default_rng(2)
    blocks = nb.blocks()
    for key, L, E in (("nb_AB", nb.L1, np.hstack([nb.E_A, nb.E_B])),
                      ("nb_C1", nb.L2, nb.E_C1), ("nb_C3", nb.L3, nb.E_C3)):
        left, right = blocks[key]
        assert left.shape[1] == np.linalg.matrix_rank(L)
        for _ in range(5):
            G = rng.standard_normal((left.shape[1], right.shape[0]))
            G /= np.linalg.norm(G, 2)
            dM = left @ G @ right
            # certificate: F = L^+ dM E^+ reproduces dM and is a contraction
            F = np.linalg.pinv(L) @ dM @ np.linalg.pinv(E)
            np.testing.assert_allclose(L @ F @ E, dM, atol=1e-14)
            assert np.linalg.norm(F, 2) <= 1 + 1e-9
        # and the largest perturbation of the paper's set is still reachable
        assert np.linalg.norm(left, 2) * np.linalg.norm(right, 2) == pytest.approx(
            np.linalg.norm(L, 2) * np.linalg.norm(E, 2), rel=1e-12)


def test_paper_norm_bounded_rejects_bad_delta():
    with pytest.raises(ParameterError):
        paper_norm_bounded(delta=-0.1)
    with pytest.raises(NonFiniteError):
        paper_norm_bounded(delta=float("inf"))
    with pytest.raises(DimensionError):
        paper_norm_bounded().perturbations(np.eye(5))


# --------------------------------------------------------------------------- parametric
W_TEST = np.logspace(-1, 4, 60)


def assert_same_response(G1, G2):
    r1, r2 = G1(1j * W_TEST), G2(1j * W_TEST)
    np.testing.assert_allclose(r1, r2, rtol=1e-9, atol=1e-9 * np.abs(r2).max())


@pytest.mark.parametrize("d_m3, m3", [(0.0, 42.0), (1.0, 30.0), (-1.0, 70.0)])
@pytest.mark.parametrize("d_k1, k1", [(0.0, 31000.0), (1.0, 37200.0), (-1.0, 24800.0)])
def test_parametric_lft_reproduces_the_seat_model_at_the_range_ends(d_m3, m3, d_k1, k1):
    pu = parametric_uncertainty(SeatParameters(), m3_range=(30.0, 70.0), stiffness_rel=0.2)
    assert pu.names == ("m3", "k1")
    ref = seat_model(SeatParameters(m3=m3, k1=k1))
    assert_same_response(pu.model_at([d_m3, d_k1]), ref)


def test_parametric_lft_with_every_element_matches_random_parameters():
    pu = parametric_uncertainty(stiffness=("k1", "k2", "k3"), damping=("c1", "c2", "c3"),
                                stiffness_rel=0.3, damping_rel=0.25)
    rng = np.random.default_rng(3)
    for _ in range(3):
        d = rng.uniform(-1, 1, len(pu.names))
        vals = dict(zip(pu.names, d))
        # parameters computed here from the definitions, not via params_at
        p = SeatParameters(
            m3=1 / ((1 / 42.0) * (1 + 0.4 * vals["m3"])),
            k1=31000 * (1 + 0.3 * vals["k1"]), k2=18000 * (1 + 0.3 * vals["k2"]),
            k3=44130 * (1 + 0.3 * vals["k3"]), c1=830 * (1 + 0.25 * vals["c1"]),
            c2=200 * (1 + 0.25 * vals["c2"]), c3=1485 * (1 + 0.25 * vals["c3"]))
        assert_same_response(pu.model_at(d), seat_model(p))
    assert pu.blk.tolist() == [[-1, 0]] * 7


def test_parametric_uncertainty_rejects_bad_input():
    with pytest.raises(ParameterError):
        parametric_uncertainty(m3_range=(70.0, 30.0))
    with pytest.raises(ParameterError):
        parametric_uncertainty(stiffness_rel=1.5)
    with pytest.raises(ParameterError):
        parametric_uncertainty(stiffness=("k4",))
    with pytest.raises(NonFiniteError):
        parametric_uncertainty(m3_range=(30.0, float("nan")))
    with pytest.raises(ParameterError):
        parametric_uncertainty(m3_range=None, stiffness=())
    pu = parametric_uncertainty()
    with pytest.raises(DimensionError):
        pu.model_at([0.0])
    with pytest.raises(DimensionError):
        close_upper(pu.G, np.zeros((7, 7)))
