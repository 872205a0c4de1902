"""The paper's application: seat suspension with a seated-human body model."""

from .model import SeatMatrices, natural_modes, seat_matrices, seat_model
from .params import SeatParameters

__all__ = ["SeatParameters", "SeatMatrices", "seat_matrices", "seat_model", "natural_modes"]
