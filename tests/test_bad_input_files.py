"""Bad and edge-case inputs generated broadly: system files, matrix files,
sizes set by options and law parameters, solver failures.

Every refusal is one line on stderr naming the file and the key (or the
option), exit status 2 (3 for a computation that failed), no traceback, no
file written, and nothing computed: the compute entry points are replaced by
functions that fail the test when reached, and for the matrix files whose
headers declare a huge array the readers of the data are replaced too, so
that the size is proved to be checked from the header before anything is
allocated.
"""

from __future__ import annotations

import math
import os
import struct
import subprocess
import sys
import zipfile
from pathlib import Path

import numpy as np
import pytest

import jointdyn as jd
from jointdyn import _validate as V
from jointdyn import config
from jointdyn.cli import main
from jointdyn.files import read_matrices, read_system
from jointdyn.sweeps import _points
from test_bad_input import _Reached, _boom, _cli, _tree, no_compute, refused  # noqa: F401 (no_compute: a fixture)

SRC = str(Path(__file__).resolve().parents[1] / "src")
#: a hang guard for subprocesses, not a speed requirement
HANG_GUARD_S = 600


# --- system files written for the tests -----------------------------------------------------
BASE = """\
[structure]
{structure}

[[force]]
dof = 0
amplitude = {amplitude}

[[contact]]
law = "{law}"
kt = 3.0e5
mu = 0.5
{law_params}
tangential = {tangential}
normal = {normal}
"""
STRUCTURE = "M = [[10.0, 0.0], [0.0, 1.0]]\nK = [[3.9e5, 0.0], [0.0, 0.0]]\nC = [[0.0, 0.0], [0.0, 55.0]]"
SPRING = "{ dof = 1, kn = 3.0e5, preload = 100.0 }"


def _toml(folder: Path, name: str = "sys.toml", **kw) -> Path:
    fields = dict(structure=STRUCTURE, amplitude="25.0", law="iwan", law_params="", tangential="{ dof = 0 }",
                  normal=SPRING)
    fields.update(kw)
    p = folder / name
    p.write_text(BASE.format(**fields))
    return p


def test_the_base_file_is_valid(tmp_path):
    s = read_system(_toml(tmp_path))
    assert s.ndof == 2 and s.w0 == pytest.approx(math.sqrt(3.9e5 / 10.0), rel=1e-12)


# --- matrix files: corrupt, truncated, declaring huge arrays ----------------------------------
M2 = np.diag([10.0, 1.0])
K2 = np.diag([3.9e5, 0.0])
HUGE = 60000


def _npy_bytes(shape, descr="<f8", data=b"") -> bytes:
    """A .npy file (format 1.0) declaring ``shape`` and holding ``data``."""
    header = "{'descr': '%s', 'fortran_order': False, 'shape': %s, }" % (descr, tuple(shape))
    header += " " * (63 - (10 + len(header)) % 64) + "\n"
    return b"\x93NUMPY\x01\x00" + struct.pack("<H", len(header)) + header.encode() + data


def _npz_members(path: Path, members: dict, compress=False) -> Path:
    with zipfile.ZipFile(path, "w", zipfile.ZIP_DEFLATED if compress else zipfile.ZIP_STORED) as z:
        for name, data in members.items():
            z.writestr(name, data)
    return path


def _good_npz(path: Path, compressed=False) -> Path:
    (np.savez_compressed if compressed else np.savez)(path, M=M2, K=K2)
    return path


def _crc_npz(d: Path) -> Path:
    p = _good_npz(d / "crc.npz")
    b = bytearray(p.read_bytes())
    first = b.find(b"\x93NUMPY", b.find(b"K.npy"))  # K's stored .npy: 128 bytes of header, then its data
    b[first + 128 + 3] ^= 0xFF
    p.write_bytes(bytes(b))
    return p


def _deflate_npz(d: Path) -> Path:
    p = _good_npz(d / "deflate.npz", compressed=True)
    b = bytearray(p.read_bytes())
    n, e = struct.unpack("<HH", b[26:30])
    b[30 + n + e] = 0xFF  # the first member's deflate stream: an invalid block type
    p.write_bytes(bytes(b))
    return p


