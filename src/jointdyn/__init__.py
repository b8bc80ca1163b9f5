"""jointdyn: dynamics of frictional joints with time-varying normal load.

Public API (everything else is private):

- contact laws: :class:`Iwan`, :class:`DiscreteIwan`, :class:`Jenkins`,
  :func:`make_law`, normal loads;
- drivers: :func:`march` (and the quasi-static analysis);
- systems: :class:`System`, :class:`Contact`.
"""

from .laws import (
    MACROSLIP,
    SEPARATION,
    STATE_NAMES,
    STICK_SLIP,
    ContactLaw,
    DiscreteIwan,
    HarmonicLoad,
    Iwan,
    Jenkins,
    SampledLoad,
    UnilateralSpring,
    backbone,
    law_names,
    make_law,
)
from .drivers import march
from .systems import PAPER, Contact, System

__version__ = "0.1.0"

__all__ = [
    "STICK_SLIP",
    "MACROSLIP",
    "SEPARATION",
    "STATE_NAMES",
    "ContactLaw",
    "Iwan",
    "DiscreteIwan",
    "Jenkins",
    "backbone",
    "make_law",
    "law_names",
    "HarmonicLoad",
    "SampledLoad",
    "UnilateralSpring",
    "march",
    "System",
    "Contact",
    "PAPER",
]
