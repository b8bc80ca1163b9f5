"""Command-line entry point: ``jointdyn <command> [options]``.

The CLI only dispatches. Every module in :mod:`jointdyn.commands` that
defines ``NAME``, ``HELP``, ``add_arguments(parser)`` and ``run(args)`` is a
subcommand. Commands validate everything (options, input files, the
writability of ``--out``, sizes and derived quantities) before computing,
and write their files only after all computing is done, each atomically.

Exit status (:mod:`jointdyn._exit`)
------------------------------------
- 0: success.
- 2: bad input (a ``ValueError`` from validation, or an argparse usage
  error): one line on stderr naming the parameter, no file written (the
  warnings of the arithmetic that found it, such as an overflow, are not
  printed; after any other end they are).
- 1: an operating-system error during the run, after validation (e.g. a
  full disk while writing the results): one line on stderr.
- 3: incomplete result: the computation ran, but its answer does not
  cover what was asked (``jointdyn frc --method hb``: a branch that failed,
  turned back or stopped at its point bound short of the gamma range).
  The output and the files are still written, with a per-point status;
  one line on stderr names where and why it stopped. Also a computation
  that failed outright (a linear solve met a singular system): one line
  saying so, no file.
- 130: interrupted (Ctrl-C).
- 141 (128 + SIGPIPE): the reader of stdout went away (``jointdyn ... |
  head``); the command stops quietly, as Unix tools do, and the shell's
  ``pipefail`` sees the same status as for a tool killed by SIGPIPE.
"""

from __future__ import annotations

import argparse
import gc
import importlib
import os
import pkgutil
import sys
import warnings

# the exit statuses live below the commands (jointdyn._exit); re-exported here for callers of main()
from ._exit import EXIT_BAD_INPUT, EXIT_BROKEN_PIPE, EXIT_INCOMPLETE, EXIT_INTERRUPTED, EXIT_OS_ERROR

__all__ = ["main", "console", "EXIT_BAD_INPUT", "EXIT_BROKEN_PIPE", "EXIT_INCOMPLETE", "EXIT_INTERRUPTED",
           "EXIT_OS_ERROR"]


class _Parser(argparse.ArgumentParser):
    def error(self, message):  # one line, exit 2 (argparse prints usage too)
        self.exit(EXIT_BAD_INPUT, f"{self.prog}: error: {message}\n")


def _commands():
    from . import commands

    out = {}
    for info in sorted(pkgutil.iter_modules(commands.__path__), key=lambda i: i.name):
        if info.name.startswith("_"):
            continue
        mod = importlib.import_module(f"{commands.__name__}.{info.name}")
        if hasattr(mod, "NAME") and hasattr(mod, "run"):
            out[mod.NAME] = mod
    return out


def build_parser() -> argparse.ArgumentParser:
    from . import __version__

    parser = _Parser(prog="jointdyn", description="Dynamics of frictional joints with varying normal load.")
    parser.add_argument("--version", action="version", version=f"%(prog)s {__version__}")
    sub = parser.add_subparsers(dest="command", required=True, parser_class=_Parser)
    for name, mod in _commands().items():
        p = sub.add_parser(name, help=getattr(mod, "HELP", None), description=getattr(mod, "HELP", None))
        mod.add_arguments(p)
        p.set_defaults(_run=mod.run)
    return parser


def _quiet_stdout() -> None:
    """Point stdout at /dev/null so that the interpreter's final flush does
    not raise BrokenPipeError again (Python's documented SIGPIPE recipe)."""
    try:
        fd = sys.stdout.fileno()
    except (AttributeError, OSError, ValueError):  # no real file (e.g. captured by a test)
        return
    devnull = os.open(os.devnull, os.O_WRONLY)
    os.dup2(devnull, fd)
    os.close(devnull)


def _dispatch(argv) -> int:
    parser = build_parser()
    try:
        args = parser.parse_args(argv)
    except SystemExit:
        sys.stdout.flush()  # --help, --version: a closed pipe shows here, not at exit
        raise
    prog = f"jointdyn {args.command}"
    from numpy.linalg import LinAlgError

    held = []
    try:
        # warnings are held back: bad input drops them (its one line says what was wrong, e.g. the
        # overflow that an arithmetic warning would only hint at); any other end issues them again
        with warnings.catch_warnings(record=True) as held:
            rc = args._run(args)
        sys.stdout.flush()
    except BrokenPipeError:
        raise
    except LinAlgError as exc:  # a ValueError, but a solver's failure (a singular system), not bad input
        _reissue(held)
        msg = " ".join(str(exc).split())
        print(f"{prog}: failed: a linear solve of the computation failed ({msg}); no result", file=sys.stderr)
        return EXIT_INCOMPLETE
    except ValueError as exc:
        msg = " ".join(str(exc).split())
        print(f"{prog}: error: {msg}", file=sys.stderr)
        return EXIT_BAD_INPUT
    except MemoryError:
        _reissue(held)
        print(f"{prog}: error: out of memory during the run (see config.MEMORY_LIMIT_BYTES)", file=sys.stderr)
        return EXIT_OS_ERROR
    except OSError as exc:  # after validation: the environment failed during the run
        _reissue(held)
        where = f": {exc.filename!r}" if getattr(exc, "filename", None) else ""
        msg = " ".join(str(exc.strerror or exc).split())
        print(f"{prog}: error: {msg}{where}", file=sys.stderr)
        return EXIT_OS_ERROR
    except KeyboardInterrupt:
        _reissue(held)
        print(f"{prog}: interrupted (finished results are kept)", file=sys.stderr)
        return EXIT_INTERRUPTED
    _reissue(held)
    return int(rc or 0)


def _reissue(held) -> None:
    """Issue again the warnings held back during a command (through the filters in force)."""
    for w in held:
        warnings.warn_explicit(w.message, w.category, w.filename, w.lineno)


def main(argv=None) -> int:
    """Run ``jointdyn`` with ``argv`` (default: ``sys.argv[1:]``); returns
    the exit status (see the module docstring). Usage errors, ``--help``
    and ``--version`` raise ``SystemExit`` as argparse does."""
    try:
        return _dispatch(argv)
    except BrokenPipeError:
        _quiet_stdout()
        return EXIT_BROKEN_PIPE


def console() -> int:
    """The ``jointdyn`` process (the console script and ``python -m jointdyn``): :func:`main` on
    ``sys.argv``, with the garbage collector told what lives as long as the process.

    The modules imported before the command and the objects alive after it
    are frozen (``gc.freeze``): the collections during the command and the
    interpreter's teardown at exit need not traverse them again (about a
    tenth of a second of a short command). The garbage of the command
    itself is collected first, so that its finalizers run as they would.
    In-process callers use :func:`main`, which leaves the collector alone.
    """
    # a cold Numba cache (the first run after installing) compiles for minutes: say so once (jointdyn._jit)
    os.environ.setdefault("JOINTDYN_ANNOUNCE_COMPILING", "1")
    gc.freeze()
    try:
        return main()
    finally:
        gc.collect()
        gc.freeze()


if __name__ == "__main__":  # pragma: no cover
    sys.exit(console())
