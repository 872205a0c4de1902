"""Scaling of generalized plants before a solver sees them, and the map back.

A plant with entries spanning many decades (the seat model mixes 1e-3 and 1e4) makes
LMI solvers lose digits.  :func:`scale_plant` applies transformations that do not change
the achievable closed-loop performance and records them so a controller designed for the
scaled plant can be mapped back:

* a diagonal state similarity ``x = T x_s`` (``scipy.linalg.matrix_balance`` of
  ``[[A, B], [C, 0]]``, powers of two, so exact in floating point);
* diagonal scalings of the controls ``u = Su u_s`` and measurements ``y_s = Sy y``,
  absorbed by the controller: ``K = Su K_s Sy``;
* one scalar on all disturbances ``w = cw w_s`` and one on all errors ``z_s = z / cz``,
  which scale every closed-loop norm by the same factor: ``gamma_s = gamma cw / cz``.
"""

from __future__ import annotations

from dataclasses import dataclass, replace

import control
import numpy as np
import scipy.linalg

from ..errors import DimensionError
from .checks import as_statespace
from .plant import GeneralizedPlant

__all__ = ["PlantScaling", "balanced_matrices", "balanced_statespace", "scale_plant",
           "state_balance", "transform_states"]


def _pow2(x):
    # powers of two keep the scaling exact in floating point
    x = np.asarray(x, dtype=float)
    x = np.where(np.isfinite(x) & (x > 0), x, 1.0)
    return np.exp2(np.round(np.log2(x)))


def state_balance(A, B, C) -> np.ndarray:
    """Diagonal ``T`` (powers of two) such that ``T⁻¹AT``, ``T⁻¹B``, ``CT`` are balanced.

    LAPACK's ``gebal`` (``scipy.linalg.matrix_balance``, no permutation) on the square
    matrix ``[[A, B], [C, 0]]`` padded with zeros, as MATLAB's ``ssbal`` does.

    Examples
    --------
    >>> import numpy as np
    >>> A = np.array([[-1.0, 1e6], [0.0, -2.0]])
    >>> T = state_balance(A, np.ones((2, 1)), np.ones((1, 2)))
    >>> float(abs(A[0, 1] * T[1] / T[0]))  # the coupling entry of T⁻¹AT
    61.03515625
    """
    A, B, C = (np.asarray(M, dtype=float) for M in (A, B, C))
    n = A.shape[0]
    m = max(B.shape[1], C.shape[0])
    M = np.zeros((n + m, n + m))
    M[:n, :n] = A
    M[:n, n:n + B.shape[1]] = B
    M[n:n + C.shape[0], :n] = C
    _, (scale, _perm) = scipy.linalg.matrix_balance(M, permute=False, separate=True)
    return _pow2(scale[:n])


def balanced_statespace(sys: control.StateSpace) -> control.StateSpace:
    """``sys`` after the diagonal state similarity of :func:`state_balance`.

    Same transfer function (powers of two, so the matrices are exact); evaluations of
    ``C (sI - A)⁻¹ B`` on the result, python-control's included, are far more accurate
    when the original states span many decades of scale.

    Examples
    --------
    >>> import control, numpy as np
    >>> G = control.ss([[-1.0, 1e6], [0.0, -2.0]], [[0.0], [1.0]], [[1.0, 0.0]], [[0.0]])
    >>> Gb = balanced_statespace(G)
    >>> bool(np.isclose(complex(Gb(1j)), complex(G(1j))))
    True
    """
    A, B, C, D = (np.asarray(M, dtype=float) for M in (sys.A, sys.B, sys.C, sys.D))
    if A.shape[0] == 0 or not all(np.all(np.isfinite(M)) for M in (A, B, C)):
        return sys
    return control.ss(*balanced_matrices(A, B, C), D)


def balanced_matrices(A, B, C):
    """``T⁻¹AT``, ``T⁻¹B``, ``CT`` with ``T`` from :func:`state_balance` (finite data)."""
    T = state_balance(A, B, C)
    return A / T[:, None] * T[None, :], B / T[:, None], C * T[None, :]


@dataclass(frozen=True)
class PlantScaling:
    """Scalings applied by :func:`scale_plant` (all powers of two).

    Attributes
    ----------
    T : numpy.ndarray
        Diagonal of the state similarity ``x = diag(T) x_s``.
    Su, Sy : numpy.ndarray
        Diagonals of ``u = diag(Su) u_s`` and ``y_s = diag(Sy) y``.
    cw, cz : float
        ``w = cw w_s`` and ``z_s = z / cz``.
    """

    T: np.ndarray
    Su: np.ndarray
    Sy: np.ndarray
    cw: float
    cz: float

    @property
    def gamma_factor(self) -> float:
        """``gamma_scaled / gamma_original`` for every closed loop."""
        return self.cw / self.cz

    def with_error_scale(self, P: GeneralizedPlant, factor: float
                         ) -> tuple[GeneralizedPlant, "PlantScaling"]:
        """Divide the errors of the already scaled ``P`` by ``factor`` (e.g. a first γ
        estimate, so the next solve sees γ near 1); return the plant and the scaling."""
        f = float(_pow2(factor))
        b = P.blocks()
        Ps = GeneralizedPlant.from_matrices(b["A"], b["B1"], b["B2"], b["C1"] / f, b["C2"],
                                            b["D11"] / f, b["D12"] / f, b["D21"], b["D22"],
                                            dt=P.dt)
        return Ps, replace(self, cz=self.cz * f)

    def controller_to_original(self, Ks) -> control.StateSpace:
        """Map a controller of the scaled plant back: ``K = Su K_s Sy``."""
        Ks = as_statespace(Ks, "K", discrete=True)
        Su, Sy = np.diag(self.Su), np.diag(self.Sy)
        return control.ss(Ks.A, np.asarray(Ks.B) @ Sy, Su @ np.asarray(Ks.C),
                          Su @ np.asarray(Ks.D) @ Sy, Ks.dt)


