"""The one CSV reader of jointdyn: measured histories, fit data and pair tables.

Every command that reads a table of numbers (``jointdyn loop --input``,
``fit --input``, ``fit --backbone``, the pairs file of an ``[[interface]]``)
reads it here, so that every one accepts the same layouts and refuses bad
files with the same one-line messages.

Accepted layout
---------------
- Optional preamble: blank lines and lines starting with ``#``; a UTF-8
  byte-order mark.
- One header row naming the columns. When the first data row follows a
  ``#`` line directly and no other header is present, that comment is the
  header (``numpy.savetxt(..., header="t x N")`` writes ``# t x N``).
- Optionally a unit row right after the header (``s,m,N``), as
  spreadsheet and DAQ exports write it.
- Separator: ``,``, ``;``, tab or runs of spaces, detected from the header
  row. With ``;`` a decimal comma is accepted (detected from the first data
  row).
- Column names: those of the :class:`Spec` (for histories ``t`` or
  ``time``; ``x`` or ``displacement``; ``N``, ``normal load`` or ``normal
  force``). Longer names match in any case; the single letters match as
  written or through the lower case (``X``, ``n``), except ``T``, which is
  jointdyn's tangential force, not a time. Surrounding whitespace and
  quotes are ignored. A unit in brackets or parentheses (``t [s]``, ``Time
  (s)``) or in the unit row must be the SI unit of the column: s, m, N.
- Other columns are ignored; every data row has as many fields as the header.

The values are parsed by pandas' compiled reader (only the columns used,
float64, correctly rounded like Python's ``float``). When that fails or
finds a missing, extra, non-numeric or non-finite field, a line-by-line scan
of the file names the first bad line. The number of data rows is bounded
before anything is parsed (the bound and its reason are the caller's).
"""

from __future__ import annotations

import csv
import math
import re
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from .. import _validate as V

__all__ = ["Spec", "RowBound", "read_table", "data_line", "HISTORY", "PAIR_HISTORY"]


@dataclass(frozen=True)
class Spec:
    """The columns a reader returns, in order, with their SI units, the other names each accepts in
    any case, and how error messages describe the expected layout.

    ``units`` maps a column to its SI unit ("" for a number without unit:
    a ratio or an index; a column it leaves out takes any unit); ``increasing`` names the column (a time) that
    must increase strictly from row to row, if any; ``min_rows`` is the
    fewest data rows accepted."""

    columns: tuple
    units: dict
    aliases: dict
    expected: str
    increasing: str | None = None
    min_rows: int = 2


@dataclass(frozen=True)
class RowBound:
    """The most data rows a file may hold, and why (said in the error), checked before parsing."""

    rows: int
    why: str


#: a contact's history: time, tangential displacement, normal load
HISTORY = Spec(
    columns=("t", "x", "N"),
    units={"t": "s", "x": "m", "N": "N"},
    aliases={
        "t": ("time",),
        "x": ("x", "displacement"),
        "N": ("n", "normal load", "normal force", "normal_load", "normal_force"),
    },
    expected="expected a header row naming the columns t, x, N in SI units (s, m, N), "
             "e.g. 't,x,N' or 't [s];x [m];N [N]', then one row of numbers per sample",
    increasing="t",
)
#: a node pair's relative history: time, tangential displacements along t1 and t2, normal approach
PAIR_HISTORY = Spec(
    columns=("t", "u1", "u2", "g"),
    units={"t": "s", "u1": "m", "u2": "m", "g": "m"},
    aliases={"t": ("time",), "u1": ("u1",), "u2": ("u2",), "g": ("g",)},
    expected="expected a header row naming the columns t, u1, u2, g in SI units (s, m, m, m), "
             "e.g. 't,u1,u2,g' or 't [s];u1 [m];u2 [m];g [m]', then one row of numbers per sample",
    increasing="t",
)
_UNIT = re.compile(r"^(.*?)\s*[\[(]\s*([^\])]*?)\s*[\])]$")
#: one header field of a space-separated file: a word with an optional unit
_SPACED_FIELD = re.compile(r"[^\s\[(]+(?:\s*[\[(][^\])]*[\])])?")
#: spellings of "no unit" in a header or a unit row
_NO_UNIT = ("", "-", "1")
#: a unit as a unit row writes it: letters, digits, / * ^ . - and an optional bracket
_UNIT_TOKEN = re.compile(r"^[\[(]?\s*[A-Za-z\u00b5\u03bc%][A-Za-z0-9\u00b5\u03bc/*^.\-\s]{0,15}\s*[\])]?$")
#: longest header line read, bytes (a longer one is not a CSV header)
_MAX_LINE = 1 << 20
#: longest field shown in a message, characters
_SHOWN = 40
#: bytes per block when counting separators and lines
_BLOCK = 1 << 22
#: the field size the csv module accepts: any line the reader gets to (a bad one is named, not a traceback)
_FIELD_LIMIT = 1 << 30


