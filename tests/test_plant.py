"""GeneralizedPlant partitions and the lower LFT."""

import control
import numpy as np
import pytest

from lmi_suspension.errors import (DimensionError, DiscreteTimeError, IllPosedLoopError,
                                   NonFiniteError)
from lmi_suspension.lti import GeneralizedPlant, lft


def random_plant(rng, n=4, nw=2, nu=1, nz=2, ny=2, d22=True):
    blocks = dict(A=rng.standard_normal((n, n)), B1=rng.standard_normal((n, nw)),
                  B2=rng.standard_normal((n, nu)), C1=rng.standard_normal((nz, n)),
                  C2=rng.standard_normal((ny, n)), D11=rng.standard_normal((nz, nw)),
                  D12=rng.standard_normal((nz, nu)), D21=rng.standard_normal((ny, nw)),
                  D22=rng.standard_normal((ny, nu)) if d22 else np.zeros((ny, nu)))
    return GeneralizedPlant.from_matrices(**blocks), blocks


def test_blocks_round_trip():
    rng = np.random.default_rng(1)
    P, blocks = random_plant(rng)
    for name, value in blocks.items():
        np.testing.assert_array_equal(getattr(P, name), value)
    assert (P.nw, P.nu, P.nz, P.ny) == (2, 1, 2, 2)
    Q = GeneralizedPlant.from_statespace(P.sys, nmeas=2, ncon=1)
    np.testing.assert_array_equal(Q.D21, blocks["D21"])


def test_blocks_are_copies():
    rng = np.random.default_rng(2)
    P, _ = random_plant(rng)
    A = P.A
    A[0, 0] = 1e6
    assert P.A[0, 0] != 1e6


def test_lft_matches_python_control_lft():
    """Two routes: our explicit formula and python-control's StateSpace.lft."""
    rng = np.random.default_rng(3)
    P, _ = random_plant(rng)
    K = control.ss(rng.standard_normal((3, 3)), rng.standard_normal((3, 2)),
                   rng.standard_normal((1, 3)), 0.1 * rng.standard_normal((1, 2)))
    CL = lft(P, K)
    ref = P.sys.lft(K, nu=1, ny=2)
    omega = np.logspace(-2, 2, 50)
    np.testing.assert_allclose(CL(1j * omega), ref(1j * omega), rtol=1e-9, atol=1e-12)
    np.testing.assert_allclose(np.sort_complex(CL.poles()), np.sort_complex(ref.poles()),
                               rtol=1e-8)


def test_lft_static_gain_by_hand():
    """x' = x + w + u, z = x + u, y = x, u = -3y: closed loop x' = -2x + w, z = -2x."""
    P = GeneralizedPlant.from_matrices(A=[[1.0]], B1=[[1.0]], B2=[[1.0]], C1=[[1.0]],
                                       C2=[[1.0]], D12=[[1.0]])
    CL = lft(P, [[-3.0]])
    np.testing.assert_allclose(CL.A, [[-2.0]])
    np.testing.assert_allclose(CL.C, [[-2.0]])


def test_lft_ill_posed_raises():
    P = GeneralizedPlant.from_matrices(A=[[-1.0]], B1=[[1.0]], B2=[[1.0]], C1=[[1.0]],
                                       C2=[[1.0]], D22=[[0.5]])
    with pytest.raises(IllPosedLoopError, match="ill-posed"):
        lft(P, [[2.0]])  # I - D22*Dk = 1 - 0.5*2 = 0


@pytest.mark.parametrize("nmeas,ncon", [(0, 1), (2, 3), (4, 1), (2, 0), (1.5, 1), (True, 1)])
def test_bad_partition_raises(nmeas, ncon):
    rng = np.random.default_rng(4)
    P, _ = random_plant(rng)
    with pytest.raises(DimensionError):
        GeneralizedPlant.from_statespace(P.sys, nmeas=nmeas, ncon=ncon)


def test_wrong_block_shapes_raise():
    with pytest.raises(DimensionError, match="D12"):
        GeneralizedPlant.from_matrices(A=[[-1.0]], B1=[[1.0]], B2=[[1.0]], C1=[[1.0]],
                                       C2=[[1.0]], D12=[[1.0, 2.0]])
    with pytest.raises(DimensionError, match="B2"):
        GeneralizedPlant.from_matrices(A=np.eye(2), B1=[[1.0], [0.0]], B2=[[1.0]],
                                       C1=[[1.0, 0.0]], C2=[[1.0, 0.0]])


def test_controller_size_mismatch_raises():
    rng = np.random.default_rng(5)
    P, _ = random_plant(rng)
    with pytest.raises(DimensionError, match="measurements"):
        lft(P, np.zeros((2, 2)))


def test_nan_and_discrete_time_raise():
    with pytest.raises(NonFiniteError):
        GeneralizedPlant.from_matrices(A=[[np.nan]], B1=[[1.0]], B2=[[1.0]], C1=[[1.0]],
                                       C2=[[1.0]])
    Pd = control.ss([[0.5]], [[1.0, 1.0]], [[1.0], [1.0]], np.zeros((2, 2)), dt=0.1)
    with pytest.raises(DiscreteTimeError):
        GeneralizedPlant.from_statespace(Pd, nmeas=1, ncon=1)
