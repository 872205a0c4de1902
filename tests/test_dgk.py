"""D-G scalings of real blocks (mu/gfit.py) and musyn with real blocks kept real.

The plant: a lightly damped oscillator (ζ = 0.02, ω_n = 1) whose stiffness is a real
parameter k (1 ± 50 %), a low-pass performance weight on the position, an expensive
control (weight 1) and 5 % sensor noise.  Its central H∞ controller has mixed µ 1.157
and complex µ 2.32 (measured 2026-11-27 with mussv): a problem where the disc cover of k
is far from the real interval.
"""

import control
import numpy as np
import pytest

from lmi_suspension import hinfnorm, hinfsyn, lft
from lmi_suspension.errors import ParameterError
from lmi_suspension.examples import stiffness_oscillator, uncertain_stiffness_oscillator
from lmi_suspension.lti.norms import freqresp
from lmi_suspension.mu import BlockStructure, MusynOptions, mussv, musyn
from lmi_suspension.mu.dfit import fit_dscales, scaled_plant
from lmi_suspension.mu.gfit import central_dg, fit_gscales, gscaled_plant, optimal_gscales
from lmi_suspension.mu.steps import mu_part as _mu_part
from lmi_suspension.uncertain import lftdata, usubs

BLK = [[-1, 0], [2, 2]]


def oscillator(**kw):
    """Inputs [w_k, d, n, u], outputs [z_k, e, z_u, y]; k = 1 + rk δ."""
    return stiffness_oscillator(**kw).P


@pytest.fixture(scope="module")
def loop():
    P = oscillator()
    K = hinfsyn(P, 1, 1, method="riccati").K
    struct = BlockStructure.coerce(BLK)
    w = np.logspace(-2, 1.5, 25)
    M = freqresp(_mu_part(lft(P, K), struct), w)
    return P, K, struct, w, M


def test_central_scalings_certify_where_their_margin_is_nonnegative(loop):
    """Where ``central_dg``'s margin is >= 0, its scalings must satisfy the bound's
    condition σ̄((N - jĜ)(I + Ĝ²)^(-1/2)) <= 1 with N = D M D⁻¹/β (Young 1996, the
    algebra redone here with matrices), and |ĝ| stays within its bound."""
    _, _, struct, w, M = loop
    beta = 1.01 * float(np.max(mussv(M, struct, omega=w).upper))
    d, g, margin = central_dg(M, struct, beta, g_max=5.0)
    assert np.all(np.abs(g) <= 5.0 * (1 + 1e-6))
    checked = 0
    for k in range(w.size):
        if margin[k] < 0:
            continue
        D = np.diag([d[0, k], d[1, k], d[1, k]])
        N = D @ M[:, :, k] @ np.linalg.inv(D) / beta
        Gh = np.diag([g[0, k], 0.0, 0.0])
        S = (N - 1j * Gh) @ np.diag(1 / np.sqrt(1 + np.diag(Gh) ** 2))
        assert np.linalg.norm(S, 2) <= 1 + 1e-6
        checked += 1
    assert checked >= w.size // 2


def test_gscaled_plant_is_the_lft_of_the_scaled_bound(loop):
    """F_l(P_DG, K) = (D̂ M D̂⁻¹ / β) Ĥ - T̂ on the real block, at any ω: the plant built
    by series and parallel connections against the formula evaluated from the fits'
    own frequency responses (matrices, no plant algebra)."""
    P, K, struct, w, M = loop
    beta = 1.2
    d, g, _ = central_dg(M, struct, beta)
    dfit = fit_dscales(w, d, max_order=2)
    gfit = fit_gscales(w, g, struct, beta)
    PDG = gscaled_plant(scaled_plant(P, 1, 1, dfit, [(1, 1), (2, 2)]), 1, 1, struct, gfit)
    wt = np.array([0.05, 0.7, 1.3, 9.0])
    got = freqresp(_mu_part(lft(PDG, K), struct), wt)
    Mt = freqresp(_mu_part(lft(P, K), struct), wt)
    for k, x in enumerate(1j * wt):
        dd = [complex(dfit.fits[0](x)), complex(dfit.fits[1](x))]
        D = np.diag([dd[0], dd[1], dd[1]])
        H = np.diag([complex(gfit.H[0](x)), 1.0, 1.0])
        T = np.zeros((3, 3), complex)
        T[0, 0] = complex(gfit.T[0](x))
        want = D @ Mt[:, :, k] @ np.linalg.inv(D) / beta @ H - T
        np.testing.assert_allclose(got[:, :, k], want, rtol=1e-7, atol=1e-9)


@pytest.mark.parametrize("poles", [None, [0.3, 2.0 + 1.5j, 8.0]],
                         ids=["log-spaced", "with a complex pair"])
def test_t_over_h_is_purely_imaginary_and_h_magnitude_is_exact(loop, poles):
    """T(jω)/H(jω) = j z(ω) with z the fitted odd function, and |H|² (1 + z²) = 1 to
    roundoff: H is the inverse of the spectral factor of 1 + z², not a magnitude fit
    (module docstring of gfit), for real basis poles and a complex pair alike."""
    _, _, struct, w, _ = loop
    g = np.array([0.8 * w / (0.3 + w**2) - 0.2 * w / (4.0 + w**2)])
    fit = fit_gscales(w, g, struct, 1.0, poles=poles)
    x = 1j * np.logspace(-3, 3, 301)  # beyond the grid too
    ratio = np.array([complex(fit.T[0](s) / fit.H[0](s)) for s in x])
    z = fit.z(0, x.imag)
    np.testing.assert_allclose(ratio.real, 0.0, atol=1e-9)
    np.testing.assert_allclose(ratio.imag, z, rtol=1e-7, atol=1e-10)
    Hm = np.abs([complex(fit.H[0](s)) for s in x])
    np.testing.assert_allclose(Hm**2 * (1 + z**2), 1.0, rtol=1e-8)
    assert all(np.all(np.real(sys.poles()) < 0) for sys in (fit.T[0], fit.H[0]))
    assert fit.HT[0].nstates == 3 * sum(1 if np.imag(c) == 0 else 2 for c in fit.poles[0])


