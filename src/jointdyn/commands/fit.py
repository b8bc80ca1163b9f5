"""``jointdyn fit``: identify a joint model from measured loops or a measured backbone.

Two forms::

    jointdyn fit --input LOOPS.csv --model MODEL [--json] [--out DIR]
    jointdyn fit --backbone BACKBONE.csv --model MODEL --mass KG [--json] [--out DIR]
    jointdyn fit --ringdown DECAY.csv --model MODEL --mass KG [--json] [--out DIR]
    jointdyn fit --frc CURVES.csv --model MODEL --mass KG [--json] [--out DIR]

``--input``: a CSV file with a header row and the columns ``t, x, N, T`` (s,
m, N, N): a fretting-rig record, one or several cycles, from rest or picked
up anywhere in a steady cycle (its first stroke then sets the slip state). The law's
force under the measured x and N is fitted to T by least squares
(:func:`jointdyn.fit_loops`). ``--backbone``: columns ``amplitude_m,
omega_rad_s, damping_ratio`` of one mode of modal mass ``--mass``, fitted
with a modal Iwan model by the describing function
(:func:`jointdyn.fit_backbone`). ``--ringdown``: columns ``t`` and one of
``x``, ``v``, ``a`` of a free decay, turned into such a backbone
(:func:`jointdyn.backbone_from_ringdown`; with ``--out``, also written as
``ringdown_backbone.csv``) and fitted the same way, the determined combinations then again
to the decay's windows (:func:`jointdyn.identify.fit_ringdown`: intervals the record
justifies, and the amplitudes over which it determines the damping ratio within 5 %, to which
``ringdown_backbone.csv`` is trimmed; ``damping_range`` in ``fit.json``). ``--frc``: columns
``force_N, omega_rad_s, amplitude_m`` of stepped-sine response curves at
several force levels (:func:`jointdyn.fit_frc`).

The console (or ``--json``: keys ``parameters``, ``standard_errors``,
``rms_residual``, ``status``, ``intervals``, ``determined_combinations``,
``record_start`` and more) gives every parameter with its standard error and
its 95 % profile-likelihood interval, or why the data do not determine it and
the combinations they do determine. Displacements implausible in metres (a
file in mm) are refused. ``--out DIR`` receives
``fit.json``, ``fit.csv`` (measured and fitted columns) and ``fit.png``
(measured and fitted overlaid, and the residuals), each written atomically
after everything is computed. Bad input: one line on stderr, exit status 2,
no file written; a fit that does not determine every parameter, or does not
converge, exits with status 3 (its results are still written).
"""

from __future__ import annotations

import io
import json
import sys
from pathlib import Path

import numpy as np

from .. import config
from .._exit import EXIT_INCOMPLETE
from ._law_args import add_law_arguments, law_params

#: jointdyn fit: largest plausible joint displacement of a loop record and modal amplitude of
#: a backbone, m (beyond them the file is taken to be in other units, e.g. mm)
FIT_PLAUSIBLE_DISPLACEMENT_M = 0.01
FIT_PLAUSIBLE_AMPLITUDE_M = 0.1

NAME = "fit"
HELP = "identify a joint model (kt, mu, chi, beta, ...) from measured loops (t, x, N, T) or a backbone"

LOOP_COLUMNS = ("t", "x", "N", "T")
BACKBONE_COLUMNS = ("amplitude_m", "omega_rad_s", "damping_ratio")
_FILES = ("fit.json", "fit.csv", "fit.png")


def add_arguments(p) -> None:
    from ..identify import LOOP_MODELS

    src = p.add_mutually_exclusive_group(required=True)
    src.add_argument("--input", default=None, metavar="FILE.csv",
                     help="measured loops: CSV with columns t, x, N, T (s, m, N, N)")
    src.add_argument("--backbone", default=None, metavar="FILE.csv",
                     help="measured backbone: CSV with columns amplitude_m, omega_rad_s, damping_ratio")
    src.add_argument("--ringdown", default=None, metavar="FILE.csv",
                     help="free decay of one mode: CSV with columns t and one of x, v, a (s; m, m/s, m/s^2), "
                          "turned into a backbone and fitted (needs --mass)")
    src.add_argument("--frc", default=None, metavar="FILE.csv",
                     help="stepped-sine response curves: CSV with columns force_N, omega_rad_s, amplitude_m "
                          "(several force levels; needs --mass)")
    p.add_argument("--model", default=config.MODEL, choices=LOOP_MODELS,
                   help=f"joint law to fit (default {config.MODEL})")
    add_law_arguments(p)
    p.add_argument("--mass", type=float, default=None, help="modal mass of the backbone's mode, kg (--backbone)")
    p.add_argument("--band", default=None, metavar="LOW:HIGH",
                   help="pass band of the ring-down's mode, Hz (--ringdown; default: around the spectrum's "
                        "peak); give it when the decay's frequency drifts enough to show two peaks")
    p.add_argument("--n-ref", type=float, default=None, dest="n_ref",
                   help="reference normal load of a loop fit, N (default: mean N in contact); fy_N = mu n_ref")
    p.add_argument("--out", default=None, metavar="DIR", help="write fit.json, fit.csv and fit.png here")
    p.add_argument("--json", action="store_true", help="print the result as one JSON object")


