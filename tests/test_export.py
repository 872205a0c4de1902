"""MATLAB export of controllers (``save_controller_mat``, ``lmi-suspension export``)."""

from pathlib import Path

import control
import numpy as np
import pytest
import scipy.io

from lmi_suspension.errors import InputError
from lmi_suspension.io import load_controller, load_controller_mat, save_controller_mat

SEAT = Path(__file__).resolve().parents[1] / "notebooks" / "controller.json"


def _response(A, B, C, D, w):
    """C (jwI - A)^-1 B + D at each frequency, by linear solves (not python-control)."""
    n = A.shape[0]
    return np.array([C @ np.linalg.solve(1j * x * np.eye(n) - A, B) + D for x in w])


def test_seat_controller_mat_has_the_json_controllers_frequency_response(tmp_path):
    """Acceptance of issue 20: read back with scipy.io.loadmat alone, the .mat gives the
    frequency response of controller.json to 1e-12 relative on 200 frequencies."""
    K, meta = load_controller(SEAT)
    path = save_controller_mat(tmp_path / "K.mat", K, metadata=meta)
    m = scipy.io.loadmat(path)
    w = np.logspace(-2, 5, 200)
    ref = _response(*(np.asarray(getattr(K, k), dtype=float) for k in "ABCD"), w)
    got = _response(m["A"], m["B"], m["C"], m["D"], w)
    assert np.max(np.abs(got - ref) / np.abs(ref)) <= 1e-12
    assert [str(x[0]) for x in m["InputName"].ravel()] == ["x1", "x3"]
    assert [str(x[0]) for x in m["OutputName"].ravel()] == ["u"]
    assert "Ts" not in m  # continuous time
    for k in "ABCD":  # doubles stored as doubles: the same numbers, bit for bit
        assert np.array_equal(m[k], np.asarray(getattr(K, k)))


def test_discretised_export_is_the_zoh_realization(tmp_path):
    K, _ = load_controller(SEAT)
    path = save_controller_mat(tmp_path / "Kd.mat", K, ts=1e-3)
    Kd, names = load_controller_mat(path)
    ref = control.c2d(K, 1e-3, method="zoh")
    assert Kd.dt == 1e-3 and names == (["x1", "x3"], ["u"])
    for k in "ABCD":
        assert np.array_equal(np.asarray(getattr(Kd, k)), np.asarray(getattr(ref, k)))
    with pytest.raises(InputError, match="ts must be a positive"):
        save_controller_mat(tmp_path / "x.mat", K, ts=0.0)


def test_static_gain_round_trips(tmp_path):
    K = control.ss([], [], [], [[1.5, -2.0]])
    K2, _ = load_controller_mat(save_controller_mat(tmp_path / "s.mat", K, inputs=["a", "b"],
                                                    outputs=["u"]))
    assert K2.nstates == 0 and np.array_equal(np.asarray(K2.D), [[1.5, -2.0]])


def test_cli_export_mat_and_json(tmp_path, capsys):
    from lmi_suspension.cli import main

    assert main(["export", "--controller", str(SEAT), "--out", str(tmp_path / "K.mat")]) == 0
    assert "wrote" in capsys.readouterr().out
    K, _ = load_controller(SEAT)
    K2, _ = load_controller_mat(tmp_path / "K.mat")
    assert np.array_equal(np.asarray(K2.A), np.asarray(K.A))
    assert main(["export", "--controller", str(SEAT), "--format", "json",
                 "--out", str(tmp_path / "K.json")]) == 0
    K3, _ = load_controller(tmp_path / "K.json")
    assert np.array_equal(np.asarray(K3.C), np.asarray(K.C))
    with pytest.raises(SystemExit) as exc:
        main(["export", "--controller", str(tmp_path / "none.json"), "--out", "x.mat"])
    assert exc.value.code == 2 and "not found" in capsys.readouterr().err


def test_unreadable_mat_is_a_typed_error(tmp_path):
    bad = tmp_path / "bad.mat"
    bad.write_text("not a mat file")
    with pytest.raises(InputError):
        load_controller_mat(bad)
    scipy.io.savemat(tmp_path / "other.mat", {"x": 1.0})
    with pytest.raises(InputError, match="lacks"):
        load_controller_mat(tmp_path / "other.mat")
