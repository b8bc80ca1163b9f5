"""EPMC harmonics and samples chosen automatically (``"auto"``), as
``frc --method hb`` chooses them: refined where a contact separates, kept
where the default already resolves the backbone."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest

import jointdyn as jd
from jointdyn import config
from jointdyn.cli import main
from jointdyn.modes import EPMCOptions, epmc
from jointdyn.hb import Discretisation, Level
from jointdyn.modes._auto import check_points, level_changes

BLADE = Path(__file__).resolve().parents[1] / "examples" / "blade.toml"


def test_default_level_kept_where_it_resolves_the_backbone():
    s = jd.System.paper_damper(eta=0.0)
    auto = epmc(s, harmonics="auto", samples="auto", progress=False)
    fixed = epmc(s, progress=False)
    assert (auto.harmonics, auto.samples) == (config.HB_HARMONICS, config.HB_SAMPLES)
    np.testing.assert_array_equal(auto.omega_rad_s, fixed.omega_rad_s)
    assert auto.counters["discretisation_levels"] == 1 and auto.counters["discretisation_converged"] == 1
    assert "chosen automatically (tried H = 7, Ns = 128;" in auto.message


def test_refined_where_the_contact_separates():
    """The blade's wedge damper opens: 7 x 128 is not enough; the level
    chosen passes its own check, and the backbone at the default level
    differs from it by more than the tolerance somewhere (the check is not
    vacuous)."""
    s = jd.read_system(BLADE)
    auto = epmc(s, harmonics="auto", samples="auto", progress=False)
    assert auto.status.ok and auto.counters["discretisation_converged"] == 1
    assert auto.samples > config.HB_SAMPLES and auto.counters["discretisation_levels"] > 1
    ch = level_changes(auto, Level(auto.harmonics, auto.samples), Discretisation.of(), 1)
    assert max(ch) <= config.HB_AUTO_RTOL
    coarse = epmc(s, progress=False)
    ch0 = level_changes(coarse, Level(coarse.harmonics, coarse.samples), Discretisation.of(), 1)
    assert max(ch0) > config.HB_AUTO_RTOL


def test_check_points_spread_and_include_the_largest_damping():
    b = epmc(jd.System.paper_damper(eta=0.0), progress=False)
    idx = check_points(b)
    assert idx[0] == 0 and idx[-1] == b.points - 1 and int(np.argmax(b.damping_ratio)) in idx
    assert len(idx) <= EPMCOptions().auto_check_points + 1


def test_cli_modes_chooses_automatically_unless_given(capsys):
    assert main(["modes", "--system", str(BLADE), "--json"]) == 0
    out = json.loads(capsys.readouterr().out)
    assert out["samples"] > config.HB_SAMPLES and "chosen automatically" in out["message"]
    assert main(["modes", "--system", str(BLADE), "--harmonics", "7", "--samples", "128", "--json"]) == 0
    out = json.loads(capsys.readouterr().out)
    assert (out["harmonics"], out["samples"]) == (7, 128) and "chosen automatically" not in out["message"]


@pytest.mark.parametrize("argv, words", [
    (["--harmonics", "x"], "--harmonics must be an integer >= 1 or 'auto', got 'x'"),
    (["--samples", "8"], "--samples must be an integer >= 16 or 'auto', got '8'"),
])
def test_cli_refuses_other_words(argv, words, capsys):
    assert main(["modes", *argv]) == 2
    assert words in capsys.readouterr().err
