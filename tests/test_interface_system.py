"""Interfaces in a System and in system files ([[interface]] tables): parsed, validated with one-line
errors naming the file and the key, and refused by the solvers that do not march them yet."""

from __future__ import annotations

import numpy as np
import pytest

import jointdyn as jd
from jointdyn.cli import main
from jointdyn.interfaces import Interface

BASE = """\
[structure]
M = [[1.0, 0.0, 0.0, 0.0], [0.0, 1.0, 0.0, 0.0], [0.0, 0.0, 1.0, 0.0], [0.0, 0.0, 0.0, 2.0]]
K = [[1e3, 0.0, 0.0, 0.0], [0.0, 1e3, 0.0, 0.0], [0.0, 0.0, 0.0, 0.0], [0.0, 0.0, 0.0, 4e3]]

[[force]]
dof = 0
amplitude = 0.1

[[contact]]
law = "jenkins"
kt = 1e3
mu = 0.3
tangential = { dof = 3 }
normal = { n0 = 1.0 }

[[interface]]
kt = 1.5e3          # tangential stiffness per pair, N/m: a number, or a list with one value per pair
kn = [1.5e3, 3e3]   # normal stiffness per pair, N/m (number or list)
mu = 0.5            # (number or list)
preload = 0.5       # normal load of each pair at rest, N (number or list)
pairs = [[0, 1, 2, -1, -1, -1], [3, -1, 2, 0, -1, -1]]
"""


def _write(tmp_path, text, name="sys.toml"):
    p = tmp_path / name
    p.write_text(text)
    return p


def test_interfaces_are_read(tmp_path):
    s = jd.read_system(_write(tmp_path, BASE))
    assert len(s.interfaces) == 1
    it = s.interfaces[0]
    np.testing.assert_array_equal(it.pairs, [[0, 1, 2, -1, -1, -1], [3, -1, 2, 0, -1, -1]])
    np.testing.assert_array_equal(it.params, [[1.5e3, 1.5e3, 0.5, 0.5], [1.5e3, 3e3, 0.5, 0.5]])
    # both pairs are closed at rest: their normal springs (on DOF 2 against ground) are in K_reference
    assert s.K_reference[2, 2] == 4.5e3
    assert s.w0 == pytest.approx(np.sqrt(1e3))


def test_pairs_from_a_csv_file_relative_to_the_system_file(tmp_path):
    (tmp_path / "model").mkdir()
    (tmp_path / "model" / "pairs.csv").write_text(
        "# node pairs of the patch\nb_n,a_t1,a_t2,a_n,b_t1,b_t2\n-1,0,1,2,-1,-1\n-1, 3,-1,2,0,-1\n")
    text = BASE.replace("pairs = [[0, 1, 2, -1, -1, -1], [3, -1, 2, 0, -1, -1]]", 'pairs = "model/pairs.csv"')
    s = jd.read_system(_write(tmp_path, text))
    np.testing.assert_array_equal(s.interfaces[0].pairs, [[0, 1, 2, -1, -1, -1], [3, -1, 2, 0, -1, -1]])


def _sub(old, new):
    def f(text):
        assert old in text
        return text.replace(old, new)
    return f


