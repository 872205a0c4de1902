"""Command line: ``lmi-suspension model | reproduce | simulate | sweep | design |
design-constrained | refine | occupants | tradeoff | export``."""

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


class _StageBar:
    """``reproduce``'s progress as a bar over its stages: a message that does not start
    with a space opens the next stage, an indented one (a D-K iteration's µ bound, a
    limit, a margin) is shown beside the bar."""

    def __init__(self, stages):
        from tqdm import tqdm

        self._bar = tqdm(total=len(stages), unit="stage", file=sys.stderr,
                         dynamic_ncols=True, bar_format="{desc} {bar} {n_fmt}/{total_fmt} "
                         "stages [{elapsed}<{remaining}] {postfix}")
        self._started = 0

    def __call__(self, message: str) -> None:
        if message.startswith("done in"):
            return
        if not message.startswith(" "):
            if self._started:
                self._bar.update(1)
            self._started += 1
            self._bar.set_description_str(message.rstrip(". "))
            self._bar.set_postfix_str("")
        else:
            self._bar.set_postfix_str(" ".join(message.split()), refresh=True)

    def close(self) -> None:
        if self._started:
            self._bar.update(self._bar.total - self._bar.n)
        self._bar.close()


def _cmd_reproduce(args: argparse.Namespace) -> int:
    import numpy as np

    from .report.reproduce import STAGES, comparison_table, reproduce

    bar = None if args.quiet or not sys.stderr.isatty() else _StageBar(STAGES)
    try:
        summary = reproduce(args.out, progress=bar, rng=np.random.default_rng(args.seed),
                            quick=args.quick)
    finally:
        if bar is not None:
            bar.close()
    sys.stdout.write(comparison_table(summary) + "\n")
    figures = sum(1 for f in summary.files if f.suffix == ".png")
    sys.stdout.write(f"{figures} figures, summary.json and controllers/ in {summary.out_dir} "
                     f"({summary.seconds:.0f} s)\n")
    return 0


_ROADS = ("bump", "noise", "iso-C")


def _road(name: str, seed: int, duration: float | None):
    import numpy as np

    from .report.reproduce import _NOISE_BAND_HZ, _NOISE_PSD
    from .seat import bump, iso8608_road, white_noise

    rng = np.random.default_rng(seed)
    if name == "bump":
        return bump(t_end=3.0 if duration is None else duration)
    duration = 5.0 if duration is None else duration
    if name == "noise":
        return white_noise(duration, 1e-3, psd=_NOISE_PSD, bandwidth_hz=_NOISE_BAND_HZ, rng=rng)
    return iso8608_road("C", 30.0, duration, 1e-3, rng=rng)