def scale_plant(P: GeneralizedPlant, *, states: bool = True, io: bool = True
                ) -> tuple[GeneralizedPlant, PlantScaling]:
    """Balance a generalized plant; return the scaled plant and the scaling.

    Examples
    --------
    >>> from lmi_suspension.lti import GeneralizedPlant
    >>> P = GeneralizedPlant.from_matrices(A=[[-1e3, 1e4], [0.0, -1e-2]], B1=[[0.0], [1.0]],
    ...     B2=[[1e3], [0.0]], C1=[[1e-3, 0.0]], C2=[[0.0, 1e2]], D12=[[1.0]], D21=[[1.0]])
    >>> Ps, sc = scale_plant(P)
    >>> bool(abs(Ps.A).max() < abs(P.A).max())
    True
    """
    b = P.blocks()
    A = b["A"]
    n = A.shape[0]
    T = np.ones(n)
    if states and n:
        T = state_balance(A, np.hstack([b["B1"], b["B2"]]), np.vstack([b["C1"], b["C2"]]))
    Ti = 1.0 / T
    A = Ti[:, None] * A * T[None, :]
    B1, B2 = Ti[:, None] * b["B1"], Ti[:, None] * b["B2"]
    C1, C2 = b["C1"] * T[None, :], b["C2"] * T[None, :]
    D11, D12, D21, D22 = b["D11"], b["D12"], b["D21"], b["D22"]
    Su, Sy, cw, cz = np.ones(P.nu), np.ones(P.ny), 1.0, 1.0
    if io:
        Su = _pow2(1.0 / np.linalg.norm(np.vstack([B2, D12, D22]), axis=0))
        B2, D12 = B2 * Su[None, :], D12 * Su[None, :]
        Sy = _pow2(1.0 / np.linalg.norm(np.hstack([C2, D21, D22 * Su[None, :]]), axis=1))
        C2, D21 = Sy[:, None] * C2, Sy[:, None] * D21
        D22 = Sy[:, None] * D22 * Su[None, :]
        cw = float(_pow2(1.0 / np.linalg.norm(np.vstack([B1, D11, D21]), 2)))
        cz = float(_pow2(np.linalg.norm(np.hstack([C1, D11 * cw, D12]), 2)))
        B1, D11, D21 = B1 * cw, D11 * (cw / cz), D21 * cw
        C1, D12 = C1 / cz, D12 / cz
    Ps = GeneralizedPlant.from_matrices(A, B1, B2, C1, C2, D11, D12, D21, D22, dt=P.dt)
    return Ps, PlantScaling(T=T, Su=Su, Sy=Sy, cw=cw, cz=cz)


def transform_states(P: GeneralizedPlant, T) -> GeneralizedPlant:
    """The same plant in the state coordinates ``x = T x_new`` (``T`` invertible).

    A state similarity leaves every input-output map unchanged, so a controller designed
    for the transformed plant is a controller of ``P`` as it is.

    Examples
    --------
    >>> import numpy as np
    >>> from lmi_suspension.lti import GeneralizedPlant
    >>> P = GeneralizedPlant.from_matrices(A=[[-1.0, 2.0], [0.0, -3.0]], B1=[[1.0], [0.0]],
    ...     B2=[[0.0], [1.0]], C1=[[1.0, 0.0]], C2=[[0.0, 1.0]], D12=[[1.0]], D21=[[1.0]])
    >>> Pt = transform_states(P, [[2.0, 1.0], [0.0, 1.0]])
    >>> bool(np.allclose(np.sort(np.linalg.eigvals(Pt.A)), [-3.0, -1.0]))
    True
    """
    T = np.asarray(T, dtype=float)
    b = P.blocks()
    n = b["A"].shape[0]
    if T.shape != (n, n):
        raise DimensionError(f"T must be {n}x{n}, got shape {T.shape}")
    A = np.linalg.solve(T, b["A"] @ T)
    B1, B2 = np.linalg.solve(T, b["B1"]), np.linalg.solve(T, b["B2"])
    return GeneralizedPlant.from_matrices(A, B1, B2, b["C1"] @ T, b["C2"] @ T, b["D11"],
                                          b["D12"], b["D21"], b["D22"], dt=P.dt)
