"""A System packed for the compiled RK4 runner, its step grids, and the one call of the runner.

:func:`pack_system` holds the frequency-independent arrays (one per System
object, cached); :func:`make_model` adds a forcing frequency and the step
grid of one period with the separation and re-contact instants; :func:`run`
is the only place that calls the compiled runner (``_core.py``).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from .. import _validate as V
from .._cache import by_identity
from ..damping import dense_damping
from ..kinematics import (
    NORMAL_HARMONIC,
    NORMAL_SAMPLED,
    NORMAL_SPRING,
    ContactKinematics,
    contact_kinematics,
    load_breakpoints,
    load_events,
    load_table,
    midpoint_loads,
    no_contact_init,
    no_contact_step,
    normal_history,
    normal_load_at,
    selection_matrix,
    tangential_history,
)
from ..laws import law_dispatch
from .options import MarchOptions, march_with_steps
from ._core import LOADS_HARMONIC, N_SUMMARY, RUN_OVERFLOW, S_OPEN, compiled_runner, grid_trig
from .status import RunStatus, run_status

__all__ = ["PackedSystem", "pack_system", "check_period_steps", "Model", "make_model", "refine_if_opened", "Grid", "RunResult", "run",
           "recontact_load", "pair_relative", "sliders", "set_sliders"]  # fmt: skip

@dataclass(frozen=True)
class PackedSystem:
    """The frequency-independent arrays of a System for the compiled runner.

    Shared by every model of the same System object and never written.
    ``arrays`` is the runner's ``system`` argument
    ``(Minv, K, C, (f_sin, f_cos), kin, P)``: the forcing
    F_i = f_i sin(w t + phi_i) as f_sin = f cos(phi) and f_cos = f sin(phi).
    """

    ndof: int
    ncontacts: int
    M: np.ndarray
    Minv: np.ndarray
    K: np.ndarray
    C: np.ndarray
    fvec: np.ndarray
    fsin: np.ndarray
    fcos: np.ndarray
    kin: ContactKinematics
    #: dense tangential and normal selection rows (nc, ndof), stuck stiffnesses kt (N/m)
    B: np.ndarray
    Bn: np.ndarray
    kt: np.ndarray
    #: law parameter rows (nc, width), state length, the laws, their (dispatched) kernels
    P: np.ndarray
    slen: int
    laws: tuple
    step: object
    init: object
    runner: object
    #: K with the normal springs closed and the interface pairs closed at rest
    #: stuck (N/m); with every contact stuck and every pair stuck and closed
    #: too (K_stuck), its highest and lowest natural frequencies (rad/s)
    K_closed: np.ndarray
    K_stuck: np.ndarray
    w_max: float
    w_min_stuck: float
    #: sum of fy / kt (m), largest forcing amplitude (N), smallest modal stiffness (N/m)
    xlin: float
    fmax: float
    kmin: float
    arrays: tuple
    #: output buffers of a run that records nothing, and the sampled-forcing
    #: table of a harmonic grid (unused there)
    nobufs: tuple
    no_forcing_table: np.ndarray
    #: the pairs of every interface, one after the other: DOFs (np, 6) and
    #: parameters kt, kn, mu, P (np, 4); rows of the state array that hold
    #: their sliders (after the contacts' rows; 0 without interfaces)
    pairs: np.ndarray = None
    pair_params: np.ndarray = None
    slider_rows: int = 0

    @property
    def npairs(self) -> int:
        """Number of interface pairs (all interfaces)."""
        return self.pairs.shape[0]

    @property
    def state_rows(self) -> int:
        """Rows of the state array: one per contact, then the pairs' sliders."""
        return self.ncontacts + self.slider_rows

    @property
    def springs(self) -> bool:
        """True when some contact's normal load comes from a normal spring."""
        return self.kin.springs.size > 0


