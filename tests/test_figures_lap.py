"""The lap joint's figure (jointdyn.figures.lap) on a stretch where every pair sticks, against the linear
structure: the backbone is the linear mode of the plates with the loaded pairs stuck (frequency of the
shipped model, the plates' modal damping ratio), the forced response that mode's response to the force,
the slip maps all stuck; then the plot from those tables."""

from __future__ import annotations

import math

import numpy as np
import pytest

from jointdyn.figures import FIGURES, figure_names
from jointdyn.figures import lap
from jointdyn.figures.lap import lap_joint_data, lap_joint_system


@pytest.fixture(scope="module")
def stuck_tables():
    # a small force and small amplitudes: no pair reaches its slip limit
    return lap_joint_data(amplitude=(1e-7, 3e-7), maps=(2e-7,), force_n=4e-3)  # peak at about 1.7e-7 m


def test_stuck_backbone_is_the_linear_mode_with_the_loaded_pairs_stuck(stuck_tables):
    from jointdyn.fe import lap_joint

    bb = stuck_tables["backbone"]
    assert (bb.status == "complete").all() and len(bb) >= 2
    f1 = lap_joint().frequencies_hz["stuck"][0]  # the script's number, stored with the model
    np.testing.assert_allclose(bb.frequency_hz, f1, rtol=1e-6)
    np.testing.assert_allclose(bb.damping_ratio, lap.LAP_ZETA, rtol=1e-6)
    np.testing.assert_allclose(bb.damping_ratio_contacts, 0.0, atol=1e-12)
    slip = stuck_tables["slip"]
    on = slip.in_interface.astype(bool)
    assert on.sum() == 120 and (~on).sum() == 144
    assert (slip.stick[on] == 1.0).all() and slip.energy_J[on].abs().max() < 1e-18
    assert slip.stick[~on].isna().all()
    assert slip.converged.all()


def test_stuck_forced_response_is_the_linear_modes(stuck_tables):
    """Amplitude a(Omega) = |phi_out phi^T F| / |omega^2 - Omega^2 + 2 i zeta omega Omega| of the linear mode
    (mass-normalised phi) at every point of both flanks, and the peak between them."""
    from scipy.linalg import eigh

    system, lj = lap_joint_system(4e-3)
    frc = stuck_tables["frc"]
    assert (frc.status == "complete").all() and {-1, 0, 1} <= set(frc.flank)
    lam, phi = eigh(lj.linear_K("stuck"), lj.M, subset_by_index=[0, 0])
    w, v = math.sqrt(lam[0]), phi[:, 0]
    W = 2 * math.pi * frc.frequency_hz.to_numpy()
    a = abs(v[lj.output_dof] * (v @ system.force)) / np.abs(w * w - W * W + 2j * lap.LAP_ZETA * w * W)
    np.testing.assert_allclose(frc.amplitude_m, a, rtol=1e-6)
    peak = frc[frc.flank == 0]
    assert float(peak.frequency_hz.iloc[0]) == pytest.approx(w * math.sqrt(1 - 2 * lap.LAP_ZETA**2) / (2 * math.pi),
                                                             rel=1e-9)


def test_registered():
    assert "lap_joint" in figure_names()


def test_plot_from_the_tables(stuck_tables, tmp_path):
    import pandas as pd

    saved = {}
    for key, df in stuck_tables.items():  # as make_figure reads them back
        df.to_csv(tmp_path / f"{key}.csv", index=False)
        saved[key] = pd.read_csv(tmp_path / f"{key}.csv")
    paths = FIGURES["lap_joint"].plot(saved, tmp_path)
    assert {p.suffix for p in paths} == {".png", ".svg"} and all(p.stat().st_size > 0 for p in paths)