def _cmd_simulate(args: argparse.Namespace) -> int:
    import dataclasses
    import json
    import math
    from pathlib import Path

    from .errors import InputError, ParameterError
    from .io import load_controller
    from .seat import closed_loop_stable, simulate
    from .seat.schedule_use import controller_for_seat, schedule_point

    path = Path(args.controller)
    if not path.is_file():
        raise InputError(f"controller file {path} not found")
    if not math.isfinite(args.delay) or args.delay < 0:
        raise ParameterError(f"--delay must be a finite number of seconds >= 0, got {args.delay}")
    if args.duration is not None and not (math.isfinite(args.duration) and args.duration > 0):
        raise ParameterError(f"--duration must be a positive number of seconds, "
                             f"got {args.duration}")
    try:
        K, _metadata = load_controller(path)
    except (KeyError, TypeError, IndexError) as exc:
        raise InputError(f"{path} is not a saved controller ({type(exc).__name__}: {exc})") \
            from exc
    Ks = K
    road = _road(args.road, args.seed, args.duration)
    seat, scheduled_on = _simulated_seat(args, K)
    K = controller_for_seat(K, seat, scheduled_on)
    if scheduled_on is not None:
        scheduled_on = schedule_point(Ks, seat, scheduled_on)
    if args.discrete:
        if scheduled_on is not None:
            raise InputError(f"--discrete: {path} holds a scheduled controller, which has no "
                             f"discrete realization in the file; run it continuous")
        import numpy as np

        from .io import load_discrete_controller
        from .seat.sampled import simulate_sampled

        Kd, _ = load_discrete_controller(path)
        noise = None
        if args.noise is not None:
            noise = tuple(float(v) for v in args.noise.split(","))
            if len(noise) != 2:
                raise ParameterError(f"--noise takes two standard deviations (m), x1,x3; "
                                     f"got {args.noise!r}")
        res = simulate_sampled(Kd, road, delay=args.delay, params=seat, noise=noise,
                               quantisation=args.quantisation,
                               rng=np.random.default_rng(args.seed))
        realization = f"discrete, {1 / Kd.dt:g} Hz, zero-order hold"
    else:
        if args.noise is not None or args.quantisation is not None:
            raise ParameterError("--noise and --quantisation apply to --discrete runs")
        res = simulate(K, road, delay=args.delay, params=seat)
        realization = "continuous"
    m = res.metrics()
    linear = closed_loop_stable(K, args.delay, seat)
    if args.plot:
        from .report.figures import plot_responses

        fig = plot_responses({f"{path.name}, d = {args.delay * 1e3:g} ms": res}, "z3dd",
                             title=road.description)
        fig.savefig(args.plot, dpi=110)
    if args.json:
        data = {"controller": str(path), "realization": realization,
                "road": road.description, "delay": args.delay, "m3": seat.m3, "k1": seat.k1,
                "scheduled_on": scheduled_on,
                "seed": args.seed, "stable_linear": linear, **dataclasses.asdict(m)}
        data = {k: (None if isinstance(v, float) and not math.isfinite(v) else v)
                for k, v in data.items()}
        sys.stdout.write(json.dumps(data, indent=1) + "\n")
        return 0
    out = sys.stdout
    out.write(f"controller {path} ({K.nstates} states, {realization}), road: "
              f"{road.description}, delay {args.delay * 1e3:g} ms\n")
    out.write(f"seat: m3 {seat.m3:g} kg, k1 {seat.k1:g} N/m"
              + ("" if scheduled_on is None else "; scheduled on the estimate "
                 + ", ".join(f"{n} = {v:g}" for n, v in scheduled_on.items())
                 + " (true value plus the estimate error, held in the schedule's range)")
              + "\n")
    rows = [("peak |z3''|", m.peak_z3dd, "m/s^2"), ("RMS z3''", m.rms_z3dd, "m/s^2"),
            ("Wk-weighted RMS z3''", m.weighted_rms_z3dd, "m/s^2"),
            ("VDV", m.vdv_z3dd, "m/s^1.75"), ("peak |x1|", m.peak_x1, "m"),
            ("peak |u| commanded", m.peak_u_command, "N"),
            ("peak |u| applied", m.peak_u, "N"), ("time in saturation", m.saturation_time, "s")]
    for label, value, unit in rows:
        out.write(f"  {label:<22} {value:12.5g} {unit}\n")
    out.write(f"  {'|x1| within z_max':<22} {'yes' if m.x1_within_limit else 'NO':>12} "
              f"(z_max = {m.z_max} m)\n")
    out.write(f"  {'stable (simulation)':<22} {'yes' if m.stable else 'NO':>12}\n")
    out.write(f"  {'stable (Nyquist)':<22} {'yes' if linear else 'NO':>12}\n")
    return 0


def _simulated_seat(args: argparse.Namespace, K) -> tuple:
    """The seat ``simulate`` runs (Table 1 with ``--m3``, ``--k1``) and, for a scheduled
    controller, the estimate errors it is scheduled with (None for one controller)."""
    import dataclasses
    import math

    from .errors import ParameterError
    from .seat import SeatParameters
    from .seat.schedule_use import is_scheduled

    seat = SeatParameters()
    for name in ("m3", "k1"):
        v = getattr(args, name)
        if v is not None:
            if not (math.isfinite(v) and v > 0):
                raise ParameterError(f"--{name} must be a positive number, got {v}")
            seat = dataclasses.replace(seat, **{name: float(v)})
    errors = {n: getattr(args, f"{n}_error") for n in ("m3", "k1")
              if getattr(args, f"{n}_error") is not None}
    for n, e in errors.items():
        if not math.isfinite(e):
            raise ParameterError(f"--{n}-error must be a finite number, got {e}")
    if not is_scheduled(K):
        if errors:
            raise ParameterError(f"--{next(iter(errors))}-error: the controller is not "
                                 f"scheduled; it measures nothing")
        return seat, None
    unused = [n for n in errors if n not in K.names]
    if unused:
        raise ParameterError(f"--{unused[0]}-error: the schedule is on {', '.join(K.names)}, "
                             f"not {unused[0]}")
    return seat, errors


def _write_certificate(c, out=None) -> None:
    """A seat certificate (:func:`~lmi_suspension.seat.record.certify_seat`) as text: the
    bump per delay first, then µ, poles, the delay margin and the requirements."""
    out = sys.stdout if out is None else out
    out.write(f"{'delay [ms]':>10} {'z3dd peak':>10} {'/limit':>7} {'u cmd [N]':>10} "
              f"{'x1 [m]':>8} {'1 kHz peak':>10}\n")
    for k, dl in enumerate(c.delays):
        out.write(f"{dl * 1e3:10g} {c.peak[k]:10.3f} {c.peak[k] / c.limit:7.3f} "
                  f"{c.u_peak[k]:10.0f} {c.x1_peak[k]:8.4f} {c.sampled_peak[k]:10.3f}\n")
    out.write(f"µ upper {c.mu.mu_peak:.4f}, lower {c.mu.mu_lower_peak:.4f}; worst case for "
              f"the bump's energy: |u| {c.mu.u_peak:.0f} N, |x1| {c.mu.x1_peak:.4f} m; "
              f"fastest pole {c.loop_radius:.0f} rad/s (controller "
              f"{c.mu.controller_fastest_pole:.0f}); delay margin "
              f"{c.delay_margin * 1e3:.0f} ms\n")
    failures = c.failures()
    out.write("requirements (issue 38's targets): " + ("all met" if not failures else
              "not met: " + "; ".join(failures)) + "\n")


