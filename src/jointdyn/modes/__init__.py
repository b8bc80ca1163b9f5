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
* :func:`backbone_dataset`: a backbone as an :class:`xarray.Dataset`.
"""

from .backbone import Backbone, ModeStatus, backbone_dataset
from .epmc import EPMCProblem, epmc
from .qsma import qsma
from .synthesis import single_mode_frc

__all__ = ["epmc", "qsma", "single_mode_frc", "backbone_dataset", "Backbone", "ModeStatus", "EPMCProblem"]
