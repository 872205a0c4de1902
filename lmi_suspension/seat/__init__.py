"""The paper's application: seat suspension with a seated-human body model.

model (Table 1, eq. 1) -> uncertainty and weights -> augmented plant of Fig. 2;
roads -> exact-delay simulation -> comfort metrics; the physical limit of the bump.
The designs: :mod:`.design` (µ-synthesis as in the paper), :mod:`.constrained` (hard
force and stroke bounds in the K-step), :mod:`.refine` (the µ controller refined to the
exact bump requirements), :mod:`.multimodel` (that refinement over a set of seats, with
a worst-case search), :mod:`.bounded` (H∞ with peak bounds) and :mod:`.sampled` (the
1 kHz implementation); :mod:`.occupants` is the set of seats a controller must serve and
its certificate over them, :mod:`.worstcase` the search for its worst seats.
:mod:`.loop` holds the loop's closed-form bump response, poles and two-block µ that
these use, :mod:`.goals` the refinement's requirements as classes of
:mod:`lmi_suspension.tune`'s protocol; :mod:`.record` the one result type (:class:`SeatDesign`) and the certificate
(:func:`certify_seat`) below every route; :mod:`.routes`, on top, the one entry to them
all (:func:`design_seat`).
"""

from .augmented import BUMP_PEAK_VELOCITY, SeatAugmentedPlant, SeatDesignOptions, seat_augmented_plant
from .model import SeatMatrices, natural_modes, seat_matrices, seat_model
from .params import SeatParameters
from .uncertainty import (DelayUncertainty, NormBounded, ParametricUncertainty, delay_uncertainty,
                          paper_norm_bounded, parametric_uncertainty)
from .weights import iso2631_wk, makeweight, wk_weight
from .roads import RoadInput, bump, iso8608_psd, iso8608_road, road_energy, white_noise
from .comfort import ComfortMetrics, comfort_metrics, vdv, weighted_rms, wk_filter
from .simulate import (MonteCarloResult, SimulationMetrics, SimulationResult, closed_loop_stable,
                       loop_transfer, monte_carlo, simulate, simulate_force, stability_delay_margin)
from .limit import LimitResult, bump_limit
from .bounded import PeakBoundedDesign, design_peak_bounded
# the designs' own modules, documented as modules: the µ design, its constrained K-step
# route, the refinement (on one seat and on a set), the set of seats and its certificate,
# and the sampled-data implementation
from . import (constrained, design, goals, loop, multimodel, mucheck, occupants, record,
               refine, routes, sampled, worstcase)
# the one result type and the certificate, below every route
from .record import SeatCertificate, SeatDesign, SeatRequirements, certify_seat
# one entry for every route: design_seat
from .routes import SeatRoute, design_seat, load_seat_design, save_seat_design

__all__ = [
    "SeatParameters", "SeatMatrices", "seat_matrices", "seat_model", "natural_modes",
    "makeweight", "iso2631_wk", "wk_weight",
    "DelayUncertainty", "delay_uncertainty", "NormBounded", "paper_norm_bounded",
    "ParametricUncertainty", "parametric_uncertainty",
    "SeatDesignOptions", "SeatAugmentedPlant", "seat_augmented_plant", "BUMP_PEAK_VELOCITY",
    "RoadInput", "bump", "white_noise", "iso8608_road", "iso8608_psd",
    "ComfortMetrics", "comfort_metrics", "vdv", "weighted_rms", "wk_filter",
    "SimulationResult", "SimulationMetrics", "MonteCarloResult", "simulate", "simulate_force",
    "closed_loop_stable", "loop_transfer", "stability_delay_margin", "monte_carlo",
    "LimitResult", "bump_limit",
    "PeakBoundedDesign", "design_peak_bounded", "road_energy",
    "design", "constrained", "refine", "multimodel", "occupants", "sampled", "worstcase",
    "goals", "loop", "mucheck", "record",
    "SeatRoute", "SeatDesign", "SeatRequirements", "SeatCertificate", "design_seat",
    "certify_seat", "save_seat_design", "load_seat_design", "routes",
]
