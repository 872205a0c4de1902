# ---
# jupyter:
#   jupytext:
#     text_representation:
#       extension: .py
#       format_name: percent
#       format_version: '1.3'
#       jupytext_version: 1.19.6
#   kernelspec:
#     display_name: Python 3
#     language: python
#     name: python3
# ---

# %% [markdown]
# # 03 · The seat-suspension paper, reproduced
#
# An active seat suspension carrying a 3-DOF seated human (paper eq. 1, Table 1): seat frame
# $m_1$, thighs/buttocks $m_2 = m_{21} + m_{22} = 1 + 7.8$ kg, upper body $m_3$. The input
# $w = \dot z_0$ is the floor velocity, $u$ the actuator force (applied as $-u$ on $m_1$),
# the performance output the upper-body acceleration $\ddot z_3$, the measurements
# $y = [x_1, x_3]$ (suspension and cushion deflections). The model is derived from the
# equations of motion, not the misprinted matrices (see `shared/paper/ERRATA.md`).

# %%
# %matplotlib inline
import time
from pathlib import Path

import matplotlib.pyplot as plt
import numpy as np
from IPython.display import Markdown, display

from lmi_suspension import HinfsynOptions, hinfsyn, lft, mussv
from lmi_suspension.report.figures import (plot_mu_bounds, plot_peak_vs_delay, plot_responses,
                                           plot_road)
from lmi_suspension.seat import (SeatDesignOptions, SeatParameters, bump, bump_limit,
                                 closed_loop_stable, natural_modes, seat_augmented_plant,
                                 seat_model, simulate, stability_delay_margin, white_noise)

T_START = time.perf_counter()


def table(rows, header):
    lines = ["| " + " | ".join(header) + " |", "|" + "---|" * len(header)]
    lines += ["| " + " | ".join(str(c) for c in r) + " |" for r in rows]
    display(Markdown("\n".join(lines)))


# %% [markdown]
# ## Model and natural modes
#
# `natural_modes` lists one row per complex pole pair (an oscillatory mode) or real pole
# (ζ = 1). The passive seat's dominant mode is the lightly damped one near 2 Hz, where the
# body is most sensitive to vertical vibration. As an independent check the natural
# frequencies are recomputed from the eigenvalues of $A$ here.

# %%
params = SeatParameters()
G = seat_model(params)
print(params)
print("inputs", G.input_labels, "outputs", G.output_labels)
modes = natural_modes(params)
table([[i + 1, f"{f:.3f}", f"{wn:.2f}", f"{z:.3f}"] for i, (f, wn, z) in enumerate(modes)],
      ["mode", "f (Hz)", "ω_n (rad/s)", "ζ"])
eig = np.linalg.eigvals(np.asarray(G.A))
wn_eig = np.sort(np.abs(eig[eig.imag >= 0]))
assert np.allclose(wn_eig, [m[1] for m in modes], rtol=1e-9)

# %% [markdown]
# ## Road inputs (Figs. 7 and 8)
#
# The bump of eq. (32): $z_0 = \tfrac a2\,(1 - \cos(2\pi V_0 t / l))$ for $t \le l/V_0$, with
# $a = 0.1$ m, $l = 2$ m, $V_0 = 30$ km/h, so it lasts $0.24$ s; the model input is its exact
# derivative $w = \dot z_0$. The random input is band-limited white noise for $w$ (two-sided
# PSD $10^{-4}$ (m/s)²/Hz up to 50 Hz, seeded).

# %%
road = bump()
assert np.isclose(road.z0.max(), 0.1) and np.isclose(road.t[np.argmax(road.z0)], 0.12)
display(plot_road(road, title="Fig. 7: bump (eq. 32)"))
noise = white_noise(5.0, 1e-3, psd=1e-4, bandwidth_hz=50.0, rng=np.random.default_rng(0))
display(plot_road(noise, title="Fig. 8: white-noise floor velocity"))

# %% [markdown]
# ## The augmented plant (Fig. 2) and its block structure
#
# `seat_augmented_plant` wraps the model in weights (Wk-weighted $\ddot z_3$, force $u/u_{\max}$,
# deflection $x_1/z_{\max}$, sensor noise) and uncertainty channels:
#
# * **delay** $d \in [0, 25]$ ms: $e^{-sd} \in N(s)(1 + W(s)\delta)$, $|\delta| \le 1$, with
#   $N$ the first-order Padé of the mid delay (eq. 8) and $W$ fitted over the *exact* envelope
#   of all delays in the interval (a complex 1×1 block);
# * **parametric**: occupant mass $m_3 \in [30, 70]$ kg and $k_1 \pm 20\,\%$ (real scalars);
# * the paper's **norm-bounded** $\Delta A, \Delta B, \Delta C_1, \Delta C_3$ with δ = 0.02;
# * the 3×3 **performance** block.
#
# The plot shows the delay cover: $|W|$ lies above the exact envelope
# $\max_d |e^{-j\omega d} - N| / |N|$ at every frequency.