@dataclass(frozen=True)
class _Layout:
    """Where the data are and how a row is split."""

    sep: str | None  # None: runs of whitespace
    decimal: str
    header_line: int  # 1-based line number of the header
    data_offset: int  # byte offset of the first line after the header (and its unit row)
    data_line: int  # its 1-based line number
    names: tuple  # header fields as written
    use: tuple  # column indices of the spec's columns
    spec: Spec = field(default=HISTORY)


class _Refused(ValueError):
    """A precise complaint about one line of the file."""


def _where(name, path, line=None) -> str:
    return f"{name} {str(path)!r}" + ("" if line is None else f" line {line}")


def _shown(text: str) -> str:
    """A field as a message quotes it: at most ``_SHOWN`` characters."""
    t = text.strip()
    return repr(t) if len(t) <= _SHOWN else f"{t[:_SHOWN]!r}... ({len(t)} characters)"


def _number(text: str, decimal: str) -> float | None:
    s = text.strip().strip('"').strip()
    if decimal == ",":
        if "." in s:
            return None
        s = s.replace(",", ".")
    try:
        return float(s)
    except (ValueError, OverflowError):
        return None


def _csv_fields(line: str, sep: str) -> list:
    """One line split by the csv module (quotes honoured), without its field-size limit."""
    limit = csv.field_size_limit()
    csv.field_size_limit(_FIELD_LIMIT)
    try:
        return next(csv.reader([line], delimiter=sep), [])
    finally:
        csv.field_size_limit(limit)


def _split(line: str, sep: str | None) -> list:
    if sep is None:
        return line.split()
    if '"' in line:
        return _csv_fields(line, sep)
    return line.split(sep)


def _separator(header: str) -> str | None:
    for sep in (";", "\t", ","):
        if sep in header:
            return sep
    return None


def _header_fields(header: str, sep: str | None) -> list:
    if sep is None:
        return _SPACED_FIELD.findall(header)
    return _csv_fields(header, sep)


def _name_unit(field: str):
    f = field.strip().strip("\"'").strip()
    m = _UNIT.match(f)
    if m:
        return m.group(1).strip(), m.group(2).strip()
    return f, ""


def _check_unit(where, shown: str, key: str, unit: str, spec: Spec) -> None:
    """A column's stated unit is its SI unit (or, for a number without unit, none)."""
    si = spec.units.get(key)
    if si is None or unit == si or (si == "" and unit in _NO_UNIT):
        return
    listed = ", ".join(f"{k} in {spec.units[k] or 'no unit'}" for k in spec.columns if k in spec.units)
    raise _Refused(f"{where}: column {shown!r} has unit {unit!r}; expected {si or 'no unit'} "
                   f"(SI units: {listed}; convert the file)")


def _match_columns(fields, where, spec: Spec = HISTORY) -> tuple:
    """Indices of the spec's columns among the header fields (units checked)."""
    parsed = [_name_unit(f) for f in fields]
    use = []
    missing = []
    for key in spec.columns:
        hits = [i for i, (b, _) in enumerate(parsed) if b == key]
        if not hits:
            hits = [i for i, (b, _) in enumerate(parsed) if b.lower() in spec.aliases.get(key, ()) and b != "T"]
        if len(hits) > 1:
            both = ", ".join(repr(fields[i].strip()) for i in hits)
            raise _Refused(f"{where}: columns {both} all name {key}; keep one")
        if not hits:
            missing.append(key)
            continue
        if parsed[hits[0]][1]:
            _check_unit(where, fields[hits[0]].strip(), key, parsed[hits[0]][1], spec)
        use.append(hits[0])
    if missing:
        found = ", ".join(_shown(f) for f in fields[:20]) or "none"
        raise _Refused(f"{where}: missing column {', '.join(missing)} (found {found}); {spec.expected}")
    return tuple(use)


