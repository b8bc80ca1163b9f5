"""Command-line entry point: ``jointdyn <command> [options]``.

The CLI only dispatches. Every module in :mod:`jointdyn.commands` that
defines ``NAME``, ``HELP``, ``add_arguments(parser)`` and ``run(args)`` is a
subcommand. Bad input (``ValueError``) prints one line on stderr and exits
with status 2; commands write their files only after all computing is done,
and atomically.
"""

from __future__ import annotations

import argparse
import importlib
import pkgutil
import sys

__all__ = ["main"]


class _Parser(argparse.ArgumentParser):
    def error(self, message):  # one line, exit 2 (argparse prints usage too)
        self.exit(2, f"{self.prog}: error: {message}\n")


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
    parser = _Parser(prog="jointdyn", description="Dynamics of frictional joints with varying normal load.")
    sub = parser.add_subparsers(dest="command", required=True, parser_class=_Parser)
    for name, mod in _commands().items():
        p = sub.add_parser(name, help=getattr(mod, "HELP", None), description=getattr(mod, "HELP", None))
        mod.add_arguments(p)
        p.set_defaults(_run=mod.run)
    return parser


def main(argv=None) -> int:
    parser = build_parser()
    args = parser.parse_args(argv)
    try:
        rc = args._run(args)
    except ValueError as exc:
        msg = " ".join(str(exc).split())
        print(f"jointdyn {args.command}: error: {msg}", file=sys.stderr)
        return 2
    except KeyboardInterrupt:
        print(f"jointdyn {args.command}: interrupted (finished results are kept)", file=sys.stderr)
        return 130
    return int(rc or 0)


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