# %%
aug = seat_augmented_plant()
table([[n, list(r)] for n, r in zip(aug.block_names, aug.blk.tolist())], ["block", "blk row [r, c]"])
print(f"P: {aug.P.nstates} states, {aug.P.ninputs} inputs, {aug.P.noutputs} outputs; "
      f"nmeas = {aug.nmeas}, ncon = {aug.ncon}")
print("inputs ", aug.P.input_labels)
print("outputs", aug.P.output_labels)

w_cov = np.logspace(-1, 4, 400)
env, bnd = aug.delay.envelope(w_cov), aug.delay.bound(w_cov)
assert np.all(bnd >= env)
fig, ax = plt.subplots(figsize=(7, 3.2))
ax.loglog(w_cov, env, label="exact envelope, d ∈ [0, 25] ms")
ax.loglog(w_cov, bnd, "--", label="|W(jω)| (cover)")
ax.set_xlabel("ω (rad/s)")
ax.legend()
ax.grid(True, which="both", alpha=0.3)
plt.show()

# %% [markdown]
# ## The controller
#
# The package's µ design, `lmi_suspension.seat.design.design_mu_controller` (D-K iteration on
# the plant above with the design's weights, `DEFAULT_DESIGN`), takes about 10–30 s. To keep this
# notebook short its result is stored next to it in `controller.json` (with the µ bounds of the
# design in the metadata; regenerate with `python make_controller.py`). If the file is
# missing the design is run here.
#
# **Fallback**, used only when the design module is not available: a *nominal* H∞ controller,
# `hinfsyn` on the plant without uncertainty channels
# (`SeatDesignOptions(include_delay=False, include_parametric=False, include_paper=False)`).
# It is not robust by design; its robustness is only *analysed* below. (The LMI reconstruction
# needs a 20 % γ relaxation on that plant with the default weights.)

# %%
t0 = time.perf_counter()
saved = Path("controller.json")
try:
    from lmi_suspension.seat import design as seat_design
except ImportError:
    seat_design = None

stored = None   # µ bounds that came with the design, to be checked below
if seat_design is not None:
    from lmi_suspension.seat.augmented import DEFAULT_DESIGN
    design_options = DEFAULT_DESIGN
    if saved.exists():
        from lmi_suspension.io import load_controller
        K, meta = load_controller(saved)
        stored = {k: np.asarray(meta[k], dtype=float) for k in ("omega", "mu_upper", "mu_lower")}
        source = f"µ design, loaded from {saved} ({meta.get('source', '')})"
    else:
        d = seat_design.design_mu_controller(rng=np.random.default_rng(0))
        K, stored = d.K, {"omega": d.omega, "mu_upper": d.mu_upper, "mu_lower": d.mu_lower}
        source = f"µ design, run here in {d.seconds:.0f} s"
else:
    design_options = SeatDesignOptions(parametric_complex=True)
    nominal = seat_augmented_plant(SeatDesignOptions(include_delay=False, include_parametric=False,
                                                     include_paper=False))
    res = hinfsyn(nominal.P, nominal.nmeas, nominal.ncon, options=HinfsynOptions(gamma_relax=0.2))
    K = res.K
    source = (f"FALLBACK nominal H∞ (LMI), certified γ = {res.gamma:.3f}, "
              f"LMI lower bound {res.gamma_lower:.3f}")
print(f"controller: {source}; order {K.nstates}; {time.perf_counter() - t0:.1f} s")

# %% [markdown]
# ## µ bounds (Fig. 15)
#
# µ of the closed loop $F_l(P, K)$ with the design's block structure: the delay cover
# (0–25 ms) and the performance block. Robust performance over that set holds where µ < 1.
# The occupant-mass, stiffness and paper norm-bounded channels are **not** in the synthesised
# structure (`DEFAULT_DESIGN` switches them off; the design module says why) and are checked
# by Monte-Carlo simulation instead.
#
# µ is recomputed here from the controller alone, and each bound is then checked by a route
# that does not use `mussv`'s algorithm: the upper bound by its own scalings (at every
# frequency $M^* X_L M + j(GM - M^*G^*) \preceq \mu_u^2 X_R$, an eigenvalue test in numpy),
# the lower bound by its Δ ($\bar\sigma(\Delta) = 1/\mu_l$ and $I - M\Delta$ singular at the
# peak). The paper's claim, robust performance over the covered set, is the certified
# upper bound below 1 (measured 0.854, upper = lower bound). The bounds stored with the
# design in `controller.json` must agree with the recomputed ones (the file and its metadata
# belong together); the simulations below check the delay part of the set directly, with the
# exact delay.

