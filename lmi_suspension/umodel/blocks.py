"""Block structures of the uncertainty Δ for µ analysis (MATLAB ``blk`` convention).

A structure is given as rows ``[r, c]`` in MATLAB's ``mussv`` convention:

* ``[r, c]`` with ``c > 0``: a full complex ``r × c`` block,
* ``[r, 0]``: a repeated complex scalar ``δ I_r`` (``r × r``),
* ``[-r, 0]``: a repeated real scalar ``δ I_r`` (``r × r``).

Block ``i`` of Δ is ``r_i × c_i``, so ``Δ = diag(Δ_1, ..., Δ_m)`` is
``(Σ r_i) × (Σ c_i)`` and the matrix it closes the loop around, in
``det(I - M Δ)``, is ``M`` of size ``(Σ c_i) × (Σ r_i)``: the rows of ``M`` are
split by the ``c_i`` and its columns by the ``r_i`` (this is MATLAB's convention).
"""

from __future__ import annotations

from dataclasses import dataclass
from enum import Enum
from functools import cached_property
from itertools import pairwise

import numpy as np

from ..errors import DimensionError, InputError, NonFiniteError

__all__ = ["Block", "BlockKind", "BlockStructure"]


class BlockKind(str, Enum):
    """Kind of an uncertainty block."""

    FULL = "full"
    """Full complex ``r × c`` matrix, scaled by ``d I``."""
    COMPLEX_SCALAR = "complex_scalar"
    """Repeated complex scalar ``δ I_r``, scaled by a full Hermitian ``D``."""
    REAL_SCALAR = "real_scalar"
    """Repeated real scalar ``δ I_r``, scaled by a Hermitian ``D`` and ``G``."""


@dataclass(frozen=True)
class Block:
    """One block ``Δ_i`` (``rows × cols``) of the structure."""

    kind: BlockKind
    rows: int
    cols: int

    @property
    def is_real(self) -> bool:
        """True for a repeated real scalar block."""
        return self.kind is BlockKind.REAL_SCALAR

    @property
    def is_scalar(self) -> bool:
        """True for a repeated (real or complex) scalar block."""
        return self.kind is not BlockKind.FULL

    @property
    def n_dscale(self) -> int:
        """Number of free real parameters in this block's D scaling (before normalisation)."""
        return 1 if self.kind is BlockKind.FULL else self.rows**2

    @property
    def n_gscale(self) -> int:
        """Number of free real parameters in this block's G scaling."""
        return self.rows**2 if self.kind is BlockKind.REAL_SCALAR else 0


