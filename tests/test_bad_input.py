"""Bad input, family by family: every refusal is one line, exit status 2 (CLI)
or a ValueError naming the parameter (API), no traceback, no file written,
and it happens before any computing.

"Before any computing" is proved, not timed: the compute entry points of
the commands (the quasi-static march and history, the sweep, the harmonic
balance, the figure maker) and the time-domain solver are replaced by
functions that fail the test when reached. The CLI runs in-process
(``jointdyn.cli.main``); subprocesses only where the real process matters
(a closed stdout pipe, the exit status of ``python -m jointdyn``), each with
a generous timeout as a hang guard.

Families: file system, overflow of derived quantities, size limits,
malformed input files, contradictory options, wrong types in the API.
"""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

import jointdyn
from jointdyn import config
from jointdyn.cli import main
from jointdyn.commands import frc as frc_command
from jointdyn.drivers import harmonic_history, quasistatic, read_history_csv
from jointdyn.sweeps import _points, frc_sweep

SRC = str(Path(__file__).resolve().parents[1] / "src")
#: a hang guard for subprocesses, not a speed requirement
HANG_GUARD_S = 600


# --- helpers --------------------------------------------------------------------
class _Reached(AssertionError):
    """Computing (or reading a huge array) was reached: validation came too late."""


def _boom(*args, **kwargs):
    raise _Reached("computing was reached before the input was refused")


@pytest.fixture
def no_compute(monkeypatch, tmp_path):
    """Every compute entry point of the commands fails the test; the working
    directory is an empty temporary one (default outputs would land there)."""
    import jointdyn.drivers
    import jointdyn.figures
    import jointdyn.modes
    import jointdyn.sweeps
    from jointdyn.commands import frc as frc_cmd

    monkeypatch.setattr(jointdyn.drivers, "quasistatic", _boom)
    monkeypatch.setattr(jointdyn.drivers, "harmonic_history", _boom)
    monkeypatch.setattr(jointdyn.sweeps, "frc_sweep", _boom)
    monkeypatch.setattr(frc_cmd, "_run_hb", _boom)
    monkeypatch.setattr(jointdyn.figures, "make_figure", _boom)
    monkeypatch.setattr(jointdyn.modes, "epmc", _boom)
    monkeypatch.setattr(jointdyn.modes, "qsma", _boom)
    monkeypatch.setattr(_points, "_steady_state_fn", lambda: _boom)
    work = tmp_path / "work"
    work.mkdir()
    monkeypatch.chdir(work)
    return work


def _tree(root: Path) -> set:
    return {str(p.relative_to(root)) for p in root.rglob("*")}


def _cli(capsys, argv):
    try:
        rc = main([str(a) for a in argv])
    except SystemExit as exc:  # argparse usage errors
        rc = exc.code
    cap = capsys.readouterr()
    return rc, cap.out, cap.err


def refused(capsys, root: Path, argv, *words, rc_expected: int = 2) -> str:
    """Run the CLI; assert exit ``rc_expected``, one stderr line holding every
    word, no traceback, nothing on stdout, no file written under ``root``."""
    before = _tree(root)
    rc, out, err = _cli(capsys, argv)
    lines = err.strip().splitlines()
    assert rc == rc_expected, (rc, err)
    assert len(lines) == 1, err
    assert "Traceback" not in err
    for w in words:
        assert w in lines[0], (w, lines[0])
    assert out == ""
    assert _tree(root) == before
    return lines[0]


# --- file system ------------------------------------------------------------------
def _read_only_dir(tmp_path: Path) -> Path:
    """A directory without write permission, or a skip where that does not
    stop this process: root (uid 0) ignores the permission bits, so the
    check (os.access plus a probe file) rightly finds the directory
    writable. The uid-independent case is the /proc test below."""
    d = tmp_path / "ro"
    d.mkdir()
    d.chmod(0o555)
    try:
        probe = d / "probe"
        probe.write_text("")
    except OSError:
        return d
    probe.unlink()
    d.chmod(0o755)
    pytest.skip("this process can write into a mode-0555 directory (running as root)")


