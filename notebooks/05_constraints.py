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
# # 05 · Hard force and stroke limits, and a constraint of one's own
#
# The paper asks for $|u(t)| \le 1500$ N (eq. 12) and $|x_1(t)| \le 0.08$ m (eq. 13) and
# only approximates them with output weights. Multi-objective LMI synthesis (`msyn`) imposes
# them exactly, for **every** floor velocity with the bump's energy
# $\|w\|_2 \le E$: the generalized-H2 (energy-to-peak) bound of Wilson (1989),
# $\sup_t |z_i(t)| \le E\,\sqrt{(C W_c C^T)_{ii}}$, beside an H∞ objective on the
# upper-body acceleration. Every number below is certified on the closed loop alone
# (`hinfnorm`, the Gramian), not read from the LMI.

# %%
# %matplotlib inline
import time

import numpy as np
import scipy.linalg
from IPython.display import display

from lmi_suspension.report.figures import plot_bounded_response, plot_force_tradeoff
from lmi_suspension.seat import bump, bump_limit, simulate
from lmi_suspension.seat.bounded import design_peak_bounded, seat_peak_plant
from lmi_suspension.seat.roads import road_energy
from lmi_suspension.synthesis import msyn
from lmi_suspension.synthesis.constraints import Channel, HinfBound

E = road_energy(bump())
print(f"energy of the bump's floor velocity: E = {E:.4f} m/s·s^1/2")

# %% [markdown]
# ## The paper's limits as hard constraints
#
# `design_peak_bounded(u_max, z_max)` builds the generalized plant
# $w = [\dot z_0, n_1, n_2] \to z = [\ddot z_3, \rho u, u, x_1]$ with $y = [x_1, x_3] +
# \epsilon n$ and calls `msyn` with the H∞ objective on $[\ddot z_3, \rho u]$ and one
# `PeakBound` on the rows $u, x_1$ driven by the floor velocity.

# %%
t0 = time.perf_counter()
free = design_peak_bounded(np.inf, np.inf)
d = design_peak_bounded(1500.0, 0.08)
print(f"({time.perf_counter() - t0:.1f} s)")
for name, x in (("no bound", free), ("1500 N, 0.08 m", d)):
    print(f"{name:>15}: H∞ {x.hinf:7.2f} (LMI {x.hinf_lmi:7.2f}); worst-case |u| "
          f"{x.u_peak:7.0f} N, |x1| {x.x1_peak:.4f} m")

# %% [markdown]
# The unconstrained optimum needs far more than 1500 N for some road of the bump's energy;
# the bounded design keeps both peaks within the limits for all of them. On the bump
# itself (one such road), the linear closed loop -- no clipping, no delay -- stays inside
# the limits:

# %%
sim = d.simulate()
print(f"bump: largest |u| {np.abs(sim.u_command).max():.0f} N, largest |x1| "
      f"{np.abs(sim.x1).max():.4f} m, peak z3'' {np.abs(sim.z3dd).max():.2f} m/s²")
assert np.abs(sim.u_command).max() <= 1500 and np.abs(sim.x1).max() <= 0.08
display(plot_bounded_response(sim, u_max=1500.0, z_max=0.08,
                              title="peak-bounded H∞ design on the bump (linear, no delay)"))

# %% [markdown]
# ## The price of a force bound
#
# The optimal H∞ level and the bump's peak acceleration against the force bound. The LMI
# level is the one the common Lyapunov matrix guarantees; the certified level is that of
# the returned controller.

# %%
bounds = [300.0, 500.0, 700.0, 1000.0, 1500.0, 2000.0, 3000.0, 6000.0]
designs = [design_peak_bounded(u, 0.08) for u in bounds]
runs = [x.simulate() for x in designs]
passive = np.abs(simulate(None, bump()).z3dd).max()
limit = bump_limit(bump()).peak
for u, x, r in zip(bounds, designs, runs):
    print(f"u_max {u:6.0f} N: H∞ {x.hinf:6.2f} (LMI {x.hinf_lmi:6.2f}), bump peak "
          f"{np.abs(r.z3dd).max():5.2f} m/s², bump |u| {np.abs(r.u_command).max():6.0f} N")
display(plot_force_tradeoff(bounds, [x.hinf for x in designs], [x.hinf_lmi for x in designs],
                            [np.abs(r.z3dd).max() for r in runs],
                            [np.abs(r.u_command).max() for r in runs], hinf_free=free.hinf,
                            passive=passive, limit=limit,
                            title="hard force bound (for every road of the bump's energy)"))

# %% [markdown]
# The bound is conservative twice over: the worst road of energy $E$ is far harsher than
# the bump (its largest force is about half the worst case), and one Lyapunov matrix
# serves all specifications. The bump's peak is not what the H∞ objective minimises (it
# weighs every frequency alike); notebook 03's µ design shapes it with weights.
#
# ## A constraint of one's own
#
# `PeakBound` bounds each output row separately. A researcher who wants the **Euclidean**
# norm of the normalised pair bounded, $\|(u/u_{max},\, x_1/z_{max})(t)\|_2 \le 1$ -- an
# ellipse in the force-stroke plane rather than a box -- writes it against the protocol:
# the synthesis variables come in as affine CVXPY expressions, and the certificate uses the
# closed loop alone ($\sup_t \|z(t)\|_2 = \sqrt{\lambda_{max}(C W_c C^T)}$ for
# $\|w\|_2 \le 1$, Wilson 1989).

