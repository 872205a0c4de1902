"""Multi-objective static state feedback by LMIs (the job of MATLAB's ``msfsyn``).

The same specifications as :func:`~.multiobjective.msyn` (H∞, H2, peak bounds, pole
regions, one's own), with the variables of state feedback: ``Y = P⁻¹`` and ``L = K Y``
make every closed-loop inequality affine (:class:`~.constraints.StateFeedbackVariables`),
one Lyapunov matrix shared by all of them (Chilali & Gahinet, IEEE TAC 41(3), 1996;
Scherer, Gahinet & Chilali, IEEE TAC 42(7), 1997).  The synthesis is
:func:`~.multiobjective.msyn`'s -- balanced plant, Lyapunov scales per constraint, frame
rounds, a reconstruction ladder -- and every specification is certified on the closed
loop ``A + B2 K`` alone.  The suspension literature designs this way (e.g. H∞ with
generalized-H2 force and stroke bounds by state feedback).
"""

from __future__ import annotations

import time
from dataclasses import dataclass, fields

import control
import cvxpy as cp
import numpy as np

from ..errors import DimensionError, ParameterError
from ..lti.checks import as_statespace
from ..lti.plant import GeneralizedPlant
from .constraints import StateFeedbackVariables, Specification
from .multiobjective import MultiobjectiveResult, _Form, _synthesise
from .result import HinfsynOptions

__all__ = ["msfsyn", "StateFeedbackResult"]


def _variables(Ps: GeneralizedPlant, scale=None) -> StateFeedbackVariables:
    return StateFeedbackVariables(Yh=cp.Variable((Ps.nstates, Ps.nstates), symmetric=True),
                                  Lh=cp.Variable((Ps.nu, Ps.nstates)), data=Ps.blocks(),
                                  scale=scale)


def _controller(v: StateFeedbackVariables, specs) -> control.StateSpace:
    # a static controller: the closed loop keeps the plant's order
    return control.ss(np.zeros((0, 0)), np.zeros((0, v.data["C2"].shape[0])),
                      np.zeros((v.data["B2"].shape[1], 0)), v.gain())


_STATE_FEEDBACK = _Form(_variables, _controller)


def msfsyn(P, ncon: int, objective: Specification, constraints=(), *,
           options: HinfsynOptions | None = None,
           lyapunov_scales=None) -> "StateFeedbackResult":
    """Multi-objective static state feedback ``u = K x``: minimise one specification's
    level subject to the others.

    Parameters
    ----------
    P : control.StateSpace
        Continuous-time plant ``ẋ = A x + B1 w + B2 u``, ``z = C1 x + D11 w + D12 u``:
        inputs ``[w, u]`` (controls last), every output a performance output; the state is
        measured.
    ncon : int
        Number of controls ``u``.
    objective, constraints, options, lyapunov_scales
        As in :func:`~.multiobjective.msyn`; channels index the rows of ``z`` and the
        columns of ``w``.

    Returns
    -------
    StateFeedbackResult
        Unpacks as ``K, CL, objective, info``; ``K`` is the gain matrix (``ncon`` by the
        number of states, ``u = K x``; MATLAB's ``msfsyn`` sign) and ``CL`` the closed
        loop from ``w`` to ``z``.  ``info.K`` is the same gain as a static
        ``StateSpace``.

    Raises
    ------
    InfeasibleError, SolverError, ParameterError
        As :func:`~.multiobjective.msyn`.

    Examples
    --------
    >>> import control
    >>> from lmi_suspension.synthesis.constraints import Channel, HinfBound, HalfPlane
    >>> P = control.ss([[1.0]], [[1.0, 1.0]], [[1.0], [0.0]], [[0.0, 0.0], [0.0, 1.0]])
    >>> K, CL, gamma, info = msfsyn(P, 1, HinfBound(), [HalfPlane(alpha=2.0)])
    >>> bool(1.0 + K[0, 0] < -2.0)     # the closed-loop pole A + B2 K left of -2
    True
    """
    t0 = time.perf_counter()
    sys = as_statespace(P, "P")
    n, nin, nz = sys.nstates, sys.ninputs, sys.noutputs
    if not (isinstance(ncon, (int, np.integer)) and 0 < ncon < nin):
        raise DimensionError(f"ncon must be between 1 and {nin - 1} (the plant has {nin} "
                             f"inputs, disturbances first), got {ncon!r}")
    if n == 0:
        raise ParameterError("msfsyn needs a plant with states")
    A, B, C, D = (np.asarray(M, dtype=float) for M in (sys.A, sys.B, sys.C, sys.D))
    nw = nin - ncon
    # the measurements are the states: y = x, no disturbance on them
    G = GeneralizedPlant.from_matrices(A, B[:, :nw], B[:, nw:], C, np.eye(n), D[:, :nw],
                                       D[:, nw:], np.zeros((n, nw)), np.zeros((n, ncon)))
    res = _synthesise(G, objective, constraints, options, lyapunov_scales, _STATE_FEEDBACK,
                      t0)
    return StateFeedbackResult(**{f.name: getattr(res, f.name) for f in fields(res)},
                               gain=np.array(res.K.D, dtype=float))


@dataclass(frozen=True)
class StateFeedbackResult(MultiobjectiveResult):
    """Result of :func:`msfsyn`: a :class:`~.multiobjective.MultiobjectiveResult` whose
    ``gain`` is ``K`` of ``u = K x``; unpacks as ``gain, CL, objective, info``."""

    gain: np.ndarray = None

    def __iter__(self):
        return iter((self.gain, self.CL, self.objective, self))
