"""System files (jointdyn.files): the TOML description of issue 10 as
written, every kind of normal load and selection, matrices from .npz, .mat,
.mtx and .npy files (dense and sparse, paths relative to the system file),
modal damping, the reference-frequency rule, and bad files: each refused
with one line naming the file and the key.
"""

from __future__ import annotations

import math
import os
import re
from pathlib import Path

import numpy as np
import pytest
import scipy.io
import scipy.sparse as sp

import jointdyn as jd
from jointdyn.files import read_matrices, read_system_file

ROOT = Path(__file__).resolve().parents[1]

#: the minimal schema of issue 10, verbatim
ISSUE_EXAMPLE = """\
[structure]              # or: file = "model.npz" holding M, K (and C)
M = [[10.0, 0.0], [0.0, 1.0]]
K = [[3.9e5, 0.0], [0.0, 0.0]]
C = [[0.0, 0.0], [0.0, 55.0]]          # optional; or zeta = [...] per mode

[[force]]                # F = amplitude * sin(w t + phase)
dof = 0
amplitude = 25.0         # N
phase_deg = 0.0

[[force]]
dof = 1
amplitude = 50.0
phase_deg = 90.0

[[contact]]
law = "discrete"         # any registered law name, e.g. the CLI --model names
kt = 3.0e5               # law parameters by name
mu = 0.5
n = 200
tangential = { dof = 0 }                            # dof2 omitted: against ground
normal = { dof = 1, kn = 3.0e5, preload = 100.0 }  # normal load from the structure
# or a prescribed load: normal = { n0 = 100.0, n1 = 50.0, phase_deg = 0.0 }

[output]
dof = 0                  # DOF whose amplitude is reported (default: first tangential DOF)
"""

#: a valid two-DOF file with a prescribed load; the error cases mutate it
BASE = """\
[structure]
M = [[2.0, 0.0], [0.0, 1.0]]
K = [[3.0e5, -1.0e5], [-1.0e5, 1.0e5]]

[[force]]
dof = 1
amplitude = 20.0

[[contact]]
law = "iwan"
kt = 2.0e5
mu = 0.3
tangential = { dof = 0 }
normal = { n0 = 100.0, n1 = 40.0, phase_deg = 30.0 }

[output]
dof = 1
"""


def _write(tmp_path, text, name="sys.toml") -> Path:
    p = tmp_path / name
    p.write_text(text)
    return p


def test_issue_example_as_written(tmp_path):
    s = jd.read_system(_write(tmp_path, ISSUE_EXAMPLE))
    # w0: lowest natural frequency of (M, K + kn on the normal DOF), tangential contact free
    assert s.w0 == pytest.approx(math.sqrt(3.9e5 / 10.0), rel=1e-14)
    assert round(s.w0, 1) == 197.5
    assert s.ndof == 2 and s.response_dof == 0
    np.testing.assert_array_equal(s.force, [25.0, 50.0])
    np.testing.assert_array_equal(s.force_phase_deg, [0.0, 90.0])
    np.testing.assert_array_equal(s.C, [[0.0, 0.0], [0.0, 55.0]])
    (c,) = s.contacts
    assert isinstance(c.law, jd.DiscreteIwan) and c.law.n == 200
    assert (c.law.kt, c.law.mu, c.law.n_ref, c.law.fy) == (3.0e5, 0.5, 100.0, 50.0)  # n_ref = the preload
    assert (c.dof, c.dof2) == (0, -1)
    assert c.normal == jd.NormalSpring(kn=3.0e5, preload=100.0, dof=1)


def test_issue_example_prescribed_alternative(tmp_path):
    text = ISSUE_EXAMPLE.replace("normal = { dof = 1, kn = 3.0e5, preload = 100.0 }",
                                 "normal = { n0 = 100.0, n1 = 50.0, phase_deg = 0.0 }")
    s = jd.read_system(_write(tmp_path, text))
    assert s.contacts[0].normal == jd.HarmonicLoad(100.0, 50.0, 0.0)
    assert s.contacts[0].law.n_ref == 100.0
    # no spring: the second DOF is free (a rigid-body mode, skipped); w0 is the first DOF's sqrt(k/m)
    assert s.w0 == pytest.approx(math.sqrt(3.9e5 / 10.0), rel=1e-14)


