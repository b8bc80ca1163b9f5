"""Bad interface and measurement files (issue 33): one CSV reader, one set of size bounds, one line each.

Each class of bad input is given the same way to every command that reads
it: the pairs file of an ``[[interface]]``, ``fit --input`` and ``fit
--backbone``. The CLI must print exactly one line on stderr, naming the
option or key (and the line of the file), exit 2 and write no file.
"""

import json
import os

import numpy as np
import pytest

from jointdyn import config
from jointdyn.cli import main

PAIRS_HEADER = "a_t1,a_t2,a_n,b_t1,b_t2,b_n"
SYSTEM = """
[structure]
M = [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]]
K = [[1.0e3, 0.0, 0.0], [0.0, 2.0e3, 0.0], [0.0, 0.0, 3.0e5]]
zeta = 0.02

[[force]]
dof = 0
amplitude = 0.1

[[interface]]
kt = {kt}
kn = {kn}
mu = 0.5
preload = 0.5
pairs = {pairs}
"""


def run_cli(argv):
    try:
        return main(argv)
    except SystemExit as exc:
        return exc.code


def one_line(capsys, rc, *words):
    err = capsys.readouterr().err.strip()
    assert rc == 2, err
    assert len(err.splitlines()) == 1, err
    for w in words:
        assert w in err, err
    return err


def _system(tmp_path, pairs='"pairs.csv"', kt="1.5e3", kn="1.5e3"):
    f = tmp_path / "s.toml"
    f.write_text(SYSTEM.format(pairs=pairs, kt=kt, kn=kn))
    return f


def _loops(n=400):
    t = np.linspace(0.0, 2.0, n)
    x = 1e-5 * np.sin(2 * np.pi * t)
    T = np.clip(1e6 * x, -5.0, 5.0)
    return t, x, np.full(n, 100.0), T


def _loops_text(sep=",", n=400):
    rows = [sep.join(f"{v:.10g}" for v in r) for r in zip(*_loops(n))]
    return rows


def _backbone_rows(n=8):
    A = np.logspace(-7, -4, n)
    return [f"{a:.6g},{100 - 10 * a / (a + 1e-5):.6g},{0.001 + 0.05 * a / (a + 1e-5):.6g}" for a in A]


# --- the same layouts accepted by every reader ----------------------------------------

LAYOUTS = {
    "bom": lambda h, rows, units: "\ufeff" + "\n".join([h, *rows]) + "\n",
    "semicolon": lambda h, rows, units: "\n".join(r.replace(",", ";") for r in [h, *rows]) + "\n",
    "unit row": lambda h, rows, units: "\n".join([h, units, *rows]) + "\n",
}


@pytest.mark.parametrize("layout", sorted(LAYOUTS))
def test_the_fit_reader_accepts_what_the_loop_reader_accepts(tmp_path, layout):
    from jointdyn.commands._fit_data import read_backbone, read_loops
    from jointdyn.drivers._csv import read_history_csv

    f = tmp_path / "loops.csv"
    f.write_text(LAYOUTS[layout]("t,x,N,T", _loops_text(), "s,m,N,N"), encoding="utf-8")
    d = read_loops(f)
    assert d["x"].size == 400 and np.allclose(d["T"], _loops()[3], atol=1e-9)
    t, x, N = read_history_csv(f)
    assert np.array_equal(t, d["t"]) and np.array_equal(x, d["x"])
    b = tmp_path / "bb.csv"
    b.write_text(LAYOUTS[layout]("amplitude_m,omega_rad_s,damping_ratio", _backbone_rows(), "m,rad/s,-"),
                 encoding="utf-8")
    assert read_backbone(b)["amplitude_m"].size == 8


@pytest.mark.parametrize("layout", sorted(LAYOUTS))
def test_the_pairs_reader_accepts_what_the_loop_reader_accepts(tmp_path, layout):
    from jointdyn.files import read_system

    (tmp_path / "pairs.csv").write_text(LAYOUTS[layout](PAIRS_HEADER, ["0,1,2,-1,-1,-1", "1,0,2,-1,-1,-1"],
                                                        "-,-,-,-,-,-"), encoding="utf-8")
    s = read_system(_system(tmp_path))
    assert s.interfaces[0].pairs.tolist() == [[0, 1, 2, -1, -1, -1], [1, 0, 2, -1, -1, -1]]


