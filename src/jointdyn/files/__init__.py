"""System files: a structure with its contacts and forcing, described in TOML.

:func:`read_system` reads the description documented in
``docs/system-files.md`` (tables ``[structure]``, ``[[force]]``,
``[[contact]]``, ``[[interface]]``, ``[output]``) and returns a :class:`~jointdyn.System`;
:func:`read_matrices` reads M, K (and C) from a ``.npz`` or MATLAB ``.mat``
file; a single matrix may also come from a Matrix Market ``.mtx`` or a
NumPy ``.npy`` file. Sparse matrices are converted to dense arrays (the
System holds dense matrices), within :data:`jointdyn.config.FILES_MAX_DOF`
degrees of freedom.

Every error is a ValueError of one line that names the file and the key,
written as a path into the TOML document: ``structure.M``, ``force[1].dof``,
``contact[0].normal.kn``, ``output.dof`` (array-of-tables entries counted
from 0).
"""

from __future__ import annotations

import math
import os
import sys
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from .. import _validate as V
from .. import config
from ._common import _dof, _number, _table, _vector, _Where
from ._pairs import _interface

__all__ = ["SystemFile", "read_system", "read_system_file", "read_matrices"]

#: top-level keys of a system file
_TOP_KEYS = ("title", "structure", "force", "contact", "interface", "output")
_STRUCTURE_KEYS = ("M", "K", "C", "zeta", "zeta_basis", "file", "w0")
#: what the modal ratios ``zeta`` refer to (``zeta_basis``): the modes with the contacts slipping (tangential
#: springs out, normal springs closed: ``System.K_reference``), the default, or stuck (``stuck_stiffness``)
ZETA_BASES = ("slipping", "stuck")
_FORCE_KEYS = ("dof", "amplitude", "phase_deg")
#: keys of a contact beside its law's own parameters
_CONTACT_KEYS = ("law", "kt", "mu", "n_ref", "tangential", "normal")
_SELECTION_KEYS = ("dof", "dof2", "direction")
_SPRING_KEYS = ("kn", "preload", *_SELECTION_KEYS)
_HARMONIC_KEYS = ("n0", "n1", "phase_deg")
_SAMPLED_KEYS = ("values",)
_OUTPUT_KEYS = ("dof", "dofs")
#: matrices a structure holds, in the order they are read
_MATRICES = ("M", "K", "C")
#: file suffixes holding one matrix per file, and several named ones
_SINGLE_SUFFIXES = (".mtx", ".npy")
_NAMED_SUFFIXES = (".npz", ".mat")
#: largest magnitude of a matrix entry: the largest double over a headroom for the sums and
#: products of the solvers (K + kt, w^2 M, their scaled copies)
_MAX_ENTRY = sys.float_info.max / 2.0**20
#: first bytes of a .npy file
_NPY_MAGIC = b"\x93NUMPY"


@dataclass(frozen=True)
class SystemFile:
    """A system file as read.

    Attributes
    ----------
    system : System
        The structure with its contacts and forcing.
    path : Path
        The file read.
    title : str
        Its ``title`` (the file name without suffix when absent).
    dofs : tuple of int
        DOFs whose amplitude and offset are reported (``[output] dofs``;
        default: the system's response DOF).
    """

    system: object
    path: Path
    title: str
    dofs: tuple


# --- matrices ---------------------------------------------------------------------


