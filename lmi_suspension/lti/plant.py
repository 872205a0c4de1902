"""Generalized plants that carry their partition, and the lower LFT.

A generalized plant maps ``[w; u] -> [z; y]``::

    x' = A  x + B1  w + B2  u
    z  = C1 x + D11 w + D12 u
    y  = C2 x + D21 w + D22 u

with ``w`` the exogenous inputs (disturbances, perturbation inputs), ``u`` the
controls, ``z`` the errors and ``y`` the measurements.  As in python-control and
MATLAB, the controls are the *last* ``ncon`` inputs and the measurements the
*last* ``nmeas`` outputs.
"""

from __future__ import annotations

from dataclasses import dataclass

import control
import numpy as np

from ..errors import DimensionError, IllPosedLoopError
from .checks import (as_finite_array, as_statespace, common_sample_time, require_continuous,
                     sample_time)

__all__ = ["GeneralizedPlant", "lft", "partition_sizes"]


def partition_sizes(P: control.StateSpace, nmeas: int, ncon: int) -> tuple[int, int, int, int]:
    """Check a partition and return ``(nw, nu, nz, ny)``.

    Raises
    ------
    DimensionError
        If ``nmeas`` or ``ncon`` is not a positive integer smaller than the number of
        outputs or inputs of ``P``.
    """
    for label, value, total, side in (
        ("nmeas", nmeas, P.noutputs, "outputs"),
        ("ncon", ncon, P.ninputs, "inputs"),
    ):
        if isinstance(value, bool) or not isinstance(value, (int, np.integer)):
            raise DimensionError(f"{label} must be an integer, got {value!r}")
        if not 0 < value < total:
            raise DimensionError(
                f"{label}={value} does not fit a plant with {total} {side}: "
                f"need 0 < {label} < {total} (at least one {'error' if side == 'outputs' else 'disturbance'} channel)"
            )
    return P.ninputs - ncon, int(ncon), P.noutputs - nmeas, int(nmeas)


