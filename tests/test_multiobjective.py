"""Multi-objective LMI synthesis (``msyn``, ``h2hinfsyn``): every result is certified here
again, on ``lft(P, K)`` alone, by computations that do not use the LMI variables."""

import control
import numpy as np
import pytest
import scipy.linalg

from lmi_suspension.errors import (DimensionError, InfeasibleError, NonFiniteError,
                                   ParameterError)
from lmi_suspension.lti import GeneralizedPlant, hinfnorm, lft
from lmi_suspension.synthesis import hinfsyn
from lmi_suspension.synthesis.constraints import (Channel, Disk, H2Bound, HalfPlane,
                                                  HinfBound, PeakBound, Sector)
from lmi_suspension.synthesis.examples import random_plant
from lmi_suspension.synthesis.multiobjective import h2hinfsyn, msyn
from test_compleib import load  # COMPleib plants, read as that module reads them


def h2_norm(A, B, C):
    """‖C (sI - A)⁻¹ B‖₂ by the controllability Gramian (scipy, not the library)."""
    Wc = scipy.linalg.solve_continuous_lyapunov(A, -B @ B.T)
    return float(np.sqrt(np.trace(C @ Wc @ C.T)))


def rows(CL, r, c=None):
    B = np.asarray(CL.B) if c is None else np.asarray(CL.B)[:, c]
    return np.asarray(CL.A), B, np.asarray(CL.C)[r]


# ------------------------------------------------------------------- single objectives

# every COMPleib problem of the subset but AC1 (whose infimum is 0): the LMI optimum
# within 1.2e-4 of hinfsyn's (measured 2026-11-25, after frame rounds; 0.14-0.51 % without)
NAMES = ["AC2", "AC3", "AC4", "AC6", "HE1", "HE2", "REA1", "REA2", "DIS1", "NN1", "NN2"]


@pytest.mark.parametrize("name", NAMES)
def test_hinf_objective_alone_is_hinfsyns_lmi_optimum(name):
    """Reference: hinfsyn's γ minimisation over the projected LMIs (another
    formulation of the same problem), on COMPleib plants."""
    P = load(name)
    K, CL, gamma, info = msyn(P, P.ny, P.nu, HinfBound())
    ref = hinfsyn(P, P.ny, P.nu).gamma_lower
    assert gamma == hinfnorm(lft(P, K))[0]
    assert np.all(np.linalg.eigvals(np.asarray(CL.A)).real < 0)
    # no better than the optimum, up to solver accuracy; AC2 has an open-loop pole at
    # s = 0, and under OpenBLAS's Sandybridge kernel its minimisation stops 0.3 % low
    # (0.111134 against 0.111489; the certified controllers agree to 1e-6), measured
    # 2026-11-25
    assert info.objective_lmi >= ref * (1 - (5e-3 if name == "AC2" else 1e-3))
    assert info.objective_lmi <= ref * (1 + 1e-3)
    assert gamma <= info.objective_lmi * (1 + 5e-3)
    if name == "AC4":
        # the one regular plant: python-control's Riccati controller, certified here, is
        # a reference outside the LMI routes (0.55729070, measured 2026-11-27; msyn's LMI
        # optimum 0.5572963); issue 41 reported hinfsyn's optimum above it on AC4.
        # hinfsyn's is 0.5572915 since 2026-11-29, above it by the cost of the trace
        # bound (test_compleib_ac4_against_riccati), hence 1e-5
        best = hinfnorm(lft(P, control.hinfsyn(P.sys, P.ny, P.nu)[0]))[0]
        assert ref <= best * (1 + 1e-5) and info.objective_lmi <= best * (1 + 1e-4)


