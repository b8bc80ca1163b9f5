"""``jointdyn frc --system FILE.toml``: a structure of your own through the
command line, time domain and harmonic balance; the paper damper's options
refused with it; bad files refused in one line with exit 2 and no file.
"""

from __future__ import annotations

import json

import numpy as np
import pandas as pd
import pytest

import jointdyn as jd
from jointdyn import hb  # noqa: F401 - a plain import: a broken package fails here, never skips
from jointdyn.cli import main
from jointdyn.sweeps import frc_sweep
from test_files import ISSUE_EXAMPLE
from tolerances import TEST_HB_VS_TIME_RTOL

SYSTEM = """\
title = "two masses on a joint"

[structure]
M = [[2.0, 0.0], [0.0, 1.0]]
K = [[3.0e5, -1.0e5], [-1.0e5, 1.0e5]]
zeta = [0.01, 0.02]

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
dofs = [0, 1]
"""


@pytest.fixture
def system_file(tmp_path):
    p = tmp_path / "joint.toml"
    p.write_text(SYSTEM)
    return p


def _cli(capsys, argv):
    try:
        rc = main(list(argv))
    except SystemExit as exc:
        rc = exc.code
    cap = capsys.readouterr()
    return rc, cap.out, cap.err


def test_time_json_files_and_resume(system_file, capsys, tmp_path):
    out = tmp_path / "run"
    argv = ["frc", "--system", str(system_file), "--gamma", "0.9:1.1:0.1", "--workers", "1", "--json",
            "--out", str(out)]
    rc, stdout, _ = _cli(capsys, argv)
    assert rc == 0
    res = json.loads(stdout)
    assert res["method"] == "time" and res["reused_points"] == 0
    sysd = res["system"]
    assert sysd["title"] == "two masses on a joint" and sysd["ndof"] == 2 and sysd["response_dof"] == 1
    assert sysd["dofs"] == [0, 1] and sysd["fy_N"] == pytest.approx(30.0)
    assert sysd["contacts"][0]["normal"] == "HarmonicLoad" and sysd["contacts"][0]["n0"] == 100.0
    system = jd.read_system(system_file)
    assert sysd["w0_rad_s"] == pytest.approx(system.w0)
    ref = frc_sweep(system, [0.9, 1.0, 1.1], dofs=[0, 1], n_workers=1, progress=False)
    for d in ("up", "down"):
        got, want = res["directions"][d], ref.sel(direction=d)
        assert got["status"] == ["periodic"] * 3
        np.testing.assert_array_equal(got["amplitude_m"], want.amplitude_m.values)
        # q = kt X / fy with fy = mu n0 of the first contact
        np.testing.assert_allclose(got["amplitude_q"], 2.0e5 * np.array(got["amplitude_m"]) / 30.0, rtol=1e-12)
        np.testing.assert_array_equal(got["dofs"]["0"]["amplitude_m"], want.dof_amplitude_m.sel(dof=0).values)
        np.testing.assert_array_equal(got["dofs"]["1"]["offset_m"], want.dof_offset_m.sel(dof=1).values)
        (c,) = got["contacts"]
        np.testing.assert_array_equal(c["energy_J"], want.contact_energy_J.sel(contact=0).values)
        np.testing.assert_array_equal(c["normal_max_N"], want.normal_max_N.sel(contact=0).values)
        assert set(c["state_fraction"]) == set(jd.STATE_NAMES)
    for name in ("frc.nc", "frc.csv", "frc.png"):
        assert (out / name).stat().st_size > 0
    df = pd.read_csv(out / "frc.csv")
    assert len(df) == 6 and {"contact_energy_J_c0", "dof_amplitude_m_dof0", "state_fraction_c0_macroslip"} <= set(df)
    before = (out / "frc.nc").read_bytes()
    rc, stdout, err = _cli(capsys, argv)
    assert rc == 0 and json.loads(stdout)["reused_points"] == 6
    assert "reused 6 of 6 points" in err
    assert (out / "frc.nc").read_bytes() == before


PAPER_OPTIONS = [
    ["--eta", "0.5"], ["--beta", "2"], ["--f1", "3"], ["--delta", "0"], ["--m", "1"], ["--k", "1"],
    ["--kt", "1"], ["--kn", "1"], ["--mu", "0.5"], ["--n0", "100"], ["--model", "iwan"],
    ["--law-param", "capacity=8"], ["--n", "20"], ["--zeta", "0"],
]


@pytest.fixture
def no_compute(monkeypatch):
    import jointdyn.sweeps
    from jointdyn.commands import frc as frc_cmd

    def boom(*a, **k):
        raise AssertionError("computing was reached before the input was refused")

    monkeypatch.setattr(jointdyn.sweeps, "frc_sweep", boom)
    monkeypatch.setattr(frc_cmd, "_run_hb", boom)


@pytest.mark.parametrize("option", PAPER_OPTIONS, ids=[o[0] for o in PAPER_OPTIONS])
@pytest.mark.parametrize("method", ["time", "hb"])
def test_paper_options_refused_with_system(option, method, system_file, no_compute, capsys, tmp_path):
    out = tmp_path / "o"
    rc, stdout, err = _cli(capsys, ["frc", "--method", method, "--system", str(system_file), *option,
                                    "--out", str(out)])
    assert rc == 2 and stdout == ""
    assert len(err.strip().splitlines()) == 1 and option[0] in err and "--system" in err
    assert not out.exists()


