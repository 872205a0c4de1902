"""The bilinear (Tustin) map between continuous and discrete time, exactly invertible.

``z = (1 + s dt/2) / (1 - s dt/2)`` without pre-warping maps the imaginary axis onto the
unit circle (``ω_c = (2/dt) tan(ω dt/2)``, ``ω`` the discrete frequency in rad/s), the open
left half-plane onto the open unit disk, and preserves every frequency-wise quantity: H∞
norms, µ at each frequency, stability.  A discrete-time design problem whose requirements
are such quantities is therefore the same problem as its continuous-time image, and a
controller designed for the image is mapped back exactly (``tustin`` of ``tustin_image`` is
the identity on matrices, up to roundoff).

The realizations keep ``B`` and ``C`` balanced by ``sqrt(2a)``, ``a = 2/dt`` (the form
that makes the map an isometry of the state-space data): with ``M = (aI - Ac)⁻¹``::

    A = M (aI + Ac),  B = sqrt(2a) M Bc,  C = sqrt(2a) Cc M,  D = Dc + Cc M Bc

and the inverse with ``N = (A + I)⁻¹``::

    Ac = a N (A - I),  Bc = sqrt(2a) N B,  Cc = sqrt(2a) C N,  Dc = D - C N B.

python-control's ``sample_system(sys, dt, "tustin")`` gives the same transfer function in
another realization; it has no inverse map.
"""

from __future__ import annotations

import control
import numpy as np
import scipy.linalg

from ..errors import ParameterError
from .checks import as_statespace, positive_scalar, sample_time

__all__ = ["tustin", "tustin_image", "tustin_frequency", "image_frequency"]


def _abcd(ss):
    n = ss.nstates
    return (np.asarray(ss.A, dtype=float).reshape(n, n),
            np.asarray(ss.B, dtype=float).reshape(n, ss.ninputs),
            np.asarray(ss.C, dtype=float).reshape(ss.noutputs, n),
            np.asarray(ss.D, dtype=float).reshape(ss.noutputs, ss.ninputs))


def tustin(sys, dt: float) -> control.StateSpace:
    """The discrete-time system of sample time ``dt`` whose values on the unit circle are
    those of the continuous-time ``sys`` on the imaginary axis (module docstring).

    Raises
    ------
    ParameterError
        If ``sys`` has a pole at ``s = 2/dt`` (it has no image then).

    Examples
    --------
    >>> import control
    >>> Gd = tustin(control.tf([1.0], [1.0, 1.0]), 0.1)
    >>> round(float(abs(Gd(1.0))), 12)  # DC gain kept
    1.0
    """
    ss = as_statespace(sys, "sys")
    dt = positive_scalar(dt, "dt")
    A, B, C, D = _abcd(ss)
    n = A.shape[0]
    if n == 0:
        return control.ss([], [], [], D, dt)
    a = 2.0 / dt
    A, B, C, lu = _factor(lambda A_: a * np.eye(n) - A_, A, B, C,
                          f"sys has a pole at s = 2/dt = {a:.6g}")
    M_B = scipy.linalg.lu_solve(lu, B)
    C_M = scipy.linalg.lu_solve(lu, C.T, trans=1).T
    r = np.sqrt(2.0 * a)
    Ad = scipy.linalg.lu_solve(lu, a * np.eye(n) + A)
    return control.ss(Ad, r * M_B, r * C_M, D + C @ M_B, dt)


def tustin_image(sys) -> control.StateSpace:
    """The continuous-time image of the discrete-time ``sys`` (the inverse of
    :func:`tustin` at ``sys.dt``).

    Raises
    ------
    ParameterError
        If ``sys`` has a pole at ``z = -1`` (it has no image then).

    Examples
    --------
    >>> import control
    >>> G = control.ss([[-2.0]], [[1.0]], [[3.0]], [[0.5]])
    >>> Gc = tustin_image(tustin(G, 0.05))
    >>> bool(abs(float(Gc.A[0, 0]) + 2.0) < 1e-12), round(float(Gc.D[0, 0]), 12)
    (True, 0.5)
    """
    ss = as_statespace(sys, "sys", discrete=True)
    dt = sample_time(ss, "sys")
    if not dt:
        raise ParameterError("tustin_image needs a discrete-time system (dt > 0)")
    A, B, C, D = _abcd(ss)
    n = A.shape[0]
    if n == 0:
        return control.ss([], [], [], D)
    a = 2.0 / dt
    A, B, C, lu = _factor(lambda A_: A_ + np.eye(n), A, B, C, "sys has a pole at z = -1")
    N_B = scipy.linalg.lu_solve(lu, B)
    C_N = scipy.linalg.lu_solve(lu, C.T, trans=1).T
    r = np.sqrt(2.0 * a)
    return control.ss(a * scipy.linalg.lu_solve(lu, A - np.eye(n)), r * N_B, r * C_N,
                      D - C @ N_B)


def image_frequency(omega, dt: float) -> np.ndarray:
    """``ω_c = (2/dt) tan(ω dt/2)``: where the image takes the value the discrete system
    takes at ``exp(jω dt)`` (``ω = π/dt`` maps to ``inf``)."""
    w = np.asarray(omega, dtype=float)
    out = 2.0 / dt * np.tan(w * dt / 2.0)
    return np.where(np.isclose(w * dt, np.pi, rtol=0, atol=1e-15), np.inf, out)


def tustin_frequency(omega_c, dt: float) -> np.ndarray:
    """``ω = (2/dt) arctan(ω_c dt/2)``: the inverse of :func:`image_frequency`."""
    return 2.0 / dt * np.arctan(np.asarray(omega_c, dtype=float) * dt / 2.0)


def _factor(shifted, A, B, C, what: str):
    """``(A, B, C, lu)`` with ``lu`` the factors of ``shifted(A)``, in the given state
    coordinates where that matrix is well conditioned, else in balanced ones (a similarity,
    so the same transfer function): a condition number above 1e14 in both is a pole at
    the map's singular point.  The given coordinates are kept where they serve, so results
    there are those of the plain formula; an LMI controller at a fixed γ had entries from
    1e-13 to 1e11 and a condition number of ``2/dt·I - A`` above 1e14 with its poles at
    most 108 rad/s, nowhere near ``2/dt = 200`` (COMPleib AC4, 10 ms, 2026-12-02)."""
    M = shifted(A)
    if np.linalg.cond(M) <= _SINGULAR_COND:
        return A, B, C, scipy.linalg.lu_factor(M)
    _, (scale, _) = scipy.linalg.matrix_balance(A, permute=False, separate=True)
    A = A * scale[None, :] / scale[:, None]          # T⁻¹ A T with T = diag(scale)
    B, C = B / scale[:, None], C * scale[None, :]
    M = shifted(A)
    if np.linalg.cond(M) > _SINGULAR_COND:
        raise ParameterError(f"the bilinear map is singular: {what}")
    return A, B, C, scipy.linalg.lu_factor(M)


#: the condition number beyond which the map's shifted matrix counts as singular
_SINGULAR_COND = 1e14
