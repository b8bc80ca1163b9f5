"""A progress bar over the continued parameter's range, for :func:`~jointdyn.continuation.continuation`."""

from __future__ import annotations

import math


class ParameterProgress:
    """A progress bar over the continued parameter's range, for :func:`continuation`.

    The bar stands at the farthest fraction ``|lam - start| / |stop - start|``
    reached (in per mille), so that it fills as the branch covers the range
    and its estimate of the time left means something; a count of points
    against ``max_points`` (a bound that a complete branch never reaches)
    would do neither. The current value of the parameter is shown beside
    it.

    Parameters
    ----------
    start, stop : float
        The range, in the units ``continuation`` sees (scaled).
    desc : str
        Label of the bar.
    progress : bool or None
        True: always shown; None: shown on a terminal only; False: no bar
        (tqdm is not even imported).
    name : str
        Name of the parameter shown beside the bar (``"gamma"``).
    scale : float
        Factor from the continued value to the shown one.
    """

    STEPS = 1000

    def __init__(self, start: float, stop: float, desc: str, progress=None, *, name: str = "lam",
                 scale: float = 1.0):
        self.start, self.span = float(start), float(stop) - float(start)
        self.name, self.scale = name, float(scale)
        self.done = 0
        self.bar = None
        if progress is not False:
            from tqdm.auto import tqdm

            self.bar = tqdm(total=self.STEPS, desc=desc, disable=None if progress is None else not progress,
                            leave=False,  # tqdm writes the postfix as ", gamma = ..."
                            bar_format="{desc}: {percentage:3.0f}%|{bar}| [{elapsed}<{remaining}{postfix}]")

    def fraction(self, lam: float) -> float:
        """Share of the range between ``start`` and ``lam`` (0 to 1)."""
        if not self.span or not math.isfinite(lam):
            return 0.0
        return min(max((lam - self.start) / self.span, 0.0), 1.0)

    def update(self, n: int = 1) -> None:
        """Points are not progress: the bar moves in :meth:`reached`."""

    def reached(self, lam: float) -> None:
        """An accepted point at ``lam``: the bar moves to the farthest fraction reached."""
        k = int(self.STEPS * self.fraction(lam))
        if self.bar is None:
            self.done = max(self.done, k)
            return
        if k > self.done:
            self.bar.update(k - self.done)
            self.done = k
        self.bar.set_postfix_str(f"{self.name} = {lam * self.scale:.5g}", refresh=False)

    def close(self) -> None:
        """Close the bar (leaves nothing on the terminal)."""
        if self.bar is not None:
            self.bar.close()

    def __enter__(self):
        return self

    def __exit__(self, *exc) -> None:
        self.close()


def _on_terminal() -> bool:
    """Whether stderr is a terminal (tqdm's bars there; plain lines elsewhere)."""
    import sys

    try:
        return sys.stderr.isatty()
    except (AttributeError, ValueError):  # replaced or closed stderr
        return False


def stage_note(text: str, progress=None) -> None:
    """One line that says which stage starts (``"HB level 2/5: H = 7, Ns = 128"``), on stderr.

    ``progress`` as in :class:`StageProgress`: False writes nothing. On a
    terminal the line goes through ``tqdm.write`` (above any bar).
    """
    if progress is False:
        return
    import sys

    if _on_terminal():
        from tqdm.auto import tqdm

        tqdm.write(text, file=sys.stderr)
    else:
        print(text, file=sys.stderr, flush=True)


class StageProgress:
    """Progress of one stage of known length (the stability of a branch's points, the files of an export).

    On a terminal a tqdm bar (left on the screen when the stage ends, with
    its time); elsewhere (stderr redirected to a file or a pipe) plain
    lines, once the stage has taken ``QUIET_S`` seconds (a short stage
    writes nothing): the items done of the total with the time spent and
    left, again each time another ``1 / LINES`` of the stage is done, and
    one line at the end.

    Parameters
    ----------
    total : int
        Items of the stage (0: nothing is shown).
    desc : str
        Name of the stage.
    progress : bool or None
        False: nothing (tqdm is not imported); True or None: shown (a bar
        on a terminal, plain lines elsewhere).
    unit : str
        Name of one item.
    """

    LINES = 4
    QUIET_S = 2.0

    def __init__(self, total: int, desc: str, progress=None, unit: str = "it"):
        import time

        self.total, self.desc, self.unit = int(total), desc, unit
        self.done = 0
        self.bar = None
        self.plain = False
        self._clock = time.perf_counter
        self._t0 = self._clock()
        self._next = 0
        if progress is False or self.total <= 0:
            return
        if _on_terminal():
            from tqdm.auto import tqdm

            self.bar = tqdm(total=self.total, desc=desc, unit=unit, leave=True)
        else:
            self.plain = True
            self._said = False
            self._next = self._step()

    def _step(self) -> int:
        return self.done + max(1, -(-self.total // self.LINES))

    def _line(self, what: str) -> None:
        import sys

        print(f"{self.desc}: {what}", file=sys.stderr, flush=True)

    def update(self, n: int = 1) -> None:
        """``n`` more items done."""
        self.done += n
        if self.bar is not None:
            self.bar.update(n)
        elif self.plain and self.done < self.total and self.done >= self._next:
            spent = self._clock() - self._t0
            if spent < self.QUIET_S:
                return
            left = spent * (self.total - self.done) / self.done
            self._line(f"{self.done}/{self.total} {self.unit}s, {spent:.1f} s, about {left:.0f} s left")
            self._said = True
            self._next = self._step()

    def close(self) -> None:
        """End of the stage: the bar closed, or the last plain line (items done and the time)."""
        if self.bar is not None:
            self.bar.close()
            self.bar = None
        elif self.plain and (self._said or self._clock() - self._t0 >= self.QUIET_S):
            self._line(f"{self.done}/{self.total} {self.unit}s done in {self._clock() - self._t0:.1f} s")
            self.plain = False

    def __enter__(self):
        return self

    def __exit__(self, *exc) -> None:
        self.close()


def stage_progress(total: int, desc: str, progress=None, unit: str = "it") -> StageProgress:
    """A :class:`StageProgress` (a context manager)."""
    return StageProgress(total, desc, progress, unit)
