"""Contact laws: compiled trial-step kernels and thin parameter classes.

Importing this package registers every built-in law (``iwan``, ``iwan-paper``,
``discrete``, ``jenkins``) for :func:`make_law`.
"""

from ._base import (
    MACROSLIP,
    SEPARATION,
    STATE_NAMES,
    STICK_SLIP,
    ContactLaw,
    law_names,
    make_law,
    register,
)
from .discrete import DiscreteIwan, Jenkins
from .exact import ExactIwan  # noqa: F401 - registers "iwan-exact"
from .iwan import Iwan, backbone
from .normal import HarmonicLoad, NormalLoad, SampledLoad, UnilateralSpring

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
    "register",
    "make_law",
    "law_names",
    "NormalLoad",
    "HarmonicLoad",
    "SampledLoad",
    "UnilateralSpring",
]