@dataclass(frozen=True)
class BlockStructure:
    """Block-diagonal structure of Δ, in MATLAB's ``blk`` convention.

    Block ``i`` of Δ is ``r_i × c_i``; Δ is ``(Σ r_i) × (Σ c_i)`` and the analysed
    matrix ``M`` (in ``det(I - M Δ)``) must be ``(Σ c_i) × (Σ r_i)``:
    ``n_out = Σ c_i`` rows and ``n_in = Σ r_i`` columns.

    Build it with :meth:`from_blk` (or :meth:`coerce`, which also accepts an existing
    structure).

    Attributes
    ----------
    blocks : tuple of Block
        The blocks in order.

    Examples
    --------
    >>> from lmi_suspension.mu import BlockStructure
    >>> s = BlockStructure.from_blk([[2, 1], [1, 0], [-1, 0]])
    >>> s.shape_M, s.shape_delta
    ((3, 4), (4, 3))
    >>> s.col_slices()[0], s.row_slices()[0]
    (slice(0, 2, None), slice(0, 1, None))
    >>> s.n_dscale_free   # one d per block (1×1 scalars), minus the overall scale
    2
    """

    blocks: tuple[Block, ...]

    # ------------------------------------------------------------------ building
    @classmethod
    def from_blk(cls, blk) -> BlockStructure:
        """Build a structure from MATLAB-style rows ``[r, c]``.

        Raises
        ------
        DimensionError
            If ``blk`` is not an ``m × 2`` array of integers, is empty, or a row is
            not one of ``[r, c]`` (``r, c > 0``), ``[r, 0]`` or ``[-r, 0]`` (``r > 0``).
        NonFiniteError
            If an entry is NaN or infinite.
        """
        try:
            arr = np.array(blk, dtype=float)
        except (TypeError, ValueError) as exc:
            raise InputError(f"blk must be a numeric m x 2 array: {exc}") from exc
        if arr.ndim == 1 and arr.size == 2:
            arr = arr.reshape(1, 2)
        if arr.ndim != 2 or arr.shape[1] != 2 or arr.shape[0] == 0:
            raise DimensionError(f"blk must be an m x 2 array with m >= 1, got shape {arr.shape}")
        if not np.all(np.isfinite(arr)):
            raise NonFiniteError("blk contains NaN or infinite entries")
        if not np.all(arr == np.round(arr)):
            raise DimensionError(f"blk entries must be integers, got {arr.tolist()}")
        blocks = []
        for i, (r, c) in enumerate(arr.astype(int)):
            if c > 0 and r > 0:
                blocks.append(Block(BlockKind.FULL, int(r), int(c)))
            elif c == 0 and r > 0:
                blocks.append(Block(BlockKind.COMPLEX_SCALAR, int(r), int(r)))
            elif c == 0 and r < 0:
                blocks.append(Block(BlockKind.REAL_SCALAR, int(-r), int(-r)))
            else:
                raise DimensionError(
                    f"blk row {i} = [{r}, {c}] is not a valid block: use [r, c] (r, c > 0) "
                    "for a full complex block, [r, 0] for a repeated complex scalar, "
                    "[-r, 0] for a repeated real scalar"
                )
        return cls(tuple(blocks))

    @classmethod
    def coerce(cls, blk) -> BlockStructure:
        """Return ``blk`` if it is a :class:`BlockStructure`, else :meth:`from_blk` of it."""
        return blk if isinstance(blk, cls) else cls.from_blk(blk)

    def to_blk(self) -> np.ndarray:
        """Return the MATLAB-style ``m × 2`` integer array."""
        rows = []
        for b in self.blocks:
            if b.kind is BlockKind.FULL:
                rows.append([b.rows, b.cols])
            elif b.kind is BlockKind.COMPLEX_SCALAR:
                rows.append([b.rows, 0])
            else:
                rows.append([-b.rows, 0])
        return np.array(rows, dtype=int)

    # ------------------------------------------------------------------ sizes
    @property
    def n_blocks(self) -> int:
        """Number of blocks."""
        return len(self.blocks)

    @property
    def n_in(self) -> int:
        """Columns of ``M`` (``Σ r_i``, rows of Δ)."""
        return sum(b.rows for b in self.blocks)

    @property
    def n_out(self) -> int:
        """Rows of ``M`` (``Σ c_i``, columns of Δ)."""
        return sum(b.cols for b in self.blocks)

    @property
    def shape_M(self) -> tuple[int, int]:
        """Required shape of ``M``: ``(Σ c_i, Σ r_i)``."""
        return (self.n_out, self.n_in)

    @property
    def shape_delta(self) -> tuple[int, int]:
        """Shape of Δ: ``(Σ r_i, Σ c_i)``."""
        return (self.n_in, self.n_out)

    @property
    def has_real(self) -> bool:
        """True if any block is a repeated real scalar."""
        return any(b.is_real for b in self.blocks)

    @property
    def has_scalar(self) -> bool:
        """True if any block is a repeated scalar (real or complex)."""
        return any(b.is_scalar for b in self.blocks)

    @property
    def is_complex_full_only(self) -> bool:
        """True if every block is a full complex block (scalar-identity D scalings)."""
        return all(b.kind is BlockKind.FULL for b in self.blocks)

    @property
    def n_dscale_free(self) -> int:
        """Free real D parameters once the overall scale is fixed (µ is invariant to it)."""
        return sum(b.n_dscale for b in self.blocks) - 1

    @property
    def n_gscale(self) -> int:
        """Free real G parameters (repeated real scalar blocks only)."""
        return sum(b.n_gscale for b in self.blocks)

    def check_M(self, shape, name: str = "M") -> None:
        """Raise :class:`DimensionError` unless ``shape[:2] == (Σ c_i, Σ r_i)``."""
        if tuple(shape[:2]) != self.shape_M:
            raise DimensionError(
                f"block structure {self.to_blk().tolist()} needs {name} of size "
                f"{self.n_out} x {self.n_in} (sum of c_i = {self.n_out} rows, sum of "
                f"r_i = {self.n_in} columns), got {name} of size {shape[0]} x {shape[1]}"
            )

    # ------------------------------------------------------------------ indices
    def _slices(self, sizes) -> tuple[slice, ...]:
        edges = [0, *np.cumsum(sizes).astype(int).tolist()]
        return tuple(slice(a, b) for a, b in pairwise(edges))

    @cached_property
    def _row_slices(self) -> tuple[slice, ...]:
        return self._slices([b.cols for b in self.blocks])

    @cached_property
    def _col_slices(self) -> tuple[slice, ...]:
        return self._slices([b.rows for b in self.blocks])

    def row_slices(self) -> tuple[slice, ...]:
        """Slices of block ``i`` in the rows of ``M`` (length ``c_i``; columns of Δ)."""
        return self._row_slices

    def col_slices(self) -> tuple[slice, ...]:
        """Slices of block ``i`` in the columns of ``M`` (length ``r_i``; rows of Δ)."""
        return self._col_slices

    # ------------------------------------------------------------------ scalings
    def d_scalings(self, d) -> tuple[np.ndarray, np.ndarray]:
        """Left and right D scalings ``(D_left, D_right)`` from per-block scales.

        ``D_left`` (``n_out × n_out``) and ``D_right`` (``n_in × n_in``) commute with Δ
        in the sense ``D_right Δ = Δ D_left``, so ``µ(D_left M D_right⁻¹) = µ(M)``.

        Parameters
        ----------
        d : sequence
            One entry per block: a positive scalar for a full block (giving ``d I_c``
            on the left and ``d I_r`` on the right), and for a repeated scalar block
            either a positive scalar (``d I_r``) or an ``r × r`` Hermitian positive
            definite matrix (the same on both sides).

        Examples
        --------
        >>> s = BlockStructure.from_blk([[2, 1], [1, 1]])
        >>> DL, DR = s.d_scalings([2.0, 1.0])
        >>> DL.diagonal().real.tolist(), DR.diagonal().real.tolist()
        ([2.0, 1.0], [2.0, 2.0, 1.0])
        """
        if len(d) != self.n_blocks:
            raise DimensionError(f"need {self.n_blocks} block scalings, got {len(d)}")
        DL = np.zeros((self.n_out, self.n_out), dtype=complex)
        DR = np.zeros((self.n_in, self.n_in), dtype=complex)
        for b, rs, cs, di in zip(self.blocks, self.row_slices(), self.col_slices(), d):
            di = np.asarray(di, dtype=complex)
            if di.ndim == 0:
                DL[rs, rs] = di * np.eye(b.cols)
                DR[cs, cs] = di * np.eye(b.rows)
            elif b.is_scalar and di.shape == (b.rows, b.rows):
                DL[rs, rs] = di
                DR[cs, cs] = di
            else:
                raise DimensionError(
                    f"scaling of block {b.kind.value} {b.rows}x{b.cols} must be a scalar"
                    + (f" or {b.rows}x{b.rows} matrix" if b.is_scalar else "")
                    + f", got shape {di.shape}"
                )
        return DL, DR

    def g_scaling(self, g) -> np.ndarray:
        """G scaling (``n_in × n_out``) from per-real-block Hermitian matrices.

        ``g`` has one entry per block: ``None`` (or 0) for complex blocks, a real
        scalar or ``r × r`` Hermitian matrix for real blocks.  Only the diagonal
        positions of real blocks are non-zero.
        """
        if len(g) != self.n_blocks:
            raise DimensionError(f"need {self.n_blocks} block G entries, got {len(g)}")
        G = np.zeros((self.n_in, self.n_out), dtype=complex)
        for b, rs, cs, gi in zip(self.blocks, self.row_slices(), self.col_slices(), g):
            if gi is None:
                continue
            gi = np.asarray(gi, dtype=complex)
            if not b.is_real:
                if np.any(gi != 0):
                    raise DimensionError(f"G must be zero on complex block {b}")
                continue
            G[cs, rs] = gi * np.eye(b.rows) if gi.ndim == 0 else gi
        return G

    def random_delta(self, rng: np.random.Generator) -> np.ndarray:
        """A random Δ of this structure with ``σ̄(Δ_i) = 1`` for every block.

        Useful to test invariance and lower bounds; randomness only from ``rng``.
        """
        Delta = np.zeros(self.shape_delta, dtype=complex)
        for b, rs, cs in zip(self.blocks, self.row_slices(), self.col_slices()):
            if b.kind is BlockKind.FULL:
                blk = rng.standard_normal((b.rows, b.cols)) + 1j * rng.standard_normal((b.rows, b.cols))
                blk /= np.linalg.norm(blk, 2)
            elif b.kind is BlockKind.COMPLEX_SCALAR:
                blk = np.exp(2j * np.pi * rng.random()) * np.eye(b.rows)
            else:
                blk = rng.choice([-1.0, 1.0]) * np.eye(b.rows)
            Delta[cs, rs] = blk
        return Delta