@pytest.mark.parametrize("normal, load, n_ref", [
    ("{ n0 = 80.0 }", jd.ConstantLoad(80.0), 80.0),
    ("{ n0 = 80.0, n1 = 20.0 }", jd.HarmonicLoad(80.0, 20.0), 80.0),
    ("{ n0 = 80.0, phase_deg = 45.0 }", jd.HarmonicLoad(80.0, 0.0, 45.0), 80.0),
    ("{ values = [60.0, 100.0, 140.0, 100.0] }", None, 100.0),
    ("{ kn = 1e6, preload = 90.0, dof = 1, dof2 = 0 }", jd.NormalSpring(1e6, 90.0, dof=1, dof2=0), 90.0),
    ("{ kn = 1e6, preload = 90.0, direction = [0.0, 1.0] }",
     jd.NormalSpring(1e6, 90.0, direction=np.array([0.0, 1.0])), 90.0),
])
def test_normal_loads(normal, load, n_ref, tmp_path):
    text = BASE.replace("normal = { n0 = 100.0, n1 = 40.0, phase_deg = 30.0 }", f"normal = {normal}")
    c = jd.read_system(_write(tmp_path, text)).contacts[0]
    if load is None:
        assert isinstance(c.normal, jd.SampledLoad)
        np.testing.assert_array_equal(c.normal.values, [60.0, 100.0, 140.0, 100.0])
    elif isinstance(load, jd.NormalSpring) and load.direction is not None:
        np.testing.assert_array_equal(c.normal.direction, load.direction)
        assert (c.normal.kn, c.normal.preload) == (load.kn, load.preload)
    else:
        assert c.normal == load
    assert c.law.n_ref == n_ref


def test_selections_n_ref_law_parameters_title_and_outputs(tmp_path):
    text = BASE.replace("tangential = { dof = 0 }", "tangential = { dof = 1, dof2 = 0 }\nn_ref = 120.0\n"
                        "capacity = 16")
    text = text.replace("[output]\ndof = 1", "[output]\ndof = 0\ndofs = [1, 0]")
    sf = read_system_file(_write(tmp_path, 'title = "two masses"\n' + text))
    c = sf.system.contacts[0]
    assert (c.dof, c.dof2, c.law.n_ref, c.law.capacity) == (1, 0, 120.0, 16)
    assert sf.title == "two masses" and sf.dofs == (1, 0) and sf.system.response_dof == 0
    text = BASE.replace("tangential = { dof = 0 }", "tangential = { direction = [1.0, -0.5] }")
    sf = read_system_file(_write(tmp_path, text, "b.toml"))
    np.testing.assert_array_equal(sf.system.contacts[0].direction, [1.0, -0.5])
    assert sf.title == "b" and sf.dofs == (1,)


def test_modal_damping_and_w0_override(tmp_path):
    """zeta per mode gives the modal ratios of (M, K + closed springs)."""
    text = BASE.replace("[[force]]", "zeta = [0.01, 0.03]\nw0 = 123.0\n\n[[force]]")
    s = jd.read_system(_write(tmp_path, text))
    assert s.w0 == 123.0
    from scipy.linalg import eigh

    lam, phi = eigh(s.K_reference, s.M)
    modal = phi.T @ s.C @ phi
    np.testing.assert_allclose(np.diag(modal), 2 * np.array([0.01, 0.03]) * np.sqrt(lam), rtol=1e-12)
    np.testing.assert_allclose(modal - np.diag(np.diag(modal)), 0.0, atol=1e-12 * np.abs(modal).max())
    scalar = jd.read_system(_write(tmp_path, BASE.replace("[[force]]", "zeta = 0.02\n\n[[force]]"), "c.toml"))
    np.testing.assert_allclose(scalar.C, jd.modal_damping(s.M, s.K_reference, 0.02), rtol=1e-14)
    assert isinstance(scalar.C, jd.ModalDamping)  # kept as an operator: no n x n C for a large structure


