"""Uncertain models and robustness analysis (MATLAB's names, python-control's objects).

atoms (:func:`ureal`, :func:`ucomplex`, :func:`ultidyn`) -> uncertain matrices and
systems as LFTs (:func:`uss`, :func:`feedback`, :func:`connect`) -> :func:`lftdata`,
:func:`usubs`, :func:`usample`, :func:`nominal` -> :func:`robstab`, :func:`wcgain`.
"""

from .atoms import UComplex, UReal, ULTIDyn, ucomplex, ultidyn, ureal
from .lfr import USS, UBlock, UMat, umat
from .analysis import RobstabResult, WcgainResult, robstab, wcgain
from .uss import LFTData, connect, feedback, lftdata, nominal, uss, usample, usubs

__all__ = [
    "UReal", "UComplex", "ULTIDyn", "ureal", "ucomplex", "ultidyn",
    "USS", "UMat", "UBlock", "umat",
    "RobstabResult", "WcgainResult", "robstab", "wcgain",
    "LFTData", "uss", "feedback", "connect", "lftdata", "usubs", "usample", "nominal",
]
