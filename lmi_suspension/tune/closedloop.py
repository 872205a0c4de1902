"""One model's loop closed by the tunable blocks at a parameter vector θ, with the
derivatives a requirement needs.

:class:`ClosedLoop` is what a :class:`~lmi_suspension.tune.Requirement` reads: the closed
loop from the disturbances ``w`` to the errors ``z`` (``A``, ``B``, ``C``, ``D`` and
:attr:`~ClosedLoop.ss`), its poles, the input sensitivity at the plant's controls, and
three derivatives with respect to θ from which any requirement's (sub)gradient follows
by the chain rule:

* :meth:`~ClosedLoop.gain_gradient`: ``∇θ Re(aᴴ T(jω) b)`` for vectors ``a``, ``b``
  (the derivative of a singular value at its peak is of this form, with ``a``, ``b``
  the singular vectors);
* :meth:`~ClosedLoop.pole_gradient`: ``∇θ λ`` of a simple closed-loop eigenvalue;
* :meth:`~ClosedLoop.sensitivity_gradient`: ``∇θ Re(aᴴ S(jω) b)`` for the input
  sensitivity ``S = (I - K P22)⁻¹`` (the map from a disturbance added at the plant's
  controls to the controls the plant receives).

The derivatives follow :mod:`~lmi_suspension.tune.hinfstruct`: the controller is the
static ``K̄ = [[D_K, C_K], [B_K, A_K]]`` closing the plant augmented with the
controller's integrators, and for an input ``d`` added to ``v = [u; x_K']``,
``dT = T_zd dK̄ T_ȳw``, ``dS = S_vd dK̄ T_ȳd`` and ``dA_cl = B₂ L dK̄ R C₂`` (``L``,
``R`` the loop's two inverses), all evaluated on the stable closed loop.
"""

from __future__ import annotations

import control
import numpy as np
import scipy.linalg

from ..lti.norms import STABILITY_TOL
from ..lti.scaling import balanced_matrices

__all__ = ["ClosedLoop"]


