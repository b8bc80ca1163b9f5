"""Validation studies of the solvers, beside the solvers they validate.

Not used by the solvers themselves: the docs scripts, the tests and the
benchmarks run them.

* :mod:`~jointdyn.validation.hb_grid`: the robustness grid of harmonic
  balance, default settings on the paper's parameter grid, each branch's
  coverage and highest peak checked against the time-domain steady state;
* :mod:`~jointdyn.validation.hb_folds`: the folds of that grid checked
  against time-domain sweeps up and down.

The package sits in the sweeps' layer: it runs harmonic balance, steady
states and sweeps, and nothing below it imports it.
"""
