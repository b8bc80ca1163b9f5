"""``jointdyn loop``: quasi-static hysteresis loop of one contact law.

The tangential displacement and the normal load are prescribed, either by
the paper's harmonic shorthand (section 2.2, Figs 3-4)::

    x(t) = A sin(2 pi f t),   N(t) = N0 + eta N0 sin(2 pi f t + delta)

with N0 = ``--n-ref``, or by a CSV file (``--input``, columns t, x, N in s,
m, N). With ``--kn`` the normal load comes from a unilateral spring
N = max(0, N_ref + kn v) (docs/model.md section 1) driven by the normal motion
v = (eta N_ref / kn) sin(2 pi f t + delta): identical to the prescribed
load in contact, 0 instead of negative while separated, so the tangential
loop does not depend on kn.

With ``--input``, the instants where N changes sign between two samples
are inserted into the history (N = 0 there, x linear), so ``loop.csv`` has
more rows than the input: its boolean column ``inserted`` marks them, and
the console and ``--json`` (``n_inserted``) say how many. A ``--period``
that does not divide the history leaves a remainder that is not analysed
(``remainder_s``); a reported cycle in which the contact never closes gets
a warning on stderr and in ``warnings``.

``--model pair`` is one interface node pair with 2-D slip (docs/model.md
section 10) under a relative history from ``--input`` (columns t, u1, u2,
g), with ``--kt``, ``--kn``, ``--mu`` and ``--preload``: see
:mod:`jointdyn.commands._pair_loop`.

Everything is validated, computed and serialised first; ``--out DIR`` then
receives ``loop.csv`` (columns t, x, N, T, state, inserted) and ``loop.png``
(T against x, separated samples marked), each written atomically. Bad input
(options, the CSV file, an unwritable ``--out``, sizes beyond the limits,
derived quantities that overflow) is a ValueError: one line on stderr, exit
status 2, no file written.
"""

from __future__ import annotations

import io
import json
import sys
from pathlib import Path

import numpy as np

from .. import config
from .._io import jsonable as _jsonable
from ._law_args import add_law_arguments, law_params, model_help

NAME = "loop"
HELP = "quasi-static hysteresis loop of a contact law under prescribed tangential motion and normal load"

#: default of --n-ref, N (a contact law's reference load; refused with --model pair)
_N_REF = 100.0
#: defaults of the harmonic shorthand (refused with --input)
_HARMONIC = {
    "amplitude": 0.5e-3,
    "frequency": 1.0,
    "eta": 0.0,
    "delta": 0.0,
    "cycles": config.QS_CYCLES,
    "steps_per_cycle": config.QS_STEPS_PER_CYCLE,
}


def add_arguments(p) -> None:
    from ..laws import law_names

    p.add_argument("--model", default=config.MODEL, choices=[*law_names(), "pair"],
                   help=model_help(config.MODEL) + "; pair: one interface node pair with 2-D slip and the normal "
                        "load max(0, P + kn g) (docs/model.md section 10), driven by --input with columns "
                        "t, u1, u2, g and needing --kn and --preload")
    add_law_arguments(p)
    p.add_argument("--kt", type=float, default=1e5, help="total tangential stiffness kt, N/m (default 1e5)")
    p.add_argument("--mu", type=float, default=0.1, help="friction coefficient mu (default 0.1)")
    p.add_argument("--n-ref", type=float, default=None, dest="n_ref",
                   help=f"reference normal load N_ref = N0, N (default {_N_REF:g}); fy = mu N_ref")
    p.add_argument("--preload", type=float, default=None,
                   help="with --model pair: the pair's normal load at rest P, N (N = max(0, P + kn g))")
    p.add_argument("--kn", type=float, default=None,
                   help="normal stiffness, N/m: N = max(0, N_ref + kn v) with prescribed normal motion "
                        "v = (eta N_ref / kn) sin(2 pi f t + delta) (default: N prescribed directly); "
                        "with --model pair the pair's normal stiffness (required)")
    p.add_argument("--amplitude", type=float, default=None,
                   help=f"tangential amplitude A, m (default {_HARMONIC['amplitude']:g})")
    p.add_argument("--frequency", type=float, default=None,
                   help=f"frequency f, Hz (default {_HARMONIC['frequency']:g})")
    p.add_argument("--eta", type=float, default=None,
                   help=f"normal-load ratio N1 / N0 (default {_HARMONIC['eta']:g}; > 1 separates)")
    p.add_argument("--delta", type=float, default=None,
                   help=f"phase of the normal load, degrees (default {_HARMONIC['delta']:g})")
    p.add_argument("--cycles", type=int, default=None,
                   help=f"number of cycles (default {_HARMONIC['cycles']}); metrics of the last one")
    p.add_argument("--steps-per-cycle", type=int, default=None, dest="steps_per_cycle",
                   help=f"time steps per cycle (default {_HARMONIC['steps_per_cycle']}; "
                        f"--cycles x --steps-per-cycle <= {config.QS_MAX_SAMPLES})")
    p.add_argument("--input", default=None, metavar="FILE.csv",
                   help="history from CSV with columns t, x, N (s, m, N; headers such as 't [s]' or 'time' "
                        "and ',', ';', tab or space separators are accepted), replacing the harmonic shorthand "
                        "(--amplitude, --frequency, --eta, --delta, --cycles, --steps-per-cycle, --kn are then "
                        "refused); the whole history is one cycle unless --period is given. The instants where N "
                        "changes sign between two samples are inserted as rows of loop.csv, marked in its "
                        "column 'inserted' (n_inserted in --json)")
    p.add_argument("--period", type=float, default=None,
                   help="with --input: cycle length, s (default: whole history); a remainder shorter than "
                        "--period at the end is not analysed (reported)")
    p.add_argument("--out", default=None, metavar="DIR",
                   help="write DIR/loop.csv (columns t, x, N, T, state, inserted) and DIR/loop.png")
    p.add_argument("--json", action="store_true", help="print the last full cycle's metrics as one JSON object")


