"""Harmonic balance that can be trusted (issue 9): no skipped peaks, honest
statuses, no folds at non-smooth corners.

Oracles: the time-domain steady state at the refined peak, the
describing-function maximum of a Jenkins oscillator, harmonic balance solved
afresh at the middle of every chord, and the requested range itself.
"""

from __future__ import annotations

import json
import math

import numpy as np
import pytest
import tolerances
from scipy.optimize import minimize_scalar
from test_hb import _df_amplitude, _jenkins_system

from jointdyn import System, config
from jointdyn.cli import EXIT_INCOMPLETE, main
from jointdyn.fourier import fourier_matrices
from jointdyn.hb import HBOptions, PointStatus, frc_hb, harmonic_balance

GRID = "0.6:1.8:0.01"


def _cli_hb(capsys, *argv, out=None):
    args = ["frc", "--method", "hb", "--gamma", GRID, "--json", *argv]
    if out is not None:
        args += ["--out", str(out)]
    rc = main(args)
    cap = capsys.readouterr()
    return rc, json.loads(cap.out), cap.err


def test_cli_finds_the_beta_1000_peak_of_the_time_domain(capsys):
    # the peak that the CLI stepped over (q = 0.0087 reported, 0.096 true at gamma 1.323)
    from jointdyn.dynamics import steady_state

    rc, out, _ = _cli_hb(capsys, "--eta", "0.01", "--beta", "1000")
    assert rc == 0 and out["status"] == "complete"
    for br in out["branches"]:  # the STEP of --gamma is the largest spacing
        assert np.max(np.abs(np.diff(br["gamma"]))) <= 0.01 * (1 + 1e-9)
    top = max(out["peaks"], key=lambda p: p["amplitude_q"])
    assert top["refined"] and abs(top["gamma"] - 1.323) < 2e-3
    ss = steady_state(System.paper_damper(eta=0.01, beta=1000.0), top["gamma"])
    assert ss.status == "periodic"
    assert abs(top["amplitude_m"] - ss.amplitude_m) <= tolerances.TEST_HB_VS_TIME_RTOL * ss.amplitude_m
    # the refined peak is at least as high as every reported point
    assert top["amplitude_q"] >= max(q for br in out["branches"] for q in br["amplitude_q"])


def test_chords_stay_within_one_percent_of_the_curve():
    # HB solved afresh at the middle gamma of every chord (the branch has no fold here); the distance
    # between chord and curve is measured in the plane (gamma, ln q), where 0.01 is 1 % of the amplitude
    # (on a steep flank the distance across the chord, not the amplitude at the same gamma)
    system = System.paper_damper(eta=0.01, beta=1000.0)
    ds = frc_hb(system, 0.6, 1.8, max_step=0.01)
    assert ds.attrs["folds"] == 0 and np.all(np.diff(ds.gamma.values) > 0)
    g, lq = ds.gamma.values, np.log(ds.amplitude_m.values)
    worst = 0.0
    for i in range(g.size - 1):
        sol = harmonic_balance(system, 0.5 * (g[i] + g[i + 1]))
        assert sol.status.ok
        slope = (lq[i + 1] - lq[i]) / (g[i + 1] - g[i])
        dist = abs(0.5 * (lq[i] + lq[i + 1]) - math.log(sol.amplitude_m)) / math.hypot(1.0, slope)
        worst = max(worst, dist)
    assert worst <= tolerances.TEST_HB_CHORD_TOL


def test_refined_peak_equals_the_describing_function_maximum():
    best = minimize_scalar(lambda gm: -_df_amplitude(gm), bounds=(1.0, 1.6), method="bounded",
                           options={"xatol": 1e-9})
    ds = frc_hb(_jenkins_system(), 0.6, 1.8, harmonics=1, samples=1024)
    assert ds.sizes["peak"] == 1 and bool(ds.peak_refined[0])
    # the AFT amplitude is within 1e-4 of the DF one (1024 samples): on a flat maximum that places the peak
    # within about sqrt(1e-4) / (curvature) in gamma
    assert abs(float(ds.peak_gamma[0]) - best.x) <= 1e-3
    assert abs(float(ds.peak_amplitude_m[0]) + best.fun) <= tolerances.TEST_HB_DF_RTOL * -best.fun
    assert float(ds.peak_amplitude_m[0]) >= ds.amplitude_m.values.max()
    assert ds.attrs["peak_gamma"] == float(ds.peak_gamma[0])


