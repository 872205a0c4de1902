"""The seat model against an independent rebuild from the second-order form of eq. (1).

Reference: the paper's eq. (1) written as M q'' + C q' + K q = F_w z0 + F_c z0' + F_u u with
q = [z1, z2, z3]. The state-space model in ``seat_model`` was derived by hand from
eq. (1) in deflection coordinates (eq. 3); here it is rebuilt mechanically from the
mass, damping and stiffness matrices in absolute coordinates and compared as transfer
functions, so an error in either derivation shows up.
"""

import numpy as np
import pytest

from lmi_suspension.errors import NonFiniteError, ParameterError
from lmi_suspension.seat import SeatParameters, natural_modes, seat_matrices, seat_model


def second_order_form(p: SeatParameters):
    """Mass, damping and stiffness matrices of eq. (1), absolute coordinates q = [z1, z2, z3]."""
    M = np.diag([p.m1, p.m2, p.m3])
    C = np.array([[p.c1 + p.c2, -p.c2, 0.0],
                  [-p.c2, p.c2 + p.c3, -p.c3],
                  [0.0, -p.c3, p.c3]])
    K = np.array([[p.k1 + p.k2, -p.k2, 0.0],
                  [-p.k2, p.k2 + p.k3, -p.k3],
                  [0.0, -p.k3, p.k3]])
    # Road enters m1 through c1 (z0') and k1 (z0); u enters m1 with a minus sign.
    f_z0 = np.array([p.k1, 0.0, 0.0])
    f_z0dot = np.array([p.c1, 0.0, 0.0])
    f_u = np.array([-1.0, 0.0, 0.0])
    return M, C, K, f_z0, f_z0dot, f_u


def independent_frequency_response(p: SeatParameters, omega):
    """H(jω) from [z0', u] to [z3'', z1 - z0, z2 - z1] computed from eq. (1) directly.

    With z0' = w the road displacement is z0 = w / s.
    """
    M, C, K, f_z0, f_z0dot, f_u = second_order_form(p)
    H = np.zeros((3, 2, len(omega)), dtype=complex)
    for i, wk in enumerate(omega):
        s = 1j * wk
        Z = M * s**2 + C * s + K  # dynamic stiffness
        q_w = np.linalg.solve(Z, f_z0 / s + f_z0dot)  # response of q to w (z0 = w/s)
        q_u = np.linalg.solve(Z, f_u)
        for j, (q, z0) in enumerate(((q_w, 1.0 / s), (q_u, 0.0))):
            H[0, j, i] = s**2 * q[2]
            H[1, j, i] = q[0] - z0
            H[2, j, i] = q[1] - q[0]
    return H


@pytest.mark.parametrize("params", [SeatParameters(), SeatParameters(m3=70.0, k1=25000.0, c2=0.0)])
def test_state_space_matches_second_order_form(params):
    G = seat_model(params)
    omega = np.logspace(-1, 3, 200)
    H_ref = independent_frequency_response(params, omega)
    H = G(1j * omega)  # outputs x inputs x freq
    np.testing.assert_allclose(H[[0, 1, 2], :, :], H_ref, rtol=1e-9, atol=1e-12)
    # measurements are y = [x1, x3] (eq. 14)
    np.testing.assert_allclose(H[3], H_ref[1], rtol=1e-9, atol=1e-12)
    np.testing.assert_allclose(H[4], H_ref[2], rtol=1e-9, atol=1e-12)


def test_eigenvalues_match_generalized_eigenproblem():
    """Poles of the state-space model = roots of det(M s² + C s + K) = 0 (eq. 1)."""
    p = SeatParameters()
    M, C, K, *_ = second_order_form(p)
    n = 3
    # First-order companion form of the quadratic eigenproblem.
    Aq = np.block([[np.zeros((n, n)), np.eye(n)],
                   [-np.linalg.solve(M, K), -np.linalg.solve(M, C)]])
    ref = np.sort_complex(np.linalg.eigvals(Aq))
    got = np.sort_complex(seat_model(p).poles())
    np.testing.assert_allclose(got, ref, rtol=1e-10)


