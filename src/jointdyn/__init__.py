"""jointdyn: dynamics of frictional joints with time-varying normal load.

Public API (everything else is private):

- contact laws: :class:`Iwan` (the exact Iwan model, the default),
  :class:`IwanClosedForm` (the paper's closed forms), :class:`DiscreteIwan`,
  :class:`Jenkins`, :func:`make_law` (:func:`law_names`,
  :func:`law_parameters`), normal loads;
- drivers: :func:`march`, :func:`quasistatic`, :func:`harmonic_loop`,
  :func:`interface_loop` (quasi-static loops of an :class:`Interface`, a
  contact patch of node pairs);
- systems: :class:`System`, :class:`Contact`, :func:`read_system` (TOML
  system files), :func:`read_matrices`;
- time integration: :func:`integrate`, :func:`steady_state`;
- harmonic balance: :func:`harmonic_balance`, :func:`frc_hb`;
- continuation: the module :mod:`jointdyn.continuation`
  (:class:`ContinuationOptions`);
- sweeps: :func:`frc_sweep`.

The time-integration, harmonic-balance, continuation and sweep names are
imported on first use, so that ``import jointdyn`` (and the CLI) stays fast.
"""

from .laws import (
    MACROSLIP,
    SEPARATION,
    STATE_NAMES,
    STICK_SLIP,
    ContactLaw,
    DiscreteIwan,
    Iwan,
    IwanClosedForm,
    Jenkins,
    backbone,
    law_names,
    law_parameters,
    make_law,
)
from .drivers import LoopResult, harmonic_history, harmonic_loop, march, quasistatic, read_history_csv
from .drivers import InterfaceLoopResult, interface_loop
from .interfaces import Interface
from .kinematics import ConstantLoad, HarmonicLoad, NormalSpring, SampledLoad
from .damping import ModalDamping
from .systems import PAPER, Contact, System, modal_damping, stuck_stiffness
from .files import read_matrices, read_system

__version__ = "0.1.0"

_LAZY = {
    "integrate": "dynamics",
    "integrate_sampled": "dynamics",
    "steady_state": "dynamics",
    "SteadyState": "dynamics",
    "SteadyStateOptions": "dynamics",
    "MarchOptions": "dynamics",
    "Trajectory": "dynamics",
    "Restart": "dynamics",
    "harmonic_balance": "hb",
    "frc_hb": "hb",
    "continue_hb": "hb",
    "ContinuationOptions": "continuation",
    "HBOptions": "hb",
    "EPMCOptions": "modes",
    "QSMAOptions": "modes",
    "hill_stability": "hb",
    "frc_sweep": "sweeps",
    "craig_bampton": "reduction",
    "reduce_system": "reduction",
    "CraigBampton": "reduction",
    "fit_loops": "identify",
    "fit_backbone": "identify",
    "backbone_from_ringdown": "identify",
    "fit_ringdown": "identify",
    "fit_frc": "identify",
    "FitResult": "identify",
}


#: submodules reachable as attributes of the package (imported on first use)
_SUBMODULES = ("continuation", "fourier", "reduction")


def __getattr__(name):
    import importlib

    if name in _SUBMODULES:
        return importlib.import_module(f".{name}", __name__)
    sub = _LAZY.get(name)
    if sub is None:
        raise AttributeError(f"module 'jointdyn' has no attribute {name!r}")
    value = getattr(importlib.import_module(f".{sub}", __name__), name)
    globals()[name] = value
    return value


def __dir__():
    return sorted(set(globals()) | set(_LAZY) | set(_SUBMODULES))

__all__ = [
    "STICK_SLIP",
    "MACROSLIP",
    "SEPARATION",
    "STATE_NAMES",
    "ContactLaw",
    "Iwan",
    "IwanClosedForm",
    "DiscreteIwan",
    "Jenkins",
    "backbone",
    "make_law",
    "law_names",
    "law_parameters",
    "ConstantLoad",
    "HarmonicLoad",
    "SampledLoad",
    "NormalSpring",
    "march",
    "quasistatic",
    "harmonic_loop",
    "harmonic_history",
    "read_history_csv",
    "LoopResult",
    "Interface",
    "interface_loop",
    "InterfaceLoopResult",
    "System",
    "Contact",
    "PAPER",
    "modal_damping",
    "ModalDamping",
    "stuck_stiffness",
    "read_system",
    "read_matrices",
    *_LAZY,
    *_SUBMODULES,
]