# %%
t0 = time.perf_counter()
cover = seat_augmented_plant(design_options)
omega_mu = stored["omega"] if stored is not None and len(stored["omega"]) else np.logspace(-2, 3.5, 150)
M = lft(cover.P, K)(1j * omega_mu)
mu_res = mussv(M, cover.blk, omega=omega_mu, rng=np.random.default_rng(0))
sigma = np.linalg.norm(np.moveaxis(M, -1, 0), ord=2, axis=(1, 2))
assert np.all(mu_res.upper <= sigma * (1 + 1e-6))       # D = I is one admissible scaling
k = int(np.argmax(mu_res.upper))
print(f"µ upper peak {mu_res.upper[k]:.4f} at {omega_mu[k]:.3g} rad/s, lower peak "
      f"{np.max(mu_res.lower):.4f} ({time.perf_counter() - t0:.1f} s)")
# the upper bound certified by its scalings, frequency by frequency
worst = 0.0
for i in range(len(omega_mu)):
    Mi = M[:, :, i]
    XL = mu_res.D_left[:, :, i].conj().T @ mu_res.D_left[:, :, i]
    XR = mu_res.D_right[:, :, i].conj().T @ mu_res.D_right[:, :, i]
    Gi = mu_res.G[:, :, i]
    H = Mi.conj().T @ XL @ Mi + 1j * (Gi @ Mi - Mi.conj().T @ Gi.conj().T) \
        - (mu_res.upper[i] * (1 + 1e-6)) ** 2 * XR
    worst = max(worst, np.linalg.eigvalsh((H + H.conj().T) / 2).max() / np.linalg.norm(XR, 2))
assert worst <= 1e-9, worst
# the lower bound's Δ destabilises at the peak, and its size is 1/lower
Dk = mu_res.delta[:, :, k]
assert np.isclose(np.linalg.norm(Dk, 2) * mu_res.lower[k], 1.0, rtol=1e-6)
assert np.linalg.svd(np.eye(Dk.shape[1]) - M[:, :, k] @ Dk, compute_uv=False).min() <= 1e-9
assert mu_res.upper[k] < 1.0  # the headline: robust performance over the covered set
if stored is not None:
    print(f"stored by the design: upper peak {np.max(stored['mu_upper']):.4f}, "
          f"lower peak {np.max(stored['mu_lower']):.4f}")
    assert np.isclose(np.max(stored["mu_upper"]), mu_res.upper[k], rtol=1e-2)
display(plot_mu_bounds(np.asarray(omega_mu), np.asarray(mu_res.upper), np.asarray(mu_res.lower),
                       title="Fig. 15: µ bounds (complex cover of the parametric set)"))

# %% [markdown]
# ## Bump responses with the exact delay (Figs. 9–11)
#
# Every µ claim above uses a *cover* of the delay. Here the closed loop is simulated with the
# exact delay $e^{-sd}$ (a shift register on a 0.1 ms grid) and force saturation at
# $u_{\max} = 1500$ N, at $d = 0, 10, 25$ ms, against the passive seat. Two routes to
# stability are compared: the Nyquist test with the exact delay (`closed_loop_stable`) and
# the simulation's divergence test.

# %%
runs = {"passive": simulate(None, road)}
for d in (0.0, 0.010, 0.025):
    runs[f"controlled, d = {1e3 * d:.0f} ms"] = simulate(K, road, delay=d)
rows = []
for label, run in runs.items():
    m = run.metrics()
    nyq = True if label == "passive" else closed_loop_stable(K, run.delay)
    assert nyq == m.stable
    rows.append([label, f"{m.peak_z3dd:.2f}", f"{m.weighted_rms_z3dd:.2f}", f"{1e3 * m.peak_x1:.1f}",
                 f"{m.peak_u:.0f}", f"{m.saturation_time * 1e3:.0f}", nyq])
table(rows, ["run", "peak |z̈3| (m/s²)", "Wk rms (m/s²)", "peak |x1| (mm)", "peak |u| (N)",
             "saturated (ms)", "stable (Nyquist)"])
