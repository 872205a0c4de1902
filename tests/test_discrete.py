"""Discrete-time synthesis and analysis (issue 63, first slice): ``hinfsyn`` by the
discrete bounded-real LMI (on the plant's bilinear image, and on the discrete data
directly) and by SLICOT SB10DD, ``msyn`` with discrete specifications, and the refusal to
mix time bases.

Reference values, each computed in the test by a route that did not produce the result:
* the bilinear (Tustin, unwarped) map sends the imaginary axis onto the unit circle and
  preserves H∞ norms, so the continuous LMI optimum of a plant (``hinfsyn``'s
  ``gamma_lower`` on the continuous plant: no controller of any order does better) is the
  optimum of its Tustin image as well: a lower bound for every discrete controller;
* every discrete controller is certified by ``hinfnorm`` of ``lft(P, K)`` recomputed here,
  by a σ̄ sweep of python-control's own evaluation on the unit circle, and by its poles.
"""

import time

import control
import numpy as np
import pytest

from lmi_suspension.errors import (DiscreteTimeError, InfeasibleError, NotBuiltError,
                                   SampleTimeError, TimebaseError)
from lmi_suspension.examples import compleib
from lmi_suspension.lti import GeneralizedPlant, hinfnorm, lft
from lmi_suspension.lti.norms import h2norm
from lmi_suspension.synthesis import HinfsynOptions, hinfsyn
from lmi_suspension.synthesis.constraints import H2Bound, HalfPlane, HinfBound, Sector
from lmi_suspension.synthesis.hinfsyn import _sb10dd, _without_d22
from lmi_suspension.synthesis.multiobjective import msyn
from mp_reference import freqresp_mp

DT = 0.01
#: the six shipped COMPleib plants of the bilinear check (the others: AC1's infimum is 0,
#: AC6, REA2, NN1 and AC2 take longer; every one of the twelve certifies)
BILINEAR = ["AC4", "HE1", "REA1", "AC3", "DIS1", "NN2"]
#: the issue's acceptance: certified discrete γ within 1e-4 of the continuous optimum.
#: Measured -4.6e-7 to 4.5e-5 on the eight plants at 10 ms under the Haswell,
#: Sandybridge and Nehalem kernels (largest: 1/(s - 1) 4.5e-5, AC3 4.3e-5 under
#: Sandybridge, HE1 4.1e-5 under Nehalem; Zen 1, 2026-12-02)
BUDGET = 1e-4
#: the discrete LMI posed on the discrete data directly (``msyn``, reconstructed 1e-3
#: above its optimum): measured 3e-9 (REA1) to 9.9e-4 (AC3) above the continuous optimum
#: at 10 ms (Haswell, 2026-12-02); where Clarabel ends its minimisation "almost solved"
#: (HE1, AC3, DIS1, NN2 and both plants of our own) it gives no lower bound
DIRECT_BUDGET = 2e-3


def _tustin(name, dt=DT):
    P = compleib(name)
    return P, control.sample_system(P.sys, dt, method="tustin")


def _unit_circle_peak(CL, dt, n=3000):
    """σ̄ on the upper unit circle: python-control's own evaluation of ``CL(z)`` on ``n``
    points, its largest re-evaluated in 40-digit arithmetic (on HE1's closed loop, whose
    poles reach |z| = 0.9985, the double-precision evaluation of the unbalanced
    realization came out 1.4e-6 high, 2026-12-02)."""
    w = np.linspace(0.0, np.pi / dt, n)
    resp = np.asarray(CL(np.exp(1j * w * dt))).reshape(CL.noutputs, CL.ninputs, -1)
    k = int(np.argmax(np.linalg.norm(resp.transpose(2, 0, 1), 2, axis=(1, 2))))
    return float(np.linalg.norm(freqresp_mp(CL, [w[k]])[:, :, 0], 2))


