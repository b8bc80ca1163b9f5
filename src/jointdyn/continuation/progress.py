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
