"""State-space model of the seat suspension with a 3-DOF seated human (paper eqs. 1–5, 14–16).

States (eq. 3)::

    x1 = z1 - z0   seat-suspension deflection, m
    x2 = z1'       seat-frame velocity, m/s
    x3 = z2 - z1   cushion deflection, m
    x4 = z2'       thigh/buttock velocity, m/s
    x5 = z3 - z2   spine deflection, m
    x6 = z3'       upper-body velocity, m/s

Inputs: ``w`` = z0' (floor velocity, m/s) and ``u`` (actuator force, N, applied as
``-u`` on m1 exactly as in eq. 1). The printed B_w of eq. (5) is wrong; the one here is
derived from eq. (1) (see ``shared/paper/ERRATA.md``).
"""

from __future__ import annotations

from dataclasses import dataclass

import control
import numpy as np

from .params import SeatParameters

__all__ = ["SeatMatrices", "seat_matrices", "seat_model", "natural_modes", "STATE_NAMES"]

STATE_NAMES = ("x1", "x2", "x3", "x4", "x5", "x6")
INPUT_NAMES = ("w", "u")
OUTPUT_NAMES = ("z3dd", "x1", "x3", "y1", "y2")


@dataclass(frozen=True)
class SeatMatrices:
    """The matrices of eq. (4)/(15): ``x' = A x + B u + Bw w``, ``z3'' = C1 x``,
    ``x1 = C2 x``, ``y = C3 x``."""

    A: np.ndarray
    B: np.ndarray
    Bw: np.ndarray
    C1: np.ndarray
    C2: np.ndarray
    C3: np.ndarray


def _as_params(params: SeatParameters | None) -> SeatParameters:
    if params is None:
        return SeatParameters()
    if not isinstance(params, SeatParameters):
        raise TypeError(f"params must be a SeatParameters, got {type(params).__name__}")
    return params


def seat_matrices(params: SeatParameters | None = None) -> SeatMatrices:
    """Return the state-space matrices of the seat model (eq. 5 with the corrected B_w).

    Examples
    --------
    >>> from lmi_suspension.seat import seat_matrices
    >>> M = seat_matrices()
    >>> M.Bw.ravel().round(3).tolist()
    [-1.0, 55.333, 0.0, 0.0, 0.0, 0.0]
    """
    p = _as_params(params)
    m1, m2, m3 = p.m1, p.m2, p.m3
    c1, c2, c3, k1, k2, k3 = p.c1, p.c2, p.c3, p.k1, p.k2, p.k3
    A = np.array([
        [0.0, 1.0, 0.0, 0.0, 0.0, 0.0],
        [-k1 / m1, -(c1 + c2) / m1, k2 / m1, c2 / m1, 0.0, 0.0],
        [0.0, -1.0, 0.0, 1.0, 0.0, 0.0],
        [0.0, c2 / m2, -k2 / m2, -(c2 + c3) / m2, k3 / m2, c3 / m2],
        [0.0, 0.0, 0.0, -1.0, 0.0, 1.0],
        [0.0, 0.0, 0.0, c3 / m3, -k3 / m3, -c3 / m3],
    ])
    B = np.array([[0.0], [-1.0 / m1], [0.0], [0.0], [0.0], [0.0]])
    Bw = np.array([[-1.0], [c1 / m1], [0.0], [0.0], [0.0], [0.0]])
    C1 = A[5:6, :].copy()  # z3'' = x6' (eq. 16); no feedthrough from u or w
    C2 = np.array([[1.0, 0.0, 0.0, 0.0, 0.0, 0.0]])
    C3 = np.array([[1.0, 0.0, 0.0, 0.0, 0.0, 0.0], [0.0, 0.0, 1.0, 0.0, 0.0, 0.0]])
    return SeatMatrices(A=A, B=B, Bw=Bw, C1=C1, C2=C2, C3=C3)


def seat_model(params: SeatParameters | None = None) -> control.StateSpace:
    """The 6-state seat + human model as a named :class:`control.StateSpace`.

    Parameters
    ----------
    params : SeatParameters, optional
        Physical parameters; the paper's Table 1 by default.

    Returns
    -------
    control.StateSpace
        Inputs ``['w', 'u']`` (floor velocity in m/s, actuator force in N) and outputs
        ``['z3dd', 'x1', 'x3', 'y1', 'y2']``: upper-body acceleration (m/s²), suspension
        deflection (m), cushion deflection (m) and the two measurements ``y = [x1, x3]``.

    Examples
    --------
    >>> from lmi_suspension.seat import seat_model
    >>> G = seat_model()
    >>> G.ninputs, G.noutputs, G.nstates
    (2, 5, 6)
    >>> bool(all(G.poles().real < 0))
    True
    """
    M = seat_matrices(params)
    C = np.vstack([M.C1, M.C2, M.C3[1:2], M.C3])
    D = np.zeros((5, 2))
    return control.ss(M.A, np.hstack([M.Bw, M.B]), C, D,
                      inputs=list(INPUT_NAMES), outputs=list(OUTPUT_NAMES),
                      states=list(STATE_NAMES), name="seat")


def natural_modes(params: SeatParameters | None = None) -> list[tuple[float, float, float]]:
    """Natural frequencies and damping of the passive seat model.

    Returns
    -------
    list of (f_hz, omega_n, zeta)
        One entry per oscillatory mode (complex-conjugate pair) or real pole, sorted
        by natural frequency: frequency in Hz, natural frequency in rad/s, damping ratio.

    Examples
    --------
    >>> from lmi_suspension.seat import natural_modes
    >>> len(natural_modes()) >= 3
    True
    """
    poles = seat_model(params).poles()
    modes = []
    for p in poles:
        if p.imag < 0:
            continue  # one entry per conjugate pair
        wn = abs(p)
        zeta = -p.real / wn if wn > 0 else 1.0
        modes.append((wn / (2 * np.pi), wn, zeta))
    modes.sort(key=lambda m: m[1])
    return modes