@pytest.mark.parametrize("text, words", [
    (SYSTEM.replace("kt = 2.0e5\n", ""), "contact[0].kt is missing"),
    (SYSTEM.replace('law = "iwan"', 'law = "coulomb"'), "contact[0].law must be one of"),
    (SYSTEM.replace("M = [[2.0, 0.0], [0.0, 1.0]]", "M = [[2.0, 1.0], [0.0, 1.0]]"), "structure.M must be symmetric"),
    (SYSTEM.replace("M = [[2.0, 0.0], [0.0, 1.0]]", "M = [[2.0, 0.0], [0.0, -1.0]]"),
     "structure.M must be positive definite"),
    (SYSTEM.replace("zeta = [0.01, 0.02]", "zeta = [0.01, 0.02, 0.03]"), "structure.zeta must have 2 entries"),
    (SYSTEM.replace("dof = 1\namplitude", "dof = 5\namplitude"), "force[0].dof must be in [0, 1]"),
    (SYSTEM.replace("[output]", "[output]\nfoo = 1"), "output.foo is not a known key"),
    (SYSTEM.replace("amplitude = 20.0", 'amplitude = "20"'), "force[0].amplitude must be a number"),
    (SYSTEM + "\n[[", "not valid TOML"),
])
@pytest.mark.parametrize("method", ["time", "hb"])
def test_bad_system_file_exit2_one_line(text, words, method, no_compute, capsys, tmp_path):
    p = tmp_path / "bad.toml"
    p.write_text(text)
    out = tmp_path / "o"
    rc, stdout, err = _cli(capsys, ["frc", "--method", method, "--system", str(p), "--out", str(out)])
    lines = err.strip().splitlines()
    assert rc == 2 and stdout == "" and len(lines) == 1 and "Traceback" not in err
    assert "--system" in lines[0] and str(p) in lines[0] and words in lines[0], lines[0]
    assert not out.exists()


def test_missing_system_file(no_compute, capsys, tmp_path):
    rc, _, err = _cli(capsys, ["frc", "--system", str(tmp_path / "none.toml")])
    assert rc == 2 and "--system must be an existing file" in err and len(err.strip().splitlines()) == 1


def test_hb_on_a_system_file(system_file, capsys, tmp_path):
    """Harmonic balance of the file's system reports its output DOF: the
    branch starts where the time-domain steady state of that DOF is."""
    rc, stdout, _ = _cli(capsys, ["frc", "--method", "hb", "--system", str(system_file), "--gamma", "0.9:1.0:0.1",
                                  "--harmonics", "5", "--samples", "128", "--json", "--out", str(tmp_path / "hb")])
    assert rc == 0
    res = json.loads(stdout)
    assert res["method"] == "hb" and res["system"]["response_dof"] == 1 and res["status"] == "complete"
    first = res["branches"][0]
    assert first["gamma"][0] == pytest.approx(0.9)
    ss = jd.steady_state(jd.read_system(system_file), 0.9, response_dof=1)
    assert first["amplitude_m"][0] == pytest.approx(ss.amplitude_m, rel=TEST_HB_VS_TIME_RTOL)
    for name in ("frc.nc", "frc.csv", "frc.png"):
        assert (tmp_path / "hb" / name).stat().st_size > 0


#: the issue's example with the forcing in phase (the spring alone)
SPRING_IN_PHASE = ISSUE_EXAMPLE.replace("phase_deg = 90.0", "phase_deg = 0.0")


def _solver_refusal(method, system):
    """The solver's own refusal of ``system`` (its ValueError text), or None
    when it takes it (the call is then made with the test's small settings)."""
    try:
        if method == "time":
            jd.steady_state(system, 0.5, max_periods=1)
        else:
            from jointdyn.hb import frc_hb

            frc_hb(system, 0.5, 0.6, harmonics=3, samples=64, progress=False)
    except ValueError as exc:
        return str(exc)
    return None


@pytest.mark.parametrize("text", [ISSUE_EXAMPLE, SPRING_IN_PHASE], ids=["as-written", "spring-in-phase"])
@pytest.mark.parametrize("method", ["time", "hb"])
def test_issue_example_runs_or_is_refused_in_one_line(method, text, capsys, tmp_path):
    """The issue's example through the command line: a solver that does not
    take a normal spring or forcing phases says so in one line naming the
    method (its own words), exit 2, no file; a solver that takes them runs."""
    p = tmp_path / "issue.toml"
    p.write_text(text)
    out = tmp_path / "o"
    gamma = "0.5:0.5:0.1" if method == "time" else "0.5:0.6:0.1"
    argv = ["frc", "--method", method, "--system", str(p), "--gamma", gamma, "--json", "--out", str(out)]
    rc, stdout, err = _cli(capsys, argv + (["--sweep", "up", "--workers", "1"] if method == "time" else []))
    if method == "time":  # the time integrator takes normal springs and forcing phases
        assert rc == 0, err
    if rc == 2:
        refusal = _solver_refusal(method, jd.read_system(p))
        assert refusal is not None, err
        assert stdout == "" and err.strip() == f"jointdyn frc: error: --method {method}: {refusal}"
        assert "Traceback" not in err and not out.exists()
    else:
        assert rc == 0, err
        res = json.loads(stdout)
        assert res["system"]["response_dof"] == 0 and res["system"]["w0_rad_s"] == pytest.approx(197.5, abs=0.05)
        for name in ("frc.nc", "frc.csv", "frc.png"):
            assert (out / name).stat().st_size > 0