def _truncated_npz(d: Path) -> Path:
    p = _good_npz(d / "cut.npz")
    b = p.read_bytes()
    p.write_bytes(b[: len(b) // 2])
    return p


def _short_npz_member(d: Path) -> Path:
    return _npz_members(d / "short.npz", {"M.npy": _npy_bytes((2, 2), data=b"\0" * 8),
                                          "K.npy": _npy_bytes((2, 2), data=b"\0" * 32)})


def _pickled_npz(d: Path) -> Path:
    return _npz_members(d / "pickled.npz", {"M.npy": _npy_bytes((2, 2), descr="|O"),
                                            "K.npy": _npy_bytes((2, 2), data=b"\0" * 32)})


def _huge_npz(d: Path) -> Path:
    return _npz_members(d / "huge.npz", {"M.npy": _npy_bytes((HUGE, HUGE)), "K.npy": _npy_bytes((HUGE, HUGE))})


def _huge_flat_npz(d: Path) -> Path:
    return _npz_members(d / "flat.npz", {"M.npy": _npy_bytes((HUGE * HUGE,)), "K.npy": _npy_bytes((2, 2))})


def _mat(d: Path, name: str, **arrays) -> Path:
    import scipy.io

    p = d / name
    scipy.io.savemat(str(p), arrays or {"M": M2, "K": K2}, do_compression=False)
    return p


def _truncated_mat(d: Path) -> Path:
    p = _mat(d, "cut.mat")
    b = p.read_bytes()
    p.write_bytes(b[: len(b) - 40])
    return p


def _huge_mat(d: Path) -> Path:
    p = _mat(d, "huge.mat", M=np.eye(3), K=np.eye(3))
    b = bytearray(p.read_bytes())
    dims = struct.pack("<IIii", 5, 8, 3, 3)  # the dimensions subelement (miINT32, 8 bytes) of the first array
    k = b.find(dims)
    assert k > 0
    b[k:k + 16] = struct.pack("<IIii", 5, 8, HUGE, HUGE)
    p.write_bytes(bytes(b))
    return p


def _hdf5_mat(d: Path) -> Path:
    p = d / "v73.mat"
    p.write_bytes(b"MATLAB 7.3 MAT-file, Platform: GLNXA64, Created on: Mon Jan  1 00:00:00 2024 HDF5 schema 1.00 ."
                  .ljust(116) + b"\0" * 8 + b"\x00\x02IM" + b"\x89HDF\r\n\x1a\n" + b"\0" * 100)
    return p


def _garbage(d: Path, name: str) -> Path:
    p = d / name
    p.write_bytes(bytes(range(256)) * 4)
    return p


def _empty(d: Path, name: str) -> Path:
    p = d / name
    p.write_bytes(b"")
    return p


def _bytes(d: Path, name: str, data: bytes) -> Path:
    p = d / name
    p.write_bytes(data)
    return p


def _text(d: Path, name: str, text: str) -> Path:
    p = d / name
    p.write_text(text)
    return p


#: (id, maker of the file, the words the line holds beside the file name); each file is named by
#: ``structure.file`` when .npz/.mat, by ``structure.M`` and ``structure.K`` otherwise
MATRIX_FILES = [
    ("crc", _crc_npz, "CRC"),
    ("deflate", _deflate_npz, "decompressing"),
    ("truncated-npz", _truncated_npz, "not a .npz"),
    ("short-member", _short_npz_member, "cannot be read"),
    ("pickled-member", _pickled_npz, "Python objects"),
    ("huge-npz", _huge_npz, "at most 10000 rows"),
    ("huge-flat-npz", _huge_flat_npz, "entries"),
    ("truncated-mat", _truncated_mat, "cannot be read"),
    ("huge-mat", _huge_mat, "at most 10000 rows"),
    ("hdf5-mat", _hdf5_mat, "v7.3"),
    ("garbage-mat", lambda d: _garbage(d, "g.mat"), "cannot be read"),
    ("empty-mat", lambda d: _empty(d, "e.mat"), "cannot be read"),
    ("garbage-npz", lambda d: _garbage(d, "g.npz"), "not a .npz"),
    ("huge-npy", lambda d: _bytes(d, "huge.npy", _npy_bytes((HUGE, HUGE))), "at most 10000 rows"),
    ("huge-flat-npy", lambda d: _bytes(d, "flat.npy", _npy_bytes((HUGE * HUGE,))), "entries"),
    ("short-npy", lambda d: _bytes(d, "short.npy", _npy_bytes((2, 2), data=b"\0" * 9)), "cannot be read"),
    ("bad-header-npy", lambda d: _bytes(d, "bad.npy", b"\x93NUMPY\x01\x00\x10\x00{not a dict}   \n"),
     "cannot be read"),
    ("garbage-npy", lambda d: _garbage(d, "g.npy"), "not a .npy"),
    ("huge-mtx-array", lambda d: _text(d, "h.mtx", f"%%MatrixMarket matrix array real general\n{HUGE} {HUGE}\n1\n"),
     "at most 10000 rows"),
    ("huge-mtx-coordinate", lambda d: _text(d, "c.mtx", "%%MatrixMarket matrix coordinate real general\n"
                                                        f"{HUGE} {HUGE} 1\n1 1 1.0\n"), "at most 10000 rows"),
    ("mtx-too-many-entries", lambda d: _text(d, "e.mtx", "%%MatrixMarket matrix coordinate real general\n"
                                                         "2 2 1000000000000\n1 1 1.0\n"), "entries"),
    ("mtx-truncated", lambda d: _text(d, "t.mtx", "%%MatrixMarket matrix coordinate real general\n2 2 3\n1 1 1.0\n"),
     "cannot be read"),
    ("mtx-no-header", lambda d: _text(d, "n.mtx", "1 2\n3 4\n"), "cannot be read"),
    ("empty-mtx", lambda d: _empty(d, "e.mtx"), "cannot be read"),
]


def _structure_for(path: Path) -> str:
    if path.suffix in (".npz", ".mat"):
        return f'file = "{path.name}"'
    return f'M = "{path.name}"\nK = "{path.name}"'


@pytest.fixture
def no_huge_reads(monkeypatch):
    """The readers of array data fail the test: a file declaring a huge array is refused from its header."""
    import scipy.io

    monkeypatch.setattr(np.lib.format, "read_array", _boom)
    monkeypatch.setattr(scipy.io, "loadmat", _boom)
    monkeypatch.setattr(scipy.io, "mmread", _boom)


@pytest.mark.parametrize("make, word", [m[1:] for m in MATRIX_FILES], ids=[m[0] for m in MATRIX_FILES])
@pytest.mark.parametrize("cmd", [["frc", "--method", "hb", "--gamma", "0.8:1.2:0.1"], ["modes"]],
                         ids=["frc-hb", "modes"])
def test_bad_matrix_file_cli(make, word, cmd, no_compute, capsys, tmp_path, request):
    path = make(no_compute)
    toml = _toml(no_compute, structure=_structure_for(path))
    if "huge" in request.node.name:
        request.getfixturevalue("no_huge_reads")
    key = "structure.file" if path.suffix in (".npz", ".mat") else "structure.M"
    line = refused(capsys, tmp_path, [*cmd, "--system", toml, "--out", "o"], str(toml), key, path.name, word)
    assert line.startswith(f"jointdyn {cmd[0]}: error: --system ")


NAMED_FILES = [m for m in MATRIX_FILES if "npz" in m[0] or "mat" in m[0] or m[0] in ("crc", "deflate")]


@pytest.mark.parametrize("make, word", [m[1:] for m in NAMED_FILES], ids=[m[0] for m in NAMED_FILES])
def test_bad_matrix_file_api(make, word, tmp_path):
    path = make(tmp_path)
    with pytest.raises(ValueError) as exc:
        read_matrices(path)
    msg = str(exc.value)
    assert len(msg.splitlines()) == 1 and msg.startswith(str(path)) and word in msg


def test_huge_header_is_refused_before_reading(no_huge_reads, tmp_path):
    """The bound comes from the header: the data readers are never called (they would fail the test)."""
    for make in (_huge_npz, _huge_mat):
        with pytest.raises(ValueError, match="declares shape"):
            read_matrices(make(tmp_path))


def test_valid_matrix_files_still_read(tmp_path):
    """The header checks let every documented format through, with the same numbers."""
    import scipy.io
    import scipy.sparse as sp

    for p in (_good_npz(tmp_path / "a.npz"), _good_npz(tmp_path / "b.npz", compressed=True), _mat(tmp_path, "c.mat")):
        got = read_matrices(p)
        np.testing.assert_array_equal(got["M"], M2)
        np.testing.assert_array_equal(got["K"], K2)
    sp.save_npz(tmp_path / "s.npz", sp.csr_matrix(M2))
    np.save(tmp_path / "m.npy", M2)
    scipy.io.mmwrite(str(tmp_path / "k.mtx"), sp.coo_matrix(K2))
    toml = _toml(tmp_path, structure='M = "s.npz"\nK = "k.mtx"')
    s = read_system(toml)
    np.testing.assert_array_equal(s.M, M2)
    np.testing.assert_array_equal(s.K, K2)
    toml = _toml(tmp_path, structure='M = "m.npy"\nK = "b.npz"')
    np.testing.assert_array_equal(read_system(toml).K, K2)


def test_unrelated_variables_are_not_read(tmp_path, monkeypatch):
    """Only M, K and C are read (and bounded): a huge unrelated member is listed, not loaded."""
    p = _npz_members(tmp_path / "extra.npz", {"M.npy": _npy_bytes((2, 2), data=M2.tobytes()),
                                              "K.npy": _npy_bytes((2, 2), data=K2.tobytes()),
                                              "X.npy": _npy_bytes((HUGE, HUGE))})
    got = read_matrices(p)
    assert set(got) == {"M", "K"}
    np.testing.assert_array_equal(got["K"], K2)


# --- TOML values out of the number range, encodings --------------------------------------------
DIGITS400 = "9" * 400
DIGITS5000 = "9" * 5000
TOML_CASES = [
    ("amplitude-400-digits", dict(amplitude=DIGITS400), "force[0].amplitude", "400 digits"),
    ("n_ref-400-digits", dict(law_params=f"n_ref = {DIGITS400}"), "contact[0].n_ref", "400 digits"),
    ("M-entry-400-digits", dict(structure=f"M = [[{DIGITS400}, 0.0], [0.0, 1.0]]\nK = [[1.0, 0.0], [0.0, 1.0]]"),
     "structure.M[0][0]", "400 digits"),
    ("zeta-400-digits", dict(structure="M = [[1.0]]\nK = [[1.0]]\nzeta = -" + DIGITS400, tangential="{ dof = 0 }",
                             normal="{ n0 = 100.0 }"), "structure.zeta", "400 digits"),
    ("preload-400-digits", dict(normal=f"{{ dof = 1, kn = 3.0e5, preload = {DIGITS400} }}"),
     "contact[0].normal.preload", "400 digits"),
    ("discrete-n-400-digits", dict(law="discrete", law_params=f"n = {DIGITS400}"), "contact[0].n", "400 digits"),
    ("dof-400-digits", dict(tangential=f"{{ dof = {DIGITS400} }}"), "contact[0].tangential.dof", "400 digits"),
    ("amplitude-5000-digits", dict(amplitude=DIGITS5000), "not valid TOML", "digits"),
    ("M-1e308", dict(structure="M = [[1.0]]\nK = [[1e308]]", normal="{ n0 = 100.0 }"), "structure.K", "at most"),
    ("K-over-M-overflows", dict(structure="M = [[1e-300]]\nK = [[1e300]]", normal="{ n0 = 100.0 }"),
     "structure.K", "floating-point range"),
    ("zero-tangential-direction", dict(tangential="{ direction = [0.0, 0.0] }"),
     "contact[0].tangential.direction", "non-zero"),
    ("zero-normal-direction", dict(normal="{ direction = [0.0, -0.0], kn = 3.0e5, preload = 100.0 }"),
     "contact[0].normal.direction", "non-zero"),
    ("sampled-all-negative", dict(normal="{ values = [-1.0, -2.0, -3.0] }"), "contact[0].normal.values",
     "positive"),
    ("sampled-all-zero", dict(normal="{ values = [0.0, 0.0] }"), "contact[0].normal.values", "positive"),
    ("sampled-negative-mean", dict(normal="{ values = [1.0, -2.0, -3.0] }"), "contact[0].normal.values",
     "n_ref"),
    ("discrete-n-2e9", dict(law="discrete", law_params="n = 2000000000"), "contact[0].n", "memory"),
    ("iwan-capacity-2e9", dict(law_params="capacity = 2000000000"), "contact[0].capacity", "memory"),
    ("closed-max-depth-2e9", dict(law="iwan-closed", law_params="max_depth = 2000000000"),
     "contact[0].max_depth", "memory"),
]


@pytest.mark.parametrize("kw, key, word", [c[1:] for c in TOML_CASES], ids=[c[0] for c in TOML_CASES])
def test_bad_system_file_values(kw, key, word, no_compute, capsys, tmp_path):
    toml = _toml(no_compute, **kw)
    refused(capsys, tmp_path, ["frc", "--method", "hb", "--gamma", "0.8:1.2:0.1", "--system", toml, "--out", "o"],
            str(toml), key, word)
    with pytest.raises(ValueError) as exc:
        read_system(toml)
    assert str(exc.value).startswith(str(toml)) and len(str(exc.value).splitlines()) == 1


@pytest.mark.parametrize("where", ["start", "title", "comment", "key"])
def test_not_utf8_keeps_the_file_name(where, no_compute, capsys, tmp_path):
    good = _toml(no_compute).read_bytes()
    bad = {"start": b"\xff" + good, "title": b'title = "\xff\xfe"\n' + good, "comment": good + b"# \xe9t\xe9\n",
           "key": good.replace(b"kt = ", b"k\xfft = ")}[where]
    p = no_compute / "bad.toml"
    p.write_bytes(bad)
    line = refused(capsys, tmp_path, ["modes", "--system", p], str(p), "not UTF-8", "line ")
    assert "codec" not in line


def test_the_paper_variant_held_by_nothing_is_refused_by_hb(no_compute, capsys, tmp_path):
    """docs/system-files.md: the example with a prescribed load in place of the spring is valid (DOF 1
    is a rigid-body mode); harmonic balance cannot fix its mean, and says so (was 'Singular matrix')."""
    toml = _toml(no_compute, normal="{ n0 = 100.0 }")
    s = read_system(toml)
    assert s.w0 == pytest.approx(math.sqrt(3.9e5 / 10.0), rel=1e-12)
    line = refused(capsys, tmp_path, ["frc", "--method", "hb", "--gamma", "0.8:1.2:0.1", "--system", toml],
                   "--method hb", "rigid-body mode", "DOF 1", "--method time")
    assert "Singular matrix" not in line


def test_normal_on_the_tangential_dof_without_support_is_refused_by_hb(no_compute, capsys, tmp_path):
    toml = _toml(no_compute, normal="{ dof = 0, kn = 3.0e5, preload = 100.0 }")
    refused(capsys, tmp_path, ["frc", "--method", "hb", "--gamma", "0.8:1.2:0.1", "--system", toml],
            "rigid-body mode", "DOF 1")


def test_a_failed_linear_solve_is_a_failure_not_bad_input(monkeypatch, capsys, tmp_path):
    """A singular system met while computing: exit 3 with one line saying what failed."""
    import jointdyn.hb

    def singular(*args, **kwargs):
        raise np.linalg.LinAlgError("Singular matrix")

    monkeypatch.setattr(jointdyn.hb, "continue_hb", singular)
    monkeypatch.chdir(tmp_path)
    line = refused(capsys, tmp_path, ["frc", "--method", "hb", "--gamma", "0.8:1.2:0.1"], "failed",
                   "Singular matrix", rc_expected=3)
    assert "error" not in line


# --- sizes set by options and law parameters -----------------------------------------------------
SIZE_OPTIONS = [
    (["frc", "--method", "hb", "--gamma", "0.8:1.2:0.1", "--harmonics", "100000"], "--harmonics"),
    (["frc", "--method", "hb", "--gamma", "0.8:1.2:0.1", "--samples", "1000000000"], "--samples"),
    (["frc", "--method", "hb", "--gamma", "0.8:1.2:0.1", "--harmonics", "3", "--samples", "1000000000"],
     "--samples"),
    (["frc", "--gamma", "1:1.1:0.1", "--steps-per-period", "1000000000", "--workers", "1"], "--steps-per-period"),
    (["frc", "--gamma", "1:1.1:0.1", "--steps-per-period", str(10**18)], "--steps-per-period"),
    (["modes", "--harmonics", "100000"], "--harmonics"),
    (["modes", "--samples", "1000000000"], "--samples"),
    (["loop", "--model", "discrete", "--n", "2000000000"], "--n"),
    (["frc", "--model", "discrete", "--n", "2000000000"], "--n"),
    (["modes", "--model", "discrete", "--law-param", "n=2000000000"], "--law-param n"),
    (["loop", "--law-param", "capacity=2000000000"], "--law-param capacity"),
    (["frc", "--method", "hb", "--law-param", "capacity=2000000000"], "--law-param capacity"),
    (["loop", "--model", "iwan-closed", "--law-param", "max_depth=2000000000"], "--law-param max_depth"),
]


@pytest.mark.parametrize("argv, word", SIZE_OPTIONS, ids=[" ".join(a) for a, _ in SIZE_OPTIONS])
def test_sizes_bounded_by_memory_before_computing(argv, word, no_compute, capsys, tmp_path):
    line = refused(capsys, tmp_path, [*argv, "--out", "o"], word, "memory", "at most")
    if word == "--harmonics":
        assert "--samples" not in line  # the default samples are not blamed for the harmonics


def test_memory_bound_from_config(monkeypatch, no_compute, capsys, tmp_path):
    """With config.MEMORY_LIMIT_BYTES the bound is exact: the largest size it names fits, one more does not."""
    from jointdyn.hb import hb_bytes

    # the memory bound every solver shares (config), lowered to make the case small
    monkeypatch.setattr(config, "MEMORY_LIMIT_BYTES", 20 << 20)
    assert V.memory_budget() == 20 << 20
    line = refused(capsys, tmp_path, ["modes", "--harmonics", "200", "--out", "o"], "--harmonics 200",
                   "config.MEMORY_LIMIT_BYTES")
    top = int(line.rsplit("at most ", 1)[1].split()[0])
    system = jd.System.paper_damper(eta=0.0)
    assert hb_bytes(system, top, 2 * top + 2) <= 20 << 20 < hb_bytes(system, top + 1, 2 * top + 4)
    with pytest.raises(ValueError, match=r"^n = 10000000 needs about .* n must be at most"):
        jd.make_law("discrete", kt=1.0, mu=1.0, n_ref=1.0, n=10_000_000)
    jd.make_law("discrete", kt=1.0, mu=1.0, n_ref=1.0, n=1000)


def test_memory_fits_names_the_label():
    with pytest.raises(ValueError, match=r"^--x 5 needs about .* more than the bound"):
        V.memory_fits("--x 5", math.inf)
    V.memory_fits("--x 5", 8.0)


def test_modes_harmonics_raise_the_default_samples(monkeypatch, capsys):
    """--harmonics alone: the samples follow (2H + 2 at least), --samples is not blamed."""
    seen = {}

    def fake(system, amps, **kw):
        seen.update(kw)
        raise _Reached("stop here")

    import jointdyn.modes

    monkeypatch.setattr(jointdyn.modes, "epmc", fake)
    with pytest.raises(_Reached):
        main(["modes", "--harmonics", "100"])
    from jointdyn.hb import AUTO, Discretisation

    assert seen["harmonics"] == 100 and seen["samples"] == AUTO  # chosen automatically, from 2H + 2
    assert Discretisation.of(seen["harmonics"], seen["samples"]).first == (100, 202)


def test_the_stiffest_mode_sets_the_step_and_is_named(no_compute, capsys, tmp_path):
    """A light, stiff normal DOF needs more time steps per period than memory allows: the refusal names
    the stiffest mode (the user gave no --steps-per-period) and points at the method without steps."""
    toml = _toml(no_compute, structure="M = [[10.0, 0.0], [0.0, 1e-30]]\nK = [[3.9e5, 0.0], [0.0, 0.0]]\n"
                                       "w0 = 197.5")
    refused(capsys, tmp_path, ["frc", "--gamma", "1:1.1:0.1", "--system", toml, "--out", "o"], "--method time",
            "stiffest mode", "--method hb")


def test_period_steps_unchanged_where_memory_allows():
    """The steps of a period are those the solver always took (the bound only refuses)."""
    from jointdyn.dynamics import MarchOptions
    from jointdyn.dynamics._model import make_model, pack_system, period_steps

    s = jd.System.paper_damper(normal="spring")
    pack = pack_system(s)
    w = 0.5 * s.w0
    march = MarchOptions(steps_per_period=64)
    J = period_steps(pack, w, march)
    assert J == max(64, int(math.ceil(2 * math.pi * pack.w_max / (w * march.max_omega_h))))
    assert make_model(s, w, march).J == J


# --- a backbone that never starts ------------------------------------------------------------------
def test_modes_out_no_start_writes_every_file(monkeypatch, capsys, tmp_path):
    import xarray as xr

    import jointdyn.modes.epmc  # noqa: F401

    epmc_mod = sys.modules["jointdyn.modes.epmc"]
    monkeypatch.setattr(epmc_mod, "newton", lambda *a, **k: (None, False, None))
    out = tmp_path / "o"
    rc, stdout, err = _cli(capsys, ["modes", "--out", out, "--json"])
    assert rc == 3
    assert sorted(os.listdir(out)) == ["modes.csv", "modes.nc", "modes.png"]
    assert xr.load_dataset(out / "modes.nc").attrs["status"] == "no-start"
    assert '"status": "no-start"' in stdout
    lines = err.strip().splitlines()
    assert len(lines) == 1 and "no-start" in lines[0] and "Traceback" not in err


# --- numpy's warnings do not print before the error line (a real process) ----------------------------
def _env():
    env = dict(os.environ)
    env["PYTHONPATH"] = SRC + os.pathsep + env.get("PYTHONPATH", "")
    return env


@pytest.mark.parametrize("case", ["gamma-1e300", "K-over-M"])
def test_no_runtime_warning_before_the_error_line(case, tmp_path):
    if case == "gamma-1e300":
        argv = ["frc", "--gamma", "1e300:1e300:1", "--sweep", "up"]
    else:
        argv = ["frc", "--system", str(_toml(tmp_path, structure="M = [[1e-300]]\nK = [[1e300]]",
                                             normal="{ n0 = 100.0 }"))]
    r = subprocess.run([sys.executable, "-W", "default", "-m", "jointdyn", *argv, "--out", str(tmp_path / "o")],
                       capture_output=True, text=True, env=_env(), timeout=HANG_GUARD_S, check=False)
    assert r.returncode == 2
    assert len(r.stderr.strip().splitlines()) == 1, r.stderr
    assert "Warning" not in r.stderr
    assert not (tmp_path / "o").exists()


# --- large structures: checks that scale, same answers as the dense path -------------------------------
def _chain(n, rng, *, rigid=False, sparse=True):
    k = rng.uniform(1e4, 1e5, n)
    K = np.diag(k + np.r_[k[1:], 0.0]) - np.diag(k[1:], 1) - np.diag(k[1:], -1)
    if rigid:  # free-free chain: one rigid-body mode
        K[0, 0] -= k[0]
    m = rng.uniform(0.1, 1.0, n)
    M = np.diag(m)
    if not sparse:
        Q = np.linalg.qr(rng.standard_normal((n, n)))[0]
        M = Q @ np.diag(m) @ Q.T
        M = 0.5 * (M + M.T)
        K = Q @ K @ Q.T
        K = 0.5 * (K + K.T)
    return M, K


@pytest.mark.parametrize("sparse", [True, False], ids=["sparse", "dense"])
@pytest.mark.parametrize("rigid", [False, True], ids=["held", "rigid"])
def test_large_path_agrees_with_the_dense_path(sparse, rigid, monkeypatch):
    from jointdyn.systems import definiteness_failure

    rng = np.random.default_rng(7)
    M, K = _chain(60, rng, rigid=rigid, sparse=sparse)
    dense = jd.System(M, None, K).w0
    # shared by systems, files and harmonic balance (config): the large-structure path at this size
    monkeypatch.setattr(config, "SYSTEM_DENSE_CHECK_MAX_DOF", 10)
    large = jd.System(M, None, K).w0
    assert large == pytest.approx(dense, rel=1e-8)
    assert definiteness_failure(M, semi=False) is None and definiteness_failure(K, semi=True) is None
    lam = np.linalg.eigvalsh(K)
    bad = K - (lam[0] + 1e-3 * lam[-1]) * np.eye(60)  # smallest eigenvalue -1e-3 of the largest
    got = definiteness_failure(bad, semi=True)
    assert got == pytest.approx(np.linalg.eigvalsh(bad)[0], rel=1e-6)
    if not rigid:
        assert definiteness_failure(K, semi=False) is None


@pytest.mark.parametrize("name", ["M", "K", "C"])
def test_large_file_refusals_name_the_matrix(name, monkeypatch, tmp_path):
    rng = np.random.default_rng(3)
    M, K = _chain(30, rng)
    mats = {"M": M, "K": K, "C": 0.01 * K}
    mats[name] = mats[name] - 2.0 * np.max(np.abs(mats[name])) * np.eye(30)
    np.savez(tmp_path / "m.npz", **mats)
    toml = _toml(tmp_path, structure='file = "m.npz"', normal="{ n0 = 100.0 }")
    # shared by systems, files and harmonic balance (config): the large-structure path at this size
    monkeypatch.setattr(config, "SYSTEM_DENSE_CHECK_MAX_DOF", 10)
    with pytest.raises(ValueError) as exc:
        read_system(toml)
    small = float(np.linalg.eigvalsh(mats[name])[0])
    msg = str(exc.value)
    assert f"structure.{name} must be positive" in msg and f"{small:.6g}"[:5] in msg


def test_asymmetry_matches_the_full_difference():
    from jointdyn.systems import asymmetry

    rng = np.random.default_rng(5)
    for n in (1, 3, 255, 256, 257, 600):
        A = rng.standard_normal((n, n))
        A = A + A.T
        if n > 1:
            A[n - 1, n // 2] += 0.5
        d = np.abs(A - A.T)
        i, j = np.unravel_index(int(np.argmax(d)), A.shape)
        assert asymmetry(A) == (float(d[i, j]), i, j)


# --- gamma grids of tiny or huge values ---------------------------------------------------------------
def test_gamma_grid_keeps_tiny_and_huge_values():
    """The grid's 12-decimal cleaning is kept where it cleans float noise and not applied where it would
    change a value (1e-300 rounded to 0 crashed the derived checks with a ZeroDivisionError)."""
    from jointdyn.commands.frc import parse_gamma

    np.testing.assert_array_equal(parse_gamma("0.6:1.8:0.01"), np.round(0.6 + 0.01 * np.arange(121), 12))
    tiny = parse_gamma("1e-300:1e-299:1e-300")
    assert tiny[0] == 1e-300 and np.all(tiny > 0) and np.all(np.diff(tiny) > 0)
    assert parse_gamma("1e300:1e300:1").tolist() == [1e300]


def test_tiny_gamma_passes_validation(no_compute, capsys):
    with pytest.raises(_Reached):
        main(["frc", "--method", "hb", "--gamma", "1e-300:1e-299:1e-300"])


@pytest.mark.parametrize("sparse", [True, False], ids=["sparse", "dense"])
def test_rigid_mode_dof_large_path_agrees(sparse, monkeypatch):
    from jointdyn.systems import rigid_mode_dof

    rng = np.random.default_rng(11)
    _, K = _chain(40, rng, sparse=sparse)
    Kr = K.copy()
    Kr[:, 7] = 0.0
    Kr[7, :] = 0.0  # DOF 7 held by nothing
    expected = (rigid_mode_dof(K), rigid_mode_dof(Kr))
    assert expected[0] is None and (not sparse or expected[1] == 7)
    # shared by systems, files and harmonic balance (config): the large-structure path at this size
    monkeypatch.setattr(config, "SYSTEM_DENSE_CHECK_MAX_DOF", 10)
    assert (rigid_mode_dof(K), rigid_mode_dof(Kr)) == expected


@pytest.mark.parametrize("fmt", ["csr", "csc", "coo", "bsr", "dia"])
def test_every_save_npz_format_reads_back(fmt, tmp_path):
    """A scipy.sparse.save_npz file of any format: its members bounded from their headers, then the matrix."""
    import scipy.sparse as sp

    A = np.array([[2.0, 1.0, 0.0, 0.0], [1.0, 2.0, 0.0, 0.0], [0.0, 0.0, 3.0, 1.0], [0.0, 0.0, 1.0, 3.0]])
    sp.save_npz(tmp_path / "a.npz", getattr(sp, f"{fmt}_matrix")(A))
    toml = _toml(tmp_path, structure='M = "a.npz"\nK = "a.npz"', tangential="{ dof = 0 }",
                 normal="{ n0 = 100.0 }")
    s = read_system(toml)
    np.testing.assert_array_equal(s.M, A)
    np.testing.assert_array_equal(s.K, A)
