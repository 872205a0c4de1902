"""The table-scheduled controller (lmi_suspension.lti.gridded) and its file.

References: the interpolated matrices are computed here by numpy from the node matrices
(the definition ``a + w (b - a)`` of multilinear interpolation, and an affine family that
multilinear interpolation reproduces exactly); the round trip compares bit for bit.
"""

import itertools
import json
import math

import control
import numpy as np
import pytest

from lmi_suspension.errors import DimensionError, InputError, NonFiniteError, ParameterError
from lmi_suspension.io import (GRIDDED_FORMAT, load_controller, save_controller,
                               save_scheduled_controller, scheduled_from_dict,
                               scheduled_to_dict)
from lmi_suspension.lti.gridded import GriddedController


def _random_ss(rng, n=3):
    return control.ss(-np.eye(n) + 0.1 * rng.standard_normal((n, n)),
                      rng.standard_normal((n, 2)), rng.standard_normal((1, n)),
                      rng.standard_normal((1, 2)))


def _mass_table(rng):
    return GriddedController.from_controllers(
        {"m3": [30.0, 45.0, 70.0]}, [_random_ss(rng) for _ in range(3)],
        inputs=["x1", "x3"], outputs=["u"])


def _same(K1, K2) -> bool:
    return all(np.array_equal(np.asarray(getattr(K1, M)), np.asarray(getattr(K2, M)))
               for M in "ABCD")


def test_nodes_exact_and_between_nodes_the_interpolation():
    rng = np.random.default_rng(1)
    K = _mass_table(rng)
    for node, Kn in zip(K.nodes, K.controllers):
        assert _same(K.at(m3=node[0]), Kn)          # a node's matrices, bit for bit
    w = (52.0 - 45.0) / (70.0 - 45.0)
    a, b = K.controllers[1], K.controllers[2]
    for M in "ABCD":
        ref = np.asarray(getattr(a, M)) + w * (np.asarray(getattr(b, M))
                                               - np.asarray(getattr(a, M)))
        # the same formula, evaluated in the same order: equal to the last bit
        assert np.array_equal(np.asarray(getattr(K.at(52.0), M)), ref)
    assert K.at(m3=52.0).input_labels == ["x1", "x3"]
    assert K.bounds == ((30.0, 70.0),)


def test_two_parameters_reproduce_an_affine_family():
    # M(p, q) = M0 + p M1 + q M2 is multilinear: the interpolation between the nodes of
    # any grid gives it back (to rounding, relative 1e-13 of the matrices' size)
    rng = np.random.default_rng(2)
    base = [_random_ss(rng) for _ in range(3)]

    def family(p, q):
        return control.ss(*(np.asarray(getattr(base[0], M)) + p * np.asarray(getattr(base[1], M))
                            + q * np.asarray(getattr(base[2], M)) for M in "ABCD"))

    axes = {"p": [0.0, 0.5, 2.0], "q": [-1.0, 3.0]}
    K = GriddedController.from_controllers(
        axes, [family(p, q) for p, q in itertools.product(*axes.values())])
    for p, q in [(0.3, 0.1), (1.7, 2.9), (2.0, -1.0), (0.5, 0.0)]:
        ref = family(p, q)
        for M in "ABCD":
            assert np.allclose(getattr(K.at(p=p, q=q), M), getattr(ref, M), rtol=0,
                               atol=1e-13 * 10)


def test_file_round_trip_is_exact(tmp_path):
    rng = np.random.default_rng(3)
    K = _mass_table(rng)
    path = save_scheduled_controller(tmp_path / "K.json", K, metadata={"made": "test"})
    assert json.loads(path.read_text())["format"] == GRIDDED_FORMAT
    K2, meta = load_controller(path)
    assert isinstance(K2, GriddedController) and meta == {"made": "test"}
    assert K2.names == K.names and K2.inputs == K.inputs and K2.outputs == K.outputs
    assert all(np.array_equal(a, b) for a, b in zip(K2.axes, K.axes))
    for m in (30.0, 31.234567, 45.0, 57.5, 70.0):  # nodes and between: the same numbers
        assert _same(K2.at(m3=m), K.at(m3=m))
    assert _same(scheduled_from_dict(scheduled_to_dict(K)).at(m3=44.0), K.at(m3=44.0))


