"""``jointdyn frc``: frequency-response curve of the paper's friction damper,
or of a structure of your own (``--system FILE.toml``, docs/system-files.md).

Time domain (``--method time``, default): steady states swept up and/or down
in gamma with warm starts (:func:`jointdyn.sweeps.frc_sweep`). Harmonic
balance (``--method hb``): :func:`jointdyn.hb.frc_hb` continuation.
With ``--system`` the options that describe the paper damper (``--eta``,
``--beta``, ``--f1``, ``--delta``, ``--m``, ``--k``, ``--kt``, ``--kn``,
``--mu``, ``--n0``, ``--model``, ``--law-param``, ``--n``, ``--zeta``) are
refused; the others work as for the damper.
Options of one method are refused with the other (one line, exit 2):
``--sweep``, ``--steps-per-period``, ``--scheduler`` and ``--workers`` are
time-domain options (the continuation follows the branch through its folds,
which holds the states of both sweep directions, along one sequential path);
``--harmonics`` and ``--samples`` are harmonic-balance options.

Everything is validated before computing (including the writability of
``--out``, derived quantities such as fy = mu N0 and the grid size, and the
connection to ``--scheduler``); ``--out`` files (``frc.nc``, ``frc.csv``,
``frc.png``) are written atomically after computing (time-domain sweep lines
are also saved one by one under ``OUT/lines`` so that an interrupted run
resumes; a resumed run says how many points it reused). The table prints
gamma with as many digits as distinct points need.
"""

from __future__ import annotations

import json
import math
from pathlib import Path

import numpy as np

from .. import _validate as V
from .. import config
from .._io import jsonable as _jsonable
from . import _frc_report as report
from ._law_args import add_law_arguments, law_params, model_help
from ._system_args import add_system_argument, load_system_file, refuse_paper_options
from ..systems import PAPER

#: the options that set the discretisation of harmonic balance, named in its refusals
_HB_NAMES = ("--harmonics", "--samples")

NAME = "frc"
#: the gamma grid START:STOP:STEP when none is given (the paper's Fig 6 range)
GAMMA_DEFAULT = (0.6, 1.8, 0.01)
#: most points of a gamma grid given as START:STOP:STEP
MAX_GAMMA_POINTS = 100_000
#: seconds to wait for a Dask scheduler to answer (--scheduler)
SCHEDULER_TIMEOUT_S = 5.0
HELP = ("frequency-response curve (steady amplitude vs gamma) of the paper's friction damper or of a structure "
        "of your own (--system FILE.toml)")

#: the options that describe the paper damper, with their values when not given
PAPER_OPTIONS = {"eta": 0.5, "beta": None, "f1": None, "delta": 0.0, "model": config.MODEL, "law_param": None,
                 "n": None, "zeta": 0.0, **{key: PAPER[key] for key in ("m", "k", "kt", "kn", "mu", "n0")}}


