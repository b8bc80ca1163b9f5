"""``[[interface]]`` tables of a system file: per-pair parameters and the pairs, inline or from a CSV file."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from .. import config
from ._common import _dof, _number, _table, _vector, _Where
from .tables import RowBound, Spec, data_line, read_table

#: keys of an ``[[interface]]`` (docs/model.md section 10)
_INTERFACE_KEYS = ("kt", "kn", "mu", "preload", "pairs")
#: why the pairs are bounded, as the errors say it
_PAIRS_WHY = ("config.INTERFACE_MAX_PAIRS: every solver evaluates each pair at every sample of every step, "
              "so the time grows with the pairs: an HB branch of 2000 pairs took 40 s of CPU")


def _pair_value(where: _Where, key: str, value):
    """A per-pair parameter: a number, or a non-empty list of numbers (one per pair)."""
    if isinstance(value, list):
        return _vector(where, key, value)
    return _number(where, key, value)


def _pairs_spec():
    from ..interfaces import PAIR_COLUMNS

    cols = ", ".join(PAIR_COLUMNS)
    return Spec(columns=PAIR_COLUMNS, units=dict.fromkeys(PAIR_COLUMNS, ""), aliases={},
                expected=f"expected a header naming the columns {cols}, then one row of integer DOF indices per "
                         "pair (-1 = fixed)", min_rows=1)


def _pairs_csv(where: _Where, key: str, path: Path, n: int) -> np.ndarray:
    """The pair table of a CSV file (jointdyn's one CSV reader, :mod:`jointdyn.files.tables`): a header
    naming the six columns a_t1, a_t2, a_n, b_t1, b_t2, b_n (any order), then one row of DOF indices
    in [-1, n - 1] per pair; at most ``config.INTERFACE_MAX_PAIRS`` rows, counted before parsing."""
    spec = _pairs_spec()
    bound = RowBound(config.INTERFACE_MAX_PAIRS, _PAIRS_WHY)
    try:
        cols, lay = read_table(path, spec, name=f"{where.file}: {key}", bound=bound)
    except ValueError as exc:
        raise ValueError(" ".join(str(exc).split())) from None
    table = np.stack(cols, axis=1)
    bad = np.argwhere(~((table == np.round(table)) & (table >= -1) & (table <= n - 1)))
    if bad.size:
        i, k = (int(v) for v in bad[0])
        line = data_line(path, lay, f"{where.file}: {key}", i)
        raise where.error(key, f"{str(path)!r} line {line}: {spec.columns[k]} = {table[i, k]:.15g} must be an integer "
                               f"DOF index in [-1, {n - 1}] (-1 = fixed)")
    return table.astype(np.int64)


def _interface(where: _Where, i: int, t, n: int, folder: Path):
    """One ``[[interface]]`` entry as an Interface (its pairs inline or from a CSV file)."""
    from ..interfaces import Interface

    key = f"interface[{i}]"
    t = _table(where, key, t, _INTERFACE_KEYS, required=_INTERFACE_KEYS)
    params = {k: _pair_value(where, f"{key}.{k}", t[k]) for k in ("kt", "kn", "mu", "preload")}
    pairs = t["pairs"]
    if isinstance(pairs, str):
        p = Path(pairs) if Path(pairs).is_absolute() else folder / pairs
        pairs = _pairs_csv(where, f"{key}.pairs", p, n)
    elif not (isinstance(pairs, list) and pairs and all(isinstance(r, list) for r in pairs)):
        raise where.error(f"{key}.pairs", f"must be a list of rows of 6 DOF indices or the path of a CSV file, "
                                          f"got {pairs!r:.60}")
    else:
        if len(pairs) > config.INTERFACE_MAX_PAIRS:  # the bound of a pairs file, before anything is built
            raise where.error(f"{key}.pairs", f"must have at most {config.INTERFACE_MAX_PAIRS} pairs ({_PAIRS_WHY}), "
                                              f"got {len(pairs)}")
        for j, row in enumerate(pairs):
            if len(row) != 6 or any(isinstance(v, bool) or not isinstance(v, int) for v in row):
                raise where.error(f"{key}.pairs[{j}]", f"must be 6 integer DOF indices (a_t1, a_t2, a_n, b_t1, "
                                                       f"b_t2, b_n; -1 = fixed), got {row!r:.60}")
            for k, v in enumerate(row):  # a huge integer is said here, before numpy refuses its type
                if abs(v) >= 2**62:
                    _dof(where, f"{key}.pairs[{j}][{k}]", v, n, ground=True)
    try:
        made = Interface(pairs=pairs, **params)
        made.check_ndof(n, "")
    except ValueError as exc:
        raise where.wrap(key, exc, _INTERFACE_KEYS) from None
    return made