def _run_route(route, out, *, seed: int = 0) -> int:
    """Design along ``route``, write the file, certify it and print the certificate.
    Exit status 1 where the route says its own requirements were not met."""
    from pathlib import Path

    import numpy as np

    from .seat.routes import design_seat, save_seat_design

    d = design_seat(route, rng=np.random.default_rng(seed),
                    progress=lambda line: sys.stderr.write(line + "\n"))
    path = save_seat_design(Path(out), d)
    _write_certificate(d.certify())
    met = d.figures.get("met", True)
    sys.stdout.write(f"{d.description}; route's requirements met: {met}; "
                     f"{d.seconds:.0f} s; written to {path}\n")
    return 0 if met else 1


def _cmd_design(args: argparse.Namespace) -> int:
    from .seat.routes import route_named

    return _run_route(route_named(args.route), args.out, seed=args.seed)


def _cmd_design_constrained(args: argparse.Namespace) -> int:
    from .seat.constrained import SHIPPED_CONTROLLER, ConstrainedRoute

    route = ConstrainedRoute(u_bound=args.u_bound, z_bound=args.z_bound,
                             disk_radius=args.disk_radius)
    return _run_route(route, args.out or SHIPPED_CONTROLLER)


def _cmd_refine(args: argparse.Namespace) -> int:
    from .errors import ParameterError
    from .seat.refine import SHIPPED_REFINED, RefineOptions, RefineRoute

    if args.no_set_mu and not args.occupants:
        raise ParameterError("refine --no-set-mu: the set's µ is a requirement only with "
                             "--occupants")
    if args.occupants and not args.out:
        raise ParameterError("refine --occupants: give --out (the shipped file is the "
                             "single-seat design's)")
    start = None
    if args.controller:
        from .io import load_controller

        start, _ = load_controller(args.controller)
    if args.occupants:
        from .seat.multimodel import OccupantRoute
        from .seat.occupants import OccupantSet

        occupants = OccupantSet()
        opts = RefineOptions(u_bound=args.u_bound, z_bound=args.z_bound,
                             disk_radius=args.disk_radius, max_iter=args.max_iter,
                             mu_performance=False,
                             occupants=None if args.no_set_mu else occupants)
        route = OccupantRoute(occupants=occupants, options=opts, start=start,
                              rounds=args.rounds)
        status = _run_route(route, args.out, seed=args.seed)
        sys.stdout.write(f"certify it over the set with: lmi-suspension occupants "
                         f"{args.out}\n")
        return status
    opts = RefineOptions(u_bound=args.u_bound, z_bound=args.z_bound,
                         disk_radius=args.disk_radius, max_iter=args.max_iter)
    return _run_route(RefineRoute(options=opts, start=start), args.out or SHIPPED_REFINED)


