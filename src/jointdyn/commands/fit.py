"""``jointdyn fit``: identify a joint model from measured loops or a measured backbone.

Two forms::

    jointdyn fit --input LOOPS.csv --model MODEL [--json] [--out DIR]
    jointdyn fit --backbone BACKBONE.csv --model MODEL --mass KG [--json] [--out DIR]

``--input``: a CSV file with a header row and the columns ``t, x, N, T`` (s,
m, N, N): a fretting-rig record, one or several cycles, from rest. The law's
force under the measured x and N is fitted to T by least squares
(:func:`jointdyn.fit_loops`). ``--backbone``: columns ``amplitude_m,
omega_rad_s, damping_ratio`` of one mode of modal mass ``--mass``, fitted
with a modal Iwan model by the describing function
(:func:`jointdyn.fit_backbone`).

The console (or ``--json``: keys ``parameters``, ``standard_errors``,
``rms_residual``, ``status`` and more) gives every parameter with its
standard error, or why the data do not determine it. ``--out DIR`` receives
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
    p.add_argument("--model", default=config.MODEL, choices=LOOP_MODELS,
                   help=f"joint law to fit (default {config.MODEL})")
    add_law_arguments(p)
    p.add_argument("--mass", type=float, default=None, help="modal mass of the backbone's mode, kg (--backbone)")
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

    if args.backbone is not None:
        if args.mass is None:
            raise ValueError("--mass is required with --backbone (modal mass, kg)")
        V.positive("--mass", args.mass)
        if args.n_ref is not None:
            raise ValueError("--n-ref applies to loop fits (--input) only")
    elif args.mass is not None:
        raise ValueError("--mass applies to backbone fits (--backbone) only")
    if args.n_ref is not None:
        V.positive("--n-ref", args.n_ref)
    if args.out is not None:
        V.output_dir("--out", args.out, files=_FILES)


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
        return fit_loops(d["x"], d["N"], d["T"], args.model, t=d["t"], n_ref=args.n_ref, law_params=held,
                         start=start)
    d = read_backbone(args.backbone, "--backbone", mass=args.mass)
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


def _print_console(args, fit) -> None:
    src = args.input if args.input is not None else args.backbone
    print(f"jointdyn fit: {fit.model} from {fit.kind} {src}: {fit.status.value}")
    for k, v in fit.parameters.items():
        se = fit.standard_errors.get(k)
        if v is None:
            print(f"  {k:<8} not identifiable: {fit.not_identifiable.get(k, fit.not_identifiable.get('mu', ''))}")
        else:
            print(f"  {k:<8} {v:.6g} +- {se:.2g}")
    unit = "N" if fit.kind == "loops" else "(relative)"
    print(f"  rms residual {fit.rms_residual:.4g} {unit}")
    if args.out is not None:
        print(f"  wrote {', '.join(str(Path(args.out) / f) for f in _FILES)}")


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