def add_arguments(p) -> None:
    g0 = ":".join(f"{v:g}" for v in GAMMA_DEFAULT)
    d = PAPER_OPTIONS
    p.add_argument("--method", default="time", help="time (time-domain steady states, default) or hb (harmonic balance)")
    add_system_argument(p)
    p.add_argument("--eta", type=float, default=None, help=f"N1/N0, normal-load oscillation ratio (>= 0; default {d['eta']:g})")
    load = p.add_mutually_exclusive_group()
    load.add_argument("--beta", type=float, default=None, help="mu N0 / F1 (> 0; default 1.0)")
    load.add_argument("--f1", type=float, default=None, help="forcing amplitude F1 in N (> 0), instead of --beta")
    p.add_argument("--gamma", default=None, metavar="START:STOP:STEP",
                   help=f"frequency-ratio grid gamma = w/w0 (default {g0}); with --system w0 is the file's "
                        "reference frequency")
    p.add_argument("--frequency", default=None, metavar="START:STOP:STEP",
                   help="forcing-frequency grid in Hz instead of --gamma (gamma = 2 pi f / w0); frc.csv gives "
                        "every point in Hz and rad/s as well")
    p.add_argument("--delta", type=float, default=None, help=f"normal-load phase, degrees (default {d['delta']:g})")
    p.add_argument("--sweep", default=None,
                   help="time: up, down or both (default both); hb: refused (the continuation follows the "
                        "branch through its folds, which holds the states of both sweep directions)")
    p.add_argument("--model", default=None, help=model_help(d["model"]))
    add_law_arguments(p)
    p.add_argument("--zeta", type=float, default=None, help=f"viscous damping ratio (default {d['zeta']:g})")
    p.add_argument("--m", type=float, default=None, help=f"mass, kg (default {d['m']:g})")
    p.add_argument("--k", type=float, default=None, help=f"stiffness, N/m (default {d['k']:g})")
    p.add_argument("--kt", type=float, default=None, help=f"tangential contact stiffness, N/m (default {d['kt']:g})")
    p.add_argument("--kn", type=float, default=None,
                   help=f"normal contact stiffness, N/m (default {d['kn']:g}); recorded only: the damper's "
                        "normal load is prescribed, N = N0 + N1 sin(w t + delta) (a normal spring: --system)")
    p.add_argument("--mu", type=float, default=None, help=f"friction coefficient (default {d['mu']:g})")
    p.add_argument("--n0", type=float, default=None, help=f"static normal load N0, N (default {d['n0']:g})")
    p.add_argument("--steps-per-period", type=int, default=None,
                   help="time: time steps per forcing period (solver default)")
    p.add_argument("--scheduler", default=None, metavar="ADDRESS",
                   help="time: run the sweep lines on the Dask scheduler at ADDRESS (e.g. tcp://host:8786; "
                        f"connection timeout {SCHEDULER_TIMEOUT_S:g} s)")
    p.add_argument("--workers", type=int, default=None,
                   help="time: local parallel workers (default: all cores; not with --scheduler)")
    p.add_argument("--harmonics", default=None, metavar="H|auto",
                   help=f"hb: number of harmonics, or auto (default: from {config.HB_HARMONICS}, raised while a "
                        f"peak changes by more than {100 * config.HB_AUTO_RTOL:g} %% with 2H+1)")
    p.add_argument("--samples", default=None, metavar="NS|auto",
                   help=f"hb: time samples per period, or auto (default: from {config.HB_SAMPLES}, doubled while a "
                        f"peak changes by more than {100 * config.HB_AUTO_RTOL:g} %% with twice as many)")
    p.add_argument("--no-stability", action="store_true", default=None,
                   help="hb: do not compute the stability of the points (stable false, growth NaN, the "
                        "Dataset's stability attribute not-computed); by default dense Hill on small "
                        "problems, shift-invert Arnoldi on large ones")
    p.add_argument("--out", default=None, metavar="DIR",
                   help="write frc.nc, frc.csv, frc.png here (time: resume checkpoints under DIR/lines; a rerun "
                        "reuses them and says how many points it reused)")
    p.add_argument("--json", action="store_true", help="print one JSON object instead of a table")


def parse_gamma(text: str, name: str = "--gamma") -> np.ndarray:
    """``START:STOP:STEP`` -> increasing grid (STOP included when on the grid); errors name ``name``."""
    parts = str(text).split(":")
    if len(parts) != 3:
        raise ValueError(f"{name} must be START:STOP:STEP, got {text!r}")
    try:
        start, stop, step = (float(s) for s in parts)
    except ValueError:
        raise ValueError(f"{name} must be START:STOP:STEP of numbers, got {text!r}") from None
    V.positive(f"{name} START", start)
    V.positive(f"{name} STEP", step)
    V.finite(f"{name} STOP", stop)
    if not stop >= start:
        raise ValueError(f"{name} STOP must be >= START ({start:g}), got {stop:g}")
    # a float until bounded: (STOP - START) / STEP may be huge or inf
    V.count_at_most(f"{name} START:STOP:STEP", (stop - start) / step + 1.0,
                    MAX_GAMMA_POINTS, "points")
    count = int(math.floor((stop - start) / step + 1e-9)) + 1
    grid = start + step * np.arange(count)
    with np.errstate(over="ignore", invalid="ignore"):
        # 12 decimals clean the float noise of a grid; not where they would change a value (tiny or huge gammas)
        rounded = np.round(grid, 12)
    return np.where(np.abs(rounded - grid) <= 1e-9 * grid, rounded, grid)


def config_gamma() -> str:
    """The default --gamma grid, as the option writes it."""
    return ":".join(f"{v:g}" for v in GAMMA_DEFAULT)


def _frequency_gammas(args) -> np.ndarray:
    """The gamma grid of ``--frequency`` (Hz): gamma = 2 pi f / w0, with w0 the system file's reference
    frequency or the paper damper's sqrt(k / m)."""
    if args.gamma is not None:
        raise ValueError("--frequency and --gamma both give the frequency grid; give one")
    hz = parse_gamma(args.frequency, "--frequency")
    if args.system_file is not None:
        w0 = args.system_file.system.w0
    else:
        w0 = math.sqrt(V.positive("--k", PAPER["k"] if args.k is None else args.k)
                       / V.positive("--m", PAPER["m"] if args.m is None else args.m))
    return V.finite_array("--frequency x 2 pi / w0 (gamma)", 2.0 * math.pi * hz / w0)


#: options of one method only, with the reason they do not apply to the other
_TIME_ONLY = {
    "sweep": "the continuation follows the branch through its folds, which holds the states of both "
             "sweep directions",
    "steps_per_period": "harmonic balance has no time steps (see --samples)",
    "scheduler": "the continuation is one sequential path",
    "workers": "the continuation is one sequential path",
}
_HB_ONLY = ("harmonics", "samples", "no_stability")


