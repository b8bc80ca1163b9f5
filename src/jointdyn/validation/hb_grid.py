"""Robustness grid of harmonic balance: default settings on the paper's parameter grid, checked.

Every case is one ``jointdyn frc --method hb`` run with the CLI's defaults
(:func:`jointdyn.hb.frc_hb` with the gamma grid's STEP as the largest
spacing), checked against what must hold:

* the branch covers the requested range (``complete``), or it is
  ``unbounded`` where friction cannot bound the resonance (Den Hartog:
  beta = mu N0 / F1 < pi/4 without viscous damping);
* its highest peak agrees with the time-domain steady state at the same
  gamma (:func:`jointdyn.dynamics.steady_state`, where that is periodic),
  started on the harmonic-balance orbit (:func:`hb_restart`): where
  several orbits coexist, the one harmonic balance found is checked.

The comparison needs a time-domain orbit that harmonic balance (period
one, one solution per point) can be: where the steady state repeats only
every p > 1 forcing periods (a subharmonic orbit), or where it depends on
the start (a second integration from rest settles elsewhere, by more than
the tolerance), the case is not compared and says which (:class:`Verdict`).
Both happen only with the closed forms, whose force jumps with the normal
load.

``docs/scripts/hb_robustness.py`` writes the table of the whole grid into
``docs/hb-robustness.md``; the tests run a subset; ``benchmarks/bench_hb_grid.py``
reports the grid's time and completion rate. :func:`grid_cases` runs many
cases, on several processes if asked.
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass

import numpy as np

from .. import config
from ..continuation import ContinuationStatus
from ..status import Status

__all__ = ["GRID_MODELS", "GRID_ETAS", "GRID_BETAS", "GRID_GAMMA", "GridCase", "Verdict", "grid_case",
           "grid_cases", "grid_table", "hb_restart"]

#: the robustness grid: models (default exact, closed form with full memory, the paper's rule, Jenkins),
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


class Verdict(Status):
    """Outcome of the time-domain check of a grid case's highest peak."""

    AGREES = "agrees", "the peak is within the tolerance of the time-domain steady state", True
    DIFFERS = "differs", "the peak is off the time-domain steady state by more than the tolerance"
    NO_PEAK = "no-peak", "no peak to compare (unbounded, or the amplitude has no maximum)", True
    PEAK_IN_JUMP = ("peak-in-a-jump", "the highest amplitude lies at a jump of the branch, above every peak "
                    "found: the peak between the jump's ends is not resolved")
    NOT_PERIODIC = ("not-periodic", "the time domain found no periodic steady state at the peak: nothing to "
                    "compare (not compared)")
    SUBHARMONIC = ("subharmonic", "the time-domain steady state repeats only every p > 1 forcing periods: "
                   "a period-one harmonic balance cannot be that orbit (not compared)")
    NOT_UNIQUE = ("not-unique", "the time-domain steady state depends on the start (from the harmonic-balance "
                  "orbit and from rest it settles on amplitudes farther apart than the tolerance; not compared)")


@dataclass(frozen=True)
class GridCase:
    """One case of the grid and its checks.

    Attributes
    ----------
    model : str
    eta, beta : float
    status : ContinuationStatus
        The branch's status (``complete``, ``unbounded``, ``failed``, ...):
        what the branch delivered, with its own ``ok``.
    covered : bool
        What the grid asks of the branch: it covers the range, or is
        unbounded with beta below Den Hartog's bound (where friction cannot
        bound the resonance).
    ok : bool
        Whether the case delivers what the grid asks: ``covered`` and the
        ``verdict`` of the time-domain check ``ok`` (the peak agrees, or
        there is none). A covered case whose peak could not be compared
        (:data:`NOT_COMPARED`: the time domain is subharmonic, depends on the
        start or is not periodic) is not ok: the table marks it ``n/c``,
        as :mod:`jointdyn.validation.hb_folds` counts a fold check with
        nothing to compare.
    points, folds, unstable : int
        Points, folds and unstable points of the branch.
    peak_gamma, peak_q : float
        Highest refined peak (NaN without one).
    time_q : float
        Time-domain steady-state q at ``peak_gamma``, started on the
        harmonic-balance orbit (NaN if not periodic or no peak).
    time_period : int
        Forcing periods after which that steady state repeats (0 where not
        periodic or not run).
    rest_q : float
        Where the peak differs from ``time_q``: the steady state at the
        same gamma started from rest (NaN where not run).
    peak_error : float
        (peak_q - time_q) / time_q (NaN where not compared).
    verdict : Verdict
        Outcome of the time-domain check.
    seconds : float
        CPU seconds of the branch (process time), the automatic choice of
        harmonics and samples included.
    harmonics, samples : int
        H and Ns of the reported branch (chosen automatically).
    message : str
        The branch's message.
    """

    model: str
    eta: float
    beta: float
    status: ContinuationStatus
    covered: bool
    ok: bool
    points: int
    folds: int
    unstable: int
    peak_gamma: float
    peak_q: float
    time_q: float
    time_period: int
    rest_q: float
    peak_error: float
    verdict: Verdict
    seconds: float
    harmonics: int
    samples: int
    message: str


