"""Robustness grid of harmonic balance: default settings on the paper's parameter grid, checked.

Every case is one ``jointdyn frc --method hb`` run with the CLI's defaults
(:func:`jointdyn.hb.frc_hb` with the gamma grid's STEP as the largest
spacing), checked against what must hold (issue 9):

* the branch covers the requested range (``complete``), or it is
  ``unbounded`` where friction cannot bound the resonance (Den Hartog:
  beta = mu N0 / F1 < pi/4 without viscous damping);
* its highest peak agrees with the time-domain steady state at the same
  gamma (:func:`jointdyn.dynamics.steady_state`, where that is periodic),
  started on the harmonic-balance orbit (:func:`hb_restart`): where
  several orbits coexist, the one harmonic balance found is checked.

``docs/scripts/hb_robustness.py`` writes the table of the whole grid into
``docs/hb-robustness.md``; the tests run a subset; ``benchmarks/bench_hb.py``
reports the grid's time and completion rate.
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass

import numpy as np

from .. import config

__all__ = ["GRID_MODELS", "GRID_ETAS", "GRID_BETAS", "GRID_GAMMA", "GridCase", "grid_case", "grid_table",
           "hb_restart"]

#: the grid of issue 9: models (default exact, closed form with full memory, the paper's rule, Jenkins),
#: eta = N1 / N0, beta = mu N0 / F1, gamma START:STOP:STEP
GRID_MODELS = (config.MODEL, "iwan-closed", "iwan-paper", "jenkins")
GRID_ETAS = (0.01, 0.5, 1.5, 10.0)
GRID_BETAS = (0.1, 1.0, 2.0, 5.0, 10.0, 1000.0)
GRID_GAMMA = (0.6, 1.8, 0.01)
#: Den Hartog's bound: below this beta friction alone cannot bound the resonance
DEN_HARTOG_BETA = math.pi / 4
#: periods and samples per period of the HB displacement marched to set the contact states of a time-domain
#: start on a harmonic-balance orbit (those of the monodromy check)
WARM_PERIODS = config.MONODROMY_WARM_PERIODS
WARM_SAMPLES = config.MONODROMY_WARM_SAMPLES


@dataclass(frozen=True)
class GridCase:
    """One case of the grid and its checks.

    Attributes
    ----------
    model : str
    eta, beta : float
    status : str
        Branch status (``complete``, ``unbounded``, ``failed``, ...).
    covered : bool
        The branch covers the range, or is unbounded with beta below Den
        Hartog's bound.
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
    covered: bool
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
    from ..hb import branch_dataset, continue_hb
    from ..systems import System

    system = System.paper_damper(eta=eta, beta=beta, model=model)
    t0 = time.process_time()
    br = continue_hb(system, gamma[0], gamma[1], max_step=gamma[2], progress=False)
    ds = branch_dataset(br)
    seconds = time.process_time() - t0
    status = str(ds.attrs["status"])
    covered = status == "complete" or (status == "unbounded" and beta < DEN_HARTOG_BETA)
    g_pk, q_pk = float(ds.attrs["peak_gamma"]), float(ds.attrs["peak_amplitude_q"])
    q_td = err = math.nan
    if time_domain and math.isfinite(g_pk):
        top = max(br.peaks, key=lambda pk: pk.amplitude_q)
        ss = steady_state(system, g_pk, start=hb_restart(system, top.X, g_pk, br.problem.H))
        if ss.status == "periodic":
            law = system.contacts[0].law
            q_td = law.kt * ss.amplitude_m / law.fy
            err = (q_pk - q_td) / q_td
    ok = covered and not abs(err) > rtol  # NaN (not compared) passes
    return GridCase(model=model, eta=eta, beta=beta, status=status, covered=covered, ok=bool(ok),
                    points=int(ds.sizes["point"]), folds=int(ds.attrs["folds"]),
                    unstable=int(ds.attrs["unstable_points"]), peak_gamma=g_pk, peak_q=q_pk, time_q=q_td, peak_error=err, seconds=seconds, message=str(ds.attrs["message"]))


def hb_restart(system, X, gamma: float, harmonics: int, periods: int = WARM_PERIODS,
               samples: int = WARM_SAMPLES):
    """Time-domain start (:class:`~jointdyn.dynamics.Restart`) on a harmonic-balance orbit at phase 0.

    Displacements and velocities of the harmonics X (m, layout of
    :class:`~jointdyn.hb.HBProblem`) at w t = 0; the contact law states
    from marching each law over ``periods`` periods of the HB displacement
    (``samples`` per period) ending there, so that a stable orbit is
    continued, not another one that coexists with it at the same gamma.
    """
    from ..drivers import march
    from ..dynamics import Restart
    from ..fourier import basis, derivative_matrix
    from ..kinematics import contact_kinematics, normal_load_samples, tangential_history

    n = system.ndof
    Xm = np.asarray(X, dtype=float).reshape(2 * harmonics + 1, n)
    e0 = basis(harmonics, np.array([0.0]))[0]
    w = gamma * system.w0
    tt = np.arange(periods * samples + 1) * (2.0 * np.pi / samples)
    kin = contact_kinematics(system)
    U = tangential_history(kin.arrays, np.ascontiguousarray(basis(harmonics, tt) @ Xm))
    N = normal_load_samples(kin, tt)
    S = np.zeros((len(system.contacts), max([c.law.state_size for c in system.contacts], default=1)))
    for i, c in enumerate(system.contacts):
        st = march(c.law, np.ascontiguousarray(U[:, i]), N[i])[3]
        S[i, : st.size] = st
    return Restart(x=e0 @ Xm, v=w * (e0 @ (derivative_matrix(harmonics) @ Xm)), states=S)


def _num(v, fmt) -> str:
    return "-" if not math.isfinite(v) else format(v, fmt)


def grid_table(cases) -> str:
    """Markdown table of grid cases (one row each) and a summary line."""
    cases = list(cases)
    head = ("| model | eta | beta | status | points | folds | unstable | peak gamma | peak q | time-domain q | "
            "error | CPU s | ok |")
    lines = [head, "|" + "---|" * 13]
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