class ClosedLoop:
    """The plant of one model closed by the blocks at ``theta`` (built by
    :func:`~lmi_suspension.tune.systune`; a requirement only reads it).

    Attributes
    ----------
    theta : numpy.ndarray
        The blocks' free parameters (:attr:`controller` is the controller there).
    A, B, C, D : numpy.ndarray
        The closed loop from ``w`` to ``z``, states ``[x_P; x_K]``.
    plant : GeneralizedPlant
        The model's plant.
    nw, nz, nu : int
        Numbers of disturbances, errors and controls.
    """

    @classmethod
    def from_blocks(cls, P, blocks, theta, nmeas: int | None = None,
                    ncon: int | None = None) -> ClosedLoop:
        """The loop of plant ``P`` closed by ``blocks`` at ``theta``: to try a
        requirement of one's own outside :func:`~lmi_suspension.tune.systune`.

        Examples
        --------
        >>> import control
        >>> from lmi_suspension.tune import tunable_gain
        >>> P = control.ss([[-1.0]], [[1.0, 1.0]], [[1.0], [1.0]], [[0.0, 0.0], [0.0, 0.0]])
        >>> loop = ClosedLoop.from_blocks(P, tunable_gain("K", 1, 1), [-2.0])
        >>> loop.poles.real.tolist(), loop.stable                 # -1 + k
        ([-3.0], True)
        """
        from .blocks import block_diagonal
        from .hinfstruct import _Loop, _plant

        block = block_diagonal(blocks)
        return cls(_Loop(_plant(P, nmeas, ncon, block), block), theta)

    def __init__(self, loop, theta):
        self.theta = np.asarray(theta, dtype=float)
        self.plant = loop.G
        self._loop = loop
        Kbar = loop.kbar(self.theta)
        (self.A, self.B, Bd, self.C, Cy, self.D, Dzd, Dyw, L, R) = loop._closed(Kbar)
        self._Bd, self._Cy, self._Dzd, self._Dyw = Bd, Cy, Dzd, Dyw
        self._Cv = L @ Kbar @ loop.C2a             # v = [u; x_K'] from the states,
        self._Dvd, self._Dyd = L, loop.D22a @ L    # and from d; ȳ from d
        self._J = np.asarray(loop.block.jacobian(self.theta), dtype=float)
        self._B2L, self._RC2 = loop.B2a @ L, R @ loop.C2a
        self.nw, self.nz, self.nu = self.B.shape[1], self.C.shape[0], loop.G.nu
        self._eig = None

    @property
    def n_params(self) -> int:
        return self._J.shape[0]

    @property
    def block(self):
        """The tunable block (all the model's blocks as one)."""
        return self._loop.block

    @property
    def controller(self) -> control.StateSpace:
        """The controller at ``theta``, for a requirement evaluated on the controller
        itself (its poles, as MATLAB's ``TuningGoal.ControllerPoles``) or on a model no
        finite plant holds (an exact delay)."""
        return self._loop.block.ss(self.theta)

    @property
    def ss(self) -> control.StateSpace:
        """The closed loop ``w -> z`` as a :class:`control.StateSpace`."""
        return control.ss(self.A, self.B, self.C, self.D)

    # ------------------------------------------------------------------ poles
    def eig(self):
        """``(λ, left, right)`` eigenvectors of ``A`` (``leftᴴ A = λ leftᴴ``), cached."""
        if self._eig is None:
            if self.A.size:
                self._eig = scipy.linalg.eig(self.A, left=True, right=True)
            else:
                self._eig = (np.zeros(0, complex), np.zeros((0, 0)), np.zeros((0, 0)))
        return self._eig

    @property
    def poles(self) -> np.ndarray:
        return self.eig()[0]

    @property
    def stable(self) -> bool:
        """Every pole ``p`` has ``Re p < -1e-12 max(1, |p|)`` (``hinfnorm``'s test)."""
        p = self.poles
        return bool(np.all(np.isfinite(p)) and
                    np.all(p.real < -STABILITY_TOL * np.maximum(1.0, np.abs(p))))

    def pole_gradient(self, k: int) -> np.ndarray:
        """``∇θ λ_k`` (complex) of the ``k``-th pole of :attr:`poles`; zeros where it
        is (numerically) defective, where it has no derivative."""
        _, vl, vr = self.eig()
        x, y = vr[:, k], vl[:, k]
        yx = y.conj() @ x
        if abs(yx) < 1e-14 * np.linalg.norm(x) * np.linalg.norm(y):
            return np.zeros(self.n_params, dtype=complex)
        a = (y.conj() @ self._B2L) / yx
        b = self._RC2 @ x
        return np.einsum("pij,i,j->p", self._J, a, b)

    # ------------------------------------------------------------------ responses
    def _at(self, omega, B, C, D):
        if not np.isfinite(omega) or self.A.size == 0:
            return D.astype(complex)
        Ab, Bb, Cb = balanced_matrices(self.A, B, C)
        return Cb @ np.linalg.solve(1j * omega * np.eye(self.A.shape[0]) - Ab, Bb) + D

    def response(self, omega: float) -> np.ndarray:
        """``T(jω)``, the closed loop ``w -> z`` (``omega = inf`` gives ``D``)."""
        return self._at(omega, self.B, self.C, self.D)

    def gain_gradient(self, omega: float, a, b) -> np.ndarray:
        """``∇θ Re(aᴴ T(jω) b)`` for ``a`` of length ``nz`` and ``b`` of length ``nw``."""
        nz, nw = self.nz, self.nw
        H = self._at(omega, np.hstack([self.B, self._Bd]), np.vstack([self.C, self._Cy]),
                     np.block([[self.D, self._Dzd], [self._Dyw, self._Dyd]]))
        left = np.asarray(a).conj() @ H[:nz, nw:]                  # aᴴ T_zd
        right = H[nz:, :nw] @ np.asarray(b)                        # T_ȳw b
        return np.einsum("pij,i,j->p", self._J, left, right).real

    @property
    def input_sensitivity(self) -> control.StateSpace:
        """``S = (I - K P22)⁻¹`` at the plant's controls (``nu × nu``): from a
        disturbance added to the controls to what the plant receives."""
        nu = self.nu
        return control.ss(self.A, self._Bd[:, :nu], self._Cv[:nu], self._Dvd[:nu, :nu])

    def sensitivity_gradient(self, omega: float, a, b) -> np.ndarray:
        """``∇θ Re(aᴴ S(jω) b)`` of the input sensitivity, ``a``, ``b`` of length
        ``nu``."""
        nu, nv = self.nu, self._Bd.shape[1]
        H = self._at(omega, self._Bd, np.vstack([self._Cv, self._Cy]),
                     np.vstack([self._Dvd, self._Dyd]))
        ap, bp = np.zeros(nv, complex), np.zeros(nv, complex)
        ap[:nu], bp[:nu] = a, b
        left = ap.conj() @ H[:nv]                                   # aᴴ S_vd
        right = H[nv:] @ bp                                         # T_ȳd b
        return np.einsum("pij,i,j->p", self._J, left, right).real