def test_max_step_is_honoured_by_the_api():
    ds = frc_hb(_jenkins_system(), 0.6, 1.8, harmonics=1, samples=256, max_step=0.005)
    assert ds.attrs["status"] == "complete"
    assert np.max(np.abs(np.diff(ds.gamma.values))) <= 0.005 * (1 + 1e-9)
    with pytest.raises(ValueError, match="max_step"):
        frc_hb(_jenkins_system(), 0.6, 1.8, max_step=0.0)


@pytest.mark.parametrize("model", ["iwan-closed", "iwan-paper"])
def test_eta_1p5_beta_5_covers_the_range(capsys, model):
    # reported 'complete' for a branch covering only gamma 0.600-0.616 (it turned back to the start)
    rc, out, _ = _cli_hb(capsys, "--model", model, "--eta", "1.5", "--beta", "5")
    assert rc == 0 and out["status"] == "complete" and out["uncovered"] == []
    g = [x for br in out["branches"] for x in br["gamma"]]
    assert min(g) == pytest.approx(0.6) and max(g) == pytest.approx(1.8)


@pytest.mark.parametrize("model,eta,beta", [("jenkins", 1.5, 1.0), ("jenkins", 1.5, 5.0), ("jenkins", 1.5, 10.0),
                                            ("jenkins", 10.0, 1.0), ("iwan-closed", 1.5, 2.0),
                                            ("iwan", 1.5, 2.0)])
def test_runs_that_failed_complete(capsys, model, eta, beta):
    # "corrector failed at the smallest step" before: the branch must now cover the range, without
    # repeated (stalled) rows
    rc, out, _ = _cli_hb(capsys, "--model", model, "--eta", str(eta), "--beta", str(beta))
    assert rc == 0 and out["status"] == "complete", out["message"]
    g = [x for br in out["branches"] for x in br["gamma"]]
    assert min(g) == pytest.approx(0.6) and max(g) == pytest.approx(1.8)
    for br in out["branches"]:
        rows = list(zip(br["gamma"], br["amplitude_m"]))
        assert all(r != s for r, s in zip(rows, rows[1:]))
        assert set(br["point_status"]) <= {s.value for s in PointStatus if s is not PointStatus.STOPPED}


def test_jenkins_beta_1000_reports_no_fold(capsys):
    # 26-30 folds and 94-190 unstable points were reported at the onset of slip (q = 1)
    rc, out, _ = _cli_hb(capsys, "--model", "jenkins", "--eta", "0.01", "--beta", "1000")
    assert rc == 0 and out["status"] == "complete"
    assert all(br["folds"] == [] for br in out["branches"])
    assert all(all(br["stable"]) for br in out["branches"])


def test_incomplete_branch_exits_3_and_writes_marked_files(capsys, tmp_path, monkeypatch):
    # a branch stopped at its point bound: exit status 3 (not 0, not 2), files with per-point status,
    # the uncovered part named on stderr and in the Dataset
    import xarray as xr

    from jointdyn import hb

    real = hb.continue_hb
    monkeypatch.setattr(hb, "continue_hb", lambda *a, **k: real(*a, max_points=12, **k))
    rc, out, err = _cli_hb(capsys, "--eta", "0.5", "--beta", "2", out=tmp_path)
    assert rc == EXIT_INCOMPLETE == 3
    assert out["status"] == "max-points" and out["uncovered"][-1][1] == pytest.approx(1.8)
    assert "incomplete" in err and "max-points" in err and "gamma" in err
    for name in ("frc.nc", "frc.csv", "frc.png"):
        assert (tmp_path / name).stat().st_size > 0
    ds = xr.open_dataset(tmp_path / "frc.nc", engine="scipy")
    st = [str(s) for s in ds.point_status.values]
    assert st[0] == "start" and st[-1] == "stopped" and ds.attrs["status"] == "max-points"
    lo, hi = (float(v) for v in ds.attrs["uncovered"].split("-"))
    assert lo == pytest.approx(float(ds.gamma.values[-1])) and hi == pytest.approx(1.8)
    ds.close()
    assert "point_status" in (tmp_path / "frc.csv").read_text().splitlines()[0]


