"""Nonlinear modes: the validation tables of docs/modes.md.

Usage::

    PYTHONPATH=src python docs/scripts/modes_tables.py [--write]

On the paper's damper at its constant normal load (m = 10 kg, k = 3.9e5
N/m, kt = 3e5 N/m, fy = mu N0 = 50 N, no viscous damping), computes:

* ``df``: one-harmonic EPMC backbones (1e-2 to 1e2 fy/kt) of the exact
  Iwan contact and of one Jenkins element against the describing function
  of the exact steady loop (plain-Python quadrature of the tests,
  ``tests/reference_modes.py``), and the energy balance of the damping
  ratio;
* ``harmonics``: frequency and damping ratio at a few amplitudes for
  H = 1, 3, 5, 7, 9, 11, 15 (512 samples), relative to H = 15;
* ``tmdsimpy``: the largest relative differences to tmdsimpy's EPMC
  (``tests/reference_tmdsimpy.py``) at the same discretisation and at the
  defaults;
* ``qsma``: QSMA against the EPMC (H = 7) at a few amplitudes;
* ``synthesis``: the peak of the single-nonlinear-mode forced response
  against full harmonic balance (eta = 0, beta = 1, 2, 5, 10);
* ``limits``: the linear stuck limit and the slipping limit.

With ``--write`` the tables replace the blocks between the markers
``<!-- NAME:start -->`` and ``<!-- NAME:end -->`` in ``docs/modes.md``.
"""

from __future__ import annotations

import argparse
import math
import sys
from pathlib import Path

import numpy as np

import jointdyn as jd
from jointdyn._io import atomic_write_text
from jointdyn.hb import frc_hb
from jointdyn.modes import epmc, qsma, single_mode_frc

PAGE = Path(__file__).resolve().parents[1] / "modes.md"
# the independent references of the tests (one copy of each)
sys.path.insert(0, str(Path(__file__).resolve().parents[2] / "tests"))
import reference_modes as ref  # noqa: E402
from reference_tmdsimpy import HARMONICS, SAMPLES, TMDSIMPY_JENKINS_EPMC  # noqa: E402

M_, K_, KT, FY = 10.0, 3.9e5, 3.0e5, 50.0
XS = FY / KT
HS = (1, 3, 5, 7, 9, 11, 15)
BACKBONES = {"jenkins": ref.jenkins_backbone(KT, FY), "iwan": ref.iwan_backbone(KT, FY)}
DF_SAMPLES = {"jenkins": 8192, "iwan": 4096}


def _damper(model="iwan", **kw):
    return jd.System.paper_damper(eta=0.0, model=model, **kw)


def _solve_at(b, amplitude):
    """(omega, D) of an EPMC backbone solved at exactly ``amplitude`` (m)."""
    p = b.problem
    i = int(np.argmin(np.abs(np.log(b.amplitude_m / amplitude))))
    v, ok, _ = p.solve(amplitude, p.pack(b.X[i], b.omega_rad_s[i], b.xi_rad_s[i]))
    assert ok
    _, w, xi = p.unpack(v, math.log10(amplitude))
    return w, xi / (2.0 * w)


def df_table() -> str:
    lines = ["| contact | samples | points | max rel. error omega | max rel. error D | max rel. error E "
             "| max energy-balance error of D |", "|---|---|---|---|---|---|---|"]
    for model in ("iwan", "jenkins"):
        b = epmc(_damper(model), (1e-2 * XS, 1e2 * XS), harmonics=1, samples=DF_SAMPLES[model], progress=False)
        tb, kinks = BACKBONES[model]
        ew = eD = eE = 0.0
        for a, w, D, E in zip(b.amplitude_m, b.omega_rad_s, b.damping_ratio, b.energy_contact_J[:, 0]):
            w_ref, D_ref, E_ref = ref.describing_function(M_, K_, tb, kinks, a)
            ew = max(ew, abs(w / w_ref - 1))
            if D_ref > 1e-12:
                eD = max(eD, abs(D / D_ref - 1))
                eE = max(eE, abs(E / E_ref - 1))
        slip = b.damping_ratio > 1e-12
        bal = np.max(np.abs(b.damping_ratio_contacts + b.damping_ratio_viscous - b.damping_ratio)[slip]
                     / b.damping_ratio[slip])
        lines.append(f"| {model} | {DF_SAMPLES[model]} | {b.points} | {ew:.1e} | {eD:.1e} | {eE:.1e} | {bal:.1e} |")
    return "\n".join(lines)


def harmonics_table() -> str:
    cases = (("iwan", 0.3), ("iwan", 1.0), ("iwan", 3.0), ("iwan", 30.0), ("jenkins", 1.5), ("jenkins", 3.0),
             ("jenkins", 30.0))
    lines = ["| contact | kt a / fy | omega (H=15), rad/s | D (H=15) | "
             + " | ".join(f"H={h}" for h in HS[:-1]) + " |", "|" + "---|" * (3 + len(HS))]
    for model, q in cases:
        res = {}
        for h in HS:
            b = epmc(_damper(model), (0.999 * q * XS, q * XS), harmonics=h, samples=512, progress=False)
            assert b.status.ok, (model, q, h, b.message)
            res[h] = (b.omega_rad_s[-1], b.damping_ratio[-1])
        w15, d15 = res[HS[-1]]
        cells = [f"{res[h][0] / w15 - 1:+.0e} / {res[h][1] / d15 - 1:+.0e}" for h in HS[:-1]]
        lines.append(f"| {model} | {q:g} | {w15:.6g} | {d15:.5g} | " + " | ".join(cells) + " |")
    return "\n".join(lines)