def _dense(where: _Where, key: str, value) -> np.ndarray:
    """A real 2-D matrix as a dense float64 array (sparse ones converted)."""
    import scipy.sparse as sp

    def bound(shape):
        if shape is not None and len(shape) == 2 and max(shape) > config.FILES_MAX_DOF:
            raise where.error(key, f"must have at most {config.FILES_MAX_DOF} rows and columns "
                                   f"(config.FILES_MAX_DOF), got shape {tuple(shape)}")

    bound(getattr(value, "shape", None))  # before a sparse matrix is made dense
    if sp.issparse(value):
        value = value.toarray()
    a = np.asarray(value)
    bound(a.shape)
    if np.iscomplexobj(a):
        raise where.error(key, "must be real, got complex entries")
    try:
        a = np.ascontiguousarray(a, dtype=np.float64)  # no copy of a float64 array read from a file
    except (TypeError, ValueError):
        raise where.error(key, f"must be a matrix of numbers, got entries of type {a.dtype}") from None
    if a.ndim != 2:
        raise where.error(key, f"must be a 2-D matrix, got shape {a.shape}")
    if a.size == 0:
        raise where.error(key, "must not be empty")
    if not float(np.max(np.abs(a))) <= _MAX_ENTRY:  # one pass: NaN, inf and too large entries
        if not np.all(np.isfinite(a)):
            i, j = np.argwhere(~np.isfinite(a))[0]
            raise where.error(key, f"must be finite everywhere (NaN/inf at [{i},{j}])")
        i, j = np.argwhere(np.abs(a) > _MAX_ENTRY)[0]
        raise where.error(key, f"entries must be at most {_MAX_ENTRY:.4g} in magnitude (the solvers add and scale "
                               f"them), got {float(a[i, j])!r} at [{i},{j}]")
    return a


class _FileError(ValueError):
    """What a matrix file's own check found (said after the file's name)."""


def _bound_header(what: str, shape, dtype=None) -> None:
    """A declared array (from a file's header, nothing read yet) within
    ``config.FILES_MAX_DOF``: ValueError naming ``what`` (a member or
    variable followed by a space, or "" for the file itself) otherwise."""
    shape = tuple(int(d) for d in shape)
    top = config.FILES_MAX_DOF
    if dtype is not None and np.dtype(dtype).hasobject:
        raise _FileError(f"{what}holds Python objects (a pickled array): save numbers (float64)")
    if len(shape) == 2 and max(shape) > top:
        raise _FileError(f"{what}declares shape {shape} in its header: a matrix must have at most {top} rows and "
                         "columns (config.FILES_MAX_DOF); nothing was read")
    if math.prod(shape) > top * top:
        raise _FileError(f"{what}declares shape {shape} in its header: more than {top} x {top} entries "
                         "(config.FILES_MAX_DOF); nothing was read")


def _npy_header(fh):
    """(shape, dtype) from the header of a .npy stream (nothing else read)."""
    fmt = np.lib.format
    version = fmt.read_magic(fh)
    if version == (1, 0):
        shape, _, dtype = fmt.read_array_header_1_0(fh)
    elif version == (2, 0):
        shape, _, dtype = fmt.read_array_header_2_0(fh)
    else:
        shape, _, dtype = fmt._read_array_header(fh, version)
    return shape, dtype


def _load_npz(path: Path, wanted) -> dict:
    """Arrays of a ``.npz`` file by name: the ``wanted`` ones read (their
    headers bounded first), the others listed as None; a
    ``scipy.sparse.save_npz`` file is one matrix, named ``""``."""
    import zipfile
    import zlib

    if not zipfile.is_zipfile(path):
        raise _FileError("is not a .npz archive (numpy.savez writes one)")
    with zipfile.ZipFile(path) as z:
        members = {i.filename[:-4]: i.filename for i in z.infolist() if i.filename.endswith(".npy")}
        sparse = {"format", "shape", "data"} <= set(members)
        read = list(members) if sparse else [k for k in wanted if k in members]
        out = {k: None for k in members}
        for key in read:
            member = members[key]
            try:
                with z.open(member) as fh:
                    shape, dtype = _npy_header(fh)
                _bound_header(f"member {member!r} ", shape, dtype)
                with z.open(member) as fh:
                    out[key] = np.lib.format.read_array(fh, allow_pickle=False)
            except _FileError:
                raise
            except (zipfile.BadZipFile, zlib.error, OSError, EOFError, RuntimeError, ValueError) as exc:
                raise _FileError(f"member {member!r} cannot be read: {exc}") from None
    if sparse:
        return {"": _sparse_npz(out)}
    return out