def read_columns(path, columns, name: str) -> dict:
    """The named columns of a CSV file with a header row, as float arrays (jointdyn's one CSV
    reader, :mod:`jointdyn.files.tables`: BOM, ``;`` separators and unit rows accepted).

    Raises
    ------
    ValueError
        Naming ``name`` and the file (and the line): unreadable, no header, a missing
        column, a non-numeric or non-finite value, a short row, fewer than 4 rows.
    """
    from ._fit_data import read_columns as read

    return read(path, columns, name)


def _validate_args(args) -> None:
    from .. import _validate as V

    modal = next((o for o, v in (("--backbone", args.backbone), ("--ringdown", args.ringdown),
                                  ("--frc", args.frc)) if v is not None), None)
    if modal is not None:
        if args.mass is None:
            raise ValueError(f"--mass is required with {modal} (modal mass, kg)")
        V.positive("--mass", args.mass)
        if args.n_ref is not None:
            raise ValueError("--n-ref applies to loop fits (--input) only")
    elif args.mass is not None:
        raise ValueError("--mass applies to modal fits (--backbone, --ringdown, --frc) only")
    if args.n_ref is not None:
        V.positive("--n-ref", args.n_ref)
    if args.band is not None:
        if args.ringdown is None:
            raise ValueError("--band applies to ring-down fits (--ringdown) only")
        from ._fit_ringdown import parse_band

        args.band = parse_band(args.band)
    if args.out is not None:
        V.output_dir("--out", args.out, files=_FILES + (("ringdown_backbone.csv",) if args.ringdown else ()))


def _law_options(args) -> tuple:
    """(held law parameters, start values): chi and beta given with --law-param start the fit."""
    lp = law_params(args)
    given = {str(i).partition("=")[0].strip() for i in (args.law_param or ())}
    start = {k: lp[k] for k in ("chi", "beta") if k in lp and k in given}
    held = {k: v for k, v in lp.items() if k not in ("chi", "beta")}
    return held, start


def _fit(args):
    from ..identify import fit_backbone, fit_loops
    from ._fit_data import read_backbone, read_loops

    held, start = _law_options(args)
    if args.input is not None:
        d = read_loops(args.input, "--input")
        _plausible("--input", args.input, "x", d["x"], FIT_PLAUSIBLE_DISPLACEMENT_M, "m")
        return fit_loops(d["x"], d["N"], d["T"], args.model, t=d["t"], n_ref=args.n_ref, law_params=held,
                         start=start)
    if args.frc is not None:
        from ..identify.frc import FRC_COLUMNS, fit_frc

        d = read_columns(args.frc, FRC_COLUMNS, "--frc")
        _plausible("--frc", args.frc, "amplitude_m", d["amplitude_m"], FIT_PLAUSIBLE_AMPLITUDE_M, "m")
        return fit_frc(d["force_N"], d["omega_rad_s"], d["amplitude_m"], mass=args.mass, model=args.model,
                       law_params=held, start=start)
    if args.ringdown is not None:
        from ._fit_ringdown import backbone_of

        b = backbone_of(args, read_columns)
        args.ringdown_backbone = b
        d = {"amplitude_m": b.amplitude_m, "omega_rad_s": b.omega_rad_s, "damping_ratio": b.damping_ratio}
        _plausible("--ringdown", args.ringdown, "x (amplitude)", d["amplitude_m"], FIT_PLAUSIBLE_AMPLITUDE_M,
                   "m")
        from ..identify import fit_ringdown

        return fit_ringdown(b, mass=args.mass, model=args.model, law_params=held, start=start)
    d = read_backbone(args.backbone, "--backbone", mass=args.mass)
    _plausible("--backbone", args.backbone, "amplitude_m", d["amplitude_m"], FIT_PLAUSIBLE_AMPLITUDE_M, "m")
    return fit_backbone(d["amplitude_m"], d["omega_rad_s"], d["damping_ratio"], mass=args.mass, model=args.model,
                        law_params=held, start=start)