def test_optimal_gscales_reach_the_pointwise_mixed_bound_and_certify_on_the_grid(loop):
    """optimal_gscales restricts G to a rational family (and D to its fit), so its level
    is at least the pointwise mixed-µ upper bound (mussv's LMI, the optimum over all D
    and G).  How close it comes depends on the loop: on this Riccati controller's loop
    and 25-point grid, 6.7 % above with 10 poles (16 poles: 0.9 %; adding the loop's
    resonant poles to the basis did not help), on the LMI central controller's loop and
    D-G-K's iterates of the oscillator within 0.5 % (2026-11-27): the test allows 10 %.
    By construction the controller's D-G-scaled loop has σ̄ <= 1 at every grid
    frequency, checked here on the plant built from the scalings."""
    P, K, struct, w, M = loop
    mu = float(np.max(mussv(M, struct, omega=w, method="lmi").upper))
    d, _, _ = central_dg(M, struct, mu)
    dfit = fit_dscales(w, d, max_order=4)
    PD = scaled_plant(P, 1, 1, dfit, [(1, 1), (2, 2)])
    Mt = freqresp(_mu_part(lft(PD, K), struct), w)
    gfit = optimal_gscales(w, Mt, struct, target=mu)
    assert mu * (1 - 1e-6) <= gfit.beta <= mu * 1.10
    PDG = gscaled_plant(PD, 1, 1, struct, gfit)
    on_grid = freqresp(_mu_part(lft(PDG, K), struct), w)
    sig = [np.linalg.norm(on_grid[:, :, k], 2) for k in range(w.size)]
    assert max(sig) <= 1 + 1e-5


@pytest.mark.slow  # 25 s on Zen 1 (2026-12-02): the second tier
def test_musyn_with_real_blocks_kept_real_returns_certified_bounds():
    """complexify=False (D-G-K, the default): whatever its path, the returned controller
    stabilises the loop, its µ bounds use the real structure (lower <= upper on the
    dense grid, both from mussv on the returned loop), and it is the best iterate, or
    the complexified run's controller where that certifies lower on the dense grid
    (``complex_candidate``; on this grid it does: D-G-K's iterate 2 reads 1.1456 on
    the design grid and rises above it between the points, 2026-12-02)."""
    P = oscillator()
    res = musyn(P, 1, 1, BLK, omega=np.logspace(-2, 1.5, 25),
                options=MusynOptions(max_iter=2, method="riccati", complexify=False,
                                     n_dense=30, reduce_order=None))  # the loop's choice
    assert np.all(res.CL.poles().real < 0)
    assert np.all(np.asarray(res.mu.lower) <= np.asarray(res.mu.upper) * (1 + 1e-6))
    assert res.mu.blk.to_blk().tolist() == BLK
    peaks = [h.mu_peak for h in res.history]
    if res.K is res.complex_run.K:  # index 0, or 1 where D-G-K started from it
        assert res.best_iteration in (0, 1) and res.complex_run.mu_peak == res.mu_peak
        assert "the complexified D-K's controller is returned" in res.stop_reason
    else:
        assert res.best_iteration == int(np.argmin(peaks)) + 1
    again = mussv(freqresp(res.CL, [res.peak_omega]), BLK)
    assert float(np.ravel(again.upper)[0]) == pytest.approx(res.mu_peak, rel=1e-3)


uncertain_oscillator = uncertain_stiffness_oscillator


@pytest.mark.slow  # 26 s on Zen 1 (2026-12-02): the second tier
def test_musyn_takes_an_uncertain_plant_and_its_bound_holds_on_the_scaled_range():
    """musyn(uss, nmeas, ncon): the structure is lftdata's plus the performance block,
    and the returned all-frequency bound β = mu_bound means (main loop theorem) that for
    every stiffness in the range shrunk by 1/β the loop is stable with ‖e/d‖∞ ≤ β:
    checked by brute force on 21 stiffness values, each loop built by usubs and its
    norm computed directly (a route that shares nothing with the µ bounds).

    The same norms bound β from above: a real |δ| <= 1/β whose loop has norm ν gives
    µ >= min(β, ν) (a complex performance block of size 1/ν closing that loop makes
    I - MΔ singular, and σ̄(Δ) = max(|δ|, 1/ν)), so β cannot exceed the largest ν by
    more than the interval certificate's slack (0.1 %, ``_SUP_RTOL``) plus the
    shortfall of the sampled δ: an inflated mu_bound fails."""
    Pu = uncertain_oscillator()
    res = musyn(Pu, 1, 1, omega=np.logspace(-2, 1.5, 25),
                options=MusynOptions(max_iter=2, method="riccati", complexify=False,
                                     n_dense=30))
    assert res.mu.blk.to_blk().tolist() == [[-1, 0], [2, 2]]
    beta = res.mu_bound
    assert res.mu_peak <= beta and np.isfinite(beta)
    norms = []
    for delta in np.linspace(-1, 1, 21) / beta:
        loop = lft(usubs(Pu, {"k": 1.0 + 0.5 * delta}), res.K, 1, 1)
        assert np.all(loop.poles().real < 0)
        norms.append(float(hinfnorm(loop)[0]))
    assert max(norms) <= beta * (1 + 1e-6)
    # β / max ν measured 1.0012 under the Haswell kernel (β 1.14674, ν 1.14537 at
    # δ = -1/β; mussv's upper and lower bounds meet at 1.14559 on a 301-point grid) and
    # under Sandybridge (another design: β 1.12986, ν 1.12853), 2026-12-01; 2e-3
    # allows the certificate's documented 1e-3 and the δ sampling
    assert beta <= max(norms) * (1 + 2e-3)


def test_musyn_blk_goes_with_certain_plants_only():
    with pytest.raises(ParameterError, match="carries its block structure"):
        musyn(uncertain_oscillator(), 1, 1, BLK)
    with pytest.raises(ParameterError, match="blk is required"):
        musyn(oscillator(), 1, 1)


def test_the_ureal_model_is_the_hand_built_lft():
    """uncertain_stiffness_oscillator (ureal, uss) against stiffness_oscillator (the LFT
    written by hand): equal at every stiffness in the range (usubs against F_u of the
    hand-built plant with the same δ), the normalisation of the two LFTs aside."""
    Pu, ex = uncertain_stiffness_oscillator(), stiffness_oscillator()
    assert lftdata(Pu).blk.to_blk().tolist() == [[-1, 0]]
    w = np.logspace(-2, 2, 9)
    for delta in (-1.0, -0.3, 0.0, 0.7, 1.0):
        direct = usubs(Pu, {"k": 1.0 + 0.5 * delta})
        # F_u(P, δ): the δ channel moved last, closed as a lower LFT
        order = [1, 2, 3, 0]
        A, B, C, D = (np.asarray(m) for m in (ex.P.A, ex.P.B, ex.P.C, ex.P.D))
        Pp = control.ss(A, B[:, order], C[order], D[np.ix_(order, order)])
        Fu = lft(Pp, control.ss([], [], [], [[delta]]), 1, 1)
        np.testing.assert_allclose(freqresp(direct, w), freqresp(Fu, w), rtol=1e-9,
                                   atol=1e-12)