def _proc_dir() -> Path:
    """A directory in which no process can create a file, whatever its uid."""
    if not (os.path.isdir("/proc") and os.path.isdir("/proc/self")):
        pytest.skip("no /proc file system")
    return Path("/proc")


COMMANDS_WITH_OUT = [
    ["loop", "--steps-per-cycle", "40"],
    ["frc", "--gamma", "0.8:0.9:0.1", "--workers", "1"],
    ["figures", "--only", "fig2"],
]


@pytest.mark.parametrize("cmd", COMMANDS_WITH_OUT, ids=lambda c: c[0])
def test_out_is_an_existing_file(cmd, no_compute, capsys, tmp_path):
    f = no_compute / "file.csv"
    f.write_text("keep")
    refused(capsys, tmp_path, [*cmd, "--out", str(f)], "--out")
    assert f.read_text() == "keep"


@pytest.mark.parametrize("cmd", COMMANDS_WITH_OUT, ids=lambda c: c[0])
def test_out_below_an_existing_file(cmd, no_compute, capsys, tmp_path):
    f = no_compute / "file"
    f.write_text("keep")
    refused(capsys, tmp_path, [*cmd, "--out", str(f / "sub" / "dir")], "--out")


@pytest.mark.parametrize("cmd", COMMANDS_WITH_OUT, ids=lambda c: c[0])
def test_out_under_proc(cmd, no_compute, capsys, tmp_path):
    refused(capsys, tmp_path, [*cmd, "--out", str(_proc_dir() / "jointdyn-test" / "out")], "--out")


@pytest.mark.parametrize("cmd", COMMANDS_WITH_OUT, ids=lambda c: c[0])
def test_out_under_read_only_dir(cmd, no_compute, capsys, tmp_path):
    ro = _read_only_dir(tmp_path)
    try:
        refused(capsys, tmp_path, [*cmd, "--out", str(ro / "out")], "--out")
    finally:
        ro.chmod(0o755)


@pytest.mark.parametrize(
    "cmd, occupied",
    [
        (["loop", "--steps-per-cycle", "40"], "loop.csv"),
        (["loop", "--steps-per-cycle", "40"], "loop.png"),
        (["frc", "--gamma", "0.8:0.9:0.1", "--workers", "1"], "frc.nc"),
        (["frc", "--gamma", "0.8:0.9:0.1", "--workers", "1"], "frc.png"),
    ],
)
def test_out_holds_a_directory_where_a_file_goes(cmd, occupied, no_compute, capsys, tmp_path):
    (no_compute / "out" / occupied).mkdir(parents=True)
    refused(capsys, tmp_path, [*cmd, "--out", str(no_compute / "out")], "--out")


def test_frc_out_lines_is_a_file(no_compute, capsys, tmp_path):
    out = no_compute / "out"
    out.mkdir()
    (out / "lines").write_text("not a directory")
    refused(capsys, tmp_path, ["frc", "--gamma", "0.8:0.9:0.1", "--workers", "1", "--out", str(out)], "--out")


@pytest.mark.parametrize(
    "make",
    [
        pytest.param(lambda d: d / "missing.csv", id="missing"),
        pytest.param(lambda d: d, id="directory"),
        pytest.param(lambda d: Path("/proc/self/mem"), id="io-error"),
    ],
)
def test_input_unreadable(make, no_compute, capsys, tmp_path):
    path = make(no_compute)
    if str(path).startswith("/proc") and not os.path.exists(path):
        pytest.skip("no /proc/self/mem")
    refused(capsys, tmp_path, ["loop", "--input", str(path)], "--input")


def test_input_unreadable_permissions(no_compute, capsys, tmp_path):
    p = no_compute / "h.csv"
    p.write_text("t,x,N\n0,0,1\n1,1e-5,1\n")
    p.chmod(0)
    try:
        with open(p, "rb"):
            pytest.skip("this process reads mode-000 files (running as root); /proc/self/mem covers I/O errors")
    except PermissionError:
        refused(capsys, tmp_path, ["loop", "--input", str(p)], "--input")
    finally:
        p.chmod(0o644)