def grid_case(model: str, eta: float, beta: float, gamma=GRID_GAMMA, *, time_domain: bool = True,
              rtol: float = 0.01) -> GridCase:
    """Run and check one case of the grid (see the module docstring)."""
    from ..hb import branch_dataset, continue_hb
    from ..systems import System

    system = System.paper_damper(eta=eta, beta=beta, model=model)
    t0 = time.process_time()
    br = continue_hb(system, gamma[0], gamma[1], max_step=gamma[2], progress=False)
    ds = branch_dataset(br)
    seconds = time.process_time() - t0
    status = br.status
    covered = status.ok or (status is ContinuationStatus.UNBOUNDED and beta < DEN_HARTOG_BETA)
    g_pk, q_pk = float(ds.attrs["peak_gamma"]), float(ds.attrs["peak_amplitude_q"])
    if _highest_at_jump(ds, q_pk):
        check = (Verdict.PEAK_IN_JUMP, math.nan, 0, math.nan)
    elif time_domain and math.isfinite(g_pk):
        check = _time_check(system, br, g_pk, q_pk, rtol)
    else:
        check = None
    verdict, q_td, period, q_rest = check or (Verdict.NO_PEAK, math.nan, 0, math.nan)
    err = (q_pk - q_td) / q_td if verdict in (Verdict.AGREES, Verdict.DIFFERS) else math.nan
    ok = covered and verdict.ok
    return GridCase(model=model, eta=eta, beta=beta, status=status, covered=covered, ok=bool(ok),
                    points=int(ds.sizes["point"]), folds=int(ds.attrs["folds"]),
                    unstable=int(ds.attrs["unstable_points"]), peak_gamma=g_pk, peak_q=q_pk, time_q=q_td,
                    time_period=period, rest_q=q_rest, peak_error=err, verdict=verdict, seconds=seconds,
                    harmonics=int(ds.attrs["harmonics"]), samples=int(ds.attrs["samples"]),
                    message=str(ds.attrs["message"]))


def grid_cases(cases, *, time_domain: bool = True, workers: int = 1) -> list:
    """:func:`grid_case` of every ``(model, eta, beta)`` of ``cases``, in their order.

    ``workers`` > 1: the cases run on that many processes, each taking the
    next case as it finishes one (``fork`` where the platform has it: the
    workers inherit the compiled kernels loaded here; they ignore SIGINT
    and end with this process, as the sweeps' workers do).
    ``GridCase.seconds`` is the CPU time of the branch in its worker.
    """
    from .. import _validate as V

    cases = [(str(m), float(e), float(b)) for m, e, b in cases]
    workers = V.positive_int("workers", workers, 1)
    if workers == 1 or len(cases) < 2:
        return [grid_case(*c, time_domain=time_domain) for c in cases]
    import concurrent.futures as cf
    import os

    from ..sweeps._pool import detach_worker, process_context

    with cf.ProcessPoolExecutor(max_workers=min(workers, len(cases)), mp_context=process_context(),
                                initializer=detach_worker, initargs=(os.getpid(),)) as pool:
        return list(pool.map(_case_task, [(c, time_domain) for c in cases]))


def _case_task(task) -> GridCase:
    """One case of :func:`grid_cases` in a worker: ``((model, eta, beta), time_domain)``."""
    case, time_domain = task
    return grid_case(*case, time_domain=time_domain)


