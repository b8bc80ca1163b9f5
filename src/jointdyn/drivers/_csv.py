"""Read a prescribed history ``t, x, N`` (or a node pair's ``t, u1, u2, g``) from a CSV file (measurement exports).

Accepted layout
---------------
- Optional preamble: blank lines and lines starting with ``#``.
- One header row naming the columns. When the first data row follows a
  ``#`` line directly and no other header is present, that comment is the
  header (``numpy.savetxt(..., header="t x N")`` writes ``# t x N``).
- Separator: ``,``, ``;``, tab or runs of spaces, detected from the header
  row. With ``;`` a decimal comma is accepted (detected from the first data
  row).
- Column names: ``t`` or ``time``; ``x`` or ``displacement``; ``N``, ``normal
  load`` or ``normal force``. Longer names match in any case; the single
  letters match as written or through the lower case (``X``, ``n``), except
  ``T``, which is jointdyn's tangential force, not a time. Surrounding
  whitespace and quotes are ignored. A unit in brackets or parentheses
  (``t [s]``, ``Time (s)``) must be the SI unit of the column: s, m, N.
- Other columns are ignored; every data row has as many fields as the header.

The values are parsed by pandas' compiled reader (only the three columns,
float64, correctly rounded like Python's ``float``). When that fails or
finds a missing, extra, non-numeric or non-finite field, a line-by-line scan
of the file names the first bad line.
"""

from __future__ import annotations

import csv
import math
import re
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from .. import _validate as V

__all__ = ["read_history_csv", "read_pair_history_csv"]

@dataclass(frozen=True)
class _Spec:
    """The columns a reader returns, in order, with their SI units, the other names each accepts in
    any case, and how error messages describe the expected layout."""

    columns: tuple
    units: dict
    aliases: dict
    expected: str


#: a contact's history: time, tangential displacement, normal load
_HISTORY = _Spec(
    columns=("t", "x", "N"),
    units={"t": "s", "x": "m", "N": "N"},
    aliases={
        "t": ("time",),
        "x": ("x", "displacement"),
        "N": ("n", "normal load", "normal force", "normal_load", "normal_force"),
    },
    expected="expected a header row naming the columns t, x, N in SI units (s, m, N), "
             "e.g. 't,x,N' or 't [s];x [m];N [N]', then one row of numbers per sample",
)
#: a node pair's relative history: time, tangential displacements along t1 and t2, normal approach
_PAIR = _Spec(
    columns=("t", "u1", "u2", "g"),
    units={"t": "s", "u1": "m", "u2": "m", "g": "m"},
    aliases={"t": ("time",), "u1": ("u1",), "u2": ("u2",), "g": ("g",)},
    expected="expected a header row naming the columns t, u1, u2, g in SI units (s, m, m, m), "
             "e.g. 't,u1,u2,g' or 't [s];u1 [m];u2 [m];g [m]', then one row of numbers per sample",
)
_UNIT = re.compile(r"^(.*?)\s*[\[(]\s*([^\])]*?)\s*[\])]$")
#: one header field of a space-separated file: a word with an optional unit
_SPACED_FIELD = re.compile(r"[^\s\[(]+(?:\s*[\[(][^\])]*[\])])?")
#: longest header line read, bytes (a longer one is not a CSV header)
_MAX_LINE = 1 << 20
#: bytes per block when counting separators
_BLOCK = 1 << 22


@dataclass(frozen=True)
class _Layout:
    """Where the data are and how a row is split."""

    sep: str | None  # None: runs of whitespace
    decimal: str
    header_line: int  # 1-based line number of the header
    data_offset: int  # byte offset of the first line after the header
    data_line: int  # its 1-based line number
    names: tuple  # header fields as written
    use: tuple  # column indices of the spec's columns
    spec: _Spec = _HISTORY


class _Refused(ValueError):
    """A precise complaint about one line of the file."""


def _where(name, path, line=None) -> str:
    return f"{name} {str(path)!r}" + ("" if line is None else f" line {line}")


def _number(text: str, decimal: str) -> float | None:
    s = text.strip().strip('"').strip()
    if decimal == ",":
        if "." in s:
            return None
        s = s.replace(",", ".")
    try:
        return float(s)
    except ValueError:
        return None


def _split(line: str, sep: str | None) -> list:
    if sep is None:
        return line.split()
    if '"' in line:
        return next(csv.reader([line], delimiter=sep))
    return line.split(sep)


def _separator(header: str) -> str | None:
    for sep in (";", "\t", ","):
        if sep in header:
            return sep
    return None


def _header_fields(header: str, sep: str | None) -> list:
    if sep is None:
        return _SPACED_FIELD.findall(header)
    return next(csv.reader([header], delimiter=sep))


