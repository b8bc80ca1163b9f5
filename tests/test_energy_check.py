"""SteadyState.energy_check: negative contact dissipation is flagged, not silent (issue 10, item of issue 9).

Oracle: the paper's closed form creates energy at issue 9's point (eta 1.5,
beta 2, gamma 0.6: -4.55e-7 J per period against an energy-balance residual of
1.9e-11 J, tests/test_default_dissipation.py); the exact default law does not.
"""

import warnings

import pytest

import jointdyn as jd
from jointdyn.dynamics import EnergyCheck, energy_check


def test_energy_check_classifies_by_the_balance_residual():
    assert energy_check(1.0, 0.9, 0.1) == EnergyCheck.PASSIVE
    # slightly negative but within the residual of the balance: passive
    assert energy_check(1.0, -1e-6, 1.0 + 2e-6) == EnergyCheck.PASSIVE
    # the balance closes and the contact returns energy: flagged
    assert energy_check(1.0, -1e-3, 1.001) == EnergyCheck.NEGATIVE_DISSIPATION
    assert not EnergyCheck.NEGATIVE_DISSIPATION.ok and EnergyCheck.PASSIVE.ok


def test_the_closed_form_is_flagged_and_the_default_law_is_not():
    closed = jd.System.paper_damper(eta=1.5, beta=2.0, model="iwan-closed")
    with pytest.warns(RuntimeWarning, match="negative-dissipation|creates energy"):
        r = jd.steady_state(closed, 0.6)
    assert r.status == "periodic" and r.energy_contact_J < -1e-7
    assert r.energy_check == "negative-dissipation" and r.to_record()["energy_check"] == "negative-dissipation"
    with warnings.catch_warnings():
        warnings.simplefilter("error", RuntimeWarning)
        d = jd.steady_state(jd.System.paper_damper(eta=1.5, beta=2.0), 0.6)
    assert d.status == "periodic" and d.energy_check == "passive"


def test_not_periodic_is_not_checked():
    r = jd.steady_state(jd.System.paper_damper(eta=0.5, beta=1.0), 1.0, max_periods=2, shooting=False)
    assert r.status != "periodic" and r.energy_check == "not-checked"


def test_sweeps_and_the_cli_flag_negative_dissipation(tmp_path):
    # the closed form at issue 9's point creates energy; the exact default does not
    import json
    import subprocess
    import sys

    flagged = jd.frc_sweep([0.6], etas=[1.5], betas=[2.0], model="iwan-closed", directions=("up",), n_workers=1,
                           progress=False)
    assert int(flagged.negative_dissipation.sum()) == 1
    exact = jd.frc_sweep([0.6], etas=[1.5], betas=[2.0], directions=("up",), n_workers=1, progress=False)
    assert int(exact.negative_dissipation.sum()) == 0
    proc = subprocess.run([sys.executable, "-m", "jointdyn", "frc", "--model", "iwan-closed", "--eta", "1.5",
                           "--beta", "2", "--gamma", "0.6:0.6:0.01", "--sweep", "up", "--json"],
                          capture_output=True, text=True)
    assert proc.returncode == 0
    assert json.loads(proc.stdout)["directions"]["up"]["negative_dissipation"] == [True]
    assert "1 periodic points where the contact creates energy" in proc.stderr