@pytest.mark.slow  # 56 s on Zen 1 (2026-12-02): the second tier
def test_constraints_ride_in_the_dgk_k_step():
    """Issue 37, item 3: with a real block kept real, constraints still ride in the LMI
    K-step.  The plant of tests/test_musyn_constraints.py (G = 2/(s+1), 40 % input
    uncertainty, here a real scalar) and its peak bound on the commanded control, at
    0.30, where the same D-G-K without the constraint reaches 0.3745 (measured
    2026-11-27).  Recomputed here from the returned controller: the peak (controllability
    Gramian, scipy) and mixed µ on the test's grid, below the all-frequency bound."""
    import scipy.linalg

    from lmi_suspension.synthesis.constraints import Channel, PeakBound

    P = control.ss([[-1.0]], [[2.0, 0.0, 2.0, 2.0]], [[0.0], [0.5], [0.0], [1.0]],
                   [[0.0, 0.0, 0.0, 0.4], [0.0, 0.5, 0.0, 0.0], [0.0, 0.0, 0.0, 1.0],
                    [0.0, 1.0, 0.0, 0.0]])
    blk = [[-1, 0], [1, 1]]
    res = musyn(P, 1, 1, blk, omega=np.logspace(-2, 2, 30),
                options=MusynOptions(method="lmi", max_iter=3, patience=1,
                                     max_dfit_order=2, n_dense=40),
                constraints=[PeakBound(Channel(outputs=(2,), inputs=(2,)), (0.30,))])
    assert res.certificates[0].met
    CL = lft(P, res.K, 1, 1)
    assert np.max(np.linalg.eigvals(np.asarray(CL.A)).real) < 0
    A, B, C = np.asarray(CL.A), np.asarray(CL.B)[:, [2]], np.asarray(CL.C)[[2]]
    Wc = scipy.linalg.solve_continuous_lyapunov(A, -B @ B.T)
    assert float(np.sqrt(C @ Wc @ C.T)[0, 0]) <= 0.30 * (1 + 1e-4)
    w = np.logspace(-3, 3, 121)
    Mss = control.ss(CL.A, np.asarray(CL.B)[:, :2], np.asarray(CL.C)[:2],
                     np.asarray(CL.D)[:2, :2])
    mu = mussv(freqresp(Mss, w), blk, omega=w)
    assert np.max(mu.lower) <= np.max(mu.upper) <= res.mu_bound * (1 + 1e-3)
    assert res.mu_lower_peak <= res.mu_peak * (1 + 1e-6) <= res.mu_bound * (1 + 1e-6)
    # mu_bound from above, by the main loop theorem (no µ code): each real |δ| <= 1/β
    # closed on the real block leaves a stable loop of norm ν <= β, and µ >= min(β, ν)
    # (a complex performance block of size 1/ν makes I - MΔ singular), so β may exceed
    # the largest ν only by the certificate's slack
    beta = res.mu_bound
    Mp = control.ss(Mss.A, np.asarray(Mss.B)[:, [1, 0]], np.asarray(Mss.C)[[1, 0]],
                    np.asarray(Mss.D)[np.ix_([1, 0], [1, 0])])  # the real channel last
    norms = []
    for delta in np.linspace(-1, 1, 21) / beta:
        closed = lft(Mp, control.ss([], [], [], [[delta]]), 1, 1)
        assert np.max(np.linalg.eigvals(np.asarray(closed.A)).real) < 0
        norms.append(float(hinfnorm(closed)[0]))
    assert max(norms) <= beta * (1 + 1e-6)
    # β / max ν measured 1.0060 (β 0.50301, ν 0.5 at δ = -1/β, where mussv's bounds
    # meet at 0.5000 as ω -> ∞: the certificate's 20 splits stop 0.6 % above it;
    # 2026-12-01, Haswell and Sandybridge kernels): 1 % allowed
    assert beta <= max(norms) * (1 + 1e-2)


# ---------------------------------------------------------------- mutation pass (issue 59)
@pytest.mark.parametrize("poles", [[0.0, 1.0], [-1.0, 2.0], []])
def test_gscale_basis_poles_must_have_positive_real_parts(poles):
    """gfit's module docstring: the basis poles ``c_k`` have ``Re c_k > 0``.  A pole at 0
    makes the basis ``ω/(c² + ω²) = 1/ω`` and the all-pass ``(c - s)/(c + s) = -1``, so
    ``H`` and ``T`` would have a pole at s = 0: refused like a negative one, and an empty
    basis too."""
    from lmi_suspension.errors import DimensionError

    w = np.logspace(-1, 1, 11)
    with pytest.raises(DimensionError, match="positive real parts"):
        fit_gscales(w, [0.1 * w / (1 + w**2)], BlockStructure.from_blk([[-1, 0]]), 1.0,
                    poles=poles)


def _pair(zeta, wn):
    return control.tf([wn**2], [1, 2 * zeta * wn, wn**2])


def test_resonances_are_the_lightly_damped_poles_and_their_half_power_edges():
    """dgstep.resonances (its docstring): per pole pair of damping ζ < 0.3 inside the
    grid's range, |p|, |p| (1 ± ζ) and |Im p|; nothing for a well-damped pair (ζ 0.5), a
    real pole, or a pair beyond the grid (1e4 rad/s).  Reference: the poles placed here,
    ζ = 0.05 at 2 rad/s: 2, 1.9, 2.1 and 2 sqrt(1 - ζ²)."""
    from lmi_suspension.mu.steps.dgstep import resonances

    CL = control.ss(_pair(0.05, 2.0) + _pair(0.5, 5.0) + _pair(0.05, 1e4)
                    + control.tf([1.0], [1.0, 3.0]))
    expect = np.sort([2.0, 2.0 * 0.95, 2.0 * 1.05, 2.0 * np.sqrt(1 - 0.05**2)])
    np.testing.assert_allclose(resonances(CL, np.logspace(-1, 2, 50)), expect, rtol=1e-9)


