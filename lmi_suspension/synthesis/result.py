"""Options and results of H∞ synthesis, shared by every method."""

from __future__ import annotations

from dataclasses import dataclass, field

import control
import numpy as np

from ..errors import ParameterError

__all__ = ["HinfsynOptions", "HinfsynResult", "Timings"]


@dataclass(frozen=True)
class HinfsynOptions:
    """Options of :func:`~lmi_suspension.synthesis.hinfsyn` (frozen; copy with
    :func:`dataclasses.replace`).

    Attributes
    ----------
    gamma : float or None
        Fixed performance level; ``None`` minimises γ.  With ``method="riccati"`` the
        controller is SLICOT ``sb10ad``'s suboptimal one at this level (``job=4``).
    gamma_relax : float
        Relative level above the LMI optimum at which the controller is reconstructed;
        the certified γ stays below ``(1 + gamma_relax) * gamma_lower`` up to solver
        accuracy.  Where that reconstruction fails, the level is relaxed fourfold per
        recovery (``4 gamma_relax``, ``16 gamma_relax``, ...).  The default keeps every
        COMPleib problem of the tests within 0.04 % of the LMI optimum.  It is also the
        margin by which a certified Riccati controller must be sought below
        ``gamma_lower`` before ``gamma_lower`` is withheld (see ``HinfsynResult``).  On a
        discrete-time plant the reconstruction is at most 5e-5 above the optimum of its
        bilinear image (``min(gamma_relax, 5e-5)``).
    gamma_atol : float
        Absolute γ floor in scaled units (plant data normalised to about 1): when the LMI
        optimum is below it (an infimum of 0, e.g. COMPleib AC1) the reconstruction
        targets ``gamma_atol`` instead of a relative relaxation of 0.
    tol_gap_abs, tol_gap_rel, tol_feas : float
        Clarabel tolerances (passed explicitly), and CVXOPT's ``abstol``, ``reltol``,
        ``feastol`` in the structured γ minimisation (``gamma_solver``), where the
        feasibility tolerance is at least 1e-7, CVXOPT's default: its dual residual
        has a floor near 1e-8 that depends on the BLAS kernel.
    reduced_tol_gap_abs, reduced_tol_gap_rel, reduced_tol_feas : float
        "Almost solved" tolerances (Clarabel's, and the structured γ minimisation's
        relative gap and feasibility): a solve that stalls within them is accepted as
        ``optimal_inaccurate`` (reported in ``warnings``); γ only needs to be accurate to
        a fraction of ``gamma_relax``.
    max_iter : int
        Iteration bound per solve: Clarabel's, and CVXOPT's per run of the structured
        γ minimisation (at most two runs of at most 60 iterations each).
    margin : float
        Strictness margin of the LMIs (``L <= -margin I``) in scaled data.
    xy_bound : float
        Bound ``trace(X) + trace(Y) <= xy_bound * n`` (scaled data) that keeps the γ
        minimisation bounded; a warning says when it is active.
    max_recoveries : int
        Number of recovery attempts (tightened tolerances, relaxed γ) after an
        inaccurate or failed solve.
    scale : bool
        Balance states and normalise inputs/outputs before solving.
    cert_rtol : float
        Relative tolerance above which a disagreement between the certified γ and the
        solver's own bound is reported in ``warnings``.
    riccati_scale : bool
        ``method="riccati"`` only: balance the plant (as the LMI route does) before
        python-control sees it. Off by default so that the baseline is python-control
        exactly as users call it.
    riccati_search : {"python-control", "bisection"}
        ``method="riccati"`` with ``gamma=None`` only: ``"python-control"`` (default, the
        baseline as users call it) takes python-control's γ-optimal ``hinfsyn``;
        ``"bisection"`` searches γ over SLICOT's suboptimal controllers (``sb10ad`` job 4),
        each certified, down to a bracket ``riccati_rtol`` wide, and returns the lowest
        certified one (faster, and it avoids the ill-conditioned optimum; used by
        :func:`~lmi_suspension.mu.musyn`).
    riccati_rtol : float
        Relative width at which the ``"bisection"`` search stops.
    gamma_abort : float or None
        ``method="lmi"`` only: raise :class:`~lmi_suspension.errors.SolverError` as soon as
        the γ minimisation's optimum exceeds this level (a γ another controller is
        certified to achieve: the minimisation has then failed, and reconstructing
        around it is wasted time).  Used by ``musyn``'s ``method="best"``.
    controller : {"explicit", "sdp"}
        ``method="lmi"`` only: how the controller is built from the Lyapunov matrices of
        the γ step.  ``"explicit"`` (default) first evaluates Gahinet's explicit formulas
        (:func:`~lmi_suspension.synthesis.lmi.decoupled_controller`, milliseconds instead
        of the controller LMI's 0.1-15 s at 4-40 states) and keeps that controller where
        it certifies at its level and its poles stay within 10⁴ times the plant's fastest
        mode (or 10⁴ rad/s); elsewhere the controller LMI runs as with ``"sdp"``
        (``warnings`` says why; ``status`` is ``"explicit"`` when the explicit controller
        was kept).  ``"sdp"`` always solves the controller LMI, whose slack and trace box
        keep the controller's poles moderate: on the plants of ``bench_hinfsyn.py`` the
        explicit controller's fastest pole was 1-17 times the controller LMI's (measured
        2026-11-29).
    gamma_solver : {"structured", "clarabel"}
        ``method="lmi"`` only: what solves the γ minimisation.  ``"structured"``
        (default) is CVXOPT's interior-point method with a KKT solver that assembles the
        Schur complement from the Lyapunov structure of the LMIs
        (:mod:`~lmi_suspension.synthesis.structured`); where it does not end optimal,
        Clarabel solves the same problem (``warnings`` says so).  ``"clarabel"`` poses it
        in CVXPY for Clarabel.  On the 40-state plant of ``bench_hinfsyn.py`` the first
        took 3.4 s and stopped 0.02 % above the optimum, the second 9.3 s and 0.16 %
        above it (OpenBLAS Haswell, measured 2026-11-29); under Sandybridge, Nehalem
        and SkylakeX the first ends optimal too, in 3.3-4.9 s (``benchmarks/HISTORY.md``).
        Where its Cholesky solves of the KKT systems lose the dual equations near the
        optimum (one small plant in six), a second run solves them by MINRES before
        Clarabel is asked.  Fixed-level problems, the controller LMI and
        :func:`~lmi_suspension.synthesis.msyn` are always Clarabel's.
    start : {"riccati", "identity"}
        ``method="lmi"`` only, without a level hint: where the γ minimisation starts.
        ``"riccati"`` (default): in the frame of the two Riccati solutions at a level
        found by a short search (:func:`~lmi_suspension.synthesis.lmi.riccati_start`),
        where the plant is regular and they exist, else in the identity frame;
        ``"identity"``: in the identity frame (the default until 2026-12-02).  On the
        60-state plant of ``bench_hinfsyn.py`` the first took 17 iterations and
        reached 29.83952, the second 22 and 29.84497, held up by its trace bound.
    """

    gamma: float | None = None
    gamma_relax: float = 5e-4
    gamma_atol: float = 1e-6
    tol_gap_abs: float = 1e-7
    tol_gap_rel: float = 1e-6
    tol_feas: float = 1e-8
    reduced_tol_gap_abs: float = 1e-4
    reduced_tol_gap_rel: float = 5e-4
    reduced_tol_feas: float = 1e-6
    max_iter: int = 200
    margin: float = 1e-8
    xy_bound: float = 1e5
    max_recoveries: int = 4
    scale: bool = True
    cert_rtol: float = 5e-3
    riccati_scale: bool = False
    riccati_search: str = "python-control"
    riccati_rtol: float = 1e-3
    gamma_abort: float | None = None
    controller: str = "explicit"
    gamma_solver: str = "structured"
    start: str = "riccati"

    def __post_init__(self):
        if self.gamma is not None and not (np.isfinite(self.gamma) and self.gamma > 0):
            raise ParameterError(f"gamma must be positive and finite, got {self.gamma!r}")
        for name in ("gamma_relax", "gamma_atol",
                     "tol_gap_abs", "tol_gap_rel", "tol_feas", "margin", "xy_bound",
                     "cert_rtol", "reduced_tol_gap_abs", "riccati_rtol",
                     "reduced_tol_gap_rel", "reduced_tol_feas"):
            v = getattr(self, name)
            if not (np.isfinite(v) and v > 0):
                raise ParameterError(f"{name} must be positive and finite, got {v!r}")
        if self.riccati_search not in ("python-control", "bisection"):
            raise ParameterError("riccati_search must be 'python-control' or 'bisection', "
                                 f"got {self.riccati_search!r}")
        if self.controller not in ("sdp", "explicit"):
            raise ParameterError("controller must be 'sdp' or 'explicit', got "
                                 f"{self.controller!r}")
        if self.gamma_solver not in ("clarabel", "structured"):
            raise ParameterError("gamma_solver must be 'clarabel' or 'structured', got "
                                 f"{self.gamma_solver!r}")
        if self.start not in ("riccati", "identity"):
            raise ParameterError(f"start must be 'riccati' or 'identity', got {self.start!r}")
        if self.gamma_abort is not None and not self.gamma_abort > 0:
            raise ParameterError(f"gamma_abort must be positive, got {self.gamma_abort!r}")
        if int(self.max_iter) < 1 or int(self.max_recoveries) < 0:
            raise ParameterError("max_iter must be >= 1 and max_recoveries >= 0")