@pytest.mark.parametrize("seed", [0, 1, 2])
def test_h2_objective_alone_is_the_riccati_h2_optimum(seed):
    """Reference: python-control's h2syn (SLICOT sb10hd) on a regular plant, its
    controller's H2 norm by the Gramian; within 0.1 %."""
    P = random_plant(5, 3, 1, 3, 2, rng=np.random.default_rng(seed), d11=False)
    ref = h2_norm(*rows(lft(P, control.h2syn(P.sys, P.ny, P.nu)), slice(None)))
    K, CL, nu, info = msyn(P, P.ny, P.nu, H2Bound())
    assert nu == pytest.approx(h2_norm(*rows(CL, slice(None))), rel=1e-9)
    assert ref * (1 - 1e-3) <= nu <= ref * (1 + 1e-3)


# ------------------------------------------------------------------- constraints


def test_half_plane_tightens_the_objective_monotonically_and_is_certified():
    P = load("HE1")
    levels = []
    for alpha in (0.0, 0.2, 0.5, 1.0):
        K, CL, gamma, info = msyn(P, P.ny, P.nu, HinfBound(), [HalfPlane(alpha)])
        poles = np.linalg.eigvals(np.asarray(CL.A))
        assert np.max(poles.real) < -alpha  # eigenvalues, not the LMI
        levels.append(gamma)
    assert all(b > a for a, b in zip(levels[1:], levels[2:]))
    assert levels[-1] > 10 * levels[0]  # measured: 0.0738 -> 1.0045


def test_a_region_no_controller_reaches_is_a_typed_error():
    # the mode at s = -1 is reachable from w only and seen by z only: no controller moves it
    P = GeneralizedPlant.from_matrices(
        A=[[-1.0, 0.0], [0.0, 1.0]], B1=[[1.0], [1.0]], B2=[[0.0], [1.0]],
        C1=[[1.0, 1.0], [0.0, 0.0]], C2=[[0.0, 1.0]], D12=[[0.0], [1.0]], D21=[[1.0]])
    K, CL, gamma, info = msyn(P, 1, 1, HinfBound(), [HalfPlane(0.5)])
    assert np.max(np.linalg.eigvals(np.asarray(CL.A)).real) < -0.5
    with pytest.raises(InfeasibleError, match="half-plane"):
        msyn(P, 1, 1, HinfBound(), [HalfPlane(2.0)])


def test_disk_and_sector_are_certified_on_the_poles():
    P = load("HE1")
    K, CL, gamma, info = msyn(P, P.ny, P.nu, HinfBound(),
                              [Disk(radius=20.0, center=0.0), Sector(np.pi / 4)])
    p = np.linalg.eigvals(np.asarray(CL.A))
    assert np.all(np.abs(p) < 20.0)
    assert np.all(np.abs(p.imag) < -p.real)  # damping ratio above cos(45°)
    assert all(c.met for c in info.certificates)


def test_peak_bound_is_active_certified_by_the_gramian_and_infeasible_when_too_tight():
    P = random_plant(4, 2, 1, 3, 1, rng=np.random.default_rng(7), d11=False)
    ch = Channel(outputs=(2,))
    # a loose bound first (a finite peak needs zero feedthrough on that row, which the
    # H∞-optimal controller does not have)
    free = msyn(P, P.ny, P.nu, HinfBound(Channel(outputs=(0, 1))), [PeakBound(ch, (1e3,))])
    peak_free = PeakBound(ch, (1.0,)).peaks(free.CL)[0]
    assert np.isfinite(peak_free) and peak_free < 1e3
    bound = 0.5 * peak_free
    K, CL, gamma, info = msyn(P, P.ny, P.nu, HinfBound(Channel(outputs=(0, 1))),
                              [PeakBound(ch, (bound,))])
    A, B, C = rows(CL, [2])
    Wc = scipy.linalg.solve_continuous_lyapunov(A, -B @ B.T)
    assert np.sqrt((C @ Wc @ C.T)[0, 0]) <= bound * (1 + 5e-3)  # Wilson's peak, directly
    assert gamma >= free.objective * (1 - 1e-3)  # the bound costs H∞ performance
    with pytest.raises(InfeasibleError, match="peak"):
        msyn(P, P.ny, P.nu, HinfBound(Channel(outputs=(0, 1))), [PeakBound(ch, (1e-9,))])