def _cmd_occupants(args: argparse.Namespace) -> int:
    """Certify controllers over the set of occupants, springs, dampers and delays."""
    import json
    import math
    from pathlib import Path

    import numpy as np

    from .errors import ParameterError
    from .io import load_controller
    from .report.figures import plot_occupants
    from .seat.occupants import occupant_samples
    from .seat.record import certify_seat

    controllers = {Path(c).stem: load_controller(c)[0] for c in args.controllers}
    if len(controllers) != len(args.controllers):
        raise ParameterError("two controllers share a file name; rename one")
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    log = sys.stderr if not args.quiet else None
    say = (lambda line: log.write(line + "\n")) if log is not None else None
    S = occupant_samples(rng=np.random.default_rng(args.seed), n_stability=args.stability,
                         n_performance=args.performance, progress=say)
    rows = {}
    sys.stdout.write(f"{'controller':>14} {'unstable':>12} {'worst/limit':>11} "
                     f"{'nominal':>8} {'|u| [N]':>8} {'|x1| [m]':>9} {'poles [rad/s]':>13}"
                     f"{'  RS µ (lower)   RP µ (lower)' if args.mu else ''}\n")
    verdicts = []
    for name, K in controllers.items():
        # the one certificate of a seat controller, with the set's samples and without
        # the bump at the nominal seat (its own command, reproduce, does that)
        cert = certify_seat(K, delays=(), occupants=S, mixed_mu=args.mu,
                            rng=np.random.default_rng(args.seed), progress=say)
        c = cert.occupants
        row = dict(unstable=c.unstable, n_stability=c.n_stability,
                   worst_ratio=c.worst_ratio, worst_delay=c.worst_delay,
                   worst_sample={k: getattr(c.worst_sample, k) for k in
                                 ("m3", "k1", "k2", "k3", "c1", "c2", "c3")},
                   nominal_ratio=c.nominal_ratio, u_max=c.u_max, x1_max=c.x1_max,
                   controller_radius=c.controller_radius, loop_radius=c.loop_radius,
                   n_performance=len(S.performance), delays=list(c.delays),
                   confirmed=[list(x) for x in c.confirmed])
        line = (f"{name:>14} {c.unstable:>5}/{c.n_stability:<6} {c.worst_ratio:11.3f} "
                f"{c.nominal_ratio:8.3f} {c.u_max:8.0f} {c.x1_max:9.4f} "
                f"{max(c.controller_radius, c.loop_radius):13.0f}")
        if args.mu:
            m = cert.mixed_mu
            row.update(rs_upper=m.rs_upper, rs_lower=m.rs_lower, rs_sup=m.rs_sup,
                       rp_upper=m.rp_upper, rp_lower=m.rp_lower, rp_sup=m.rp_sup,
                       rs_worst_omega=m.rs_worst_omega,
                       rs_worst=None if m.rs_worst is None else
                       {k: getattr(m.rs_worst, k) for k in
                        ("m3", "k1", "k2", "k3", "c1", "c2", "c3")})
            line += (f"  {m.rs_sup:6.3f} ({m.rs_lower:5.3f})  {m.rp_sup:6.3f} "
                     f"({m.rp_lower:5.3f})")
        sys.stdout.write(line + "\n")
        for w in cert.worst_seats:
            row[f"searched_{w.figure}"] = w.as_dict()        # value null: unstable
            sys.stdout.write(f"{'':>14} searched {w.label.split()[-1]}: {w.describe()}\n")
        failures = cert.failures()
        row["requirements_not_met"] = list(failures)
        verdicts.append(f"{name}: " + ("all met" if not failures else "; ".join(failures)))
        fig = plot_occupants(c, S, title=f"{name}: {len(S.performance)} seats × "
                                         f"{len(c.delays)} delays")
        fig.savefig(out / f"occupants_{name}.png", dpi=110)
        rows[name] = {k: (None if isinstance(v, float) and not math.isfinite(v) else v)
                      for k, v in row.items()}   # strict JSON: null for an unstable loop
    (out / "occupants.json").write_text(json.dumps(
        dict(seed=args.seed, n_stability=args.stability, n_performance=args.performance,
             nominal_limit=S.nominal_limit, controllers=rows), indent=1, default=float))
    sys.stdout.write("requirements (issue 38's targets, over the set):\n  "
                     + "\n  ".join(verdicts) + "\n")
    sys.stdout.write(f"written: {out / 'occupants.json'} and occupants_<controller>.png\n")
    return 0


def _cmd_tradeoff(args: argparse.Namespace) -> int:
    import json
    from datetime import date
    from pathlib import Path

    from . import __version__
    from .errors import ParameterError
    from .report.figures import plot_constrained_tradeoff
    from .seat.constrained import bump_figures, constrained_tradeoff, save_constrained
    from .seat.design import design_mu_controller
    from .seat.limit import bump_limit
    from .seat.params import SeatParameters
    from .seat.roads import bump

    try:
        bounds = [float(x) for x in args.u_bounds.split(",") if x.strip()]
    except ValueError as exc:
        raise ParameterError(f"--u-bounds: expected numbers separated by commas, got "
                             f"{args.u_bounds!r}") from exc
    out = Path(args.out)
    (out / "controllers").mkdir(parents=True, exist_ok=True)
    bar = _progress_bar(args, len(bounds), "designs")
    finished = []

    def done(point):
        save_constrained(out / "controllers" / f"mu_constrained_{point.u_bound:g}N.json",
                         point.design)
        finished.append(point)
        if bar is not None:
            bar.update(len(finished))
        sys.stderr.write(f"{point.u_bound:g} N: µ {point.mu_peak:.4f}, bump peak "
                         f"{min(point.bump_peak):.2f}–{max(point.bump_peak):.2f} m/s², "
                         f"commanded ≤ {max(point.bump_u):.0f} N ({point.seconds:.0f} s)\n")

    try:
        points = constrained_tradeoff(bounds, z_bound=args.z_bound,
                                      disk_radius=args.disk_radius or None, progress=done)
    finally:
        if bar is not None:
            bar.close()
    limit = bump_limit(bump()).peak
    mu = design_mu_controller()
    ref_peak, ref_u, _x1 = bump_figures(mu.K)
    passive_peak, passive_u, _x1 = bump_figures(None, delays=(0.0,))
    u_max = SeatParameters().u_max
    fig = plot_constrained_tradeoff(
        points, limit=limit, u_actuator=u_max, reference={
            f"µ controller (µ {mu.mu_peak:.3f}), clipped at {u_max:g} N": (ref_u, ref_peak),
            "passive seat": (passive_u, passive_peak)},
        title="constrained µ-synthesis: force bound against bump peak")
    fig.savefig(out / "tradeoff.png", dpi=130)
    table = {"command": (f"lmi-suspension tradeoff --u-bounds {args.u_bounds} --z-bound "
                         f"{args.z_bound:g} --disk-radius {args.disk_radius:g}"),
             "date": date.today().isoformat(), "version": __version__,
             "limit": limit, "z_bound": args.z_bound, "disk_radius": args.disk_radius,
             "points": [p.as_dict() for p in points],
             "reference": {"mu_peak": mu.mu_peak, "bump_peak": ref_peak, "bump_u": ref_u},
             "passive": {"bump_peak": passive_peak[0]}}
    (out / "tradeoff.json").write_text(json.dumps(table, indent=1))
    for p in points:
        sys.stdout.write(f"{p.u_bound:8g} N  µ {p.mu_peak:.4f}  worst case {p.u_peak:6.0f} N  "
                         f"bump peak {max(p.bump_peak):6.2f} m/s² ({max(p.bump_peak) / limit:.2f}"
                         f" × limit)  commanded {max(p.bump_u):5.0f} N\n")
    sys.stdout.write(f"written to {out / 'tradeoff.json'} and {out / 'tradeoff.png'}\n")
    return 0


