"""``jointdyn frc``: frequency-response curve of the paper's friction damper.

Time domain (``--method time``, default): steady states swept up and/or down
in gamma with warm starts (:func:`jointdyn.sweeps.frc_sweep`). Harmonic
balance (``--method hb``): :func:`jointdyn.hb.frc_hb` continuation.
Everything is validated before computing; ``--out`` files (``frc.nc``,
``frc.csv``, ``frc.png``) are written atomically after computing (time-domain
sweep lines are also saved one by one under ``OUT/lines`` so that an
interrupted run resumes).
"""

from __future__ import annotations

import json
import math
from pathlib import Path

import numpy as np

from .. import _validate as V
from .. import config
from ..systems import PAPER

NAME = "frc"
HELP = "frequency-response curve (steady amplitude vs gamma) of the paper's friction damper"


def add_arguments(p) -> None:
    g0 = ":".join(f"{v:g}" for v in config.SWEEP_GAMMA_DEFAULT)
    p.add_argument("--method", default="time", help="time (time-domain steady states, default) or hb (harmonic balance)")
    p.add_argument("--eta", type=float, default=0.5, help="N1/N0, normal-load oscillation ratio (>= 0; default 0.5)")
    load = p.add_mutually_exclusive_group()
    load.add_argument("--beta", type=float, default=None, help="mu N0 / F1 (> 0; default 1.0)")
    load.add_argument("--f1", type=float, default=None, help="forcing amplitude F1 in N (> 0), instead of --beta")
    p.add_argument("--gamma", default=g0, metavar="START:STOP:STEP",
                   help=f"frequency-ratio grid gamma = w/w0 (default {g0})")
    p.add_argument("--delta", type=float, default=0.0, help="normal-load phase, degrees (default 0)")
    p.add_argument("--sweep", default="both", help="up, down or both (default both)")
    p.add_argument("--model", default="iwan", help="contact law: iwan, iwan-paper, discrete, jenkins (default iwan)")
    p.add_argument("--n", type=int, default=config.LAW_DISCRETE_N,
                   help=f"elements of the discrete law (default {config.LAW_DISCRETE_N})")
    p.add_argument("--zeta", type=float, default=0.0, help="viscous damping ratio (default 0)")
    p.add_argument("--m", type=float, default=PAPER["m"], help=f"mass, kg (default {PAPER['m']:g})")
    p.add_argument("--k", type=float, default=PAPER["k"], help=f"stiffness, N/m (default {PAPER['k']:g})")
    p.add_argument("--kt", type=float, default=PAPER["kt"], help=f"tangential contact stiffness, N/m (default {PAPER['kt']:g})")
    p.add_argument("--kn", type=float, default=PAPER["kn"],
                   help=f"normal contact stiffness, N/m (default {PAPER['kn']:g}); recorded only: the damper's "
                        "normal load is prescribed, N = N0 + N1 sin(w t + delta)")
    p.add_argument("--mu", type=float, default=PAPER["mu"], help=f"friction coefficient (default {PAPER['mu']:g})")
    p.add_argument("--n0", type=float, default=PAPER["n0"], help=f"static normal load N0, N (default {PAPER['n0']:g})")
    p.add_argument("--steps-per-period", type=int, default=None, help="time steps per forcing period (solver default)")
    p.add_argument("--scheduler", default=None, metavar="ADDRESS", help="run the sweep lines on this Dask scheduler")
    p.add_argument("--workers", type=int, default=None, help="local parallel workers (default: all cores)")
    p.add_argument("--harmonics", type=int, default=config.HB_HARMONICS,
                   help=f"hb: number of harmonics (default {config.HB_HARMONICS})")
    p.add_argument("--samples", type=int, default=config.HB_SAMPLES,
                   help=f"hb: time samples per period (default {config.HB_SAMPLES})")
    p.add_argument("--out", default=None, metavar="DIR", help="write frc.nc, frc.csv, frc.png here")
    p.add_argument("--json", action="store_true", help="print one JSON object instead of a table")


def parse_gamma(text: str) -> np.ndarray:
    """``START:STOP:STEP`` -> increasing grid (STOP included when on the grid)."""
    parts = str(text).split(":")
    if len(parts) != 3:
        raise ValueError(f"--gamma must be START:STOP:STEP, got {text!r}")
    try:
        start, stop, step = (float(s) for s in parts)
    except ValueError:
        raise ValueError(f"--gamma must be START:STOP:STEP of numbers, got {text!r}") from None
    V.positive("--gamma START", start)
    V.positive("--gamma STEP", step)
    V.finite("--gamma STOP", stop)
    if not stop >= start:
        raise ValueError(f"--gamma STOP must be >= START ({start:g}), got {stop:g}")
    count = int(math.floor((stop - start) / step + 1e-9)) + 1
    if count > 100000:
        raise ValueError(f"--gamma must have at most 100000 points, got {count}")
    return np.round(start + step * np.arange(count), 12)