def test_the_dg_step_takes_mu_at_resonances_between_the_grid_points():
    """MussvStep with constraints also takes µ at the loop's resonances, and the peak is
    the larger.  A 1x1 complex full block, whose µ is |M| by definition (reference: the
    loop's response evaluated here), and a pair of ζ = 0.01 at 1.05 rad/s between the
    grid points 1 and 2: without constraints the grid's peak |M(j1)| = 10.5, with them
    the resonance's, 50.0, at its frequency; the lower bound goes with it."""
    from lmi_suspension.mu.steps import DKSetup
    from lmi_suspension.mu.steps.dgstep import MussvStep, resonances

    CL = control.ss(_pair(0.01, 1.05))
    omega = np.array([0.5, 1.0, 2.0])
    struct = BlockStructure.coerce([[1, 1]])

    def step(constraints):
        setup = DKSetup(G=None, struct=struct, dk_struct=struct, mixed=False, free=(0, 0),
                        omega=omega, options=None, rng=np.random.default_rng(0),
                        constraints=constraints)
        return MussvStep(setup)(CL, None)

    def gain(w):
        return abs(complex(CL(1j * w)))

    plain = step(())
    assert plain.mu_peak == pytest.approx(max(gain(w) for w in omega), rel=1e-6)
    at = resonances(CL, omega)
    k = int(np.argmax([gain(w) for w in at]))
    assert gain(at[k]) > 4 * plain.mu_peak
    found = step(("a constraint",))
    assert found.mu_peak == pytest.approx(gain(at[k]), rel=1e-6)
    assert found.peak_omega == at[k]
    assert found.lower_peak == pytest.approx(gain(at[k]), rel=1e-6)


def test_the_best_route_replaces_an_earlier_controller_only_beyond_the_slack():
    """_k_step with method="best": a later route replaces an earlier one only when it
    certifies lower by more than ``_KSTEP_RTOL`` (its comment: the LMI would otherwise win
    ties).  Injected syntheses: the plant as given certifies 1.0, the diagonally
    balanced one 0.05 % or 0.2 % lower; both beat the previous controller's 10, so the
    Gramian-balanced realization and the LMI are not tried."""
    from types import SimpleNamespace

    from lmi_suspension.mu.steps.kstep import _KSTEP_RTOL, _k_step

    PD = control.ss([[-1.0]], [[1.0, 1.0]], [[1.0], [1.0]], np.zeros((2, 2)))

    def run(second):
        calls = []

        def synthesis(P, nmeas, ncon, *, method, options, **heuristics):
            calls.append((method, options.riccati_scale))
            return SimpleNamespace(gamma=second if options.riccati_scale else 1.0)

        best = _k_step(synthesis, PD, 1, 1, MusynOptions(method="best"), gamma_prev=10.0)
        return best.gamma, calls

    gamma, calls = run(1 - 0.5 * _KSTEP_RTOL)
    assert gamma == 1.0 and calls == [("riccati", False), ("riccati", True)]
    assert run(1 - 2 * _KSTEP_RTOL)[0] == 1 - 2 * _KSTEP_RTOL


def test_an_initial_controller_that_leaves_a_marginal_pole_is_refused():
    """``K0`` must stabilise the loop: x' = u + w, y = z = x with K0 = 0 leaves the pole
    at s = 0 (marginal, not stable) and is refused; K0 = -1 gives 1/(s + 1), whose norm
    1 (at ω = 0) is the certified γ."""
    from lmi_suspension.lti.plant import GeneralizedPlant
    from lmi_suspension.mu.steps.kstep import initial_controller

    G = GeneralizedPlant.from_statespace(
        control.ss([[0.0]], [[1.0, 1.0]], [[1.0], [1.0]], np.zeros((2, 2))), 1, 1)
    struct = BlockStructure.coerce([[1, 1]])
    with pytest.raises(ParameterError, match="does not stabilise"):
        initial_controller(control.ss([], [], [], [[0.0]]), G, struct, ())
    given = initial_controller(control.ss([], [], [], [[-1.0]]), G, struct, ())
    assert given.gamma == pytest.approx(1.0, rel=1e-6)


def test_overrelaxed_extrapolates_the_d_steps_change_geometrically():
    """fit._overrelaxed: ``previous (d / previous)^α`` per block (_OverRelaxation's
    docstring): previous 2, D-step 4 and α = 1.5 give 2 · 2^1.5; an unchanged entry stays;
    α = 1 gives the D-step itself."""
    from lmi_suspension.mu.steps.fit import _overrelaxed

    out = _overrelaxed([np.array([4.0, 3.0])], [np.array([2.0, 3.0])], 1.5)
    np.testing.assert_allclose(out[0], [2.0 * 2.0**1.5, 3.0], rtol=1e-12)
    np.testing.assert_allclose(_overrelaxed([np.array([4.0])], [np.array([2.0])], 1.0)[0],
                               [4.0], rtol=1e-12)


def test_scaled_peak_is_the_norm_of_the_d_scaled_loop():
    """fit._scaled_peak: max over ω of σ̄(D̂_L(jω) M D̂_R(jω)⁻¹) (its docstring), for a 2x1
    full block (one z row, two w columns of M: ``BlockStructure.shape_M``) and a 1x1
    block, computed here with matrices from the fits' own responses: D̂_L = diag(d_1, d_2)
    on M's rows, D̂_R = diag(d_1, d_1, d_2) on its columns, d_1 = (s + 2)/(s + 1),
    d_2 = 1."""
    from lmi_suspension.mu.steps.fit import _scaled_peak

    struct = BlockStructure.coerce([[2, 1], [1, 1]])
    assert struct.shape_M == (2, 3)
    rng = np.random.default_rng(3)
    w = np.array([0.1, 1.0, 3.0, 10.0])
    M = rng.standard_normal((2, 3, w.size)) + 1j * rng.standard_normal((2, 3, w.size))
    fits = [control.ss(control.tf([1.0, 2.0], [1.0, 1.0])), control.ss([], [], [], [[1.0]])]
    ref = 0.0
    for k, x in enumerate(1j * w):
        d1 = complex(fits[0](x))
        DL, DR = np.diag([d1, 1.0]), np.diag([d1, d1, 1.0])
        ref = max(ref, np.linalg.norm(DL @ M[:, :, k] @ np.linalg.inv(DR), 2))
    assert _scaled_peak(fits, M, w, struct) == pytest.approx(ref, rel=1e-12)


