"""Folds of the robustness grid checked against time-domain sweeps.

A fold (a turning point of the branch with a stability change) of a
harmonic-balance branch means that two stable periodic responses coexist
between it and its partner fold: a time-domain sweep up in gamma stays on
one of them and a sweep down on the other, so that the two sweeps jump at
different gammas and differ in between. :func:`fold_check` computes the
branch of one grid case (:func:`jointdyn.hb.continue_hb`, the grid's
settings), and where it reports folds runs time-domain sweeps up and down
(:func:`jointdyn.sweeps.frc_sweep`, each point warm-started from the
previous one) through the fold interval: points spread over the interval
and its surroundings, and points between each pair of neighbouring folds.

The verdict (:class:`FoldVerdict`) says whether the two sweeps settle on
periodic orbits that differ by more than ``rtol`` somewhere between the
outermost folds (``confirmed``), whether they agree there (``not-seen``:
the fold is not confirmed), or whether the time domain finds no periodic
steady state between them in at least one direction (``not-periodic``:
nothing to compare; not ok, as the robustness grid counts a peak it cannot
compare, :data:`jointdyn.validation.hb_grid.NOT_COMPARED`). ``docs/scripts/hb_robustness.py --folds`` writes the
table of the grid's folds into ``docs/hb-robustness.md``.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..dynamics import SteadyStatus
from ..status import Status
from .hb_grid import GRID_GAMMA

__all__ = ["FoldCheck", "FoldVerdict", "fold_check", "fold_table"]

#: points of the time-domain sweeps spread over the fold interval and its surroundings ...
SPREAD_POINTS = 15
#: ... which extend beyond the outermost folds by this fraction of their distance, at least MIN_MARGIN
MARGIN = 0.3
MIN_MARGIN = 1e-3
#: points strictly between two neighbouring folds
INNER_POINTS = 5
#: periodic status code of a sweep's points (``frc_sweep``'s ``status`` variable)
PERIODIC = SteadyStatus.PERIODIC.code


class FoldVerdict(Status):
    """Outcome of the time-domain check of a branch's folds."""

    CONFIRMED = ("confirmed", "time-domain sweeps up and down settle on different periodic orbits between "
                 "the folds: the response jumps there", True)
    NOT_SEEN = ("not-seen", "time-domain sweeps up and down agree between the folds: the folds are not "
                "confirmed by the time domain")
    NOT_PERIODIC = ("not-periodic", "between the folds the time domain finds no periodic steady state in at "
                    "least one direction: nothing to compare")


@dataclass(frozen=True)
class FoldCheck:
    """The folds of one grid case and the time-domain sweeps through them.

    Attributes
    ----------
    model : str
    eta, beta : float
    folds : tuple of float
        Forcing frequency ratios gamma of the branch's folds, ascending.
    gammas : tuple of float
        Points of the time-domain sweeps, ascending.
    q_up, q_down : tuple of float
        Amplitude ratio q of the sweeps up and down (NaN where not periodic).
    inside_apart : tuple of float
        Points between the outermost folds where both sweeps are periodic
        and differ by more than ``rtol``.
    verdict : FoldVerdict
    """

    model: str
    eta: float
    beta: float
    folds: tuple
    gammas: tuple
    q_up: tuple
    q_down: tuple
    inside_apart: tuple
    verdict: FoldVerdict


def sweep_points(folds) -> np.ndarray:
    """Points of the time-domain sweeps through ``folds`` (ascending gammas)."""
    lo, hi = folds[0], folds[-1]
    margin = max(MARGIN * (hi - lo), MIN_MARGIN)
    parts = [np.linspace(lo - margin, hi + margin, SPREAD_POINTS), folds]
    parts += [np.linspace(a, b, INNER_POINTS + 2)[1:-1] for a, b in zip(folds[:-1], folds[1:]) if b > a]
    return np.unique(np.round(np.concatenate(parts), 10))


def fold_check(model: str, eta: float, beta: float, gamma=GRID_GAMMA, *, rtol: float = 0.02):
    """Check the folds of one grid case against time-domain sweeps (see the module docstring).

    Parameters
    ----------
    model : str
        Contact model name.
    eta, beta : float
        Normal-load ratio and friction ratio of the paper damper.
    gamma : tuple, optional
        START, STOP, STEP of the branch (the grid's by default).
    rtol : float, optional
        Relative difference of the two sweeps' q that counts as a jump.

    Returns
    -------
    FoldCheck or None
        None where the branch reports no fold.
    """
    from ..hb import continue_hb
    from ..systems import System
    from ..sweeps import frc_sweep

    system = System.paper_damper(eta=eta, beta=beta, model=model)
    br = continue_hb(system, gamma[0], gamma[1], max_step=gamma[2], progress=False)
    folds = np.sort(np.asarray(br.lam)[np.asarray(br.fold, dtype=bool)])
    if folds.size == 0:
        return None
    g = sweep_points(folds)
    ds = frc_sweep(list(g), etas=[eta], betas=[beta], model=model, directions=("up", "down"),
                   n_workers=1, progress=False, loop_outputs=False)
    one = ds.sel(eta=eta, beta=beta).squeeze()
    q = {d: one["amplitude_q"].sel(direction=d).values.ravel() for d in ("up", "down")}
    ok = {d: one["status"].sel(direction=d).values.ravel() == PERIODIC for d in ("up", "down")}
    inside = (g > folds[0]) & (g < folds[-1])
    both = inside & ok["up"] & ok["down"]
    apart = both & (np.abs(q["up"] - q["down"]) > rtol * np.maximum(np.abs(q["up"]), np.abs(q["down"])))
    if apart.any():
        verdict = FoldVerdict.CONFIRMED
    elif inside.any() and not both[inside].any():
        verdict = FoldVerdict.NOT_PERIODIC
    else:
        verdict = FoldVerdict.NOT_SEEN
    return FoldCheck(model=model, eta=eta, beta=beta, folds=tuple(folds.tolist()), gammas=tuple(g.tolist()),
                     q_up=tuple(q["up"].tolist()), q_down=tuple(q["down"].tolist()),
                     inside_apart=tuple(g[apart].tolist()), verdict=verdict)


def _span(values) -> str:
    return "-" if not values else (f"{values[0]:.5f}" if len(values) == 1 else f"{values[0]:.5f} to {values[-1]:.5f}")


def fold_table(checks) -> str:
    """Markdown table of fold checks (one row each) and a summary line."""
    checks = [c for c in checks if c is not None]
    lines = ["| model | eta | beta | folds | fold gammas | sweep points | up and down apart at | verdict |",
             "|" + "---|" * 8]
    for c in checks:
        lines.append(f"| {c.model} | {c.eta:g} | {c.beta:g} | {len(c.folds)} | {_span(c.folds)} | {len(c.gammas)} | "
                     f"{_span(c.inside_apart)} ({len(c.inside_apart)}) | {c.verdict.value} |")
    counts = {v: sum(c.verdict is v for c in checks) for v in FoldVerdict}
    lines.append("")
    lines.append(f"{len(checks)} branches with folds: " + ", ".join(f"{v.value} {n}" for v, n in counts.items()) + ".")
    return "\n".join(lines)