@pytest.mark.parametrize("name", BILINEAR)
def test_the_discrete_optimum_of_a_tustin_plant_is_the_continuous_one(name):
    P, Pd = _tustin(name)
    lower = hinfsyn(P, P.ny, P.nu).gamma_lower  # the continuous LMI optimum
    K, CL, gamma, info = hinfsyn(Pd, P.ny, P.nu)
    assert K.dt == DT and CL.dt == DT
    # the certificate, recomputed: the discrete closed loop's norm and its poles
    gamma_cl = hinfnorm(lft(Pd, K, P.ny, P.nu))[0]
    assert gamma == pytest.approx(gamma_cl, rel=1e-9)
    assert np.all(np.abs(np.linalg.eigvals(np.asarray(CL.A))) < 1)
    # (1e-7, not hinfnorm's rtol of 1e-9: a closed loop this near the optimum is nearly
    # all-pass, and on NN2 hinfnorm returned σ̄ at 0.5999 rad/s where 0.6285 rad/s is
    # 1.7e-8 higher in 40-digit arithmetic, measured 2026-12-02)
    assert _unit_circle_peak(CL, DT) <= gamma * (1 + 1e-7)
    # no controller beats the optimum, and this one is near it
    assert lower * (1 - 1e-6) <= gamma <= lower * (1 + BUDGET)
    # the discrete LMI optimum is the same number (a lower bound the continuous route
    # validated on the image): measured within 2.6e-6 of the continuous one (AC4)
    assert info.gamma_lower == pytest.approx(lower, rel=1e-5)


def _own_plants():
    """Two plants of this project: the unstable scalar plant of hinfsyn's docstring
    (1/(s - 1), weighted control, measurement noise) and a seeded random 5-state plant
    with an unstable mode (``synthesis.examples.random_plant``)."""
    from lmi_suspension.synthesis.examples import random_plant

    scalar = GeneralizedPlant.from_matrices(A=[[1.0]], B1=[[1.0, 0.0]], B2=[[1.0]],
                                            C1=[[1.0], [0.0]], C2=[[1.0]],
                                            D12=[[0.0], [1.0]], D21=[[0.0, 1.0]])
    rand = random_plant(5, 2, 1, 2, 1, rng=np.random.default_rng(63))
    return {"scalar": scalar, "random5": rand}


@pytest.mark.parametrize("name", ["scalar", "random5"])
def test_the_bilinear_check_on_two_plants_of_our_own(name):
    P = _own_plants()[name]
    lower = hinfsyn(P, P.ny, P.nu).gamma_lower
    Pd = control.sample_system(P.sys, DT, method="tustin")
    K, CL, gamma, info = hinfsyn(Pd, P.ny, P.nu)
    assert gamma == pytest.approx(hinfnorm(lft(Pd, K, P.ny, P.nu))[0], rel=1e-9)
    assert np.all(np.abs(np.linalg.eigvals(np.asarray(CL.A))) < 1)
    assert lower * (1 - 1e-6) <= gamma <= lower * (1 + BUDGET)
    assert info.gamma_lower == pytest.approx(lower, rel=1e-5)  # measured 2.4e-7

@pytest.mark.parametrize("name", BILINEAR + ["scalar", "random5"])
def test_the_discrete_lmi_posed_on_the_discrete_data_directly(name):
    # msyn with one H∞ objective is the discrete bounded-real LMI on the discrete data
    # (no bilinear image): certified by the discrete hinfnorm, above the continuous
    # optimum and within DIRECT_BUDGET of it
    P = _own_plants()[name] if name in ("scalar", "random5") else compleib(name)
    lower = hinfsyn(P, P.ny, P.nu).gamma_lower
    Pd = control.sample_system(P.sys, DT, method="tustin")
    G = _without_d22(GeneralizedPlant.from_statespace(Pd, P.ny, P.nu, discrete=True))
    K, CL, gamma, info = msyn(G, P.ny, P.nu, HinfBound())
    assert K.dt == DT and np.all(np.abs(np.linalg.eigvals(np.asarray(CL.A))) < 1)
    assert gamma == pytest.approx(hinfnorm(lft(G, K))[0], rel=1e-9)
    assert lower * (1 - 1e-6) <= gamma <= lower * (1 + DIRECT_BUDGET)


def test_a_plant_without_bilinear_image_is_solved_on_the_discrete_data():
    # a pole at z = -1 has no continuous image (s = infinity): hinfsyn poses the discrete
    # LMI on the discrete data directly; SB10DD's scan (D12, D21 of full rank) is the
    # second route on the same plant: measured 1.720811 against 1.720786 (2026-12-02);
    # each within its own relaxation (gamma_relax 5e-4, riccati_rtol 1e-3) of the other
    Pd = GeneralizedPlant.from_matrices(
        A=[[-1.0, 0.2], [0.0, 0.5]], B1=[[1.0, 0.0], [0.3, 0.0]], B2=[[1.0], [0.5]],
        C1=[[1.0, 0.0], [0.0, 0.0]], C2=[[1.0, 1.0]], D12=[[0.0], [1.0]],
        D21=[[0.0, 1.0]], dt=DT)
    lmi = hinfsyn(Pd, 1, 1)
    assert any("pole at z = -1" in w and "directly" in w for w in lmi.warnings)
    ric = hinfsyn(Pd, 1, 1, method="riccati")
    for r in (lmi, ric):
        assert r.K.dt == DT and np.all(np.abs(r.poles) < 1)
        assert r.gamma == pytest.approx(hinfnorm(lft(Pd, r.K, 1, 1))[0], rel=1e-9)
    assert lmi.gamma == pytest.approx(ric.gamma, rel=1.5e-3)


