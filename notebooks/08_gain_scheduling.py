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
# # 08 · Gain scheduling: robust, scheduled and frozen-optimal controllers
#
# A mass-spring-damper whose mass $m \in [1, 4]$ is **measured** (a load that is weighed,
# an occupant that sits down): $m\ddot x = -kx - c\dot x + d + u$ with $k = 1$, $c = 0.2$,
# a disturbance force $d$, the control force $u$, the position measured with noise
# $0.1\,n$ and the errors $z = [x,\ 0.1\,u]$ — the textbook example of the
# {doc}`gain-scheduling guide <../guide/lpv>`. The control force acts through $1/m$, so
# the plant's $B_2$ depends on the parameter: the gridded route `lpvsyn`, not the
# polytopic `hinfgs`.
#
# Three controllers, each certified by a computation that did not produce it (the
# closed-loop poles and `hinfnorm` of the loop formed from the returned controller):
#
# - the **frozen-point optimum**: `hinfsyn` at each design value of $m$. No controller
#   scheduled on $m$ can beat it at that $m$, so its curve is a lower bound;
# - the **scheduled** controller $K(m)$ of `lpvsyn`, for $m$ frozen during operation;
# - one **robust** LTI controller for the whole range (full order, tuned by `systune` on
#   the plants at both ends and the middle).

# %%
# %matplotlib inline
import tempfile
import time
from pathlib import Path

import control
import matplotlib.pyplot as plt
import numpy as np
from IPython.display import Markdown, display

from lmi_suspension import hinfnorm, lft
from lmi_suspension.io import load_scheduled_controller, save_scheduled_controller
from lmi_suspension.lpv import lpvsyn
from lmi_suspension.synthesis import hinfsyn
from lmi_suspension.tune import HinfBound, systune, tunable_ss

T0 = time.perf_counter()


def msd(m, k=1.0, c=0.2):
    """Inputs [d, n, u], outputs [x, 0.1 u, y]; y = x + 0.1 n."""
    A = [[0.0, 1.0], [-k / m, -c / m]]
    B = [[0.0, 0.0, 0.0], [1.0 / m, 0.0, 1.0 / m]]
    C = [[1.0, 0.0], [0.0, 0.0], [1.0, 0.0]]
    D = [[0.0, 0.0, 0.0], [0.0, 0.0, 0.1], [0.0, 0.1, 0.0]]
    return control.ss(A, B, C, D)


def certified(m, K):
    """The frozen loop's H∞ norm, after checking its poles (inf if unstable)."""
    loop = lft(msd(m), K)
    if np.max(loop.poles().real) >= 0.0:
        return np.inf
    return float(hinfnorm(loop)[0])


def table(rows):
    """A Markdown table of dicts with equal keys (no pandas dependency)."""
    header = list(rows[0])
    lines = ["| " + " | ".join(header) + " |", "|" + "---|" * len(header)]
    lines += ["| " + " | ".join(str(r[h]) for h in header) + " |" for r in rows]
    display(Markdown("\n".join(lines)))


GRID = np.linspace(1.0, 4.0, 9)      # the design grid
DENSE = np.linspace(1.0, 4.0, 61)    # the plot's grid: 7.5 times denser

# %% [markdown]
# ## The frozen-point optimum: `hinfsyn` at each design value
#
# `gamma_lower` is the LMI optimum at that plant — no controller of any order reaches a
# lower norm there — and `gamma` the certified norm of the controller it returns.

# %%
t = time.perf_counter()
frozen = [hinfsyn(msd(m), 1, 1) for m in GRID]
lower = np.array([r.gamma_lower for r in frozen])
for m, lo, r in zip(GRID, lower, frozen):
    # second route: the loop formed with the returned controller, poles and norm
    assert lo <= certified(m, r.K) <= r.gamma * (1 + 1e-6)
print(f"hinfsyn at {GRID.size} values: {time.perf_counter() - t:.1f} s; "
      f"optimum from {lower.min():.6f} (m = {GRID[lower.argmin()]:g}) "
      f"to {lower.max():.6f} (m = {GRID[lower.argmax()]:g})")

# %% [markdown]
# ## The scheduled controller: `lpvsyn`
#
# $X(m) = X_0 + m X_1 + X_2/m$ and the same for $Y(m)$ (the basis $[1, m, 1/m]$: the
# plant is affine in $1/m$), the projected H∞ LMIs imposed at the 9 design values,
# $\gamma$ minimised in one SDP. `res.gamma` is certified by `hinfnorm` on the 33-point
# check grid; `gamma_frozen(m)` forms $K(m)$ and certifies it at any $m$ in the range,
# between the grid points too.

# %%
t = time.perf_counter()
res = lpvsyn(msd, {"m": GRID}, nmeas=1, ncon=1, basis=lambda m: [1.0, m, 1.0 / m],
             rate={"m": 0.0})
print(f"lpvsyn: {time.perf_counter() - t:.1f} s ({res.seconds_lmi:.1f} s in the SDP), "
      f"γ_lmi = {res.gamma_lmi:.6f}, certified γ = {res.gamma:.6f} on "
      f"{res.check_grid['m'].size} points, warnings: {res.warnings}")
assert res.warnings == ()
scheduled = np.array([res.gamma_frozen(m=m) for m in DENSE])
# gamma_frozen is hinfnorm of the loop; here the poles too, on every sixth value
for m in DENSE[::6]:
    assert certified(m, res.K.at(m=m)) == res.gamma_frozen(m=m)

# %% [markdown]
# ## One robust LTI controller for the whole range
#
# A full-order (2-state) controller tuned by `systune` against the largest of the three
# loops' norms at $m = 1, 2.5, 4$ (a multi-model design: one set of parameters for every
# model). The tuning is local (nonsmooth BFGS from three starts), so its value is an
# upper bound on what one LTI controller can do; the certificate is the norm of the
# returned controller on the dense grid, not only on the three models it was tuned on.