def _option(dest: str) -> str:
    return "--" + dest.replace("_", "-")


def _check_sources(args) -> None:
    """The harmonic shorthand and --input exclude each other; fill the
    shorthand's defaults."""
    if args.input is not None:
        given = [_option(d) for d in (*_HARMONIC, "kn") if getattr(args, d) is not None]
        if given:
            raise ValueError(
                f"{', '.join(given)} cannot be combined with --input: the CSV gives the whole history "
                "(t, x, N); drop them or drop --input"
            )
        return
    if args.period is not None:
        raise ValueError("--period applies to --input only (the harmonic period is 1 / --frequency)")
    for dest, value in _HARMONIC.items():
        if getattr(args, dest) is None:
            setattr(args, dest, value)


def _check_derived(args) -> None:
    """Quantities computed from several options: no overflow, no size
    beyond the limits (checked before anything is allocated)."""
    from .. import _validate as V

    fy = V.derived("fy = --mu x --n-ref", args.mu * args.n_ref, positive=args.mu > 0.0)
    if args.input is not None:
        return
    V.count_at_most("--cycles x --steps-per-cycle", float(args.cycles) * args.steps_per_cycle,
                    config.QS_MAX_SAMPLES, "samples")
    V.derived("--cycles / --frequency (duration, s)", args.cycles / args.frequency)
    V.derived("--eta x --n-ref (normal-load amplitude, N)", args.eta * args.n_ref)
    V.derived("--kt x --amplitude (elastic force, N)", args.kt * args.amplitude)
    if fy > 0.0:
        V.derived("--kt x --amplitude / fy (normalised displacement)", args.kt * args.amplitude / fy)
    if args.kn is not None:
        V.derived("--eta x --n-ref / --kn (normal motion, m)", args.eta * args.n_ref / args.kn)


def _validate_args(args):
    from .. import _validate as V

    _check_sources(args)
    V.positive("--kt", args.kt)
    V.nonnegative("--mu", args.mu)
    V.positive("--n-ref", args.n_ref)
    if args.kn is not None:
        V.positive("--kn", args.kn)
    if args.input is None:
        V.positive("--amplitude", args.amplitude)
        V.positive("--frequency", args.frequency)
        V.nonnegative("--eta", args.eta)
        V.finite("--delta", args.delta)
        V.positive_int("--cycles", args.cycles, 1)
        V.positive_int("--steps-per-cycle", args.steps_per_cycle, 4)
    else:
        V.input_file("--input", args.input)
    if args.period is not None:
        V.positive("--period", args.period)
    _check_derived(args)
    if args.out is not None:
        V.output_dir("--out", args.out, files=("loop.csv", "loop.png"))


def _plot_png(res, title) -> bytes:
    from ..figures import pyplot, use_math_text
    from ._frc_report import wrap

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
    ax.set_title(wrap(title, 75), fontsize=9)
    ax.grid(True, alpha=0.3)
    ax.legend(fontsize=8)
    use_math_text(fig)
    fig.tight_layout()
    buf = io.BytesIO()
    fig.savefig(buf, format="png")
    plt.close(fig)
    return buf.getvalue()


def _history(args, law):
    """The prescribed history and the cycle length (None: one window),
    validated before the march."""
    from .. import _validate as V
    from ..drivers import cycle_count, harmonic_history, read_history_csv

    if args.input is None:
        t, x, N = harmonic_history(
            args.amplitude, args.frequency, args.n_ref, eta=args.eta, delta_deg=args.delta,
            cycles=args.cycles, steps_per_cycle=args.steps_per_cycle, kn=args.kn,
        )
        return t, x, N, 1.0 / args.frequency
    t, x, N = read_history_csv(args.input, name="--input")
    if args.period is not None:
        cycle_count(t, args.period, name="--period")
    if law.fy > 0.0:
        xmax = float(np.max(np.abs(x)))
        V.derived("--kt x max|x| / fy (normalised displacement of --input)", args.kt * xmax / law.fy)
    return t, x, N, args.period