def _name_unit(field: str):
    f = field.strip().strip("\"'").strip()
    m = _UNIT.match(f)
    if m:
        return m.group(1).strip(), m.group(2).strip()
    return f, ""


def _match_columns(fields, where, spec: _Spec = _HISTORY) -> tuple:
    """Indices of the spec's columns among the header fields (units checked)."""
    parsed = [_name_unit(f) for f in fields]
    use = []
    missing = []
    for key in spec.columns:
        hits = [i for i, (b, _) in enumerate(parsed) if b == key]
        if not hits:
            hits = [i for i, (b, _) in enumerate(parsed) if b.lower() in spec.aliases[key] and b != "T"]
        if len(hits) > 1:
            both = ", ".join(repr(fields[i].strip()) for i in hits)
            raise _Refused(f"{where}: columns {both} all name {key}; keep one")
        if not hits:
            missing.append(key)
            continue
        unit = parsed[hits[0]][1]
        if unit and unit != spec.units[key]:
            si = ", ".join(f"{k} in {spec.units[k]}" for k in spec.columns)
            raise _Refused(
                f"{where}: column {fields[hits[0]].strip()!r} has unit {unit!r}; expected {spec.units[key]} "
                f"(SI units: {si}; convert the file)"
            )
        use.append(hits[0])
    if missing:
        found = ", ".join(repr(f.strip()) for f in fields) or "none"
        raise _Refused(f"{where}: missing column {', '.join(missing)} (found {found}); {spec.expected}")
    return tuple(use)


def _is_numeric_row(text: str) -> bool:
    """A data row rather than a header (a decimal comma splits a number
    into two numbers here, which keeps the row numeric)."""
    tokens = [tok for tok in re.split(r"[,;\s]+", text.strip()) if tok]
    return bool(tokens) and all(_number(tok, ".") is not None for tok in tokens)


def _decode(raw: bytes, where: str, first: bool, hint: str = "") -> str:
    try:
        return raw.decode("utf-8-sig" if first else "utf-8")
    except UnicodeDecodeError:
        raise _Refused(f"{where}: not UTF-8 text{hint}") from None


def _layout(path: Path, name: str, spec: _Spec = _HISTORY) -> _Layout:
    """Find the header, the separator and the decimal mark."""
    comment = None
    with open(path, "rb") as fh:
        lineno = 0
        while True:
            raw = fh.readline(_MAX_LINE)
            if not raw:
                raise _Refused(f"{_where(name, path)} has no data; {spec.expected}")
            lineno += 1
            if len(raw) == _MAX_LINE and not raw.endswith(b"\n"):
                raise _Refused(f"{_where(name, path, lineno)} is longer than {_MAX_LINE} bytes; {spec.expected}")
            text = _decode(raw, _where(name, path, lineno), lineno == 1, f"; {spec.expected}").strip()
            if not text:
                continue
            if text.startswith("#"):
                comment = (lineno, text.lstrip("#").strip(), fh.tell())
                continue
            if not _is_numeric_row(text):
                header, header_line, offset, data_line = text, lineno, fh.tell(), lineno + 1
                break
            if comment is None or not comment[1] or _is_numeric_row(comment[1]):
                raise _Refused(f"{_where(name, path, lineno)} holds numbers but no header row came before it; {spec.expected}")
            header, header_line, offset, data_line = comment[1], comment[0], comment[2], comment[0] + 1
            break
        sep = _separator(header)
        fields = _header_fields(header, sep)
        use = _match_columns(fields, _where(name, path, header_line), spec)
        decimal = "."
        if sep == ";":
            fh.seek(offset)
            for raw in fh:
                first = raw.decode("utf-8", errors="replace").strip()
                if first:
                    decimal = "," if "," in first else "."
                    break
    return _Layout(sep, decimal, header_line, offset, data_line, tuple(fields), use, spec)


def _scan(path: Path, lay: _Layout, name: str, upto_row: int | None = None):
    """First bad data line as ``(line, reason)``, else None; with
    ``upto_row`` the line number of that data row (0-based) instead."""
    ncols = len(lay.names)
    row = 0
    with open(path, "rb") as fh:
        fh.seek(lay.data_offset)
        for lineno, raw in enumerate(fh, start=lay.data_line):
            text = _decode(raw, _where(name, path, lineno), False).rstrip("\r\n")
            if not text.strip():
                continue
            if upto_row is not None:
                if row == upto_row:
                    return lineno, ""
                row += 1
                continue
            fields = _split(text, lay.sep)
            if len(fields) != ncols:
                cols = ", ".join(f.strip() for f in lay.names)
                return lineno, f"expected {ncols} fields ({cols}), got {len(fields)}"
            for key, i in zip(lay.spec.columns, lay.use):
                v = _number(fields[i], lay.decimal)
                if v is None:
                    shown = fields[i].strip()
                    return lineno, f"{key} is empty" if not shown else f"{key} = {shown!r} is not a number"
                if not math.isfinite(v):
                    return lineno, f"{key} = {fields[i].strip()!r} is not finite"
    return None