def _option(dest: str) -> str:
    return "--" + dest.replace("_", "-")


def _check_method_options(args) -> None:
    """Refuse the options that the chosen method would ignore; fill the
    defaults of the others."""
    if args.method == "hb":
        for dest, why in _TIME_ONLY.items():
            if getattr(args, dest) is not None:
                raise ValueError(f"{_option(dest)} applies to --method time only: {why}")
        return
    for dest in _HB_ONLY:
        if getattr(args, dest) is not None:
            raise ValueError(f"{_option(dest)} applies to --method hb only")
    if args.scheduler is not None and args.workers is not None:
        raise ValueError("--workers cannot be combined with --scheduler: the cluster's workers run the lines")
    args.sweep = "both" if args.sweep is None else args.sweep


def _check_derived(args, gammas) -> None:
    """Quantities computed from several options stay finite and positive."""
    fy = V.derived("fy = --mu x --n0", args.mu * args.n0, positive=True)
    if args.f1 is not None:
        V.derived("beta = --mu x --n0 / --f1", fy / args.f1, positive=True)
    else:
        V.derived("F1 = --mu x --n0 / --beta", fy / args.beta, positive=True)
    V.derived("--eta x --n0 (normal-load amplitude, N)", args.eta * args.n0)
    w0 = V.derived("w0 = sqrt(--k / --m)", math.sqrt(args.k / args.m), positive=True)
    w_top = V.derived("--gamma STOP x w0 (highest forcing frequency, rad/s)", float(gammas[-1]) * w0)
    V.derived("(--gamma STOP x w0)^2 (the inertia scale w^2 of the solvers, rad^2/s^2)", w_top * w_top)
    V.derived("2 pi / (--gamma START x w0) (longest forcing period, s)", 2.0 * math.pi / (float(gammas[0]) * w0))
    V.derived("--zeta x 2 sqrt(--k x --m) (viscous coefficient)", 2.0 * args.zeta * math.sqrt(args.k) * math.sqrt(args.m))
    V.derived("--kt / fy (normalised contact stiffness)", args.kt / fy)


def _check_system_derived(system, gammas) -> None:
    """The grid in rad/s stays finite for the system file's reference frequency."""
    w0 = V.derived("w0 of --system (reference frequency, rad/s)", system.w0, positive=True)
    w_top = V.derived("--gamma STOP x w0 (highest forcing frequency, rad/s)", float(gammas[-1]) * w0)
    V.derived("(--gamma STOP x w0)^2 (the inertia scale w^2 of the solvers, rad^2/s^2)", w_top * w_top)
    V.derived("2 pi / (--gamma START x w0) (longest forcing period, s)", 2.0 * math.pi / (float(gammas[0]) * w0))


def _validate_paper(args, gammas) -> None:
    """The paper damper's options, with their defaults filled in."""
    from ..laws import law_names

    for dest, value in PAPER_OPTIONS.items():
        if getattr(args, dest) is None and value is not None:
            setattr(args, dest, value)
    V.choice("--model", args.model, law_names())
    V.nonnegative("--eta", args.eta)
    if args.f1 is not None:
        V.positive("--f1", args.f1)
    else:
        args.beta = V.positive("--beta", 1.0 if args.beta is None else args.beta)
    V.finite("--delta", args.delta)
    args.law_params = law_params(args)
    V.nonnegative("--zeta", args.zeta)
    for key in ("m", "k", "kt", "kn", "mu", "n0"):
        V.positive(f"--{key}", getattr(args, key))
    _check_derived(args, gammas)


def _validate(args):
    V.choice("--method", args.method, ("time", "hb"))
    _check_method_options(args)
    if args.method == "time":
        V.choice("--sweep", args.sweep, ("up", "down", "both"))
    gammas = None  # from --frequency once w0 is known
    if getattr(args, "frequency", None) is None:
        gammas = parse_gamma(config_gamma() if args.gamma is None else args.gamma)
    if args.steps_per_period is not None:
        V.positive_int("--steps-per-period", args.steps_per_period, 8)
    if args.workers is not None:
        V.positive_int("--workers", args.workers)
    if args.method == "hb":
        from ..hb import AUTO, Discretisation

        disc = Discretisation.of(AUTO if args.harmonics is None else args.harmonics,
                              AUTO if args.samples is None else args.samples, names=_HB_NAMES)
        args.harmonics = AUTO if disc.harmonics_auto else disc.first.harmonics
        args.samples = AUTO if disc.samples_auto else disc.first.samples
    args.system_file = None
    if args.system is not None:
        refuse_paper_options(args, PAPER_OPTIONS)
        args.system_file = load_system_file(args)
        gammas = _frequency_gammas(args) if gammas is None else gammas
        _check_system_derived(args.system_file.system, gammas)
    else:
        gammas = _frequency_gammas(args) if gammas is None else gammas
        _validate_paper(args, gammas)
    if args.method == "time":
        _check_time_steps(args, gammas)
    else:
        from ..hb import check_mean_position, check_memory

        check_memory(_system(args), disc, names=_HB_NAMES)
        try:  # the solver's own refusal, made before --out is checked and anything computed
            check_mean_position(_system(args))
        except ValueError as exc:
            raise ValueError(f"--method hb: {exc}") from None
    if args.out is not None:
        subdirs = ("lines",) if args.method == "time" else ()
        V.output_dir("--out", args.out, files=("frc.nc", "frc.csv", "frc.png"), subdirs=subdirs)
    return gammas