@dataclass(frozen=True)
class Timings:
    """Wall-clock seconds spent in each phase of a synthesis."""

    setup: float = 0.0
    solve: float = 0.0
    reconstruct: float = 0.0
    certify: float = 0.0

    @property
    def total(self) -> float:
        return self.setup + self.solve + self.reconstruct + self.certify


@dataclass(frozen=True)
class HinfsynResult:
    """Result of an H∞ synthesis.

    Unpacks like python-control: ``K, CL, gamma, info = hinfsyn(...)``, where ``info``
    is this result object itself.

    Attributes
    ----------
    K : control.StateSpace
        Controller from measurements ``y`` to controls ``u``.
    CL : control.StateSpace
        Closed loop ``lft(P, K)`` from ``w`` to ``z``.
    gamma : float
        Certified closed-loop H∞ norm, ``hinfnorm(CL)`` (``inf`` if not stable).
    gamma_solver : float
        The solver's own bound (the γ of the reconstruction LMI, or Riccati γ).
    gamma_lower : float or None
        LMI optimum: no controller of any order achieves less (up to solver accuracy).
        When the returned controller certifies below it, ``warnings`` says that the γ
        minimisation was inaccurate, and it is no lower bound (reported on COMPleib AC4 in
        issue 41; not reproduced on d4a1a73, tested by injection).  None at a
        fixed ``gamma``, for the Riccati route, where the certified γ is above even
        the most relaxed reconstruction level of it (``warnings`` then gives the value
        the γ minimisation claimed), and, on a plant that meets the Riccati
        assumptions, where SLICOT's controller at ``gamma_lower / (1 + gamma_relax)``
        certifies below it (looked for where scipy's Riccati solutions exist at that
        level; ``warnings`` gives the levels).
    poles : numpy.ndarray
        Closed-loop poles.
    status : str
        Solver status of the last solve.
    method : str
        ``"lmi"`` or ``"riccati"``.
    timings : Timings
        Seconds per phase.
    warnings : tuple of str
        Recoveries and certificate disagreements, never silent.
    controller_fastest_pole : float
        Largest ``|p|`` over the controller poles (rad/s), 0 for a static controller.
    cond_xy : float
        Condition number of ``I - X Y`` used in the reconstruction (LMI method).
    cond_lyap : float
        Condition number of the closed-loop Lyapunov matrix (LMI method).
    """

    K: control.StateSpace
    CL: control.StateSpace
    gamma: float
    gamma_solver: float
    gamma_lower: float | None
    poles: np.ndarray
    status: str
    method: str
    timings: Timings = field(default_factory=Timings)
    warnings: tuple = ()
    controller_fastest_pole: float = 0.0
    cond_xy: float = float("nan")
    cond_lyap: float = float("nan")

    def __iter__(self):
        return iter((self.K, self.CL, self.gamma, self))

    @property
    def stable(self) -> bool:
        """Whether the closed loop is internally stable."""
        return bool(np.isfinite(self.gamma))
