"""Small things a new user tripped on (issue 33): frequencies in Hz, the reported DOF, what amplitude_q
is, the help and the option names in messages, the lap-joint figure's row labels."""

import json

import numpy as np
import pandas as pd
import pytest

import jointdyn as jd
from jointdyn.cli import main

SYSTEM = """
[structure]
M = [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]]
K = [[1.0e3, 0.0, 0.0], [0.0, 2.0e3, 0.0], [0.0, 0.0, 3.0e5]]
zeta = 0.02

[[force]]
dof = 0
amplitude = 0.1

[[interface]]
kt = 1.5e3
kn = 1.5e3
mu = 0.5
preload = {preload}
pairs = [[0, 1, 2, -1, -1, -1]]
"""


def run_cli(argv):
    try:
        return main(argv)
    except SystemExit as exc:
        return exc.code


def _system(tmp_path, preload="0.5"):
    f = tmp_path / "s.toml"
    f.write_text(SYSTEM.format(preload=preload))
    return f


def test_frc_takes_a_frequency_grid_in_hz_and_writes_both_frequencies(tmp_path, capsys):
    f = _system(tmp_path)
    w0 = jd.read_system(f).w0
    out = tmp_path / "out"
    rc = run_cli(["frc", "--system", str(f), "--method", "hb", "--harmonics", "1", "--samples", "16",
                  "--frequency", "4:6:0.5", "--out", str(out), "--json"])
    res = json.loads(capsys.readouterr().out)
    assert rc == 0
    gam = res["branches"][0]["gamma"]
    assert gam[0] == pytest.approx(2 * np.pi * 4.0 / w0) and gam[-1] == pytest.approx(2 * np.pi * 6.0 / w0)
    table = pd.read_csv(out / "frc.csv")
    assert np.allclose(table["omega_rad_s"], table["gamma"] * w0, rtol=1e-12)
    assert np.allclose(table["frequency_hz"], table["omega_rad_s"] / (2 * np.pi), rtol=1e-12)
    assert table["frequency_hz"].iloc[0] == pytest.approx(4.0)


def test_frequency_and_gamma_together_are_refused(tmp_path, capsys):
    rc = run_cli(["frc", "--system", str(_system(tmp_path)), "--frequency", "4:6:0.5", "--gamma", "0.9:1.1:0.1"])
    err = capsys.readouterr().err.strip()
    assert rc == 2 and len(err.splitlines()) == 1 and "--frequency" in err and "--gamma" in err


def test_a_time_domain_frc_csv_has_both_frequencies(tmp_path, capsys):
    out = tmp_path / "out"
    rc = run_cli(["frc", "--eta", "0", "--beta", "50", "--gamma", "1.3:1.3:0.1", "--out", str(out), "--json"])
    capsys.readouterr()
    table = pd.read_csv(out / "frc.csv")
    w0 = jd.System.paper_damper().w0
    assert rc == 0 and np.allclose(table["omega_rad_s"], 1.3 * w0) and np.allclose(table["frequency_hz"],
                                                                                 1.3 * w0 / (2 * np.pi))


def test_steady_state_reports_the_systems_output_dof_by_default():
    M, K = np.diag([1.0, 2.0]), np.array([[3e3, -1e3], [-1e3, 2e3]])
    s = jd.System(M, 0.02 * K / 30.0, K, force=[1.0, 0.0], output_dof=1)
    default = jd.steady_state(s, 1.0, max_periods=400)
    one = jd.steady_state(s, 1.0, max_periods=400, response_dof=1)
    zero = jd.steady_state(s, 1.0, max_periods=400, response_dof=0)
    assert default.amplitude_m == pytest.approx(one.amplitude_m, rel=1e-9)
    assert abs(default.amplitude_m - zero.amplitude_m) > 1e-3 * zero.amplitude_m


@pytest.mark.parametrize("preload,words", [("0.5", "interfaces' pairs"), ("0.0", "undefined (null)")])
def test_amplitude_q_says_what_it_is_for_an_interface_only_system(tmp_path, capsys, preload, words):
    rc = run_cli(["frc", "--system", str(_system(tmp_path, preload)), "--method", "hb", "--harmonics", "1",
                  "--samples", "16", "--gamma", "0.8:1.2:0.2", "--json"])
    cap = capsys.readouterr()
    res = json.loads(cap.out)
    assert rc == 0 and cap.err == ""  # no numpy warning of a division by fy = 0
    meaning = res["system"]["amplitude_q_meaning"]
    assert words in meaning and "first contact" not in meaning and res["system"]["fy_N"] is None
    q = res["branches"][0]["amplitude_q"]
    assert all(v is None for v in q) if preload == "0.0" else all(v > 0 for v in q)


def test_frc_help_names_interfaces(capsys):
    assert run_cli(["frc", "--help"]) == 0
    text = " ".join(capsys.readouterr().out.split())
    assert "[[interface]]" in text and "--frequency" in text


@pytest.mark.parametrize("argv,words", [
    (["--mode", "9"], ("--mode must be in [1, 3]",)),
    (["--output-dof", "7"], ("--output-dof must be in [0, 2]",)),
    (["--output-dof", "1"], ("--output-dof: DOF 1 does not move",)),
])
def test_modes_messages_name_the_cli_options(tmp_path, capsys, argv, words):
    rc = run_cli(["modes", "--system", str(_system(tmp_path)), "--amplitude", "1e-6:1e-3", *argv])
    err = capsys.readouterr().err.strip()
    assert rc == 2 and len(err.splitlines()) == 1, err
    for w in words:
        assert w in err, err


