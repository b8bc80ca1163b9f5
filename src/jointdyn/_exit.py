"""Exit statuses of the ``jointdyn`` command, in one place below the commands.

- :data:`EXIT_OK` (0): success.
- :data:`EXIT_OS_ERROR` (1): an operating-system error during the run,
  after validation (e.g. a full disk while writing the results).
- :data:`EXIT_BAD_INPUT` (2): bad input (a ``ValueError`` from validation,
  or an argparse usage error): one line on stderr naming the parameter, no
  file written.
- :data:`EXIT_INCOMPLETE` (3): the computation ran, but its answer does
  not cover what was asked (a harmonic-balance branch or a backbone that
  stops short, a sweep with points not computed); the output and the files
  are still written, with a per-point status.
- :data:`EXIT_INTERRUPTED` (130): interrupted (Ctrl-C).
- :data:`EXIT_BROKEN_PIPE` (141, 128 + SIGPIPE): the reader of stdout went
  away.
"""

from __future__ import annotations

__all__ = ["EXIT_OK", "EXIT_OS_ERROR", "EXIT_BAD_INPUT", "EXIT_INCOMPLETE", "EXIT_INTERRUPTED", "EXIT_BROKEN_PIPE"]

EXIT_OK = 0
EXIT_OS_ERROR = 1
EXIT_BAD_INPUT = 2
#: the run finished but its result does not cover the request
EXIT_INCOMPLETE = 3
EXIT_INTERRUPTED = 130
#: exit status when stdout's reader went away (128 + SIGPIPE)
EXIT_BROKEN_PIPE = 141
