"""Compare two folders of jointdyn outputs number by number: ``python benchmarks/compare_outputs.py OLD NEW``.

Both folders hold the same workloads run by two versions of jointdyn
(``benchmarks/reference_outputs.py``, which says how to set up each tree):
CLI JSON (``*.json``), tables (``*.csv``), Datasets (``*.nc``) and arrays
(``*.npz``). Every file of OLD (except ``*.err``, ``*.png``, ``*.svg`` and ``log.txt``) is compared
with the file of the same path in NEW:

* each file is read into leaves: a JSON object is flattened to paths
  (``branches[0]/gamma``; a list of numbers is one leaf), a CSV table to its
  columns, a Dataset to its variables, coordinates, dimensions and attributes
  (an attribute holding JSON is flattened too); a file that is not JSON is
  compared line by line;
* a leaf name of OLD is mapped through the documented renames (``RENAMES``,
  from CHANGELOG.md) before it is looked up in NEW;
* a file whose path differs only in a 12-hex-digit key (the sweeps'
  checkpoint folders, named by a hash of their inputs) is matched to the one
  file of NEW with the same path but that key;
* numbers (scalars and arrays, also numbers written as text as in CSV or
  ``repr`` strings) are equal only when their bits are equal: the same shape
  and ``float.hex`` of every element (NaN equals NaN);
* other values (labels, statuses) are compared after the documented value
  renames (``VALUE_RENAMES``), with both folders' paths replaced by ``<OUT>``.

Each file is reported as ``identical`` (the same bytes), ``same-numbers``
(every number of OLD is in NEW bit for bit; renamed, added keys and changed
labels listed), or ``NUMERIC-DIFF`` / ``MISSING`` / ``REMOVED-NUMBERS``
(listed with the largest relative difference). Leaves that measure run time
(``TIMING``) are not outputs and are skipped. The exit status is 1 when any
file is not identical or same-numbers.
"""

from __future__ import annotations

import argparse
import csv
import io
import json
import math
import re
import sys
from pathlib import Path

import numpy as np

#: leaf names renamed between the two versions (old -> new), from CHANGELOG.md
RENAMES = {
    "energy_contact_j": "energy_contact_J",
    "energy_viscous_j": "energy_viscous_J",
    "detail": "message",
}
#: label values renamed (old -> new), from CHANGELOG.md: hyphenated statuses, one "not computed"
VALUE_RENAMES = {
    "not computed": "not-computed",
    "missing": "not-computed",
    "no peak": "no-peak",
    "peak in a jump": "peak-in-a-jump",
    "not periodic": "not-periodic",
    "not unique": "not-unique",
    "not seen": "not-seen",
}
#: leaf names that are run times, not outputs
TIMING = re.compile(r"(^|[/:@_])(seconds|elapsed|wall_s|cpu_s|time_s)($|[/@\[])")
_SKIP_SUFFIXES = (".err", ".png", ".svg")
_NUM = re.compile(r"^[+-]?(\d+\.?\d*([eE][+-]?\d+)?|\.\d+([eE][+-]?\d+)?|nan|inf|NaN|Infinity|-Infinity)$")


# ---------------------------------------------------------------- reading files into leaves
def _flatten(obj, prefix: str, out: dict) -> None:
    if isinstance(obj, dict):
        for k, v in obj.items():
            _flatten(v, f"{prefix}/{k}" if prefix else str(k), out)
    elif isinstance(obj, list) and obj and all(isinstance(v, (dict, list)) for v in obj):
        for i, v in enumerate(obj):
            _flatten(v, f"{prefix}[{i}]", out)
    elif isinstance(obj, str) and obj[:1] in "{[":
        try:
            _flatten(json.loads(obj), prefix, out)
        except ValueError:
            out[prefix] = obj
    else:
        out[prefix] = obj


def _read_json(path: Path) -> dict:
    text = path.read_text()
    try:
        data = json.loads(text)
    except ValueError:
        return {f"line {i + 1}": line for i, line in enumerate(text.splitlines())}
    out: dict = {}
    _flatten(data, "", out)
    return out


def _read_csv(path: Path) -> dict:
    rows = list(csv.reader(io.StringIO(path.read_text())))
    if not rows:
        return {}
    header, body = rows[0], rows[1:]
    out = {"rows": len(body)}
    for j, name in enumerate(header):
        out[f"col:{name}"] = [r[j] if j < len(r) else "" for r in body]
    return out


