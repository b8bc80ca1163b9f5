"""What a sweep sweeps: families of systems and their lines.

A family is a grid of labelled :class:`~jointdyn.System` objects with its
Dataset dimensions: one System (no dimension), a mapping of labelled
Systems (dimension ``system``), or the paper damper's grid of groups
(dimensions ``eta``, ``beta`` or ``f1``, ``delta``; every point of the grid
is ``System.paper_damper(...)``). A line is one System of the family swept
in one direction; :class:`LineSpec` says everything that determines its
results, and its key names its checkpoints.
"""

from __future__ import annotations

import dataclasses
import hashlib
import json
import math
import re
from collections.abc import Mapping
from dataclasses import dataclass

import numpy as np

from .. import _validate as V
from ..damping import ModalDamping

__all__ = ["LineSpec", "Family", "fingerprint", "system_family", "paper_family"]

_OVERRIDES = ("m", "k", "kt", "mu", "n0")
#: characters kept from a label in a checkpoint folder name
_SAFE = re.compile(r"[^A-Za-z0-9.=+-]+")
_LABEL_CHARS = 48


def _canon(obj):
    """A JSON-able canonical description of a (nested) value: dataclasses by
    type and fields, arrays by dtype, shape and a hash of their bytes, floats
    by repr (exact)."""
    if dataclasses.is_dataclass(obj) and not isinstance(obj, type):
        t = type(obj)
        return [f"{t.__module__}.{t.__qualname__}", {f.name: _canon(getattr(obj, f.name)) for f in dataclasses.fields(obj)}]
    if isinstance(obj, ModalDamping):  # by its factors (M Phi, 2 zeta w): no n x n matrix to hash
        return ["ModalDamping", _canon(np.asarray(obj.B)), _canon(np.asarray(obj.d))]
    if isinstance(obj, np.ndarray):
        a = np.ascontiguousarray(obj)
        return ["ndarray", a.dtype.str, list(a.shape), hashlib.sha1(a.tobytes()).hexdigest()]
    if isinstance(obj, (bool, np.bool_)):
        return bool(obj)
    if isinstance(obj, (int, np.integer)):
        return int(obj)
    if isinstance(obj, (float, np.floating)):
        return repr(float(obj))
    if obj is None or isinstance(obj, str):
        return obj
    if isinstance(obj, (tuple, list)):
        return [_canon(v) for v in obj]
    if isinstance(obj, Mapping):
        return {str(k): _canon(v) for k, v in sorted(obj.items(), key=lambda kv: str(kv[0]))}
    raise TypeError(f"cannot describe a {type(obj).__name__} for a resume key")


def fingerprint(system) -> str:
    """SHA-1 of everything that defines ``system`` (matrices, contacts and
    their laws and loads, forcing, reference frequency, output DOF)."""
    text = json.dumps(_canon(system), sort_keys=True, separators=(",", ":"))
    return hashlib.sha1(text.encode()).hexdigest()