def test_api_frc_sweep_out_is_a_file(monkeypatch, tmp_path):
    monkeypatch.setattr(_points, "_steady_state_fn", lambda: _boom)
    f = tmp_path / "file.csv"
    f.write_text("keep")
    for out in (f, f / "below"):
        with pytest.raises(ValueError, match="^out "):
            frc_sweep([1.0], n_workers=1, progress=False, out=out)
    with pytest.raises(ValueError, match="^out "):
        frc_sweep([1.0], n_workers=1, progress=False, out=_proc_dir() / "jointdyn-test")
    assert f.read_text() == "keep" and _tree(tmp_path) == {"file.csv"}


@pytest.mark.parametrize("bad", [42, None.__class__, b"", ""], ids=["int", "type", "bytes", "empty"])
def test_api_path_types(bad):
    with pytest.raises(ValueError, match="^path must be a file-system path"):
        read_history_csv(bad)


# --- overflow of derived quantities -------------------------------------------------
OVERFLOW = [
    (["loop", "--mu", "1e308"], "fy = --mu x --n-ref"),
    (["loop", "--mu", "10", "--n-ref", "1e308"], "fy = --mu x --n-ref"),
    (["loop", "--mu", "1e-200", "--n-ref", "1e-200"], "underflow"),
    (["loop", "--frequency", "1e-308"], "--cycles / --frequency"),
    (["loop", "--kt", "1e308", "--amplitude", "10"], "--kt x --amplitude"),
    (["loop", "--mu", "1e-300", "--n-ref", "1e-10"], "--kt x --amplitude / fy"),
    (["loop", "--eta", "1e308", "--n-ref", "10"], "--eta x --n-ref"),
    (["loop", "--eta", "1e300", "--kn", "1e-300"], "--kn"),
    (["frc", "--mu", "1e308", "--n0", "10"], "fy = --mu x --n0"),
    (["frc", "--f1", "1e-320"], "beta = --mu x --n0 / --f1"),
    (["frc", "--beta", "1e-320"], "F1 = --mu x --n0 / --beta"),
    (["frc", "--k", "1e308", "--m", "1e-308"], "w0 = sqrt(--k / --m)"),
    (["frc", "--eta", "1e308", "--n0", "10"], "--eta x --n0"),
    (["frc", "--kt", "1e308", "--mu", "1e-10"], "--kt / fy"),
    (["frc", "--gamma", "0.6:1.8:1e-320"], "--gamma"),
]


@pytest.mark.parametrize("argv, word", OVERFLOW, ids=[" ".join(a) for a, _ in OVERFLOW])
def test_overflow_refused_before_computing(argv, word, no_compute, capsys, tmp_path):
    out = no_compute / "out"
    refused(capsys, tmp_path, [*argv, "--json", "--out", str(out)], word)


def test_loop_mu_overflow_writes_nothing_with_json(no_compute, capsys, tmp_path):
    """The reported case: files used to be written before the JSON failed."""
    refused(capsys, tmp_path, ["loop", "--mu", "1e308", "--json", "--out", "o"], "--mu")
    assert not (no_compute / "o").exists()


@pytest.mark.parametrize(
    "kw, word",
    [
        ({"frequency": 1e-308}, "frequency"),
        ({"eta": 1e308, "n0": 10.0}, "eta x n0"),
        ({"amplitude": 1e308, "x_offset": 1e308}, "x_offset"),
    ],
)
def test_api_harmonic_history_overflow(kw, word):
    args = {"amplitude": 1e-3, "frequency": 1.0, "n0": 100.0, **kw}
    with pytest.raises(ValueError, match=word):
        harmonic_history(args.pop("amplitude"), args.pop("frequency"), args.pop("n0"), **args)


# --- size limits ------------------------------------------------------------------------
def _history(path: Path, rows: int = 3, duration: float = 1.0) -> Path:
    t = np.linspace(0.0, duration, rows)
    lines = ["t,x,N"] + [f"{float(ti)!r},{1e-5 * i!r},100" for i, ti in enumerate(t)]
    path.write_text("\n".join(lines) + "\n")
    return path