def test_a_unit_row_in_other_units_is_refused(tmp_path, capsys):
    f = tmp_path / "loops.csv"
    f.write_text("\n".join(["t,x,N,T", "s,mm,N,N", *_loops_text()]) + "\n")
    one_line(capsys, run_cli(["fit", "--input", str(f)]), "--input", "line 2", "unit 'mm'")


# --- tracebacks: huge integers and huge fields ----------------------------------------

HUGE_INT = "1" * 30
HUGE_FIELD = "1" * 200_000


@pytest.mark.parametrize("field,words", [
    (HUGE_INT, ("interface[0].pairs", "line 3", "b_n", "[-1, 2]")),
    (HUGE_FIELD, ("interface[0].pairs", "line 3", "200000 characters")),
    (f'"{HUGE_FIELD}"', ("interface[0].pairs", "line 3", "200000 characters")),
    ("1.5", ("interface[0].pairs", "line 3", "integer")),
])
def test_a_pairs_file_with_a_huge_or_bad_field(tmp_path, capsys, field, words):
    (tmp_path / "pairs.csv").write_text(f"{PAIRS_HEADER}\n0,1,2,-1,-1,-1\n1,0,2,-1,-1,{field}\n")
    out = tmp_path / "out"
    rc = run_cli(["frc", "--system", str(_system(tmp_path)), "--method", "hb", "--out", str(out)])
    one_line(capsys, rc, *words)
    assert not out.exists()


@pytest.mark.parametrize("option", ["--input", "--backbone"])
@pytest.mark.parametrize("field", [HUGE_INT + "e300", HUGE_FIELD, f'"{HUGE_FIELD}"'])
def test_a_fit_file_with_a_huge_field(tmp_path, capsys, option, field):
    if option == "--input":
        rows = _loops_text()
        rows[4] = ",".join([rows[4].split(",")[0], field, "100", "1"])
        text = "\n".join(["t,x,N,T", *rows]) + "\n"
    else:
        rows = _backbone_rows()
        rows[2] = ",".join([field, "100", "0.01"])
        text = "\n".join(["amplitude_m,omega_rad_s,damping_ratio", *rows]) + "\n"
    f = tmp_path / "data.csv"
    f.write_text(text)
    out = tmp_path / "out"
    rc = run_cli(["fit", option, str(f), "--mass", "1", "--out", str(out)] if option == "--backbone"
                 else ["fit", option, str(f), "--out", str(out)])
    one_line(capsys, rc, option, "line")
    assert not out.exists()


# --- non-regular files ----------------------------------------------------------------

@pytest.mark.skipif(not hasattr(os, "mkfifo"), reason="no FIFOs here")
@pytest.mark.parametrize("kind", ["fifo", "devzero"])
def test_a_fifo_or_device_is_not_a_regular_file(tmp_path, capsys, kind):
    p = tmp_path / "pairs.csv"
    if kind == "fifo":
        os.mkfifo(p)
    else:
        p.symlink_to("/dev/zero")
    rc = run_cli(["frc", "--system", str(_system(tmp_path)), "--method", "hb"])
    one_line(capsys, rc, "interface[0].pairs", "not a regular file")
    rc = run_cli(["fit", "--input", str(p)])
    one_line(capsys, rc, "--input", "not a regular file")


# --- size bounds, the same for every way of giving the same thing ---------------------

def test_inline_pairs_are_bounded_like_a_pairs_file(tmp_path, capsys, monkeypatch):
    # an input-size bound shared by every command (config), lowered to make the case small
    monkeypatch.setattr(config, "INTERFACE_MAX_PAIRS", 5)
    row = "[0, 1, 2, -1, -1, -1]"
    inline = _system(tmp_path, pairs="[" + ", ".join([row] * 6) + "]")
    rc = run_cli(["frc", "--system", str(inline), "--method", "hb"])
    one_line(capsys, rc, "interface[0].pairs", "at most 5 pairs", "INTERFACE_MAX_PAIRS")
    (tmp_path / "pairs.csv").write_text(PAIRS_HEADER + "\n" + "0,1,2,-1,-1,-1\n" * 6)
    rc = run_cli(["frc", "--system", str(_system(tmp_path)), "--method", "hb"])
    one_line(capsys, rc, "interface[0].pairs", "at most 5 data rows", "INTERFACE_MAX_PAIRS")
    from jointdyn.interfaces import Interface

    with pytest.raises(ValueError, match="INTERFACE_MAX_PAIRS"):
        Interface(kt=1.0, kn=1.0, mu=0.5, preload=1.0, pairs=[[0, 1, 2, -1, -1, -1]] * 6)


