"""What ``jointdyn frc`` shows of a structure of your own (``--system``): the
amplitude of the output DOF in mm (and of the other ``[output] dofs``), not
q = kt X / fy of the first contact, which means nothing at a blade tip.

The paper damper keeps q, its dimensionless amplitude (the paper's Fig 6).
"""

from __future__ import annotations

import textwrap

import numpy as np

__all__ = ["output_dofs", "dof_mm", "y_values", "peak_value", "y_label", "curve_label", "wrap",
           "print_system_table", "reason_name", "status_cell", "print_notes"]

#: characters per line of a wrapped plot title (fontsize 9 on a 6.4 in wide figure)
TITLE_WIDTH = 80


def wrap(title: str, width: int = TITLE_WIDTH) -> str:
    """``title`` broken into lines of at most ``width`` characters (a long
    file title or path wraps instead of running off the picture)."""
    return "\n".join(textwrap.wrap(title, width)) or title


def output_dofs(result) -> list[int]:
    """DOFs shown for a ``--system`` run: its output DOF first, then the other
    ``[output] dofs``; ``[]`` for the paper damper."""
    if "system" not in result:
        return []
    sysd = result["system"]
    first = int(sysd["response_dof"])
    return [first] + [int(d) for d in sysd["dofs"] if int(d) != first]


def _floats(values) -> np.ndarray:
    return np.array([np.nan if v is None else v for v in values], float)


def dof_mm(r, result, dof: int):
    """Amplitude (half peak-to-peak) of DOF ``dof`` in mm per point of one
    sweep direction or branch ``r``; None when ``r`` does not carry it."""
    if dof == int(result["system"]["response_dof"]):
        return 1e3 * _floats(r["amplitude_m"])
    values = r.get("dofs", {}).get(str(dof), {}).get("amplitude_m")
    return None if values is None else 1e3 * _floats(values)


def y_values(r, result) -> np.ndarray:
    """What frc.png draws for ``r``: the output DOF's amplitude in mm for a
    ``--system`` run, q for the paper damper."""
    if "system" in result:
        return dof_mm(r, result, int(result["system"]["response_dof"]))
    return _floats(r["amplitude_q"])


def peak_value(pk, result):
    """A refined peak's height in the units of :func:`y_values` (None if unknown)."""
    key = "amplitude_m" if "system" in result else "amplitude_q"
    value = pk.get(key)
    return None if value is None else (1e3 * value if "system" in result else value)


def y_label(result) -> str:
    if len(output_dofs(result)) > 1:
        return "amplitude of the output DOFs, mm (half peak-to-peak)"
    if "system" in result:
        return f"amplitude of DOF {result['system']['response_dof']}, mm (half peak-to-peak)"
    return "amplitude of q = kt x / fy (half peak-to-peak)"


def curve_label(result, what: str) -> str:
    """Legend entry ``what`` of the output DOF's curve, ``"DOF n, what"`` when other DOFs are drawn
    beside it (their entries are ``"DOF k, ..."``)."""
    dofs = output_dofs(result)
    return f"DOF {dofs[0]}, {what}" if len(dofs) > 1 else what


def reason_name(status_code, reason_code):
    """Name of why a point is not-settled (None for the other points)."""
    from .. import config
    from ..dynamics.status import SteadyStatus

    reasons = config.SWEEP_NOT_SETTLED_REASONS
    if int(status_code) != SteadyStatus.NOT_SETTLED.code:
        return None
    return reasons[int(reason_code)] if 0 < int(reason_code) < len(reasons) else "unknown"


def status_cell(r, i: int) -> str:
    """The status of point ``i`` of a sweep direction for the table: a
    steady state that repeats every K > 1 forcing periods is ``periodic-KT``."""
    from ..dynamics.status import SteadyStatus

    status = r["status"][i]
    multiple = r.get("period_multiple", [1] * (i + 1))[i]
    periodic = status in {s.value for s in SteadyStatus if s.ok}
    return f"{status}-{multiple}T" if periodic and multiple > 1 else status


#: what each not-settled reason means, for the notes under the table
REASON_TEXT = {
    "slowly-converging": "still converging when the period budget ran out",
    "quasi-periodic-or-chaotic": "the mismatch over a period stopped shrinking: quasi-periodic or chaotic",
    "long-period": "repeats only after more forcing periods than the largest multiple looked for",
}


def print_notes(result, digits: int) -> None:
    """Under the table of a time sweep: what ``periodic-KT`` means, and why
    each not-settled point did not settle."""
    dirs = result["directions"]
    if any(p > 1 for r in dirs.values() for p in r.get("period_multiple", [])):
        print("periodic-KT: the steady state repeats every K forcing periods (period_multiple in the JSON and files)")
    for d, r in dirs.items():
        for g, reason in zip(r["gamma"], r.get("not_settled_reason", [])):
            if reason is not None:
                why = f"{reason}, {REASON_TEXT[reason]}" if reason in REASON_TEXT else reason
                print(f"not settled at gamma {g:.{digits}g} ({d}): {why}")


def _cell(value, ok: bool = True) -> str:
    return "-" if value is None or not ok or not np.isfinite(value) else f"{value:.5g}"


def print_system_table(result, digits: int, joined) -> None:
    """The table of a ``--system`` run: per gamma, the amplitude of each
    output DOF in mm (per sweep direction, with its status; or per branch
    point, with its stability)."""
    dofs = output_dofs(result)
    sysd = result["system"]
    print(f"{sysd['title']}: amplitude (half peak-to-peak) of DOF {', '.join(map(str, dofs))}, mm")
    w = max(8, digits + 6)
    if result["method"] == "time":
        dirs = list(result["directions"])
        cols = {d: [(k, dof_mm(result["directions"][d], result, k)) for k in dofs] for d in dirs}
        cols = {d: [(k, v) for k, v in c if v is not None] for d, c in cols.items()}
        print(f"{'gamma':<{w}s} " + "  ".join(" ".join(f"{f'x{k}_{d}':>12s}" for k, _ in cols[d])
                                              + f" {'status':>11s}" for d in dirs))
        for i, g in enumerate(result["directions"][dirs[0]]["gamma"]):
            cells = []
            for d in dirs:
                status = result["directions"][d]["status"][i]
                cells.append(" ".join(f"{_cell(v[i], status == 'periodic'):>12s}" for _, v in cols[d])
                             + f" {status_cell(result['directions'][d], i):>11s}")
            print(f"{g:<{w}.{digits}g} " + "  ".join(cells))
        print_notes(result, digits)
        return
    print(f"status: {result['status']} {result['message']}")
    for br in result["branches"]:
        cols = [(k, v) for k in dofs if (v := dof_mm(br, result, k)) is not None]
        print(f"branch {br['branch']}: {len(br['gamma'])} points, folds at {br['folds']}")
        print(f"  {'gamma':<{w}s} " + " ".join(f"{f'x{k}':>12s}" for k, _ in cols))
        for i, (g, s, ps) in enumerate(zip(br["gamma"], br["stable"], br["point_status"])):
            print(f"  {g:<{w}.{digits}g} " + " ".join(f"{_cell(v[i]):>12s}" for _, v in cols)
                  + f" {'stable' if s else 'unstable':<8s}{'' if ps in joined else ' ' + ps}")
    for pk in result["peaks"]:
        value = peak_value(pk, result)
        print(f"peak: gamma = {pk['gamma']:.6g}, x{dofs[0]} = {_cell(value)} mm (branch {pk['branch']}"
              f"{'' if pk['refined'] else ', not fully refined'})")