def _check_time_steps(args, gammas) -> None:
    """The steps of a forcing period at the lowest gamma (the most) fit the memory bound, for the
    lines run at once: refused before computing, naming --steps-per-period when it sets the step,
    else the structure's stiffest mode."""
    from ..dynamics import check_period_steps

    system = _system(args)
    lines = 1 if args.sweep != "both" or args.workers == 1 else 2
    try:
        check_period_steps(system, float(gammas[0]) * system.w0, args.steps_per_period, lines=lines,
                           name="--steps-per-period")
    except ValueError as exc:
        msg = str(exc)
        raise ValueError(msg if msg.startswith("--") else f"--method time: {msg}; --method hb has no time step") from None


def _connect(address):
    """A Dask client of the scheduler at ``address``, or a ValueError naming
    --scheduler (quickly: a short connection timeout)."""
    from distributed import Client
    from distributed.comm import parse_address
    from distributed.comm.addressing import parse_host_port
    from distributed.comm.registry import get_backend

    try:  # the address itself, without starting a client
        scheme, location = parse_address(address)
        get_backend(scheme)
        if scheme in ("tcp", "tls", "ws", "wss"):
            parse_host_port(location)
    except ValueError as exc:
        raise ValueError(f"--scheduler must be a Dask scheduler address such as tcp://host:8786, got "
                         f"{address!r}: {exc}") from None
    timeout = SCHEDULER_TIMEOUT_S
    try:
        return Client(address, timeout=timeout)
    except (OSError, TimeoutError, ValueError, TypeError) as exc:
        raise ValueError(
            f"--scheduler cannot reach a Dask scheduler at {address!r} within {timeout:g} s: {exc}"
        ) from None


def _system_header(sf) -> dict:
    """What the JSON says about a --system structure."""
    from ..hb.problem import amplitude_q_meaning

    system = sf.system
    contacts = []
    for c in system.contacts:
        law = c.law
        contacts.append({"law": type(law).__name__, "kt": law.kt, "mu": law.mu, "n_ref": law.n_ref,
                         "fy_N": law.fy, **law.law_params(), "normal": type(c.normal).__name__,
                         "n0": float(c.normal.n0)})
    return {"file": str(sf.path), "title": sf.title, "ndof": int(system.ndof), "w0_rad_s": float(system.w0),
            "response_dof": int(system.response_dof), "dofs": [int(d) for d in sf.dofs],
            "fy_N": float(system.contacts[0].law.fy) if system.contacts else None, "contacts": contacts,
            "amplitude_q_meaning": amplitude_q_meaning(system)}


def _header(args) -> dict:
    if args.system_file is not None:
        return {"method": args.method, "system": _system_header(args.system_file)}
    head = {"method": args.method, "eta": args.eta}
    if args.f1 is not None:
        head["f1"] = args.f1
        head["beta"] = args.mu * args.n0 / args.f1
    else:
        head["beta"] = args.beta
        head["f1"] = args.mu * args.n0 / args.beta
    head.update(delta_deg=args.delta, model=args.model, law_params=args.law_params, zeta=args.zeta,
                m=args.m, k=args.k, kt=args.kt, kn=args.kn, mu=args.mu, n0=args.n0)
    return head


def _system(args):
    """The System of the run: the --system file's, or the paper damper of the options."""
    if args.system_file is not None:
        return args.system_file.system
    from ..systems import System

    return System.paper_damper(
        eta=args.eta,
        beta=args.beta if args.f1 is None else 1.0,
        f1=args.f1,
        delta_deg=args.delta,
        model=args.model,
        zeta=args.zeta,
        law_params=args.law_params,
        m=args.m, k=args.k, kt=args.kt, mu=args.mu, n0=args.n0,
    )