def test_api_status_of_a_partial_branch():
    ds = frc_hb(System.paper_damper(eta=0.5, beta=2.0), 0.6, 1.8, max_points=12)
    assert ds.attrs["status"] == "max-points" and not math.isnan(float(ds.gamma.values[-1]))
    assert ds.point_status.values[-1] == PointStatus.STOPPED.value
    assert "not computed" in ds.attrs["message"]


@pytest.mark.parametrize("model,eta,beta", [("iwan", 0.01, 0.1), ("iwan", 10.0, 0.1), ("iwan", 0.5, 2.0),
                                            ("iwan", 1.5, 5.0), ("iwan-closed", 0.01, 1000.0),
                                            ("iwan-paper", 1.5, 10.0), ("jenkins", 1.5, 1.0)])
def test_robustness_grid_subset(model, eta, beta):
    # docs/hb-robustness.md: covered (or unbounded below Den Hartog's bound, beta = 0.1) and the highest
    # peak within 1 % of the time domain started on the HB orbit
    from jointdyn.validation.hb_grid import grid_case, grid_table

    c = grid_case(model, eta, beta)
    assert c.covered and c.ok, c.message
    assert c.status == ("unbounded" if beta < math.pi / 4 else "complete")
    if beta > math.pi / 4:
        assert abs(c.peak_error) <= tolerances.TEST_HB_VS_TIME_RTOL
    row = grid_table([c]).splitlines()[2]
    assert row.startswith(f"| {model} | {eta:g} | {beta:g} | {c.status} |") and row.endswith("| yes |")



def test_grid_cases_on_processes_equal_the_cases_in_turn():
    # grid_cases with two worker processes: the same branches, in the order asked, as one after the other
    from jointdyn.validation.hb_grid import grid_cases

    cases = [(config.MODEL, 0.5, 1000.0), ("jenkins", 0.01, 2.0), (config.MODEL, 1.5, 2.0)]
    par = grid_cases(cases, time_domain=False, workers=2)
    seq = grid_cases(cases, time_domain=False)
    assert [(c.model, c.eta, c.beta) for c in par] == cases
    for a, b in zip(par, seq):
        assert (a.status, a.points, a.harmonics, a.samples) == (b.status, b.points, b.harmonics, b.samples)
        assert a.peak_q == b.peak_q and a.peak_gamma == b.peak_gamma
    with pytest.raises(ValueError, match="workers"):
        grid_cases(cases, workers=0)


def test_grid_does_not_compare_a_subharmonic_time_domain_orbit():
    # the full-memory closed form at eta = 0.5, beta = 5: the time-domain steady state at the HB peak repeats
    # every 4 forcing periods, so the period-one HB peak (q 1.436 against 1.371) is marked not compared, not passed
    from jointdyn.validation.hb_grid import Verdict, grid_case, grid_table

    c = grid_case("iwan-closed", 0.5, 5.0)
    assert c.covered and c.verdict is Verdict.SUBHARMONIC and c.time_period > 1 and not c.ok
    assert math.isnan(c.peak_error) and grid_table([c]).splitlines()[2].endswith("| n/c |")


def test_a_finer_sampling_whose_branch_fails_is_followed_by_the_next():
    # the full-memory closed form at eta = 0.5, beta = 2: its force jumps with the normal load, the peak check
    # asks for 512 samples, where the corrector fails near the resonance (it completes with 128, 256 and 1024)
    ds = frc_hb(System.paper_damper(eta=0.5, beta=2.0, model="iwan-closed"), 0.6, 1.8, max_step=0.01)
    levels = ds.attrs["discretisation_levels"].split(", ")
    assert ds.attrs["status"] == "complete" and ds.sizes["peak"] >= 1
    assert f"{config.HB_HARMONICS}x512" in levels and levels[-1] != f"{config.HB_HARMONICS}x512"

def test_failed_branch_exits_3_and_names_where(capsys, tmp_path):
    # a real failure (the paper's closed form at eta = 1.5, beta = 1: its force jumps near gamma 1.06, and
    # Newton fails at the start, with 7 harmonics and 128 samples; the automatic choice takes more samples and
    # completes): exit status 3, files written, no repeated rows, the message names where
    rc, out, err = _cli_hb(capsys, "--model", "iwan-paper", "--eta", "1.5", "--beta", "1", "--harmonics", "7",
                           "--samples", "128", out=tmp_path)
    assert rc == EXIT_INCOMPLETE
    assert out["status"] == "failed" and out["uncovered"]
    assert "failed" in err and "near gamma" in err and "not computed for gamma" in out["message"]
    for br in out["branches"]:
        rows = list(zip(br["gamma"], br["amplitude_m"]))
        assert all(r != s for r, s in zip(rows, rows[1:]))
    assert any(s == "stopped" for br in out["branches"] for s in br["point_status"])
    assert (tmp_path / "frc.png").stat().st_size > 0


