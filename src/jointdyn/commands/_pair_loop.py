"""``jointdyn loop --model pair``: quasi-static loop of one interface node pair.

The pair (docs/model.md section 10) is driven by a prescribed relative
history from a CSV file (``--input``, columns t, u1, u2, g in s, m, m, m):
the tangential displacements along t1 and t2 and the normal approach g
(positive closes), with N = max(0, P + kn g), P = ``--preload``. Every
instant where ``P + kn g`` changes sign between two samples is inserted
(column ``inserted`` of loop.csv, ``n_inserted`` in --json). With
``--period`` the history is cut into cycles and the metrics are those of
the last full one; otherwise the whole history is one cycle.

The JSON gives the metrics of the last full cycle: ``energy_J``
(work of T over it), the fractions of it the pair sticks, slips and is
open, the largest |T| and the range of N over its samples.

``--out DIR`` receives ``loop.csv`` (columns t, u1, u2, g, T1, T2, N, state,
inserted) and ``loop.png`` (T1 against u1 and T2 against u2), each written
atomically after everything is computed. Bad input: one line on stderr,
exit status 2, no file written.
"""

from __future__ import annotations

import io
import json
import sys
from pathlib import Path

import numpy as np

#: options of the harmonic shorthand and of the contact laws, which a pair refuses
_REFUSED = ("amplitude", "frequency", "eta", "delta", "cycles", "steps_per_cycle", "n_ref", "law_param", "n")


def _validate(args) -> None:
    from .. import _validate as V

    given = ["--" + d.replace("_", "-") for d in _REFUSED if getattr(args, d, None) is not None]
    if given:
        raise ValueError(f"{', '.join(given)} cannot be combined with --model pair: the pair takes --kt, --kn, "
                         "--mu, --preload and its history from --input (t, u1, u2, g)")
    for opt, value in (("--kn", args.kn), ("--preload", args.preload), ("--input", args.input)):
        if value is None:
            raise ValueError(f"{opt} is required with --model pair")
    V.positive("--kt", args.kt)
    V.positive("--kn", args.kn)
    V.nonnegative("--mu", args.mu)
    V.nonnegative("--preload", args.preload)
    V.derived("--mu x --preload (slip force, N)", args.mu * args.preload)
    V.input_file("--input", args.input)
    if args.period is not None:
        V.positive("--period", args.period)
    if args.out is not None:
        V.output_dir("--out", args.out, files=("loop.csv", "loop.png"))


#: largest force, normal load or work a pair loop computes (N, N, J): the largest double over a
#: headroom for the sums of its steps and the products of its metrics
_HUGE = sys.float_info.max / 2.0**20


def _check_scales(args, u1, u2, g) -> None:
    """The forces and the work the history can produce stay finite: checked before computing, so that
    no overflow is computed as if valid (each bound names the options and the file's columns)."""
    with np.errstate(all="ignore"):
        span = float(np.ptp(u1)) + float(np.ptp(u2))
        force = args.kt * span  # the largest tangential force of a stuck pair
        normal = args.preload + args.kn * float(np.max(g))  # the largest normal load
        path = float(np.sum(np.abs(np.diff(u1))) + np.sum(np.abs(np.diff(u2))))
        work = min(force, args.mu * normal) * path  # the most work the tangential force can do
    for label, value in (
        ("--kt x the range of u1 and u2 of --input (tangential force, N)", force),
        ("--preload + --kn x the largest g of --input (normal load, N)", normal),
        ("the range of u1 and u2 of --input (m)", span),
        ("the tangential force x the path of u1 and u2 of --input (work, J)", work),
    ):
        if not value <= _HUGE:
            raise ValueError(f"{label} must be at most {_HUGE:.4g} (double precision, with headroom for sums), got "
                             f"{value:.4g}: reduce --kt, --kn, --preload or the values of --input")


def _report(args, res) -> dict:
    from ..laws import STATE_NAMES

    last = res.code[-1, 0]
    tol = 1e-9 * float(res.t[-1] - res.t[0])
    cyc = (res.t >= res.t_start_s - tol) & (res.t <= res.t_end_s + tol)  # the samples of the last full cycle
    T = res.T[cyc, 0]
    N = res.N[cyc, 0]
    report = {
        "model": "pair",
        "parameters": {"kt_N_per_m": args.kt, "kn_N_per_m": args.kn, "mu": args.mu, "preload_N": args.preload,
                       "input": str(args.input), "period_s": args.period},
        "status": str(res.status),
        "n_cycles": res.n_cycles,
        "cycle_is_period": args.period is not None,
        "t_start_s": res.t_start_s,
        "t_end_s": res.t_end_s,
        "energy_J": res.energy_J,
        "energy_per_cycle_J": res.energy_J,  # deprecated duplicate of energy_J, kept for one release
        "stick_fraction": float(res.stick_fraction[0]),
        "slip_fraction": float(res.slip_fraction[0]),
        "open_fraction": float(res.open_fraction[0]),
        "force_max_N": float(np.max(np.hypot(T[:, 0], T[:, 1]))),
        "normal_load_min_N": float(np.min(N)),
        "normal_load_max_N": float(np.max(N)),
        "final_state": STATE_NAMES[int(last)],
        "n_inserted": res.n_inserted,
    }
    duration = float(res.t[-1] - res.t[0])
    remainder = float(res.t[-1]) - res.t_end_s
    report["remainder_s"] = remainder if remainder > 1e-9 * duration else 0.0
    report["warnings"] = [] if res.status.value == "ok" else [res.status.message]
    return report