def test_open_pairs_need_an_amplitude_range_and_say_why(tmp_path, capsys):
    rc = run_cli(["modes", "--system", str(_system(tmp_path, "0.0"))])
    err = capsys.readouterr().err.strip()
    assert rc == 2 and "--amplitude must be given" in err and "open at rest" in err and "first contact" not in err


def test_the_lap_joint_maps_label_each_row_once():
    from jointdyn.figures import pyplot
    from jointdyn.figures.lap import _plot_maps

    plt = pyplot()
    rows = [{"map": k, "x_mm": float(i), "y_mm": 0.0, "in_interface": 1, "slip": 0.5, "open": 0.1,
             "amplitude_m": 1e-4 * (k + 1), "converged": True, "frequency_hz": 100.0, "energy_J": 1e-3}
            for k in range(3) for i in range(4)]
    fig, axes = plt.subplots(2, 3)
    _plot_maps(axes, pd.DataFrame(rows))
    labels = [axes[r, 0].get_ylabel() for r in range(2)]
    plt.close(fig)
    assert labels[0].startswith("(d) ") and labels[1].startswith("(e) ")


def test_epmc_from_a_repeated_linear_mode_says_why_it_cannot_start(tmp_path, capsys):
    """Two DOFs of equal stiffness and an open pair: mode 1's frequency is repeated, the start singular."""
    f = tmp_path / "s.toml"
    f.write_text(SYSTEM.format(preload="0.0").replace("[0.0, 2.0e3, 0.0]", "[0.0, 1.0e3, 0.0]"))
    rc = run_cli(["modes", "--system", str(f), "--amplitude", "1e-6:1e-3", "--harmonics", "3", "--samples", "32",
                  "--out", str(tmp_path / "o")])
    err = capsys.readouterr().err.strip()
    assert rc == 3 and "no-start" in err and "repeated (mode 2 too)" in err and "detune" in err, err
    f.write_text(SYSTEM.format(preload="0.0").replace("[0.0, 2.0e3, 0.0]", "[0.0, 1.0001e3, 0.0]"))
    rc = run_cli(["modes", "--system", str(f), "--amplitude", "1e-6:1e-3", "--harmonics", "3", "--samples", "32",
                  "--out", str(tmp_path / "o2")])
    assert rc == 0, capsys.readouterr().err


def test_a_linear_mode_knows_its_repeated_partners():
    from jointdyn.modes._free import linear_stuck_mode

    M = np.eye(3)
    s = jd.System(M, np.zeros((3, 3)), np.diag([4.0, 4.0, 9.0]))
    assert linear_stuck_mode(s, 1, 0).repeated == (2,)
    assert linear_stuck_mode(s, 3, 2).repeated == ()
    s = jd.System(M, np.zeros((3, 3)), np.diag([4.0, 4.0 * (1 + 1e-6), 9.0]))
    assert linear_stuck_mode(s, 1, 0).repeated == ()


HELD_BY_FRICTION = """
[structure]
M = [[1.0, 0.0], [0.0, 0.5]]
K = [[1.0e4, 0.0], [0.0, 0.0]]

[[force]]
dof = 0
amplitude = 2.0

[[contact]]
law = "jenkins"
kt = 2.0e4
mu = 0.5
tangential = { dof = 0, dof2 = 1 }
normal = { n0 = 10.0 }
"""


def test_hb_takes_a_dof_held_only_by_friction_and_refuses_one_held_by_nothing(tmp_path, capsys):
    """DOF 1 hangs on DOF 0 through a friction contact only: stuck, the structure is held, and harmonic
    balance restarts the law at the preloaded static state, so the stuck contact holds DOF 1's mean: the
    solver (and so the command line) computes the curve. A DOF held by nothing, not even by the stuck
    contacts, is still refused, and the command line says so in one line before it writes anything."""
    from jointdyn.hb import check_mean_position, frc_hb
    from jointdyn.hb.problem import held_by_contacts

    f = tmp_path / "s.toml"
    f.write_text(HELD_BY_FRICTION.replace("amplitude = 2.0", "amplitude = 1.0e-3"))
    s = jd.read_system(f)
    assert held_by_contacts(s)
    check_mean_position(s)
    ds = frc_hb(s, 0.5, 1.5, harmonics=1, samples=16, progress=False)
    assert ds.attrs["status"] == "complete"
    out = tmp_path / "o"
    assert run_cli(["frc", "--system", str(f), "--method", "hb", "--harmonics", "1", "--samples", "16",
                    "--out", str(out)]) == 0
    free = HELD_BY_FRICTION.replace("[[1.0, 0.0], [0.0, 0.5]]", "[[1.0, 0.0, 0.0], [0.0, 0.5, 0.0], [0.0, 0.0, 0.2]]")
    free = free.replace("[[1.0e4, 0.0], [0.0, 0.0]]", "[[1.0e4, 0.0, 0.0], [0.0, 0.0, 0.0], [0.0, 0.0, 0.0]]")
    g = _write_text(tmp_path / "free.toml", free)
    with pytest.raises(ValueError, match="mostly DOF 2: held by nothing"):
        check_mean_position(jd.read_system(g))
    capsys.readouterr()
    out2 = tmp_path / "o2"
    rc = run_cli(["frc", "--system", str(g), "--method", "hb", "--out", str(out2)])
    err = capsys.readouterr().err.strip()
    assert rc == 2 and len(err.splitlines()) == 1 and "held by nothing" in err and "--method time" in err
    assert not out2.exists()


def _write_text(path, text):
    path.write_text(text)
    return path
