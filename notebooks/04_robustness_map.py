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
# # 04 · A robustness map: occupant mass × actuator delay, on Dask
#
# The paper designs for one occupant (m3 = 43.3 kg) and delays up to 25 ms. A seat carries
# anyone from 30 to 70 kg, and an actuator's delay may grow with wear. Here the saved µ
# controller (`controller.json`, the design of notebook 03) runs on the paper's bump for a
# grid of upper-body masses and delays, each case simulated with the exact delay and the
# 1500 N saturation, its linear loop tested by the Nyquist criterion with $e^{-sd}$, and its
# peak compared with **that occupant's own physical limit** (the clairvoyant LP of
# `bump_limit`: no controller can do better).
#
# `run_sweep` runs the cases on a local Dask cluster (two worker processes here), writes one
# Parquet table, and can resume; `lmi-suspension sweep` does the same from the shell:
#
# ```
# lmi-suspension sweep --controller notebooks/controller.json --m3 30:70:9 --delay 0:0.3:13 --out map
# ```

# %%
# %matplotlib inline
import tempfile
import time
from pathlib import Path

import numpy as np
from IPython.display import Image, display

from lmi_suspension.sweep import SweepSpec, parse_range, plot_map, read_results, run_sweep
from lmi_suspension.io import load_controller
from lmi_suspension.seat import SeatParameters, stability_delay_margin

T_START = time.perf_counter()
ctrl = Path("controller.json").resolve()
spec = SweepSpec(controllers=(str(ctrl),),
                 grid=(("m3", parse_range("30:70:9", "m3")),
                       ("delay", parse_range("0:0.3:13", "delay"))))
out = Path(tempfile.mkdtemp()) / "map"
res = run_sweep(spec, out, workers=2)
print(f"{res.n_cases} cases in {res.wall_seconds:.1f} s on {res.workers} workers "
      f"({res.throughput:.1f} cases/s), {res.n_failed} failed")

# %% [markdown]
# The map: colour is the peak upper-body acceleration over the occupant's physical limit
# (1 would be the best any force history could do); hatched cells are unstable. The boundary
# should sit at the controller's delay margin, computed independently below from the loop
# transfer (`stability_delay_margin`). Above the margin stability can come back: a delay
# system's roots cross the imaginary axis back and forth as the delay grows (for the 30 kg
# occupant the loop is unstable at 75 and 100 ms and stable again at 125 ms), which is why
# the map tests each case rather than the margin alone.

# %%
table, _ = read_results(out)
rows = table.to_pylist()
fig = plot_map(table, spec, str(ctrl))
K, _ = load_controller(ctrl)
margins = {m: stability_delay_margin(K, params=SeatParameters(m3=m)) for m in (30.0, 50.0, 70.0)}
for m, dm in margins.items():
    fig.axes[0].plot([m], [1e3 * dm], "w*", ms=12)
    # every delay below the margin is stable in the map; the first unstable one is above it
    column = [r for r in rows if r["m3"] == m]
    assert all(r["stable"] for r in column if r["delay"] < dm), m
    assert min(r["delay"] for r in column if not r["stable"]) >= dm, m
display(fig)
print("delay margins (white stars):", {m: f"{1e3 * d:.0f} ms" for m, d in margins.items()})

# %%
stable = [r for r in rows if r["stable"]]
worst = max(stable, key=lambda r: r["limit_ratio"])
best = min(stable, key=lambda r: r["limit_ratio"])
print(f"stable cases {len(stable)}/{len(rows)}; limit ratio from {best['limit_ratio']:.2f} "
      f"(m3 {best['m3']:.0f} kg, {1e3 * best['delay']:.0f} ms) to {worst['limit_ratio']:.2f} "
      f"(m3 {worst['m3']:.0f} kg, {1e3 * worst['delay']:.0f} ms)")
assert all(r["limit_ratio"] >= 0.95 for r in stable)  # no controller beats the LP (2 ms grid)
display(Image(filename=str(out / "tradeoff.png")))
print(f"notebook run time {time.perf_counter() - T_START:.1f} s")