def test_load_controller_still_reads_one_controller(tmp_path):
    Kc = _random_ss(np.random.default_rng(4))
    K2, _ = load_controller(save_controller(tmp_path / "K.json", Kc))
    assert isinstance(K2, control.StateSpace) and _same(K2, Kc)


def test_load_controller_reads_an_lpvsyn_schedule(tmp_path):
    from lmi_suspension.lpv import ScheduledController, lpvsyn

    def msd(m):  # tests/test_lpv.py's mass-spring-damper
        return control.ss([[0, 1], [-1 / m, -0.2 / m]], [[0, 0, 0], [1 / m, 0, 1 / m]],
                          [[1, 0], [0, 0], [1, 0]], [[0, 0, 0], [0, 0, 0.1], [0, 0.1, 0]])

    Ks = lpvsyn(msd, {"m": [1.0, 2.0, 4.0]}, 1, 1).K
    K2, _ = load_controller(save_scheduled_controller(tmp_path / "lpv.json", Ks))
    assert isinstance(K2, ScheduledController)
    assert _same(K2.at(m=2.0), Ks.at(m=2.0))


def test_bad_values_are_typed_errors():
    K = _mass_table(np.random.default_rng(5))
    with pytest.raises(ParameterError, match="outside"):
        K.at(m3=80.0)
    with pytest.raises(ParameterError, match="outside"):
        K.at(m3=29.0)
    with pytest.raises(ParameterError, match="unknown"):
        K.at(mass=40.0)
    with pytest.raises(ParameterError, match="expected 1 value"):
        K.at()
    with pytest.raises(NonFiniteError):
        K.at(m3=math.nan)
    with pytest.raises(ParameterError):
        K.at(m3="40")
    with pytest.raises(ParameterError, match="not both"):
        K.at(40.0, m3=40.0)
    # a mass an ulp past the end is the end
    assert _same(K.at(m3=np.nextafter(70.0, 71.0)), K.controllers[-1])


def test_bad_tables_are_typed_errors():
    rng = np.random.default_rng(6)
    Ks = [_random_ss(rng), _random_ss(rng, n=4)]
    with pytest.raises(DimensionError, match="states"):
        GriddedController.from_controllers({"m3": [30.0, 70.0]}, Ks)
    with pytest.raises(ParameterError, match="increasing"):
        GriddedController.from_controllers({"m3": [70.0, 30.0]}, [Ks[0], Ks[0]])
    with pytest.raises(DimensionError, match="nodes"):
        GriddedController.from_controllers({"m3": [30.0, 50.0, 70.0]}, [Ks[0], Ks[0]])
    with pytest.raises(InputError, match="lacks key"):
        GriddedController.from_dict({"names": ["m3"]})
    with pytest.raises(InputError, match="interpolation"):
        GriddedController.from_dict({"interpolation": "cubic"})


# ------------------------------------------------------------ piecewise constant (bins)

def _bin_table(rng):
    # bins of different orders: never blended, so allowed
    return GriddedController.from_controllers(
        {"m3": [30.0, 40.0, 55.0, 70.0]},
        [_random_ss(rng, n=3), _random_ss(rng, n=4), _random_ss(rng, n=2)],
        inputs=["x1", "x3"], outputs=["u"], interpolation="bins")