BAD = [
    (_sub("mu = 0.5            #", "mu = -0.5           #"), "interface[0].mu must be >= 0"),
    (_sub("kn = [1.5e3, 3e3]", "kn = [1.5e3, 3e3, 1.0]"), "interface[0].kn must be a number or a list of 2"),
    (_sub("kn = [1.5e3, 3e3]", 'kn = "stiff"'), "interface[0].kn must be a number"),
    (_sub("kn = [1.5e3, 3e3]", "kn = [1.5e3, -3e3]"), "interface[0]: kn[1] must be > 0"),
    (_sub("preload = 0.5       #", "#"), "interface[0].preload is missing"),
    (_sub("preload = 0.5       #", "preload = 0.5\nbolt = 1 #"), "interface[0].bolt is not a known key"),
    (_sub("[3, -1, 2, 0, -1, -1]]", "[3, -1, 2, 0, -1]]"), "interface[0].pairs[1] must be 6 integer DOF indices"),
    (_sub("[3, -1, 2, 0, -1, -1]]", "[3, -1, 2, 0, -1, 1.5]]"), "interface[0].pairs[1] must be 6 integer"),
    (_sub("[3, -1, 2, 0, -1, -1]]", "[3, -1, 2, 7, -1, -1]]"), "pairs[1, 3] (b_t1) must be in [-1, 3]"),
    (_sub("[3, -1, 2, 0, -1, -1]]", "[3, -1, 2, 3, -1, -1]]"), "pairs[1] names a DOF twice"),
    (_sub("[3, -1, 2, 0, -1, -1]]", "[3, -1, 2, 0, -2, -1]]"), "pairs[1, 4] (b_t2) must be an integer >= -1"),
    (_sub('pairs = [[0, 1, 2, -1, -1, -1], [3, -1, 2, 0, -1, -1]]', 'pairs = 3'),
     "interface[0].pairs must be a list of rows"),
    (_sub('pairs = [[0, 1, 2, -1, -1, -1], [3, -1, 2, 0, -1, -1]]', 'pairs = "absent.csv"'),
     "interface[0].pairs must be an existing file"),
    (lambda text: "interface = 3\n" + text[:text.index("[[interface]]")], "interface must be an array of tables"),
]


@pytest.mark.parametrize("mutate, words", BAD)
def test_bad_interfaces_name_the_file_and_the_key(mutate, words, tmp_path):
    p = _write(tmp_path, mutate(BASE))
    with pytest.raises(ValueError) as exc:
        jd.read_system(p)
    msg = str(exc.value)
    assert "\n" not in msg and str(p) in msg and words in msg, msg


@pytest.mark.parametrize("csv, words", [
    ("a_t1,a_t2,a_n,b_t1,b_t2\n0,1,2,-1,-1\n", "missing column b_n"),
    ("a_t1,a_t2,a_n,b_t1,b_t2,b_n\n0,1,2,-1,-1\n", "line 2: expected 6 fields"),
    ("a_t1,a_t2,a_n,b_t1,b_t2,b_n\n0,1,x,-1,-1,-1\n", "line 2: a_n = 'x' is not a number"),
    ("a_t1,a_t2,a_n,b_t1,b_t2,b_n\n", "must have at least 1 data row,"),
])
def test_bad_pair_csv_files(csv, words, tmp_path):
    (tmp_path / "pairs.csv").write_text(csv)
    text = BASE.replace("pairs = [[0, 1, 2, -1, -1, -1], [3, -1, 2, 0, -1, -1]]", 'pairs = "pairs.csv"')
    text = text.replace("kn = [1.5e3, 3e3]", "kn = 1.5e3")
    with pytest.raises(ValueError, match="interface\\[0\\].pairs") as exc:
        jd.read_system(_write(tmp_path, text))
    assert words in str(exc.value) and "\n" not in str(exc.value)


def test_system_validates_its_interfaces():
    it = Interface(kt=1.0, kn=1.0, mu=0.1, preload=1.0, pairs=[[0, 1, 5, -1, -1, -1]])
    with pytest.raises(ValueError, match=r"interface 0 pairs\[0, 2\] \(a_n\) must be in \[-1, 2\]"):
        jd.System(M=np.eye(3), C=None, K=np.eye(3), interfaces=(it,))
    with pytest.raises(ValueError, match="interfaces must be Interface instances"):
        jd.System(M=np.eye(3), C=None, K=np.eye(3), interfaces=("pair",))


def test_solvers_refuse_interfaces_they_do_not_march(tmp_path, capsys):
    s = jd.read_system(_write(tmp_path, BASE))
    from jointdyn.modes import qsma

    # time integration, harmonic balance and EPMC march interfaces (test_interface_dynamics, test_hb_interfaces),
    # reduce_system keeps their DOFs (test_interface_modes_reduction); QSMA refuses them and names EPMC
    with pytest.raises(ValueError, match=r"^system: has interfaces \(2 node pairs\), which QSMA does not support.*"
                                         r"use EPMC"):
        qsma(s, [1e-4, 1e-3])
    p = str(tmp_path / "sys.toml")
    for argv in (["modes", "--method", "qsma", "--system", p, "--json"],):
        try:
            rc = main(argv)
        except SystemExit as exc:
            rc = exc.code
        err = capsys.readouterr().err
        assert rc == 2 and "interfaces" in err and len(err.strip().splitlines()) == 1, err