def _sweep(args, gammas, directions, client):
    """(Dataset, its one line per direction) of the time-domain sweep of the
    --system structure or of the paper damper's options."""
    from ..sweeps import frc_sweep

    common = dict(directions=directions, steps_per_period=args.steps_per_period, client=client,
                  n_workers=args.workers, out=None if args.out is None else Path(args.out), progress=not args.json)
    if args.system_file is not None:
        try:
            ds = frc_sweep(args.system_file.system, gammas, dofs=args.system_file.dofs, **common)
        except np.linalg.LinAlgError:
            raise  # a failed solve, not a refusal (the command line says so)
        except ValueError as exc:
            # the options are checked already: what is left is the time integrator's refusal of the structure
            raise ValueError(f"--method time: {exc}") from None
        return ds, ds
    ds = frc_sweep(
        gammas,
        etas=[args.eta],
        betas=None if args.f1 is not None else [args.beta],
        f1s=None if args.f1 is None else [args.f1],
        deltas=[args.delta],
        model=args.model,
        law_params=args.law_params,
        zeta=args.zeta,
        m=args.m, k=args.k, kt=args.kt, mu=args.mu, n0=args.n0,
        **common,
    )
    ds.attrs["kn"] = float(args.kn)
    load = "beta" if args.f1 is None else "f1"
    return ds, ds.isel(eta=0, delta=0, **{load: 0})


def _loop_outputs(one) -> dict:
    """Per-DOF and per-contact results of one direction (a --system sweep)."""
    from ..laws import STATE_NAMES

    dofs = {str(int(d)): {v: _jsonable(one[f"dof_{v}"].sel(dof=d).values) for v in ("amplitude_m", "offset_m")}
            for d in one.dof.values}
    contacts = []
    for c in one.contact.values:
        sub = one.sel(contact=c)
        item = {"energy_J": _jsonable(sub.contact_energy_J.values),
                **{v: _jsonable(sub[v].values) for v in ("normal_mean_N", "normal_min_N", "normal_max_N")},
                "state_fraction": {s: _jsonable(sub.state_fraction.sel(state=s).values) for s in STATE_NAMES}}
        contacts.append(item)
    return {"dofs": dofs, "contacts": contacts}


def _run_time(args, gammas):
    import sys

    from ..sweeps import status_name

    directions = ("up", "down") if args.sweep == "both" else (args.sweep,)
    client = None if args.scheduler is None else _connect(args.scheduler)
    try:
        ds, line = _sweep(args, gammas, directions, client)
    finally:
        if client is not None:
            client.close()
    result = _header(args)
    result["reused_points"] = int(ds.attrs.get("reused_points", 0))
    result["directions"] = {}
    for d in directions:
        one = line.sel(direction=d)
        result["directions"][d] = {
            "gamma": _jsonable(one.gamma.values),
            **{v: _jsonable(one[v].values) for v in ("amplitude_q", "amplitude_m", "offset_m", "max_abs_m")},
            "status": [status_name(c) for c in one.status.values],
            # a steady state that repeats every K periods: K (1: the forcing period; 0: not periodic)
            "period_multiple": [int(p) for p in one.period_multiple.values],
            "not_settled_reason": [report.reason_name(s, r) for s, r in zip(one.status.values,
                                                                            one.not_settled_reason.values)],
            "negative_dissipation": [bool(v) for v in one.negative_dissipation.values],
        }
        if "contact" in one.dims or "dof" in one.dims:
            result["directions"][d].update(_loop_outputs(one))
        if "pair" in one.dims:  # the interfaces' node pairs (NaN sums where a point has no steady state)
            result["directions"][d].update(_pair_json(one.pair_energy_J.values, {
                k: one[f"pair_{k}_fraction"].values for k in ("stick", "slip", "open")}))
    flagged = int(line.negative_dissipation.sum())
    if flagged:
        print(f"jointdyn frc: warning: {flagged} periodic points where the contact creates energy over the period "
              "(negative dissipation beyond the energy-balance residual; negative_dissipation in the results)",
              file=sys.stderr)
    if result["reused_points"] or ds.attrs.get("stale_points"):
        stale = int(ds.attrs.get("stale_points", 0))
        note = f"; recomputed {stale} points saved by another solver version" if stale else ""
        print(f"jointdyn frc: resumed from {Path(args.out) / 'lines'}: reused {result['reused_points']} of "
              f"{ds.status.size} points{note}", file=sys.stderr)
    return ds, result