def _cmd_export(args: argparse.Namespace) -> int:
    from pathlib import Path

    from .errors import InputError
    from .io import load_controller, save_controller, save_controller_mat

    src = Path(args.controller)
    if not src.is_file():
        raise InputError(f"controller file {src} not found")
    try:
        K, metadata = load_controller(src)
    except (KeyError, TypeError, IndexError) as exc:
        raise InputError(f"{src} is not a saved controller ({type(exc).__name__}: {exc})") \
            from exc
    out = Path(args.out)
    if args.format == "mat":
        save_controller_mat(out, K, ts=args.ts, metadata=metadata)
    else:
        if args.ts is not None:
            raise InputError("--ts: a JSON controller is continuous-time; use --format mat")
        save_controller(out, K, metadata=metadata)
    sys.stdout.write(f"wrote {out} ({K.nstates} states, inputs {list(K.input_labels)}, "
                     f"outputs {list(K.output_labels)}"
                     + (f", discretised at Ts = {args.ts} s" if args.ts else "") + ")\n")
    return 0


def _cmd_sweep(args: argparse.Namespace) -> int:
    from .errors import ParameterError
    from .sweep import SweepSpec, run_sweep
    from .sweep.spec import parse_range

    axes = [("m3", args.m3), ("delay", args.delay), ("m3_error", args.m3_error)]
    for item in args.param or ():
        name, sep, value = item.partition("=")
        if not sep or not name:
            raise ParameterError(f"--param: expected NAME=RANGE, got {item!r}")
        axes.append((name.strip(), value.strip()))
    axes = [(n, v) for n, v in axes if v is not None]
    if args.spec is not None:
        if axes or args.controller or args.samples or args.sampling:
            raise ParameterError("--spec: give the axes, controllers, samples and sampling "
                                 "in the spec file, not also as flags")
        spec = SweepSpec.from_toml(args.spec)
    else:
        controllers = tuple(args.controller or ("passive",))
        sampling = args.sampling or "uniform"
        if args.samples:
            ranges = []
            for name, value in axes:
                lo, sep, hi = value.partition(":")
                if not sep or ":" in hi:
                    raise ParameterError(f"{name}: with --samples give a range lo:hi, "
                                         f"got {value!r}")
                ranges.append((name, *parse_range([lo, hi], name)))
            spec = SweepSpec(controllers=controllers, samples=args.samples,
                             ranges=tuple(ranges), road=args.road, duration=args.duration,
                             seed=args.seed, limit=not args.no_limit, sampling=sampling)
        else:
            grid = tuple((n, parse_range(v, n)) for n, v in axes)
            spec = SweepSpec(controllers=controllers, grid=grid, road=args.road,
                             duration=args.duration, seed=args.seed, limit=not args.no_limit,
                             sampling=sampling)
    bar = _progress_bar(args, spec.n_cases, "cases")
    try:
        res = run_sweep(spec, args.out, scheduler=args.scheduler, workers=args.workers,
                        progress=bar.update if bar is not None else None)
    finally:
        if bar is not None:
            bar.close()
    out = sys.stdout
    out.write(f"{res.n_cases} cases ({res.n_run} run now, {res.n_skipped} found finished, "
              f"{res.n_failed} with an error) in {res.wall_seconds:.1f} s on "
              f"{res.workers} worker(s): {res.throughput:.2f} cases/s\n")
    out.write(f"  table   {res.table}\n")
    for fig in res.figures:
        out.write(f"  figure  {fig}\n")
    return 0 if res.n_failed == 0 else 1