@dataclass(frozen=True)
class LineSpec:
    """One sweep line: everything that determines its results.

    Attributes
    ----------
    label : str
        The System's label in its family (readable part of the key).
    system : str
        :func:`fingerprint` of the System.
    direction : str
        ``up`` (gamma increasing) or ``down``.
    gammas : tuple of float
        The grid, increasing (the line visits it in its direction).
    steps_per_period : int or None
        Integration steps per forcing period (None: solver default).
    dofs : tuple of int
        DOFs whose amplitude and offset are recorded per point.
    loop_outputs : bool
        Whether per-DOF and per-contact outputs are computed (from the
        recorded steady period).
    steady : SteadyStateOptions or None
        The steady state's numbers (None: its defaults, left out of the JSON so that the key of a line
        with the defaults does not change).
    """

    label: str
    system: str
    direction: str
    gammas: tuple
    steps_per_period: int | None = None
    dofs: tuple = ()
    loop_outputs: bool = False
    steady: object = None

    def to_json(self) -> str:
        """Canonical JSON (exact floats via repr)."""
        d = dataclasses.asdict(self)
        if self.steady is None:
            d.pop("steady")
        else:
            d["steady"] = {k: repr(v) for k, v in d["steady"].items()}
        d["gammas"] = [repr(float(g)) for g in self.gammas]
        d["dofs"] = [int(i) for i in self.dofs]
        return json.dumps(d, sort_keys=True)

    @property
    def key(self) -> str:
        """Folder name of the line's checkpoints: readable prefix plus a hash of the spec."""
        h = hashlib.sha1(self.to_json().encode()).hexdigest()[:12]
        label = _SAFE.sub("_", self.label)[:_LABEL_CHARS]
        return f"{label}_{self.direction}_{h}"

    @property
    def folder(self) -> str:
        """Folder name of the line's checkpoints: as :attr:`key`, but the hash
        leaves out the gamma grid, so that a rerun on another grid (one more
        point, a finer step) finds the points it can reuse (each checkpoint
        records the gammas its points were reached through)."""
        d = json.loads(self.to_json())
        d.pop("gammas")
        h = hashlib.sha1(json.dumps(d, sort_keys=True).encode()).hexdigest()[:12]
        label = _SAFE.sub("_", self.label)[:_LABEL_CHARS]
        return f"{label}_{self.direction}_{h}"

    def resume_key(self) -> str:
        """:meth:`checkpoint_key` without the gamma grid: the key a checkpoint
        must carry to be reused on any grid (its points are reused where the
        gammas that led to them match, see ``sweeps._checkpoint``)."""
        from .. import __version__
        from ..dynamics.version import SOLVER_VERSION

        d = json.loads(self.to_json())
        d.pop("gammas")
        return json.dumps({"line": json.dumps(d, sort_keys=True), "solver_version": SOLVER_VERSION,
                           "jointdyn": __version__}, sort_keys=True)

    def checkpoint_key(self) -> str:
        """The spec with the versions of the solver and of jointdyn: the
        resume key stored in (and compared with) each checkpoint."""
        from .. import __version__
        from ..dynamics.version import SOLVER_VERSION

        return json.dumps({"line": self.to_json(), "solver_version": SOLVER_VERSION, "jointdyn": __version__},
                          sort_keys=True)


@dataclass(frozen=True)
class Family:
    """A grid of labelled Systems and its Dataset description.

    Attributes
    ----------
    dims : tuple of str
        Dataset dimensions of the grid (before ``direction`` and ``gamma``).
    coords : dict
        xarray coordinates: name -> (dims, values, attrs).
    entries : tuple
        ``(index, label, system)`` per grid point; ``index`` indexes ``dims``.
    attrs : dict
        Dataset attributes describing the family.
    """

    dims: tuple
    coords: dict
    entries: tuple
    attrs: dict

    @property
    def shape(self) -> tuple:
        """Sizes of :attr:`dims`."""
        return tuple(len(self.coords[d][1]) for d in self.dims)


def _fy(system) -> float:
    """fy = mu n_ref of the first contact (N; NaN without contacts)."""
    return float(system.contacts[0].law.fy) if system.contacts else math.nan


def _describe(system) -> dict:
    """Scalars describing one System (Dataset attributes or coordinates)."""
    laws = ", ".join(type(c.law).__name__ for c in system.contacts) or "none"
    return {"w0_rad_s": float(system.w0), "fy_N": _fy(system), "response_dof": int(system.response_dof),
            "ndof": int(system.ndof), "laws": laws}


def system_family(obj) -> Family:
    """The family of one System (no grid dimension) or of a mapping
    ``{label: System}`` (dimension ``system``)."""
    from ..systems import System

    if isinstance(obj, System):
        return Family(dims=(), coords={}, entries=(((), "system", obj),), attrs=_describe(obj))
    if not isinstance(obj, Mapping) or not obj:
        raise ValueError("system must be a System or a non-empty mapping {label: System}, got "
                         f"{type(obj).__name__}")
    entries = []
    for i, (label, s) in enumerate(obj.items()):
        if not isinstance(label, str) or not label:
            raise ValueError(f"system labels must be non-empty strings, got {label!r}")
        if not isinstance(s, System):
            raise ValueError(f"system[{label!r}] must be a System, got {type(s).__name__}")
        entries.append(((i,), label, s))
    desc = [_describe(s) for _, _, s in entries]
    coords = {"system": (("system",), np.array([lab for _, lab, _ in entries], dtype=str), {})}
    units = {"w0_rad_s": "rad/s", "fy_N": "N", "response_dof": "1", "ndof": "1"}
    for name, unit in units.items():
        coords[name] = (("system",), np.array([d[name] for d in desc]), {"units": unit})
    return Family(dims=("system",), coords=coords, entries=tuple(entries), attrs={})