SIZES = [
    (["loop", "--cycles", "100000", "--steps-per-cycle", "100000"], "--cycles x --steps-per-cycle"),
    (["loop", "--cycles", "1", "--steps-per-cycle", str(config.QS_MAX_SAMPLES + 1)], "--steps-per-cycle"),
    (["frc", "--gamma", "0.6:1.8:1e-9"], "at most"),
    (["frc", "--gamma", f"1:2:{1 / frc_command.MAX_GAMMA_POINTS}"], "--gamma"),
]


@pytest.mark.parametrize("argv, word", SIZES, ids=[" ".join(a) for a, _ in SIZES])
def test_size_limits(argv, word, no_compute, capsys, tmp_path):
    line = refused(capsys, tmp_path, argv, word)
    assert "at most" in line


@pytest.mark.parametrize("period", ["1e-6", "1e-300", "0.4"])
def test_loop_period_too_short_for_the_history(period, no_compute, capsys, tmp_path):
    """A 3-row, 1 s history holds at most one cycle of >= 2 sample intervals."""
    p = _history(no_compute / "h.csv")
    line = refused(capsys, tmp_path, ["loop", "--input", str(p), "--period", period], "--period")
    assert "at least 1.0 s" in line


def test_api_size_limits():
    with pytest.raises(ValueError, match=r"cycles x steps_per_cycle must be at most"):
        harmonic_history(1e-3, 1.0, 100.0, cycles=100000, steps_per_cycle=100000)
    t = np.linspace(0.0, 1.0, 3)
    from jointdyn import Iwan

    for period in (1e-6, 1e-300, 5e-324):
        with pytest.raises(ValueError, match=r"^period must be at least"):
            quasistatic(Iwan(1e5, 0.1, 100.0), t, np.zeros(3), np.full(3, 100.0), period=period)


# --- malformed files ---------------------------------------------------------------------
MALFORMED = [
    ("t,x,N\n0,0,100\n1,1e-5,100\n2,2e-5,100,7\n3,3e-5,100\n", "line 4: expected 3 fields (t, x, N), got 4"),
    ("t,x,N\n0,0,100\n1,1e-5\n2,2e-5,100\n", "line 3: expected 3 fields (t, x, N), got 2"),
    ("t,x,N,T,state\n0,0,1,0,a\n1,1e-5,1,0,b,c\n", "line 3: expected 5 fields"),
    ("t,x,N,T,state\n0,0,1,0,a\n1,1e-5,1,0\n", "line 3: expected 5 fields"),
    ("t x N T\n0 0 1 0\n1 1e-5 1\n", "line 3: expected 4 fields"),
    ("0,0,100\n1,1e-5,100\n", "line 1 holds numbers but no header row"),
    ("\n\n0;0;100\n1;1e-5;100\n", "line 3 holds numbers but no header row"),
    ("t,x,N\n0,0,100\n1,abc,100\n", "line 3: x = 'abc' is not a number"),
    ("t,x,N\n0,0,100\n1,1e-5,\n", "line 3: N is empty"),
    ("t,x,N\n0,0,100\n1,nan,100\n", "line 3: x = 'nan' is not finite"),
    ("t,x,N\n0,0,100\n1,1e400,100\n", "line 3: x = '1e400' is not finite"),
    ("t [s],x [mm],N [N]\n0,0,100\n1,1,100\n", "unit 'mm'; expected m"),
    ("T,x,N\n0,0,100\n1,1e-5,100\n", "missing column t"),
    ("t,x\n0,0\n1,1e-5\n", "missing column N"),
    ("t,X,x,N\n0,0,0,1\n1,1,1,1\n", None),  # exact names win over aliases: accepted
    ("time,Time,x,N\n0,0,0,1\n1,1,1,1\n", "all name t"),
    ("t,x,N\n0,0,100\n", "at least 2 samples"),
    ("t,x,N\n", "at least 2 samples"),
    ("", "has no data"),
    ("# only a comment\n", "has no data"),
    ("t,x,N\n0,0,100\n\n2,1e-5,100\n1,2e-5,100\n", "line 5: t must be strictly increasing, got t = 1.0 after t = 2.0 on line 4"),
    ("t,x,N\n0,0,100\n0,1e-5,100\n", "line 3: t must be strictly increasing"),
]


