"""Command line: ``lmi-suspension model | reproduce | simulate``."""

from __future__ import annotations

import argparse
import logging
import sys

__all__ = ["main"]


def _cmd_model(args: argparse.Namespace) -> int:
    from .seat import SeatParameters, natural_modes, seat_model

    params = SeatParameters(m3=args.m3) if args.m3 is not None else SeatParameters()
    G = seat_model(params)
    out = sys.stdout
    out.write("Seat suspension + 3-DOF seated human (paper eq. 1, Table 1)\n")
    out.write(f"  m1 = {params.m1} kg, m2 = m21 + m22 = {params.m21} + {params.m22} = "
              f"{params.m2:.1f} kg, m3 = {params.m3} kg\n")
    out.write(f"  states {G.nstates}, inputs {list(G.input_labels)}, "
              f"outputs {list(G.output_labels)}\n\n")
    out.write(f"  {'mode':>4}  {'f [Hz]':>9}  {'omega_n [rad/s]':>15}  {'zeta':>7}  kind\n")
    for i, (f_hz, wn, zeta) in enumerate(natural_modes(params), start=1):
        kind = "oscillatory" if zeta < 1.0 - 1e-12 else "real pole"
        out.write(f"  {i:>4}  {f_hz:9.3f}  {wn:15.3f}  {zeta:7.4f}  {kind}\n")
    return 0


def build_parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(
        prog="lmi-suspension",
        description="Robust active seat suspension: model, µ-synthesis, simulation.")
    parser.add_argument("-v", "--verbose", action="store_true", help="log progress details")
    sub = parser.add_subparsers(dest="command", required=True)

    p_model = sub.add_parser("model", help="print the seat model's natural frequencies and damping")
    p_model.add_argument("--m3", type=float, default=None,
                         help="occupant upper-body mass in kg (default: Table 1, 43.3)")
    p_model.set_defaults(func=_cmd_model)
    return parser


def main(argv: list[str] | None = None) -> int:
    """Entry point of the ``lmi-suspension`` console script."""
    from .errors import LmiSuspensionError

    parser = build_parser()
    args = parser.parse_args(argv)
    logging.basicConfig(level=logging.INFO if args.verbose else logging.WARNING,
                        format="%(levelname)s %(name)s: %(message)s")
    try:
        return args.func(args)
    except LmiSuspensionError as exc:
        parser.exit(2, f"lmi-suspension: error: {exc}\n")


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