@pytest.mark.slow  # 17 s on Zen 1 (2026-12-02): the second tier
def test_hinf_bound_on_an_h2_objective_is_active():
    """The H2-optimal controller (row 2) of this plant has ‖T∞‖∞ = 20.7 on rows 0-1 and
    ‖T2‖₂ = 57.08 (measured 2026-11-25); under H∞ bounds of 60 and then 40 the H2 norm
    grows (59.9, 69.7) and each bound holds on the certified closed loop.  Bounds of 19-30
    made Clarabel fail before the LMIs were posed in frames (2026-11-25)."""
    P = random_plant(5, 3, 1, 3, 2, rng=np.random.default_rng(4), d11=False)
    ch, h2 = Channel(outputs=(0, 1)), H2Bound(Channel(outputs=(2,)))
    free = msyn(P, P.ny, P.nu, h2)
    norms = [free.objective]
    for bound in (60.0, 40.0):
        K, CL, nu, info = msyn(P, P.ny, P.nu, h2, [HinfBound(ch, bound=bound)])
        sys_inf = control.ss(CL.A, CL.B, np.asarray(CL.C)[:2], np.asarray(CL.D)[:2])
        assert hinfnorm(sys_inf)[0] <= bound
        assert nu == pytest.approx(h2_norm(*rows(CL, [2])), rel=1e-9)
        norms.append(nu)
    assert norms[0] < norms[1] < norms[2]


class DecayRate:
    """A specification written from scratch against the protocol (not a subclass)."""

    name = "decay rate"
    bound = None

    def __init__(self, alpha):
        self.alpha = alpha

    def lmis(self, v, level, slack):
        M = v.calA + v.calA.T + 2 * self.alpha * v.calX
        return [(M + M.T) / 2 << -slack * np.eye(M.shape[0])]

    def certify(self, CL):
        return float(np.max(np.linalg.eigvals(np.asarray(CL.A)).real) + self.alpha)


def test_a_specification_of_ones_own_rides_in_the_synthesis():
    P = load("HE2")
    K, CL, gamma, info = msyn(P, P.ny, P.nu, HinfBound(), [DecayRate(0.3)])
    ref = msyn(P, P.ny, P.nu, HinfBound(), [HalfPlane(0.3)])
    assert np.max(np.linalg.eigvals(np.asarray(CL.A)).real) < -0.3
    assert gamma == pytest.approx(ref.objective, rel=1e-3)
    assert info.certificates[1].name == "decay rate" and info.certificates[1].met


# ------------------------------------------------------------------- h2hinfsyn


def _fake_closed_loop(gamma, nu):
    """A closed loop whose rows 0-1 have ‖·‖∞ = gamma and row 2 ‖·‖₂ = nu, in closed
    form: c/(s + 1) has H∞ norm |c| (at ω = 0) and H2 norm |c|/√2."""
    return control.ss([[-1.0]], [[1.0]], [[gamma], [0.0], [nu * np.sqrt(2.0)]],
                      np.zeros((3, 1)))


# the injected Pareto front: the H∞ optimum 2, and under ‖T∞‖∞ <= γ the H2 optimum
# ν*(γ)² = 1 + 4/(γ - 1.5) (convex, decreasing); the H2-only controller has ‖T∞‖∞ = 12
GAMMA_OPT, GAMMA_FREE = 2.0, 12.0


def _nu_star(gamma):
    return np.sqrt(1.0 + 4.0 / (gamma - 1.5))