@by_identity
def pack_system(system) -> PackedSystem:
    """The :class:`PackedSystem` of ``system`` (cached per System object).

    The step of the period grids follows the stiffest linear mode the
    structure can reach: every contact stuck (kt) and every normal spring
    closed (kn), so that a light, stiff normal DOF is integrated stably.
    """
    n = system.ndof
    cs = system.contacts
    kin = contact_kinematics(system, True)  # the runner marches the interfaces itself
    M = np.ascontiguousarray(system.M, dtype=np.float64)
    Minv = np.ascontiguousarray(np.linalg.inv(system.M))
    K = np.ascontiguousarray(system.K, dtype=np.float64)
    C = np.ascontiguousarray(dense_damping(system.C))  # the march's K and inverse mass are dense too
    fvec = np.ascontiguousarray(system.force, dtype=np.float64)
    phi = np.radians(system.force_phase_deg)
    fsin = np.ascontiguousarray(fvec * np.cos(phi))
    fcos = np.ascontiguousarray(fvec * np.sin(phi))
    if cs:
        disp = law_dispatch([c.law for c in cs])
        P, slen, step, init = disp.P, disp.state_size, disp.step, disp.init
    else:
        P, slen, step, init = np.zeros((0, 5)), 1, no_contact_step, no_contact_init
    B, Bn = selection_matrix(kin, n), selection_matrix(kin, n, normal=True)
    kt = np.array([c.law.kt for c in cs], dtype=np.float64)
    Kcl = K.copy()
    for i in kin.springs:
        Kcl += kin.normal_par[i, 1] * np.outer(Bn[i], Bn[i])
    Kst = Kcl.copy()
    for i in range(len(cs)):
        Kst += kt[i] * np.outer(B[i], B[i])
    pairs, ppar, Kp_start, Kp_stiff = _interface_arrays(system)
    Kcl += Kp_start  # the pairs stuck and closed at rest: the linear start's structure
    Kst += Kp_stiff  # every pair stuck and closed: the stiffest mode
    slider_rows = -(-2 * pairs.shape[0] // slen)
    from scipy.linalg import eigh

    lam = eigh(0.5 * (Kst + Kst.T), system.M, eigvals_only=True)
    w_max = math.sqrt(max(lam[-1], 0.0))
    w_min = math.sqrt(max(lam[0], 0.0))
    fmax = float(np.max(np.abs(fvec)))
    xlin = sum(c.law.fy / c.law.kt for c in cs) + float(np.sum(ppar[:, 2] * ppar[:, 3] / ppar[:, 0]))
    return PackedSystem(
        ndof=n, ncontacts=len(cs), M=M, Minv=Minv, K=K, C=C, fvec=fvec, fsin=fsin, fcos=fcos, kin=kin, B=B,
        Bn=Bn, kt=kt, P=P, slen=slen, laws=tuple(c.law for c in cs), step=step, init=init,
        runner=compiled_runner(step, kin.springs.size > 0, bool(np.any(fcos != 0.0)), pairs.shape[0] > 0),
        K_closed=np.ascontiguousarray(Kcl), K_stuck=np.ascontiguousarray(Kst),
        w_max=w_max, w_min_stuck=w_min, xlin=xlin, fmax=fmax,
        kmin=max(w_min**2 * float(np.min(np.diag(system.M))), 1e-300),
        arrays=(Minv, K, C, (fsin, fcos), kin.arrays, P, (pairs, ppar)), nobufs=_buffers(1, n, len(cs)),
        no_forcing_table=np.zeros((1, n)), pairs=pairs, pair_params=ppar, slider_rows=slider_rows,
    )  # fmt: skip


def _interface_arrays(system):
    """The pairs of every interface of ``system`` (DOFs (np, 6), parameters (np, 4)) and two
    stiffness matrices (N/m): the springs kt, kt, kn of the pairs closed at rest (preload > 0), and
    those of every pair (stuck and closed: the stiffest the structure can be)."""
    itfs = tuple(getattr(system, "interfaces", ()))
    n = system.ndof
    if not itfs:
        return np.zeros((0, 6), dtype=np.int64), np.zeros((0, 4)), np.zeros((n, n)), np.zeros((n, n))
    pairs = np.ascontiguousarray(np.concatenate([i.pairs for i in itfs]), dtype=np.int64)
    par = np.ascontiguousarray(np.concatenate([i.params for i in itfs]))
    B = np.concatenate([i.selection(n) for i in itfs])  # rows u1, u2, g of every pair
    k = np.stack([par[:, 0], par[:, 0], par[:, 1]], axis=1).ravel()
    k_all = B.T @ (k[:, None] * B)
    k_rest = B.T @ ((k * np.repeat(par[:, 3] > 0.0, 3))[:, None] * B)
    return pairs, par, k_rest, k_all


def _buffers(cap, n, nc):
    """Sample buffers (t, x, v, T, N, code) for ``cap`` samples."""
    return (
        np.zeros(cap),
        np.zeros((cap, n)),
        np.zeros((cap, n)),
        np.zeros((cap, nc)),
        np.zeros((cap, nc)),
        np.zeros((cap, nc), dtype=np.int8),
    )


#: a step grid with its load tables: the runner's ``grid`` argument
#: ``(t, N, F, (sin_mid, sin_end, cos_mid, cos_end), N_mid)`` (see ``_core.py``)
Grid = tuple


def _harmonic_tables(pack: PackedSystem, tg, Ng, w) -> Grid:
    """The runner's grid tuple of a harmonic step grid tg (s) with normal loads Ng (N)."""
    trig = grid_trig(tg, w, 0.0)
    N_mid = midpoint_loads(pack.kin.arrays, tg, w, 0.0)
    return (tg, Ng, pack.no_forcing_table, trig, N_mid)


def recontact_load(kin: ContactKinematics, c: int, march: MarchOptions) -> float:
    """Load (N) a prescribed load is snapped to at a re-contact instant:
    ``march.recontact_alpha`` times n0 (harmonic) or times the largest |sample| (sampled)."""
    if kin.normal_kind[c] == NORMAL_SAMPLED:
        return march.recontact_alpha * float(np.max(np.abs(kin.normal_table[c])))
    return march.recontact_alpha * kin.normal_par[c, 0]


def _period_grid(pack: PackedSystem, w: float, J: int, events: bool, march: MarchOptions):
    """Step grid of one forcing period with the separation/re-contact instants, and its normal loads.

    J uniform steps; an instant within ``march.event_merge`` of a step of a
    grid point moves that point, else it is inserted. The load is snapped
    to exactly 0 at a separation and to :func:`recontact_load` at a
    re-contact. The slope changes of sampled loads (their sample phases)
    are grid points too (inserted or merged the same way, not snapped).
    """
    Tp = 2 * math.pi / w
    t = np.arange(J + 1) * (Tp / J)  # np.linspace(0, Tp, J + 1), bit for bit, cheaper
    t[J] = Tp
    tol = march.event_merge * Tp / J
    tg = t
    ev_at = {}
    instants = list(load_events(pack.kin, w, Tp)) if events else []
    instants += [(float(tb), -1, False) for tb in load_breakpoints(pack.kin, Tp)]
    for te, ci, rising in instants:
        k = int(np.argmin(np.abs(tg - te)))
        if abs(tg[k] - te) <= tol:
            if k == 0 or k == tg.size - 1:
                # an event at the period boundary: keep the boundary exact
                te = tg[k]
            else:
                tg[k] = te
        else:
            k = int(np.searchsorted(tg, te))
            tg = np.insert(tg, k, te)
            # re-key events recorded at later indices
            ev_at = {(kk + 1 if kk >= k else kk): v for kk, v in ev_at.items()}
        if ci >= 0:
            ev_at.setdefault(k, []).append((ci, rising))
    N = load_table(pack.kin.arrays, tg, w)
    for k, lst in ev_at.items():
        for ci, rising in lst:
            N[k, ci] = recontact_load(pack.kin, ci, march) if rising else 0.0
            if k == 0:
                N[tg.size - 1, ci] = N[0, ci]
            if k == tg.size - 1:
                N[0, ci] = N[k, ci]
    return tg, np.ascontiguousarray(N)


@dataclass(frozen=True)
class Model:
    """A packed System at one forcing frequency, with its period grid.

    Built by :func:`make_model`. ``grid`` is the period grid (None when
    ``w == 0``: sampled loads); ``xcap0`` and ``xcap`` are the blow-up caps
    of the displacements (m) and of (x, v); ``march`` holds the numbers of
    the march (its ``steps_per_period`` the requested base) and ``refined``
    says whether the steps follow ``march.spring_omega_h`` (a normal spring
    opened).
    """

    pack: PackedSystem
    system: object
    w: float
    events: bool
    max_split: int
    J: int
    xcap0: float
    xcap: np.ndarray
    grid: Grid | None
    period: float
    march: MarchOptions
    refined: bool = False

    @property
    def n(self) -> int:
        return self.pack.ndof

    @property
    def nc(self) -> int:
        return self.pack.ncontacts

    def cap(self, x, v) -> np.ndarray:
        """Blow-up caps, never below ``march.blowup_factor`` times the starting state."""
        wv = max(self.pack.w_max, self.w, 1.0)
        xs = float(np.max(np.abs(x))) + float(np.max(np.abs(v))) / wv
        factor = self.march.blowup_factor
        if factor * xs <= self.xcap0:
            return self.xcap  # the usual case: the start is far below the caps
        n = self.n
        return np.maximum(self.xcap, factor * np.concatenate([np.full(n, xs), np.full(n, xs * wv)]))

    def segment_grid(self, ta: float, tb: float) -> Grid:
        """Grid for ta < t <= tb (0 <= ta < tb <= ta + period), from the period grid."""
        Tp = self.period
        base, Nbase = self.grid[0], self.grid[1]
        tt = np.concatenate([base[:-1], base + Tp])
        NN = np.concatenate([Nbase[:-1], Nbase], axis=0)
        eps = 1e-12 * Tp
        inside = (tt > ta + eps) & (tt < tb - eps)
        tg = np.concatenate([[ta], tt[inside], [tb]])
        Ng = np.empty((tg.size, self.nc))
        Ng[1:-1] = NN[inside]
        for ci in range(self.nc):
            Ng[0, ci] = normal_load_at(self.pack.kin, ci, self.w, ta)
            Ng[-1, ci] = normal_load_at(self.pack.kin, ci, self.w, tb)
        # an end point that is a grid point keeps its (event-snapped) value
        for idx, te in ((0, ta), (-1, tb)):
            k = np.flatnonzero(np.abs(tt - te) <= eps)
            if k.size:
                Ng[idx] = NN[k[0]]
        return _harmonic_tables(self.pack, np.ascontiguousarray(tg), np.ascontiguousarray(Ng), self.w)

    def section_time(self) -> float:
        """Poincare-section time in [0, period) where every contact is open, else 0.

        Mid-separation of the first contact whose prescribed load opens (the
        minimum of a harmonic or sampled load), if every contact is open
        there; there the law states are reset, so (x, v) is the whole state
        of the period map. A normal spring's opening depends on the motion,
        unknown before the period is run: it never sets the section (0 where
        only springs open).
        """
        kin = self.pack.kin
        for c in range(self.nc):
            n0, p1, delta = kin.normal_par[c]
            ts = None
            if kin.normal_kind[c] == NORMAL_HARMONIC and p1 > n0:
                ts = ((1.5 * math.pi - float(delta)) / self.w) % self.period
            elif kin.normal_kind[c] == NORMAL_SAMPLED and np.min(kin.normal_table[c]) < 0.0:
                m = int(p1)
                ts = int(np.argmin(kin.normal_table[c, :m])) / m * self.period
            if ts is not None:
                if all(normal_load_at(kin, cc, self.w, ts) < 0.0 for cc in range(self.nc)):
                    return ts
                return 0.0
        return 0.0

    def initial_states(self, x: np.ndarray, loads=None) -> np.ndarray:
        """Virgin law states at displacements x (m) and prescribed normal loads
        ``loads`` (N; default the loads at t = 0, event-snapped: a re-contact
        at t = 0 starts the virgin curve there); a spring contact's load
        comes from x."""
        S = np.zeros((self.pack.state_rows, self.pack.slen))
        x = np.ascontiguousarray(x, dtype=np.float64)
        if self.pack.npairs:  # virgin pairs: sliders at the relative displacements of x
            set_sliders(self.pack, S, pair_relative(self.pack, x)[0])
        u = tangential_history(self.pack.kin.arrays, x[None, :])[0]
        n_x = normal_history(self.pack.kin.arrays, x[None, :], np.zeros(1), self.w)[0]
        for i, law in enumerate(self.pack.laws):
            if self.pack.kin.normal_kind[i] == NORMAL_SPRING:
                n_at0 = n_x[i]
            elif loads is not None:
                n_at0 = loads[i]
            elif self.grid is not None:
                n_at0 = self.grid[1][0, i]
            else:
                n_at0 = normal_load_at(self.pack.kin, i, self.w, 0.0)
            s = law.initial_state(float(u[i]), float(n_at0))
            S[i, : s.size] = s
        return S

    def run_grid(self, x, v, S, grid: Grid, nper: int, rdof: int = 0):
        """Run ``nper`` repetitions of ``grid`` in place, recording nothing."""
        return run(self, grid, LOADS_HARMONIC, x, v, S, nper, rdof=rdof)

    def run_periods(self, x, v, S, nper: int, *, rec: bool = False, rdof: int = 0):
        """Run ``nper`` forcing periods in place (optionally recording every step)."""
        cap = nper * (self.J + 4 * self.nc + 8) + 1
        return run(self, self.grid, LOADS_HARMONIC, x, v, S, nper, rdof=rdof, record=rec, capacity=cap)


def make_model(system, w: float, march: MarchOptions, *, events: bool = True,
               force_scale: float | None = None, refined: bool = False) -> Model:  # fmt: skip
    """A :class:`Model` of ``system`` at forcing frequency ``w`` (rad/s; 0: sampled loads, where the
    steps are the samples' and ``march.steps_per_period`` is not used) marched with ``march``.

    ``march.steps_per_period`` is raised so that w_max h <= ``march.max_omega_h``
    (w_max: every contact stuck, every normal spring closed), and with
    ``refined`` (a normal spring opens) so that w_max h <= ``march.spring_omega_h``.
    ``events=False`` (for the convergence study only): no step boundaries
    at separation/re-contact and no splits at velocity reversals.
    ``force_scale`` (N, default the largest forcing amplitude) sets the
    blow-up caps.
    """
    pack = pack_system(system)
    w = float(w)
    refined = bool(refined) and pack.springs
    J = period_steps(pack, w, march, refined=refined)
    fs = pack.fmax if force_scale is None else force_scale
    xcap0 = march.blowup_factor * (fs / pack.kmin + pack.xlin + 1e-12)
    xcap = np.empty(2 * pack.ndof)
    xcap[: pack.ndof] = xcap0
    xcap[pack.ndof :] = xcap0 * max(pack.w_max, w, 1.0)
    grid, period = None, math.nan
    if w > 0:
        tg, Ng = _period_grid(pack, w, J, events, march)
        grid, period = _harmonic_tables(pack, tg, Ng, w), 2 * math.pi / w
    return Model(pack=pack, system=system, w=w, events=bool(events),
                 max_split=march.max_splits if events else 0, J=J, xcap0=xcap0, xcap=xcap,
                 grid=grid, period=period, march=march, refined=refined)  # fmt: skip


#: float64 words per step of a period held by a run (the grid, its loads and trigonometric tables,
#: their copies while events are inserted) beside those per DOF and per contact
_STEP_WORDS = 12
_STEP_WORDS_PER_DOF = 4
_STEP_WORDS_PER_CONTACT = 8


def period_steps(pack: PackedSystem, w: float, march: MarchOptions, *, refined: bool = False,
                 lines: int = 1, name: str = "steps_per_period") -> int:  # fmt: skip
    """Steps of one forcing period at ``w`` (rad/s): ``march.steps_per_period``,
    raised so that w_max h <= ``march.max_omega_h`` (``march.spring_omega_h`` when
    ``refined``), checked against the memory bound for ``lines`` runs at once
    before anything is allocated (ValueError saying which of the two sets it,
    ``name`` for the first)."""
    steps_per_period = march.steps_per_period
    J = float(steps_per_period)
    if w > 0:
        wh = march.spring_omega_h if refined else march.max_omega_h
        with np.errstate(over="ignore", divide="ignore"):
            need = float(np.ceil(np.float64(2 * math.pi) * pack.w_max / (np.float64(w) * wh)))
        J = max(J, need)
    words = _STEP_WORDS + _STEP_WORDS_PER_DOF * pack.ndof + _STEP_WORDS_PER_CONTACT * pack.ncontacts
    per_step = 8.0 * words * max(int(lines), 1)
    top = max(int(V.memory_budget() // per_step) - 1, 0)
    if J > steps_per_period:
        label = (f"the time step of the stiffest mode (w_max = {pack.w_max:.6g} rad/s with every contact stuck "
                 f"and every normal spring closed; w_max h <= {wh:g}: {J:.6g} steps per forcing period at "
                 f"w = {w:.6g} rad/s)")
        hint = f"at most {top} steps fit"
    else:
        label = f"{name} {int(steps_per_period)}"
        hint = f"{name} must be at most {top} here"
    V.memory_fits(label, (J + 1.0) * per_step, hint=hint)
    return int(J)


def check_period_steps(system, w: float, steps_per_period: int | None = None, *, march: MarchOptions | None = None,
                       lines: int = 1, name: str = "steps_per_period") -> int:  # fmt: skip
    """The steps of one forcing period of ``system`` at ``w`` (rad/s), refused before anything is computed
    (ValueError naming ``name`` where ``steps_per_period`` sets the step, else the stiffest mode) when
    ``lines`` runs at once would exceed the memory bound: :func:`period_steps` with the march ``march``
    (:class:`~jointdyn.dynamics.options.MarchOptions`, None: the defaults), its steps per period
    replaced by ``steps_per_period`` where given, refined where the system has normal springs. The
    lowest frequency of a sweep needs the most."""
    march = march_with_steps(march, steps_per_period, steps_name=name)
    pack = pack_system(system)
    return period_steps(pack, w, march, refined=pack.springs, lines=lines, name=name)


def refine_if_opened(model: Model, summary) -> Model | None:
    """The refined model (``march.spring_omega_h``) if a normal spring of
    ``model`` opened during the repetitions of ``summary`` and the model is
    not refined yet; else None."""
    if model.refined or not model.pack.springs or not np.any(summary[:, S_OPEN] > 0):
        return None
    return make_model(model.system, model.w, model.march, events=model.events, refined=True)


@dataclass(frozen=True, slots=True)
class RunResult:
    """What one :func:`run` returns.

    ``summary`` (done, N_SUMMARY) and ``z_end`` (done, 2 n) hold the
    per-repetition summary (columns ``S_*`` of ``_core.py``) and the state
    at the end of each repetition; ``pairs`` (done, npairs, 4) per
    repetition and interface pair the work of its force (J) and the
    fractions of the repetition it was stuck, slipping, open; ``samples``
    is ``(t, x, v, T, N, code)`` when recording, else None.
    """

    summary: np.ndarray
    z_end: np.ndarray
    status: RunStatus
    done: int
    samples: tuple | None
    pairs: np.ndarray | None = None


def run(model: Model, grid: Grid, mode: int, x, v, S, nper: int, *, rdof: int = 0, record: bool = False,
        capacity: int = 1) -> RunResult:  # fmt: skip
    """March ``nper`` repetitions of ``grid`` from (x, v, S), which are updated in place.

    The only call of the compiled runner. When recording, ``capacity``
    samples are allocated and doubled (the run repeated from the same
    start) until they suffice.
    """
    pack = model.pack
    summ = np.zeros((nper, N_SUMMARY))
    zend = np.zeros((nper, 2 * pack.ndof))
    psum = np.zeros((nper, pack.npairs, 4))
    control = (mode, nper, 0.0, model.w, rdof, model.max_split, record, model.march.recontact_alpha)
    io = (x, v, S, model.cap(x, v))
    if record:
        x0, v0, S0 = x.copy(), v.copy(), S.copy()
    while True:
        bufs = _buffers(capacity, pack.ndof, pack.ncontacts) if record else pack.nobufs
        nrec, status, done = pack.runner(pack.arrays, grid, control, io, (*bufs, summ, zend, psum))
        if status != RUN_OVERFLOW:
            break
        capacity *= 2
        x[:], v[:], S[:] = x0, v0, S0
    samples = tuple(b[:nrec] for b in bufs) if record else None
    return RunResult(summ[:done], zend[:done], run_status(status), done, samples, psum[:done])


def pair_relative(pack: PackedSystem, x) -> tuple[np.ndarray, np.ndarray]:
    """(u (np, 2), g (np,)) of every interface pair at displacements x (m)."""
    x = np.asarray(x, dtype=np.float64)
    xe = np.append(x, 0.0)  # index -1 (a fixed side) reads the appended 0
    p = pack.pairs
    return xe[p[:, :2]] - xe[p[:, 3:5]], xe[p[:, 2]] - xe[p[:, 5]]


def sliders(pack: PackedSystem, S) -> np.ndarray:
    """The interface pairs' committed sliders (np, 2), m, from a state array (rows after the contacts)."""
    m = pack.npairs
    return np.asarray(S)[pack.ncontacts:].ravel()[: 2 * m].reshape(m, 2).copy()


def set_sliders(pack: PackedSystem, S, W) -> None:
    """Write the sliders W (np, 2), m, into the state array S (rows after the contacts), in place."""
    m = pack.npairs
    flat = np.zeros(pack.slider_rows * pack.slen)
    flat[: 2 * m] = np.asarray(W, dtype=np.float64).ravel()
    S[pack.ncontacts:] = flat.reshape(pack.slider_rows, pack.slen)
