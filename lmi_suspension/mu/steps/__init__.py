"""The three exchangeable steps of D-K iteration, each behind a small protocol.

:func:`~lmi_suspension.mu.musyn` is a short loop over them::

    K-step      PD            -> controller K          (steps/kstep.py)
    D/G-step    F_l(P, K)     -> µ bounds and scalings  (steps/dgstep.py)
    fit         the scalings  -> the next scaled PD     (steps/fit.py)

Each step is built once per run from the run's :class:`DKSetup` (so a class whose
``__init__`` takes the setup is a step factory) and may keep state from one iteration to
the next: the constrained K-step its Lyapunov scales, the D-fit its over-relaxation.
:class:`DKSteps` names the factories; ``None`` keeps the default.  A new K-step is one
class with ``__init__(self, setup)`` and ``__call__(self, PD, *, iteration, gamma_prev)``.

The loop owns the rules that compare iterates (best, patience, stopping); the steps own
their heuristics, each a named constant with the measurement that chose it.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Callable, Protocol, runtime_checkable

import control
import numpy as np

from ...lti.plant import GeneralizedPlant
from ...umodel.blocks import BlockStructure

__all__ = ["DKSetup", "DKSteps", "KStep", "KStepResult", "ScaleStep", "ScaleFit",
           "LoopAnalysis", "NextPlant"]


@dataclass(frozen=True)
class DKSetup:
    """What every step of one ``musyn`` run may read.

    Attributes
    ----------
    G : GeneralizedPlant
        The unscaled plant.
    struct : BlockStructure
        The true uncertainty structure (real blocks real).
    dk_struct : BlockStructure
        The structure the D/G-step works with: ``struct`` itself for D-G-K, its complex
        cover for D-K (``MusynOptions.complexify`` or no real block).
    mixed : bool
        D-G-K: real blocks stay real, their G scalings absorbed into the scaled plant.
    free : tuple of int
        ``(inputs, outputs)`` beyond ``struct``: the channels of the constraints alone.
    omega : numpy.ndarray
        The design grid, rad/s.
    options : MusynOptions
    rng : numpy.random.Generator
    constraints : tuple of Specification
    lyapunov_scales : tuple of float or None
        The constrained K-step's first Lyapunov scales (searched when None).
    """

    G: GeneralizedPlant
    struct: BlockStructure
    dk_struct: BlockStructure
    mixed: bool
    free: tuple
    omega: np.ndarray
    options: object
    rng: np.random.Generator
    constraints: tuple = ()
    lyapunov_scales: tuple | None = None

    @property
    def nmeas(self) -> int:
        return self.G.ny

    @property
    def ncon(self) -> int:
        return self.G.nu


@runtime_checkable
class KStepResult(Protocol):
    """What the loop reads of a K-step: the controller, the γ certified for it on the
    scaled plant, and what the step wants the record to say."""

    K: control.StateSpace
    gamma: float
    warnings: tuple


class KStep(Protocol):
    """H∞ synthesis on the scaled plant ``PD``.

    ``gamma_prev`` is the previous controller's norm on ``PD`` (NaN at the first
    iteration): a step that cannot reach it has failed.  Raises an
    :class:`~lmi_suspension.errors.LmiSuspensionError` when it finds no controller.
    """

    def __call__(self, PD: control.StateSpace, *, iteration: int,
                 gamma_prev: float) -> KStepResult: ...


@dataclass(frozen=True)
class LoopAnalysis:
    """The D/G-step's account of one closed loop.

    Attributes
    ----------
    M : numpy.ndarray
        The loop's response on the design grid, ``(nz, nw, nω)``.
    mu : MussvResult
        µ bounds and scalings on the grid (``dk_struct``).
    upper : numpy.ndarray
        The upper bound per grid frequency.
    mu_peak, peak_omega : float
        The peak of the upper bound and where (possibly at a resonance off the grid).
    lower_peak : float
        The largest lower bound found.
    K : control.StateSpace
        The controller of the loop.
    """

    M: np.ndarray
    mu: object
    upper: np.ndarray
    mu_peak: float
    peak_omega: float
    lower_peak: float
    K: control.StateSpace

    @property
    def d_blocks(self):
        """Per-block D-scale magnitudes on the grid (what the D-fit fits)."""
        return self.mu.d_blocks


class ScaleStep(Protocol):
    """The D/G-step: µ bounds of a stable closed loop and the scalings behind them."""

    def __call__(self, CL: control.StateSpace, K: control.StateSpace) -> LoopAnalysis: ...


@dataclass(frozen=True)
class NextPlant:
    """The fit step's result: the next scaled plant and how it was made.

    Attributes
    ----------
    PD : control.StateSpace
        The scaled plant of the next K-step.
    orders : tuple of int
        The fitted scalings' orders, per block.
    K_ref : control.StateSpace
        The controller the plant was built around (its loop's scalings).
    gamma : float or None
        ``K_ref``'s norm on ``PD``, where the step computed it already.
    fallback : callable or None
        A plainer plant of the same step, for a K-step that fails on this one.
    """

    PD: control.StateSpace
    orders: tuple
    K_ref: control.StateSpace
    gamma: float | None = None
    fallback: Callable[[], "NextPlant"] | None = None


class ScaleFit(Protocol):
    """Rational fits of the scalings of ``here``'s loop, absorbed into the next scaled
    plant.  ``best_iteration`` lets a step go back to the best iterate's scalings.
    Raises an :class:`~lmi_suspension.errors.LmiSuspensionError` when no usable plant
    results.

    A step that may build its next plant from the best iterate rather than from
    ``here`` (over-relaxation) says so with a true ``restarts_from_best`` attribute:
    the loop then does not stop on a K-step that does worse than the previous
    controller, since the next plant restarts from the best iterate anyway.
    """

    def __call__(self, here: LoopAnalysis, *, iteration: int,
                 best_iteration: int) -> NextPlant: ...


@dataclass(frozen=True)
class DKSteps:
    """The step factories of a ``musyn`` run; ``None`` keeps the default.

    Each is called once with the run's :class:`DKSetup` and returns the step.

    Attributes
    ----------
    kstep : callable, optional
        Default :class:`~.kstep.HinfKStep` (``MusynOptions.method``), or
        :class:`~.kstep.ConstrainedKStep` when ``musyn`` has constraints.
    dgstep : callable, optional
        Default :class:`~.dgstep.MussvStep`.
    fit : callable, optional
        Default :class:`~.fit.DScaleFit` (D-K) or :class:`~.fit.DGScaleFit` (D-G-K).

    Examples
    --------
    A K-step that records what it designs, around the default one:

    >>> from lmi_suspension.mu.steps import DKSteps
    >>> from lmi_suspension.mu.steps.kstep import HinfKStep
    >>> class Logged(HinfKStep):
    ...     def __call__(self, PD, *, iteration, gamma_prev):
    ...         syn = super().__call__(PD, iteration=iteration, gamma_prev=gamma_prev)
    ...         print(iteration, syn.K.nstates)
    ...         return syn
    >>> steps = DKSteps(kstep=Logged)  # musyn(..., steps=steps)
    """

    kstep: Callable[[DKSetup], KStep] | None = None
    dgstep: Callable[[DKSetup], ScaleStep] | None = None
    fit: Callable[[DKSetup], ScaleFit] | None = None


def mu_part(CL: control.StateSpace, struct: BlockStructure) -> control.StateSpace:
    """The ``w -> z`` part of a closed loop that ``struct`` covers (its first rows and
    columns); the closed loop itself when there are no constraint channels."""
    nz, nw = struct.shape_M
    if (CL.noutputs, CL.ninputs) == (nz, nw):
        return CL
    return control.ss(CL.A, np.asarray(CL.B)[:, :nw], np.asarray(CL.C)[:nz],
                      np.asarray(CL.D)[:nz, :nw])


def certificates(constraints, CL_full) -> tuple:
    """Each constraint recomputed on the unscaled closed loop, independently of the
    K-step's own certificates (which are on the scaled plant)."""
    from ...synthesis.multiobjective import _certify

    return tuple(_certify(c, CL_full, c.bound, c.bound) for c in constraints)


def block_sizes(struct: BlockStructure) -> list[tuple[int, int]]:
    """``(rows, cols)`` of each block of ``struct``."""
    return [(b.rows, b.cols) for b in struct.blocks]