def test_h2hinfsyn_weighted_search_finds_the_injected_pareto_minimum(monkeypatch):
    """Injected: ``msyn`` replaced by a known Pareto front (above), whose H2 results carry
    no LMI level (``objective_lmi`` nan, as every H2 minimisation of the plant below
    does).  Reference: the minimiser of γ² + ν*(γ)² in closed form, f'(γ) = 0 solved by
    brentq: γ* = 2.4526, cost 11.227, against 13 for the H∞-only controller (2, 3) and
    145.4 for the H2-only one.  The search's bracket ends 0.08 wide (10 golden steps
    on [2.004, 12]), so the cost is within 1e-3 of the minimum (f'' <= 12 there)."""
    import scipy.optimize

    import lmi_suspension.synthesis.multiobjective as mo

    def fake_msyn(G, nmeas, ncon, objective, constraints=(), options=None,
                  lyapunov_scales=None):
        if isinstance(objective, HinfBound):
            gamma, nu, level = GAMMA_OPT, _nu_star(GAMMA_OPT), GAMMA_OPT
        else:
            bounds = [c.bound for c in constraints if isinstance(c, HinfBound)]
            gamma = min(bounds) if bounds else GAMMA_FREE
            if gamma < GAMMA_OPT:
                raise InfeasibleError("injected: below the H∞ optimum")
            nu, level = _nu_star(gamma), float("nan")
        CL = _fake_closed_loop(gamma, nu)
        return mo.MultiobjectiveResult(
            K=control.ss([], [], [], [[0.0]]), CL=CL,
            objective=gamma if isinstance(objective, HinfBound) else nu,
            objective_lmi=level, certificates=(), poles=np.array([-1.0]), status="injected",
            seconds=0.0, warnings=(), lyapunov_scales=())

    monkeypatch.setattr(mo, "msyn", fake_msyn)
    P = random_plant(5, 3, 1, 3, 2, rng=np.random.default_rng(4), d11=False)  # sizes only
    g_star = scipy.optimize.brentq(lambda g: 2 * g - 4 / (g - 1.5) ** 2, GAMMA_OPT, GAMMA_FREE,
                                   xtol=1e-14)
    best = g_star**2 + _nu_star(g_star) ** 2
    assert best < 0.9 * (GAMMA_OPT**2 + _nu_star(GAMMA_OPT) ** 2)  # the premise: interior
    K, CL, normz, info = h2hinfsyn(P, P.ny, P.nu, 1, W=(1.0, 1.0))
    assert normz[0] == pytest.approx(hinfnorm(control.ss(CL.A, CL.B, np.asarray(CL.C)[:2],
                                                          np.asarray(CL.D)[:2]))[0], rel=1e-9)
    assert best <= normz[0] ** 2 + normz[1] ** 2 <= best * (1 + 1e-3)
    assert normz[0] == pytest.approx(g_star, rel=2e-2)
    # the weights move the point along the front: W = (1, 4) favours the H2 norm
    g4 = scipy.optimize.brentq(lambda g: 2 * g - 16 / (g - 1.5) ** 2, GAMMA_OPT, GAMMA_FREE)
    normz4 = h2hinfsyn(P, P.ny, P.nu, 1, W=(1.0, 4.0))[2]
    assert normz4[0] == pytest.approx(g4, rel=2e-2) and normz4[0] > normz[0] * 1.1


