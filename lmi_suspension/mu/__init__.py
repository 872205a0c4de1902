"""Structured singular value µ and µ-synthesis.

block structures -> bounds (``mussv``, over intervals ``interval_bound``) -> rational D-scale fits -> D-K iteration (``musyn``)
-> direct D-scale search (``search_dscales``, run by ``musyn`` from the first iterate).
"""

from ..umodel.blocks import Block, BlockKind, BlockStructure
from .bounds import MussvOptions, MussvResult, MussvTimings, mussv
from .dfit import DScaleFit, fit_dscales, fit_magnitude, scaled_plant
from .dsearch import DScaleSearchResult, search_dscales
from .interval import IntervalBound, interval_bound
from .dk import MusynIteration, MusynOptions, MusynResult, default_omega, musyn
from .plot import plot_dscales, plot_mu

__all__ = [
    "Block",
    "BlockKind",
    "BlockStructure",
    "MussvOptions",
    "MussvResult",
    "MussvTimings",
    "mussv",
    "IntervalBound",
    "interval_bound",
    "plot_dscales",
    "DScaleFit",
    "fit_dscales",
    "fit_magnitude",
    "scaled_plant",
    "DScaleSearchResult",
    "search_dscales",
    "MusynOptions",
    "MusynIteration",
    "MusynResult",
    "musyn",
    "default_omega",
    "plot_mu",
]