def test_zeta_basis_stuck_gives_the_ratios_of_the_stuck_modes(tmp_path):
    """zeta_basis = "stuck": the ratios are those of the modes of (M, K + every contact's kt and closed
    normal spring), the structure a modal test excites at low level; "slipping" is the default."""
    from scipy.linalg import eigh

    text = BASE.replace("[[force]]", 'zeta = [0.01, 0.03]\nzeta_basis = "stuck"\n\n[[force]]')
    s = jd.read_system(_write(tmp_path, text))
    Ks = s.K + s.contacts[0].law.kt * np.outer([1.0, 0.0], [1.0, 0.0])  # the contact on DOF 0 against ground
    np.testing.assert_allclose(jd.stuck_stiffness(s), Ks, rtol=1e-15)
    lam, phi = eigh(Ks, s.M)
    modal = phi.T @ (s.C @ phi)
    np.testing.assert_allclose(np.diag(modal), 2 * np.array([0.01, 0.03]) * np.sqrt(lam), rtol=1e-12)
    np.testing.assert_allclose(modal - np.diag(np.diag(modal)), 0.0, atol=1e-12 * np.abs(modal).max())
    slipping = jd.read_system(_write(tmp_path, text.replace('"stuck"', '"slipping"'), "d.toml"))
    default = jd.read_system(_write(tmp_path, text.replace('zeta_basis = "stuck"\n', ""), "e.toml"))
    np.testing.assert_array_equal(slipping.C.toarray(), default.C.toarray())
    assert np.max(np.abs(slipping.C.toarray() - s.C.toarray())) > 1e-3 * np.max(np.abs(s.C.toarray()))


def test_w0_skips_rigid_body_modes(tmp_path):
    """A DOF held by nothing but a tangential contact is a rigid-body mode
    of (M, K_reference): w0 is the lowest elastic frequency; a structure
    held by nothing at all reads once the file gives w0."""
    free = BASE.replace("K = [[3.0e5, -1.0e5], [-1.0e5, 1.0e5]]", "K = [[3.0e5, 0.0], [0.0, 0.0]]")
    s = jd.read_system(_write(tmp_path, free))
    assert s.w0 == pytest.approx(math.sqrt(3.0e5 / 2.0), rel=1e-14)
    coupled = BASE.replace("K = [[3.0e5, -1.0e5], [-1.0e5, 1.0e5]]", "K = [[1.0e5, -1.0e5], [-1.0e5, 1.0e5]]")
    # two masses on one spring: rigid mode plus sqrt(k (1/m1 + 1/m2))
    assert jd.read_system(_write(tmp_path, coupled, "c.toml")).w0 == pytest.approx(math.sqrt(1.0e5 * 1.5), rel=1e-12)
    bare = BASE.replace("K = [[3.0e5, -1.0e5], [-1.0e5, 1.0e5]]", "K = [[0.0, 0.0], [0.0, 0.0]]\nw0 = 250.0")
    assert jd.read_system(_write(tmp_path, bare, "b.toml")).w0 == 250.0


# --- matrix files -------------------------------------------------------------------------
M2 = np.array([[2.0, 0.0], [0.0, 1.0]])
K2 = np.array([[3.0e5, -1.0e5], [-1.0e5, 1.0e5]])
C2 = 1e-3 * K2
_STRUCT = re.compile(r"\[structure\]\n.*?\n\n", re.S)


def _with_structure(body: str) -> str:
    return _STRUCT.sub("[structure]\n" + body + "\n\n", BASE, count=1)


def _same(s) -> None:
    np.testing.assert_array_equal(s.M, M2)
    np.testing.assert_array_equal(s.K, K2)
    np.testing.assert_array_equal(s.C, C2)