def _hb_branches(br, dofs=()) -> list:
    """The segments of an HBBranch as JSON objects (per point: gamma, amplitudes, stability, status;
    ``dofs``: the amplitude and offset of each of these DOFs too, under ``dofs``)."""
    from ..hb.export import pair_arrays
    from ..hb.problem import reference_scales

    kt, fy = reference_scales(br.problem.system)
    amp, off, mx = br.response()
    pairs = pair_arrays(br)
    gam = br.gamma()
    out = []
    for b in dict.fromkeys(br.segment.tolist()):
        idx = np.flatnonzero(br.segment == b)
        q = kt * amp[idx] / fy if fy > 0.0 else np.full(idx.size, np.nan)  # no slip force: null, not a warning
        one = {"gamma": gam[idx], "amplitude_q": q, "amplitude_m": amp[idx],
               "offset_m": off[idx], "max_abs_m": mx[idx]}
        one = {k: _jsonable(v) for k, v in one.items()}
        if len(dofs):
            one["dofs"] = {str(d): {"amplitude_m": _jsonable(r[0][idx]), "offset_m": _jsonable(r[1][idx])}
                           for d, r in ((int(d), br.response(int(d))) for d in dofs)}
        one["stable"] = [bool(s) for s in br.stable[idx]]
        one["point_status"] = [str(s) for s in br.point_status[idx]]
        one["folds"] = [int(i) for i in np.flatnonzero(br.fold[idx])]
        one["branch"] = int(b)  # the segment (0: from START; then continued back from STOP or over a jump)
        if pairs:  # the interfaces' node pairs: total and per pair, per point
            one.update(_pair_json(pairs["pair_energy_J"][idx],
                                  {k: pairs[f"pair_{k}_fraction"][idx] for k in ("stick", "slip", "open")}))
        out.append(one)
    return out


def _pair_json(energy, fractions) -> dict:
    """``energy_interface_J`` (per point, J; ``energy_pairs_J`` its deprecated duplicate) and ``pairs`` (per
    point and pair: ``energy_J``, J, and the ``stick_fraction``, ``slip_fraction``, ``open_fraction`` of the
    period) of the JSON."""
    energy = np.asarray(energy, dtype=float)
    total = _jsonable(energy.sum(axis=1))
    return {"energy_interface_J": total, "energy_pairs_J": total,
            "pairs": {"energy_J": _jsonable(energy),
                      **{f"{k}_fraction": _jsonable(np.asarray(v, dtype=float)) for k, v in fractions.items()}}}


def _hb_peaks(br) -> list:
    """The refined peaks of an HBBranch as JSON objects."""
    return [{"gamma": pk.gamma, "amplitude_q": _jsonable([pk.amplitude_q])[0],
             "amplitude_m": _jsonable([pk.amplitude_m])[0], "branch": pk.segment, "refined": pk.refined,
             "at_stop": pk.at_stop}
            for pk in br.peaks]


def _run_hb(args, gammas):
    """The hb branch: ``(branch, result)`` (the Dataset is built only for files: xarray takes time to import)."""
    from ..hb import continue_hb
    from ..hb.export import discretisation_attrs

    system = _system(args)
    if gammas.size < 2:
        raise ValueError("--gamma must span a range (STOP > START) for --method hb")
    # the grid's STEP is the largest gamma spacing of the branch (the step control may take smaller ones)
    step = float(gammas[1] - gammas[0])
    try:
        br = continue_hb(system, float(gammas[0]), float(gammas[-1]), harmonics=args.harmonics,
                         samples=args.samples, max_step=step, progress=None if not args.json else False,
                         stability=False if args.no_stability else None)
    except np.linalg.LinAlgError:
        raise  # a failed solve, not a refusal (the command line says so)
    except ValueError as exc:
        # what the harmonic-balance solver refuses (a kind of normal load, mixed laws) is said as its own
        raise ValueError(f"--method hb: {exc}") from None
    result = _header(args)
    result["harmonics"] = br.problem.H
    result["samples"] = br.problem.Ns
    result["discretisation"] = {k: (_jsonable([v])[0] if isinstance(v, float) else v)
                                for k, v in discretisation_attrs(br).items()}
    result["branches"] = _hb_branches(br, () if args.system_file is None else args.system_file.dofs)
    result["peaks"] = _hb_peaks(br)
    result["status"] = br.status.value
    result["message"] = br.message
    result["uncovered"] = [[float(a), float(b)] for a, b in br.uncovered]
    result["stability"] = br.stability  # hill, hill-arnoldi, or not-computed (--no-stability)
    return br, result


def _plot_title(result) -> str:
    return report.wrap(_title_text(result))


def _title_text(result) -> str:
    if "system" in result:
        sysd = result["system"]
        return (f"{result['method']}: {sysd['title']} ({Path(sysd['file']).name}), DOF {sysd['response_dof']}, "
                f"w0 = {sysd['w0_rad_s']:.6g} rad/s")
    load = f"beta = {result['beta']:g}" if result.get("beta") is not None else ""
    return (f"{result['method']}: eta = {result['eta']:g}, {load}, delta = {result['delta_deg']:g} deg, "
            f"{result['model']}")