def _jsonable(values):
    out = []
    for v in np.asarray(values).tolist():
        if isinstance(v, float) and not math.isfinite(v):
            out.append(None)
        else:
            out.append(v)
    return out


def _validate(args):
    from ..laws import law_names

    V.choice("--method", args.method, ("time", "hb"))
    V.choice("--sweep", args.sweep, ("up", "down", "both"))
    V.choice("--model", args.model, law_names())
    gammas = parse_gamma(args.gamma)
    V.nonnegative("--eta", args.eta)
    if args.f1 is not None:
        V.positive("--f1", args.f1)
    else:
        args.beta = V.positive("--beta", 1.0 if args.beta is None else args.beta)
    V.finite("--delta", args.delta)
    V.positive_int("--n", args.n)
    V.nonnegative("--zeta", args.zeta)
    for key in ("m", "k", "kt", "kn", "mu", "n0"):
        V.positive(f"--{key}", getattr(args, key))
    if args.steps_per_period is not None:
        V.positive_int("--steps-per-period", args.steps_per_period, 8)
    if args.workers is not None:
        V.positive_int("--workers", args.workers)
    V.positive_int("--harmonics", args.harmonics)
    V.positive_int("--samples", args.samples, 4)
    if args.out is not None and Path(args.out).exists() and not Path(args.out).is_dir():
        raise ValueError(f"--out must be a directory, got existing file {args.out!r}")
    return gammas


def _header(args) -> dict:
    head = {"method": args.method, "eta": args.eta}
    if args.f1 is not None:
        head["f1"] = args.f1
        head["beta"] = args.mu * args.n0 / args.f1
    else:
        head["beta"] = args.beta
        head["f1"] = args.mu * args.n0 / args.beta
    head.update(delta_deg=args.delta, model=args.model, n=args.n, zeta=args.zeta,
                m=args.m, k=args.k, kt=args.kt, kn=args.kn, mu=args.mu, n0=args.n0)
    return head


def _run_time(args, gammas):
    from ..sweeps import frc_sweep, status_name

    directions = ("up", "down") if args.sweep == "both" else (args.sweep,)
    client = None
    if args.scheduler:
        from distributed import Client

        client = Client(args.scheduler)
    try:
        ds = frc_sweep(
            gammas,
            etas=[args.eta],
            betas=None if args.f1 is not None else [args.beta],
            f1s=None if args.f1 is None else [args.f1],
            deltas=[args.delta],
            directions=directions,
            model=args.model,
            n=args.n,
            zeta=args.zeta,
            m=args.m, k=args.k, kt=args.kt, mu=args.mu, n0=args.n0,
            steps_per_period=args.steps_per_period,
            client=client,
            n_workers=args.workers,
            out=None if args.out is None else Path(args.out),
            progress=not args.json,
        )
    finally:
        if client is not None:
            client.close()
    ds.attrs["kn"] = float(args.kn)
    load = "beta" if args.f1 is None else "f1"
    line = ds.isel(eta=0, delta=0, **{load: 0})
    result = _header(args)
    result["directions"] = {}
    for d in directions:
        one = line.sel(direction=d)
        result["directions"][d] = {
            "gamma": _jsonable(one.gamma.values),
            **{v: _jsonable(one[v].values) for v in ("amplitude_q", "amplitude_m", "offset_m", "max_abs_m")},
            "status": [status_name(c) for c in one.status.values],
        }
    return ds, result


def _hb_branches(ds) -> list:
    """Split an hb Dataset (dim ``point``) into its branches (variable ``branch``: segment index)."""
    ids = np.asarray(ds["branch"].values)
    out = []
    for b in dict.fromkeys(ids.tolist()):
        sub = ds.isel(point=np.flatnonzero(ids == b))
        br = {v: _jsonable(sub[v].values) for v in ("gamma", "amplitude_q", "amplitude_m", "offset_m", "max_abs_m")}
        br["stable"] = [bool(s) for s in np.asarray(sub["stable"].values)]
        br["folds"] = [int(i) for i in np.flatnonzero(np.asarray(sub["fold"].values, bool))]
        out.append(br)
    return out