def _write(path: Path, text: str) -> Path:
    path.write_bytes(text.encode())
    return path


@pytest.mark.parametrize("text, word", MALFORMED, ids=[f"m{i}" for i in range(len(MALFORMED))])
def test_malformed_csv_cli(text, word, no_compute, capsys, tmp_path):
    p = _write(no_compute / "h.csv", text)
    if word is None:
        t, x, N = read_history_csv(p)
        assert t.tolist() == [0.0, 1.0] and x.tolist() == [0.0, 1.0]
        return
    line = refused(capsys, tmp_path, ["loop", "--input", str(p), "--out", "o"], word)
    assert line.startswith(f"jointdyn loop: error: --input {str(p)!r}")


@pytest.mark.parametrize("text, word", [m for m in MALFORMED if m[1] is not None][:12])
def test_malformed_csv_api(text, word, tmp_path):
    p = _write(tmp_path / "h.csv", text)
    with pytest.raises(ValueError) as exc:
        read_history_csv(p)
    msg = str(exc.value)
    assert msg.startswith(f"path {str(p)!r}") and word in msg


def test_not_utf8(no_compute, capsys, tmp_path):
    p = no_compute / "h.csv"
    p.write_bytes(b"t,x,N\n0,0,1\n\xff\xfe,1,1\n")
    refused(capsys, tmp_path, ["loop", "--input", str(p)], "line 3: not UTF-8")
    p.write_bytes(b"\xff\xfe\x00t\x00,\x00x\n")
    refused(capsys, tmp_path, ["loop", "--input", str(p)], "line 1: not UTF-8")


def test_binary_file_without_newlines(no_compute, capsys, tmp_path):
    p = no_compute / "h.bin"
    p.write_bytes(b"t" * (2 << 20))
    refused(capsys, tmp_path, ["loop", "--input", str(p)], "longer than")


# --- the reader's accepted variants (same numbers as the plain file) -------------------------
def _reference_reader(text: str):
    """Plain-Python oracle: the three columns of a comma file with header t,x,N."""
    rows = [r.split(",") for r in text.strip().splitlines()[1:] if r.strip()]
    return [np.array([float(r[i]) for r in rows]) for i in range(3)]


def _sample_text(rng, n=200) -> str:
    t = np.cumsum(rng.uniform(1e-4, 1e-2, n))
    x = rng.standard_normal(n) * 1e-3
    N = 100.0 + 60.0 * rng.standard_normal(n)
    return "t,x,N\n" + "".join(f"{a!r},{b!r},{c!r}\n" for a, b, c in zip(t.tolist(), x.tolist(), N.tolist()))


VARIANTS = {
    "units": lambda s: s.replace("t,x,N", "t [s], x [m], N [N]", 1),
    "words": lambda s: s.replace("t,x,N", "Time (s);Displacement (m);Normal load (N)", 1).replace(",", ";"),
    "decimal-comma": lambda s: s.replace("t,x,N", "t;x;N", 1).replace(",", ";").replace(".", ","),
    "tabs": lambda s: s.replace(",", "\t"),
    "spaces": lambda s: s.replace("t,x,N", "t [s]  x [m]  N [N]", 1).replace(",", "   "),
    "savetxt": lambda s: "# " + s.replace(",", " "),
    "crlf-bom-blank": lambda s: "\ufeff# exported\r\n\r\n" + s.replace("\n", "\r\n\r\n"),
}


@pytest.mark.parametrize("variant", list(VARIANTS))
def test_reader_variants_give_the_same_numbers(variant, tmp_path):
    rng = np.random.default_rng(12)
    text = _sample_text(rng)
    ref = _reference_reader(text)
    p = tmp_path / "h.csv"
    p.write_bytes(VARIANTS[variant](text).encode())
    got = read_history_csv(p)
    for a, b in zip(got, ref):
        np.testing.assert_array_equal(a, b)
        assert a.flags.writeable and a.flags.c_contiguous and a.dtype == np.float64