def _sparse_npz(arrays: dict):
    """The matrix of a ``scipy.sparse.save_npz`` file from its arrays."""
    import scipy.sparse as sp

    fmt = np.asarray(arrays["format"]).ravel()[0].item() if np.asarray(arrays["format"]).size else ""
    fmt = fmt.decode("ascii", "replace") if isinstance(fmt, bytes) else str(fmt)
    shape = tuple(int(d) for d in np.asarray(arrays["shape"]).ravel())
    _bound_header("its sparse matrix ", shape)
    if fmt in ("csr", "csc", "bsr"):
        cls = {"csr": sp.csr_matrix, "csc": sp.csc_matrix, "bsr": sp.bsr_matrix}[fmt]
        return cls((arrays["data"], arrays["indices"], arrays["indptr"]), shape=shape)
    if fmt == "coo":
        return sp.coo_matrix((arrays["data"], (arrays["row"], arrays["col"])), shape=shape)
    if fmt == "dia":
        return sp.dia_matrix((arrays["data"], arrays["offsets"]), shape=shape)
    raise _FileError(f"is a sparse matrix of unknown format {fmt!r}")


def _load_mat(path: Path, wanted) -> dict:
    """Variables of a MATLAB file by name: the ``wanted`` ones read (their
    declared shapes bounded first), the others listed as None."""
    import scipy.io

    try:
        listed = scipy.io.whosmat(str(path))
    except NotImplementedError:
        raise _FileError("is a MATLAB v7.3 (HDF5) file; save it with -v7 (scipy.io reads v4 to v7)") from None
    names = {name: shape for name, shape, _ in listed if not name.startswith("__")}
    read = [k for k in wanted if k in names]
    for k in read:
        _bound_header(f"variable {k!r} ", names[k])
    data = scipy.io.loadmat(str(path), variable_names=read) if read else {}
    return {k: data.get(k) for k in names}


def _load_named(path: Path, wanted=_MATRICES) -> dict:
    """Arrays of a ``.npz`` or ``.mat`` file by name (``wanted`` read, the
    others listed as None; a ``scipy.sparse.save_npz`` file is one matrix,
    named ``""``)."""
    if path.suffix.lower() == ".mat":
        return _load_mat(path, wanted)
    return _load_npz(path, wanted)


def _load_single(path: Path):
    """The matrix of a ``.mtx`` or ``.npy`` file (its declared size bounded first)."""
    if path.suffix.lower() == ".mtx":
        import scipy.io

        rows, cols, entries, *_ = scipy.io.mminfo(str(path))
        _bound_header("", (rows, cols))
        if int(entries) > int(rows) * int(cols):
            raise _FileError(f"declares {entries} entries in a {rows} x {cols} matrix")
        return scipy.io.mmread(str(path))
    with open(path, "rb") as fh:
        if fh.read(len(_NPY_MAGIC)) != _NPY_MAGIC:
            raise _FileError("is not a .npy file (numpy.save writes one)")
        fh.seek(0)
        shape, dtype = _npy_header(fh)
        _bound_header("", shape, dtype)
        fh.seek(0)
        return np.lib.format.read_array(fh, allow_pickle=False)


def _read_file(where: _Where, key: str, path: Path, loader):
    """``loader(path)`` with every failure as one line naming ``key`` and the file.

    The readers of the formats (zipfile, numpy, scipy.io) raise many kinds of
    exception on a corrupt or truncated file; each is said as a file that
    cannot be read, never a traceback."""
    if not path.is_file():
        what = ("a directory" if path.is_dir() else "not a regular file (a FIFO, a device or a broken link)"
                if os.path.lexists(path) else "no such file")
        raise where.error(key, f"names {str(path)!r}: {what}")
    try:
        return loader(path)
    except _FileError as exc:
        raise where.error(key, f"{str(path)!r} {exc}") from None
    except MemoryError:
        raise where.error(key, f"{str(path)!r} is too large to read into memory") from None
    except Exception as exc:  # noqa: BLE001 - a foreign reader's failure on a corrupt file, said in one line
        raise where.error(key, f"{str(path)!r} cannot be read as a {path.suffix} matrix file: "
                               f"{type(exc).__name__}: {exc}") from None


