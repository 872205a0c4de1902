"""Certified γ of LMI and python-control H∞ synthesis on the COMPleib subset, as a markdown table.

Run: ``python benchmarks/compleib_table.py`` (needs ../shared/data beside the checkout).
"""
import json, time, warnings
warnings.simplefilter("ignore")
from lmi_suspension.lti import GeneralizedPlant
from lmi_suspension.synthesis import hinfsyn
d = json.load(open(str(__import__("pathlib").Path(__file__).resolve().parents[2] / "shared" / "data" / "compleib_subset.json")))["problems"]
print("| problem | n | LMI optimum (lower) | LMI certified γ | gap | seconds | Riccati (python-control) reported / certified |")
print("|---|---|---|---|---|---|---|")
for name, p in d.items():
    P = GeneralizedPlant.from_matrices(A=p["A"], B1=p["B1"], B2=p["B"], C1=p["C1"], C2=p["C"], D11=p["D11"], D12=p["D12"], D21=p["D21"])
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