def test_table_marks_the_stopped_point_and_lists_the_peaks(capsys, monkeypatch):
    from jointdyn import hb

    real = hb.continue_hb
    monkeypatch.setattr(hb, "continue_hb", lambda *a, **k: real(*a, max_points=40, **k))
    rc = main(["frc", "--method", "hb", "--gamma", "1.0:1.8:0.01", "--eta", "0.5", "--beta", "2"])
    cap = capsys.readouterr()
    assert rc == EXIT_INCOMPLETE
    lines = cap.out.splitlines()
    assert lines[0].startswith("status: max-points") and lines[1].startswith("branch 0: 40 points")
    rows = [r for r in lines if r.startswith("  ")]
    assert rows[0].endswith("start") and rows[-1].endswith("stopped") and len(rows) == 40
    assert all(r.split()[-1] in ("stable", "unstable") for r in rows[1:-1])
    assert "incomplete: max-points" in cap.err


def test_stable_zigzags_of_a_closed_form_are_not_folds():
    # the paper's closed form at eta = 0.5, beta = 1 turns back 16 times by 1e-5 to 1e-4 in gamma near
    # gamma 1.031-1.035 (jumps of its force), with stable points all around: no fold, and the time domain
    # agrees, its up and down sweeps do not jump apart there
    from jointdyn.sweeps import frc_sweep, to_frame

    system = System.paper_damper(eta=0.5, beta=1.0, model="iwan-paper")
    ds = frc_hb(system, 0.6, 1.8, max_step=0.01)
    assert ds.attrs["status"] == "complete" and ds.attrs["folds"] == 0 and ds.stable.values.all()
    g = np.round(np.arange(1.028, 1.0381, 0.002), 6)
    td = to_frame(frc_sweep(g, etas=(0.5,), betas=(1.0,), model="iwan-paper", directions=("up", "down"),
                            progress=False, n_workers=1))
    up = td[td.direction == "up"].sort_values("gamma").amplitude_q.to_numpy()
    dn = td[td.direction == "down"].sort_values("gamma").amplitude_q.to_numpy()
    assert np.all(np.abs(up - dn) <= tolerances.TEST_HB_VS_TIME_RTOL * dn)


# --- automatic choice of harmonics and samples (the default: harmonics="auto", samples="auto")


@pytest.mark.parametrize("eta,beta", [(10.0, 5.0), (10.0, 10.0), (1.5, 1000.0), (10.0, 1000.0)])
def test_default_model_with_separation_matches_the_time_domain(eta, beta):
    # with 7 harmonics and 128 samples projected uniformly the peaks are 2.6 % and 5.8 % above the time domain
    # at eta 10, beta 5 and 10, and at beta = 1000 (the contact slips only in the last ~0.002 rad before
    # separation) the peak changes by 0.4 % from level to level up to 15 x 2048 with the corner terms alone:
    # the phases graded towards separation (jointdyn.fourier.separation_grid) resolve that slip, and the first
    # level passes the check
    from jointdyn.validation.hb_grid import grid_case

    c = grid_case(config.MODEL, eta, beta)
    assert c.status == "complete" and c.ok, c.message
    assert abs(c.peak_error) <= tolerances.TEST_HB_VS_TIME_RTOL
    assert (c.harmonics, c.samples) == (config.HB_HARMONICS, config.HB_SAMPLES)


