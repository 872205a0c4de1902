"""µ-synthesis with constraints in its LMI K-step (issue 17, item 1).

Every figure a test asserts is recomputed in the test from the returned controller: the
closed loop ``lft(P, K)`` built here, its poles, its Gramian, and µ by ``mussv`` on a
grid of the test's own.
"""

import control
import numpy as np
import pytest
import scipy.linalg

from lmi_suspension.errors import DimensionError, InfeasibleError, ParameterError
from lmi_suspension.lti import freqresp, lft
from lmi_suspension.mu import MusynOptions, mussv, musyn
from lmi_suspension.synthesis.constraints import Channel, HalfPlane, PeakBound

BLK = [[1, 1], [1, 1]]  # input-multiplicative uncertainty, performance
OMEGA = np.logspace(-2, 2, 30)
OPTIONS = MusynOptions(method="lmi", max_iter=3, patience=1, max_dfit_order=0, n_dense=40,
                       dscale_overrelax=1.0)
#: the extra constraint channel: input disturbance -> commanded control
FORCE = Channel(outputs=(2,), inputs=(2,))


def _plant():
    """G = 2/(s+1) with 40 % input-multiplicative uncertainty and a performance weight
    0.5 on the output error; inputs [p, w, d, u], outputs [q, e, u_cmd, y]: ``d`` (an
    input disturbance) and ``u_cmd`` are the channels of the constraints alone."""
    A = [[-1.0]]
    B = [[2.0, 0.0, 2.0, 2.0]]
    C = [[0.0], [0.5], [0.0], [1.0]]
    D = [[0.0, 0.0, 0.0, 0.4],
         [0.0, 0.5, 0.0, 0.0],
         [0.0, 0.0, 0.0, 1.0],
         [0.0, 1.0, 0.0, 0.0]]
    return control.ss(A, B, C, D)


def _force_peak(P, K) -> float:
    """sup over ‖d‖₂ ≤ 1 of |u_cmd(t)|: sqrt(C Wc Cᵀ) of the closed loop (Wilson 1989),
    with the Gramian from scipy here."""
    CL = lft(P, K, 1, 1)
    A, B = np.asarray(CL.A), np.asarray(CL.B)[:, [2]]
    C = np.asarray(CL.C)[[2]]
    Wc = scipy.linalg.solve_continuous_lyapunov(A, -B @ B.T)
    return float(np.sqrt(C @ Wc @ C.T)[0, 0])


def _mu_peak(P, K) -> tuple:
    CL = lft(P, K, 1, 1)
    M = freqresp(control.ss(CL.A, np.asarray(CL.B)[:, :2], np.asarray(CL.C)[:2],
                            np.asarray(CL.D)[:2, :2]), OMEGA)
    res = mussv(M, BLK, omega=OMEGA)
    return float(np.max(res.upper)), float(np.max(res.lower))


@pytest.fixture(scope="module")
def free():
    """The same D-K without the constraint channels (the plant without d and u_cmd)."""
    P = _plant()
    sub = control.ss(P.A, np.asarray(P.B)[:, [0, 1, 3]], np.asarray(P.C)[[0, 1, 3]],
                     np.asarray(P.D)[np.ix_([0, 1, 3], [0, 1, 3])])
    return musyn(sub, 1, 1, BLK, omega=OMEGA, options=OPTIONS)


def test_peak_bound_rides_in_the_k_step(free):
    P = _plant()
    free_peak = _force_peak(P, free.K)
    bound = 0.5 * free_peak
    res = musyn(P, 1, 1, BLK, omega=OMEGA, options=OPTIONS,
                constraints=[PeakBound(FORCE, (bound,))])
    # the constraint is met on the closed loop built here, and it is active: the free
    # design's force is twice the bound, the constrained one's is near it
    peak = _force_peak(P, res.K)
    assert 0.8 * bound < peak <= bound * (1 + 5e-3)
    assert res.mu_peak < 1.5 * free.mu_peak  # (and robust performance holds either way)
    # every iterate certified on it, on the unscaled plant
    for it in res.history:
        assert len(it.certificates) == 1 and it.certificates[0].met
    assert res.certificates[0].met
    # µ of the returned controller recomputed here: lower <= upper, the reported peak
    # is the upper bound (on the test's grid it can only be lower or equal, up to the
    # D-scale tolerance)
    upper, lower = _mu_peak(P, res.K)
    assert lower <= upper * (1 + 1e-6)
    assert upper <= res.mu_peak * (1 + 1e-3)
    assert res.mu_lower_peak <= res.mu_peak * (1 + 1e-6)
    # CL is the part blk covers
    assert (res.CL.noutputs, res.CL.ninputs) == (2, 2)


def test_pole_region_on_every_iterate():
    P = _plant()
    region = HalfPlane(alpha=3.0)
    res = musyn(P, 1, 1, BLK, omega=OMEGA, options=OPTIONS, constraints=[region])
    for it in res.history:
        poles = np.linalg.eigvals(np.asarray(lft(P, it.K, 1, 1).A))
        assert np.all(poles.real < -3.0)


def test_constraints_need_the_lmi_k_step():
    with pytest.raises(ParameterError, match="method='lmi'"):
        musyn(_plant(), 1, 1, BLK, omega=OMEGA, options=MusynOptions(method="best"),
              constraints=[HalfPlane(1.0)])


def test_extra_channels_without_constraints_are_a_dimension_error():
    with pytest.raises(DimensionError):
        musyn(_plant(), 1, 1, BLK, omega=OMEGA, options=OPTIONS)


def test_wrong_number_of_lyapunov_scales():
    with pytest.raises(ParameterError, match="one scale per constraint"):
        musyn(_plant(), 1, 1, BLK, omega=OMEGA, options=OPTIONS,
              constraints=[PeakBound(FORCE, (1.0,))], lyapunov_scales=[1.0, 2.0])


def test_constraints_no_controller_meets_together_are_infeasible():
    # each alone is met (u = 0 meets the force bound, pole placement the decay rate),
    # but moving the plant's pole at -1 left of -10 takes force the bound forbids
    P = _plant()
    with pytest.raises(InfeasibleError):
        musyn(P, 1, 1, BLK, omega=OMEGA, options=OPTIONS,
              constraints=[PeakBound(FORCE, (1e-6,)), HalfPlane(alpha=10.0)])


def test_initial_controller_must_meet_the_constraints():
    # u = k y moves the plant's pole to -1 + 2k (computed here from the closed loop)
    P, region = _plant(), HalfPlane(alpha=3.0)
    for k in (-0.5, -2.0):
        assert np.linalg.eigvals(np.asarray(lft(P, [[k]], 1, 1).A))[0] == \
            pytest.approx(-1.0 + 2.0 * k)
    with pytest.raises(ParameterError, match="K0 violates"):
        musyn(P, 1, 1, BLK, omega=OMEGA, options=OPTIONS, constraints=[region],
              K0=[[-0.5]])
    res = musyn(P, 1, 1, BLK, omega=OMEGA, options=OPTIONS, constraints=[region],
                K0=[[-2.0]])
    assert np.array_equal(res.history[0].K.D, [[-2.0]])
    assert res.history[0].certificates[0].met
    for it in res.history:
        poles = np.linalg.eigvals(np.asarray(lft(P, it.K, 1, 1).A))
        assert np.all(poles.real < -3.0)