def test_bins_pick_the_bin_controller_unchanged():
    # reference: the bin of a value by its definition [lo, hi) (the last one [lo, hi]),
    # written here with plain comparisons
    K = _bin_table(np.random.default_rng(11))
    assert K.bounds == ((30.0, 70.0),)
    assert K.bins == (((30.0, 40.0),), ((40.0, 55.0),), ((55.0, 70.0),))
    assert K.nodes == ((35.0,), (47.5,), (62.5,))
    for m in (30.0, 33.3, np.nextafter(40.0, 0.0), 40.0, 47.0, 54.999, 55.0, 61.0, 70.0,
              np.nextafter(70.0, 71.0)):
        ref = next(i for i, ((lo, hi),) in enumerate(K.bins)
                   if lo <= m < hi or (i == len(K.bins) - 1 and m >= lo))
        assert K.bin_index(m3=m) == ref
        assert _same(K.at(m3=m), K.controllers[ref])        # bit for bit
    assert K.at(m3=40.0).nstates == 4 and K.at(m3=39.0).nstates == 3
    assert K.at(m3=50.0).input_labels == ["x1", "x3"]


def test_bins_in_two_parameters_follow_the_product_order():
    rng = np.random.default_rng(12)
    Ks = [_random_ss(rng) for _ in range(6)]
    K = GriddedController.from_controllers({"m3": [30.0, 50.0, 70.0],
                                            "k1": [0.8, 0.9, 1.1, 1.2]}, Ks,
                                           interpolation="bins")
    # itertools.product over (m3 bins) x (k1 bins): index = i_m3 * 3 + i_k1
    assert _same(K.at(m3=31.0, k1=0.85), Ks[0])
    assert _same(K.at(m3=31.0, k1=1.15), Ks[2])
    assert _same(K.at(m3=60.0, k1=1.0), Ks[4])
    assert K.bins[4] == ((50.0, 70.0), (0.9, 1.1))


def test_bins_file_round_trip_is_exact(tmp_path):
    K = _bin_table(np.random.default_rng(13))
    path = save_scheduled_controller(tmp_path / "bins.json", K, metadata={"made": "test"})
    data = json.loads(path.read_text())
    assert data["format"] == GRIDDED_FORMAT and data["interpolation"] == "bins"
    assert [c["bin"] for c in data["controllers"]] == [{"m3": [30.0, 40.0]},
                                                       {"m3": [40.0, 55.0]},
                                                       {"m3": [55.0, 70.0]}]
    K2, meta = load_controller(path)
    assert isinstance(K2, GriddedController) and K2.interpolation == "bins"
    assert meta == {"made": "test"}
    assert all(np.array_equal(a, b) for a, b in zip(K2.axes, K.axes))
    for a, b in zip(K2.controllers, K.controllers):
        assert _same(a, b)
    # written again, the same text
    again = save_scheduled_controller(tmp_path / "again.json", K2, metadata={"made": "test"})
    assert again.read_text() == path.read_text()


def test_bad_bins_are_typed_errors():
    rng = np.random.default_rng(14)
    K1 = _random_ss(rng)
    with pytest.raises(ParameterError, match="at least two"):
        GriddedController.from_controllers({"m3": [30.0]}, [K1], interpolation="bins")
    with pytest.raises(DimensionError, match="bins"):
        GriddedController.from_controllers({"m3": [30.0, 50.0, 70.0]}, [K1],
                                           interpolation="bins")
    with pytest.raises(DimensionError, match="inputs"):
        GriddedController.from_controllers(
            {"m3": [30.0, 50.0, 70.0]}, [K1, control.ss([[-1.0]], [[1.0]], [[1.0]], [[0.0]])],
            interpolation="bins")
    with pytest.raises(ParameterError, match="interpolation"):
        GriddedController.from_controllers({"m3": [30.0, 70.0]}, [K1], interpolation="step")
    K = _bin_table(rng)
    with pytest.raises(ParameterError, match="outside"):
        K.at(m3=71.0)
    with pytest.raises(NonFiniteError):
        K.at(m3=math.nan)
    with pytest.raises(ParameterError, match="not bins"):
        _mass_table(rng).bins
    with pytest.raises(ParameterError, match="not bins"):
        _mass_table(rng).bin_index(m3=40.0)
