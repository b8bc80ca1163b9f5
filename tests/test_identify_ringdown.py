"""Ring-down to backbone (jointdyn.backbone_from_ringdown, issue 32), checked against closed
forms (a linear free decay) and against the describing-function backbone of an SDOF with an
Iwan joint whose free decay jointdyn's own time integration computes; and bad data refused
with one clear error."""

from __future__ import annotations

import math

import numpy as np
import pytest

import jointdyn as jd
from jointdyn.identify.backbone import _model
from jointdyn.identify.ringdown import backbone_from_ringdown

W0 = 500.0
T0 = 2.0 * math.pi / W0


def _linear(zeta=0.0025, periods=150, per=64, kind="x"):
    t = np.arange(0.0, periods * T0, T0 / per)
    wd = W0 * math.sqrt(1.0 - zeta * zeta)
    x = np.exp(-zeta * W0 * t) * np.cos(wd * t)
    if kind == "x":
        return t, x
    # velocity of the same decay (d/dt of the closed form)
    return t, np.exp(-zeta * W0 * t) * (-zeta * W0 * np.cos(wd * t) - wd * np.sin(wd * t))


@pytest.mark.parametrize("kind", ["x", "v"])
def test_a_linear_decay_gives_its_damping_ratio_and_frequency(kind):
    t, y = _linear(kind=kind)
    b = backbone_from_ringdown(t, y, kind)
    assert b.amplitude_m.size >= 10
    # what is left of the filter's transients next to the trimmed ends: measured 1.2 % at the
    # first window, 0.4 % at the last; 3e-6 in the middle
    np.testing.assert_allclose(b.damping_ratio, 0.0025, rtol=0.015)
    n = b.amplitude_m.size
    np.testing.assert_allclose(b.damping_ratio[n // 4: 3 * n // 4], 0.0025, rtol=1e-4)
    np.testing.assert_allclose(b.omega_rad_s, W0 * math.sqrt(1 - 0.0025 ** 2), rtol=1e-3)
    # the envelope: exp(-zeta w0 t) at the window centres, m (velocity divided by omega)
    assert np.all(np.diff(b.amplitude_m) < 0.0)
    assert "trimmed" in b.message and b.trimmed_s[0] >= 10 * T0


def test_iwan_free_decay_by_time_integration_matches_its_backbone():
    """m = 2 kg, k = 4e5 N/m, Iwan kt = 1e5 N/m, fy = 20 N, zeta = 0.2 %, released from 3 slip
    displacements, 64 samples per period. Where the damping ratio changes slowly (amplitudes
    0.03 to 0.25 phi_max: measured within 1.3 %), the extracted frequency is within 0.5 % and
    the damping ratio within 5 % of the one-harmonic backbone. Closer to macroslip the damping
    ratio changes by much within one window (the slowly varying assumption fails, +6 % at
    0.23 phi_max) and is not checked here."""
    from jointdyn.dynamics.integrate import integrate_sampled

    law = jd.make_law("iwan", kt=1e5, mu=0.2, n_ref=100.0)
    m, k, zeta = 2.0, 4e5, 0.002
    system = jd.System.sdof(m=m, k=k, law=law, c=2 * zeta * math.sqrt((k + 1e5) * m))
    period = 2.0 * math.pi / math.sqrt((k + 1e5) / m)
    t = np.arange(0.0, 150 * period, period / 64)
    tr = integrate_sampled(system, t, np.zeros((t.size, 1)), np.full((t.size, 1), 100.0), x0=[3 * law.x_slip])
    x = tr.x[np.searchsorted(tr.t, t), 0]
    b = backbone_from_ringdown(t, x, "x")
    w_ref, D_ref = _model(law, k, zeta, m, b.amplitude_m)
    assert np.max(np.abs(b.omega_rad_s / w_ref - 1.0)) < 0.005
    ok = (b.amplitude_m > 0.03 * law.x_slip) & (b.amplitude_m < 0.25 * law.x_slip)
    assert np.count_nonzero(ok) >= 5
    assert np.max(np.abs(b.damping_ratio[ok] / D_ref[ok] - 1.0)) < 0.05


@pytest.mark.parametrize("case,word", [
    ("short", "shorter than"),
    ("aliased", "aliased"),
    ("steady", "no decay"),
    ("two", "two modes in the band"),
    ("kind", "kind must be one of"),
])
def test_bad_ringdowns_are_refused(case, word):
    t, x = _linear()
    kind = "x"
    if case == "short":
        t, x = t[:64 * 8], x[:64 * 8]
    elif case == "aliased":
        t, x = _linear(per=6)
    elif case == "steady":
        x = np.cos(W0 * t)
    elif case == "two":
        x = x + np.exp(-0.0025 * 1.08 * W0 * t) * np.cos(1.08 * W0 * t)
    else:
        kind = "displacement"
    with pytest.raises(ValueError, match=word):
        backbone_from_ringdown(t, x, kind)