# the oscillator's D-G-K runs of the tests below: a coarse grid and Riccati K-steps keep
# them to a few seconds; they test the loop's rules, not the µ reached
# (full order: these tests follow the loop's choice of controller, not its reduction)
_QUICK = {"method": "riccati", "dscale_search": 0, "n_dense": 10, "max_gfit_poles": 3,
          "reduce_order": None}
_QUICK_W = np.logspace(-2, 1.5, 12)


def _coarse_dense_grid(monkeypatch):
    """The returned loop's µ certified on the design grid itself (the dense grid's 400+
    mixed-µ LMIs are what makes these runs long; the rule under test is the same)."""
    from lmi_suspension.mu import dk

    monkeypatch.setattr(dk, "_dense_grid", lambda omega, n, peak, CL: np.asarray(omega))


def test_the_complexified_controller_is_kept_where_dgk_certifies_higher(monkeypatch):
    """Injection: in the D-G-K phase, from iteration 2 on, the K-step returns a worse
    controller (the central H∞ one at twice the optimal level) and the D/G-step reports
    half its µ, so the loop takes it for its best.  The dense-grid certificate, computed
    apart from the steps, finds it above the complexified D-K's controller
    (``complex_candidate="keep"``), which must then be returned, and the result says
    so."""
    from dataclasses import replace

    from lmi_suspension import HinfsynOptions
    from lmi_suspension.mu.steps import DKSteps
    from lmi_suspension.mu.steps.dgstep import MussvStep
    from lmi_suspension.mu.steps.kstep import _GivenController, default_kstep

    _coarse_dense_grid(monkeypatch)
    P = oscillator()
    struct = BlockStructure.coerce(BLK)
    g_opt = hinfsyn(P, 1, 1, method="riccati").gamma
    poor = hinfsyn(P, 1, 1, method="riccati", options=HinfsynOptions(gamma=2 * g_opt)).K

    class Worse:
        def __init__(self, setup):
            self.mixed, self.inner = setup.mixed, default_kstep(setup)

        def __call__(self, PD, *, iteration, gamma_prev):
            if self.mixed and iteration >= 2:
                return _GivenController(poor, float(gamma_prev), ("injected",))
            return self.inner(PD, iteration=iteration, gamma_prev=gamma_prev)

    class Lying(MussvStep):
        def __call__(self, CL, K):
            here = super().__call__(CL, K)
            if self.setup.mixed and K is poor:
                return replace(here, mu_peak=here.mu_peak / 2, lower_peak=here.mu_peak / 2,
                               upper=here.upper / 2)
            return here

    res = musyn(P, 1, 1, BLK, omega=_QUICK_W, steps=DKSteps(kstep=Worse, dgstep=Lying),
                options=MusynOptions(max_iter=2, complex_candidate="keep", **_QUICK))
    assert [h.K is poor for h in res.history] == [False, True]  # the injection took hold
    assert res.best_iteration == 0 and res.K is res.complex_run.K
    assert "complexified D-K's controller is returned" in res.stop_reason
    # the two routes: the injected iterate's µ recomputed here on the dense grid is above
    # what the returned controller certifies there (each loop's own LMI-refined bound)
    dense = res.mu.omega
    mu_poor = mussv(freqresp(_mu_part(lft(P, poor), struct), dense), struct, omega=dense)
    assert float(np.max(mu_poor.lower)) > res.mu_peak
    assert res.complex_run.mu_peak == pytest.approx(res.mu_peak, rel=0, abs=0)
    # certificates of the returned controller: poles, bounds in order, bound recomputed
    assert np.all(res.CL.poles().real < 0)
    assert res.mu_lower_peak <= res.mu_peak
    again = mussv(freqresp(_mu_part(lft(P, res.K), struct), dense), struct, omega=dense,
                  method="lmi")
    assert float(np.max(again.upper)) == pytest.approx(res.mu_peak, rel=2e-3)  # LMI tol


def _steered_dg_step(factors, made):
    """A D/G-step factory whose instances of the mixed phase report µ scaled by
    ``factors[i][iteration - 1]`` (their i-th instance: each ``_dk_loop`` builds its
    own), and records each mixed instance's controllers in ``made``."""
    from dataclasses import replace

    from lmi_suspension.mu.steps.dgstep import MussvStep

    class Steered(MussvStep):
        def __init__(self, setup):
            super().__init__(setup)
            self.calls = []
            if setup.mixed:
                made.append(self.calls)
                self.factors = factors[len(made) - 1] if len(made) <= len(factors) else ()

        def __call__(self, CL, K):
            here = super().__call__(CL, K)
            if not self.setup.mixed:
                return here
            self.calls.append(K)
            f = self.factors[len(self.calls) - 1] if len(self.calls) <= len(self.factors) \
                else 1.0
            return replace(here, mu_peak=here.mu_peak * f, upper=here.upper * f,
                           lower_peak=min(here.lower_peak, here.mu_peak * f))

    return Steered


def _mixed_mu(P, K, omega):
    """Mixed µ upper bound peak of ``F_l(P, K)`` on ``omega`` by the LMI (no AB13MD,
    no musyn code)."""
    from lmi_suspension.mu.bounds import MussvOptions

    struct = BlockStructure.coerce(BLK)
    mu = mussv(freqresp(_mu_part(lft(P, K), struct), omega), struct, omega=omega,
               method="lmi", options=MussvOptions(compute_lower=False))
    return float(np.max(mu.upper))


def test_auto_goes_on_from_the_complexified_controller_where_its_first_k_step_improves(
        monkeypatch):
    """``complex_candidate="auto"`` (the default): D-G-K starts from the complexified
    controller; its first iterate is reported 10 % below its mixed µ (so below the
    controller's complex µ: the start is tried) and its second at 45 % (an
    improvement), so that start is kept: one mixed phase only, its first iterate the
    complexified controller, every record reported to the callback once decided.  Its
    third iterate, reported as it is (more than ``_DGK_REGRESSION`` above the best as
    reported), ends D-G-K before ``max_iter``.  The result is certified apart: its mixed
    µ (LMI bound, recomputed here) is no higher than the complexified controller's on
    the same grid (issue 64's invariant)."""
    from lmi_suspension.mu.steps import DKSteps

    _coarse_dense_grid(monkeypatch)
    P = oscillator()
    made, seen = [], []
    res = musyn(P, 1, 1, BLK, omega=_QUICK_W, callback=seen.append,
                steps=DKSteps(dgstep=_steered_dg_step([(0.9, 0.45)], made)),
                options=MusynOptions(max_iter=4, max_dfit_order=1, **_QUICK))
    assert len(made) == 1  # no D-G-K from the beginning
    assert made[0][0] is res.complex_run.K and res.history[0].K is res.complex_run.K
    assert seen == list(res.history) and not res.complex_run.start_history
    assert len(res.history) == 3 and "more than 2% above the best" in res.stop_reason
    assert np.all(res.CL.poles().real < 0) and res.mu_lower_peak <= res.mu_peak
    dense = res.mu.omega
    assert _mixed_mu(P, res.K, dense) == pytest.approx(res.mu_peak, rel=2e-3)  # LMI tol
    assert res.mu_peak <= _mixed_mu(P, res.complex_run.K, dense) * (1 + 2e-3)