def _read_nc(path: Path) -> dict:
    import xarray as xr

    ds = xr.load_dataset(path)
    out: dict = {f"dim:{k}": int(v) for k, v in ds.sizes.items()}
    for k, v in ds.attrs.items():
        _flatten(v, f"attr:{k}", out)
    for kind, group in (("coord", ds.coords), ("var", ds.data_vars)):
        for name, da in group.items():
            out[f"{kind}:{name}"] = da.values
            out[f"{kind}:{name}@dims"] = list(da.dims)
            for k, v in da.attrs.items():
                _flatten(v, f"{kind}:{name}@{k}", out)
    return out


def _read_npz(path: Path) -> dict:
    with np.load(path, allow_pickle=False) as z:
        return {f"array:{k}": z[k] for k in z.files}


def read_leaves(path: Path) -> dict:
    """Leaves of one output file (see module docstring)."""
    if path.suffix == ".npz":
        return _read_npz(path)
    if path.suffix == ".nc":
        return _read_nc(path)
    if path.suffix == ".csv":
        return _read_csv(path)
    return _read_json(path)


# ---------------------------------------------------------------- comparing leaves
def _as_numbers(value):
    """A float64 array of a numeric leaf (numbers, numeric text), else None."""
    if isinstance(value, bool) or value is None:
        return None
    if isinstance(value, (int, float)):
        return np.array([float(value)])
    if isinstance(value, str):
        return np.array([float(value)]) if _NUM.match(value.strip()) else None
    arr = np.asarray(value, dtype=object) if isinstance(value, list) else np.asarray(value)
    if arr.dtype.kind in "iuf":
        return arr.astype(np.float64).ravel()
    if arr.dtype.kind == "b":
        return None
    if arr.size and all(isinstance(v, (int, float, np.integer, np.floating)) and not isinstance(v, (bool, np.bool_))
                        or (isinstance(v, str) and _NUM.match(v.strip())) for v in arr.ravel()):
        return np.array([float(v) for v in arr.ravel()])
    return None


def _label(value, dirs: tuple[str, ...]):
    if isinstance(value, np.ndarray):
        value = value.tolist()
    if isinstance(value, list):
        return [_label(v, dirs) for v in value]
    if isinstance(value, str):
        for d in dirs:
            value = value.replace(d, "<OUT>")
        return value
    return value


def _renamed_label(value):
    if isinstance(value, list):
        return [_renamed_label(v) for v in value]
    if isinstance(value, str):
        for old, new in VALUE_RENAMES.items():
            value = re.sub(rf"(?<![\w-]){re.escape(old)}(?![\w-])", new, value)
    return value


def _bits_equal(a: np.ndarray, b: np.ndarray) -> bool:
    if a.shape != b.shape:
        return False
    return all(x.hex() == y.hex() or (math.isnan(x) and math.isnan(y)) for x, y in zip(a.tolist(), b.tolist()))


def _max_rel(a: np.ndarray, b: np.ndarray) -> str:
    if a.shape != b.shape:
        return f"shape {a.shape} -> {b.shape}"
    with np.errstate(all="ignore"):
        d = np.abs(a - b) / np.maximum(np.abs(a), np.abs(b))
    d = d[np.isfinite(d)]
    nan_change = int(np.sum(np.isnan(a) != np.isnan(b)))
    worst = f"max rel diff {d.max():.3g}" if d.size else "no finite difference"
    return worst + (f", {nan_change} NaN changes" if nan_change else "") + f", {int(np.sum(a != b))} of {a.size} differ"


def _new_name(key: str, old_keys) -> str:
    for old, new in RENAMES.items():
        renamed = re.sub(rf"(?<![A-Za-z0-9]){re.escape(old)}(?![A-Za-z0-9])", new, key)
        if renamed != key and renamed not in old_keys:
            key = renamed
    return key


def _compare_leaf(key: str, a, b, dirs: tuple[str, ...], rep: dict) -> None:
    na, nb = _as_numbers(a), _as_numbers(b)
    if na is not None and nb is not None:
        if not _bits_equal(na, nb):
            rep["numeric"].append(f"{key}: {_max_rel(na, nb)}")
        return
    la, lb = _label(a, dirs), _label(b, dirs)
    if la == lb and _label(a, ()) != _label(b, ()):
        rep["output_folder_only"].append(key)
    if la != lb:
        if _renamed_label(la) == lb:
            rep["labels_renamed"].append(key)
        else:
            rep["labels"].append(f"{key}: {str(la)[:80]!r} -> {str(lb)[:80]!r}")