def test_reader_extra_columns_in_any_order(tmp_path):
    rng = np.random.default_rng(3)
    text = _sample_text(rng)
    t, x, N = _reference_reader(text)
    p = tmp_path / "h.csv"
    body = "".join(f"{c!r},{a!r},stick-slip,{b!r},\"q,r\"\n" for a, b, c in zip(t.tolist(), x.tolist(), N.tolist()))
    p.write_text('N [N],t,state,x,"note, quoted"\n' + body)
    got = read_history_csv(p)
    for a, b in zip(got, (t, x, N)):
        np.testing.assert_array_equal(a, b)


def test_reader_reads_loop_csv_back(tmp_path, capsys):
    """jointdyn's own loop.csv (columns t, x, N, T, state, inserted) is a valid
    input: T is the tangential force, never taken for t."""
    rc, _, _ = _cli(capsys, ["loop", "--eta", "1.2", "--steps-per-cycle", "40", "--out", str(tmp_path)])
    assert rc == 0
    import pandas as pd

    df = pd.read_csv(tmp_path / "loop.csv")
    t, x, N = read_history_csv(tmp_path / "loop.csv")
    np.testing.assert_array_equal(t, df["t"].to_numpy())
    np.testing.assert_array_equal(N, df["N"].to_numpy())


# --- contradictory options ---------------------------------------------------------------------
HARMONIC_OPTIONS = [
    ["--amplitude", "1e-3"],
    ["--frequency", "2"],
    ["--eta", "1.5"],
    ["--delta", "90"],
    ["--cycles", "3"],
    ["--steps-per-cycle", "100"],
    ["--kn", "1e5"],
]


@pytest.mark.parametrize("opt", HARMONIC_OPTIONS, ids=lambda o: o[0])
def test_loop_input_refuses_harmonic_options(opt, no_compute, capsys, tmp_path):
    p = _history(no_compute / "h.csv")
    line = refused(capsys, tmp_path, ["loop", "--input", str(p), *opt, "--out", "o"], opt[0])
    assert "--input" in line


def test_loop_input_refuses_default_valued_harmonic_option(no_compute, capsys, tmp_path):
    """Given explicitly, even at its default value, an option is refused."""
    p = _history(no_compute / "h.csv")
    refused(capsys, tmp_path, ["loop", "--input", str(p), "--eta", "0"], "--eta")


def test_loop_period_without_input(no_compute, capsys, tmp_path):
    refused(capsys, tmp_path, ["loop", "--period", "1"], "--period")


FRC_CONTRADICTIONS = [
    (["--method", "hb", "--sweep", "down"], "--sweep"),
    (["--method", "hb", "--sweep", "up"], "--sweep"),
    (["--method", "hb", "--steps-per-period", "64"], "--steps-per-period"),
    (["--method", "hb", "--scheduler", "tcp://127.0.0.1:9"], "--scheduler"),
    (["--method", "hb", "--workers", "2"], "--workers"),
    (["--harmonics", "5"], "--harmonics"),
    (["--method", "time", "--samples", "64"], "--samples"),
    (["--scheduler", "tcp://127.0.0.1:9", "--workers", "2"], "--workers"),
]


@pytest.mark.parametrize("argv, word", FRC_CONTRADICTIONS, ids=[" ".join(a) for a, _ in FRC_CONTRADICTIONS])
def test_frc_refuses_options_of_the_other_method(argv, word, no_compute, capsys, tmp_path):
    refused(capsys, tmp_path, ["frc", "--gamma", "1.1:1.3:0.1", *argv, "--out", "o"], word)


# --- a Dask scheduler that does not answer -----------------------------------------------------
def test_frc_unreachable_scheduler(no_compute, capsys, tmp_path, monkeypatch):
    monkeypatch.setattr(frc_command, "SCHEDULER_TIMEOUT_S", 0.5)  # the command line's own wait, shortened
    refused(capsys, tmp_path, ["frc", "--gamma", "1:1.1:0.1", "--scheduler", "tcp://127.0.0.1:9", "--out", "o"],
            "--scheduler")


@pytest.mark.parametrize("address", ["tcp://x", "no-port", "nonsense://a:1"])
def test_frc_malformed_scheduler_address(address, no_compute, capsys, tmp_path):
    refused(capsys, tmp_path, ["frc", "--gamma", "1:1.1:0.1", "--scheduler", address], "--scheduler")