def test_structure_file_npz_and_mat(tmp_path):
    np.savez(tmp_path / "model.npz", M=M2, K=K2, C=C2, extra=np.ones(3))
    _same(jd.read_system(_write(tmp_path, _with_structure('file = "model.npz"'))))
    scipy.io.savemat(tmp_path / "model.mat", {"M": sp.csc_matrix(M2), "K": K2, "C": sp.csc_matrix(C2)})
    _same(jd.read_system(_write(tmp_path, _with_structure('file = "model.mat"'))))
    got = read_matrices(tmp_path / "model.mat")
    assert set(got) == {"M", "K", "C"} and all(isinstance(v, np.ndarray) for v in got.values())
    np.savez(tmp_path / "noc.npz", M=M2, K=K2)
    assert set(read_matrices(tmp_path / "noc.npz")) == {"M", "K"}
    # C from the file is not given twice; an inline C beside a file without one is fine
    s = jd.read_system(_write(tmp_path, _with_structure('file = "noc.npz"\nC = [[0.0, 0.0], [0.0, 1.0]]')))
    np.testing.assert_array_equal(s.C, [[0.0, 0.0], [0.0, 1.0]])


def test_one_matrix_per_file_relative_to_the_system_file(tmp_path, monkeypatch):
    """M from a dense Matrix Market file, K from a sparse one, C from .npy;
    relative paths resolve against the system file's folder, not the cwd."""
    sub = tmp_path / "model"
    sub.mkdir()
    scipy.io.mmwrite(sub / "m.mtx", M2)
    scipy.io.mmwrite(sub / "k.mtx", sp.coo_matrix(K2))
    np.save(sub / "c.npy", C2)
    sp.save_npz(sub / "k_sparse.npz", sp.csr_matrix(K2))
    text = _with_structure('M = "model/m.mtx"\nK = "model/k.mtx"\nC = "model/c.npy"')
    path = _write(tmp_path, text)
    elsewhere = tmp_path / "elsewhere"
    elsewhere.mkdir()
    monkeypatch.chdir(elsewhere)
    _same(jd.read_system(path))
    _same(jd.read_system(_write(tmp_path, text.replace("model/k.mtx", "model/k_sparse.npz"), "b.toml")))
    # an absolute path works too
    _same(jd.read_system(_write(tmp_path, text.replace('"model/m.mtx"', f'"{sub / "m.mtx"}"'), "c.toml")))


def test_size_bound_before_conversion(tmp_path, monkeypatch):
    from jointdyn import config

    # an input-size bound kept with the others in config, lowered to make the case small
    monkeypatch.setattr(config, "FILES_MAX_DOF", 1)
    with pytest.raises(ValueError, match=r"structure\.M must have at most 1 rows and columns"):
        jd.read_system(_write(tmp_path, BASE))


# --- bad files --------------------------------------------------------------------------------
def _sub(old, new):
    def f(text):
        assert old in text, old
        return text.replace(old, new, 1)
    return f


def _add(section_line, extra):
    return _sub(section_line, section_line + "\n" + extra)


