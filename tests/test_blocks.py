"""Tests of the µ block structure (MATLAB ``blk`` convention)."""

import numpy as np
import pytest

from lmi_suspension.errors import DimensionError, NonFiniteError
from lmi_suspension.mu import BlockKind, BlockStructure


def test_parse_kinds_and_sizes():
    s = BlockStructure.from_blk([[2, 3], [2, 0], [-1, 0]])
    assert [b.kind for b in s.blocks] == [BlockKind.FULL, BlockKind.COMPLEX_SCALAR, BlockKind.REAL_SCALAR]
    assert [(b.rows, b.cols) for b in s.blocks] == [(2, 3), (2, 2), (1, 1)]
    # MATLAB: Δ is (Σr) × (Σc) and M is (Σc) × (Σr).
    assert s.shape_delta == (2 + 2 + 1, 3 + 2 + 1)
    assert s.shape_M == (6, 5)
    assert s.has_real and s.has_scalar and not s.is_complex_full_only
    np.testing.assert_array_equal(s.to_blk(), [[2, 3], [2, 0], [-1, 0]])
    assert BlockStructure.coerce(s) is s


def test_single_row_accepted_and_equality():
    assert BlockStructure.from_blk([3, 2]) == BlockStructure.from_blk([[3, 2]])


def test_slices_partition_M():
    s = BlockStructure.from_blk([[2, 1], [1, 3]])
    # rows of M split by c_i, columns by r_i
    assert s.row_slices() == (slice(0, 1), slice(1, 4))
    assert s.col_slices() == (slice(0, 2), slice(2, 3))


def test_free_parameter_counts():
    # full: 1 each; repeated complex r×r: r² (Hermitian); real r×r: r² for D and r² for G;
    # minus one overall scale.
    s = BlockStructure.from_blk([[1, 1], [2, 2], [3, 0], [-2, 0]])
    assert s.n_dscale_free == 1 + 1 + 9 + 4 - 1
    assert s.n_gscale == 4


@pytest.mark.parametrize(
    "blk",
    [[[0, 1]], [[1, -1]], [[-1, 2]], [[1.5, 1]], [], [[1, 2, 3]]],
)
def test_invalid_rows_raise_dimension_error(blk):
    with pytest.raises(DimensionError):
        BlockStructure.from_blk(blk)


def test_nan_blk_raises():
    with pytest.raises(NonFiniteError):
        BlockStructure.from_blk([[1, np.nan]])


def test_check_M_names_both_sizes():
    s = BlockStructure.from_blk([[2, 1], [1, 1]])
    with pytest.raises(DimensionError, match=r"2 x 3.*got M of size 3 x 2"):
        s.check_M((3, 2))


def test_d_scalings_commute_with_delta():
    # D_right Δ = Δ D_left for every Δ of the structure: checked on random Δ.
    rng = np.random.default_rng(4)
    s = BlockStructure.from_blk([[2, 3], [2, 0], [-1, 0], [1, 2]])
    H = rng.standard_normal((2, 2)) + 1j * rng.standard_normal((2, 2))
    Dh = H @ H.conj().T + np.eye(2)  # Hermitian positive definite for the repeated block
    DL, DR = s.d_scalings([2.0, Dh, 0.7, 1.0])
    assert DL.shape == (s.n_out, s.n_out) and DR.shape == (s.n_in, s.n_in)
    for _ in range(3):
        Delta = s.random_delta(rng)
        np.testing.assert_allclose(DR @ Delta, Delta @ DL, atol=1e-12)


def test_random_delta_blocks_have_unit_norm():
    rng = np.random.default_rng(5)
    s = BlockStructure.from_blk([[2, 3], [2, 0], [-1, 0]])
    Delta = s.random_delta(rng)
    for b, rs, cs in zip(s.blocks, s.row_slices(), s.col_slices()):
        blk = Delta[cs, rs]
        assert np.linalg.norm(blk, 2) == pytest.approx(1.0)
        if b.is_real:
            assert np.all(blk.imag == 0)


def test_d_scalings_reject_wrong_shapes():
    s = BlockStructure.from_blk([[2, 1], [2, 0]])
    with pytest.raises(DimensionError):
        s.d_scalings([1.0])
    with pytest.raises(DimensionError):
        s.d_scalings([np.eye(2), 1.0])  # a full block takes a scalar only


def test_g_scaling_only_on_real_blocks():
    s = BlockStructure.from_blk([[1, 2], [-2, 0]])
    G = s.g_scaling([None, np.array([[1.0, 2j], [-2j, 3.0]])])
    assert G.shape == (s.n_in, s.n_out) == (3, 4)
    np.testing.assert_array_equal(G[1:, 2:], [[1.0, 2j], [-2j, 3.0]])
    assert np.count_nonzero(G[:1, :]) == 0 and np.count_nonzero(G[:, :2]) == 0
    with pytest.raises(DimensionError):
        s.g_scaling([1.0, 0.0])