# --- wrong types in the API --------------------------------------------------------------------
@pytest.mark.parametrize("client", ["tcp://x", 8786, object()], ids=["address", "int", "object"])
def test_api_frc_sweep_client_type(client, monkeypatch, tmp_path):
    monkeypatch.setattr(_points, "_steady_state_fn", lambda: _boom)
    with pytest.raises(ValueError, match=r"^client must be a distributed\.Client") as exc:
        frc_sweep([1.0], client=client, progress=False, out=tmp_path / "o")
    assert "connect first" in str(exc.value)
    assert not (tmp_path / "o").exists()


@pytest.mark.parametrize(
    "call, word",
    [
        (lambda: quasistatic(jointdyn.Iwan(1e5, 0.1, 100.0), [0, 1, 2], [0, 0, 0], [1, 1, 1], period="x"), "period"),
        (lambda: harmonic_history(1e-3, 1.0, 100.0, cycles="many"), "cycles"),
        (lambda: harmonic_history(1e-3, 1.0, 100.0, steps_per_cycle=2.5), "steps_per_cycle"),
        (lambda: read_history_csv(Path("x.csv"), name="--input"), "--input"),
        (lambda: frc_sweep([1.0], n_workers="two", progress=False), "n_workers"),
        (lambda: frc_sweep([1.0], out=3, n_workers=1, progress=False), "out"),
    ],
    ids=["period-str", "cycles-str", "steps-float", "missing-file", "workers-str", "out-int"],
)
def test_api_wrong_types(call, word, monkeypatch, tmp_path):
    monkeypatch.setattr(_points, "_steady_state_fn", lambda: _boom)
    monkeypatch.chdir(tmp_path)
    with pytest.raises(ValueError) as exc:
        call()
    assert str(exc.value).startswith(word), str(exc.value)


# --- real processes: exit status, a closed pipe --------------------------------------------------
def _env():
    env = dict(os.environ)
    env["PYTHONPATH"] = SRC + os.pathsep + env.get("PYTHONPATH", "")
    return env


def test_subprocess_exit_status_and_one_line(tmp_path):
    r = subprocess.run(
        [sys.executable, "-m", "jointdyn", "loop", "--mu", "1e308", "--json", "--out", str(tmp_path / "o")],
        capture_output=True, text=True, env=_env(), timeout=HANG_GUARD_S, check=False,
    )
    assert r.returncode == 2
    assert r.stdout == "" and len(r.stderr.strip().splitlines()) == 1 and "--mu" in r.stderr
    assert not (tmp_path / "o").exists()


@pytest.mark.parametrize("argv", [["loop", "--json", "--steps-per-cycle", "40"],
                                  ["loop", "--steps-per-cycle", "40"]], ids=["json", "table"])
def test_closed_stdout_exits_quietly(argv):
    """``jointdyn ... | head -c 300``: the reader is gone before the output
    is written; exit 141 (128 + SIGPIPE) with nothing on stderr."""
    p = subprocess.Popen([sys.executable, "-m", "jointdyn", *argv], stdout=subprocess.PIPE,
                         stderr=subprocess.PIPE, env=_env())
    p.stdout.close()  # long before the command prints
    err = p.stderr.read().decode()
    assert p.wait(timeout=HANG_GUARD_S) == 141
    assert err == ""


def test_version(capsys):
    with pytest.raises(SystemExit) as exc:
        main(["--version"])
    assert exc.value.code == 0
    assert capsys.readouterr().out.strip() == f"jointdyn {jointdyn.__version__}"


@pytest.mark.parametrize("command", [None, "loop", "frc", "modes", "figures"])
def test_every_help_text_prints(command, capsys):
    # argparse expands % in help texts: a literal percent sign must be written %%
    from jointdyn.cli import main

    argv = ["--help"] if command is None else [command, "--help"]
    with pytest.raises(SystemExit) as exc:
        main(argv)
    assert exc.value.code == 0
    assert "usage: jointdyn" in capsys.readouterr().out