def _plot_png(args, res) -> bytes:
    from ..figures import pyplot

    plt = pyplot()
    fig, axes = plt.subplots(1, 2, figsize=(9.0, 4.0), dpi=120)
    sl = res.t >= res.t_start_s
    for k, ax in enumerate(axes):
        ax.plot(res.u[:, 0, k] * 1e3, res.T[:, 0, k], color="0.75", lw=0.8, label="whole history")
        ax.plot(res.u[sl, 0, k] * 1e3, res.T[sl, 0, k], color="C0", lw=1.5, label="last cycle")
        ax.set_xlabel(f"u{k + 1} (mm)")
        ax.set_ylabel(f"T{k + 1} (N)")
        ax.grid(True, alpha=0.3)
    axes[0].legend(fontsize=8)
    fig.suptitle(f"pair: kt={args.kt:g} N/m, kn={args.kn:g} N/m, mu={args.mu:g}, P={args.preload:g} N", fontsize=9)
    fig.tight_layout()
    buf = io.BytesIO()
    fig.savefig(buf, format="png")
    plt.close(fig)
    return buf.getvalue()


def _write_files(args, res) -> None:
    import pandas as pd

    from .._io import write_table_and_figure
    from ..laws import STATE_NAMES

    png = _plot_png(args, res)
    table = pd.DataFrame({"t": res.t, "u1": res.u[:, 0, 0], "u2": res.u[:, 0, 1], "g": res.g[:, 0],
                          "T1": res.T[:, 0, 0], "T2": res.T[:, 0, 1], "N": res.N[:, 0],
                          "state": np.asarray(STATE_NAMES, dtype=object)[res.code[:, 0].astype(np.intp)],
                          "inserted": res.inserted})
    write_table_and_figure(args.out, "loop", table, png)


def run(args) -> int:
    """``jointdyn loop --model pair``; ValueError for bad input (exit 2, no file)."""
    from ..drivers import cycle_count, interface_loop, read_pair_history_csv
    from ..interfaces import Interface

    _validate(args)
    pair = Interface(kt=args.kt, kn=args.kn, mu=args.mu, preload=args.preload, pairs=[[0, 1, 2, -1, -1, -1]])
    t, u1, u2, g = read_pair_history_csv(args.input, name="--input")
    if args.period is not None:
        cycle_count(t, args.period, name="--period")
    _check_scales(args, u1, u2, g)
    with np.errstate(all="ignore"):  # an overflow is refused below, in one line, not warned about
        res = interface_loop(pair, t, u1, u2, g, period=args.period)
        report = _report(args, res)
    finite = all(np.all(np.isfinite(a)) for a in (res.T, res.N)) and all(
        np.isfinite(v) for v in report.values() if isinstance(v, float))
    if not finite:
        raise ValueError("the parameters overflow double precision (a force, load or the work is not finite): "
                         "reduce --kt, --kn, --preload or the displacements of --input")
    text = json.dumps(report, allow_nan=False) if args.json else None
    if args.out is not None:
        _write_files(args, res)
    for w in report["warnings"]:
        print(f"jointdyn loop: warning: {w}", file=sys.stderr)
    if args.json:
        print(text)
        return 0
    print(f"jointdyn loop: pair, slip force mu P = {args.mu * args.preload:g} N, {res.n_cycles} cycle(s), "
          f"last [{res.t_start_s:g}, {res.t_end_s:g}] s")
    what = "energy per cycle " if args.period is not None else "work of T (whole)"
    print(f"  {what}  {report['energy_J']:.6g} J")
    print(f"  time fractions     stick {report['stick_fraction']:.4f}, slip {report['slip_fraction']:.4f}, "
          f"open {report['open_fraction']:.4f}")
    print(f"  max |T|            {report['force_max_N']:.6g} N; N in [{report['normal_load_min_N']:.6g}, "
          f"{report['normal_load_max_N']:.6g}] N")
    print(f"  rows               {res.t.size - res.n_inserted} from --input + {res.n_inserted} inserted")
    if args.out is not None:
        print(f"  wrote {Path(args.out) / 'loop.csv'}, {Path(args.out) / 'loop.png'}")
    return 0
