"""Contact laws: compiled trial-step kernels and thin parameter classes.

Importing this package imports every module of it whose name does not start
with ``_``; each law module registers its law(s) (built in: ``iwan``,
the exact Iwan model and the default; ``iwan-closed`` and ``iwan-paper``,
the closed forms; ``discrete``; ``jenkins``), so a new law is one module
dropped here (see :mod:`jointdyn.laws._base` for the contract).
"""

import importlib as _importlib
import pkgutil as _pkgutil

from ._base import (
    MACROSLIP,
    SEPARATION,
    STATE_NAMES,
    STICK_SLIP,
    ContactLaw,
    LawParameter,
    canonical_law_params,
    law_names,
    law_param,
    law_parameters,
    law_label,
    law_summary,
    make_law,
    register,
)

for _module in _pkgutil.iter_modules(__path__):
    if not _module.name.startswith("_"):
        _importlib.import_module(f"{__name__}.{_module.name}")

from ._dispatch import MAX_LAW_SLOTS, LawDispatch, law_dispatch  # noqa: E402
from .discrete import DiscreteIwan, Jenkins  # noqa: E402
from .exact import Iwan  # noqa: E402
from .iwan_closed import IwanClosedForm, backbone  # noqa: E402

__all__ = [
    "STICK_SLIP",
    "MACROSLIP",
    "SEPARATION",
    "STATE_NAMES",
    "ContactLaw",
    "LawParameter",
    "Iwan",
    "IwanClosedForm",
    "DiscreteIwan",
    "Jenkins",
    "backbone",
    "register",
    "make_law",
    "law_names",
    "law_param",
    "law_parameters",
    "law_summary",
    "law_label",
    "canonical_law_params",
    "MAX_LAW_SLOTS",
    "LawDispatch",
    "law_dispatch",
]