def _plot(result, path: Path) -> None:
    from ..figures import pyplot, use_math_text

    plt = pyplot()

    from .._io import atomic_path
    from ..figures.curves import mark_legend, plot_frc_curve
    from ..sweeps import NOT_COMPUTED, STATUS_CODES

    fig, ax = plt.subplots(figsize=(6.4, 4.2))
    if result["method"] == "time":
        for d, style in (("up", "-"), ("down", "--")):
            if d not in result["directions"]:
                continue
            r = result["directions"][d]
            codes = [STATUS_CODES.get(s, NOT_COMPUTED) for s in r["status"]]
            plot_frc_curve(ax, r["gamma"], report.y_values(r, result), codes, color="C0" if d == "up" else "C3",
                           linestyle=style, label=report.curve_label(result, f"sweep {d}"),
                           rug_y=0.03 if d == "up" else 0.07)
            for k, dof in enumerate(report.output_dofs(result)[1:]):  # the other [output] DOFs, thinner
                y = report.dof_mm(r, result, dof)
                if y is not None:
                    ok = np.array(codes) == 0
                    ax.plot(r["gamma"], np.where(ok, y, np.nan), style, color=f"C{k + 4}", lw=0.9,
                            label=f"DOF {dof}, sweep {d}")
        mark_legend(ax, fontsize=8)
    else:
        _plot_hb(ax, result)
    ax.set_title(_plot_title(result), fontsize=9)
    ax.set_xlabel("gamma = w / w0")
    ax.set_ylabel(report.y_label(result))
    ax.grid(alpha=0.3)
    use_math_text(fig)
    fig.tight_layout()
    with atomic_path(path) as tmp:
        fig.savefig(tmp, dpi=120)
    plt.close(fig)


def _plot_hb(ax, result) -> None:
    """hb branches: stable (solid) and unstable (dashed) lines, broken before every point not joined to
    the previous one; folds (squares), points where a segment stopped short (red x), peaks (^; open where
    found at a stop), parts of the range without points (hatched)."""
    from ..figures.curves import branch_pieces

    first = {}
    for br in result["branches"]:
        g = np.array(br["gamma"], float)
        a = report.y_values(br, result)
        st = np.array(br["stable"], bool)
        cut = np.array([piece[0] for piece in branch_pieces(br["point_status"])], dtype=int)
        # a NaN row between two points that are not joined breaks the line there
        g, a, st = (np.insert(v, cut[cut > 0], f) for v, f in ((g, np.nan), (a, np.nan), (st, True)))
        for sel, style, c, name in ((st, "-", "C0", "stable"), (~st, "--", "C1", "unstable")):
            name = report.curve_label(result, name)
            shown = bool(np.any(sel & np.isfinite(a)))  # no legend entry for a style never drawn
            ax.plot(g, np.where(sel, a, np.nan), style, color=c, label=name if shown and name not in first else None)
            first[name] = first.get(name) or shown
        gp = np.array(br["gamma"], float)
        ap = report.y_values(br, result)
        marks = ((br["folds"], "ks", "fold"),
                 ([i for i, s in enumerate(br["point_status"]) if s == "stopped"], "rx", "stopped short"),
                 ([i for i, s in enumerate(br["point_status"]) if s == "after-jump"], "k|", "after a jump"))
        for idx, fmt, name in marks:
            if len(idx):
                ax.plot(gp[idx], ap[idx], fmt, ms=6, label=name if name not in first else None)
                first[name] = True
        for k, dof in enumerate(report.output_dofs(result)[1:]):  # the other [output] DOFs, thinner
            y = report.dof_mm(br, result, dof)
            if y is not None:
                ax.plot(gp, y, "-", color=f"C{k + 4}", lw=0.9, label=f"DOF {dof}" if dof not in first else None)
                first[dof] = True
    for pk in result.get("peaks", []):
        if report.peak_value(pk, result) is not None:
            # a peak where the branch could be followed only up to it: an open marker (a lower bound)
            name = "peak at a stop (at least)" if pk.get("at_stop") else "peak"
            ax.plot([pk["gamma"]], [report.peak_value(pk, result)], "^", color="C2", ms=5,
                    mfc="none" if pk.get("at_stop") else "C2", label=name if name not in first else None)
            first[name] = True
    from ..continuation import ContinuationStatus

    status = ContinuationStatus(result["status"])
    what = "no bounded response" if status is ContinuationStatus.UNBOUNDED else "not computed"
    for k, (a, b) in enumerate(result["uncovered"]):
        ax.axvspan(a, b, facecolor="0.9", edgecolor="0.6", hatch="//", lw=0, label=what if k == 0 else None)
    if not status.ok:
        ax.text(0.01, 0.98, f"status: {result['status']}", transform=ax.transAxes, va="top", fontsize=8,
                color="C3")
    ax.legend(fontsize=8)


def _with_frequency(ds, w0: float):
    """``ds`` with the forcing frequency of every point in rad/s and Hz beside gamma: gamma alone is
    relative to a w0 that may be another mode than the one a user looks at."""
    omega = ds["gamma"] * w0
    return ds.assign(omega_rad_s=omega.assign_attrs(units="rad/s", long_name="forcing frequency w = gamma w0"),
                     frequency_hz=(omega / (2.0 * math.pi)).assign_attrs(units="Hz", long_name="w / (2 pi)"))


