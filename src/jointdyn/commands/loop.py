"""``jointdyn loop``: quasi-static hysteresis loop of one contact law.

The tangential displacement and the normal load are prescribed, either by
the paper's harmonic shorthand (section 2.2, Figs 3-4)::

    x(t) = A sin(2 pi f t),   N(t) = N0 + eta N0 sin(2 pi f t + delta)

with N0 = ``--n-ref``, or by a CSV file (``--input``, columns t, x, N in s,
m, N). With ``--kn`` the normal load comes from a unilateral spring
N = max(0, N_ref + kn v) (MODEL.md section 1) driven by the normal motion
v = (eta N_ref / kn) sin(2 pi f t + delta): identical to the prescribed
load in contact, 0 instead of negative while separated, so the tangential
loop does not depend on kn.

Everything is computed first; ``--out DIR`` then receives ``loop.csv``
(columns t, x, N, T, state) and ``loop.png`` (T against x, separated samples
marked), each written atomically. Bad input is a ValueError: one line on
stderr, exit status 2, no file written.
"""

from __future__ import annotations

import io
import json
import math
from pathlib import Path

from .. import config
from ._law_args import add_law_arguments, law_params, model_help

NAME = "loop"
HELP = "quasi-static hysteresis loop of a contact law under prescribed tangential motion and normal load"


def add_arguments(p) -> None:
    from ..laws import law_names

    p.add_argument("--model", default="iwan", choices=law_names(), help=model_help("iwan"))
    add_law_arguments(p)
    p.add_argument("--kt", type=float, default=1e5, help="total tangential stiffness kt, N/m (default 1e5)")
    p.add_argument("--mu", type=float, default=0.1, help="friction coefficient mu (default 0.1)")
    p.add_argument("--n-ref", type=float, default=100.0, dest="n_ref",
                   help="reference normal load N_ref = N0, N (default 100); fy = mu N_ref")
    p.add_argument("--kn", type=float, default=None,
                   help="normal stiffness, N/m: N = max(0, N_ref + kn v) with prescribed normal motion "
                        "v = (eta N_ref / kn) sin(2 pi f t + delta) (default: N prescribed directly)")
    p.add_argument("--amplitude", type=float, default=0.5e-3, help="tangential amplitude A, m (default 0.5e-3)")
    p.add_argument("--frequency", type=float, default=1.0, help="frequency f, Hz (default 1)")
    p.add_argument("--eta", type=float, default=0.0, help="normal-load ratio N1 / N0 (default 0; > 1 separates)")
    p.add_argument("--delta", type=float, default=0.0, help="phase of the normal load, degrees (default 0)")
    p.add_argument("--cycles", type=int, default=config.QS_CYCLES,
                   help=f"number of cycles (default {config.QS_CYCLES}); metrics of the last one")
    p.add_argument("--steps-per-cycle", type=int, default=config.QS_STEPS_PER_CYCLE, dest="steps_per_cycle",
                   help=f"time steps per cycle (default {config.QS_STEPS_PER_CYCLE})")
    p.add_argument("--input", default=None, metavar="FILE.csv",
                   help="history from CSV with columns t, x, N (s, m, N), replacing the harmonic shorthand; "
                        "the whole history is then one cycle unless --period is given")
    p.add_argument("--period", type=float, default=None,
                   help="with --input: cycle length, s (default: whole history)")
    p.add_argument("--out", default=None, metavar="DIR", help="write DIR/loop.csv and DIR/loop.png")
    p.add_argument("--json", action="store_true", help="print the last full cycle's metrics as one JSON object")


def _validate_args(args):
    from .. import _validate as V

    V.positive("--kt", args.kt)
    V.nonnegative("--mu", args.mu)
    V.positive("--n-ref", args.n_ref)
    if args.kn is not None:
        V.positive("--kn", args.kn)
    V.positive("--amplitude", args.amplitude)
    V.positive("--frequency", args.frequency)
    V.nonnegative("--eta", args.eta)
    V.finite("--delta", args.delta)
    V.positive_int("--cycles", args.cycles, 1)
    V.positive_int("--steps-per-cycle", args.steps_per_cycle, 4)
    if args.period is not None:
        V.positive("--period", args.period)
        if args.input is None:
            raise ValueError("--period applies to --input only (the harmonic period is 1 / --frequency)")
    if args.input is not None and args.kn is not None:
        raise ValueError("--kn cannot be combined with --input: the CSV gives the normal load N directly")
    if args.out is not None:
        out = Path(args.out)
        if out.exists() and not out.is_dir():
            raise ValueError(f"--out must be a directory, got existing file {str(out)!r}")