def read_matrices(path) -> dict:
    """M, K (and C when present) from a ``.npz`` or MATLAB ``.mat`` file.

    Parameters
    ----------
    path : str or os.PathLike
        A ``.npz`` file (arrays named ``M``, ``K``, ``C``, e.g. written by
        ``numpy.savez``) or a MATLAB file up to v7 (variables ``M``, ``K``,
        ``C``; sparse variables are accepted).

    Returns
    -------
    dict
        ``{"M": ..., "K": ...}`` and ``"C"`` when the file holds it: dense
        float64 arrays (kg, N/m, N s/m). Other variables are ignored.

    Raises
    ------
    ValueError
        Unreadable file, a missing ``M`` or ``K`` (the message lists the
        variables found), an entry that is not a finite real 2-D matrix.
    """
    p = Path(os.fspath(path))
    where = _Where(p)
    if p.suffix.lower() not in _NAMED_SUFFIXES:
        raise where.error("path", f"must be a .npz or .mat file (M, K and C by name), got suffix {p.suffix!r}")
    data = _read_file(where, "path", p, _load_named)
    found = ", ".join(sorted(data)) or "none"
    out = {}
    for name in _MATRICES:
        if name in data:
            out[name] = _dense(where, name, data[name])
        elif name != "C":
            raise where.error(name, f"is missing (variables found: {found})")
    return out


def _matrix_value(where: _Where, key: str, value, folder: Path) -> np.ndarray:
    """``structure.M`` etc.: an inline list of rows or the path of a matrix file."""
    if isinstance(value, str):
        p = Path(value)
        p = p if p.is_absolute() else folder / p
        suffix = p.suffix.lower()
        if suffix in _SINGLE_SUFFIXES:
            return _dense(where, key, _read_file(where, key, p, _load_single))
        if suffix in _NAMED_SUFFIXES:
            name = key.rsplit(".", 1)[-1]
            data = _read_file(where, key, p, lambda q: _load_named(q, (name,)))
            pick = data.get(name, data.get("") if len(data) == 1 else None)
            if pick is None:
                raise where.error(key, f"names {str(p)!r}, which holds no variable {name!r} "
                                       f"(found: {', '.join(sorted(data)) or 'none'})")
            return _dense(where, key, pick)
        raise where.error(key, f"names {value!r}: a matrix file must end in .mtx, .npy, .npz or .mat")
    if not isinstance(value, list) or not value or not all(isinstance(r, list) for r in value):
        raise where.error(key, f"must be a list of rows (a matrix) or the path of a matrix file, got {value!r:.60}")
    widths = {len(r) for r in value}
    if len(widths) != 1:
        raise where.error(key, f"rows must have equal lengths, got {sorted(widths)}")
    rows = [[_number(where, f"{key}[{i}][{j}]", v) for j, v in enumerate(r)] for i, r in enumerate(value)]
    return _dense(where, key, rows)


def _symmetric(where: _Where, key: str, A: np.ndarray) -> None:
    from ..systems import asymmetry

    scale = float(np.max(np.abs(A)))
    diff, i, j = asymmetry(A)
    if diff > 1e-10 * scale:
        raise where.error(key, f"must be symmetric ({key}[{i},{j}] = {float(A[i, j])!r} but {key}[{j},{i}] = "
                               f"{float(A[j, i])!r})")