@pytest.mark.slow  # 47 s on Zen 1 (2026-12-02): the second tier
def test_h2hinfsyn_matlab_conventions_and_certified_norms():
    """On a real plant: W = (1, 0) against the H∞ optimum of the H∞ channel alone by two
    other routes: SLICOT's γ iteration (python-control's hinfsyn: its γ, 9.95624; its
    controller destabilises this plant, so only the value is used) and hinfsyn's
    projected LMIs (9.95677, another formulation than msyn's change of variables);
    msyn's controller certifies 9.96343 (measured 2026-11-27).  W = (1, 1) against the
    two single-objective controllers, each certified here: the mixed cost γ² + ν² must
    beat both (measured: 3661.1 against 3686.7 for the H2-only controller, whose
    ‖T∞‖∞ is 20.72; the H∞-only one has an infinite H2 norm)."""
    P = random_plant(5, 3, 1, 3, 2, rng=np.random.default_rng(4), d11=False)
    K, CL, normz, info = h2hinfsyn(P, P.ny, P.nu, 1, W=(1.0, 0.0))
    b = P.blocks()
    P01 = GeneralizedPlant.from_matrices(A=b["A"], B1=b["B1"], B2=b["B2"], C1=b["C1"][:2],
                                         C2=b["C2"], D11=b["D11"][:2], D12=b["D12"][:2],
                                         D21=b["D21"], D22=b["D22"])
    gamma_slicot = float(control.hinfsyn(P01.sys, P01.ny, P01.nu)[2])
    gamma_proj = hinfsyn(P01, P01.ny, P01.nu).gamma_lower
    assert gamma_proj == pytest.approx(gamma_slicot, rel=1e-4)  # the two references agree
    # certified, so not below the optimum (up to solver accuracy), and within 0.2 % of it
    assert gamma_slicot * (1 - 1e-4) <= normz[0] <= gamma_slicot * (1 + 2e-3)
    K, CL, normz, info = h2hinfsyn(P, P.ny, P.nu, 1, W=(1.0, 1.0))
    # the norms of the two channels, recomputed here
    sys_inf = control.ss(CL.A, CL.B, np.asarray(CL.C)[:2], np.asarray(CL.D)[:2])
    assert normz[0] == pytest.approx(hinfnorm(sys_inf)[0], rel=1e-9)
    assert normz[1] == pytest.approx(h2_norm(*rows(CL, [2])), rel=1e-9)
    h2 = msyn(P, P.ny, P.nu, H2Bound(Channel(outputs=(2,))))
    h2_cost = hinfnorm(control.ss(h2.CL.A, h2.CL.B, np.asarray(h2.CL.C)[:2],
                                  np.asarray(h2.CL.D)[:2]))[0] ** 2 \
        + h2_norm(*rows(h2.CL, [2])) ** 2
    assert normz[0] ** 2 + normz[1] ** 2 < h2_cost * (1 - 1e-3)


# ------------------------------------------------------------------- bad input


def test_bad_input_is_typed():
    P = random_plant(4, 2, 1, 2, 1, rng=np.random.default_rng(0))  # D11 != 0
    with pytest.raises(ParameterError, match="feedthrough"):
        msyn(P, 1, 1, H2Bound())
    with pytest.raises(DimensionError, match="out of range"):
        msyn(P, 1, 1, HinfBound(Channel(outputs=(5,))))
    with pytest.raises(ParameterError, match="nz2"):
        h2hinfsyn(P, 1, 1, 2)
    with pytest.raises(ParameterError, match="positive bound"):
        msyn(P, 1, 1, HinfBound(), [H2Bound(bound=None)])
    with pytest.raises(ParameterError, match="not a specification"):
        msyn(P, 1, 1, HinfBound(), [object()])
    bad = control.ss(P.sys.A, P.sys.B, P.sys.C, P.sys.D)
    A = np.array(bad.A)
    A[0, 0] = np.nan
    with pytest.raises(NonFiniteError):
        msyn(control.ss(A, bad.B, bad.C, bad.D), 1, 1, HinfBound())
    with pytest.raises(ValueError):  # SampleTimeError is a ValueError
        msyn(control.ss(bad.A, bad.B, bad.C, bad.D, True), 1, 1, HinfBound())


# ------------------------------------------------- each constraint: active, infeasible