def _floats(name, values, check):
    if values is None:
        raise ValueError(f"{name} must be a non-empty list of numbers")
    arr = np.atleast_1d(np.asarray(values, dtype=object))
    if arr.ndim != 1 or arr.size == 0:
        raise ValueError(f"{name} must be a non-empty 1-D list of numbers")
    out = [check(name, v) for v in arr]
    if len(set(out)) != len(out):
        raise ValueError(f"{name} must not contain duplicates, got {list(out)}")
    return out


def _paper_groups(etas, betas, f1s, deltas, overrides):
    """Validated groups: (etas, load name, loads, deltas, overrides as pairs)."""
    etas = _floats("eta", (0.5,) if etas is None else etas, V.nonnegative)
    if betas is not None and f1s is not None:
        raise ValueError("give either beta (mu N0 / F1) or f1 (forcing amplitude, N), not both")
    if f1s is not None:
        load_name, loads = "f1", _floats("f1", f1s, V.positive)
    else:
        load_name, loads = "beta", _floats("beta", (1.0,) if betas is None else betas, V.positive)
    deltas = _floats("delta", (0.0,) if deltas is None else deltas, V.finite)
    ov = tuple((key, V.positive(key, overrides[key])) for key in _OVERRIDES if overrides.get(key) is not None)
    if load_name == "beta" and dict(ov).get("mu", 0.5) <= 0:
        raise ValueError("mu must be > 0 when sweeping beta = mu N0 / F1")
    return etas, load_name, loads, deltas, ov


def paper_family(*, etas, betas, f1s, deltas, model, law_params, zeta, overrides) -> Family:
    """The paper damper's grid (eta x beta or F1 x delta) as a family of
    ``System.paper_damper`` (docs/model.md section 6)."""
    from ..laws import canonical_law_params, law_names
    from ..systems import PAPER, System

    etas, load_name, loads, deltas, ov = _paper_groups(etas, betas, f1s, deltas, overrides)
    V.choice("model", model, law_names())
    lp = canonical_law_params(model, law_params)
    zeta = V.nonnegative("zeta", zeta)
    entries = []
    for ie, eta in enumerate(etas):
        for il, load in enumerate(loads):
            for idl, delta in enumerate(deltas):
                kw = {"beta": load} if load_name == "beta" else {"beta": 1.0, "f1": load}
                s = System.paper_damper(eta=eta, delta_deg=delta, model=model, zeta=zeta, law_params=dict(lp),
                                        **kw, **dict(ov))
                label = f"eta{eta:g}_{load_name}{load:g}{'N' if load_name == 'f1' else ''}_delta{delta:g}"
                entries.append(((ie, il, idl), label, s))
    p = dict(PAPER)
    p.update(dict(ov))
    fy = p["mu"] * p["n0"]
    load_attrs = ({"long_name": "mu N0 / F1"} if load_name == "beta"
                  else {"long_name": "forcing amplitude F1", "units": "N"})
    coords = {
        "eta": (("eta",), np.asarray(etas, float), {"long_name": "N1 / N0"}),
        load_name: ((load_name,), np.asarray(loads, float), load_attrs),
        "delta": (("delta",), np.asarray(deltas, float), {"long_name": "normal-load phase", "units": "deg"}),
    }
    if load_name == "beta":
        coords["f1"] = (("beta",), fy / np.asarray(loads, float), {"units": "N", "long_name": "forcing amplitude F1"})
    else:
        coords["beta"] = (("f1",), fy / np.asarray(loads, float), {"long_name": "mu N0 / F1"})
    attrs = {
        "title": "steady-state frequency response of the friction damper (docs/model.md section 6)",
        "model": model,
        **{f"law_param_{key}": val for key, val in lp},
        "zeta": float(zeta),
        "fy_N": float(fy),
        "w0_rad_s": math.sqrt(p["k"] / p["m"]),
        **{key: float(val) for key, val in p.items()},
    }
    return Family(dims=("eta", load_name, "delta"), coords=coords, entries=tuple(entries), attrs=attrs)