def test_sb10dd_against_the_lmi_on_the_same_discrete_plant():
    # AC4 meets SB10DD's assumptions (D12, D21 of full rank, no zero on the unit circle)
    P, Pd = _tustin("AC4")
    lmi = hinfsyn(Pd, P.ny, P.nu)
    ric = hinfsyn(Pd, P.ny, P.nu, method="riccati")
    assert ric.gamma == pytest.approx(hinfnorm(lft(Pd, ric.K, P.ny, P.nu))[0], rel=1e-9)
    assert np.all(np.abs(ric.poles) < 1)
    # both certified above the common lower bound; the Riccati search stops within its
    # riccati_rtol (1e-3) of the lowest level SB10DD solves
    assert ric.gamma >= lmi.gamma_lower * (1 - 1e-6)
    assert ric.gamma <= lmi.gamma * (1 + 2e-3)


def test_a_fixed_gamma_on_a_discrete_plant_both_routes():
    # AC4 at 10 ms; the reference is the continuous LMI optimum, a lower bound for every
    # discrete controller of the Tustin image (the bilinear map preserves H∞ norms)
    P, Pd = _tustin("AC4")
    lower = hinfsyn(P, P.ny, P.nu).gamma_lower
    level = 1.2 * lower
    for method in ("lmi", "riccati"):
        K, CL, gamma, info = hinfsyn(Pd, P.ny, P.nu, method=method,
                                     options=HinfsynOptions(gamma=level))
        assert K.dt == DT
        assert gamma == pytest.approx(hinfnorm(lft(Pd, K, P.ny, P.nu))[0], rel=1e-9)
        assert np.all(np.abs(np.linalg.eigvals(np.asarray(CL.A))) < 1)
        # a controller at the level asked for (the certificate's rtol beside it), and no
        # controller beats the optimum
        assert lower * (1 - 1e-6) <= gamma <= level * (1 + 1e-6)
    # below the optimum the discrete LMIs are infeasible; SB10DD returns a controller
    # there (slycot 0.7: one that destabilises the loop, max |z| 1.58, 2026-12-02), and the
    # certificate says it does not achieve the level
    with pytest.raises(InfeasibleError):
        hinfsyn(Pd, P.ny, P.nu, options=HinfsynOptions(gamma=0.9 * lower))
    try:
        ric = hinfsyn(Pd, P.ny, P.nu, method="riccati",
                      options=HinfsynOptions(gamma=0.9 * lower))
    except InfeasibleError:
        pass
    else:
        assert not ric.gamma <= 0.9 * lower
        assert any("NOT stable" in w or "exceeds" in w for w in ric.warnings)


def test_sb10dd_is_not_monotone_in_gamma_and_the_scan_does_not_trust_it():
    # SLICOT SB10DD (slycot 0.7) on HE1 sampled at 10 ms: a controller at some levels
    # between 0.075 and 0.3, none at 0.5, 1, 2, one again at 5 (measured 2026-12-02).
    # Which of the low levels succeed depends on the BLAS kernel (SkylakeX: 0.075 only;
    # Haswell: 0.075 and 0.2; Sandybridge: 0.1 and 0.2), that one of them does, below a
    # level that fails, does not.  A bisection from [0, 1] stopped at 6.9 (certified
    # 0.125) before the scan of _scan_sb10dd
    P, Pd = _tustin("HE1")
    G = _without_d22(GeneralizedPlant.from_statespace(Pd, P.ny, P.nu, discrete=True))

    def solves(gamma):
        try:
            _sb10dd(G, gamma)
        except InfeasibleError:
            return False
        return True

    assert any(solves(g) for g in (0.075, 0.1, 0.125, 0.15, 0.2, 0.3))
    with pytest.raises(Exception, match="not admissible"):
        _sb10dd(G, 1.0)
    res = hinfsyn(Pd, P.ny, P.nu, method="riccati")
    lower = hinfsyn(P, P.ny, P.nu).gamma_lower
    assert lower * (1 - 1e-6) <= res.gamma <= lower * 1.01
    assert any("not monotone" in w for w in res.warnings)


