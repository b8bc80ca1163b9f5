"""``jointdyn modes``: backbone of a nonlinear mode (frequency and damping ratio against amplitude).

The system is the paper's friction damper at its constant normal load
(``--model``, ``--law-param``) or a TOML system file (``--system``; its
forcing is not used, its normal loads must be autonomous). ``--method
epmc`` (default) follows the extended periodic motion concept by harmonic
balance (:func:`jointdyn.modes.epmc`, ``--harmonics``, ``--samples``,
``--max-points``; harmonics and samples chosen automatically unless given,
as ``frc --method hb`` does); ``--method qsma`` is the quasi-static estimate
(:func:`jointdyn.modes.qsma`). The amplitude is the first-harmonic
amplitude of the output DOF in metres (``--amplitude MIN:MAX``, stepped
logarithmically).

Everything is validated before computing; ``--out`` files (``modes.nc``,
``modes.csv``, ``modes.png``) are written atomically after computing.

Exit status: 0 for a complete backbone; 2 for bad input (one line, no
file); :data:`jointdyn._exit.EXIT_INCOMPLETE` (3) when the backbone stops short (status
``failed``, ``max-points`` or ``no-start``): the files are still written
and carry the status, and ``--json`` prints it.
"""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np

from .. import _validate as V
from .. import config
from .._exit import EXIT_INCOMPLETE
from .._io import jsonable as _jsonable
from ..continuation import ContinuationOptions
from ._law_args import add_law_arguments, law_params, model_help
from ._system_args import load_system_file, option_names

NAME = "modes"
HELP = "backbone of a nonlinear mode (natural frequency and damping ratio against amplitude) by EPMC or QSMA"
#: options of the EPMC only
_EPMC_ONLY = ("harmonics", "samples", "max_points")


def add_arguments(p) -> None:
    q0, q1 = config.MODES_AMPLITUDE_Q
    p.add_argument("--system", default=None, metavar="FILE.toml",
                   help="system file (structure, contacts, normal loads; its forcing is not used) instead of the "
                        "paper's damper at constant normal load")
    p.add_argument("--method", default="epmc", help="epmc (extended periodic motion concept, default) or qsma "
                                                    "(quasi-static modal analysis, the fast estimate)")
    p.add_argument("--model", default=None, help=model_help(config.MODEL) + "; not with --system (its file names "
                                                                           "its laws)")
    add_law_arguments(p)
    p.add_argument("--amplitude", default=None, metavar="MIN:MAX",
                   help="range of the first-harmonic amplitude of the output DOF, m (default "
                        f"{q0:g}:{q1:g} times fy/kt of the first contact)")
    p.add_argument("--mode", type=int, default=1, help="linear stuck mode to start from, 1-based (default 1)")
    p.add_argument("--output-dof", type=int, default=None,
                   help="DOF whose amplitude is the modal amplitude (default: the system's output DOF)")
    p.add_argument("--harmonics", default=None, metavar="H|auto",
                   help=f"epmc: harmonics, or auto (default: from {config.HB_HARMONICS}, raised while the backbone "
                        "changes with more, as frc --method hb does)")
    p.add_argument("--samples", default=None, metavar="NS|auto",
                   help=f"epmc: AFT time samples per period, or auto (default: from {config.HB_SAMPLES}, doubled "
                        "while the backbone changes with more: where a contact separates)")
    p.add_argument("--max-points", type=int, default=None,
                   help=f"epmc: bound on the points of the backbone (default {ContinuationOptions.max_points})")
    p.add_argument("--out", default=None, metavar="DIR", help="write modes.nc, modes.csv, modes.png here")
    p.add_argument("--json", action="store_true", help="print one JSON object instead of a table")


def parse_amplitude(text: str) -> tuple[float, float]:
    """``MIN:MAX`` (m) -> (min, max) with 0 < min < max."""
    return V.positive_interval("--amplitude", text)


def _validate(args):
    """Options checked and the System built; returns ``(system, amplitude range, label)``."""
    from ..laws import law_names
    from ..modes import amplitude_range, check_free_vibration, linear_stuck_mode, output_dof_of
    from ..systems import System

    V.choice("--method", args.method, ("epmc", "qsma"))
    if args.method == "qsma":
        for dest in _EPMC_ONLY:
            if getattr(args, dest) is not None:
                raise ValueError(f"--{dest.replace('_', '-')} applies to --method epmc only")
    if args.system is not None:
        if args.model is not None or args.law_param or args.n is not None:
            raise ValueError("--model, --law-param and --n cannot be combined with --system: the system file "
                             "names the law of each contact")
        sf = load_system_file(args)
        system = sf.system
        label = Path(args.system).name
        args.title = sf.title  # the file's title, in the JSON, modes.nc and modes.png
        args.figure_label = f"{sf.title} ({label})"
    else:
        args.model = config.MODEL if args.model is None else V.choice("--model", args.model, law_names())
        args.law_params = law_params(args)
        system = System.paper_damper(eta=0.0, model=args.model, law_params=args.law_params)
        label = f"paper's damper, {args.model}"
        args.title = args.figure_label = label
    check_free_vibration(system, args.method.upper(), springs=args.method == "epmc", held=True)
    with option_names(amplitude="--amplitude", output_dof="--output-dof", mode="--mode"):
        amps = amplitude_range(system, None if args.amplitude is None else parse_amplitude(args.amplitude))
        args.output_dof = output_dof_of(system, args.output_dof)
        linear_stuck_mode(system, V.positive_int("--mode", args.mode, 1), args.output_dof)
    if args.method == "epmc":
        from ..hb import AUTO, Discretisation, check_memory

        names = ("--harmonics", "--samples")
        disc = Discretisation.of(AUTO if args.harmonics is None else args.harmonics,
                              AUTO if args.samples is None else args.samples, names=names)
        check_memory(system, disc, names=names)
        args.harmonics = AUTO if disc.harmonics_auto else disc.first.harmonics
        args.samples = AUTO if disc.samples_auto else disc.first.samples
        args.max_points = V.positive_int("--max-points", ContinuationOptions.max_points if args.max_points is None
                                         else args.max_points, 2)
    if args.out is not None:
        V.output_dir("--out", args.out, files=("modes.nc", "modes.csv", "modes.png"))
    return system, amps, label