NORMAL = "normal = { n0 = 100.0, n1 = 40.0, phase_deg = 30.0 }"
BAD = [
    ("unknown top key", lambda t: "foo = 1\n" + t, "foo is not a known key"),
    ("unknown structure key", _add("[structure]", "Mass = 3.0"), "structure.Mass is not a known key"),
    ("unknown force key", _add("amplitude = 20.0", "phase = 3.0"), "force[0].phase is not a known key"),
    ("unknown contact key", _add("mu = 0.3", "kk = 1.0"), "contact[0].kk is not a known key"),
    ("law parameter of another law", _add("mu = 0.3", "n = 200"), "contact[0].n is not a known key"),
    ("unknown normal key", _sub(NORMAL, "normal = { n0 = 100.0, n2 = 3.0 }"), "contact[0].normal.n2 is not a known"),
    ("spring key in a prescribed load", _sub(NORMAL, "normal = { kn = 1e5, preload = 9.0, dof = 1, n1 = 2.0 }"),
     "contact[0].normal.n1 is not a known key"),
    ("unknown output key", _add("[output]", "dofz = 3"), "output.dofz is not a known key"),
    ("M not square", _sub("M = [[2.0, 0.0], [0.0, 1.0]]", "M = [[2.0, 0.0, 1.0], [0.0, 1.0, 0.0]]"),
     "structure.M must be square"),
    ("ragged M", _sub("M = [[2.0, 0.0], [0.0, 1.0]]", "M = [[2.0, 0.0], [0.0]]"), "structure.M rows must have"),
    ("K of another size", _sub("K = [[3.0e5, -1.0e5], [-1.0e5, 1.0e5]]", "K = [[1.0]]"),
     "structure.K must be 2 x 2 like M"),
    ("non-symmetric M", _sub("M = [[2.0, 0.0], [0.0, 1.0]]", "M = [[2.0, 0.5], [0.0, 1.0]]"),
     "structure.M must be symmetric"),
    ("indefinite M", _sub("M = [[2.0, 0.0], [0.0, 1.0]]", "M = [[2.0, 0.0], [0.0, -1.0]]"),
     "structure.M must be positive definite"),
    ("singular M", _sub("M = [[2.0, 0.0], [0.0, 1.0]]", "M = [[2.0, 0.0], [0.0, 0.0]]"),
     "structure.M must be positive definite"),
    ("indefinite K", _sub("K = [[3.0e5, -1.0e5], [-1.0e5, 1.0e5]]", "K = [[3.0e5, 0.0], [0.0, -1.0e5]]"),
     "structure.K must be positive semi-definite"),
    ("non-finite K", _sub("K = [[3.0e5, -1.0e5], [-1.0e5, 1.0e5]]", "K = [[inf, 0.0], [0.0, 1.0]]"),
     "structure.K[0][0] must be finite"),
    ("zeta and C", _add("[structure]", "C = [[0.0, 0.0], [0.0, 0.0]]\nzeta = 0.01"),
     "structure.zeta cannot be combined with a damping matrix C"),
    ("negative zeta", _add("[structure]", "zeta = -0.01"), "structure.zeta must be >= 0"),
    ("zeta_basis without zeta", _add("[structure]", 'zeta_basis = "stuck"'),
     "structure.zeta_basis needs structure.zeta"),
    ("unknown zeta_basis", _add("[structure]", 'zeta = 0.01\nzeta_basis = "free"'),
     "structure.zeta_basis must be one of 'slipping', 'stuck'"),
    ("zeta per mode of the wrong length", _add("[structure]", "zeta = [0.01]"), "structure.zeta must have 2 entries"),
    ("w0 zero", _add("[structure]", "w0 = 0.0"), "structure.w0 must be > 0"),
    ("no stiffness and no w0", _sub("K = [[3.0e5, -1.0e5], [-1.0e5, 1.0e5]]", "K = [[0.0, 0.0], [0.0, 0.0]]"),
     "structure.w0 is needed"),
    ("force DOF out of range", _sub("dof = 1\namplitude", "dof = 2\namplitude"), "force[0].dof must be in [0, 1]"),
    ("force DOF twice", _add("amplitude = 20.0", "\n[[force]]\ndof = 1\namplitude = 3.0"),
     "force[1].dof 1 is already forced by force[0]"),
    ("tangential DOF out of range", _sub("tangential = { dof = 0 }", "tangential = { dof = 7 }"),
     "contact[0].tangential.dof must be in [0, 1]"),
    ("tangential dof2 = dof", _sub("tangential = { dof = 0 }", "tangential = { dof = 0, dof2 = 0 }"),
     "contact[0].tangential.dof2 must differ from dof"),
    ("tangential dof and direction", _sub("tangential = { dof = 0 }", "tangential = { dof = 1, direction = [1, 0] }"),
     "contact[0].tangential.dof cannot be combined with direction"),
    ("direction of the wrong length", _sub("tangential = { dof = 0 }", "tangential = { direction = [1.0] }"),
     "contact[0].tangential.direction must have 2 entries"),
    ("normal DOF out of range", _sub(NORMAL, "normal = { kn = 1e5, preload = 90.0, dof = 2 }"),
     "contact[0].normal.dof must be in [0, 1]"),
    ("output DOF out of range", _sub("[output]\ndof = 1", "[output]\ndof = 3"), "output.dof must be in [0, 1]"),
    ("output DOFs repeated", _add("[output]", "dofs = [0, 0]"), "output.dofs must not repeat a DOF"),
    ("missing kt", _sub("kt = 2.0e5\n", ""), "contact[0].kt is missing"),
    ("missing mu", _sub("mu = 0.3\n", ""), "contact[0].mu is missing"),
    ("missing law", _sub('law = "iwan"\n', ""), "contact[0].law is missing"),
    ("missing tangential", _sub("tangential = { dof = 0 }\n", ""), "contact[0].tangential is missing"),
    ("missing normal", _sub(NORMAL + "\n", ""), "contact[0].normal is missing"),
    ("missing preload", _sub(NORMAL, "normal = { kn = 1e5, dof = 1 }"), "contact[0].normal.preload is missing"),
    ("missing normal DOF", _sub(NORMAL, "normal = { kn = 1e5, preload = 9.0 }"), "contact[0].normal.dof is missing"),
    ("empty normal", _sub(NORMAL, "normal = { }"), "contact[0].normal must give kn and preload"),
    ("missing M", _sub("M = [[2.0, 0.0], [0.0, 1.0]]\n", ""), "structure.M is missing"),
    ("missing structure", lambda t: t.split("[[force]]", 1)[1].join(["[[force]]", ""]), "structure is missing"),
    ("unknown law", _sub('law = "iwan"', 'law = "coulomb"'), "contact[0].law must be one of"),
    ("law parameter out of range", _sub('law = "iwan"', 'law = "discrete"\nn = 0'), "contact[0].n must be an integer"),
    ("kt negative", _sub("kt = 2.0e5", "kt = -2.0e5"), "contact[0].kt must be > 0"),
    ("kn negative", _sub(NORMAL, "normal = { kn = -1e5, preload = 9.0, dof = 1 }"), "contact[0].normal.kn must be > 0"),
    ("n0 zero", _sub(NORMAL, "normal = { n0 = 0.0 }"), "contact[0].normal.n0 must be > 0"),
    ("one sample", _sub(NORMAL, "normal = { values = [100.0] }"), "contact[0].normal.values must have at least 2"),
    ("amplitude a string", _sub("amplitude = 20.0", 'amplitude = "20"'), "force[0].amplitude must be a number"),
    ("dof a float", _sub("dof = 1\namplitude", "dof = 1.0\namplitude"), "force[0].dof must be an integer"),
    ("kt a boolean", _sub("kt = 2.0e5", "kt = true"), "contact[0].kt must be a number"),
    ("M a number", _sub("M = [[2.0, 0.0], [0.0, 1.0]]", "M = 2.0"), "structure.M must be a list of rows"),
    ("M entry a string", _sub("M = [[2.0, 0.0], [0.0, 1.0]]", 'M = [[2.0, "a"], [0.0, 1.0]]'),
     "structure.M[0][1] must be a number"),
    ("contact not a table array", lambda t: t.replace("[[contact]]", "[contact]"), "contact must be an array of tables"),
    ("structure not a table", lambda t: "structure = 3\n" + t.split("\n\n", 1)[1], "structure must be a table"),
    ("invalid TOML", lambda t: t + "\nthis is = = not toml\n", "not valid TOML"),
    ("matrix file missing", _sub("M = [[2.0, 0.0], [0.0, 1.0]]", 'M = "nowhere.mtx"'),
     "structure.M names"),
    ("matrix file of an unknown kind", _sub("M = [[2.0, 0.0], [0.0, 1.0]]", 'M = "m.txt"'),
     "a matrix file must end in .mtx, .npy, .npz or .mat"),
    ("structure file .mtx", _sub("M = [[2.0, 0.0], [0.0, 1.0]]\nK = [[3.0e5, -1.0e5], [-1.0e5, 1.0e5]]",
                                 'file = "m.mtx"'), "structure.file must be a .npz or .mat file"),
]


