"""Generalized plants, norms, scaling and the bilinear map of continuous- and
discrete-time LTI systems."""

from .bilinear import tustin, tustin_image
from .checks import as_statespace
from .plant import GeneralizedPlant, lft
from .norms import freqresp, hinfnorm

__all__ = ["GeneralizedPlant", "lft", "as_statespace", "hinfnorm", "freqresp", "tustin",
           "tustin_image"]
