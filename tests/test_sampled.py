"""The discretised controller and the sampled-data loop (issue 17, item 3)."""

import control
import numpy as np
import pytest

from lmi_suspension.errors import DimensionError, LmiSuspensionError, ParameterError
from lmi_suspension.seat.roads import bump
from lmi_suspension.seat.sampled import discretise_controller, simulate_sampled
from lmi_suspension.seat.simulate import simulate


def _lag_controller():
    """A smooth test controller (poles at 60 and 200 rad/s, below the 1 kHz Nyquist rate
    of 3142 rad/s): a skyhook-like feedback on both deflections."""
    return control.ss(control.tf([[[4e4 * 60], [-2e4 * 200]]],
                                 [[[1, 60], [1, 200]]]))


def test_tustin_keeps_stability_and_the_frequency_response():
    K = _lag_controller()
    Kd = discretise_controller(K, 1e-3)
    assert Kd.dt == 1e-3 and np.all(np.abs(Kd.poles()) < 1)
    # the bilinear map's warping, (2/T) tan(ωT/2), computed here: at 20 rad/s the
    # discrete response is the continuous one at 20.0013 rad/s
    w = 20.0
    wd = 2e3 * np.tan(w * 1e-3 / 2)
    resp_d = np.asarray(Kd(np.exp(1j * w * 1e-3)))
    resp_c = np.asarray(K(1j * wd))
    assert np.allclose(resp_d, resp_c, rtol=1e-9)


def test_tustin_of_a_badly_scaled_realization_is_balanced_first():
    """A lag controller in coordinates scaled by 1e-7 ... 1e7 (‖A‖ about 1e14, as
    ``reproduce``'s nominal H∞ LMI controller had 8e11): scipy's Tustin map warned of an
    ill-conditioned solve (LinAlgWarning) on the user's terminal.  Balanced first, it is
    silent and its response is the well-scaled realization's map, computed here."""
    import warnings

    K = control.ss([[0.0, 1.0], [-12000.0, -260.0]], [[0.0], [1.0]], [[2.4e6, 100.0]],
                   [[0.0]])                        # poles at 60 and 200 rad/s, companion form
    T = np.diag([1e-7, 1e7])
    Ti = np.diag([1e7, 1e-7])
    bad = control.ss(Ti @ K.A @ T, Ti @ K.B, K.C @ T, K.D)
    assert np.linalg.cond(np.eye(2) - 0.5e-3 * np.asarray(bad.A)) > 1e10  # the premise
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        Kd = discretise_controller(bad, 1e-3)
    ref = control.sample_system(K, 1e-3, method="bilinear")
    for w in (1.0, 60.0, 2000.0):
        z = np.exp(1j * w * 1e-3)
        assert np.allclose(np.asarray(Kd(z)), np.asarray(ref(z)), rtol=1e-9)


def test_prewarped_tustin_is_exact_at_its_frequency():
    K = _lag_controller()
    w0 = 500.0
    Kd = discretise_controller(K, 1e-3, prewarp=w0)
    assert np.allclose(np.asarray(Kd(np.exp(1j * w0 * 1e-3))), np.asarray(K(1j * w0)),
                       rtol=1e-9)


def test_held_command_is_the_difference_equation_of_the_sampled_measurements():
    """Independent route: python-control's forced_response of Kd on the sampled y."""
    Kd = discretise_controller(_lag_controller(), 1e-3)
    r = simulate_sampled(Kd, bump(t_end=1.0), u_max=np.inf)
    every = 10  # 1 ms / 0.1 ms
    y = np.vstack([r.x1[::every], r.x3[::every]])
    ref = control.forced_response(Kd, U=y).outputs
    assert np.allclose(r.u_command[::every], ref, rtol=1e-10, atol=1e-9)
    # held between samples
    assert np.all(r.u_command[1:every] == r.u_command[0])


def test_sampled_loop_converges_to_the_continuous_one():
    """At 1 kHz the bump peak is within 5 % of the continuous loop's (the issue's
    acceptance), and a faster rate is closer still."""
    K = _lag_controller()
    cont = simulate(K, bump(), delay=0.01, u_max=np.inf)
    peak_c = np.max(np.abs(cont.z3dd))
    errors = []
    for T in (1e-3, 2e-4):
        r = simulate_sampled(discretise_controller(K, T), bump(), delay=0.01, u_max=np.inf)
        errors.append(abs(np.max(np.abs(r.z3dd)) - peak_c) / peak_c)
    assert errors[0] < 0.05
    assert errors[1] < errors[0]


def test_delay_and_clipping_act_on_the_held_command():
    Kd = discretise_controller(_lag_controller(), 1e-3)
    free = simulate_sampled(Kd, bump(t_end=1.0), delay=0.005, u_max=np.inf)
    u_max = 0.5 * np.max(np.abs(free.u_command))
    r = simulate_sampled(Kd, bump(t_end=1.0), delay=0.005, u_max=u_max)
    shifted = np.clip(np.concatenate([np.zeros(50), r.u_command[:-50]]), -u_max, u_max)
    assert np.array_equal(r.u_applied, shifted)
    assert r.saturated_fraction > 0


def test_noise_and_quantisation_are_reproducible():
    Kd = discretise_controller(_lag_controller(), 1e-3)
    runs = [simulate_sampled(Kd, bump(t_end=0.5), noise=(1e-4, 1e-4), quantisation=1e-5,
                             rng=np.random.default_rng(3)) for _ in range(2)]
    assert np.array_equal(runs[0].u_command, runs[1].u_command)
    quiet = simulate_sampled(Kd, bump(t_end=0.5))
    assert not np.array_equal(runs[0].u_command, quiet.u_command)


@pytest.mark.parametrize("kwargs, error", [
    (dict(delay=0.00015), ParameterError),          # not a multiple of the fine step
    (dict(noise=(1e-4, 1e-4)), ParameterError),     # noise without a generator
    (dict(noise=(np.nan, 0.0), rng=np.random.default_rng(0)), ParameterError),
    (dict(quantisation=-1.0), ParameterError),
    (dict(u_max=0.0), ParameterError),
])
def test_bad_input_is_a_typed_error(kwargs, error):
    Kd = discretise_controller(_lag_controller(), 1e-3)
    with pytest.raises(error):
        simulate_sampled(Kd, bump(t_end=0.2), **kwargs)


def test_wrong_controllers_are_typed_errors():
    K = _lag_controller()
    with pytest.raises(ParameterError):
        simulate_sampled(K, bump(t_end=0.2))            # continuous
    with pytest.raises(ParameterError):
        simulate_sampled(discretise_controller(K, 1.5e-4), bump(t_end=0.2))  # 1.5 steps
    with pytest.raises(DimensionError):
        simulate_sampled(control.ss([], [], [], [[1.0]], 1e-3), bump(t_end=0.2))
    with pytest.raises(ParameterError):
        discretise_controller(K, 1e-3, prewarp=4000.0)  # above π/T
    with pytest.raises(ParameterError):
        discretise_controller(K, 1e-3, method="foh")
    with pytest.raises(LmiSuspensionError):
        discretise_controller(discretise_controller(K), 1e-3)