def _structure(where: _Where, s, folder: Path) -> dict:
    """The matrices of ``[structure]`` (checked: square, same size, symmetric,
    M positive definite, K positive semi-definite) and its options."""
    s = _table(where, "structure", s, _STRUCTURE_KEYS)
    mats = {}
    if "file" in s:
        for name in ("M", "K"):
            if name in s:
                raise where.error(f"structure.{name}", "is given twice: inline and by structure.file; give one")
        f = s["file"]
        if not isinstance(f, str):
            raise where.error("structure.file", f"must be a path (string), got {f!r:.60}")
        p = Path(f) if Path(f).is_absolute() else folder / f
        if p.suffix.lower() not in _NAMED_SUFFIXES:
            raise where.error("structure.file", f"must be a .npz or .mat file holding M, K (and C), got {f!r}; "
                                                "a .mtx file holds one matrix: give M = \"m.mtx\", K = \"k.mtx\"")
        data = _read_file(where, "structure.file", p, _load_named)
        for name in _MATRICES:
            if name in data:
                if name in s:
                    raise where.error(f"structure.{name}", f"is given twice: inline and in {str(p)!r}; give one")
                mats[name] = _dense(where, f"structure.file {name}", data[name])
            elif name != "C":
                raise where.error("structure.file", f"{str(p)!r} holds no {name} (found: {', '.join(sorted(data)) or 'none'})")
    for name in _MATRICES:
        if name in s:
            mats[name] = _matrix_value(where, f"structure.{name}", s[name], folder)
        elif name not in mats and name != "C":
            raise where.error(f"structure.{name}", "is missing (give the matrix, or structure.file)")
    _check_matrices(where, mats)
    if "C" in mats and "zeta" in s:
        raise where.error("structure.zeta", "cannot be combined with a damping matrix C; give one")
    out = {"mats": mats, "zeta": None, "w0": None, "zeta_basis": ZETA_BASES[0]}
    if "zeta_basis" in s:
        if "zeta" not in s:
            raise where.error("structure.zeta_basis", "needs structure.zeta (the ratios it refers to)")
        if s["zeta_basis"] not in ZETA_BASES:
            raise where.error("structure.zeta_basis", f"must be one of {', '.join(map(repr, ZETA_BASES))}, "
                              f"got {s['zeta_basis']!r:.60}")
        out["zeta_basis"] = s["zeta_basis"]
    if "zeta" in s:
        z = s["zeta"]
        n = mats["M"].shape[0]
        out["zeta"] = (_number(where, "structure.zeta", z, low=0.0) if not isinstance(z, list)
                       else _vector(where, "structure.zeta", z, n))
        if np.any(np.asarray(out["zeta"]) < 0):
            raise where.error("structure.zeta", f"must be >= 0, got {z!r:.60}")
    if "w0" in s:
        out["w0"] = _number(where, "structure.w0", s["w0"], low=0.0, low_open=True)
    return out


def _check_matrices(where: _Where, mats: dict) -> None:
    M = mats["M"]
    n = M.shape[0]
    for name, A in mats.items():
        key = f"structure.{name}"
        if A.shape != (n, n):
            what = "square" if name == "M" else f"{n} x {n} like M"
            raise where.error(key, f"must be {what}, got shape {A.shape[0]} x {A.shape[1]}")
        _symmetric(where, key, A)
    if n > config.SYSTEM_DENSE_CHECK_MAX_DOF:  # a factorisation and Lanczos iterations, no eigen-decomposition
        from ..systems import definiteness_failure

        for name in _MATRICES:
            if name in mats:
                lam = definiteness_failure(mats[name], semi=name != "M")
                if lam is not None:
                    what = "definite" if name == "M" else "semi-definite"
                    raise where.error(f"structure.{name}", f"must be positive {what} (smallest eigenvalue {lam:.6g})")
        return
    try:
        np.linalg.cholesky(M)
    except np.linalg.LinAlgError:
        lam = float(np.linalg.eigvalsh(M)[0])
        raise where.error("structure.M", f"must be positive definite (smallest eigenvalue {lam:.6g})") from None
    lam = np.linalg.eigvalsh(mats["K"])
    if lam[0] < -1e-10 * max(abs(lam[-1]), 1e-300):
        raise where.error("structure.K", f"must be positive semi-definite (smallest eigenvalue {lam[0]:.6g})")
    if "C" in mats:
        lc = np.linalg.eigvalsh(mats["C"])
        if lc[0] < -1e-10 * max(abs(lc[-1]), 1e-300):
            raise where.error("structure.C", f"must be positive semi-definite (smallest eigenvalue {lc[0]:.6g})")


