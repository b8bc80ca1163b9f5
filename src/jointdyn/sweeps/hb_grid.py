"""Robustness grid of harmonic balance: default settings on the paper's parameter grid, checked.

Every case is one ``jointdyn frc --method hb`` run with the CLI's defaults
(:func:`jointdyn.hb.frc_hb` with the gamma grid's STEP as the largest
spacing), checked against what must hold (issue 9):

* the branch covers the requested range (``complete``), or it is
  ``unbounded`` where friction cannot bound the resonance (Den Hartog:
  beta = mu N0 / F1 < pi/4 without viscous damping);
* its highest peak agrees with the time-domain steady state at the same
  gamma (:func:`jointdyn.dynamics.steady_state`, where that is periodic).

``docs/scripts/hb_robustness.py`` writes the table of the whole grid into
``docs/hb-robustness.md``; the tests run a subset; ``benchmarks/bench_hb.py``
reports the grid's time and completion rate.
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass

from .. import config

__all__ = ["GRID_MODELS", "GRID_ETAS", "GRID_BETAS", "GRID_GAMMA", "GridCase", "grid_case", "grid_table"]

#: the grid of issue 9: models (default exact, closed form with full memory, the paper's rule, Jenkins),
#: eta = N1 / N0, beta = mu N0 / F1, gamma START:STOP:STEP
GRID_MODELS = (config.MODEL, "iwan-closed", "iwan-paper", "jenkins")
GRID_ETAS = (0.01, 0.5, 1.5, 10.0)
GRID_BETAS = (0.1, 1.0, 2.0, 5.0, 10.0, 1000.0)
GRID_GAMMA = (0.6, 1.8, 0.01)
#: Den Hartog's bound: below this beta friction alone cannot bound the resonance
DEN_HARTOG_BETA = math.pi / 4


@dataclass(frozen=True)
class GridCase:
    """One case of the grid and its checks.

    Attributes
    ----------
    model : str
    eta, beta : float
    status : str
        Branch status (``complete``, ``unbounded``, ``failed``, ...).
    ok : bool
        The branch covers the range, or is unbounded with beta below Den
        Hartog's bound, and its highest peak (if any, where the time
        domain is periodic) is within ``rtol`` of the time domain.
    points, folds, unstable : int
        Points, folds and unstable points of the branch.
    peak_gamma, peak_q : float
        Highest refined peak (NaN without one).
    time_q : float
        Time-domain steady-state q at ``peak_gamma`` (NaN if not periodic or no peak).
    peak_error : float
        (peak_q - time_q) / time_q (NaN where not compared).
    seconds : float
        CPU seconds of the branch (process time).
    message : str
        The branch's message.
    """

    model: str
    eta: float
    beta: float
    status: str
    ok: bool
    points: int
    folds: int
    unstable: int
    peak_gamma: float
    peak_q: float
    time_q: float
    peak_error: float
    seconds: float
    message: str


def grid_case(model: str, eta: float, beta: float, gamma=GRID_GAMMA, *, time_domain: bool = True,
              rtol: float = 0.01) -> GridCase:
    """Run and check one case of the grid (see the module docstring)."""
    from ..dynamics import steady_state
    from ..hb import frc_hb
    from ..systems import System

    system = System.paper_damper(eta=eta, beta=beta, model=model)
    t0 = time.process_time()
    ds = frc_hb(system, gamma[0], gamma[1], max_step=gamma[2], progress=False)
    seconds = time.process_time() - t0
    status = str(ds.attrs["status"])
    covered = status == "complete" or (status == "unbounded" and beta < DEN_HARTOG_BETA)
    g_pk, q_pk = float(ds.attrs["peak_gamma"]), float(ds.attrs["peak_amplitude_q"])
    q_td = err = math.nan
    if time_domain and math.isfinite(g_pk):
        ss = steady_state(system, g_pk)
        if ss.status == "periodic":
            law = system.contacts[0].law
            q_td = law.kt * ss.amplitude_m / law.fy
            err = (q_pk - q_td) / q_td
    ok = covered and not abs(err) > rtol  # NaN (not compared) passes
    return GridCase(model=model, eta=eta, beta=beta, status=status, ok=bool(ok), points=int(ds.sizes["point"]),
                    folds=int(ds.attrs["folds"]), unstable=int(ds.attrs["unstable_points"]), peak_gamma=g_pk,
                    peak_q=q_pk, time_q=q_td, peak_error=err, seconds=seconds, message=str(ds.attrs["message"]))


def _num(v, fmt) -> str:
    return "-" if not math.isfinite(v) else format(v, fmt)


def grid_table(cases) -> str:
    """Markdown table of grid cases (one row each) and a summary line."""
    cases = list(cases)
    lines = ["| model | eta | beta | status | points | folds | unstable | peak gamma | peak q | time-domain q | "
             "error | CPU s | ok |", "|" + "---|" * 13]
    for c in cases:
        lines.append(f"| {c.model} | {c.eta:g} | {c.beta:g} | {c.status} | {c.points} | {c.folds} | {c.unstable} | "
                     f"{_num(c.peak_gamma, '.5f')} | {_num(c.peak_q, '.5g')} | {_num(c.time_q, '.5g')} | "
                     f"{_num(100 * c.peak_error, '+.2f')}{'' if not math.isfinite(c.peak_error) else ' %'} | "
                     f"{c.seconds:.2f} | {'yes' if c.ok else '**no**'} |")
    good = sum(c.ok for c in cases)
    lines.append("")
    lines.append(f"{good} of {len(cases)} cases pass; {sum(c.status == 'complete' for c in cases)} branches "
                 f"complete; CPU time of the branches {sum(c.seconds for c in cases):.1f} s.")
    return "\n".join(lines)