def test_discrete_msyn_h2_objective_and_a_decay_region():
    P, Pd = _tustin("AC4", dt=0.05)
    G = GeneralizedPlant.from_statespace(Pd, P.ny, P.nu, discrete=True)
    G = _without_d22(G)
    # H2 objective: certified by the discrete h2norm (impulse-response energy); the
    # H∞-optimal controller is a feasible point, so the H2-optimal one is no worse
    K2, CL2, h2, info2 = msyn(G, P.ny, P.nu, H2Bound())
    assert h2 == pytest.approx(h2norm(lft(G, K2)), rel=1e-9)
    Kinf = hinfsyn(G, P.ny, P.nu).K
    assert h2 <= h2norm(lft(G, Kinf)) * (1 + 5e-3)
    # Re s < -alpha is |z| < exp(-alpha dt) in the z-plane
    alpha = 0.02  # AC4 has an open-loop mode at s = -0.05
    K, CL, gamma, info = msyn(G, P.ny, P.nu, HinfBound(), [HalfPlane(alpha=alpha)])
    assert np.max(np.abs(np.linalg.eigvals(np.asarray(CL.A)))) < np.exp(-alpha * 0.05)
    assert all(c.met for c in info.certificates)
    with pytest.raises(NotBuiltError, match="not an LMI region"):
        msyn(G, P.ny, P.nu, HinfBound(), [Sector(theta=0.5)])


def test_mixing_time_bases_is_refused_quickly():
    t0 = time.perf_counter()
    P, Pd = _tustin("AC4")
    Kc = control.ss([[-1.0]], [[1.0, 0.0]], [[1.0]], [[0.0, 0.0]])
    Kd = control.ss([[0.5]], [[1.0, 0.0]], [[1.0]], [[0.0, 0.0]], DT)
    with pytest.raises(SampleTimeError, match="continuous-time"):
        lft(Pd, Kc, P.ny, P.nu)                       # discrete plant, continuous K
    with pytest.raises(SampleTimeError, match="discrete-time"):
        lft(P, Kd)                                    # continuous plant, discrete K
    with pytest.raises(SampleTimeError):
        lft(Pd, control.ss(Kd.A, Kd.B, Kd.C, Kd.D, 0.02), P.ny, P.nu)  # two sample times
    # a static gain fits either time base
    assert lft(Pd, np.zeros((1, 2)), P.ny, P.nu).dt == DT
    bad = control.ss(Pd.A, Pd.B, Pd.C, Pd.D, True)    # discrete, no sample time
    with pytest.raises(SampleTimeError, match="unspecified"):
        hinfsyn(bad, P.ny, P.nu)
    nan = control.ss(Pd.A, Pd.B, Pd.C, Pd.D, float("nan"))
    with pytest.raises(SampleTimeError):
        hinfsyn(nan, P.ny, P.nu)
    # routes not built for discrete time say so, typed
    with pytest.raises(DiscreteTimeError):
        GeneralizedPlant.from_statespace(Pd, P.ny, P.nu)
    assert issubclass(SampleTimeError, TimebaseError) and issubclass(TimebaseError, ValueError)
    assert time.perf_counter() - t0 < 1.0


# ------------------------------------------------------------------ µ-synthesis

def _musyn_pair(P, blk, w, opts, dt):
    from lmi_suspension.lti import tustin
    from lmi_suspension.lti.bilinear import tustin_frequency
    from lmi_suspension.mu import musyn

    cont = musyn(P, 1, 1, blk, omega=w, options=opts)
    disc = musyn(tustin(P, dt), 1, 1, blk, omega=tustin_frequency(w, dt), options=opts)
    return cont, disc


def _assert_discrete_certified(res, blk, dt):
    from lmi_suspension.lti.norms import freqresp
    from lmi_suspension.mu import mussv

    assert res.K.dt == dt and res.CL.dt == dt
    assert all(r.K is None or r.K.dt == dt for r in res.history)
    # the full-order controller of a reduction and the iterates' scaled plants too
    assert res.K_full is None or res.K_full.dt == dt
    assert all(r.PD is None or r.PD.dt == dt for r in res.history)
    assert np.all(np.abs(res.CL.poles()) < 1)
    assert 0 < res.peak_omega <= np.pi / dt and np.all(res.omega < np.pi / dt)
    assert res.mu_lower_peak <= res.mu_peak * (1 + 1e-9)
    # µ of the discrete closed loop, evaluated on the unit circle (not on the image)
    again = mussv(freqresp(res.CL, [res.peak_omega]), blk, method="lmi")
    assert float(np.max(again.upper)) == pytest.approx(res.mu_peak, rel=1e-5)


