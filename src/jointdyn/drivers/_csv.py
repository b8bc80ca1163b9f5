"""Read a prescribed history ``t, x, N`` (or a node pair's ``t, u1, u2, g``) from a CSV file (measurement exports).

The layouts accepted and the messages are those of jointdyn's one CSV
reader, :mod:`jointdyn.files.tables`.
"""

from __future__ import annotations

from .. import config
from ..files.tables import HISTORY, PAIR_HISTORY, RowBound, read_table

__all__ = ["read_history_csv", "read_pair_history_csv", "HISTORY_ROWS"]

#: the samples of a prescribed history: those of a loop given by --cycles x --steps-per-cycle
HISTORY_ROWS = RowBound(config.QS_MAX_SAMPLES, "config.QS_MAX_SAMPLES: the samples of one quasi-static "
                                               "loop, as for --cycles x --steps-per-cycle, which memory and "
                                               "time allow")


def read_history_csv(path, *, name: str = "path"):
    """Read a history ``t, x, N`` (SI units: s, m, N) from a CSV file.

    The layouts accepted (header variants, separators, units) are described
    in :mod:`jointdyn.files.tables`: a header row naming the columns ``t``,
    ``x``, ``N`` (or ``time``, ``displacement``, ``normal load``; units such
    as ``t [s]`` or a unit row must be SI), separated by ``,``, ``;``, tabs
    or spaces, then one sample per row. Other columns are ignored.

    Parameters
    ----------
    path : str or Path
        CSV file.
    name : str
        How error messages name the file's parameter (the CLI passes
        ``--input``).

    Returns
    -------
    t, x, N : ndarray
        Float64 arrays (writable, contiguous) of equal length (>= 2), finite,
        t strictly increasing: times (s), displacement (m), normal load (N).

    Raises
    ------
    ValueError
        A missing, unreadable or non-regular file, no header row, a missing
        or ambiguous column, a non-SI unit, more than
        ``config.QS_MAX_SAMPLES`` rows, a row with a missing or extra field,
        a non-numeric or non-finite value, fewer than 2 samples, or t not
        strictly increasing. The message names the file and the line.
    """
    return tuple(read_table(path, HISTORY, name=name, bound=HISTORY_ROWS)[0])


def read_pair_history_csv(path, *, name: str = "path"):
    """Read a node pair's relative history ``t, u1, u2, g`` (SI units: s, m, m, m) from a CSV file.

    The layouts of :func:`read_history_csv` with the columns ``t`` (or
    ``time``), ``u1``, ``u2`` (relative tangential displacements along t1
    and t2) and ``g`` (normal approach, positive closes); other columns
    (such as the ``T1, T2, N`` of ``jointdyn loop --model pair --out``) are
    ignored.

    Returns
    -------
    t, u1, u2, g : ndarray
        Float64 arrays of equal length (>= 2), finite, t strictly increasing.

    Raises
    ------
    ValueError
        As :func:`read_history_csv`, naming the file and the line.
    """
    return tuple(read_table(path, PAIR_HISTORY, name=name, bound=HISTORY_ROWS)[0])
