"""Identification: joint-model parameters from measurements (docs/guide/identify.md).

* :func:`fit_loops`: a contact law (kt, mu; chi, beta of Segalman's law) from
  measured hysteresis loops t, x, N, T, by least squares of the law's force;
* :func:`fit_backbone`: a modal Iwan model (linear stiffness, joint law,
  linear damping ratio) from a measured backbone (amplitude, frequency,
  damping ratio against amplitude) by the one-harmonic describing function.

* :func:`backbone_from_ringdown`: the backbone of one mode from its free decay, and
  :func:`fit_ringdown`: the modal model fitted to that decay's windows;
* :func:`fit_frc`: the modal Iwan model from stepped-sine response curves at several
  force levels.

The fits return a :class:`FitResult` with standard errors, the correlation matrix,
the rms residual, a :class:`FitStatus` and the profile-likelihood interval
(:class:`Interval`) of every parameter; parameters the data do not determine
are reported as not identifiable, with the reason, and the combinations they
do determine are given.
"""

from .backbone import BACKBONE_MODELS, describing_function, fit_backbone
from .frc import fit_frc
from .loops import LOOP_MODELS, fit_loops
from ._profile import Interval
from .result import FitResult, FitStatus
from .ringdown import RingdownBackbone, RingdownOptions, backbone_from_ringdown
from .ringdown_fit import fit_ringdown

__all__ = ["fit_loops", "fit_backbone", "fit_frc", "describing_function", "FitResult", "FitStatus", "Interval",
           "backbone_from_ringdown", "fit_ringdown", "RingdownBackbone", "RingdownOptions", "LOOP_MODELS",
           "BACKBONE_MODELS"]