def _plot_png(fit) -> bytes:
    from ..figures import pyplot

    plt = pyplot()
    fig, (ax, ar) = plt.subplots(2, 1, figsize=(6.0, 6.0), dpi=120, height_ratios=(3, 1))
    m, f = fit.measured, fit.fitted
    if fit.kind == "loops":
        ax.plot(m["x"] * 1e3, m["T"], ".", color="0.6", ms=2, label="measured")
        ax.plot(m["x"] * 1e3, f["T"], color="C0", lw=1.2, label=f"fitted {fit.model}")
        ax.set_xlabel("x (mm)")
        ax.set_ylabel("T (N)")
        xr = m["t"] if "t" in m else np.arange(m["x"].size)
        ar.plot(xr, f["T"] - m["T"], color="C3", lw=0.6)
        ar.set_xlabel("t (s)" if "t" in m else "sample")
        ar.set_ylabel("residual (N)")
    elif fit.kind == "frc":
        for F in np.unique(m["force_N"]):
            sel = m["force_N"] == F
            ax.plot(m["omega_rad_s"][sel], m["amplitude_m"][sel] * 1e3, ".", ms=3, label=f"F = {F:.4g} N")
        ax.set_xlabel("omega (rad/s)")
        ax.set_ylabel("amplitude (mm)")
        ar.plot(m["omega_rad_s"], f["equation_error"], ".", color="C3", ms=2)
        ar.set_xlabel("omega (rad/s)")
        ar.set_ylabel("relative error")
    else:
        A = m["amplitude_m"]
        ax.semilogx(A, m["omega_rad_s"], "o", color="0.5", ms=3, label="measured omega")
        ax.semilogx(A, f["omega_rad_s"], color="C0", label="fitted omega")
        ax.set_ylabel("omega (rad/s)")
        ax2 = ax.twinx()
        ax2.semilogx(A, m["damping_ratio"], "s", color="0.7", ms=3)
        ax2.semilogx(A, f["damping_ratio"], color="C1", label="fitted damping ratio")
        ax2.set_ylabel("damping ratio")
        ar.semilogx(A, f["omega_rad_s"] / m["omega_rad_s"] - 1.0, color="C0", label="omega (relative)")
        ar.semilogx(A, (f["damping_ratio"] - m["damping_ratio"]) / np.max(m["damping_ratio"]), color="C1",
                    label="damping (of its max)")
        ar.set_xlabel("amplitude (m)")
        ar.set_ylabel("residual")
        ar.legend(fontsize=7)
    ax.set_title(f"{fit.model}: {fit.status.value}", fontsize=9)
    ax.grid(True, alpha=0.3)
    ax.legend(fontsize=8)
    ar.grid(True, alpha=0.3)
    fig.tight_layout()
    buf = io.BytesIO()
    fig.savefig(buf, format="png")
    plt.close(fig)
    return buf.getvalue()


def _csv_text(fit) -> str:
    m, f = fit.measured, fit.fitted
    cols = dict(m)
    for k, v in f.items():
        cols[f"{k}_fit"] = v
    names = list(cols)
    lines = [",".join(names)]
    for row in zip(*(cols[k] for k in names)):
        lines.append(",".join(f"{float(v):.17g}" for v in row))
    return "\n".join(lines) + "\n"


def _write_files(args, fit, text: str) -> None:
    from .._io import atomic_path

    png = _plot_png(fit)
    table = _csv_text(fit)
    out = Path(args.out)
    for fname, payload in (("fit.json", text), ("fit.csv", table)):
        with atomic_path(out / fname) as tmp:
            Path(tmp).write_text(payload)
    with atomic_path(out / "fit.png") as tmp:
        Path(tmp).write_bytes(png)
    if getattr(args, "ringdown_backbone", None) is not None:
        from ._fit_ringdown import write_backbone

        write_backbone(out, args.ringdown_backbone, fit.damping_range)