@pytest.mark.parametrize("option,setting", [("--backbone", "FIT_MAX_BACKBONE_POINTS"),
                                            ("--input", "FIT_MAX_LOOP_SAMPLES")])
def test_fit_data_are_bounded_before_fitting(tmp_path, capsys, monkeypatch, option, setting):
    from jointdyn.commands import _fit_data

    monkeypatch.setattr(_fit_data, "_BACKBONE_ROWS", _fit_data.RowBound(6, f"config.{setting}"))
    monkeypatch.setattr(_fit_data, "_LOOP_ROWS", _fit_data.RowBound(300, f"config.{setting}"))

    def refused(*a, **k):
        raise AssertionError("the fit ran")

    monkeypatch.setattr("jointdyn.identify.fit_backbone", refused)
    monkeypatch.setattr("jointdyn.identify.fit_loops", refused)
    f = tmp_path / "data.csv"
    if option == "--backbone":
        f.write_text("\n".join(["amplitude_m,omega_rad_s,damping_ratio", *_backbone_rows(8)]) + "\n")
        argv = ["fit", option, str(f), "--mass", "1"]
    else:
        f.write_text("\n".join(["t,x,N,T", *_loops_text()]) + "\n")
        argv = ["fit", option, str(f)]
    one_line(capsys, run_cli(argv), option, "data rows", setting)


def test_the_shipped_bounds_are_those_measured():
    assert config.INTERFACE_MAX_PAIRS == 5_000
    assert config.FIT_MAX_BACKBONE_POINTS == 1_000
    assert config.FIT_MAX_LOOP_SAMPLES == 1_000_000


# --- overflow computed as if valid ----------------------------------------------------

@pytest.mark.parametrize("params,rows,words", [
    (["--kt", "1e6", "--kn", "1e6", "--mu", "0.5", "--preload", "10"],
     ["0,0,0,0", "1,1e300,1e300,1e300", "2,0,0,-1e300"], ("--kt", "--input")),
    (["--kt", "1e300", "--kn", "1", "--mu", "1", "--preload", "1"],
     ["0,0,0,0", "1,1e10,0,0", "2,0,0,0"], ("--kt", "tangential force")),
    (["--kt", "1", "--kn", "1e300", "--mu", "1", "--preload", "1"],
     ["0,0,0,0", "1,0,0,1e10", "2,0,0,0"], ("--kn", "normal load")),
])
def test_a_pair_loop_that_would_overflow_is_refused(tmp_path, capsys, params, rows, words):
    f = tmp_path / "h.csv"
    f.write_text("\n".join(["t,u1,u2,g", *rows]) + "\n")
    out = tmp_path / "out"
    with np.errstate(all="raise"):  # no overflow computed on the way to the refusal
        rc = run_cli(["loop", "--model", "pair", *params, "--input", str(f), "--out", str(out), "--json"])
    one_line(capsys, rc, *words)
    assert not out.exists()


def test_a_pair_loop_of_large_but_finite_values_still_runs(tmp_path, capsys):
    f = tmp_path / "h.csv"
    f.write_text("t,u1,u2,g\n0,0,0,0\n1,1e-5,0,0\n2,0,0,0\n")
    rc = run_cli(["loop", "--model", "pair", "--kt", "1e300", "--kn", "1e300", "--mu", "0.5", "--preload", "1e300",
                  "--input", str(f), "--json"])
    cap = capsys.readouterr()
    assert rc == 0 and cap.err == ""
    assert json.loads(cap.out)["force_max_N"] == pytest.approx(1e295)


# --- library messages that named no key -----------------------------------------------

@pytest.mark.parametrize("key", ["kt", "kn"])
@pytest.mark.parametrize("method", ["time", "hb"])
def test_a_pair_stiffness_beyond_the_range_names_its_key(tmp_path, capsys, key, method):
    f = _system(tmp_path, pairs="[[0, 1, 2, -1, -1, -1]]", **{key: "1e308"})
    rc = run_cli(["frc", "--system", str(f), "--method", method, "--gamma", "0.9:1.1:0.1"])
    one_line(capsys, rc, f"interface[0].{key}", "at most")


