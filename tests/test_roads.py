"""Tests of the road inputs: the paper's bump (eq. 32), white noise, ISO 8608 roads."""

import numpy as np
import pytest
from scipy.integrate import cumulative_trapezoid
from scipy.signal import welch

from lmi_suspension.errors import DimensionError, NonFiniteError, ParameterError
from lmi_suspension.seat.roads import (ISO8608_BAND, ISO8608_GD_N0, RoadInput, bump,
                                       iso8608_psd, iso8608_road, white_noise)


def test_bump_shape_matches_eq32():
    # eq. (32) and ERRATA.md: a = 0.1 m, l = 2 m, V0 = 30 km/h -> lasts l/V0 = 0.24 s.
    r = bump(dt=1e-4)
    V0 = 30 / 3.6
    assert np.isclose(r.z0.max(), 0.1, atol=1e-9)
    assert np.isclose(r.t[np.argmax(r.z0)], 0.12, atol=1e-4)
    assert np.all(r.z0[r.t > 2.0 / V0] == 0) and np.all(r.w[r.t > 2.0 / V0] == 0)
    # Peak slope of a/2 (1 - cos(2 pi V0 t / l)) is a pi V0 / l, reached at l/(4 V0).
    assert np.isclose(r.w.max(), 0.1 * np.pi * V0 / 2.0, rtol=1e-6)


def test_bump_w_is_the_derivative_of_z0():
    # Independent route: the integral of w reproduces z0 (trapezoid error O(dt^2)).
    r = bump(dt=1e-4)
    z_int = cumulative_trapezoid(r.w, r.t, initial=0.0)
    assert np.max(np.abs(z_int - r.z0)) < 1e-6
    # and a central difference of z0 matches w inside the bump
    inside = (r.t > 0.01) & (r.t < 0.23)
    dz = np.gradient(r.z0, r.t)
    assert np.max(np.abs(dz[inside] - r.w[inside])) < 1e-4


@pytest.mark.parametrize("kwargs, err", [
    (dict(a=-0.1), ParameterError),
    (dict(l=0.0), ParameterError),
    (dict(V0_kmh=float("nan")), NonFiniteError),
    (dict(dt=0.0), ParameterError),
    (dict(t_end=1.0, dt=2.0), ParameterError),
])
def test_bump_rejects_bad_parameters(kwargs, err):
    with pytest.raises(err):
        bump(**kwargs)


def test_road_input_validation():
    t = np.linspace(0, 1, 11)
    with pytest.raises(NonFiniteError):
        RoadInput(t, np.zeros(11), np.r_[np.zeros(10), np.nan])
    with pytest.raises(DimensionError):
        RoadInput(t, np.zeros(10), np.zeros(11))
    with pytest.raises(ParameterError):
        RoadInput(t[::-1], np.zeros(11), np.zeros(11))
    r = RoadInput(t, np.zeros(11), np.zeros(11))
    assert not r.w.flags.writeable  # frozen data


def test_white_noise_psd_convention():
    # Two-sided PSD S0 over |f| <= B: variance 2 B S0, and a Welch estimate of the
    # one-sided PSD is 2 S0 in band and ~0 above it.
    S0, B, dt = 1e-3, 40.0, 1e-3
    r = white_noise(200.0, dt, psd=S0, bandwidth_hz=B, rng=np.random.default_rng(3))
    assert abs(r.w.var() / (2 * B * S0) - 1) < 0.05
    f, P = welch(r.w, fs=1 / dt, nperseg=4096)
    band = (f > 1) & (f < 0.9 * B)
    assert abs(np.mean(P[band]) / (2 * S0) - 1) < 0.05
    assert np.mean(P[f > 1.2 * B]) < 1e-3 * 2 * S0
    # z0 is the integral of w
    assert np.allclose(np.gradient(r.z0, r.t)[1:-1], r.w[1:-1], atol=0.05 * r.w.std())


def test_white_noise_full_band_is_sampled_unit_intensity():
    # psd = 1 with the Nyquist band: i.i.d. samples of variance 1/dt (the paper's Fig. 8).
    r = white_noise(10.0, 1e-3, rng=np.random.default_rng(0))
    assert abs(r.w.var() * 1e-3 - 1) < 0.05
    assert abs(r.w.mean()) < 1e-12


def test_white_noise_reproducible_and_needs_generator():
    a = white_noise(1.0, 1e-3, rng=np.random.default_rng(7))
    b = white_noise(1.0, 1e-3, rng=np.random.default_rng(7))
    assert np.array_equal(a.w, b.w)
    with pytest.raises(ParameterError):
        white_noise(1.0, 1e-3, rng=7)
    with pytest.raises(ParameterError):
        white_noise(1.0, 1e-3, bandwidth_hz=600.0, rng=np.random.default_rng(0))


def test_iso8608_class_table():
    # ISO 8608:1995: geometric means 16, 64, 256, ... (x1e-6 m^3) at n0 = 0.1 cycles/m.
    assert ISO8608_GD_N0["A"] == pytest.approx(16e-6)
    assert ISO8608_GD_N0["D"] == pytest.approx(1024e-6)
    assert ISO8608_GD_N0["H"] == pytest.approx(262144e-6)
    assert iso8608_psd(0.2, "B") == pytest.approx(64e-6 / 4)
    with pytest.raises(ParameterError):
        iso8608_psd(0.1, "Z")


@pytest.mark.parametrize("road_class, V_kmh", [("C", 72.0), ("A", 36.0)])
def test_iso8608_profile_psd_matches_standard(road_class, V_kmh):
    # Independent estimate: Welch PSD of the synthesised profile vs Gd(n) of ISO 8608.
    V = V_kmh / 3.6
    dt = 0.005
    r = iso8608_road(road_class, V_kmh, 400.0, dt, rng=np.random.default_rng(11))
    f, P = welch(r.z0, fs=1 / dt, nperseg=8192)
    n = f / V
    band = (n > 2 * ISO8608_BAND[0]) & (n < 0.8 * ISO8608_BAND[1]) & (f < 0.4 / dt)
    G_true = iso8608_psd(n[band], road_class) / V
    ratio = P[band] / G_true
    # Welch with ~20 averages: each bin within a factor 2, the band average within 10 %.
    assert np.all((ratio > 0.4) & (ratio < 2.5))
    assert abs(np.exp(np.mean(np.log(ratio))) - 1) < 0.1
    # w is the derivative of z0: compare with a spectral derivative estimate
    fw, Pw = welch(r.w, fs=1 / dt, nperseg=8192)
    assert np.allclose(Pw[band], (2 * np.pi * fw[band]) ** 2 * P[band], rtol=0.05)


def test_iso8608_bad_input():
    rng = np.random.default_rng(0)
    with pytest.raises(ParameterError):
        iso8608_road("Q", 50.0, 10.0, 0.01, rng=rng)
    with pytest.raises(ParameterError):
        iso8608_road("A", -50.0, 10.0, 0.01, rng=rng)
    with pytest.raises(ParameterError):
        iso8608_road("A", 50.0, 10.0, 0.01, rng=None)
