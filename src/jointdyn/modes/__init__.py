"""Nonlinear modes of structures with frictional contacts (docs/modes.md).

* :func:`epmc`: backbones by the extended periodic motion concept (Krack
  2015): periodic free motions with an artificial negative mass-proportional
  damping that cancels the dissipation, by harmonic balance with the same
  AFT, laws and exact Jacobians as :mod:`jointdyn.hb`, continued in the
  log of the modal amplitude by :mod:`jointdyn.continuation`;
* :func:`qsma`: the fast estimate by quasi-static modal analysis (Lacayo
  and Allen): a static push along the linear mode shape and Masing's rule;
* :func:`single_mode_frc`: forced response near a resonance from one
  nonlinear mode (single-nonlinear-mode synthesis, Krack et al.);
* :func:`backbone_dataset`: a backbone as an :class:`xarray.Dataset`;
* :class:`EPMCOptions`, :class:`QSMAOptions`: the numbers of each method, with their defaults;
* what a backbone requires, checked by :func:`epmc` and :func:`qsma` and by
  the command line before it computes: :func:`check_free_vibration`,
  :func:`amplitude_range`, :func:`output_dof_of`, :func:`linear_stuck_mode`.
"""

from ._free import amplitude_range, check_free_vibration, linear_stuck_mode, output_dof_of
from .backbone import Backbone, ModeStatus, backbone_dataset
from .epmc import EPMCProblem, epmc
from .options import EPMCOptions, QSMAOptions
from .qsma import qsma
from .synthesis import single_mode_frc

__all__ = ["epmc", "qsma", "single_mode_frc", "backbone_dataset", "Backbone", "ModeStatus", "EPMCProblem",
           "EPMCOptions", "QSMAOptions", "amplitude_range", "check_free_vibration", "linear_stuck_mode",
           "output_dof_of"]