@pytest.mark.parametrize("key,value,holder", [("kt", "1e302", "interface[0].kn"), ("kn", "1e-300", "interface[0].kn")])
def test_an_ill_conditioned_static_stiffness_is_not_called_singular(tmp_path, capsys, key, value, holder):
    text = SYSTEM.format(pairs="[[0, 1, 2, -1, -1, -1]]", kt="1.5e3", kn="1.5e3").replace(
        "[0.0, 0.0, 3.0e5]", "[0.0, 0.0, 0.0]").replace(f"{key} = 1.5e3", f"{key} = {value}")
    f = tmp_path / "s.toml"
    f.write_text(text)
    rc = run_cli(["frc", "--system", str(f), "--method", "hb", "--gamma", "0.9:1.1:0.1"])
    err = one_line(capsys, rc, "ill-conditioned, not singular", holder, "DOF 2")
    assert "held by nothing" not in err


@pytest.mark.parametrize("column,value,words", [
    ("x", "1e300", ("--input", "line 6", "x = 1e+300", "FIT_MAX_MAGNITUDE")),
    ("T", "-1e300", ("--input", "line 6", "T = -1e+300")),
    ("N", "1e300", ("--input", "line 6", "N = 1e+300")),
])
def test_loop_values_beyond_the_fit_range_name_the_line(tmp_path, capsys, column, value, words):
    rows = _loops_text()
    fields = rows[4].split(",")
    fields["txNT".index(column)] = value
    rows[4] = ",".join(fields)
    f = tmp_path / "loops.csv"
    f.write_text("\n".join(["t,x,N,T", *rows]) + "\n")
    one_line(capsys, run_cli(["fit", "--input", str(f)]), *words)


# --- data checks name the option's file, column and row -------------------------------

@pytest.mark.parametrize("column,fill,words", [
    ("x", "0.001", ("--input", "column x", "every row", "lines 2 to 401")),
    ("N", "-1", ("--input", "column N", "<= 0 on every row")),
    ("N", "0", ("--input", "column N", "<= 0 on every row")),
    ("T", "0", ("--input", "column T", "0 on every row")),
])
def test_loop_data_checks_name_the_column(tmp_path, capsys, column, fill, words):
    t, x, N, T = _loops()
    cols = {"t": t, "x": x, "N": N, "T": T}
    cols[column] = np.full(t.size, float(fill))
    f = tmp_path / "loops.csv"
    np.savetxt(f, np.c_[cols["t"], cols["x"], cols["N"], cols["T"]], delimiter=",", header="t,x,N,T",
               comments="")
    one_line(capsys, run_cli(["fit", "--input", str(f)]), *words)


@pytest.mark.parametrize("column,value,words", [
    (2, "-0.01", ("--backbone", "line 4", "column damping_ratio", ">= 0")),
    (0, "-1e-5", ("--backbone", "line 4", "column amplitude_m", "> 0")),
    (1, "0", ("--backbone", "line 4", "column omega_rad_s", "> 0")),
    (0, "1e300", ("--backbone", "line 4", "column amplitude_m", "FIT_MAX_MAGNITUDE")),
])
def test_backbone_data_checks_name_the_column_and_row(tmp_path, capsys, column, value, words):
    rows = _backbone_rows()
    fields = rows[2].split(",")
    fields[column] = value
    rows[2] = ",".join(fields)
    f = tmp_path / "bb.csv"
    f.write_text("\n".join(["amplitude_m,omega_rad_s,damping_ratio", *rows]) + "\n")
    out = tmp_path / "out"
    one_line(capsys, run_cli(["fit", "--backbone", str(f), "--mass", "1", "--out", str(out)]), *words)
    assert not out.exists()


def test_loops_in_mm_fitted_as_metres_are_said_implausible(tmp_path, capsys):
    t, x, N, T = _loops()
    f = tmp_path / "loops.csv"
    np.savetxt(f, np.c_[t, 1e3 * x, N, T], delimiter=",", header="t,x,N,T", comments="")
    rc = run_cli(["fit", "--input", str(f), "--model", "jenkins", "--json"])
    cap = capsys.readouterr()
    report = json.loads(cap.out)
    assert rc in (0, 3)
    assert any("x in m" in w for w in report["warnings"]) and "if x is in mm" in cap.err
    np.savetxt(f, np.c_[t, x, N, T], delimiter=",", header="t,x,N,T", comments="")
    run_cli(["fit", "--input", str(f), "--model", "jenkins", "--json"])
    assert json.loads(capsys.readouterr().out)["warnings"] == []