def _plot_png(res, title) -> bytes:
    from ..figures import pyplot

    plt = pyplot()
    import numpy as np

    from ..laws import SEPARATION

    fig, ax = plt.subplots(figsize=(6.0, 4.5), dpi=120)
    ax.plot(res.x * 1e3, res.T, color="0.75", lw=0.8, label="whole history")
    sl = res.cycle_slice(-1)
    ax.plot(res.x[sl] * 1e3, res.T[sl], color="C0", lw=1.5, label="last cycle")
    sep = res.code == SEPARATION
    if np.any(sep):
        ax.plot(res.x[sep] * 1e3, res.T[sep], "x", color="C3", ms=3, label="separation (N <= 0)")
    ax.set_xlabel("x (mm)")
    ax.set_ylabel("T (N)")
    ax.set_title(title, fontsize=9)
    ax.grid(True, alpha=0.3)
    ax.legend(fontsize=8)
    fig.tight_layout()
    buf = io.BytesIO()
    fig.savefig(buf, format="png")
    plt.close(fig)
    return buf.getvalue()


def _jsonable(v):
    if isinstance(v, float) and not math.isfinite(v):
        return None
    return v


def run(args) -> int:
    import pandas as pd

    from .._io import atomic_path
    from ..drivers import harmonic_history, quasistatic, read_history_csv
    from ..laws import make_law

    _validate_args(args)
    lp = law_params(args)
    law = make_law(args.model, kt=args.kt, mu=args.mu, n_ref=args.n_ref, **lp)
    if args.input is not None:
        t, x, N = read_history_csv(args.input)
        period = args.period
    else:
        t, x, N = harmonic_history(
            args.amplitude, args.frequency, args.n_ref, eta=args.eta, delta=math.radians(args.delta),
            cycles=args.cycles, steps_per_cycle=args.steps_per_cycle, kn=args.kn,
        )
        period = 1.0 / args.frequency
    res = quasistatic(law, t, x, N, period=period)
    last = res.last_cycle()

    params = {"kt_N_per_m": args.kt, "mu": args.mu, "n_ref_N": args.n_ref, "fy_N": law.fy}
    params.update(lp)
    if args.input is not None:
        params.update(input=str(args.input), period_s=period)
    else:
        params.update(
            amplitude_m=args.amplitude, frequency_Hz=args.frequency, n0_N=args.n_ref, eta=args.eta,
            delta_deg=args.delta, cycles=args.cycles, steps_per_cycle=args.steps_per_cycle, kn_N_per_m=args.kn,
        )
    report = {"model": args.model, "parameters": params, "n_cycles": res.n_cycles, **last}
    report["cycle_is_period"] = period is not None
    report = {k: _jsonable(v) for k, v in report.items()}

    # everything computed: now the files, each atomically
    if args.out is not None:
        title = f"{args.model}: kt={args.kt:g} N/m, mu={args.mu:g}, N_ref={args.n_ref:g} N"
        if args.input is None:
            title += f", eta={args.eta:g}, delta={args.delta:g} deg"
        png = _plot_png(res, title)
        table = pd.DataFrame({"t": res.t, "x": res.x, "N": res.N, "T": res.T, "state": res.state})
        csv_text = table.to_csv(index=False, float_format="%.17g")
        out = Path(args.out)
        with atomic_path(out / "loop.csv") as tmp:
            Path(tmp).write_text(csv_text)
        with atomic_path(out / "loop.png") as tmp:
            Path(tmp).write_bytes(png)

    if args.json:
        print(json.dumps(report, allow_nan=False))
    else:
        what = "last cycle" if period is not None else "whole history (work done)"
        print(f"jointdyn loop: {args.model}, fy = {law.fy:g} N, {res.n_cycles} cycle(s), {what} "
              f"[{last['t_start_s']:g}, {last['t_end_s']:g}] s")
        print(f"  energy per cycle   {last['energy_per_cycle_J']:.6g} J")
        print(f"  force min / max    {last['force_min_N']:.6g} / {last['force_max_N']:.6g} N")
        print(f"  secant stiffness   {last['secant_stiffness_N_per_m']:.6g} N/m")
        print(f"  loss factor        {last['loss_factor']:.6g}")
        print(f"  time fractions     stick-slip {last['stick_slip_fraction']:.4f}, "
              f"macroslip {last['macroslip_fraction']:.4f}, separation {last['separation_fraction']:.4f}")
        if args.out is not None:
            print(f"  wrote {Path(args.out) / 'loop.csv'}, {Path(args.out) / 'loop.png'}")
    return 0