def _separators_match(path: Path, lay: _Layout, nrows: int) -> bool:
    """Every data row has the header's number of fields (separator count;
    a quoted separator also makes it differ, and the scan then decides)."""
    sep = lay.sep.encode()
    count = 0
    with open(path, "rb") as fh:
        fh.seek(lay.data_offset)
        while block := fh.read(_BLOCK):
            count += block.count(sep)
    return count == (len(lay.names) - 1) * nrows


def _fast_columns(path: Path, lay: _Layout):
    """The three columns by pandas' C reader and whether the rows were
    checked completely; None when pandas refuses the file or a row lacks a
    field (the scan says which)."""
    import pandas as pd

    ncols = len(lay.names)
    kw = {"header": None, "names": list(range(ncols)), "engine": "c", "skip_blank_lines": True}
    if int(pd.__version__.split(".")[0]) < 3:
        kw["float_precision"] = "round_trip"  # correctly rounded, as Python's float (pandas 3's default)
    if lay.sep is None:
        kw.update(sep=r"\s+", dtype={i: np.float64 for i in lay.use})
    else:
        # no NA spellings: an empty or "nan" field fails the float conversion, and the scan names it
        kw.update(sep=lay.sep, decimal=lay.decimal, dtype=np.float64, na_filter=False)
        if ncols > len(lay.use):
            kw["usecols"] = list(lay.use)
    with open(path, "rb") as fh:
        fh.seek(lay.data_offset)
        try:
            df = pd.read_csv(fh, **kw)
        except pd.errors.EmptyDataError:
            return [np.empty(0) for _ in lay.use], True
        except (pd.errors.ParserError, ValueError, UnicodeDecodeError):
            return None
    nrows = len(df)
    if lay.sep is None and ncols > len(lay.use) and df[ncols - 1].isna().any():
        return None  # a row lacks its last field
    checked = lay.sep is None or ncols == len(lay.use) or _separators_match(path, lay, nrows)
    # one column at a time: each copy is writable and its block is freed
    return [np.array(df.pop(i), dtype=np.float64) for i in lay.use], checked


def read_history_csv(path, *, name: str = "path"):
    """Read a history ``t, x, N`` (SI units: s, m, N) from a CSV file.

    The layouts accepted (header variants, separators, units) are described
    in :mod:`jointdyn.drivers._csv`: a header row naming the columns ``t``,
    ``x``, ``N`` (or ``time``, ``displacement``, ``normal load``; units such
    as ``t [s]`` must be SI), separated by ``,``, ``;``, tabs or spaces, then
    one sample per row. Other columns are ignored.

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
        A missing or unreadable file, no header row, a missing or ambiguous
        column, a non-SI unit, a row with a missing or extra field, a
        non-numeric or non-finite value, fewer than 2 samples, or t not
        strictly increasing. The message names the file and the line.
    """
    return tuple(_read_columns(path, name, _HISTORY))


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
    return tuple(_read_columns(path, name, _PAIR))


def _read_columns(path, name: str, spec: _Spec) -> list:
    """The spec's columns of a CSV file, validated (see :func:`read_history_csv`)."""
    path = V.input_file(name, path)
    try:
        lay = _layout(path, name, spec)
        fast = _fast_columns(path, lay)
        if fast is None or not fast[1] or not all(np.isfinite(c).all() for c in fast[0]):
            bad = _scan(path, lay, name)
            if bad is not None:
                raise _Refused(f"{_where(name, path, bad[0])}: {bad[1]}")
            if fast is None or not all(np.isfinite(c).all() for c in fast[0]):
                raise _Refused(f"{_where(name, path)} cannot be parsed as CSV; {spec.expected}")
        cols = fast[0]
        t = cols[0]
        if t.size < 2:
            raise _Refused(f"{_where(name, path)} must have at least 2 samples (data rows), got {t.size}")
        steps = np.diff(t)
        if not np.all(steps > 0):
            i = int(np.flatnonzero(~(steps > 0))[0])
            a, _ = _scan(path, lay, name, upto_row=i)
            b, _ = _scan(path, lay, name, upto_row=i + 1)
            raise _Refused(
                f"{_where(name, path, b)}: t must be strictly increasing, got t = {float(t[i + 1])!r} "
                f"after t = {float(t[i])!r} on line {a}"
            )
    except OSError as exc:
        raise ValueError(f"{_where(name, path)} cannot be read: {exc.strerror or exc}") from None
    return cols
