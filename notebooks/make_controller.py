"""Regenerate ``controller.json``: the seat µ design that notebooks 03 and 04 load.

Run from this folder: ``python make_controller.py`` (about 10 s). The file holds the
controller and, in its metadata, its µ bounds and how it was made, so the notebooks can
check what they load.
"""

from pathlib import Path

import numpy as np

from lmi_suspension.io import save_controller
from lmi_suspension.seat.design import design_mu_controller

if __name__ == "__main__":
    d = design_mu_controller(rng=np.random.default_rng(0))
    save_controller(Path(__file__).with_name("controller.json"), d.K, metadata={
        "source": "lmi_suspension.seat.design.design_mu_controller(rng=default_rng(0))",
        "seconds": d.seconds, "mu_peak": d.mu_peak, "mu_lower_peak": d.mu_lower_peak,
        "omega": d.omega, "mu_upper": d.mu_upper, "mu_lower": d.mu_lower})