@pytest.mark.parametrize("mutate, words", [(m, w) for _, m, w in BAD], ids=[c for c, _, _ in BAD])
def test_bad_files_name_the_key_and_the_file(mutate, words, tmp_path):
    path = _write(tmp_path, mutate(BASE))
    with pytest.raises(ValueError) as exc:
        jd.read_system(path)
    msg = str(exc.value)
    assert "\n" not in msg
    assert msg.startswith(f"{path}: "), msg
    assert words in msg, msg


def test_bad_matrix_files(tmp_path):
    np.savez(tmp_path / "mk.npz", M=M2)
    with pytest.raises(ValueError, match=r"structure\.file .*holds no K \(found: M\)"):
        jd.read_system(_write(tmp_path, _with_structure('file = "mk.npz"')))
    np.savez(tmp_path / "both.npz", M=M2, K=K2)
    with pytest.raises(ValueError, match=r"structure\.M is given twice"):
        jd.read_system(_write(tmp_path, _with_structure('file = "both.npz"\nM = [[1.0, 0.0], [0.0, 1.0]]')))
    (tmp_path / "junk.npz").write_bytes(b"not a zip file")
    with pytest.raises(ValueError, match=r"structure\.file .*junk\.npz.* is not a \.npz archive"):
        jd.read_system(_write(tmp_path, _with_structure('file = "junk.npz"')))
    (tmp_path / "junk.npy").write_bytes(b"not numpy")
    with pytest.raises(ValueError, match=r"structure\.M .*junk\.npy.* is not a \.npy file"):
        jd.read_system(_write(tmp_path, BASE.replace("M = [[2.0, 0.0], [0.0, 1.0]]", 'M = "junk.npy"')))
    (tmp_path / "junk.mtx").write_text("not matrix market\n")
    with pytest.raises(ValueError, match=r"structure\.M .*junk\.mtx"):
        jd.read_system(_write(tmp_path, BASE.replace("M = [[2.0, 0.0], [0.0, 1.0]]", 'M = "junk.mtx"')))
    np.save(tmp_path / "cplx.npy", M2 * 1j)
    with pytest.raises(ValueError, match=r"structure\.M must be real"):
        jd.read_system(_write(tmp_path, BASE.replace("M = [[2.0, 0.0], [0.0, 1.0]]", 'M = "cplx.npy"')))
    np.save(tmp_path / "vec.npy", np.ones(2))
    with pytest.raises(ValueError, match=r"structure\.M must be a 2-D matrix"):
        jd.read_system(_write(tmp_path, BASE.replace("M = [[2.0, 0.0], [0.0, 1.0]]", 'M = "vec.npy"')))
    with pytest.raises(ValueError, match=r"M is missing \(variables found: K\)"):
        np.savez(tmp_path / "k.npz", K=K2)
        read_matrices(tmp_path / "k.npz")
    with pytest.raises(ValueError, match=r"path must be a \.npz or \.mat file"):
        read_matrices(tmp_path / "vec.npy")


