"""Version of the time-domain solver's results.

:data:`SOLVER_VERSION` names the results of :func:`~jointdyn.dynamics.steady_state`
and :func:`~jointdyn.dynamics.integrate` for given inputs. Increase it with
every change that alters those results (a different step rule, event
handling, tolerance or classification); code changes that keep every result
bit for bit leave it alone. Stored results carry it (the resume checkpoints
of :func:`jointdyn.sweeps.frc_sweep`), so that results of another solver
version are recomputed rather than reused.
"""

__all__ = ["SOLVER_VERSION"]

#: results version of the time-domain solver (see the module docstring)
SOLVER_VERSION = 2