# --- forcing, contacts, output ------------------------------------------------------


def _forces(where: _Where, entries, n: int):
    """Amplitudes (N) and phases (degrees) per DOF from ``[[force]]``."""
    if not isinstance(entries, list):
        raise where.error("force", "must be an array of tables ([[force]] entries)")
    amp = np.zeros(n)
    phase = np.zeros(n)
    seen = {}
    for i, f in enumerate(entries):
        key = f"force[{i}]"
        f = _table(where, key, f, _FORCE_KEYS, required=("dof", "amplitude"))
        d = _dof(where, f"{key}.dof", f["dof"], n)
        if d in seen:
            raise where.error(f"{key}.dof", f"{d} is already forced by force[{seen[d]}]; one entry per DOF")
        seen[d] = i
        amp[d] = _number(where, f"{key}.amplitude", f["amplitude"])
        phase[d] = _number(where, f"{key}.phase_deg", f.get("phase_deg", 0.0))
    return amp, phase


def _selection(where: _Where, key: str, t: dict, n: int) -> dict:
    """``dof``/``dof2`` or ``direction`` of a tangential or normal selection."""
    if "direction" in t:
        for k in ("dof", "dof2"):
            if k in t:
                raise where.error(f"{key}.{k}", "cannot be combined with direction (a selection vector); give one")
        direction = _vector(where, f"{key}.direction", t["direction"], n)
        if not np.any(direction != 0.0):
            raise where.error(f"{key}.direction", "must have a non-zero entry (it selects the relative motion)")
        return {"direction": direction}
    if "dof" not in t:
        raise where.error(f"{key}.dof", "is missing (or give direction, a selection vector)")
    d = _dof(where, f"{key}.dof", t["dof"], n)
    d2 = _dof(where, f"{key}.dof2", t.get("dof2", -1), n, ground=True)
    if d2 == d:
        raise where.error(f"{key}.dof2", f"must differ from dof ({d}); omit it (or -1) for ground")
    return {"dof": d, "dof2": d2}


def _normal(where: _Where, key: str, t, n: int):
    """The normal load of a contact and its static load (the law's default n_ref)."""
    from ..kinematics import ConstantLoad, HarmonicLoad, NormalSpring, SampledLoad

    if not isinstance(t, dict):
        raise where.error(key, f"must be a table, got {t!r:.60}")
    if "kn" in t or "preload" in t:
        t = _table(where, key, t, _SPRING_KEYS, required=("kn", "preload"))
        kn = _number(where, f"{key}.kn", t["kn"], low=0.0, low_open=True)
        preload = _number(where, f"{key}.preload", t["preload"], low=0.0, low_open=True)
        sel = _selection(where, key, t, n)
        make, fields = (lambda: NormalSpring(kn=kn, preload=preload, **sel)), _SPRING_KEYS
    elif "values" in t:
        t = _table(where, key, t, _SAMPLED_KEYS)
        values = _vector(where, f"{key}.values", t["values"])
        if not np.any(values > 0.0):
            raise where.error(f"{key}.values", f"must have a positive (compressive) entry: the contact is never "
                                               f"loaded, got {t['values']!r:.60}")
        make, fields = (lambda: SampledLoad(values)), _SAMPLED_KEYS
    elif "n0" in t:
        t = _table(where, key, t, _HARMONIC_KEYS)
        n0 = _number(where, f"{key}.n0", t["n0"], low=0.0, low_open=True)
        if "n1" in t or "phase_deg" in t:
            n1 = _number(where, f"{key}.n1", t.get("n1", 0.0), low=0.0)
            ph = _number(where, f"{key}.phase_deg", t.get("phase_deg", 0.0))
            make = lambda: HarmonicLoad(n0=n0, n1=n1, phase_deg=ph)  # noqa: E731
        else:
            make = lambda: ConstantLoad(n0)  # noqa: E731
        fields = _HARMONIC_KEYS
    else:
        raise where.error(key, "must give kn and preload (a normal spring), n0 (a constant load), n0 with n1 "
                               "and phase_deg (a harmonic load) or values (a sampled period)")
    try:
        load = make()
    except ValueError as exc:
        raise where.wrap(key, exc, fields) from None
    return load, load.n0


