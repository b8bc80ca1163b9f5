"""Sweep speed (issue 3, sweeps): the full Fig 6 data set and a per-point comparison
against a plain ``scipy.integrate.solve_ivp``-style integration.

``run(quick)`` returns

- ``fig6_seconds``: wall time of the Fig 6 sweep (4 eta x 6 beta x gamma grid,
  up and down, the default contact model named in ``model``) on all local
  cores; ``quick`` uses a reduced gamma grid and says so (``grid``); the
  default model against the closed form in the same run is
  ``bench_exact.py``'s ``fig6_time_domain``;
- ``seconds_per_point``: mean steady-state point cost (wall time x workers /
  points, i.e. CPU-seconds per point) of that sweep;
- ``baseline``: for a subset of points, the seconds of ``jointdyn``'s
  ``steady_state`` for that point alone (cold start, one thread) and of the
  reference integrator run over the same number of forcing periods, and
  their ratio (best of ``BASELINE_ROUNDS`` rounds, each round one run of
  jointdyn then one of the reference; 1 round in quick mode).

Reference integrator: scipy's explicit Runge-Kutta (RK45, rtol 1e-8, step at
most the period / ``MarchOptions().steps_per_period`` like jointdyn's base step) stepped
from Python; every right-hand-side evaluation calls the contact law's
compiled trial kernel from Python (``law.step`` from the committed state),
and the law's state is committed after every accepted step -- the textbook
way of putting a hysteretic law into an ODE solver. It does not locate
separation instants (an honest but lighter baseline than jointdyn's solver).
When the point needs many periods the reference runs at most
``BASELINE_MAX_PERIODS`` of them and its time is scaled to the same count
(``baseline_periods_run`` says how many ran).
"""

from __future__ import annotations

import math
import time

import numpy as np

BASELINE_MAX_PERIODS = 20
BASELINE_ROUNDS = 5
BASELINE_POINTS = (  # (eta, beta, gamma)
    (0.5, 2.0, 0.9),
    (0.5, 2.0, 1.2),
    (1.5, 5.0, 1.1),
    (0.01, 10.0, 1.5),
)


def _reference_periods(system, gamma, periods):
    """Integrate ``periods`` forcing periods with scipy RK45 + Python law calls.

    Step size capped at the period / ``MarchOptions().steps_per_period`` (the
    base step of jointdyn's integrator: the same time resolution), rtol 1e-8.
    """
    from scipy.integrate import RK45

    from jointdyn.dynamics import MarchOptions

    steps = MarchOptions().steps_per_period
    c = system.contacts[0]
    law = c.law
    step = law.step
    params = law.params
    m = float(system.M[0, 0])
    k = float(system.K[0, 0])
    cv = float(system.C[0, 0])
    f1 = float(system.force[0])
    w = gamma * system.w0
    delta = math.radians(c.phase_deg)
    s_old = law.initial_state(0.0, c.n0 + c.n1 * math.sin(delta))
    s_new = np.empty_like(s_old)

    def rhs(t, y):
        N = c.n0 + c.n1 * math.sin(w * t + delta)
        T, _, _ = step(params, s_old, s_new, y[0], N)
        return np.array([y[1], (f1 * math.sin(w * t) - k * y[0] - cv * y[1] - T) / m])

    t_end = periods * 2.0 * math.pi / w
    solver = RK45(rhs, 0.0, np.zeros(2), t_end, rtol=1e-8, atol=1e-12, max_step=(2 * math.pi / w) / steps)
    nsteps = 0
    while solver.status == "running":
        solver.step()
        nsteps += 1
        # commit the law at the accepted point
        N = c.n0 + c.n1 * math.sin(w * solver.t + delta)
        step(params, s_old, s_new, solver.y[0], N)
        s_old[:] = s_new
    return nsteps


def run(quick: bool = False) -> dict:
    import os

    from jointdyn.dynamics import steady_state
    from jointdyn.figures.dynamics import FIG6_BETAS, FIG6_ETAS, FIG6_GAMMA, fig6_data
    from jointdyn.sweeps import default_workers
    from jointdyn.systems import System

    out = {"load_average_before": list(os.getloadavg())}
    # warm the numba cache (compile once) so timings are steady-state speed
    steady_state(System.paper_damper(eta=0.5, beta=2.0), 1.0)

    start, stop, step_ = FIG6_GAMMA
    if quick:
        step_ = 0.05
    gammas = np.round(start + step_ * np.arange(int(round((stop - start) / step_)) + 1), 12)
    workers = default_workers()
    t0 = time.perf_counter()
    df = fig6_data(gammas=gammas, progress=False)
    wall = time.perf_counter() - t0
    npts = len(df)
    out["grid"] = (f"{'REDUCED (quick) ' if quick else ''}{len(FIG6_ETAS)} eta x {len(FIG6_BETAS)} beta x "
                   f"{len(gammas)} gamma x 2 directions = {npts} points")
    out["model"] = str(df.model.iloc[0])
    out["fig6_seconds"] = wall
    out["fig6_target_seconds"] = 60.0
    out["workers"] = workers
    out["cpu_count"] = os.cpu_count()
    out["seconds_per_point"] = wall * workers / npts
    out["status_counts"] = {str(k): int(v) for k, v in df.status_name.value_counts().items()}
    out["mean_periods_per_point"] = float(df.periods.mean())

    from jointdyn.dynamics import MarchOptions

    _reference_periods(System.paper_damper(eta=0.5, beta=2.0), 1.0, 1)  # warm the Python-side dispatch
    rows = []
    for eta, beta, gamma in BASELINE_POINTS[: 2 if quick else None]:
        system = System.paper_damper(eta=eta, beta=beta)
        # rounds alternate one run of each (best of rounds for both, same
        # policy): a burst of load on this shared machine hits both sides
        reps = 1 if quick else BASELINE_ROUNDS
        res = steady_state(system, gamma)
        periods = max(1, int(res.periods))
        run_p = min(periods, 3 if quick else BASELINE_MAX_PERIODS)
        t_ours = t_ref = math.inf
        for _ in range(reps):
            t0 = time.perf_counter()
            res = steady_state(system, gamma)
            t_ours = min(t_ours, time.perf_counter() - t0)
            t0 = time.perf_counter()
            nsteps = _reference_periods(system, gamma, run_p)
            t_ref = min(t_ref, (time.perf_counter() - t0) * periods / run_p)
        rows.append(dict(eta=eta, beta=beta, gamma=gamma, status=res.status, periods=periods,
                         seconds_jointdyn=t_ours, seconds_reference=t_ref, baseline_periods_run=run_p,
                         reference_steps=nsteps, ms_per_period_jointdyn=1e3 * t_ours / periods,
                         ms_per_period_reference=1e3 * t_ref / periods, speedup=t_ref / t_ours))
    out["baseline"] = rows
    out["baseline_speedup_geomean"] = math.exp(sum(math.log(r["speedup"]) for r in rows) / len(rows))
    out["baseline_note"] = ("reference = scipy RK45 stepped from Python, law kernel called from Python at every "
                            "RHS evaluation, law state committed at accepted steps, max step = period/"
                            f"{MarchOptions().steps_per_period}, rtol 1e-8; time scaled from baseline_periods_run to "
                            "the periods jointdyn used for the point")
    out["load_average_after"] = list(os.getloadavg())
    out["load_note"] = ("the machine is shared: a 1-minute load average above the core count means other "
                        "jobs took CPU during the timings")
    out["speedup_per_point_geomean"] = float(np.exp(np.mean([np.log(r["speedup"]) for r in rows])))
    out["speedup_target"] = 100.0
    return out
