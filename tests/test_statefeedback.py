"""Multi-objective static state feedback (``msfsyn``): every result is certified here
again on the closed loop ``A + B2 K`` built in the test, and the single objectives are
checked against the Riccati optima computed in the test with scipy."""

import control
import numpy as np
import pytest
import scipy.linalg

from lmi_suspension.errors import DimensionError, InfeasibleError, NonFiniteError, ParameterError
from lmi_suspension.lti import hinfnorm
from lmi_suspension.synthesis import msfsyn
from lmi_suspension.synthesis.constraints import (Channel, Disk, H2Bound, HalfPlane,
                                                  HinfBound, PeakBound, Sector)
from test_compleib import load
from test_multiobjective import DecayRate, h2_norm


def regular_plant(seed, n=5, nw=2, nu=1, nz=2):
    """``ẋ = A x + B1 w + B2 u``, ``z = [C x; u]`` with one unstable mode."""
    rng = np.random.default_rng(seed)
    A = rng.standard_normal((n, n))
    A -= (np.max(np.linalg.eigvals(A).real) - 0.5) * np.eye(n)
    B1, B2 = rng.standard_normal((n, nw)), rng.standard_normal((n, nu))
    C1 = np.vstack([rng.standard_normal((nz, n)), np.zeros((nu, n))])
    D12 = np.vstack([np.zeros((nz, nu)), np.eye(nu)])
    return A, B1, B2, C1, D12


def as_sf_plant(A, B1, B2, C1, D12, D11=None):
    D11 = np.zeros((C1.shape[0], B1.shape[1])) if D11 is None else D11
    return control.ss(A, np.hstack([B1, B2]), C1, np.hstack([D11, D12]))


def closed_loop(A, B1, B2, C1, D12, K):
    """The loop ``u = K x``, built here (not by the library)."""
    return A + B2 @ K, B1, C1 + D12 @ K


def fi_riccati(A, B1, B2, C1, D12, gamma):
    """Full-information H∞ Riccati equation (D11 = 0): its stabilising solution ``X``
    and the central gain, or None if there is none with ``X >= 0`` (Doyle, Glover,
    Khargonekar & Francis, IEEE TAC 34(8), 1989; scipy's indefinite-R solver)."""
    nw, nu = B1.shape[1], B2.shape[1]
    R = scipy.linalg.block_diag(-gamma**2 * np.eye(nw), D12.T @ D12)
    S = np.hstack([np.zeros((A.shape[0], nw)), C1.T @ D12])
    try:
        X = scipy.linalg.solve_continuous_are(A, np.hstack([B1, B2]), C1.T @ C1, R, s=S)
    except (np.linalg.LinAlgError, ValueError):
        return None
    if np.min(np.linalg.eigvalsh((X + X.T) / 2)) < -1e-9 * max(1.0, np.abs(X).max()):
        return None
    return X, -np.linalg.solve(D12.T @ D12, B2.T @ X + D12.T @ C1)


def fi_optimum(data):
    """The full-information H∞ optimum by bisection on :func:`fi_riccati` (which a
    static state feedback attains when D11 = 0: Khargonekar, Petersen & Zhou, IEEE TAC
    33(8), 1988), checked by the central gain's certified norm just above it."""
    lo, hi = 1e-6, 1e6
    assert fi_riccati(*data, hi) is not None
    for _ in range(80):
        mid = np.sqrt(lo * hi)
        lo, hi = (lo, mid) if fi_riccati(*data, mid) is not None else (mid, hi)
    A, B1, C = closed_loop(*data, fi_riccati(*data, hi * 1.001)[1])
    assert np.all(np.linalg.eigvals(A).real < 0)
    central = hinfnorm(control.ss(A, B1, C, 0))[0]
    assert hi * (1 - 1e-6) <= central <= hi * 1.001  # the reference is real
    return hi


def compleib_data(name):
    P = load(name)
    b = P.blocks()
    return b["A"], b["B1"], b["B2"], b["C1"], b["D12"]


# AC1 (singular D12), AC4 (D11 != 0) and NN1 (the central gain just above the Riccati
# bisection certifies 19.7 against 4.37: its assumptions fail) have no valid reference;
# AC2's infimum is not attained (a mode at s = 0 that z does not see) -- see below
COMPLEIB = ["AC3", "AC6", "HE1", "HE2", "REA1", "REA2", "DIS1", "NN2"]


@pytest.mark.parametrize("name", COMPLEIB)
def test_hinf_alone_is_the_full_information_riccati_optimum(name):
    """Measured 2026-11-25: within 0.07 % on every problem (AC3 0.068 %)."""
    data = compleib_data(name)
    ref = fi_optimum(data)
    K, CL, gamma, info = msfsyn(as_sf_plant(*data), data[2].shape[1], HinfBound())
    A, B, C = closed_loop(*data, K)
    assert np.all(np.linalg.eigvals(A).real < 0)
    assert gamma == pytest.approx(hinfnorm(control.ss(A, B, C, 0))[0], rel=1e-6)
    assert info.objective_lmi == pytest.approx(ref, rel=1e-3)
    assert ref * (1 - 1e-6) <= gamma <= ref * (1 + 1e-3)