def test_corrected_bw_and_force_sign():
    """ERRATA: B_w = [-1, +c1/m1, 0, 0, 0, 0]^T and B = [0, -1/m1, 0, 0, 0, 0]^T."""
    p = SeatParameters()
    m = seat_matrices(p)
    np.testing.assert_array_equal(m.Bw.ravel(), [-1.0, p.c1 / p.m1, 0, 0, 0, 0])
    np.testing.assert_array_equal(m.B.ravel(), [0.0, -1.0 / p.m1, 0, 0, 0, 0])
    # C1 = [0, 0, 0, c3/m3, -k3/m3, -c3/m3] (eq. 16) and no feedthrough
    np.testing.assert_allclose(m.C1.ravel(), [0, 0, 0, p.c3 / p.m3, -p.k3 / p.m3, -p.c3 / p.m3])
    assert not np.any(seat_model(p).D)


def test_static_force_deflects_seat_down():
    """A constant upward actuator force u > 0 acts as -u on m1: at steady state the
    deflection is -u/k1 (all springs in series above carry no load)."""
    p = SeatParameters()
    G = seat_model(p)
    dc = G.dcgain()  # outputs x inputs
    assert dc[1, 1] == pytest.approx(-1.0 / p.k1, rel=1e-12)
    # body acceleration has no static response
    assert dc[0, 1] == pytest.approx(0.0, abs=1e-12)


def test_table1_values_and_m2_split():
    p = SeatParameters()
    assert (p.m21, p.m22, p.m2) == (1.0, 7.8, pytest.approx(8.8))  # Table 1 "1+7.8"
    assert (p.m1, p.m3, p.c1, p.c2, p.c3, p.k1, p.k2, p.k3) == (
        15.0, 43.3, 830.0, 200.0, 1485.0, 31000.0, 18000.0, 44130.0)
    assert (p.z_max, p.u_max, p.delay_min, p.delay_max) == (0.08, 1500.0, 0.0, 0.025)


@pytest.mark.parametrize("field,value,err", [
    ("m1", 0.0, ParameterError), ("m3", -43.3, ParameterError), ("k2", -1.0, ParameterError),
    ("c1", -5.0, ParameterError), ("k3", float("nan"), NonFiniteError),
    ("u_max", float("inf"), NonFiniteError), ("delay_min", -0.001, ParameterError),
    ("m22", "7.8", ParameterError),
])
def test_bad_parameters_raise_typed_errors(field, value, err):
    with pytest.raises(err, match=field):
        SeatParameters(**{field: value})
    assert issubclass(err, ValueError)


def test_delay_bounds_ordered():
    with pytest.raises(ParameterError, match="delay_max"):
        SeatParameters(delay_min=0.03, delay_max=0.02)


def test_natural_modes_consistent_with_poles():
    modes = natural_modes()
    poles = seat_model().poles()
    for f_hz, wn, zeta in modes:
        assert f_hz == pytest.approx(wn / (2 * np.pi))
        assert np.min(np.abs(np.abs(poles) - wn)) < 1e-9 * wn
        assert 0 < zeta <= 1.0
    # Rayleigh's principle: the rigid-occupant mode shape q = [1, 1, 1] gives an upper
    # bound sqrt(k1 / (m1 + m2 + m3)) on the undamped fundamental frequency.
    p = SeatParameters()
    M, _, K, *_ = second_order_form(p)
    w_undamped = np.sqrt(np.min(np.linalg.eigvals(np.linalg.solve(M, K)).real))
    w_rigid = np.sqrt(p.k1 / (p.m1 + p.m2 + p.m3))
    assert w_undamped <= w_rigid
    # the lightly damped first mode (ζ ≈ 0.13) sits close to the undamped one
    assert modes[0][1] == pytest.approx(w_undamped, rel=0.05)