class _Bar:
    """A tqdm bar fed with cumulative counts (what the library's callbacks report)."""

    def __init__(self, total: int, unit: str):
        from tqdm import tqdm

        self._bar = tqdm(total=total, unit=unit, file=sys.stderr, dynamic_ncols=True)
        self._seen = 0

    def update(self, done: int, total: int | None = None) -> None:
        if total is not None and total != self._bar.total:
            self._bar.total = total
            self._bar.refresh()
        self._bar.update(done - self._seen)
        self._seen = done

    def close(self) -> None:
        self._bar.close()


def _progress_bar(args: argparse.Namespace, total: int, unit: str):
    """A progress bar on a terminal; None under --quiet or when stderr is not one."""
    if getattr(args, "quiet", False) or not sys.stderr.isatty():
        return None
    return _Bar(total, unit)


class _Parser(argparse.ArgumentParser):
    """Usage errors as one line (exit code 2), like every other error of the CLI."""

    def error(self, message):
        self.exit(2, f"{self.prog}: error: {message}\n")


def build_parser() -> argparse.ArgumentParser:
    parser = _Parser(
        prog="lmi-suspension",
        description="Robust active seat suspension: model, µ-synthesis, simulation.")
    parser.add_argument("-v", "--verbose", action="store_true", help="log progress details")
    sub = parser.add_subparsers(dest="command", required=True)

    p_model = sub.add_parser("model", help="print the seat model's natural frequencies and damping")
    p_model.add_argument("--m3", type=float, default=None,
                         help="occupant upper-body mass in kg (default: Table 1, 43.3)")
    p_model.set_defaults(func=_cmd_model)

    p_rep = sub.add_parser("reproduce", help="run the paper's study: µ design, comparison, "
                           "simulations, figures, summary.json, controller.json")
    p_rep.add_argument("--out", default="reproduce_out", help="output directory "
                       "(default: ./reproduce_out)")
    p_rep.add_argument("--quick", action="store_true",
                       help="short runs and two delays (a smoke test, rough figures)")
    p_rep.add_argument("--seed", type=int, default=0, help="seed of every random number (0)")
    p_rep.add_argument("-q", "--quiet", action="store_true",
                       help="no progress bar (there is none either when stderr is not a "
                            "terminal; -v logs the stages)")
    p_rep.set_defaults(func=_cmd_reproduce)

    p_sim = sub.add_parser("simulate", help="simulate a saved controller on a road")
    p_sim.add_argument("--controller", required=True,
                       help="controller JSON (save_controller, or a scheduled controller's "
                            "file: run at --m3/--k1 plus the estimate errors)")
    p_sim.add_argument("--delay", type=float, default=0.0, help="actuator delay in seconds")
    p_sim.add_argument("--m3", type=float, default=None,
                       help="the occupant's upper-body mass, kg (default Table 1, 43.3); a "
                            "scheduled controller runs scheduled on it")
    p_sim.add_argument("--m3-error", type=float, default=None,
                       help="with a scheduled controller: the seat's mass estimate minus "
                            "the true mass, kg (default 0)")
    p_sim.add_argument("--k1", type=float, default=None,
                       help="the seat spring, N/m (default Table 1)")
    p_sim.add_argument("--k1-error", type=float, default=None,
                       help="with a controller scheduled on k1: the estimate's error, N/m")
    p_sim.add_argument("--road", choices=_ROADS, default="bump",
                       help="bump (eq. 32), noise (white floor velocity) or iso-C "
                            "(ISO 8608 class C at 30 km/h)")
    p_sim.add_argument("--seed", type=int, default=0, help="seed of the random roads (0)")
    p_sim.add_argument("--duration", type=float, default=None,
                       help="length of the road record in seconds (bump 3, noise/iso-C 5)")
    p_sim.add_argument("--plot", default=None, help="write the z3'' response to this PNG")
    p_sim.add_argument("--json", action="store_true", help="print the metrics as JSON")
    p_sim.add_argument("--discrete", action="store_true",
                       help="run the file's discrete realization (Ad, Bd, Cd, Dd, dt) in the "
                            "sampled-data loop: zero-order hold, exact delay, clipping")
    p_sim.add_argument("--noise", default=None,
                       help="with --discrete: sensor-noise standard deviations x1,x3 in m "
                            "(seeded by --seed)")
    p_sim.add_argument("--quantisation", type=float, default=None,
                       help="with --discrete: sensor resolution in m")
    p_sim.set_defaults(func=_cmd_simulate)

    p_sw = sub.add_parser(
        "sweep", help="robustness maps: many simulations over seat, delay, road and "
        "controllers on Dask, written to DIR/results.parquet with figures",
        description="A grid (ranges start:stop:count) or, with --samples, a Monte-Carlo "
        "(ranges lo:hi) over the seat's parameters, the delay and the road, for each "
        "controller; run on a local Dask cluster or on --scheduler. Re-running into the "
        "same --out skips the finished cases.")
    p_sw.add_argument("--controller", action="append", default=None,
                      help="controller JSON (repeatable; 'passive' for none; 'design' or "
                           "'design:ROUTE' for one designed per seat, see 'design')")
    p_sw.add_argument("--m3", default=None, help="upper-body mass, kg (e.g. 30:70:9)")
    p_sw.add_argument("--delay", default=None, help="actuator delay, s (e.g. 0:0.05:11)")
    p_sw.add_argument("--m3-error", default=None,
                      help="a scheduled controller's mass-estimate error, kg (e.g. -10:10:5; "
                           "other estimates' errors as --param k1_error=...)")
    p_sw.add_argument("--param", action="append", default=None, metavar="NAME=RANGE",
                      help="another axis: a seat parameter (k1, c2, ...), a scheduled "
                           "controller's estimate error (k1_error, ...) or the road's "
                           "(height, length, speed_kmh; psd)")
    p_sw.add_argument("--road", choices=("bump", "iso8608", "noise"), default="bump",
                      help="the road (default bump, eq. 32)")
    p_sw.add_argument("--duration", type=float, default=None,
                      help="record length, s (bump 3, others 5)")
    p_sw.add_argument("--samples", type=int, default=0,
                      help="Monte-Carlo: this many cases per controller, axes as lo:hi")
    p_sw.add_argument("--sampling", choices=("uniform", "lhs"), default=None,
                      help="with --samples: draw each case uniformly (default), or 'lhs': "
                           "one Latin hypercube of the samples, the same seats for every "
                           "controller")
    p_sw.add_argument("--seed", type=int, default=0, help="entropy of every case's seed (0)")
    p_sw.add_argument("--no-limit", action="store_true",
                      help="skip the physical limit (bump LP) and limit_ratio")
    p_sw.add_argument("--spec", default=None, help="a TOML spec file instead of the flags")
    p_sw.add_argument("--out", required=True, help="output directory")
    p_sw.add_argument("--scheduler", default=None,
                      help="address of a running Dask scheduler (default: a local cluster)")
    p_sw.add_argument("--workers", type=int, default=None,
                      help="worker processes of the local cluster (default 2; 0: no Dask)")
    p_sw.add_argument("-q", "--quiet", action="store_true", help="no progress bar")
    p_sw.set_defaults(func=_cmd_sweep)

    p_de = sub.add_parser("design",
                          help="design a seat controller along a route with its default "
                               "choices (seconds to tens of minutes), write it, certify it "
                               "(exit status 1 where the route's own requirements are not "
                               "met; the certificate's verdict on issue 38's targets is "
                               "printed)")
    p_de.add_argument("route", choices=("mu", "constrained", "refined", "occupants",
                                        "peak_bounded", "discrete"),
                      help="mu: D-K as in the paper (seconds); constrained: hard force/stroke "
                           "bounds in every K-step (minutes); refined: the µ controller "
                           "refined to the bump requirements (minutes); occupants: that "
                           "refinement over 30-70 kg and aged springs (tens of minutes); "
                           "peak_bounded: H∞ with peak bounds, no delay (seconds); "
                           "discrete: D-K on the plant sampled at 1 kHz (a minute)")
    p_de.add_argument("--out", required=True, help="controller file to write")
    p_de.add_argument("--seed", type=int, default=0, help="seed of the route's random draws")
    p_de.set_defaults(func=_cmd_design)

    p_dc = sub.add_parser("design-constrained",
                          help="µ-synthesis with hard force/stroke bounds and a pole disk in "
                               "every K-step (minutes); writes the controller file "
                               "reproduce loads")
    p_dc.add_argument("--u-bound", type=float, default=9000.0,
                      help="|u| bound, N, for every floor velocity of the bump's energy")
    p_dc.add_argument("--z-bound", type=float, default=0.16, help="|x1| bound, m, likewise")
    p_dc.add_argument("--disk-radius", type=float, default=2000.0,
                      help="closed-loop poles in |s| < this, rad/s")
    p_dc.add_argument("--out", default=None,
                      help="controller file to write (default: the one shipped in the package)")
    p_dc.set_defaults(func=_cmd_design_constrained)

    p_rf = sub.add_parser("refine",
                          help="refine the µ controller to exact bump requirements (force, "
                               "stroke, µ, poles) by a fixed-order search (minutes); writes "
                               "the controller file reproduce loads")
    p_rf.add_argument("--controller", default=None,
                      help="start controller JSON (default: the µ design, designed now)")
    p_rf.add_argument("--u-bound", type=float, default=1500.0,
                      help="commanded |u| on the bump at every delay 0-25 ms, N")
    p_rf.add_argument("--z-bound", type=float, default=0.08, help="|x1| on the bump, m")
    p_rf.add_argument("--disk-radius", type=float, default=1900.0,
                      help="controller and loop poles in |s| < this, rad/s")
    p_rf.add_argument("--max-iter", type=int, default=600,
                      help="SLSQP iterations in all (with --occupants: per round)")
    p_rf.add_argument("--out", default=None,
                      help="controller file to write (default: the one shipped in the package)")
    p_rf.add_argument("--occupants", action="store_true",
                      help="refine for every seat of 30-70 kg, springs and dampers ±20 %%: "
                           "rounds of refinement on a growing set of seats, each followed "
                           "by a worst-case search (robust stability of the delay cover "
                           "and, by mixed µ, over the whole set, instead of the µ weights' "
                           "robust performance)")
    p_rf.add_argument("--no-set-mu", action="store_true",
                      help="with --occupants: leave out the set's mixed-µ robust stability "
                           "(the seats' delay covers only)")
    p_rf.add_argument("--rounds", type=int, default=3, help="with --occupants: rounds")
    p_rf.add_argument("--seed", type=int, default=0,
                      help="with --occupants: seed of the worst-case search's samples")
    p_rf.set_defaults(func=_cmd_refine)

    p_oc = sub.add_parser("occupants",
                          help="certify controllers over occupants of 30-70 kg, springs and "
                               "dampers ±20 %%, delays 0-25 ms: exact-delay Nyquist on "
                               "Latin-hypercube samples, the bump at 0-25 ms against each "
                               "sample's own limit, and mixed µ (--mu); a table, a JSON "
                               "file and one map per controller")
    p_oc.add_argument("controllers", nargs="+", help="controller JSON files")
    p_oc.add_argument("--stability", type=int, default=10_000,
                      help="stability samples (about 6 ms each)")
    p_oc.add_argument("--performance", type=int, default=200,
                      help="performance samples, each met at 0, 5, ..., 25 ms (about 0.8 s "
                           "each, mostly its own limit's LP)")
    p_oc.add_argument("--seed", type=int, default=2026, help="seed of the samples")
    p_oc.add_argument("--mu", action="store_true",
                      help="also mixed µ, robust stability and performance: upper bounds "
                           "over every frequency, lower bounds on the grid (under a "
                           "minute per controller)")
    p_oc.add_argument("--out", default="occupants_out", help="output folder")
    p_oc.add_argument("-q", "--quiet", action="store_true", help="no progress lines")
    p_oc.set_defaults(func=_cmd_occupants)

    p_to = sub.add_parser("tradeoff",
                          help="the force bound's price: one design-constrained per bound "
                               "(minutes each), simulated on the bump at 0-25 ms; writes "
                               "tradeoff.json, tradeoff.png and the controllers")
    p_to.add_argument("--u-bounds", default="2500,3600,6000,9000",
                      help="force bounds, N, separated by commas")
    p_to.add_argument("--z-bound", type=float, default=0.16, help="|x1| bound, m")
    p_to.add_argument("--disk-radius", type=float, default=2000.0,
                      help="closed-loop poles in |s| < this, rad/s (0: no disk)")
    p_to.add_argument("--out", default="tradeoff", help="output directory")
    p_to.add_argument("--quiet", action="store_true", help="no progress bar")
    p_to.set_defaults(func=_cmd_tradeoff)

    p_ex = sub.add_parser("export", help="write a saved controller as a MATLAB .mat file "
                          "(A, B, C, D, InputName, OutputName; Ts when discretised) or JSON")
    p_ex.add_argument("--controller", required=True, help="controller JSON (save_controller)")
    p_ex.add_argument("--format", choices=("mat", "json"), default="mat")
    p_ex.add_argument("--out", required=True, help="the file to write")
    p_ex.add_argument("--ts", type=float, default=None,
                      help="discretise (zero-order hold) at this sample time, s (mat only)")
    p_ex.set_defaults(func=_cmd_export)
    return parser


def main(argv: list[str] | None = None) -> int:
    """Entry point of the ``lmi-suspension`` console script."""
    from .errors import LmiSuspensionError

    parser = build_parser()
    args = parser.parse_args(argv)
    logging.basicConfig(level=logging.INFO if args.verbose else logging.WARNING,
                        format="%(levelname)s %(name)s: %(message)s")
    if not args.verbose:
        # dask sets its loggers to INFO when it is imported (after this); their start and
        # close chatter would reach the handler above and break the progress bars
        for handler in logging.getLogger().handlers:
            handler.addFilter(lambda r: not r.name.startswith("distributed")
                              or r.levelno >= logging.ERROR)
    try:
        return args.func(args)
    except (LmiSuspensionError, ValueError, OSError) as exc:
        # One line, no traceback: bad files, bad numbers, solver failures.
        message = " ".join(str(exc).split()) or type(exc).__name__
        parser.exit(2, f"lmi-suspension: error: {message}\n")


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
