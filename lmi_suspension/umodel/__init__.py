"""Uncertain models: the algebra of uncertain matrices and systems (below µ).

atoms (:func:`ureal`, :func:`ucomplex`, :func:`ultidyn`) -> uncertain matrices and
systems as LFTs (:func:`uss`, :func:`feedback`, :func:`connect`) -> :func:`lftdata` (with
the :class:`BlockStructure` of Δ), :func:`usubs`, :func:`usample`, :func:`nominal`.
µ (:mod:`lmi_suspension.mu`) takes what these build; the robustness analysis above µ
(:func:`~lmi_suspension.uncertain.robstab`, :func:`~lmi_suspension.uncertain.wcgain`)
and these names together are :mod:`lmi_suspension.uncertain`, the users' import path.
"""

from .atoms import UComplex, ULTIDyn, UReal, ucomplex, ultidyn, ureal
from .blocks import Block, BlockKind, BlockStructure
from .lfr import USS, UBlock, UMat, umat
from .uss import LFTData, connect, feedback, lftdata, nominal, usample, uss, usubs

__all__ = [
    "Block", "BlockKind", "BlockStructure",
    "UReal", "UComplex", "ULTIDyn", "ureal", "ucomplex", "ultidyn",
    "USS", "UMat", "UBlock", "umat",
    "LFTData", "uss", "feedback", "connect", "lftdata", "usubs", "usample", "nominal",
]
