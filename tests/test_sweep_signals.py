"""Real processes and real signals (issue 12): a SIGKILLed ``jointdyn frc``
leaves none of its worker processes behind; Ctrl-C (SIGINT to the process
group) halfway through a sweep keeps every finished point, the rerun reuses
them, says so, and writes files identical to an uninterrupted run.

Each subprocess has a generous timeout as a hang guard, not a speed
requirement. Linux only (the processes are found through /proc).
"""

from __future__ import annotations

import json
import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pytest

pytestmark = pytest.mark.skipif(not os.path.isdir("/proc/self"), reason="needs /proc (Linux)")

SRC = str(Path(__file__).resolve().parents[1] / "src")
#: a hang guard for subprocesses and waits, not a speed requirement
HANG_GUARD_S = 600
POLL_S = 0.05


def _env():
    env = dict(os.environ)
    env["PYTHONPATH"] = SRC + os.pathsep + env.get("PYTHONPATH", "")
    return env


def _stat(pid: int):
    """(state, ppid) of a process, or None if it is gone."""
    try:
        text = Path(f"/proc/{pid}/stat").read_text()
    except (FileNotFoundError, ProcessLookupError):
        return None
    fields = text[text.rindex(")") + 2:].split()
    return fields[0], int(fields[1])


def _children(pid: int) -> list[int]:
    out = []
    for d in os.listdir("/proc"):
        if d.isdigit():
            st = _stat(int(d))
            if st is not None and st[1] == pid:
                out.append(int(d))
    return out


def _running(pids) -> list[int]:
    """The pids that still exist and are not zombies."""
    return [p for p in pids if (st := _stat(p)) is not None and st[0] != "Z"]


def _wait_until(cond, what: str):
    deadline = time.monotonic() + HANG_GUARD_S
    while not cond():
        if time.monotonic() > deadline:
            raise AssertionError(f"hang guard: {what}")
        time.sleep(POLL_S)


#: runs the CLI with every steady state slowed by 20 ms (the real solver's
#: results; the delay gives the test time to interrupt halfway), with SIGINT
#: handled as in a terminal's foreground job (a test runner started in the
#: background of a non-interactive shell passes SIGINT on ignored)
SLOW_CLI = (
    "import signal, sys, time\n"
    "signal.signal(signal.SIGINT, signal.default_int_handler)\n"
    "import jointdyn.sweeps._points as f\n"
    "real = f._steady_state_fn()\n"
    "def slow(*a, **k):\n"
    "    time.sleep(0.02)\n"
    "    return real(*a, **k)\n"
    "f._steady_state_fn = lambda: slow\n"
    "from jointdyn.cli import main\n"
    "sys.exit(main(sys.argv[1:]))\n"
)
ARGS = ["frc", "--gamma", "0.7:1.3:0.005", "--eta", "0.5", "--beta", "2", "--workers", "2", "--json"]
POINTS = 2 * 121


def test_sigkill_leaves_no_worker_process(tmp_path):
    p = subprocess.Popen([sys.executable, "-c", SLOW_CLI, *ARGS, "--out", str(tmp_path / "o")], cwd=tmp_path,
                         env=_env(), stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL, start_new_session=True)
    try:
        _wait_until(lambda: len(_children(p.pid)) >= 2 or p.poll() is not None, "the workers never started")
        assert p.poll() is None, "the sweep ended before it could be killed"
        workers = _children(p.pid)
        # the workers are running their first chunks
        _wait_until(lambda: any((tmp_path / "o" / "lines").glob("*/*.npz")), "no chunk finished")
        os.kill(p.pid, signal.SIGKILL)
        p.wait(timeout=HANG_GUARD_S)
        _wait_until(lambda: not _running(workers), f"workers {_running(workers)} outlived their parent")
    finally:
        if p.poll() is None:
            os.killpg(p.pid, signal.SIGKILL)


def test_watchdog_ends_a_worker_whose_parent_died(tmp_path):
    """The fallback where the kernel sends no death signal: a process running
    only the parent watchdog exits once its parent is gone."""
    pidfile = tmp_path / "child.pid"
    code = (
        "import os, sys, time\n"
        "from jointdyn.sweeps._pool import _watch_parent\n"
        "parent = os.getpid()\n"
        "if os.fork() == 0:\n"
        f"    open({str(pidfile)!r}, 'w').write(str(os.getpid()))\n"
        "    _watch_parent(parent, 0.05)\n"
        "    os._exit(0)\n"
        "time.sleep(600)\n"
    )
    p = subprocess.Popen([sys.executable, "-c", code], env=_env(), start_new_session=True)
    try:
        _wait_until(lambda: pidfile.exists() and pidfile.read_text(), "the child never started")
        child = int(pidfile.read_text())
        assert _running([child])
        os.kill(p.pid, signal.SIGKILL)
        p.wait(timeout=HANG_GUARD_S)
        _wait_until(lambda: not _running([child]), "the orphaned child kept running")
    finally:
        if p.poll() is None:
            os.killpg(p.pid, signal.SIGKILL)


def _saved_points(out: Path) -> int:
    return sum(int(np.load(f)["done"]) for f in out.glob("lines/*/*.npz"))


def test_sigint_keeps_finished_points_and_the_rerun_reuses_them(tmp_path):
    out = tmp_path / "interrupted"
    p = subprocess.Popen([sys.executable, "-c", SLOW_CLI, *ARGS, "--out", str(out)], cwd=tmp_path, env=_env(),
                         stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, start_new_session=True)
    try:
        _wait_until(lambda: len(list(out.glob("lines/*/*.npz"))) >= 3 or p.poll() is not None,
                    "no chunk was saved")
        assert p.poll() is None, "the sweep ended before it could be interrupted"
        workers = _children(p.pid)
        os.killpg(p.pid, signal.SIGINT)  # Ctrl-C: the whole process group
        stdout, stderr = p.communicate(timeout=HANG_GUARD_S)
    finally:
        if p.poll() is None:
            os.killpg(p.pid, signal.SIGKILL)
    assert p.returncode == 130, stderr
    assert stderr.strip().splitlines()[-1] == "jointdyn frc: interrupted (finished results are kept)"
    assert "Traceback" not in stderr and stdout == ""
    assert not (out / "frc.nc").exists()
    assert not _running(workers)
    saved = _saved_points(out)
    assert 0 < saved < POINTS
    # the rerun (unslowed) reuses exactly the saved points and says so
    again = subprocess.run([sys.executable, "-m", "jointdyn", *ARGS, "--out", str(out)], cwd=tmp_path, env=_env(),
                           capture_output=True, text=True, timeout=HANG_GUARD_S, check=False)
    assert again.returncode == 0, again.stderr
    assert json.loads(again.stdout)["reused_points"] == saved
    assert f"reused {saved} of {POINTS} points" in again.stderr
    ref = tmp_path / "uninterrupted"
    whole = subprocess.run([sys.executable, "-m", "jointdyn", *ARGS, "--out", str(ref)], cwd=tmp_path, env=_env(),
                           capture_output=True, text=True, timeout=HANG_GUARD_S, check=False)
    assert whole.returncode == 0, whole.stderr
    for name in ("frc.nc", "frc.csv"):
        assert (out / name).read_bytes() == (ref / name).read_bytes(), name
    resumed, fresh = json.loads(again.stdout), json.loads(whole.stdout)
    resumed.pop("reused_points"), fresh.pop("reused_points")
    assert resumed == fresh