def test_auto_peak_is_converged_in_harmonics_and_samples():
    # oracle: harmonic balance solved afresh at the peak with twice the harmonics and twice the samples
    # (eta = 0.01, beta = 1: the check of the first level asks for 256 samples)
    system = System.paper_damper(eta=0.01, beta=1.0)
    ds = frc_hb(system, 0.6, 1.8, max_step=0.01)
    a = ds.attrs
    assert a["harmonics_choice"] == a["samples_choice"] == "auto" and a["check_converged"] == 1
    assert a["check_peaks"] == ds.sizes["peak"] >= 1
    assert a["discretisation_levels"].startswith(f"{config.HB_HARMONICS}x{config.HB_SAMPLES}, ")
    assert a["discretisation_levels"].endswith(f"{a['harmonics']}x{a['samples']}")
    assert max(a["check_harmonics_change"], a["check_samples_change"]) <= config.HB_AUTO_RTOL
    H, Ns = 2 * a["harmonics"] + 1, 2 * a["samples"]
    top = ds.peak_amplitude_m.values.max()  # the changes are measured against the highest peak
    for g, amp in zip(ds.peak_gamma.values, ds.peak_amplitude_m.values):
        sol = harmonic_balance(system, float(g), harmonics=H, samples=Ns, response_dof=system.response_dof)
        assert sol.status.ok
        assert abs(amp - sol.amplitude_m) <= tolerances.TEST_HB_AUTO_CONVERGED_RTOL * top


def test_auto_keeps_a_converged_branch_as_it_is():
    # the paper damper's benchmark case: 7 harmonics and 128 samples pass the check, so the branch is the
    # one computed with them, bit for bit, and only the check solves are added
    system = System.paper_damper(eta=0.5, beta=2.0)
    auto = frc_hb(system, 0.6, 1.8)
    fixed = frc_hb(system, 0.6, 1.8, harmonics=config.HB_HARMONICS, samples=config.HB_SAMPLES)
    assert auto.attrs["discretisation_levels"] == f"{config.HB_HARMONICS}x{config.HB_SAMPLES}"
    assert auto.attrs["check_converged"] == 1 and auto.attrs["check_peaks"] >= 1
    assert auto.attrs["check_harmonics"] == 2 * config.HB_HARMONICS + 1
    assert auto.attrs["check_samples"] == 2 * config.HB_SAMPLES
    np.testing.assert_array_equal(auto.amplitude_q.values, fixed.amplitude_q.values)
    np.testing.assert_array_equal(auto.peak_amplitude_q.values, fixed.peak_amplitude_q.values)
    assert fixed.attrs["harmonics_choice"] == fixed.attrs["samples_choice"] == "fixed"
    assert "check_converged" not in fixed.attrs


def test_a_peak_that_asks_for_more_stops_the_coarse_branch(monkeypatch):
    # Jenkins at eta = 0.5, beta = 1 (the CLI's benchmark case): the peak near gamma 1.06 asks for 256 samples.
    # The branch with 128 stops once past that peak (the rest of it would be discarded), the branch with 256
    # confirms the stop, and the branch returned is the one computed with 256, bit for bit
    from jointdyn.hb import discretisation as hb_disc

    made = []
    real = hb_disc._fixed_branch
    monkeypatch.setattr(hb_disc, "_fixed_branch", lambda *a, **k: made.append(real(*a, **k)) or made[-1])
    system = System.paper_damper(eta=0.5, beta=1.0, model="jenkins")
    auto = frc_hb(system, 0.6, 1.8, max_step=0.01)
    assert auto.attrs["discretisation_levels"] == f"{config.HB_HARMONICS}x{config.HB_SAMPLES}, " \
                                                  f"{config.HB_HARMONICS}x{2 * config.HB_SAMPLES}"
    assert auto.attrs["check_converged"] == 1 and auto.attrs["status"] == "complete"
    stop = made[0]
    assert isinstance(stop, hb_disc._Refine) and stop.level == (config.HB_HARMONICS, 2 * config.HB_SAMPLES)
    assert abs(stop.peak.lam - float(auto.peak_gamma.values[0])) < 0.01
    fixed = frc_hb(system, 0.6, 1.8, max_step=0.01, harmonics=config.HB_HARMONICS, samples=2 * config.HB_SAMPLES)
    np.testing.assert_array_equal(auto.amplitude_q.values, fixed.amplitude_q.values)
    np.testing.assert_array_equal(auto.gamma.values, fixed.gamma.values)
    np.testing.assert_array_equal(auto.peak_amplitude_q.values, fixed.peak_amplitude_q.values)