def _is_numeric_row(text: str) -> bool:
    """A data row rather than a header (a decimal comma splits a number
    into two numbers here, which keeps the row numeric)."""
    tokens = [tok for tok in re.split(r"[,;\s]+", text.strip()) if tok]
    return bool(tokens) and all(_number(tok, ".") is not None for tok in tokens)


def _unit_row(text: str, lay_sep, fields) -> list | None:
    """The units of a unit row (one per header field), or None when ``text`` is not one."""
    tokens = _split(text, lay_sep)
    if len(tokens) != len(fields) or _is_numeric_row(text):
        return None
    units = []
    for tok in tokens:
        t = tok.strip().strip("\"'").strip()
        if t not in _NO_UNIT and not _UNIT_TOKEN.match(t):
            return None
        units.append(t.strip("[]() "))
    return units


def _decode(raw: bytes, where: str, first: bool, hint: str = "") -> str:
    try:
        return raw.decode("utf-8-sig" if first else "utf-8")
    except UnicodeDecodeError:
        raise _Refused(f"{where}: not UTF-8 text{hint}") from None


def _readline(fh, where_line, lineno: int, spec: Spec) -> str | None:
    """The next line of a file's head as text (None at its end), refused when longer than ``_MAX_LINE``."""
    raw = fh.readline(_MAX_LINE)
    if not raw:
        return None
    if len(raw) == _MAX_LINE and not raw.endswith(b"\n"):
        raise _Refused(f"{where_line(lineno)} is longer than {_MAX_LINE} bytes; {spec.expected}")
    return _decode(raw, where_line(lineno), lineno == 1, f"; {spec.expected}").strip()


def _find_header(fh, path, name, spec: Spec) -> tuple:
    """(header text, its line, byte offset after it, next line number), the file positioned after it."""
    comment = None
    lineno = 0
    while True:
        text = _readline(fh, lambda k: _where(name, path, k), lineno + 1, spec)
        if text is None:
            raise _Refused(f"{_where(name, path)} has no data; {spec.expected}")
        lineno += 1
        if not text:
            continue
        if text.startswith("#"):
            comment = (lineno, text.lstrip("#").strip(), fh.tell())
            continue
        if not _is_numeric_row(text):
            return text, lineno, fh.tell(), lineno + 1
        if comment is None or not comment[1] or _is_numeric_row(comment[1]):
            raise _Refused(f"{_where(name, path, lineno)} holds numbers but no header row came before it; "
                           f"{spec.expected}")
        fh.seek(comment[2])
        return comment[1], comment[0], comment[2], comment[0] + 1


def _layout(path: Path, name: str, spec: Spec = HISTORY) -> _Layout:
    """Find the header, its unit row, the separator and the decimal mark."""
    with open(path, "rb") as fh:
        header, header_line, offset, data_line = _find_header(fh, path, name, spec)
        sep = _separator(header)
        fields = _header_fields(header, sep)
        use = _match_columns(fields, _where(name, path, header_line), spec)
        # a unit row directly after the header (blank lines between are skipped)
        lineno = data_line
        while (text := _readline(fh, lambda k: _where(name, path, k), lineno, spec)) == "":
            lineno += 1
        units = _unit_row(text, sep, fields) if text else None
        if units is not None:
            for key, i in zip(spec.columns, use):
                _check_unit(_where(name, path, lineno), f"{fields[i].strip()} [{units[i]}]", key, units[i], spec)
            offset, data_line = fh.tell(), lineno + 1
        decimal = "."
        if sep == ";":
            fh.seek(offset)
            for raw in fh:
                first = raw[:_MAX_LINE].decode("utf-8", errors="replace").strip()
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
                cols = ", ".join(f.strip() if len(f.strip()) <= _SHOWN else _shown(f) for f in lay.names[:20])
                return lineno, f"expected {ncols} fields ({cols}), got {len(fields)}"
            for key, i in zip(lay.spec.columns, lay.use):
                v = _number(fields[i], lay.decimal)
                if v is None:
                    shown = fields[i].strip()
                    return lineno, f"{key} is empty" if not shown else f"{key} = {_shown(shown)} is not a number"
                if not math.isfinite(v):
                    return lineno, f"{key} = {_shown(fields[i])} is not finite"
    return None