def _run_hb(args, gammas):
    from ..hb import frc_hb
    from ..systems import System

    system = System.paper_damper(
        eta=args.eta,
        beta=args.beta if args.f1 is None else 1.0,
        f1=args.f1,
        delta=math.radians(args.delta),
        model=args.model,
        zeta=args.zeta,
        n=args.n,
        m=args.m, k=args.k, kt=args.kt, mu=args.mu, n0=args.n0,
    )
    if gammas.size < 2:
        raise ValueError("--gamma must span a range (STOP > START) for --method hb")
    ds = frc_hb(system, float(gammas[0]), float(gammas[-1]), harmonics=args.harmonics, samples=args.samples,
                progress=None if not args.json else False)
    result = _header(args)
    result["harmonics"] = args.harmonics
    result["samples"] = args.samples
    result["branches"] = _hb_branches(ds)
    result["status"] = str(ds.attrs.get("status", ""))
    result["message"] = str(ds.attrs.get("message", ""))
    return ds, result


def _plot(result, path: Path) -> None:
    from ..figures import pyplot

    plt = pyplot()

    from .._io import atomic_path
    from ..sweeps._plot import mark_legend, plot_frc_curve

    fig, ax = plt.subplots(figsize=(6.4, 4.2))
    if result["method"] == "time":
        for d, style in (("up", "-"), ("down", "--")):
            if d not in result["directions"]:
                continue
            r = result["directions"][d]
            amp = np.array([np.nan if v is None else v for v in r["amplitude_q"]], float)
            codes = [config.SWEEP_STATUS.index(s) for s in r["status"]]
            plot_frc_curve(ax, r["gamma"], amp, codes, color="C0" if d == "up" else "C3",
                           linestyle=style, label=f"sweep {d}", rug_y=0.03 if d == "up" else 0.07)
        mark_legend(ax, fontsize=8)
    else:
        for i, br in enumerate(result["branches"]):
            g = np.array(br["gamma"], float)
            a = np.array([np.nan if v is None else v for v in br["amplitude_q"]], float)
            st = np.array(br["stable"], bool)
            ax.plot(g, np.where(st, a, np.nan), "-", color="C0", label="stable" if i == 0 else None)
            ax.plot(g, np.where(~st, a, np.nan), "--", color="C1", label="unstable" if i == 0 else None)
            if br["folds"]:
                ax.plot(g[br["folds"]], a[br["folds"]], "ks", ms=4, label="fold" if i == 0 else None)
        ax.legend(fontsize=8)
    load = f"beta = {result['beta']:g}" if result.get("beta") is not None else ""
    ax.set_title(f"{result['method']}: eta = {result['eta']:g}, {load}, delta = {result['delta_deg']:g} deg, "
                 f"{result['model']}", fontsize=9)
    ax.set_xlabel("gamma = w / w0")
    ax.set_ylabel("amplitude of q = kt x / fy (half peak-to-peak)")
    ax.grid(alpha=0.3)
    fig.tight_layout()
    with atomic_path(path) as tmp:
        fig.savefig(tmp, dpi=120)
    plt.close(fig)


def run(args) -> int:
    gammas = _validate(args)
    if args.method == "time":
        ds, result = _run_time(args, gammas)
    else:
        ds, result = _run_hb(args, gammas)
    if args.out is not None:
        out = Path(args.out)
        if args.method == "time":
            from ..sweeps import write_outputs

            write_outputs(ds, out)
        else:
            from .._io import atomic_path

            with atomic_path(out / "frc.nc") as tmp:
                ds.to_netcdf(tmp, engine="scipy")
            with atomic_path(out / "frc.csv") as tmp:  # one row per point (per-harmonic data in frc.nc)
                flat = ds.drop_dims([d for d in ds.dims if d != "point"])
                flat.to_dataframe().reset_index().to_csv(tmp, index=False)
        _plot(result, out / "frc.png")
    if args.json:
        print(json.dumps(result))
    else:
        _print_table(result)
    return 0


def _print_table(result) -> None:
    if result["method"] == "time":
        dirs = list(result["directions"])
        print("gamma    " + "  ".join(f"{'q_' + d:>12s} {'status':>11s}" for d in dirs))
        g = result["directions"][dirs[0]]["gamma"]
        for i, gi in enumerate(g):
            cells = []
            for d in dirs:
                r = result["directions"][d]
                a = r["amplitude_q"][i]
                cells.append(f"{'-' if a is None or r['status'][i] != 'periodic' else f'{a:.5g}':>12s} "
                             f"{r['status'][i]:>11s}")
            print(f"{gi:<8.4g} " + "  ".join(cells))
    else:
        print(f"status: {result['status']} {result['message']}")
        for b, br in enumerate(result["branches"]):
            print(f"branch {b}: {len(br['gamma'])} points, folds at {br['folds']}")
            for g, a, s in zip(br["gamma"], br["amplitude_q"], br["stable"]):
                print(f"  {g:<8.4g} {a if a is not None else float('nan'):>12.5g} {'stable' if s else 'unstable'}")