def test_a_stop_the_finished_branch_does_not_confirm_is_undone(monkeypatch):
    # with every local maximum checked as soon as the amplitude falls (drop 1), the full-memory closed form at
    # eta = 0.5, beta = 2 stops at a wiggle near gamma 0.652, six times lower than its resonance, whose change
    # is within the tolerance of the resonance's amplitude: the finished branch does not confirm the stop and
    # the choice is made again without stops, giving the branch of the default drop, which checks only passed
    # resonances
    from jointdyn.hb import discretisation as hb_disc

    system = System.paper_damper(eta=0.5, beta=2.0, model="iwan-closed")
    default = frc_hb(system, 0.6, 1.8, max_step=0.01)
    made = []
    real = hb_disc._fixed_branch
    monkeypatch.setattr(hb_disc, "_fixed_branch", lambda *a, **k: made.append(real(*a, **k)) or made[-1])
    every = frc_hb(system, 0.6, 1.8, max_step=0.01, hb_options=HBOptions(auto_early_drop=1.0))
    assert isinstance(made[0], hb_disc._Refine) and made[0].peak.lam < 0.7
    assert any(not isinstance(m, hb_disc._Refine) and m.status.value == "failed" for m in made)
    assert every.attrs["status"] == default.attrs["status"] == "complete"
    assert every.attrs["discretisation_levels"] == default.attrs["discretisation_levels"]
    np.testing.assert_array_equal(every.amplitude_q.values, default.amplitude_q.values)


def test_auto_at_its_bound_says_it_is_not_converged():
    # with the samples bounded at their start, the check of eta = 0.01, beta = 1 fails and the branch says so
    ds = frc_hb(System.paper_damper(eta=0.01, beta=1.0), 0.6, 1.8, max_step=0.01,
                hb_options=HBOptions(auto_max_samples=config.HB_SAMPLES))
    assert ds.attrs["check_converged"] == 0 and ds.attrs["samples"] == config.HB_SAMPLES
    assert ds.attrs["check_samples_change"] > config.HB_AUTO_RTOL
    assert "not converged in the discretisation" in ds.attrs["message"]


def test_harmonics_and_samples_refuse_other_words(capsys):
    with pytest.raises(ValueError, match="harmonics"):
        frc_hb(System.paper_damper(), 0.6, 1.8, harmonics="many")
    with pytest.raises(ValueError, match="samples"):
        frc_hb(System.paper_damper(), 0.6, 1.8, harmonics=7, samples=10)
    assert main(["frc", "--method", "hb", "--gamma", GRID, "--samples", "3"]) == 2
    # the same rule as the Python API's: at least 2H + 2 samples of the first H (config.HB_HARMONICS when auto)
    assert f"--samples must be an integer >= {2 * config.HB_HARMONICS + 2} or 'auto'" in capsys.readouterr().err


def test_cli_reports_the_discretisation(capsys):
    rc, out, _ = _cli_hb(capsys, "--eta", "0.5", "--beta", "2", "--harmonics", "auto")
    assert rc == 0 and out["harmonics"] == config.HB_HARMONICS and out["samples"] == config.HB_SAMPLES
    d = out["discretisation"]
    assert d["harmonics_choice"] == "auto" and d["check_converged"] == 1
    assert d["check_harmonics_change"] <= config.HB_AUTO_RTOL
    rc, out, _ = _cli_hb(capsys, "--eta", "0.5", "--beta", "2", "--harmonics", "5", "--samples", "64")
    assert rc == 0 and (out["harmonics"], out["samples"]) == (5, 64)
    assert out["discretisation"]["harmonics_choice"] == "fixed"


def test_separation_corners_make_few_samples_accurate():
    # Jenkins at eta = 1.5, beta = 1000 (open about a quarter of the period): the force's corners at
    # separation and re-contact, projected with the re-contact corners taken into account and the phases graded
    # towards separation (jointdyn.fourier.separation_grid), leave 128 samples within 1e-6 of 4096 (the uniform
    # projection: 1.7e-3) and the force's coefficients at one X within 1e-8 of max |T| of 16384 samples;
    # oracle: the same problem with 32 and 128 times the samples
    from jointdyn.hb.problem import HBProblem

    system = System.paper_damper(eta=1.5, beta=1000.0, model="jenkins")
    q = {Ns: harmonic_balance(system, 1.3034, samples=Ns) for Ns in (128, 4096)}
    assert abs(q[128].amplitude_m - q[4096].amplitude_m) <= 1e-6 * q[4096].amplitude_m
    X = q[4096].X
    F = {}
    for Ns in (128, 16384):
        p = HBProblem(system, samples=Ns)
        F[Ns] = p.evaluate(X, 1.3034).R - p.linear_matrix(p.omega(1.3034)) @ X + p.forcing(p.f_dir * p.f1_ref)
        assert p._uniform is not None and p._taug.size > Ns  # graded phases added
    T = HBProblem(system, samples=128).evaluate(X, 1.3034).T
    assert np.abs(F[128] - F[16384]).max() <= 1e-8 * np.abs(T).max()
    p = HBProblem(System.paper_damper(eta=0.5, beta=2.0), samples=128)
    assert p._uniform is None and p._Pg is fourier_matrices(p.H, 128)[1]  # no separation: the uniform projection