@pytest.mark.parametrize("factors", [(0.9, 2.0), (1.5,)])
def test_auto_abandons_the_complexified_start_where_it_does_not_improve(monkeypatch,
                                                                         factors):
    """``complex_candidate="auto"``: the start from the complexified controller is
    abandoned where its second iterate (its first K-step) is reported at twice its µ,
    after that iterate; or where its first iterate is reported at 1.5 times its mixed µ
    (then above the controller's complex µ: G = 0 is optimal at its peak), at once.  Its
    records are kept in ``complex_run.start_history``, not reported, and D-G-K starts
    from the beginning (a second mixed phase, whose first controller is its own
    K-step's).  The result is certified apart and no worse than the complexified
    controller."""
    from lmi_suspension.mu.steps import DKSteps

    _coarse_dense_grid(monkeypatch)
    P = oscillator()
    made, seen = [], []
    res = musyn(P, 1, 1, BLK, omega=_QUICK_W, callback=seen.append,
                steps=DKSteps(dgstep=_steered_dg_step([factors], made)),
                options=MusynOptions(max_iter=2, max_dfit_order=1, **_QUICK))
    assert len(made) == 2 and len(made[0]) == len(factors)
    trial = res.complex_run.start_history
    assert len(trial) == len(factors) and trial[0].K is res.complex_run.K
    assert f"abandoned at iteration {len(factors)}" in res.stop_reason
    assert seen == list(res.history) and res.history[0].K is not res.complex_run.K
    assert all(rec.K is not K for rec in res.history for K in made[0])
    assert np.all(res.CL.poles().real < 0) and res.mu_lower_peak <= res.mu_peak
    dense = res.mu.omega
    assert _mixed_mu(P, res.K, dense) == pytest.approx(res.mu_peak, rel=2e-3)
    assert res.mu_peak <= _mixed_mu(P, res.complex_run.K, dense) * (1 + 2e-3)


def test_dgk_stops_after_an_iterate_past_the_regression_bound():
    """``_regressed``: the best iterate itself and one within ``_DGK_REGRESSION`` of the
    best go on; one above it stops D-G-K, saying which iterates."""
    from lmi_suspension.mu import dk

    best = (1.6085, None, 5)
    assert dk._regressed(5, 1.6085, best) is None
    assert dk._regressed(6, 1.6085 * (1 + 0.99 * dk._DGK_REGRESSION), best) is None
    said = dk._regressed(6, 1.7507, best)
    assert "iterate 6 (µ 1.7507)" in said and "iterate 5 (1.6085)" in said


def test_a_time_budget_ends_both_phases_after_their_first_iterate_and_says_so(monkeypatch):
    """A budget far below one iteration: the complexified phase and D-G-K each stop
    after their first iterate (the unit the budget counts in), the result is that
    iterate's certified controller, and ``stop_reason`` names the budget."""
    _coarse_dense_grid(monkeypatch)
    P = oscillator()
    res = musyn(P, 1, 1, BLK, omega=_QUICK_W,
                options=MusynOptions(max_iter=6, time_budget=1e-3, **_QUICK))
    assert len(res.history) == 1 and len(res.complex_run.history) == 1
    assert "time budget of 0.001 s" in res.stop_reason
    assert "time budget of 0.001 s" in res.complex_run.stop_reason
    assert np.all(res.CL.poles().real < 0) and res.mu_lower_peak <= res.mu_peak
    with pytest.raises(ParameterError):
        MusynOptions(time_budget=0.0)
    with pytest.raises(ParameterError):
        MusynOptions(max_gfit_poles=0)
    with pytest.raises(ParameterError):
        MusynOptions(complex_candidate="complex")


def test_max_gfit_poles_caps_the_states_the_g_scalings_add(loop, monkeypatch):
    """With a level target no basis reaches, ``optimal_gscales`` tries every basis size
    of ``_G_POLE_COUNTS``; ``max_poles`` stops it at the largest size within the cap (or
    the cap itself below the smallest), and the scaled plant then has at most three
    states per pole and real block more than the D-scaled one (gfit's docstring)."""
    from lmi_suspension.mu import gfit

    P, _, struct, w, M = loop
    tried = []
    inner = gfit._optimal_gscales

    def recorded(omega, Mt, struct, poles, g_max):
        tried.append(len(poles))
        return inner(omega, Mt, struct, poles, g_max)

    monkeypatch.setattr(gfit, "_optimal_gscales", recorded)
    optimal_gscales(w, M, struct, target=1e-3)
    assert tried == list(gfit._G_POLE_COUNTS)
    for cap, sizes in ((4, [3]), (2, [2])):
        tried.clear()
        capped = optimal_gscales(w, M, struct, target=1e-3, max_poles=cap)
        assert tried == sizes and capped.poles[0].size == sizes[-1]
        PG = gscaled_plant(P, 1, 1, struct, capped)
        assert PG.nstates <= P.nstates + 3 * sizes[-1]


@pytest.mark.slow  # 290 s on Zen 1 (2026-12-02): the second tier
def test_two_mass_mixed_musyn_is_no_worse_than_its_complexified_controller():
    """The two-mass plant (two real parameters, issue 64): default ``musyn`` runs the
    complexified D-K and D-G-K, and returns the lower certified mixed µ.  Checked apart
    from musyn: the returned loop's poles and mixed µ (LMI bound on the dense grid), and
    the complexified controller's mixed µ on the same grid, which the result must not
    exceed (0.1 %: the two controllers' certificates were taken on grids around their
    own peaks)."""
    from lmi_suspension.examples import uncertain_two_mass

    res = musyn(uncertain_two_mass(), 1, 1)
    data = lftdata(uncertain_two_mass())
    struct = BlockStructure.coerce(data.blk.to_blk().tolist() + [[1, 2]])
    P = data.M
    dense = res.mu.omega
    assert np.all(res.CL.poles().real < 0)
    assert res.mu_lower_peak <= res.mu_peak
    mine = mussv(freqresp(_mu_part(lft(P, res.K), struct), dense), struct, omega=dense,
                 method="lmi")
    assert float(np.max(mine.upper)) == pytest.approx(res.mu_peak, rel=2e-3)
    theirs = mussv(freqresp(_mu_part(lft(P, res.complex_run.K), struct), dense), struct,
                   omega=dense, method="lmi")
    assert res.mu_peak <= float(np.max(theirs.upper)) * (1 + 1e-3)


