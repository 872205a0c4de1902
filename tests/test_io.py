"""Controllers round-trip through JSON bit for bit."""

import json

import control
import numpy as np
import pytest
from hypothesis import given, settings, strategies as st

from lmi_suspension.errors import DimensionError, InputError, NonFiniteError
from lmi_suspension.io import controller_from_dict, load_controller, save_controller


@settings(max_examples=20, deadline=None)
@given(seed=st.integers(0, 2**31 - 1), n=st.integers(0, 8))
def test_round_trip_is_exact(tmp_path_factory, seed, n):
    rng = np.random.default_rng(seed)
    # awkward magnitudes: fast poles, tiny and huge gains
    scale = 10.0 ** rng.uniform(-8, 8, size=4)
    if n:
        K = control.ss(scale[0] * rng.standard_normal((n, n)), scale[1] * rng.standard_normal((n, 2)),
                       scale[2] * rng.standard_normal((1, n)), scale[3] * rng.standard_normal((1, 2)))
    else:
        K = control.ss([], [], [], scale[3] * rng.standard_normal((1, 2)))
    path = tmp_path_factory.mktemp("k") / "controller.json"
    save_controller(path, K, inputs=["x1", "x3"], outputs=["u"],
                    metadata={"mu_peak": np.float64(0.97), "weights": np.arange(3.0)})
    K2, meta = load_controller(path)
    for name in "ABCD":
        a, b = np.asarray(getattr(K, name)), np.asarray(getattr(K2, name))
        assert a.size == b.size
        assert a.reshape(-1).tobytes() == b.reshape(-1).tobytes()  # bit for bit
    assert list(K2.input_labels) == ["x1", "x3"] and list(K2.output_labels) == ["u"]
    assert meta == {"mu_peak": 0.97, "weights": [0.0, 1.0, 2.0]}


def test_bad_files_raise_typed_errors(tmp_path):
    bad = tmp_path / "bad.json"
    bad.write_text("{not json")
    with pytest.raises(InputError):
        load_controller(bad)
    good = {"A": [[-1.0]], "B": [[1.0, 0.0]], "C": [[1.0]], "D": [[0.0, 0.0]],
            "inputs": ["x1", "x3"], "outputs": ["u"]}
    with pytest.raises(InputError, match="inputs"):
        controller_from_dict({k: v for k, v in good.items() if k != "inputs"})
    with pytest.raises(DimensionError):
        controller_from_dict({**good, "D": [[0.0]]})
    with pytest.raises(NonFiniteError):
        controller_from_dict({**good, "A": [[float("nan")]]})
    json.dumps(good)  # the valid description is plain JSON
    assert controller_from_dict(good).nstates == 1
