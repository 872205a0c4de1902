"""Certified γ of LMI and python-control H∞ synthesis on the COMPleib subset, as a markdown table.

Run: ``python benchmarks/compleib_table.py`` (the plants ship with the package:
``lmi_suspension/data/compleib_subset.json``, read by ``lmi_suspension.examples.compleib``).
"""
import time, warnings
warnings.simplefilter("ignore")
from lmi_suspension.examples import COMPLEIB_PROBLEMS, compleib
from lmi_suspension.synthesis import hinfsyn
print("| problem | n | LMI optimum (lower) | LMI certified γ | gap | seconds | Riccati (python-control) reported / certified |")
print("|---|---|---|---|---|---|---|")
for name in COMPLEIB_PROBLEMS:
    P = compleib(name)
    t = time.time()
    try:
        r = hinfsyn(P, P.ny, P.nu); dt = time.time() - t
        lo = r.gamma_lower; gap = f"{100*(r.gamma/lo-1):.2f} %" if lo and lo > 1e-6 else "—"
        lmi = f"{lo:.5g} | {r.gamma:.5g} | {gap} | {dt:.2f}"
    except Exception as e:
        lmi = f"— | error: {type(e).__name__} | — | —"
    try:
        q = hinfsyn(P, P.ny, P.nu, method="riccati"); ric = f"{q.gamma_solver:.5g} / {q.gamma:.5g}"
    except Exception as e:
        ric = f"{type(e).__name__}"
    print(f"| {name} | {P.nstates} | {lmi} | {ric} |", flush=True)