def test_mixed_bounds_keep_mussvs_upper_bound_and_its_lower_peak(loop):
    """``mixed_bounds`` (the D/G-step's and the dense certificate's µ with real blocks)
    computes the lower bound at the highest upper bounds only: its upper bounds are
    ``mussv``'s own at every frequency, its lower bound is ``mussv``'s where computed
    and 0 elsewhere, and its peak is the peak of ``mussv``'s lower bound computed here at
    every frequency (power iteration: 1e-4)."""
    from lmi_suspension.mu.steps import dgstep

    _, _, struct, w, M = loop
    w, M = w[::2], M[:, :, ::2]  # 13 points: the reference's lower bound is the cost
    assert dgstep.lower_where_it_counts(struct)
    assert not dgstep.lower_where_it_counts(BlockStructure.coerce([[1, 1], [2, 2]]))
    assert not dgstep.lower_where_it_counts(BlockStructure.coerce([[-2, 0], [2, 2]]))
    got = dgstep.mixed_bounds(M, struct, w, np.random.default_rng(0))
    full = mussv(M, struct, omega=w, rng=np.random.default_rng(0))
    assert full.method == got.method == "ab13md"
    np.testing.assert_allclose(got.upper, full.upper, rtol=1e-12)
    lower = np.asarray(got.lower)
    assert np.all(lower <= np.asarray(got.upper))
    assert 1 <= np.count_nonzero(lower) <= dgstep._LOWER_POINTS + dgstep._LOWER_PEAKS
    assert np.max(lower) == pytest.approx(float(np.max(full.lower)), rel=1e-4)
    assert np.argmax(lower) == np.argmax(full.upper) or np.max(lower) >= np.max(full.lower)


def test_every_dgk_k_step_sees_a_scaled_plant_within_the_fit_caps(monkeypatch):
    """The order of the plant each K-step sees is bounded by the caps of the fits
    (issue 64): the plant's states, each D fit's order (``max_dfit_order``) on the
    ``z`` and ``w`` channels of its block (the last block's D is 1), and three states per
    G basis pole (``max_gfit_poles``) and real channel (gfit's docstring).  Recorded at
    every K-step of a short run of both phases; the returned loop is checked apart
    (poles, bounds in order)."""
    from lmi_suspension.mu.steps import DKSteps
    from lmi_suspension.mu.steps.kstep import HinfKStep

    _coarse_dense_grid(monkeypatch)
    ex = stiffness_oscillator()
    struct = BlockStructure.coerce(BLK)
    seen = []

    class Recorded(HinfKStep):
        def __call__(self, PD, *, iteration, gamma_prev):
            seen.append((self.setup.mixed, iteration, PD.nstates))
            return super().__call__(PD, iteration=iteration, gamma_prev=gamma_prev)

    opts = MusynOptions(max_iter=3, patience=3, max_dfit_order=2,
                        **dict(_QUICK, max_gfit_poles=2))
    res = musyn(ex.P, 1, 1, BLK, omega=_QUICK_W, options=opts, steps=DKSteps(kstep=Recorded))
    d_states = sum(2 * (b.rows + b.cols) for b in struct.blocks[:-1])  # order 2 per channel
    g_states = 3 * 2 * sum(b.rows for b in struct.blocks if b.is_real)
    later = [(mixed, n) for mixed, it, n in seen if it > 1]
    assert any(mixed for mixed, _ in later) and any(not mixed for mixed, _ in later)
    for mixed, n in later:
        assert n <= ex.P.nstates + d_states + (g_states if mixed else 0)
    assert np.all(res.CL.poles().real < 0) and res.mu_lower_peak <= res.mu_peak


def test_the_direct_lmi_route_reaches_cvxpys_optimum_and_refuses_an_infeasible_one():
    """:func:`~lmi_suspension.mu.lmisolve.solve_lmi` (the optimal G-scalings' SDP posed
    for Clarabel without CVXPY) against the same problem modelled in CVXPY (the route
    the project used before, 2026-12-02): a complex Hermitian LMI with a bound on the
    variables; the optimum agrees to the solvers' tolerance and the LMI holds at the
    returned point.  An infeasible problem is a SolverError, not a point."""
    import warnings

    import cvxpy as cp

    from lmi_suspension.errors import SolverError
    from lmi_suspension.mu.lmisolve import solve_lmi

    rng = np.random.default_rng(7)
    m = 3

    def herm():
        X = rng.standard_normal((m, m)) + 1j * rng.standard_normal((m, m))
        return X + X.conj().T

    A0, A1, A2 = herm(), herm(), herm()
    G = np.array([[0.0, 1, 0], [0, -1, 0], [0, 0, 1], [0, 0, -1]])
    sol = solve_lmi([1.0, 0, 0], [-A0], [[np.eye(m), -A1, -A2]], G=G, h=np.ones(4))
    t, x = cp.Variable(), cp.Variable(2)
    L = t * np.eye(m) - A0 - x[0] * A1 - x[1] * A2
    with warnings.catch_warnings():
        # CVXPY's route is the reference here; under OPENBLAS_CORETYPE=Sandybridge it
        # ends AlmostSolved on this problem (2026-12-02), within the tolerance below
        warnings.filterwarnings("ignore", message="Solution may be inaccurate")
        cp.Problem(cp.Minimize(t), [(L + L.H) / 2 >> 0, cp.abs(x) <= 1]).solve(
            solver=cp.CLARABEL)
    assert sol.status == "optimal"
    assert sol.x[0] == pytest.approx(float(t.value), rel=1e-5)
    Lx = sol.x[0] * np.eye(m) - A0 - sol.x[1] * A1 - sol.x[2] * A2
    assert np.min(np.linalg.eigvalsh(Lx)) >= -1e-6 and np.all(np.abs(sol.x[1:]) <= 1 + 1e-7)
    with pytest.raises(SolverError):  # t I ⪰ A0 with t <= min eig(A0) - 1
        solve_lmi([1.0], [-A0], [[np.eye(m)]], G=[[1.0]],
                  h=[np.min(np.linalg.eigvalsh(A0)) - 1.0])