def test_musyn_of_a_discrete_plant_is_the_design_of_its_bilinear_image():
    # tests/test_musyn.py's singular plant sampled by Tustin at 0.1 s, on the warped
    # image of the continuous run's grid: the same D-K problem, so the same µ up to the
    # roundoff of two realizations (measured 1e-13 relative, 2026-12-02; the tolerance
    # leaves room for a path that roundoff turns)
    from lmi_suspension.mu.dk import MusynOptions
    from test_musyn import singular_plant

    dt, blk = 0.1, [[1, 1], [1, 1]]
    cont, disc = _musyn_pair(singular_plant(), blk, np.logspace(-3, 1, 20),
                             MusynOptions(max_iter=2, method="lmi"), dt)
    _assert_discrete_certified(disc, blk, dt)
    assert disc.mu_peak == pytest.approx(cont.mu_peak, rel=1e-3)


def test_musyn_of_a_discrete_plant_refuses_what_the_map_does_not_carry():
    from lmi_suspension.lti import tustin
    from lmi_suspension.mu import musyn
    from lmi_suspension.errors import ParameterError
    from test_musyn import singular_plant

    Pd = tustin(singular_plant(), 0.1)
    with pytest.raises(ParameterError, match="pi/dt"):
        musyn(Pd, 1, 1, [[1, 1], [1, 1]], omega=np.linspace(1.0, 40.0, 5))
    with pytest.raises(NotBuiltError, match="constraints"):
        musyn(Pd, 1, 1, [[1, 1], [1, 1]], constraints=[HinfBound(bound=10.0)])


@pytest.mark.slow  # 169 s on Zen 1 under Sandybridge (2026-12-02): the second tier
def test_mixed_dgk_on_a_discrete_plant():
    # the stiffness oscillator (lmi_suspension.examples, a real stiffness) at 50 ms: D-G-K
    # keeps the stiffness real on the image as on the continuous plant; measured mixed µ
    # 1.03700 discrete against 1.03604 continuous (the runs' paths differ after the first
    # D-fit), complexified 1.130868 against 1.130874 (2026-12-02)
    from lmi_suspension.examples import stiffness_oscillator
    from lmi_suspension.mu.dk import MusynOptions

    ex, dt = stiffness_oscillator(), 0.05
    cont, disc = _musyn_pair(ex.P, ex.blk, np.logspace(-2, 2, 40),
                             MusynOptions(max_iter=3, complexify=False, reduce_order=None), dt)
    _assert_discrete_certified(disc, ex.blk, dt)
    # full order: each run's own order reduction would pick its own order and µ within 1 %
    assert disc.mu_peak == pytest.approx(cont.mu_peak, rel=5e-3)
    assert disc.mu_peak < 1.131  # below the complexified design (measured 1.1309)


@pytest.mark.slow  # 34-40 s on Zen 1 (2026-12-02): the second tier
def test_discrete_h2hinfsyn_returns_the_certified_norms():
    # AC4 sampled with a zero-order hold at 50 ms (D22 stays 0): the Pareto point of
    # ‖T∞‖∞² + ‖T2‖₂² (the H2 channel is z's last row), its norms recomputed here on CL
    from lmi_suspension.synthesis import h2hinfsyn

    P = compleib("AC4")
    Pd = control.sample_system(P.sys, 0.05, method="zoh")
    K, CL, (ginf, g2), info = h2hinfsyn(Pd, P.ny, P.nu, 1, W=(1.0, 1.0))
    assert K.dt == 0.05 and np.all(np.abs(CL.poles()) < 1)
    assert ginf == pytest.approx(hinfnorm(CL[0, :])[0], rel=1e-9)
    assert g2 == pytest.approx(h2norm(CL[1, :]), rel=1e-9)
    # each norm alone is no better than its own optimum (msyn on that channel alone)
    from lmi_suspension.synthesis.constraints import Channel
    alone = msyn(Pd, P.ny, P.nu, HinfBound(Channel(outputs=(0,))))
    assert ginf >= alone.objective_lmi * (1 - 1e-4)