@dataclass(frozen=True)
class GeneralizedPlant:
    """A continuous-time state-space plant together with its ``(w, u) -> (z, y)`` partition.

    Build one with :meth:`from_statespace` (python-control's convention: controls last,
    measurements last) or :meth:`from_matrices`.

    Attributes
    ----------
    sys : control.StateSpace
        The whole plant, inputs ``[w; u]`` and outputs ``[z; y]``.
    nw, nu, nz, ny : int
        Numbers of disturbances, controls, errors and measurements.

    Examples
    --------
    >>> import numpy as np
    >>> from lmi_suspension.lti import GeneralizedPlant
    >>> P = GeneralizedPlant.from_matrices(
    ...     A=[[-1.0]], B1=[[1.0]], B2=[[1.0]], C1=[[1.0], [0.0]], C2=[[1.0]],
    ...     D11=[[0.0], [0.0]], D12=[[0.0], [1.0]], D21=[[0.1]], D22=[[0.0]])
    >>> (P.nw, P.nu, P.nz, P.ny)
    (1, 1, 2, 1)
    """

    sys: control.StateSpace
    nw: int
    nu: int
    nz: int
    ny: int

    def __post_init__(self):
        if not isinstance(self.sys, control.StateSpace):
            raise DimensionError("GeneralizedPlant.sys must be a control.StateSpace")
        if self.nw + self.nu != self.sys.ninputs or self.nz + self.ny != self.sys.noutputs:
            raise DimensionError(
                f"partition (nw={self.nw}, nu={self.nu}, nz={self.nz}, ny={self.ny}) does not fit "
                f"a plant with {self.sys.ninputs} inputs and {self.sys.noutputs} outputs"
            )
        if min(self.nw, self.nu, self.nz, self.ny) < 1:
            raise DimensionError("every partition block (w, u, z, y) needs at least one channel")

    # ----------------------------------------------------------------- builders
    @classmethod
    def from_statespace(cls, P, nmeas: int, ncon: int, *, discrete: bool = False
                        ) -> "GeneralizedPlant":
        """Wrap a plant whose last ``ncon`` inputs are controls and last ``nmeas`` outputs
        are measurements; a discrete-time plant only where the caller allows it
        (``discrete=True``), else :class:`~lmi_suspension.errors.DiscreteTimeError`."""
        if isinstance(P, GeneralizedPlant):
            if (P.ny, P.nu) != (nmeas, ncon):
                raise DimensionError(
                    f"plant carries partition ny={P.ny}, nu={P.nu}; got nmeas={nmeas}, ncon={ncon}"
                )
            if not discrete:
                require_continuous(P, "P")
            return P
        ss = as_statespace(P, "P", discrete=discrete)
        nw, nu, nz, ny = partition_sizes(ss, nmeas, ncon)
        return cls(ss, nw, nu, nz, ny)

    @classmethod
    def from_matrices(cls, A, B1, B2, C1, C2, D11=None, D12=None, D21=None, D22=None,
                      *, input_names=None, output_names=None, dt: float = 0.0
                      ) -> "GeneralizedPlant":
        """Assemble a plant from its nine blocks; missing ``D`` blocks are zero; ``dt`` is
        the sample time (0 for continuous time)."""
        A = as_finite_array(A, "A", ndim=2)
        n = A.shape[0]
        if A.shape != (n, n):
            raise DimensionError(f"A must be square, got shape {A.shape}")
        B1 = as_finite_array(B1, "B1", ndim=2)
        B2 = as_finite_array(B2, "B2", ndim=2)
        C1 = as_finite_array(C1, "C1", ndim=2)
        C2 = as_finite_array(C2, "C2", ndim=2)
        if n == 0:
            B1, B2 = B1.reshape(0, -1), B2.reshape(0, -1)
        nw, nu = B1.shape[1], B2.shape[1]
        nz, ny = C1.shape[0], C2.shape[0]

        def block(D, name, rows, cols):
            if D is None:
                return np.zeros((rows, cols))
            D = as_finite_array(D, name, ndim=2)
            if D.shape != (rows, cols):
                raise DimensionError(f"{name} must be {rows}x{cols}, got {D.shape}")
            return D

        for name, M, shape in (("B1", B1, (n, nw)), ("B2", B2, (n, nu)),
                               ("C1", C1, (nz, n)), ("C2", C2, (ny, n))):
            if M.shape != shape:
                raise DimensionError(f"{name} must be {shape[0]}x{shape[1]}, got {M.shape}")
        D11 = block(D11, "D11", nz, nw)
        D12 = block(D12, "D12", nz, nu)
        D21 = block(D21, "D21", ny, nw)
        D22 = block(D22, "D22", ny, nu)
        kwargs = {}
        if input_names is not None:
            kwargs["inputs"] = list(input_names)
        if output_names is not None:
            kwargs["outputs"] = list(output_names)
        sys = control.ss(A, np.hstack([B1, B2]), np.vstack([C1, C2]),
                         np.block([[D11, D12], [D21, D22]]), dt, **kwargs)
        sample_time(sys, "the plant")
        return cls(sys, nw, nu, nz, ny)

    # ----------------------------------------------------------------- blocks
    @property
    def nstates(self) -> int:
        return self.sys.nstates

    @property
    def dt(self) -> float:
        """Sample time in seconds (0 for a continuous-time plant)."""
        return sample_time(self.sys, "the plant")

    @property
    def A(self) -> np.ndarray:
        return np.array(self.sys.A)

    @property
    def B1(self) -> np.ndarray:
        return np.array(self.sys.B[:, : self.nw])

    @property
    def B2(self) -> np.ndarray:
        return np.array(self.sys.B[:, self.nw:])

    @property
    def C1(self) -> np.ndarray:
        return np.array(self.sys.C[: self.nz, :])

    @property
    def C2(self) -> np.ndarray:
        return np.array(self.sys.C[self.nz:, :])

    @property
    def D11(self) -> np.ndarray:
        return np.array(self.sys.D[: self.nz, : self.nw])

    @property
    def D12(self) -> np.ndarray:
        return np.array(self.sys.D[: self.nz, self.nw:])

    @property
    def D21(self) -> np.ndarray:
        return np.array(self.sys.D[self.nz:, : self.nw])

    @property
    def D22(self) -> np.ndarray:
        return np.array(self.sys.D[self.nz:, self.nw:])

    def blocks(self) -> dict[str, np.ndarray]:
        """All nine blocks by name (copies)."""
        return {k: getattr(self, k) for k in
                ("A", "B1", "B2", "C1", "C2", "D11", "D12", "D21", "D22")}

    def lft(self, K) -> control.StateSpace:
        """Close the loop ``u = K y``; see :func:`lft`."""
        return lft(self, K)


