"""The showcases of joints whose normal load comes from the structure: their data and files."""

import numpy as np
import pytest
import pandas as pd

import tolerances as C

from jointdyn.figures import figure_names, make_figure
from jointdyn.figures.joints import BLADE_PRELOADS


def test_normal_dof_light_equals_prescribed_and_heavy_differs(tmp_path):
    assert "normal_dof" in figure_names()
    paths = make_figure("normal_dof", tmp_path)
    df = pd.read_csv(tmp_path / "normal_dof_curves.csv")
    q = {case: sub.set_index("gamma") for case, sub in df.groupby("case")}
    pres, light, heavy = q["prescribed"], q["spring, light normal DOF"], q["spring, heavy normal DOF"]
    both = (pres.status == "periodic") & (light.status == "periodic")
    assert both.mean() > 0.95
    # a light normal DOF responds quasi-statically: the prescribed load's answer
    rel = np.abs(light.amplitude_q[both] / pres.amplitude_q[both] - 1.0)
    assert rel.max() <= C.TEST_SPRING_PRESCRIBED_RTOL
    # a normal DOF tuned to 2 w0 amplifies the normal load near resonance: a different answer
    ok = (pres.status == "periodic") & (heavy.status == "periodic")
    assert np.abs(heavy.amplitude_q[ok] / pres.amplitude_q[ok] - 1.0).max() > 10 * C.TEST_SPRING_PRESCRIBED_RTOL
    assert {p.suffix for p in paths} >= {".png", ".csv"}


def test_blade_damper_design_chart_has_an_interior_optimum(tmp_path):
    assert "blade_damper" in figure_names()
    make_figure("blade_damper", tmp_path)
    design = pd.read_csv(tmp_path / "blade_damper_design.csv").set_index("preload_N")
    limits = pd.read_csv(tmp_path / "blade_damper_limits.csv").set_index("limit")
    curves = pd.read_csv(tmp_path / "blade_damper_curves.csv")
    assert list(design.index) == list(BLADE_PRELOADS)
    best = design.peak_m.idxmin()
    assert BLADE_PRELOADS[0] < best < BLADE_PRELOADS[-1]
    # friction damping: every peak below the linear references, the optimum well below both ends
    # (the largest periodic response of either sweep: with separation the two sweeps jump at different places)
    assert (design.peak_m < limits.peak_m.min()).all()
    assert design.peak_m[best] < 0.6 * min(design.peak_m.iloc[0], design.peak_m.iloc[-1])
    # a large preload approaches the stuck damper's resonance frequency
    assert abs(design.gamma_peak.iloc[-1] / limits.gamma_peak["damper stuck"] - 1.0) < 0.01
    # points that are not periodic are labelled, never plotted as results
    assert set(curves.status) <= {"periodic", "not-settled", "unbounded"}
    assert (curves.status == "periodic").mean() > 0.9


def test_the_blade_example_file_is_the_figures_blade():
    from pathlib import Path

    import jointdyn as jd
    from jointdyn.figures.joints import blade_system

    path = Path(__file__).resolve().parents[1] / "examples" / "blade.toml"
    s, ref = jd.read_system(path), blade_system(20.0)
    for name in ("M", "K", "C", "force", "K_reference"):
        np.testing.assert_allclose(getattr(s, name), getattr(ref, name), rtol=1e-12, atol=1e-12 * np.abs(
            getattr(ref, name)).max())
    assert s.response_dof == ref.response_dof == 2 and s.w0 == pytest.approx(ref.w0, rel=1e-12)
    r, r_ref = jd.steady_state(s, 1.0), jd.steady_state(ref, 1.0)
    assert r.status == r_ref.status == "periodic" and r.amplitude_m == pytest.approx(r_ref.amplitude_m, rel=1e-9)