margin = stability_delay_margin(K)
print(f"delay margin of the linear loop: {1e3 * margin:.1f} ms (needs > 25 ms)")
# the headline: stable at every delay of the design's interval, by the margin and by the
# Nyquist test with the exact delay (another route) just below the margin and at 25 ms
assert margin > 0.025
assert closed_loop_stable(K, 0.025) and closed_loop_stable(K, 0.99 * min(margin, 1.0))

for signal, limit in (("z3dd", None), ("x1", params.z_max), ("u_applied", params.u_max)):
    display(plot_responses(runs, signal, limit=limit, t_max=1.5))

# %% [markdown]
# ## Peak $|\ddot z_3|$ against the delay, and the physical limit
#
# No controller can do better than the **physical limit**: the smallest peak $|\ddot z_3|$
# reachable by *any* force history with $|u| \le u_{\max}$ and $|x_1| \le z_{\max}$, even one
# that knows the whole road in advance (a linear programme, `bump_limit`, re-simulated on a
# fine grid as a certificate). The controlled peaks must stay above it; how close they come
# is the honest measure of the design.

# %%
delays = np.arange(0, 26, 5) * 1e-3
peaks = []
for d in delays:
    run = simulate(K, road, delay=float(d))
    peaks.append(run.metrics().peak_z3dd if run.stable else np.nan)
limit = bump_limit(road)
passive_peak = runs["passive"].metrics().peak_z3dd
print(f"physical limit {limit.peak:.2f} m/s² (re-simulated {limit.certified_peak:.2f}), "
      f"passive {passive_peak:.2f} m/s²")
table([[f"{1e3 * d:.0f}", f"{p:.2f}", f"{p / limit.certified_peak:.2f}"] for d, p in zip(delays, peaks)],
      ["d (ms)", "peak |z̈3| (m/s²)", "÷ physical limit"])
# the LP optimum bounds every admissible force history from below (5 % for its 2 ms grid)
assert all(p >= 0.95 * limit.peak for p in peaks if np.isfinite(p))
# the headline: at every delay up to 25 ms the controlled seat is stable and peaks below
# the passive one
assert all(np.isfinite(p) and p < passive_peak for p in peaks)
display(plot_peak_vs_delay(delays, {"controller": peaks}, limit=limit.peak, passive=passive_peak,
                           title="peak upper-body acceleration on the bump"))
# %% [markdown]
# ## Designed at 1 kHz, or designed and then discretised
#
# The board runs the controller at 1 kHz. The design above is continuous and is sampled
# afterwards (Tustin); the shipped `discrete` route instead runs D-K on the augmented
# plant sampled behind a zero-order hold (the guide "Discrete time" says how),
# so its controller is the one the board runs. Both are simulated here as the board runs
# them: the continuous seat, the controller at 1 kHz, a zero-order hold and the exact delay.
# The discrete design is also checked at every whole-sample delay 0–25 by the spectral
# radius of its sampled loop.

# %%
from lmi_suspension.seat.discrete_design import integer_delay_radii
from lmi_suspension.seat.routes import load_seat_design
from lmi_suspension.seat.sampled import discretise_controller, simulate_sampled

at_1khz = load_seat_design("discrete")
pair = {"designed, then Tustin": discretise_controller(K, 1e-3, warn_unresolved=False),
        "designed at 1 kHz": at_1khz.Kd}
rows = []
for name, Kd in pair.items():
    poles = np.linalg.eigvals(Kd.A)
    fastest = np.max(np.abs(np.log(poles.astype(complex)))) / Kd.dt
    for d in delays:
        s = simulate_sampled(Kd, road, delay=float(d))
        rows.append([name, f"{1e3 * d:.0f}", f"{np.max(np.abs(s.z3dd)) / limit.certified_peak:.2f}",
                     f"{np.max(np.abs(s.u_command)):.0f}", f"{fastest:.0f}",
                     "yes" if s.stable else "NO"])
        assert s.stable
table(rows, ["controller", "d (ms)", "peak ÷ limit", "max |u| command (N)",
             "fastest pole (rad/s)", "stable"])
radii = integer_delay_radii(at_1khz.Kd, np.arange(26))
print(f"designed at 1 kHz: µ {at_1khz.figures['mu_peak_upper']:.4f} on the sampled plant; "
      f"largest spectral radius over the delays of 0-25 samples {radii.max():.6f}")
assert radii.max() < 1

# %%
print(f"notebook run time {time.perf_counter() - T_START:.1f} s")