def _contact(where: _Where, i: int, c, n: int):
    """One ``[[contact]]`` entry as a Contact (its law's n_ref defaults to the static normal load)."""
    from ..laws import law_names, law_parameters, make_law
    from ..systems import Contact

    key = f"contact[{i}]"
    if not isinstance(c, dict):
        raise where.error(key, f"must be a table, got {c!r:.60}")
    law = c.get("law")
    if law is None:
        raise where.error(f"{key}.law", f"is missing (a registered law: {', '.join(law_names())})")
    if law not in law_names():
        raise where.error(f"{key}.law", f"must be one of {', '.join(law_names())}; got {law!r}")
    params = tuple(p.name for p in law_parameters(law))
    c = _table(where, key, c, (*_CONTACT_KEYS, *params), required=("kt", "mu", "tangential", "normal"))
    tan = _selection(where, f"{key}.tangential",
                     _table(where, f"{key}.tangential", c["tangential"], _SELECTION_KEYS), n)
    normal, n_static = _normal(where, f"{key}.normal", c["normal"], n)
    kt = _number(where, f"{key}.kt", c["kt"])
    mu = _number(where, f"{key}.mu", c["mu"])
    if "n_ref" in c:
        n_ref = _number(where, f"{key}.n_ref", c["n_ref"])
    elif not n_static > 0.0:
        raise where.error(f"{key}.normal.values", f"have the mean {n_static:.6g} N, the static load the law's "
                                                  "n_ref defaults to, which must be > 0: give n_ref (N), or "
                                                  "values with a positive mean")
    else:
        n_ref = n_static
    given = {p: c[p] for p in params if p in c}
    for p, v in given.items():
        if isinstance(v, (bool, list, dict)):
            raise where.error(f"{key}.{p}", f"must be a number or a name, got {v!r:.60}")
    try:
        made = make_law(law, kt=kt, mu=mu, n_ref=n_ref, **given)
    except ValueError as exc:
        raise where.wrap(key, exc, ("kt", "mu", "n_ref", *params)) from None
    return Contact(made, normal=normal, **tan)


def _output(where: _Where, o, n: int):
    """(output DOF or None, reported DOFs or None) of ``[output]``."""
    o = _table(where, "output", o, _OUTPUT_KEYS)
    dof = _dof(where, "output.dof", o["dof"], n) if "dof" in o else None
    dofs = None
    if "dofs" in o:
        if not isinstance(o["dofs"], list) or not o["dofs"]:
            raise where.error("output.dofs", f"must be a non-empty list of DOF indices, got {o['dofs']!r:.60}")
        dofs = [_dof(where, f"output.dofs[{k}]", d, n) for k, d in enumerate(o["dofs"])]
        if len(set(dofs)) != len(dofs):
            raise where.error("output.dofs", f"must not repeat a DOF, got {dofs}")
    return dof, dofs


def _not_utf8(p: Path, exc: UnicodeDecodeError) -> str:
    """Where a file stops being UTF-8 (line and byte), as TOML requires it."""
    try:
        with open(p, "rb") as fh:
            head = fh.read(exc.start)
    except OSError:
        head = b""
    line = head.count(b"\n") + 1
    bad = exc.object[exc.start:exc.start + 1].hex() if isinstance(exc.object, bytes) else "?"
    return f"line {line}: byte 0x{bad} is not UTF-8 (a TOML file is UTF-8 text)"