def lft(P, K, nmeas: int | None = None, ncon: int | None = None) -> control.StateSpace:
    """Lower linear fractional transformation ``F_l(P, K)``: close ``u = K y``.

    Parameters
    ----------
    P : GeneralizedPlant or control.StateSpace
        Generalized plant. For a bare ``StateSpace`` the partition defaults to
        ``ncon = K.noutputs`` and ``nmeas = K.ninputs``.
    K : control.StateSpace, control.TransferFunction or array_like
        Controller from ``y`` to ``u``.

    Returns
    -------
    control.StateSpace
        The closed loop from ``w`` to ``z``; states ordered ``[x_P; x_K]``; in the time
        base of ``P`` and ``K`` (both continuous, or both discrete with one sample time;
        a static gain fits either).

    Raises
    ------
    SampleTimeError
        If ``P`` and ``K`` have different time bases.
    IllPosedLoopError
        If ``I - D22 D_K`` is singular (numerically: condition number above 1e12).
    DimensionError
        If ``K`` does not fit the partition.

    Examples
    --------
    >>> import control
    >>> from lmi_suspension.lti import GeneralizedPlant, lft
    >>> P = GeneralizedPlant.from_matrices(A=[[1.0]], B1=[[1.0]], B2=[[1.0]],
    ...     C1=[[1.0]], C2=[[1.0]], D12=[[1.0]])
    >>> CL = lft(P, control.ss([], [], [], [[-3.0]]))
    >>> float(CL.A[0, 0])
    -2.0
    """
    K = as_statespace(K, "K", discrete=True)
    if isinstance(P, GeneralizedPlant):
        if nmeas is not None and nmeas != P.ny or ncon is not None and ncon != P.nu:
            raise DimensionError("nmeas/ncon disagree with the plant's own partition")
        G = P
    else:
        G = GeneralizedPlant.from_statespace(
            P, K.ninputs if nmeas is None else nmeas, K.noutputs if ncon is None else ncon,
            discrete=True)
    dt = common_sample_time(("the plant", G.sys), ("the controller", K))
    if (K.ninputs, K.noutputs) != (G.ny, G.nu):
        raise DimensionError(
            f"K maps {K.ninputs} inputs to {K.noutputs} outputs; the plant has "
            f"{G.ny} measurements and {G.nu} controls"
        )
    A, B1, B2 = G.A, G.B1, G.B2
    C1, C2, D11, D12, D21, D22 = G.C1, G.C2, G.D11, G.D12, G.D21, G.D22
    Ak, Bk, Ck, Dk = (np.asarray(m, dtype=float) for m in (K.A, K.B, K.C, K.D))
    nk = Ak.shape[0]
    Ak, Bk, Ck = Ak.reshape(nk, nk), Bk.reshape(nk, G.ny), Ck.reshape(G.nu, nk)

    # Well-posedness: u = Ck xk + Dk y and y = C2 x + D21 w + D22 u.
    R = np.eye(G.ny) - D22 @ Dk
    if np.linalg.cond(R) > 1e12:
        raise IllPosedLoopError(
            f"the loop is ill-posed: I - D22*Dk is singular (cond = {np.linalg.cond(R):.3g})")
    Rinv = np.linalg.inv(R)
    # y = Rinv (C2 x + D22 Ck xk + D21 w);  u = Ck xk + Dk y
    Ycx = Rinv @ C2
    Yck = Rinv @ D22 @ Ck
    Ycw = Rinv @ D21
    Ucx = Dk @ Ycx
    Uck = Ck + Dk @ Yck
    Ucw = Dk @ Ycw
    Acl = np.block([[A + B2 @ Ucx, B2 @ Uck], [Bk @ Ycx, Ak + Bk @ Yck]])
    Bcl = np.vstack([B1 + B2 @ Ucw, Bk @ Ycw])
    Ccl = np.hstack([C1 + D12 @ Ucx, D12 @ Uck])
    Dcl = D11 + D12 @ Ucw
    names = {}
    try:
        names = dict(inputs=list(G.sys.input_labels[: G.nw]),
                     outputs=list(G.sys.output_labels[: G.nz]))
    except AttributeError:  # pragma: no cover - very old python-control
        pass
    return control.ss(Acl, Bcl, Ccl, Dcl, dt, **names)