def compare_leaves(old: dict, new: dict, dirs: tuple[str, ...]) -> dict:
    """Classified differences between the leaves of two versions of one file."""
    rep = {"renamed": [], "added": [], "removed_numbers": [], "removed_other": [], "labels": [],
           "labels_renamed": [], "output_folder_only": [], "numeric": [], "timing_skipped": []}
    matched = set()
    for key, a in old.items():
        if TIMING.search(key):
            rep["timing_skipped"].append(key)
            matched.add(key)
            continue
        renamed = _new_name(key, old)
        names = [n for n in dict.fromkeys((key, renamed)) if n in new]
        if not names:
            rep["removed_numbers" if _as_numbers(a) is not None else "removed_other"].append(key)
            continue
        if renamed != key:
            rep["renamed"].append(f"{key} -> {renamed}" + (" (old name kept too)" if key in new else ""))
        for nkey in names:
            matched.add(nkey)
            _compare_leaf(key, a, new[nkey], dirs, rep)
    rep["added"] = sorted(k for k in new if k not in matched and not TIMING.search(k))
    return rep


_HASH = re.compile(r"_[0-9a-f]{12}(?=/|$)")


def _same_but_hash(rel: Path, new_dir: Path) -> Path | None:
    """The one file of ``new_dir`` whose path differs from ``rel`` only in 12-hex-digit keys
    (the sweeps' checkpoint folders are named by a hash of their inputs, whose recipe may change)."""
    if not _HASH.search(rel.as_posix()):
        return None
    want = _HASH.sub("_<hash>", rel.as_posix())
    found = [p for p in new_dir.rglob(rel.name) if _HASH.sub("_<hash>", p.relative_to(new_dir).as_posix()) == want]
    return found[0] if len(found) == 1 else None


def compare_dirs(old_dir: Path, new_dir: Path) -> list[tuple[str, str, dict]]:
    """(file, verdict, details) for every output file of ``old_dir``."""
    folders = {old_dir, old_dir.resolve(), new_dir, new_dir.resolve()}
    dirs = tuple(str(d) for d in sorted(folders, key=lambda p: -len(str(p))))
    results = []
    for path in sorted(p for p in old_dir.rglob("*") if p.is_file()):
        rel = path.relative_to(old_dir)
        if path.suffix in _SKIP_SUFFIXES or path.name == "log.txt":
            continue
        other = new_dir / rel
        if not other.is_file():
            other = _same_but_hash(rel, new_dir)
        if other is None:
            results.append((str(rel), "MISSING", {}))
            continue
        note = [] if other == new_dir / rel else [str(other.relative_to(new_dir))]
        if path.read_bytes() == other.read_bytes():
            results.append((str(rel), "identical", {"matched_by_name_without_hash": note} if note else {}))
            continue
        rep = compare_leaves(read_leaves(path), read_leaves(other), dirs)
        rep["matched_by_name_without_hash"] = note
        verdict = ("NUMERIC-DIFF" if rep["numeric"] else "REMOVED-NUMBERS" if rep["removed_numbers"]
                   else "same-numbers")
        results.append((str(rel), verdict, rep))
    return results


def report(results) -> str:
    """A Markdown table of ``compare_dirs`` and the details of each file not identical."""
    lines = ["| file | verdict | renamed | added | labels (renamed / other) |", "|---|---|---|---|---|"]
    details = []
    for rel, verdict, rep in results:
        rep = {k: (v if k == "numeric" else list(dict.fromkeys(re.sub(r"\[\d+\]", "[*]", x) for x in v)))
               for k, v in rep.items()}
        if not rep:
            lines.append(f"| {rel} | {verdict} | | | |")
            continue
        n = {k: len(rep.get(k, ())) for k in ("renamed", "added", "labels_renamed", "labels")}
        lines.append(f"| {rel} | {verdict} | {n['renamed']} | {n['added']} | {n['labels_renamed']} / {n['labels']} |")
        details.append(f"\n### {rel}: {verdict}")
        for k, v in rep.items():
            if v:
                shown = v[:12] + ([f"... {len(v) - 12} more"] if len(v) > 12 else [])
                details.append(f"- {k} ({len(v)}): " + "; ".join(f"`{s}`" for s in shown))
    bad = [r for r in results if r[1] not in ("identical", "same-numbers")]
    summary = (f"\n{len(results)} files: {sum(r[1] == 'identical' for r in results)} identical, "
               f"{sum(r[1] == 'same-numbers' for r in results)} same numbers, {len(bad)} with a numeric "
               "difference, a missing file or removed numbers")
    return "\n".join(lines + details + [summary])


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("old", type=Path, help="folder of the old version's outputs")
    ap.add_argument("new", type=Path, help="folder of the new version's outputs")
    args = ap.parse_args(argv)
    for d in (args.old, args.new):
        if not d.is_dir():
            print(f"compare_outputs: {d} is not a folder", file=sys.stderr)
            return 2
    results = compare_dirs(args.old, args.new)
    print(report(results))
    return 0 if all(r[1] in ("identical", "same-numbers") for r in results) else 1


if __name__ == "__main__":
    sys.exit(main())