def _titled(ds, result):
    """``ds`` with the --system file's ``title`` as its ``title`` attribute (frc.nc carries it as the JSON
    and frc.png do); what the run computed, the title of a paper-damper run, moves to ``summary``."""
    if "system" in result:
        what = ds.attrs.get("title")
        ds.attrs["title"] = result["system"]["title"]
        if what and what != ds.attrs["title"]:
            ds.attrs["summary"] = what
    return ds


def exit_status(result) -> int:
    """0, or :data:`jointdyn._exit.EXIT_INCOMPLETE` for an hb branch that does not cover the range and is
    not unbounded (failed, turned back, stopped at its point bound)."""
    from .._exit import EXIT_INCOMPLETE
    from ..continuation import ContinuationStatus

    if result["method"] != "hb":
        return 0
    status = ContinuationStatus(result["status"])
    # an unbounded response is an answer: no bounded steady state over part of the range
    return 0 if status.ok or status is ContinuationStatus.UNBOUNDED else EXIT_INCOMPLETE


def _export(args, ds, result, out: Path) -> None:
    """The files of ``--out`` (the Dataset as netCDF + CSV, the figure), with the progress of that stage
    (a bar on a terminal, plain lines elsewhere when it is long; nothing with ``--json``)."""
    from ..continuation import stage_progress

    with stage_progress(2, f"export to {out}", False if args.json else None, unit="file") as bar:
        if args.method == "time":
            from ..sweeps import write_outputs

            write_outputs(_with_frequency(_titled(ds, result), _system(args).w0), out)
        else:
            from .._io import write_dataset
            from ..hb import branch_dataset

            # frc.csv: one row per point (per-harmonic data in frc.nc)
            write_dataset(_with_frequency(_titled(branch_dataset(ds), result), _system(args).w0), out, "frc")
        bar.update(1)
        _plot(result, out / "frc.png")
        bar.update(1)


def run(args) -> int:
    gammas = _validate(args)
    if args.method == "time":
        ds, result = _run_time(args, gammas)
    else:
        ds, result = _run_hb(args, gammas)
    if args.out is not None:
        _export(args, ds, result, Path(args.out))
    if args.json:
        print(json.dumps(result))
    else:
        _print_table(result)
    rc = exit_status(result)
    if rc:
        import sys

        print(f"jointdyn frc: incomplete: {result['status']}: {result['message']}", file=sys.stderr)
    return rc


def _digits(values, least: int = 4) -> int:
    """Fewest significant digits (>= ``least``) that print distinct values
    distinctly (at most 17, which round-trips any float)."""
    vals = sorted({float(v) for v in values if v is not None})
    for p in range(least, 17):
        if len({f"{v:.{p}g}" for v in vals}) == len(vals):
            return p
    return 17


def _print_table(result) -> None:
    if "system" in result:  # the output DOFs in mm: q of the first contact means nothing at a blade tip
        gammas = (result["directions"][next(iter(result["directions"]))]["gamma"] if result["method"] == "time"
                  else [g for br in result["branches"] for g in br["gamma"]])
        from ..hb.results import JOINED

        report.print_system_table(result, _digits(gammas), JOINED)
        return
    if result["method"] == "time":
        dirs = list(result["directions"])
        g = result["directions"][dirs[0]]["gamma"]
        p = _digits(g)
        w = max(8, p + 6)
        print(f"{'gamma':<{w}s} " + "  ".join(f"{'q_' + d:>12s} {'status':>11s}" for d in dirs))
        for i, gi in enumerate(g):
            cells = []
            for d in dirs:
                r = result["directions"][d]
                a = r["amplitude_q"][i]
                cells.append(f"{'-' if a is None or r['status'][i] != 'periodic' else f'{a:.5g}':>12s} "
                             f"{report.status_cell(r, i):>11s}")
            print(f"{gi:<{w}.{p}g} " + "  ".join(cells))
        report.print_notes(result, p)
    else:
        from ..hb.results import JOINED

        print(f"status: {result['status']} {result['message']}")
        p = _digits([g for br in result["branches"] for g in br["gamma"]])
        w = max(8, p + 6)
        for br in result["branches"]:
            print(f"branch {br['branch']}: {len(br['gamma'])} points, folds at {br['folds']}")
            for g, a, s, ps in zip(br["gamma"], br["amplitude_q"], br["stable"], br["point_status"]):
                print(f"  {g:<{w}.{p}g} {a if a is not None else float('nan'):>12.5g} "
                      f"{'stable' if s else 'unstable':<8s}{'' if ps in JOINED else ' ' + ps}")
        for pk in result["peaks"]:
            q = float("nan") if pk["amplitude_q"] is None else pk["amplitude_q"]
            print(f"peak: gamma = {pk['gamma']:.6g}, q = {q:.6g} (branch {pk['branch']}"
                  f"{'' if pk['refined'] else ', not fully refined'})")