# %%
class EllipsePeak:
    """sup_t ‖diag(1/bounds) z(t)‖₂ <= 1 for every ‖w‖₂ <= energy, on a channel."""

    name = "ellipse peak"
    bound = 1.0                # the normalised peak; msyn hands it over as `level`
    lyapunov_scalable = True   # its LMIs hold for alpha P as for P (see the protocol)

    def __init__(self, channel, bounds, energy):
        self.channel, self.weights = channel, energy / np.asarray(bounds, dtype=float)

    def lmis(self, v, level, slack):
        import cvxpy as cp
        B, C = v.B(self.channel), v.C(self.channel)
        Cw = np.diag(self.weights) @ C
        nw, nz = B.shape[1], C.shape[0]
        M1 = cp.bmat([[v.calA + v.calA.T, B], [B.T, -np.eye(nw)]])
        M2 = cp.bmat([[v.calX, Cw.T], [Cw, level**2 * np.eye(nz)]])
        return [(M1 + M1.T) / 2 << -slack * np.eye(M1.shape[0]),
                (M2 + M2.T) / 2 >> slack * np.eye(M2.shape[0])]

    def certify(self, CL):
        rows, cols = list(self.channel.outputs), list(self.channel.inputs)
        A, B = np.asarray(CL.A), np.asarray(CL.B)[:, cols]
        C = np.diag(self.weights) @ np.asarray(CL.C)[rows]
        Wc = scipy.linalg.solve_continuous_lyapunov(A, -B @ B.T)
        return float(np.sqrt(np.linalg.eigvalsh(C @ Wc @ C.T).max()))

# %% [markdown]
# `msyn` works on a balanced copy of the plant whose inputs and outputs are rescaled by
# one common factor; it converts a specification's `bound` into those units and hands it
# to `lmis` as `level`, so the LMIs above are written with `level`, never with the number
# 1 itself. `certify` runs on the user's closed loop, in the user's units, and judges.

# %%
P = seat_peak_plant()
spec = EllipsePeak(Channel(outputs=(2, 3), inputs=(0,)), (1500.0, 0.08), E)
K, CL, gamma, info = msyn(P, 2, 1, HinfBound(Channel(outputs=(0, 1))), [spec])
for c in info.certificates:
    print(f"{c.name:>13}: achieved {c.achieved:.4f}, met {c.met}")
A, B, C = np.asarray(CL.A), np.asarray(CL.B)[:, :1], np.asarray(CL.C)[[2, 3]]
Wc = scipy.linalg.solve_continuous_lyapunov(A, -B @ B.T)
u_pk, x1_pk = np.sqrt(np.diag(C @ Wc @ C.T)) * E
print(f"H∞ {gamma:.2f} (box bounds: {d.hinf:.2f}); worst-case |u| {u_pk:.0f} N, |x1| {x1_pk:.4f} m")
assert info.certificates[1].achieved <= 1.005

# %% [markdown]
# ## Bounds inside µ-synthesis: what the force bound costs the seat
#
# `musyn(..., constraints=[...])` carries such bounds through every K-step of D-K
# iteration; `design_constrained_mu` does it for the seat's delay-robust design, with the
# force and stroke bounds above and the closed-loop poles in a 2000 rad/s disk (a 1 kHz
# controller resolves them). Each design takes minutes, so the trade-off over the force
# bound was measured once by `lmi-suspension tradeoff` and ships with the package; the
# command and date are in the file. The shipped controller is its 9000 N point, and is
# simulated again here as a check on the file.

# %%
from IPython.display import display

from lmi_suspension.report.figures import plot_constrained_tradeoff
from lmi_suspension.seat.constrained import bump_figures, load_constrained, load_tradeoff

points, table = load_tradeoff()
print(f"{table['command']}  ({table['date']}, version {table['version']})")
for p in points:
    print(f"{p.u_bound:6g} N: µ {p.mu_peak:.3f}, bump peak {min(p.bump_peak):.2f}–"
          f"{max(p.bump_peak):.2f} m/s² ({max(p.bump_peak) / table['limit']:.2f} × the "
          f"limit), commanded ≤ {max(p.bump_u):.0f} N")
ref = table["reference"]
display(plot_constrained_tradeoff(
    points, limit=table["limit"],
    reference={f"µ controller (µ {ref['mu_peak']:.3f}), clipped at 1500 N":
               (ref["bump_u"], ref["bump_peak"]),
               "passive seat": ((0.0,), (table["passive"]["bump_peak"],))}))

K_shipped, _Kd, meta = load_constrained()
peak, u_cmd, _x1 = bump_figures(K_shipped, delays=(0.0, 0.025))
same = next(p for p in points if p.u_bound == meta["u_bound"])
print(f"shipped controller re-simulated: {peak[0]:.3f} / {peak[1]:.3f} m/s² at 0 / 25 ms, "
      f"commanded ≤ {max(u_cmd):.0f} N")
assert abs(peak[0] - same.bump_peak[0]) <= 1e-6 * peak[0]
assert abs(peak[1] - same.bump_peak[-1]) <= 1e-6 * peak[1]