def _compute(args, system, amps):
    from ..modes import backbone_dataset, epmc, qsma

    if args.method == "qsma":
        b = qsma(system, amps, mode=args.mode, output_dof=args.output_dof)
    else:
        b = epmc(system, amps, mode=args.mode, output_dof=args.output_dof, harmonics=args.harmonics,
                 samples=args.samples, max_points=args.max_points, progress=None if not args.json else False)
    return b, backbone_dataset(b)


def _result(args, ds, label) -> dict:
    keys = ("amplitude_m", "amplitude_q", "omega_rad_s", "frequency_hz", "damping_ratio", "damping_ratio_contacts",
            "damping_ratio_viscous", "contact_energy_J")
    branch = {k: _jsonable(ds[k].values) for k in keys}
    # deprecated duplicates of contact_energy_J (per contact), kept for one release (CHANGELOG)
    branch["energy_contact_J"] = branch["energy_contact_j"] = branch["contact_energy_J"]
    if "pair" in ds.dims:  # the interfaces' node pairs: the total per point, and per point and pair
        branch["energy_interface_J"] = branch["energy_pairs_J"] = _jsonable(ds["energy_interface_J"].values)
        branch["pairs"] = {"energy_J": _jsonable(ds["pair_energy_J"].values),
                           **{f"{k}_fraction": _jsonable(ds[f"pair_{k}_fraction"].values)
                              for k in ("stick", "slip", "open")}}
    return {"method": args.method, "system": label, "title": args.title, "mode": int(ds.attrs["linear_mode"]),
            "output_dof": int(ds.attrs["output_dof"]), "harmonics": int(ds.attrs["harmonics"]),
            "samples": int(ds.attrs["samples"]), "omega_linear_rad_s": float(ds.attrs["omega_linear_rad_s"]),
            "branches": [branch],
            "status": str(ds.attrs["status"]), "message": str(ds.attrs["message"])}


def _plot(ds, title: str, path: Path) -> None:
    from .._io import atomic_path
    from ..figures import pyplot, use_math_text
    from ._frc_report import wrap

    plt = pyplot()
    fig, (ax1, ax2) = plt.subplots(2, 1, figsize=(6.4, 6.0), sharex=True)
    a = ds.amplitude_m.values
    ax1.plot(a, ds.omega_rad_s.values, "-", color="C0")
    ax1.axhline(ds.attrs["omega_linear_rad_s"], color="0.6", ls=":", lw=1, label="linear, contacts stuck")
    ax1.set_ylabel("natural frequency, rad/s")
    ax1.legend(fontsize=8)
    ax2.plot(a, ds.damping_ratio.values, "-", color="C3")
    ax2.set_ylabel("modal damping ratio")
    ax2.set_xlabel("first-harmonic amplitude of DOF %d, m" % ds.attrs["output_dof"])
    points = bool(np.any(np.isfinite(a) & (a > 0.0)))  # a backbone that never started has none
    for ax in (ax1, ax2):
        if points:
            ax.set_xscale("log")
        ax.grid(alpha=0.3, which="both")
    if not points:
        ax2.text(0.5, 0.5, f"no point: {ds.attrs['message']}", transform=ax2.transAxes, ha="center",
                 va="center", fontsize=8, color="C3", wrap=True)
    ax1.set_title(wrap(f"{ds.attrs['method'].upper()} backbone of mode {ds.attrs['linear_mode']} ({title}); "
                       f"status {ds.attrs['status']}"), fontsize=9)
    use_math_text(fig)
    fig.tight_layout()
    with atomic_path(path) as tmp:
        fig.savefig(tmp, dpi=120)
    plt.close(fig)


def _write(ds, out: Path, title: str) -> None:
    from .._io import write_dataset

    write_dataset(ds, out, "modes")  # modes.csv: one row per point (per-DOF and per-contact data in modes.nc)
    _plot(ds, title, out / "modes.png")


def run(args) -> int:
    system, amps, label = _validate(args)
    backbone, ds = _compute(args, system, amps)
    if args.out is not None:
        ds.attrs["title"] = args.title
        _write(ds, Path(args.out), args.figure_label)
    result = _result(args, ds, label)
    if args.json:
        print(json.dumps(result))
    else:
        _print_table(result)
    if backbone.status.ok:
        return 0
    import sys

    print(f"jointdyn modes: incomplete: {result['status']}: {result['message']}", file=sys.stderr)
    return EXIT_INCOMPLETE


def _print_table(result) -> None:
    print(f"{result['method']} backbone of mode {result['mode']} ({result['system']}): status {result['status']}, "
          f"{result['message']}")
    br = result["branches"][0]
    print(f"{'amplitude_m':>14s} {'omega_rad_s':>14s} {'frequency_hz':>14s} {'damping_ratio':>14s}")
    for a, w, f, d in zip(br["amplitude_m"], br["omega_rad_s"], br["frequency_hz"], br["damping_ratio"]):
        print(f"{a:14.6e} {w:14.8g} {f:14.8g} {d:14.6e}")