def test_h2_and_hinf_bounds_are_active_and_infeasible_below_their_optima():
    """Plant of the test above: its H2 optimum on row 2 is 57.08 (measured 2026-11-25,
    and ``free.objective`` here); an H2 bound tightening towards it raises the H∞ level
    of rows 0-1, below it nothing is feasible.  An H∞ bound at half of rows 0-1's own
    optimum (their H∞ objective alone) is infeasible too."""
    P = random_plant(5, 3, 1, 3, 2, rng=np.random.default_rng(4), d11=False)
    inf_ch, h2_ch = Channel(outputs=(0, 1)), Channel(outputs=(2,))
    free = msyn(P, P.ny, P.nu, H2Bound(h2_ch))
    hinf = msyn(P, P.ny, P.nu, HinfBound(inf_ch))
    nu_hinf = h2_norm(*rows(hinf.CL, [2])) if np.all(np.asarray(hinf.CL.D)[2] == 0) else np.inf
    levels = []
    for bound in (1.3 * free.objective, 1.1 * free.objective):
        assert bound < nu_hinf  # the H∞-optimal controller violates it: the bound acts
        K, CL, gamma, info = msyn(P, P.ny, P.nu, HinfBound(inf_ch), [H2Bound(h2_ch, bound)])
        assert h2_norm(*rows(CL, [2])) <= bound * (1 + 5e-3)
        levels.append(gamma)
    assert hinf.objective < levels[0] < levels[1]
    with pytest.raises(InfeasibleError, match="H2"):
        msyn(P, P.ny, P.nu, HinfBound(inf_ch), [H2Bound(h2_ch, 0.5 * free.objective)])
    with pytest.raises(InfeasibleError, match="H∞"):
        msyn(P, P.ny, P.nu, H2Bound(h2_ch), [HinfBound(inf_ch, 0.5 * hinf.objective)])


def _fixed_mode_plant(a, b):
    """A mode ``-a ± j b`` reachable from ``w`` only (no controller moves it) beside an
    unstable one the controller must stabilise."""
    return GeneralizedPlant.from_matrices(
        A=[[-a, b, 0.0], [-b, -a, 0.0], [0.0, 0.0, 1.0]], B1=[[1.0], [0.0], [1.0]],
        B2=[[0.0], [0.0], [1.0]], C1=[[1.0, 0.0, 1.0], [0.0, 0.0, 0.0]],
        C2=[[0.0, 0.0, 1.0]], D12=[[0.0], [1.0]], D21=[[1.0]])


def test_disk_and_sector_are_active_and_infeasible_around_a_fixed_mode():
    P = load("HE1")
    levels = []
    for radius in (40.0, 10.0, 4.0):
        K, CL, gamma, info = msyn(P, P.ny, P.nu, HinfBound(), [Disk(radius=radius)])
        assert np.max(np.abs(np.linalg.eigvals(np.asarray(CL.A)))) < radius
        levels.append(gamma)
    assert levels[0] <= levels[1] * (1 + 1e-3) and levels[1] < levels[2]
    levels = []
    for theta in (np.pi / 3, np.pi / 4, np.pi / 6):
        K, CL, gamma, info = msyn(P, P.ny, P.nu, HinfBound(), [Sector(theta)])
        p = np.linalg.eigvals(np.asarray(CL.A))
        assert np.all(np.abs(p.imag) < np.tan(theta) * -p.real)
        levels.append(gamma)
    assert levels[0] <= levels[1] * (1 + 1e-3) and levels[1] < levels[2]
    # |−1 ± 2j| = 2.24 and its damping ratio 0.45 (a 63° sector) are out of any
    # controller's reach
    Q = _fixed_mode_plant(1.0, 2.0)
    msyn(Q, 1, 1, HinfBound(), [Disk(radius=3.0), Sector(np.pi * 0.4)])
    with pytest.raises(InfeasibleError, match="disk"):
        msyn(Q, 1, 1, HinfBound(), [Disk(radius=2.0)])
    with pytest.raises(InfeasibleError, match="sector"):
        msyn(Q, 1, 1, HinfBound(), [Sector(np.pi / 4)])