def test_grid_folds_are_jumps_of_time_domain_sweeps():
    """The closed form's folds at eta 1.5, beta 2 (grid case): time-domain
    sweeps up and down settle on different periodic orbits between them;
    a branch without folds has nothing to check."""
    from jointdyn.validation.hb_folds import FoldVerdict, fold_check

    c = fold_check("iwan-closed", 1.5, 2.0)
    assert c is not None and len(c.folds) >= 2
    assert c.verdict is FoldVerdict.CONFIRMED
    assert all(c.folds[0] < g < c.folds[-1] for g in c.inside_apart) and len(c.inside_apart) >= 3
    # away from the folds (the closed form's time-domain jump lies within 3e-4 of the HB fold) one orbit:
    outside = [i for i, g in enumerate(c.gammas) if g < c.folds[0] - 1e-3 or g > c.folds[-1] + 1e-3]
    assert len(outside) >= 2
    for i in outside:
        assert abs(c.q_up[i] - c.q_down[i]) <= 0.02 * abs(c.q_down[i])
    assert fold_check("iwan", 0.5, 2.0) is None


def test_grid_finds_the_peak_the_continuation_jumped_over():
    """Jenkins at eta 10, beta 5: the continuation stalls at gamma 1.2007 and
    jumps to 1.2107, over the resonance the time domain finds near 1.202 at
    q 9.69. Continued back from the jump's end, the branch reaches the peak;
    it agrees with the time-domain steady state there."""
    from jointdyn.validation.hb_grid import Verdict, grid_case

    c = grid_case("jenkins", 10.0, 5.0)
    assert c.covered and c.verdict is Verdict.AGREES and c.ok
    assert 1.200 < c.peak_gamma < 1.203 and abs(c.peak_q - 9.69) <= 0.01 * 9.69
    assert abs(c.peak_q - c.time_q) <= 0.01 * c.time_q


def test_grid_flags_a_highest_amplitude_at_a_jump_above_every_peak():
    """The grid's 'peak in a jump': the branch's highest point is one end of a
    jump and no peak found reaches it (a secondary peak elsewhere does not
    hide the missed resonance); a peak at least as high clears it."""
    import xarray as xr

    from jointdyn.validation.hb_grid import _highest_at_jump

    q = np.array([0.5, 0.6, 0.55, 1.0, 1.4, 0.9, 0.8])
    status = np.array(["start", "joined", "joined", "joined", "joined", "after-jump", "joined"])
    ds = xr.Dataset({"amplitude_q": ("point", q), "point_status": ("point", status)})
    assert _highest_at_jump(ds, math.nan)  # no peak at all
    assert _highest_at_jump(ds, 0.6)  # only the small bump at the second point
    assert not _highest_at_jump(ds, 1.4)
    ds_mid = xr.Dataset({"amplitude_q": ("point", q), "point_status": ("point", np.roll(status, 2))})
    assert not _highest_at_jump(ds_mid, 0.6)  # the highest point joined on both sides


