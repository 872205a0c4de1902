"""Generalized plants, norms and scaling of continuous-time LTI systems."""

from .checks import as_statespace
from .plant import GeneralizedPlant, lft
from .norms import freqresp, hinfnorm

__all__ = ["GeneralizedPlant", "lft", "as_statespace", "hinfnorm", "freqresp"]