# %%
t = time.perf_counter()
tuned = systune([msd(m) for m in (1.0, 2.5, 4.0)], tunable_ss("K", 2, 1, 1),
                soft=HinfBound(), starts=3, rng=np.random.default_rng(0))
K_robust = tuned.K[0]
robust = np.array([certified(m, K_robust) for m in DENSE])
print(f"systune: {time.perf_counter() - t:.1f} s, tuned on 3 models {tuned.soft:.6f}, "
      f"certified on {DENSE.size} values {robust.max():.6f}")
assert np.all(np.isfinite(robust))

# %% [markdown]
# ## γ against the mass

# %%
fig, ax = plt.subplots(figsize=(7, 3.8))
ax.plot(GRID, lower, "ko-", ms=4, label="frozen optimum (hinfsyn at each m): lower bound")
ax.plot(DENSE, scheduled, "C0-", label="scheduled K(m) (lpvsyn), certified")
ax.plot(DENSE, robust, "C3--", label="one robust LTI controller (systune), certified")
ax.axhline(res.gamma_lmi, color="C0", lw=0.6, ls=":", label="lpvsyn's γ_lmi")
ax.set(xlabel="mass m", ylabel="closed-loop H∞ norm",
       title="Scheduled, robust and frozen-optimal controllers, m ∈ [1, 4]")
ax.legend(fontsize=8)
plt.show()

# %% [markdown]
# The worst values over the range, and what each controller gives away:

# %%
worst_lower = float(lower.max())
rows = [
    {"controller": "frozen optimum (hinfsyn per m)", "worst γ": f"{worst_lower:.6f}",
     "at m": f"{GRID[lower.argmax()]:g}", "above the lower bound": "—"},
    {"controller": "scheduled (lpvsyn)", "worst γ": f"{scheduled.max():.6f}",
     "at m": f"{DENSE[scheduled.argmax()]:g}",
     "above the lower bound": f"{100 * (scheduled.max() / worst_lower - 1):.1f} %"},
    {"controller": "robust LTI (systune)", "worst γ": f"{robust.max():.6f}",
     "at m": f"{DENSE[robust.argmax()]:g}",
     "above the lower bound": f"{100 * (robust.max() / worst_lower - 1):.1f} %"},
]
table(rows)
# a theorem: no controller beats the frozen optimum at any design value (1e-6: hinfnorm's
# and the LMI's tolerances)
on_grid = np.array([res.gamma_frozen(m=m) for m in GRID])
robust_on_grid = np.array([certified(m, K_robust) for m in GRID])
assert np.all(lower <= on_grid * (1 + 1e-6)) and np.all(lower <= robust_on_grid * (1 + 1e-6))
# not a theorem (the robust controller is tuned locally, the scheduled one carries a 2 %
# back-off), but what the example shows: measured 2026-12-02 0.240246 < 0.246567 < 0.276138
assert worst_lower <= scheduled.max() < robust.max()
for m in (1.0, 2.5, 4.0):
    i = int(np.argmin(np.abs(DENSE - m)))
    print(f"m = {m:g}: scheduled {scheduled[i]:.6f}, robust {robust[i]:.6f}")

# %% [markdown]
# The scheduled controller stays within 5 % of the frozen optimum at every mass (2.6 % at
# its worst point, against the worst frozen optimum); the robust controller's norm is the
# same at every mass (to 12 digits, measured 2026-12-02): its worst channel is one the
# mass does not move, and it pays 15 % over the lower bound everywhere. Tuned locally,
# from three starts: other starts stopped at 0.282 and 0.307, so 0.276 is what one LTI
# controller was found to reach, not what none can beat. The worst-case figures alone
# understate the difference: the scheduled controller's advantage is the whole curve.

# %% [markdown]
# ## Saving, loading and a 1 kHz realization
#
# `save_scheduled_controller` writes the Lyapunov coefficients, the scalings and the
# plant and basis as tables on the check grid, every float as its shortest round-tripping
# repr: the loaded controller's `at(m)` equals the original's bit for bit at every table
# node. `at_discrete` is the Tustin realization at one value (a `NyquistError` if a
# controller pole lay above the Nyquist rate).

# %%
with tempfile.TemporaryDirectory() as tmp:
    path = save_scheduled_controller(Path(tmp) / "K.json", res)
    K_loaded, meta = load_scheduled_controller(path)
    print(f"{path.name}: {path.stat().st_size / 1024:.0f} kB, metadata keys {sorted(meta)}")
node = float(res.check_grid["m"][13])          # a table node between two design values
a, b = res.K.at(m=node), K_loaded.at(m=node)
assert all(np.array_equal(getattr(a, x), getattr(b, x)) for x in "ABCD")
print(f"at m = {node:g}: the loaded controller equals the original bit for bit")

Kd = res.K.at_discrete(dt=1e-3, m=2.2)
Kc = res.K.at(m=2.2)
w = np.logspace(-2, 2, 50)
gap = np.max(np.abs(Kd.frequency_response(w).complex - Kc.frequency_response(w).complex)
             / np.abs(Kc.frequency_response(w).complex))
print(f"K(2.2) at 1 kHz: poles |z| ≤ {np.abs(Kd.poles()).max():.6f}, fastest continuous "
      f"pole {np.abs(Kc.poles()).max():.0f} rad/s; response within {gap:.1e} (relative) "
      "of the continuous one up to 100 rad/s")
assert np.abs(Kd.poles()).max() < 1.0 and gap < 1e-2
print(f"notebook: {time.perf_counter() - T0:.0f} s")