def tmdsimpy_table() -> str:
    amps = np.array([r[0] for r in TMDSIMPY_JENKINS_EPMC])
    lines = ["| jointdyn discretisation | max rel. diff. omega | max rel. diff. D (slipping points) |",
             "|---|---|---|"]
    for h, ns in ((HARMONICS, SAMPLES), (jd.config.HB_HARMONICS, jd.config.HB_SAMPLES)):
        b = epmc(_damper("jenkins"), (0.99 * amps[0], 1.01 * amps[-1]), harmonics=h, samples=ns, progress=False)
        ew = eD = 0.0
        for a, w_ref, D_ref in TMDSIMPY_JENKINS_EPMC:
            w, D = _solve_at(b, a)
            ew = max(ew, abs(w / w_ref - 1))
            if D_ref > 1e-12:
                eD = max(eD, abs(D / D_ref - 1))
        lines.append(f"| H = {h}, {ns} samples | {ew:.1e} | {eD:.1e} |")
    return "\n".join(lines)


def qsma_table() -> str:
    qs = (0.03, 0.3, 1.0, 3.0, 10.0, 100.0)
    lines = ["| contact | kt a / fy | omega EPMC, rad/s | omega QSMA / EPMC - 1 | D EPMC | D QSMA / EPMC - 1 |",
             "|---|---|---|---|---|---|"]
    for model in ("iwan", "jenkins"):
        s = _damper(model)
        b = epmc(s, progress=False)
        for q in qs:
            a = q * XS
            w, D = _solve_at(b, a)
            qb = qsma(s, (0.5 * a, a))  # the push ends exactly at a
            i = qb.points - 1
            assert qb.status.ok and abs(qb.amplitude_m[i] / a - 1) < 1e-9, (qb.amplitude_m[i], a)
            dq = (f"{qb.damping_ratio[i] / D - 1:+.1e}" if D > 1e-12
                  else f"(stuck: D = {qb.damping_ratio[i]:.0e} by QSMA)")
            lines.append(f"| {model} | {q:g} | {w:.6g} | {qb.omega_rad_s[i] / w - 1:+.1e} | {D:.4g} | {dq} |")
    return "\n".join(lines)


def synthesis_table() -> str:
    lines = ["| beta | peak a, HB (um) | peak a, synthesis (um) | rel. diff. | peak gamma, HB | "
             "peak gamma, synthesis | rel. diff. |", "|---|---|---|---|---|---|---|"]
    for beta in (1.0, 2.0, 5.0, 10.0):
        s = jd.System.paper_damper(eta=0.0, beta=beta)
        ds = single_mode_frc(epmc(s, progress=False))
        hb = frc_hb(s, 0.8, 1.6, progress=False, ds_max=0.01)
        a = hb.harmonic_amplitude_m.values[:, 1]
        i = int(np.argmax(a))
        a_s, g_s = ds.attrs["peak_amplitude_m"], ds.attrs["peak_gamma"]
        g_h = float(hb.gamma.values[i])
        lines.append(f"| {beta:g} | {a[i] * 1e6:.5g} | {a_s * 1e6:.5g} | {a_s / a[i] - 1:+.1e} | {g_h:.5g} | "
                     f"{g_s:.5g} | {g_s / g_h - 1:+.1e} |")
    return "\n".join(lines)


def limits_table() -> str:
    w_stuck, w_slip = math.sqrt((K_ + KT) / M_), math.sqrt(K_ / M_)
    lines = ["| contact | omega / sqrt((k + kt)/m) - 1 at 1e-7 fy/kt | D at 1e-7 fy/kt | "
             "omega / sqrt(k/m) - 1 at 1e4 fy/kt | D a pi k / (2 fy) - 1 at 1e2, 1e3, 1e4 fy/kt |",
             "|---|---|---|---|---|"]
    for model in ("iwan", "jenkins"):
        lo = epmc(_damper(model), (1e-7 * XS, 1e-6 * XS), progress=False)
        hi = epmc(_damper(model), (10 * XS, 1e4 * XS), progress=False)
        errs = []
        for q in (1e2, 1e3, 1e4):
            w, D = _solve_at(hi, q * XS)
            errs.append(f"{D * q * XS * math.pi * K_ / (2 * FY) - 1:+.1e}")
        lines.append(f"| {model} | {lo.omega_rad_s[0] / w_stuck - 1:+.1e} | {lo.damping_ratio[0]:.1e} | "
                     f"{w / w_slip - 1:+.1e} | {', '.join(errs)} |")
    return "\n".join(lines)


TABLES = {"df": df_table, "limits": limits_table, "harmonics": harmonics_table, "tmdsimpy": tmdsimpy_table,
          "qsma": qsma_table, "synthesis": synthesis_table}


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__)
    ap.add_argument("--write", action="store_true", help="update docs/modes.md")
    ap.add_argument("--only", action="append", choices=sorted(TABLES), help="compute only these tables")
    args = ap.parse_args(argv)
    tables = {}
    for k, f in TABLES.items():
        if not args.only or k in args.only:
            tables[k] = f()
            print(f"{k}:\n{tables[k]}\n", flush=True)
    if args.write:
        text = PAGE.read_text()
        for k, v in tables.items():
            a, b = f"<!-- {k}:start -->", f"<!-- {k}:end -->"
            i, j = text.index(a) + len(a), text.index(b)
            text = text[:i] + "\n" + v + "\n" + text[j:]
        atomic_write_text(PAGE, text)
    return 0


if __name__ == "__main__":
    sys.exit(main())