def read_system_file(path) -> SystemFile:
    """Read a TOML system file (``docs/system-files.md``) with its output options.

    Parameters
    ----------
    path : str or os.PathLike
        The ``.toml`` file; matrix files it names are resolved against its
        folder.

    Returns
    -------
    SystemFile
        The System, the path, the title and the reported DOFs.

    Raises
    ------
    ValueError
        One line naming the file and the key: unknown key, wrong type or
        shape, non-symmetric or indefinite M, DOF out of range, missing or
        unknown law parameter, unknown law, unreadable matrix file.
    """
    import tomllib

    from ..systems import System, modal_damping, stuck_stiffness

    p = Path(os.fspath(path))
    where = _Where(p)
    try:
        with open(p, "rb") as fh:
            doc = tomllib.load(fh)
    except tomllib.TOMLDecodeError as exc:
        raise ValueError(" ".join(f"{p}: not valid TOML: {exc}".split())) from None
    except UnicodeDecodeError as exc:
        raise ValueError(f"{p}: not valid TOML: {_not_utf8(p, exc)}") from None
    except ValueError as exc:  # what the parser does not convert (an integer beyond Python's digit limit)
        msg = str(exc)
        if "integer string conversion" in msg:
            msg = f"an integer has more than {sys.get_int_max_str_digits()} digits (Python reads no longer ones)"
        raise ValueError(" ".join(f"{p}: not valid TOML: {msg}".split())) from None
    except OSError as exc:
        raise ValueError(f"{p}: cannot be read: {exc.strerror or exc}") from None
    _table(where, "", doc, _TOP_KEYS, required=("structure",))
    title = doc.get("title", p.stem)
    if not isinstance(title, str):
        raise where.error("title", f"must be a string, got {title!r:.60}")
    st = _structure(where, doc["structure"], p.parent)
    M, K = st["mats"]["M"], st["mats"]["K"]
    n = M.shape[0]
    force, phase = _forces(where, doc.get("force", []), n)
    entries = doc.get("contact", [])
    if not isinstance(entries, list):
        raise where.error("contact", "must be an array of tables ([[contact]] entries)")
    contacts = tuple(_contact(where, i, c, n) for i, c in enumerate(entries))
    entries = doc.get("interface", [])
    if not isinstance(entries, list):
        raise where.error("interface", "must be an array of tables ([[interface]] entries)")
    interfaces = tuple(_interface(where, i, c, n, p.parent) for i, c in enumerate(entries))
    out_dof, dofs = _output(where, doc.get("output", {}), n)
    kw = dict(contacts=contacts, force=force, force_phase_deg=phase, w0_rad_s=st["w0"], output_dof=out_dof,
              interfaces=interfaces)
    try:
        system = System(M, st["mats"].get("C"), K, **kw)
        if st["zeta"] is not None:  # an operator: no n x n C for a large sparse structure (jointdyn.damping)
            Kz = system.K_reference if st["zeta_basis"] == "slipping" else stuck_stiffness(system)
            system = System(M, modal_damping(M, Kz, st["zeta"], form="operator"), K, **kw)
    except ValueError as exc:
        raise ValueError(" ".join(f"{p}: {exc}".split())) from None
    if st["w0"] is None and not math.isfinite(system.w0):
        raise where.error("structure.K", "and structure.M give natural frequencies beyond the floating-point range "
                          "(K / M overflows): give them in consistent units")
    if st["w0"] is None and not system.w0 > 0.0:
        raise where.error("structure.w0", "is needed: every natural frequency of (M, K) with the normal springs "
                          "in place and the tangential contacts free is 0 (nothing but the tangential contacts holds "
                          "the structure); give w0 (rad/s) under [structure]")
    return SystemFile(system=system, path=p, title=title,
                      dofs=tuple(dofs) if dofs is not None else (system.response_dof,))


def read_system(path):
    """The :class:`~jointdyn.System` of a TOML system file (``docs/system-files.md``).

    Parameters
    ----------
    path : str or os.PathLike
        The ``.toml`` file; matrix files it names are resolved against its
        folder.

    Returns
    -------
    System

    Raises
    ------
    ValueError
        One line naming the file and the key (see :func:`read_system_file`).
    """
    return read_system_file(path).system
