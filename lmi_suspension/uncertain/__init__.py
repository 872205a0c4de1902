"""Uncertain models and robustness analysis (MATLAB's names, python-control's objects).

atoms (:func:`ureal`, :func:`ucomplex`, :func:`ultidyn`) -> uncertain matrices and
systems as LFTs (:func:`uss`, :func:`feedback`, :func:`connect`) -> :func:`lftdata`,
:func:`usubs`, :func:`usample`, :func:`nominal` -> :func:`robstab`, :func:`wcgain`.

The models are :mod:`lmi_suspension.umodel`, below µ; the analysis (:mod:`.analysis`)
stands on µ; this package, above both, hands on the names of both.
"""

from ..umodel import (
    USS,
    LFTData,
    UBlock,
    UComplex,
    ULTIDyn,
    UMat,
    UReal,
    connect,
    feedback,
    lftdata,
    nominal,
    ucomplex,
    ultidyn,
    umat,
    ureal,
    usample,
    uss,
    usubs,
)
from .analysis import RobstabResult, WcgainResult, robstab, wcgain

__all__ = [
    "UReal", "UComplex", "ULTIDyn", "ureal", "ucomplex", "ultidyn",
    "USS", "UMat", "UBlock", "umat",
    "RobstabResult", "WcgainResult", "robstab", "wcgain",
    "LFTData", "uss", "feedback", "connect", "lftdata", "usubs", "usample", "nominal",
]