def test_a_huge_integer_in_inline_pairs_names_its_entry(tmp_path, capsys):
    f = _system(tmp_path, pairs=f"[[0, 1, 2, -1, -1, {HUGE_INT}]]")
    rc = run_cli(["frc", "--system", str(f), "--method", "hb"])
    one_line(capsys, rc, "interface[0].pairs[0][5]", "must be in [0, 2]")


def test_hb_names_the_open_pair_that_alone_holds_a_dof(tmp_path, capsys):
    text = SYSTEM.format(pairs="[[0, 1, 2, -1, -1, -1]]", kt="1.5e3", kn="1.5e3").replace(
        "[0.0, 0.0, 3.0e5]", "[0.0, 0.0, 0.0]").replace("preload = 0.5", "preload = 0.0")
    f = tmp_path / "s.toml"
    f.write_text(text)
    rc = run_cli(["frc", "--system", str(f), "--method", "hb", "--gamma", "0.9:1.1:0.1"])
    err = one_line(capsys, rc, "DOF 2", "interface[0].kn", "open at rest", "--method time")
    assert "held by nothing" not in err


@pytest.mark.parametrize("argv,name", [
    (["loop", "--input"], "HISTORY_ROWS"),
    (["loop", "--model", "pair", "--kt", "1e3", "--kn", "1e3", "--mu", "0.5", "--preload", "1", "--input"],
     "HISTORY_ROWS"),
])
def test_loop_histories_are_bounded_before_parsing(tmp_path, capsys, monkeypatch, argv, name):
    from jointdyn.drivers import _csv

    monkeypatch.setattr(_csv, name, _csv.RowBound(3, "config.QS_MAX_SAMPLES"))
    f = tmp_path / "h.csv"
    cols = "t,u1,u2,g" if "pair" in argv else "t,x,N"
    row = "0,0,0,0" if "pair" in argv else "0,0,1"
    f.write_text(cols + "\n" + "\n".join(row.replace("0", str(i), 1) for i in range(5)) + "\n")
    one_line(capsys, run_cli([*argv, str(f)]), "--input", "at most 3 data rows", "QS_MAX_SAMPLES")


def test_epmc_calls_a_tiny_normal_stiffness_ill_conditioned(tmp_path, capsys):
    text = SYSTEM.format(pairs="[[0, 1, 2, -1, -1, -1]]", kt="1.5e3", kn="1e-300").replace(
        "[0.0, 0.0, 3.0e5]", "[0.0, 0.0, 0.0]")
    f = tmp_path / "s.toml"
    f.write_text(text)
    err = one_line(capsys, run_cli(["modes", "--system", str(f)]), "ill-conditioned", "1e-300 (rad/s)^2")
    assert "must be positive definite" not in err


def test_the_library_fits_keep_the_bounds_of_the_cli(monkeypatch):
    import jointdyn as jd

    # input-size bounds shared by the fit command and the fits (config), lowered to make the case small
    monkeypatch.setattr(config, "FIT_MAX_BACKBONE_POINTS", 5)
    monkeypatch.setattr(config, "FIT_MAX_LOOP_SAMPLES", 300)
    A = np.logspace(-7, -4, 8)
    with pytest.raises(ValueError, match="FIT_MAX_BACKBONE_POINTS"):
        jd.fit_backbone(A, np.full(8, 100.0), np.full(8, 0.01), mass=1.0)
    t, x, N, T = _loops()
    with pytest.raises(ValueError, match="FIT_MAX_LOOP_SAMPLES"):
        jd.fit_loops(x, N, T, t=t)


@pytest.mark.skipif(not hasattr(os, "mkfifo"), reason="no FIFOs here")
def test_a_fifo_as_matrix_file_is_not_a_regular_file(tmp_path, capsys):
    os.mkfifo(tmp_path / "k.npy")
    text = SYSTEM.format(pairs="[[0, 1, 2, -1, -1, -1]]", kt="1.5e3", kn="1.5e3").replace(
        "K = [[1.0e3, 0.0, 0.0], [0.0, 2.0e3, 0.0], [0.0, 0.0, 3.0e5]]", 'K = "k.npy"')
    f = tmp_path / "s.toml"
    f.write_text(text)
    one_line(capsys, run_cli(["frc", "--system", str(f), "--method", "hb"]), "structure.K", "not a regular file")
