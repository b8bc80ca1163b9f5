"""One status vocabulary: every solver result carries ``status`` (with ``ok`` and ``message``) and
``message``; status values are hyphenated; the sweep codes are the steady-state statuses' own codes."""

from __future__ import annotations

import importlib
import pkgutil

import numpy as np
import pytest

import jointdyn
from jointdyn.status import Status


def _all_status_classes():
    for info in pkgutil.walk_packages(jointdyn.__path__, "jointdyn."):
        if not info.name.endswith("__main__"):  # running it would run the command line
            importlib.import_module(info.name)
    out, todo = [], list(Status.__subclasses__())
    while todo:
        cls = todo.pop()
        out.append(cls)
        todo.extend(cls.__subclasses__())
    return [c for c in out if c.__module__.startswith("jointdyn.")]


def test_every_status_value_is_hyphenated_and_has_a_message():
    classes = _all_status_classes()
    assert len(classes) >= 10  # the package's enumerations were found
    bad = [f"{c.__module__}.{c.__name__}.{m.name} = {m.value!r}" for c in classes for m in c
           if m.value != m.value.strip().lower() or " " in m.value or not m.message]
    assert not bad, "\n".join(bad)


def test_status_codes_round_trip():
    for cls in _all_status_classes():
        for m in cls:
            assert cls.from_code(m.code) is m


def _check(result, ok: bool):
    assert isinstance(result.status, Status)
    assert result.status.ok is ok
    assert isinstance(result.message, str) and result.message


def test_loop_result_has_a_status_and_a_message():
    from jointdyn.drivers import LoopStatus, harmonic_loop

    r = harmonic_loop(jointdyn.Jenkins(kt=1.0e5, mu=0.5, n_ref=100.0), 2.0e-4, n0=100.0, cycles=2, steps_per_cycle=64)
    _check(r, True)
    assert r.status is LoopStatus.OK and r.status == "ok" and r.message == LoopStatus.OK.message


def test_hb_solution_has_a_status_and_a_message():
    from jointdyn.hb import SolveStatus, harmonic_balance

    system = jointdyn.System.paper_damper(eta=0.5, beta=1.0, model="jenkins")
    sol = harmonic_balance(system, 0.8, harmonics=3, samples=64)
    _check(sol, True)
    assert sol.status.ok and sol.status is SolveStatus.CONVERGED and "max |R|" in sol.message
    bad = harmonic_balance(system, 0.8, harmonics=3, samples=64, max_iter=1,
                           guess=np.ones(sol.X.size) * 1e-2)
    _check(bad, False)
    assert not bad.status.ok and bad.status is SolveStatus.NOT_CONVERGED


def test_steady_state_says_message_and_keeps_detail_as_an_alias():
    from jointdyn.dynamics import integrate, steady_state

    system = jointdyn.System.paper_damper(eta=0.5, beta=1.0, model="jenkins")
    ss = steady_state(system, 0.8)
    _check(ss, True)
    assert not hasattr(ss, "detail") and "message" in ss.to_record() and "detail" not in ss.to_record()
    tr = integrate(system, 0.8, periods=1)
    _check(tr, True)


@pytest.mark.parametrize("name", ["jointdyn._exit", "jointdyn.cli"])
def test_exit_codes_live_in_one_module(name):
    from jointdyn import _exit

    mod = importlib.import_module(name)
    assert (mod.EXIT_BAD_INPUT, mod.EXIT_INCOMPLETE, mod.EXIT_OS_ERROR) == (2, 3, 1)
    assert mod.EXIT_INCOMPLETE is _exit.EXIT_INCOMPLETE