def _rigid_body_plant():
    """A double integrator (split by roundoff as in the D-scaled two-mass plants) moved
    by u, beside a slow stable mode (-2e-7; the scalings' slowest was -4.7e-7) u does not
    reach, and fast well-damped modes with small Hankel singular values: inputs [w, u],
    outputs [z, y]."""
    eps = 5e-16
    A = np.zeros((6, 6))
    A[0, 1], A[1, 0] = 1.0, eps  # ±2.2e-8
    A[2, 2] = -2e-7
    A[3:5, 3:5] = [[-50.0, 20.0], [-20.0, -50.0]]
    A[5, 5] = -300.0
    B = np.zeros((6, 2))
    B[:, 0] = [0.0, 1.0, 1e-3, 1e-2, 1e-2, 1e-2]
    B[1, 1] = 1.0
    C = np.zeros((2, 6))
    C[0] = [1.0, 0.0, 1e-3, 1e-2, 0.0, 1e-2]
    C[1, 0] = 1.0
    D = np.array([[0.0, 1.0], [1.0, 0.0]])
    return control.ss(A, B, C, D)


def test_a_rigid_body_mode_beside_a_slow_stable_one_is_stabilisable():
    """The D-G-K run on the two-mass plant ended on "(A, B2) is not stabilisable" at
    s = ±4.6e-8j (2026-12-02): the PBH test on the whole A saw the slow stable mode next
    to the rigid-body one.  On the unstable block of an ordered Schur form the test
    passes, and it still refuses a mode u cannot reach (the same plant with u cut from
    the rigid body)."""
    from lmi_suspension.errors import InfeasibleError
    from lmi_suspension.synthesis.checks import check_stabilizable
    from lmi_suspension.synthesis.hinfsyn import _as_plant

    P = _rigid_body_plant()
    check_stabilizable(_as_plant(P, 1, 1))
    cut = control.ss(P.A, np.column_stack([np.asarray(P.B)[:, 0], np.zeros(6)]), P.C, P.D)
    with pytest.raises(InfeasibleError, match="not stabilisable"):
        check_stabilizable(_as_plant(cut, 1, 1))


def test_the_k_steps_reduced_plant_keeps_its_error_bound_and_the_axis_modes(caplog):
    """:func:`~lmi_suspension.mu.steps.fit.reduced_for_kstep`: fewer states, the
    near-axis modes kept (not truncated), and the frequency response within the
    returned balanced-truncation bound (computed here on a grid, apart from the SLICOT
    route); a failing reduction (injected) leaves the plant whole and says so at INFO."""
    import logging

    from lmi_suspension.mu.steps import fit as fitmod

    P = _rigid_body_plant()
    Pr, bound = fitmod.reduced_for_kstep(P, tol=1e-2)
    assert Pr.nstates < P.nstates and 0 < bound <= 1e-2
    ev = np.linalg.eigvals(np.asarray(Pr.A))
    assert np.sum(np.abs(ev) < 1e-6) == 3  # the double integrator and the slow mode
    w = np.logspace(-1, 4, 300)
    err = max(np.linalg.norm(np.asarray(P(1j * x)) - np.asarray(Pr(1j * x)), 2) for x in w)
    assert err <= bound * (1 + 1e-6) + 1e-9
    with caplog.at_level(logging.INFO, logger=fitmod.__name__):
        def broken(*a, **k):
            raise ValueError("injected")
        import slycot
        orig = slycot.ab09ad
        slycot.ab09ad = broken
        try:
            same, b0 = fitmod.reduced_for_kstep(P, tol=1e-2)
        finally:
            slycot.ab09ad = orig
    assert same is P and b0 == 0.0
    assert any("no reduction" in r.getMessage() and r.levelno == logging.INFO
               for r in caplog.records)


@pytest.mark.parametrize("changed", [False, True])
def test_a_reduced_k_step_plant_is_used_only_where_the_previous_loop_keeps_its_level(
        loop, monkeypatch, caplog, changed):
    """D-G-K's fit step hands the K-step the reduced scaled plant only where the
    controller it was built around has the same norm on it as on the full plant (an
    open-loop truncation bound says nothing through the loop; the seat over m3 and k1:
    1.77 against 1.00, 2026-12-02).  Injected: a "reduction" that is the full plant in
    another realization (kept), and one whose w -> z feedthrough moved (refused: the
    full plant, with the previous controller's norm on it, and an INFO record)."""
    import logging

    from lmi_suspension.mu.dk import _setup
    from lmi_suspension.mu.steps import fit as fitmod
    from lmi_suspension.mu.steps.dgstep import MussvStep

    P, K, struct, w, M = loop
    setup, _ = _setup(P, 1, 1, BLK, w, MusynOptions(max_gfit_poles=2, max_dfit_order=1),
                      np.random.default_rng(0), (), None, None)
    here = MussvStep(setup)(_mu_part(lft(P, K), struct), K)
    full = {}

    def fake(PD, tol=1e-2):
        full["PD"] = PD
        T = np.diag(np.linspace(1.0, 2.0, PD.nstates))  # same plant, other coordinates
        moved = np.zeros_like(np.asarray(PD.D))
        if changed:
            moved[:2, :2] = 0.5
        return control.ss(T @ PD.A @ np.linalg.inv(T), T @ PD.B, PD.C @ np.linalg.inv(T),
                          np.asarray(PD.D) + moved), 1e-3

    monkeypatch.setattr(fitmod, "reduced_for_kstep", fake)
    with caplog.at_level(logging.INFO, logger=fitmod.__name__):
        nxt = fitmod.DGScaleFit(setup)(here, iteration=1, best_iteration=1)
    level = float(hinfnorm(_mu_part(lft(full["PD"], K), struct))[0])
    if changed:
        assert nxt.PD is full["PD"] and nxt.gamma == pytest.approx(level, rel=1e-9)
        assert any("sees it whole" in r.getMessage() and r.levelno == logging.INFO
                   for r in caplog.records)
    else:
        assert nxt.PD is not full["PD"] and nxt.gamma == pytest.approx(level, rel=1e-3)