def data_line(path, lay: _Layout, name: str, row: int) -> int:
    """The 1-based line number of data row ``row`` (0-based) of a file read by :func:`read_table`."""
    return _scan(Path(path), lay, name, upto_row=row)[0]


def _count_rows(path: Path, lay: _Layout, name: str, bound: RowBound) -> None:
    """Refuse a file of more than ``bound.rows`` data rows before parsing it (lines are counted
    in blocks; blank lines are counted exactly only when the quick count is over the bound)."""
    lines = 0
    with open(path, "rb") as fh:
        fh.seek(lay.data_offset)
        last = b"\n"
        while block := fh.read(_BLOCK):
            lines += block.count(b"\n")
            last = block[-1:]
    lines += last != b"\n"
    if lines <= bound.rows:
        return
    rows = 0
    with open(path, "rb") as fh:
        fh.seek(lay.data_offset)
        for raw in fh:
            rows += bool(raw.strip())
            if rows > bound.rows:
                raise _Refused(f"{_where(name, path)} must have at most {bound.rows} data rows ({bound.why}); "
                               "nothing was computed")


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


def read_table(path, spec: Spec, *, name: str = "path", bound: RowBound | None = None):
    """Read the columns of ``spec`` from a CSV file (layouts: see the module's docstring).

    Parameters
    ----------
    path : str or Path
        CSV file (a regular file: a FIFO or a device is refused).
    spec : Spec
        The columns, their SI units and aliases, the increasing column.
    name : str
        How error messages name the file's parameter (the CLI's option, such
        as ``--input``, or a TOML key).
    bound : RowBound, optional
        The most data rows accepted, checked before anything is parsed.

    Returns
    -------
    columns : list of ndarray
        Float64 arrays (writable, contiguous) of equal length (at least
        ``spec.min_rows``), finite, in the order of ``spec.columns``.
    layout : object
        Where the data rows are (for :func:`data_line`, which turns a row
        index into the line a message names).

    Raises
    ------
    ValueError
        A missing, unreadable or non-regular file, no header row, a missing
        or ambiguous column, a non-SI unit, too many rows, a row with a
        missing or extra field, a non-numeric or non-finite value, too few
        rows, or the increasing column not strictly increasing. One line
        naming ``name``, the file and the line.
    """
    path = V.input_file(name, path)
    try:
        lay = _layout(path, name, spec)
        if bound is not None:
            _count_rows(path, lay, name, bound)
        fast = _fast_columns(path, lay)
        if fast is None or not fast[1] or not all(np.isfinite(c).all() for c in fast[0]):
            bad = _scan(path, lay, name)
            if bad is not None:
                raise _Refused(f"{_where(name, path, bad[0])}: {bad[1]}")
            if fast is None or not all(np.isfinite(c).all() for c in fast[0]):
                raise _Refused(f"{_where(name, path)} cannot be parsed as CSV; {spec.expected}")
        cols = fast[0]
        if cols[0].size < spec.min_rows:
            rows = "data row" if spec.min_rows == 1 else "samples (data rows)"
            raise _Refused(f"{_where(name, path)} must have at least {spec.min_rows} {rows}, got {cols[0].size}")
        if spec.increasing is not None:
            _check_increasing(path, lay, name, cols[spec.columns.index(spec.increasing)], spec.increasing)
    except OSError as exc:
        raise ValueError(f"{_where(name, path)} cannot be read: {exc.strerror or exc}") from None
    return cols, lay


def _check_increasing(path, lay, name, t, key) -> None:
    steps = np.diff(t)
    if not np.all(steps > 0):
        i = int(np.flatnonzero(~(steps > 0))[0])
        a = data_line(path, lay, name, i)
        b = data_line(path, lay, name, i + 1)
        raise _Refused(f"{_where(name, path, b)}: {key} must be strictly increasing, got {key} = {float(t[i + 1])!r} "
                       f"after {key} = {float(t[i])!r} on line {a}")