def _highest_at_jump(ds, q_peak: float) -> bool:
    """True when the branch's highest amplitude is a point reached by a jump, or the point the jump left,
    above the highest peak found (``q_peak``, NaN without one): the resonance lies in the jump."""
    q = np.asarray(ds["amplitude_q"].values, dtype=float)
    if not np.isfinite(q).any() or q_peak >= float(np.nanmax(q)):
        return False
    i = int(np.nanargmax(q))
    after = np.asarray(ds["point_status"].values) == "after-jump"
    return bool(after[i] or (i + 1 < after.size and after[i + 1]))


def _time_check(system, br, g_pk: float, q_pk: float, rtol: float):
    """(verdict, time-domain q from the HB orbit, its period multiple, q from rest) at the highest peak."""
    from ..dynamics import steady_state

    law = system.contacts[0].law
    top = max(br.peaks, key=lambda pk: pk.amplitude_q)
    ss = steady_state(system, g_pk, start=hb_restart(system, top.X, g_pk, br.problem.H))
    q_td = law.kt * ss.amplitude_m / law.fy
    if not ss.status.ok:
        return Verdict.NOT_PERIODIC, math.nan, 0, math.nan
    if ss.period_multiple > 1:
        return Verdict.SUBHARMONIC, q_td, ss.period_multiple, math.nan
    if abs(q_pk - q_td) <= rtol * q_td:
        return Verdict.AGREES, q_td, 1, math.nan
    rest = steady_state(system, g_pk)
    q_rest = law.kt * rest.amplitude_m / law.fy if rest.status.ok else math.nan
    if rest.status.ok and rest.period_multiple == 1 and abs(q_rest - q_td) > rtol * q_td:
        return Verdict.NOT_UNIQUE, q_td, 1, q_rest
    return Verdict.DIFFERS, q_td, 1, q_rest


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


def _ok_mark(c: GridCase, apart) -> str:
    """``yes``, ``n/c`` (covered, the peak not comparable with the time domain) or ``**no**``."""
    return "yes" if c.ok else ("n/c" if c.covered and c.verdict in apart else "**no**")


#: verdicts where the peak is not compared with the time domain (no periodic orbit that a period-one
#: harmonic balance can be): neither a pass nor a failure
NOT_COMPARED = (Verdict.SUBHARMONIC, Verdict.NOT_UNIQUE, Verdict.NOT_PERIODIC)


def grid_table(cases) -> str:
    """Markdown table of grid cases (one row each) and a summary line."""
    cases = list(cases)
    head = ("| model | eta | beta | status | points | folds | unstable | peak gamma | peak q | time-domain q | "
            "error | check | H x Ns | CPU s | ok |")
    lines = [head, "|" + "---|" * 15]
    apart = NOT_COMPARED
    for c in cases:
        check = c.verdict.value
        if c.verdict is Verdict.SUBHARMONIC:
            check += f" (period {c.time_period})"
        elif c.verdict is Verdict.NOT_UNIQUE:
            check += f" (from rest q = {c.rest_q:.5g})"
        lines.append(f"| {c.model} | {c.eta:g} | {c.beta:g} | {c.status} | {c.points} | {c.folds} | {c.unstable} | "
                     f"{_num(c.peak_gamma, '.5f')} | {_num(c.peak_q, '.5g')} | {_num(c.time_q, '.5g')} | "
                     f"{_num(100 * c.peak_error, '+.2f')}{'' if not math.isfinite(c.peak_error) else ' %'} | "
                     f"{check} | {c.harmonics} x {c.samples} | {c.seconds:.2f} | {_ok_mark(c, apart)} |")
    nc = [sum(c.covered and c.verdict is v for c in cases) for v in apart]
    lines.append("")
    lines.append(f"{sum(c.ok for c in cases)} of {len(cases)} cases pass, {sum(nc)} not compared (time-domain "
                 f"steady state subharmonic: {nc[0]}, dependent on the start: {nc[1]}, not periodic: {nc[2]}), "
                 f"{sum(not c.ok and _ok_mark(c, apart) != 'n/c' for c in cases)} fail; "
                 f"{sum(c.status.ok for c in cases)} branches complete; CPU time of the branches "
                 f"{sum(c.seconds for c in cases):.1f} s.")
    return "\n".join(lines)