def test_unreadable_or_missing_file(tmp_path):
    with pytest.raises(ValueError, match="cannot be read"):
        jd.read_system(tmp_path / "absent.toml")


def test_documented_examples_read(tmp_path):
    """Every complete example of docs/system-files.md (a TOML block with a
    [structure] table and no file references) reads as documented."""
    page = (ROOT / "docs" / "system-files.md").read_text()
    blocks = [b for b in re.findall(r"```toml\n(.*?)```", page, re.S)
              if "[structure]" in b and not re.search(r'"[^"]+\.(npz|mat|mtx|npy)"', b)]
    assert len(blocks) >= 3
    for i, block in enumerate(blocks):
        jd.read_system(_write(tmp_path, block, f"doc{i}.toml"))
    assert "197.5 rad/s" in page


def test_same_file_same_fingerprint(tmp_path):
    """Two reads of one file give equal Systems (a resume key finds them equal)."""
    from jointdyn.sweeps._family import fingerprint

    p = _write(tmp_path, ISSUE_EXAMPLE)
    assert fingerprint(jd.read_system(p)) == fingerprint(jd.read_system(p))


def test_cwd_does_not_matter_for_the_toml_path(tmp_path, monkeypatch):
    p = _write(tmp_path, BASE)
    monkeypatch.chdir(tmp_path)
    a = jd.read_system("sys.toml")
    monkeypatch.chdir(os.sep)
    b = jd.read_system(p)
    np.testing.assert_array_equal(a.K, b.K)
