"""The paper's application: seat suspension with a seated-human body model.

model (Table 1, eq. 1) -> uncertainty and weights -> augmented plant of Fig. 2.
"""

from .augmented import BUMP_PEAK_VELOCITY, SeatAugmentedPlant, SeatDesignOptions, seat_augmented_plant
from .model import SeatMatrices, natural_modes, seat_matrices, seat_model
from .params import SeatParameters
from .uncertainty import (DelayUncertainty, NormBounded, ParametricUncertainty, delay_uncertainty,
                          paper_norm_bounded, parametric_uncertainty)
from .weights import iso2631_wk, makeweight, wk_weight

__all__ = [
    "SeatParameters", "SeatMatrices", "seat_matrices", "seat_model", "natural_modes",
    "makeweight", "iso2631_wk", "wk_weight",
    "DelayUncertainty", "delay_uncertainty", "NormBounded", "paper_norm_bounded",
    "ParametricUncertainty", "parametric_uncertainty",
    "SeatDesignOptions", "SeatAugmentedPlant", "seat_augmented_plant", "BUMP_PEAK_VELOCITY",
]