def _interval_text(iv) -> str:
    if iv is None:
        return ""
    lo = "-inf" if iv.low is None else f"{iv.low:.5g}"
    hi = "inf" if iv.high is None else f"{iv.high:.5g}"
    return f"  ({100 * iv.level:.3g} %: [{lo}, {hi}])"


def _range_line(rng: dict) -> str:
    """The fit's damping range (``FitResult.damping_range``) in one line."""
    if rng["points"] == 0:
        return f"determined within +-{100 * rng['bound']:g} % at no amplitude: every point kept, none determined"
    written = "ringdown_backbone.csv holds these" if rng["points"] >= 2 else "every point kept"
    return (f"determined within +-{100 * rng['bound']:g} % (95 %) from {rng['amplitude_high_m']:.4g} to "
            f"{rng['amplitude_low_m']:.4g} m, {rng['points']} points; {rng['trimmed_top']} trimmed at the top, "
            f"{rng['trimmed_bottom']} at the bottom ({written})")


def _print_console(args, fit) -> None:
    src = next(s for s in (args.input, args.backbone, args.ringdown, args.frc) if s is not None)
    print(f"jointdyn fit: {fit.model} from {fit.kind} {src}: {fit.status.value}")
    if getattr(args, "ringdown_backbone", None) is not None:
        print(f"  ring-down: {args.ringdown_backbone.message}")
        if fit.damping_range is not None:
            print(f"  damping range: {_range_line(fit.damping_range)}")
    if fit.record_start is not None:
        print(f"  record {fit.record_start}")
    for k, v in fit.parameters.items():
        se = fit.standard_errors.get(k)
        iv = _interval_text(fit.intervals.get(k))
        if v is None:
            print(f"  {k:<8} not identifiable: {fit.not_identifiable.get(k, fit.not_identifiable.get('mu', ''))}")
        else:
            print(f"  {k:<8} {v:.6g} +- {se:.2g}{iv}" if se is not None else f"  {k:<8} {v:.6g}{iv}")
    if fit.conditional_on:
        print(f"  (standard errors with {', '.join(fit.conditional_on)} held; the intervals are not conditional)")
    for k, c in fit.determined_combinations.items():
        lo, hi = c["interval"]["low"], c["interval"]["high"]
        word = "not determined" if "not_determined" in c else "determined"
        print(f"  {word}: {k} = {c['value']:.6g} {c['unit']} (95 %: [{lo if lo is None else f'{lo:.5g}'}, "
              f"{hi if hi is None else f'{hi:.5g}'}]): {c['meaning']}")
    unit = "N" if fit.kind == "loops" else "(relative)"
    print(f"  rms residual {fit.rms_residual:.4g} {unit}")
    if args.out is not None:
        extra = ("ringdown_backbone.csv",) if getattr(args, "ringdown_backbone", None) is not None else ()
        print(f"  wrote {', '.join(str(Path(args.out) / f) for f in _FILES + extra)}")


def _plausible(name, path, column, values, limit, unit) -> None:
    """Refuse magnitudes no joint test gives in the documented SI unit (a file in mm read as m)."""
    big = float(np.max(np.abs(values)))
    if big > limit:
        raise ValueError(f"{name} {str(path)!r} column {column}: values up to {big:.4g} are not plausible in {unit} "
                         f"(a joint test stays below {limit:g} {unit}); the file may be in other units (mm?): "
                         f"convert it to SI")


def run(args) -> int:
    _validate_args(args)
    from ._fit_data import plausibility

    fit = _fit(args)
    warnings = plausibility(fit, fit.measured if fit.kind == "loops" else None)
    report = fit.to_dict()
    report["warnings"] = warnings
    try:
        text = json.dumps(report, allow_nan=False)
    except ValueError:
        src = "--input" if args.input is not None else "--backbone"
        raise ValueError(f"the fitted values overflow double precision: the data of {src} are beyond the range of "
                         "a fit (scale them to SI units of ordinary size)") from None
    if args.out is not None:
        _write_files(args, fit, text)
    if args.json:
        print(text)
    else:
        _print_console(args, fit)
    for w in warnings:
        print(f"jointdyn fit: warning: {w}", file=sys.stderr)
    if not fit.status.ok:
        print(f"jointdyn fit: {fit.message}", file=sys.stderr)
        return EXIT_INCOMPLETE
    return 0
