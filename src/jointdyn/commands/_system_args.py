"""``--system FILE.toml`` shared by the commands: a structure of the user's
own (``docs/system-files.md``) instead of the paper damper's options.

The options that describe the paper damper are refused together with
``--system`` (one line, exit 2): the file describes the structure, its
contacts and its forcing.
"""

from __future__ import annotations

from contextlib import contextmanager

from .. import _validate as V

__all__ = ["add_system_argument", "refuse_paper_options", "load_system_file", "option_names"]


def add_system_argument(p) -> None:
    """``--system FILE.toml``."""
    p.add_argument("--system", default=None, metavar="FILE.toml",
                   help="a structure of your own: TOML file with [structure] M, K (C or zeta), [[force]], "
                        "[[contact]] (law and parameters, tangential and normal selection, prescribed load or "
                        "normal spring), [[interface]] (patches of node pairs: kt, kn, mu, preload, pairs inline or "
                        "from a CSV file) and [output] (docs/system-files.md); refuses the options that describe "
                        "the paper damper")


def option_name(dest: str) -> str:
    """``--law-param`` for ``law_param``."""
    return "--" + dest.replace("_", "-")


def refuse_paper_options(args, dests) -> None:
    """ValueError naming the first paper-damper option given together with ``--system``."""
    for dest in dests:
        if getattr(args, dest, None) is not None:
            raise ValueError(f"{option_name(dest)} describes the paper damper and cannot be combined with --system "
                             f"(the system file {args.system!r} describes the structure, contacts and forcing)")


def load_system_file(args):
    """The :class:`~jointdyn.files.SystemFile` of ``--system`` (ValueError
    naming --system, the file and the key on any problem)."""
    from ..files import read_system_file

    V.input_file("--system", args.system)
    try:
        return read_system_file(args.system)
    except ValueError as exc:
        raise ValueError(f"--system {exc}") from None


@contextmanager
def option_names(**names):
    """Library errors raised inside the block, their leading Python argument (``mode``,
    ``output_dof``, ``amplitude``) said as the CLI option that gave it (``--mode``, ...):
    ``option_names(output_dof="--output-dof")``."""
    try:
        yield
    except ValueError as exc:
        msg = str(exc)
        for arg, option in names.items():
            if msg == arg or msg.startswith((f"{arg} ", f"{arg}:")):
                raise ValueError(option + msg[len(arg):]) from None
        raise