def _notes(args, res, period) -> dict:
    """What the user must know about the history actually analysed: rows
    inserted, an unanalysed remainder, a contact that never closes."""
    last = res.last_cycle()
    duration = float(res.t[-1] - res.t[0])
    remainder = float(res.t[-1]) - last["t_end_s"]
    if remainder <= config.QS_SNAP_RTOL * duration:
        remainder = 0.0
    warnings = []
    sl = res.cycle_slice(-1)
    if np.all(res.N[sl] <= 0.0):
        what = "reported cycle" if period is not None else "history"
        warnings.append(f"the contact never closes (N <= 0 throughout the {what}): energy, forces and "
                        "stiffness are 0")
    return {"n_inserted": int(res.n_inserted), "remainder_s": remainder, "warnings": warnings}


def _report(args, law, res, period, lp) -> dict:
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
    report.update(_notes(args, res, period))
    return {k: _jsonable(v) for k, v in report.items()}


def _write_files(args, res) -> None:
    """loop.png and loop.csv, each atomically (everything is computed)."""
    import pandas as pd

    from .._io import write_table_and_figure

    title = f"{args.model}: kt={args.kt:g} N/m, mu={args.mu:g}, N_ref={args.n_ref:g} N"
    if args.input is None:
        title += f", eta={args.eta:g}, delta={args.delta:g} deg"
    png = _plot_png(res, title)
    table = pd.DataFrame({"t": res.t, "x": res.x, "N": res.N, "T": res.T, "state": res.state,
                          "inserted": res.inserted})
    write_table_and_figure(args.out, "loop", table, png)


def _print_console(args, law, res, report, period) -> None:
    what = "last cycle" if period is not None else "whole history (work done)"
    print(f"jointdyn loop: {args.model}, fy = {law.fy:g} N, {res.n_cycles} cycle(s), {what} "
          f"[{report['t_start_s']:g}, {report['t_end_s']:g}] s")
    print(f"  energy per cycle   {report['energy_J']:.6g} J")
    print(f"  force min / max    {report['force_min_N']:.6g} / {report['force_max_N']:.6g} N")
    ksec, loss = report["secant_stiffness_N_per_m"], report["loss_factor"]
    print(f"  secant stiffness   {float('nan') if ksec is None else ksec:.6g} N/m")
    print(f"  loss factor        {float('nan') if loss is None else loss:.6g}")
    print(f"  time fractions     stick-slip {report['stick_slip_fraction']:.4f}, "
          f"macroslip {report['macroslip_fraction']:.4f}, separation {report['separation_fraction']:.4f}")
    if args.input is not None:
        n_in = res.t.size - res.n_inserted
        where = "; column 'inserted' of loop.csv" if args.out is not None else ""
        print(f"  rows               {n_in} from --input + {res.n_inserted} inserted (N = 0 crossings{where})")
    if report["remainder_s"] > 0.0:
        print(f"  not analysed       the last {report['remainder_s']:g} s (after t = {report['t_end_s']:g} s): "
              "shorter than --period")
    if args.out is not None:
        print(f"  wrote {Path(args.out) / 'loop.csv'}, {Path(args.out) / 'loop.png'}")


def run(args) -> int:
    from ..drivers import quasistatic
    from ..laws import make_law

    if args.model == "pair":
        from ._pair_loop import run as run_pair

        return run_pair(args)
    if args.preload is not None:
        raise ValueError("--preload applies to --model pair only (a contact law's reference load is --n-ref)")
    if args.n_ref is None:
        args.n_ref = _N_REF
    _validate_args(args)
    lp = law_params(args)
    law = make_law(args.model, kt=args.kt, mu=args.mu, n_ref=args.n_ref, **lp)
    t, x, N, period = _history(args, law)
    res = quasistatic(law, t, x, N, period=period)
    if not np.all(np.isfinite(res.T)):
        raise ValueError("the parameters overflow double precision (the force T is not finite): "
                         "reduce --kt or --amplitude, or raise --mu x --n-ref")
    report = _report(args, law, res, period, lp)
    text = json.dumps(report, allow_nan=False) if args.json else None
    # everything computed and serialised: now the files, each atomically
    if args.out is not None:
        _write_files(args, res)
    for w in report["warnings"]:
        print(f"jointdyn loop: warning: {w}", file=sys.stderr)
    if args.json:
        print(text)
    else:
        _print_console(args, law, res, report, period)
    return 0