def test_a_peak_the_branch_reaches_only_from_one_side_is_reported_at_the_stop(capsys):
    """Jenkins at eta 10, beta 5, 7 harmonics and 128 samples: the left flank of
    the resonance stalls at gamma 1.2007, q 9.37, and the continuation jumps to
    1.2107. Continued back over the jump, the branch climbs the right flank to
    q 9.70 near gamma 1.2012 and cannot be followed past that point: the peak
    is reported there, found at a stop (not refined). Oracles: no
    harmonic-balance solution solved afresh between the jump's ends is higher,
    the time-domain steady states from rest next to it lie below it (1.2008:
    q 9.37 on the left flank; 1.203: q 9.68 on the right one), and so does the
    point the jump left."""
    from jointdyn.dynamics import steady_state
    from jointdyn.hb import continue_hb

    system = System.paper_damper(eta=10.0, beta=5.0, model="jenkins")
    law = system.contacts[0].law
    br = continue_hb(system, 0.6, 1.8, max_step=0.01, harmonics=7, samples=128)
    assert br.status == "complete" and "traced back from the point after a jump" in br.message
    top = max(br.peaks, key=lambda pk: pk.amplitude_q)
    assert top.at_stop and not top.refined and top.segment >= 1
    assert 1.2008 < top.gamma < 1.2020 and top.amplitude_q > 9.6
    first = int(np.flatnonzero(br.gap & (br.segment == 0))[0])
    assert br.point_status[first] == PointStatus.AFTER_JUMP
    left, after = br.lam[first - 1], br.lam[first]
    assert left < top.gamma < after
    # the point the jump left is lower
    assert br.problem.amplitudes(br.X[first - 1], 0)[0] * law.kt / law.fy < top.amplitude_q - 0.2
    # harmonic balance afresh between the jump's ends, from the peak's coefficients: nothing higher
    solved = 0
    for g in np.linspace(left, after, 9):
        sol = harmonic_balance(system, float(g), harmonics=7, samples=128, guess=top.X)
        if sol.status.ok:
            solved += 1
            assert law.kt * sol.amplitude_m / law.fy <= top.amplitude_q * (1 + 1e-6)
    assert solved >= 3
    for g, lo in ((1.2008, 9.3), (1.203, 9.6)):
        ss = steady_state(system, g)
        assert ss.status == "periodic" and ss.period_multiple == 1
        assert lo < law.kt * ss.amplitude_m / law.fy < top.amplitude_q
    # reported as such in the CLI's JSON
    rc, out, _ = _cli_hb(capsys, "--model", "jenkins", "--eta", "10", "--beta", "5", "--harmonics", "7",
                         "--samples", "128")
    assert rc == 0 and any(pk["at_stop"] and not pk["refined"] for pk in out["peaks"])


@pytest.mark.parametrize("eta,beta", [(0.5, 2.0), (1.5, 5.0)])
def test_extrapolated_corrector_start_keeps_the_branch(eta, beta):
    # the default law has a smooth force at the onset of slip: each correction starts from the branch's
    # extrapolation, on the same hyperplane as the tangent prediction, so the branch has the same points,
    # the same peaks and the same discretisation, in fewer residual evaluations
    from jointdyn.continuation import ContinuationOptions
    from jointdyn.hb import continue_hb

    s = System.paper_damper(eta=eta, beta=beta)
    on = continue_hb(s, 0.6, 1.8, max_step=0.01, progress=False)
    off = continue_hb(s, 0.6, 1.8, max_step=0.01, progress=False,
                      options=ContinuationOptions(start_extrapolation=0.0))
    assert on.status is off.status and on.lam.size == off.lam.size
    assert (on.problem.H, on.problem.Ns) == (off.problem.H, off.problem.Ns)
    # the points agree to Newton's tolerance, carried along the branch (each hyperplane is placed from
    # the point before): a few 1e-8 in gamma
    scale = np.abs(off.X).max()
    assert np.abs(on.lam - off.lam).max() < 1e-7 and np.abs(on.X - off.X).max() < 1e-6 * scale
    assert len(on.peaks) == len(off.peaks) >= 1
    for p, q in zip(on.peaks, off.peaks):
        assert p.gamma == pytest.approx(q.gamma, abs=1e-7) and p.amplitude_q == pytest.approx(q.amplitude_q, rel=1e-7)
    assert on.counters["residual_evaluations"] < 0.9 * off.counters["residual_evaluations"]


def test_laws_with_a_kink_at_slip_start_corrections_from_the_prediction():
    # Jenkins has a stick-slip kink: harmonic balance leaves the option at None (tangent prediction),
    # the branch is the one computed with the extrapolation switched off, bit for bit
    from jointdyn.continuation import ContinuationOptions
    from jointdyn.hb import continue_hb
    from jointdyn.laws import Iwan, Jenkins

    assert Iwan.smooth_force and not Jenkins.smooth_force
    s = System.paper_damper(eta=0.5, beta=1.0, model="jenkins")
    a = continue_hb(s, 0.6, 1.8, harmonics=7, samples=128, progress=False)
    b = continue_hb(s, 0.6, 1.8, harmonics=7, samples=128, progress=False,
                    options=ContinuationOptions(start_extrapolation=0.0))
    assert np.array_equal(a.lam, b.lam) and np.array_equal(a.X, b.X)
    assert a.counters["residual_evaluations"] == b.counters["residual_evaluations"]