@pytest.mark.parametrize("seed", [0, 1])
def test_hinf_alone_on_a_random_regular_plant(seed):
    data = regular_plant(seed)
    ref = fi_optimum(data)
    K, CL, gamma, info = msfsyn(as_sf_plant(*data), 1, HinfBound())
    A, B, C = closed_loop(*data, K)
    assert gamma == pytest.approx(hinfnorm(control.ss(A, B, C, 0))[0], rel=1e-6)
    assert ref * (1 - 1e-6) <= gamma <= ref * (1 + 1e-3)
    assert K.shape == (1, 5)


def test_an_infimum_that_is_not_attained_is_certified_and_says_so():
    """COMPleib AC2: the full-information optimum 0.0519 needs a closed-loop pole at
    s = 0 (its open-loop pole there is invisible from z); the controller returned is
    certified at its own, higher level and the result warns."""
    data = compleib_data("AC2")
    K, CL, gamma, info = msfsyn(as_sf_plant(*data), data[2].shape[1], HinfBound())
    A, B, C = closed_loop(*data, K)
    assert np.all(np.linalg.eigvals(A).real < 0)
    assert gamma == pytest.approx(hinfnorm(control.ss(A, B, C, 0))[0], rel=1e-6)
    assert gamma <= info.certificates[0].lmi_level * (1 + 5e-3)
    # near the infimum, or far above it and saying so (0.1115 against 0.0519, measured
    # 2026-11-25 under every kernel)
    assert gamma <= info.objective_lmi * 1.01 or any("may not be attained" in w
                                                     for w in info.warnings)


@pytest.mark.parametrize("seed", [0, 1, 2])
def test_h2_alone_is_the_lqr_optimum(seed):
    """Reference: the LQR Riccati equation (Q = C1ᵀC1, R = D12ᵀD12, S = C1ᵀD12), whose
    optimal H2 norm is sqrt(trace(B1ᵀ X B1)); the gain's norm by the Gramian."""
    A, B1, B2, C1, D12 = data = regular_plant(seed)
    X = scipy.linalg.solve_continuous_are(A, B2, C1.T @ C1, D12.T @ D12, s=C1.T @ D12)
    ref = float(np.sqrt(np.trace(B1.T @ X @ B1)))
    K, CL, nu, info = msfsyn(as_sf_plant(*data), 1, H2Bound())
    assert nu == pytest.approx(h2_norm(*closed_loop(*data, K)), rel=1e-9)
    assert ref * (1 - 1e-6) <= nu <= ref * (1 + 1e-3)


def test_half_plane_is_active_monotone_and_infeasible_where_no_gain_reaches():
    data = compleib_data("HE1")
    levels = []
    for alpha in (0.0, 0.5, 1.0, 2.0):
        K, CL, gamma, info = msfsyn(as_sf_plant(*data), 2, HinfBound(), [HalfPlane(alpha)])
        assert np.max(np.linalg.eigvals(closed_loop(*data, K)[0]).real) < -alpha
        levels.append(gamma)
    assert all(b > a for a, b in zip(levels[1:], levels[2:]))
    # a mode at s = -1 that u cannot move
    A = np.diag([-1.0, 1.0])
    P = as_sf_plant(A, np.ones((2, 1)), np.array([[0.0], [1.0]]),
                    np.array([[1.0, 1.0], [0.0, 0.0]]), np.array([[0.0], [1.0]]))
    msfsyn(P, 1, HinfBound(), [HalfPlane(0.5)])
    with pytest.raises(InfeasibleError, match="half-plane"):
        msfsyn(P, 1, HinfBound(), [HalfPlane(2.0)])


def test_disk_sector_and_a_specification_of_ones_own_are_certified_on_the_poles():
    data = compleib_data("HE2")
    K, CL, gamma, info = msfsyn(as_sf_plant(*data), 2, HinfBound(),
                                [Disk(radius=10.0), Sector(np.pi / 4), DecayRate(0.2)])
    p = np.linalg.eigvals(closed_loop(*data, K)[0])
    assert np.all(np.abs(p) < 10.0)
    assert np.all(np.abs(p.imag) < -p.real)
    assert np.all(p.real < -0.2)
    assert [c.met for c in info.certificates] == [True] * 4


