"""Time integration of a :class:`~jointdyn.systems.System` (docs/model.md section 6).

Equation of motion (systems.py)::

    M x'' + C x' + K x = F(t) - sum_c B_c T_c(u_c, N_c(t)),   u_c = B_c . x,

with either harmonic loads ``F = f sin(w t)``, ``N_c = n0 + n1 sin(w t +
delta)`` (:func:`integrate`) or sampled ones (:func:`integrate_sampled`).
The scheme (explicit RK4 with trial/commit law evaluation, step boundaries
at separation/re-contact, steps split at velocity reversals) is described in
``_core.py`` and docs/time-integration.md.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .. import _validate as V
from ..kinematics import sampled_load_grid
from ..systems import System
from ._core import LOADS_SAMPLED
from ._model import Model, make_model, refine_if_opened, run
from ._start import free_body_start
from .options import MarchOptions, march_options, march_with_steps
from .status import RunStatus

__all__ = ["Trajectory", "Restart", "integrate", "integrate_sampled"]


@dataclass(frozen=True)
class Restart:
    """State of a run at a forcing-period boundary (phase w t = 0 mod 2 pi).

    Opaque to users: pass it (or a :class:`SteadyState` holding it) as
    ``start`` to warm-start another run of the same system.

    Attributes
    ----------
    x, v : ndarray
        Displacements (m) and velocities (m/s), one per DOF.
    states : ndarray
        Committed law states, one row per contact, then the sliders of the
        interface pairs (two numbers per pair, row after row).
    """

    x: np.ndarray
    v: np.ndarray
    states: np.ndarray


@dataclass(frozen=True)
class Trajectory:
    """Samples of a time integration (every accepted step end).

    Attributes
    ----------
    t : ndarray, shape (ns,)
        Time, s (the first sample is the initial state).
    x, v : ndarray, shape (ns, ndof)
        Displacements (m) and velocities (m/s).
    T : ndarray, shape (ns, ncontacts)
        Tangential contact forces, N.
    N : ndarray, shape (ns, ncontacts)
        Normal loads, N.
    code : ndarray of int8, shape (ns, ncontacts)
        Motion state per contact (STICK_SLIP, MACROSLIP, SEPARATION).
        Interface pairs are not recorded here: their relative motion is
        that of ``x`` (``Interface.relative``), their sliders are in
        ``final.states`` and their per-period results in
        :class:`~jointdyn.dynamics.SteadyState`.
    final : Restart
        Final state (x, v, law states), usable as a start for a further run.
    status : RunStatus
        ``"ok"`` or ``"blow-up"`` (non-finite or astronomically large state).
    """

    t: np.ndarray
    x: np.ndarray
    v: np.ndarray
    T: np.ndarray
    N: np.ndarray
    code: np.ndarray
    final: Restart
    status: RunStatus = RunStatus.OK

    @property
    def message(self) -> str:
        """What the status means, in one line."""
        return self.status.message


def _omega(system: System, gamma) -> float:
    g = V.positive("gamma", gamma)
    w0 = system.w0
    if not w0 > 0:
        raise ValueError("system has no positive natural frequency w0 (gamma = w / w0 undefined)")
    return g * w0


def _start_vectors(model: Model, x0, v0, states):
    n = model.n
    x = np.zeros(n) if x0 is None else V.finite_array("x0", np.atleast_1d(x0)).copy()
    v = np.zeros(n) if v0 is None else V.finite_array("v0", np.atleast_1d(v0)).copy()
    if x.shape != (n,):
        raise ValueError(f"x0 must have length {n}, got {x.shape[0]}")
    if v.shape != (n,):
        raise ValueError(f"v0 must have length {n}, got {v.shape[0]}")
    if states is None:
        S = model.initial_states(x)
    else:
        S = np.array(states, dtype=np.float64, ndmin=2)
        shape = (model.pack.state_rows, model.pack.slen)
        if S.shape != shape:
            raise ValueError(f"states must have shape {shape}, got {S.shape}")
    return x, v, np.ascontiguousarray(S)


def integrate(
    system: System,
    gamma: float,
    *,
    periods: int = 1,
    steps_per_period: int | None = None,
    x0=None,
    v0=None,
    states=None,
    start: Restart | None = None,
    options: MarchOptions | None = None,
) -> Trajectory:
    """Integrate the harmonically forced system over whole forcing periods.

    Solves M x'' + C x' + K x = f sin(w t) - sum_c B_c T_c(u_c, N_c(t)) with
    N_c(t) = n0 + n1 sin(w t + delta) (docs/model.md section 6) from t = 0.

    Parameters
    ----------
    system : System
        The structure, contacts and forcing amplitudes.
    gamma : float
        Frequency ratio w / w0 (> 0), w0 = ``system.w0``.
    periods : int
        Number of forcing periods (>= 1).
    steps_per_period : int, optional
        Base steps per forcing period (default ``options.steps_per_period``,
        256; replaces that field); raised automatically so that w_max h <=
        ``options.max_omega_h`` for the stiffest mode with every contact
        stuck and every normal spring closed, and (the run repeated) so that
        w_max h <= ``options.spring_omega_h`` when a normal spring opens;
        events and reversals add steps.
    x0, v0 : array_like, optional
        Initial displacements (m) and velocities (m/s); default rest (the preloaded static state); for
        a free-free structure (rigid-body modes with every contact stuck) the default starts its
        rigid-body part in the periodic motion of the free body, zero mean position and momentum
        (:func:`jointdyn.dynamics._start.free_body_start`), so that the forcing's start imparts no drift.
    states : array_like, optional
        Committed law states (one row per contact); default virgin at x0.
    start : Restart, optional
        Initial state from a previous run (overrides x0, v0, states).
    options : MarchOptions, optional
        The numbers of the time march (:class:`~jointdyn.dynamics.options.MarchOptions`; None: the
        defaults).

    Returns
    -------
    Trajectory
        Samples at every accepted step end (grid points, separation and
        re-contact instants, velocity reversals of the contacts).
    """
    if not isinstance(system, System):
        raise ValueError(f"system must be a System, got {type(system).__name__}")
    march = march_with_steps(options, steps_per_period, name="options")
    periods = V.positive_int("periods", periods)
    w = _omega(system, gamma)
    model = make_model(system, w, march)
    rest = start is None and x0 is None and v0 is None
    if start is not None:
        x0, v0, states = start.x, start.v, start.states
    x, v, S = _start_vectors(model, x0, v0, states)
    if rest:  # a free-free structure: its rigid-body part in the free body's periodic motion (no drift)
        x, v = free_body_start(model, x, v)
    start = (x.copy(), v.copy(), S.copy())
    res = model.run_periods(x, v, S, periods, rec=True)
    finer = refine_if_opened(model, res.summary)
    if finer is not None:  # a normal spring opened: again with the refined steps
        x, v, S = (a.copy() for a in start)
        res = finer.run_periods(x, v, S, periods, rec=True)
    return _trajectory(res, x, v, S)


def _trajectory(res, x, v, S) -> Trajectory:
    t, X, Vv, T, N, code = res.samples
    return Trajectory(t=t, x=X, v=Vv, T=T, N=N, code=code, final=Restart(x.copy(), v.copy(), S.copy()),
                      status=res.status)  # fmt: skip


def _as_samples(name, values, t, width):
    if callable(values):
        arr = np.array([np.atleast_1d(np.asarray(values(ti), dtype=float)) for ti in t])
    else:
        arr = np.asarray(values, dtype=float)
    if arr.ndim == 1 and width == 1:
        arr = arr[:, None]
    arr = V.finite_array(name, arr, 2)
    if arr.shape != (t.size, width):
        raise ValueError(f"{name} must have shape {(t.size, width)}, got {arr.shape}")
    return arr


def integrate_sampled(
    system: System,
    t,
    force,
    normal,
    *,
    x0=None,
    v0=None,
    states=None,
    start: Restart | None = None,
    options: MarchOptions | None = None,
) -> Trajectory:
    """Integrate with forcing and normal loads given at sample times.

    F(t) and N_c(t) are piecewise linear between the samples; each sample
    interval is one RK4 step (use as many samples as accuracy needs), with
    an extra step boundary at every zero crossing of a normal load and steps
    split at velocity reversals of the contacts, as in :func:`integrate`.
    The system's own ``force``, ``n0``, ``n1`` and ``delta`` are ignored.

    Parameters
    ----------
    system : System
        Mass, damping, stiffness and contacts (laws and DOFs).
    t : array_like, shape (nt,)
        Strictly increasing sample times, s.
    force : array_like (nt, ndof) or callable
        Forcing per DOF at the samples, N; a callable ``F(t) -> (ndof,)`` is
        evaluated at the samples.
    normal : array_like (nt, ncontacts) or callable
        Normal loads at the samples, N; or a callable ``N(t) -> (ncontacts,)``.
        The column of a contact with a normal spring is not read (its load
        comes from the state).
    x0, v0, states, start
        As in :func:`integrate`.
    options : MarchOptions, optional
        As in :func:`integrate`; the steps are the samples' (``steps_per_period`` is not used).

    Returns
    -------
    Trajectory
    """
    t = V.increasing("t", V.finite_array("t", t))
    if t.size < 2:
        raise ValueError("t must have at least 2 samples")
    if not isinstance(system, System):
        raise ValueError(f"system must be a System, got {type(system).__name__}")
    n, nc = system.ndof, len(system.contacts)
    F = _as_samples("force", force, t, n)
    N = _as_samples("normal", normal, t, nc) if nc else np.zeros((t.size, 0))
    march = march_options(options, "options")
    model = make_model(system, 0.0, march, force_scale=float(np.max(np.abs(F))))
    N = N.copy()
    for c in model.pack.kin.springs:  # a spring's load comes from the state: its column is not read
        N[:, c] = model.pack.kin.normal_par[c, 0]
    tg, Fg, Ng = sampled_load_grid(t, F, N, march.recontact_alpha)
    if start is not None:
        x0, v0, states = start.x, start.v, start.states
    fresh = states is None
    x, v, S = _start_vectors(model, x0, v0, states)
    if fresh:
        S = np.ascontiguousarray(model.initial_states(x, Ng[0]))
    z = np.zeros(0)
    grid = (tg, Ng, Fg, (z, z, z, z), np.zeros((0, 0)))
    res = run(model, grid, LOADS_SAMPLED, x, v, S, 1, record=True, capacity=tg.size * (1 + 2 * nc) + 8)
    return _trajectory(res, x, v, S)