def test_peak_bound_is_active_certified_by_the_gramian_and_infeasible_when_too_tight():
    A, B1, B2, C1, D12 = data = regular_plant(3, nz=3)
    P = as_sf_plant(*data)
    perf, ch = Channel(outputs=(0, 1, 3)), Channel(outputs=(2,))
    free = msfsyn(P, 1, HinfBound(perf))
    Ac, Bc, Cc = closed_loop(*data, free.gain)
    peak_free = float(np.sqrt((Cc[2] @ scipy.linalg.solve_continuous_lyapunov(
        Ac, -Bc @ Bc.T) @ Cc[2])))
    levels = [free.objective]
    for bound in (0.9 * peak_free, 0.7 * peak_free):  # 1.19 -> 1.32 -> 1.88 (2026-11-25)
        K, CL, gamma, info = msfsyn(P, 1, HinfBound(perf), [PeakBound(ch, (bound,))])
        Ac, Bc, Cc = closed_loop(*data, K)
        Wc = scipy.linalg.solve_continuous_lyapunov(Ac, -Bc @ Bc.T)
        assert np.sqrt(Cc[2] @ Wc @ Cc[2]) <= bound * (1 + 5e-3)  # Wilson's peak, directly
        levels.append(gamma)
    assert levels[0] * (1 + 1e-3) < levels[1] < levels[2]  # the bound costs H∞ performance
    # a hundredth of the free peak (1e-9 in absolute terms: Clarabel fails on the
    # feasibility problem itself under OpenBLAS's Nehalem kernel, its row C / b of 1e9
    # -- a SolverError, measured 2026-11-25)
    with pytest.raises(InfeasibleError, match="peak"):
        msfsyn(P, 1, HinfBound(perf), [PeakBound(ch, (0.01 * peak_free,))])


def test_result_unpacks_with_the_gain_and_the_closed_loop_from_w_to_z():
    data = regular_plant(0)
    res = msfsyn(as_sf_plant(*data), 1, HinfBound())
    K, CL, gamma, info = res
    assert K is res.gain and info is res
    A, B, C = closed_loop(*data, K)
    w = 1j * np.logspace(-2, 2, 7)
    ref = np.array([C @ np.linalg.solve(s * np.eye(5) - A, B) for s in w])
    assert np.allclose(np.moveaxis(CL(w), -1, 0), ref, rtol=1e-8, atol=1e-12)


def test_bad_input_is_typed():
    P = as_sf_plant(*regular_plant(0))
    with pytest.raises(DimensionError, match="ncon"):
        msfsyn(P, 3, HinfBound())
    with pytest.raises(DimensionError, match="ncon"):
        msfsyn(P, 0, HinfBound())
    with pytest.raises(DimensionError, match="out of range"):
        msfsyn(P, 1, HinfBound(Channel(outputs=(7,))))
    with pytest.raises(ParameterError, match="not a specification"):
        msfsyn(P, 1, HinfBound(), [object()])
    A = np.array(P.A)
    A[0, 0] = np.nan
    with pytest.raises(NonFiniteError):
        msfsyn(control.ss(A, P.B, P.C, P.D), 1, HinfBound())
    with pytest.raises(ValueError):  # DiscreteTimeError is a ValueError
        msfsyn(control.ss(P.A, P.B, P.C, P.D, 0.1), 1, HinfBound())
    # a mode at s = 1 that u cannot move: no gain stabilises it
    bad = as_sf_plant(np.diag([1.0, -1.0]), np.ones((2, 1)), np.array([[0.0], [1.0]]),
                      np.array([[1.0, 0.0], [0.0, 0.0]]), np.array([[0.0], [1.0]]))
    with pytest.raises(InfeasibleError, match="stabilisable"):
        msfsyn(bad, 1, HinfBound())


def test_seat_state_feedback_with_hard_force_and_stroke_bounds():
    """The suspension literature's design (H∞ comfort, generalized-H2 force and stroke
    bounds, all states measured) on the seat of ``seat.bounded``: the bounds hold for
    every floor velocity of the bump's energy by the Gramian, and on the bump itself
    by a time simulation of the linear loop built here.  Measured 2026-11-25: H∞ 23.08
    without bounds (its worst road needs 6211 N), 27.65 at 1500 N / 0.08 m (output
    feedback through x1, x3: 28.6)."""
    from lmi_suspension.seat.bounded import RHO_U, U, X1, Z3DD, seat_peak_plant
    from lmi_suspension.seat.roads import road_energy
    from lmi_suspension.seat.roads import bump

    b = seat_peak_plant().blocks()
    road = bump()
    E = road_energy(road)
    P = control.ss(b["A"], np.hstack([b["B1"][:, :1], b["B2"]]), b["C1"],
                   np.hstack([b["D11"][:, :1], b["D12"]]))
    perf, limits = Channel(outputs=(Z3DD, RHO_U)), Channel(outputs=(U, X1))
    free = msfsyn(P, 1, HinfBound(perf))
    K, CL, gamma, info = msfsyn(P, 1, HinfBound(perf), [PeakBound(limits, (1500 / E, 0.08 / E))])
    data = (b["A"], b["B1"][:, :1], b["B2"], b["C1"], b["D12"])
    A, B, C = closed_loop(*data, K)
    Wc = scipy.linalg.solve_continuous_lyapunov(A, -B @ B.T)
    worst = E * np.sqrt(np.diag(C @ Wc @ C.T))[[U, X1]]
    assert worst[0] <= 1500 * (1 + 5e-3) and worst[1] <= 0.08 * (1 + 5e-3)
    assert E * PeakBound(limits, (1.0, 1.0)).peaks(free.CL)[0] > 1500  # the bound is active
    assert free.objective < gamma
    resp = control.forced_response(control.ss(A, B, C, 0), road.t, np.asarray(road.w))
    y = np.asarray(resp.outputs)
    assert np.max(np.abs(y[U])) <= 1500 and np.max(np.abs(y[X1])) <= 0.08
