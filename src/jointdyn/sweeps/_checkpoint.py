"""Resume checkpoints of sweep lines: one small file per finished chunk.

Layout under ``OUT/lines``: a folder per line (:attr:`LineSpec.key`, a
readable label plus a hash of the line's spec) holding ``pNNNNNN.npz``, the
chunk that starts at position NNNNNN of the line in its sweep direction.
Each file holds the chunk's per-point arrays, the warm start of the point
after it (x, v, law states, or ``cold``), the resume key: the line's spec
without its gamma grid, with the solver's results version and the jointdyn
version (:meth:`LineSpec.resume_key`), and ``path``: the gammas the line
visited from its first point to the chunk's last, in sweep order. The
folder (:attr:`LineSpec.folder`) does not depend on the grid either.
Files are written atomically.

A line resumes from position 0 along the chain of chunks (each names where
the next starts); the chain stops at the first missing or unreadable file,
at a file whose path is not the start of the line's own (its points were
reached through other gammas: their warm starts, hence their results,
differ), or at a file whose key differs (made by another solver version:
its points are counted as stale and recomputed, and the new chunks replace
it). So a rerun on a grid extended by a point reuses every point before it
in the sweep direction, on any grid whose visit order starts the same.
"""

from __future__ import annotations

import zipfile
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from .._io import atomic_path
from ._points import ChunkResult

__all__ = ["LineCheckpoints", "chunk_path", "save_chunk", "load_line"]

_RESTART = ("restart_x", "restart_v", "restart_states")


def chunk_path(line_dir: Path, first: int) -> Path:
    """File of the chunk starting at position ``first``."""
    return Path(line_dir) / f"p{int(first):06d}.npz"


def save_chunk(line_dir: Path, key: str, chunk: ChunkResult, path) -> Path:
    """Write ``chunk`` (atomically) with the resume ``key`` and the gammas
    ``path`` that the line visited up to the chunk's last point."""
    arrays = dict(chunk.arrays)
    arrays["path"] = np.asarray(path, dtype=np.float64)
    if arrays["path"].shape != (chunk.first + chunk.done,):
        raise ValueError(f"path must hold the {chunk.first + chunk.done} gammas up to the chunk's last point")
    arrays["first"] = np.int64(chunk.first)
    arrays["done"] = np.int64(chunk.done)
    arrays["key"] = np.array(key)
    arrays["cold"] = np.bool_(chunk.restart is None)
    if chunk.restart is not None:
        arrays["restart_x"] = np.asarray(chunk.restart.x, float)
        arrays["restart_v"] = np.asarray(chunk.restart.v, float)
        arrays["restart_states"] = np.asarray(chunk.restart.states, float)
    path = chunk_path(line_dir, chunk.first)
    path.parent.mkdir(parents=True, exist_ok=True)
    with atomic_path(path) as tmp:
        with open(tmp, "wb") as fh:
            np.savez(fh, **arrays)
    return path


@dataclass(frozen=True)
class LineCheckpoints:
    """What a line's checkpoints give back.

    Attributes
    ----------
    chunks : tuple of ChunkResult
        Reusable chunks in line order, from position 0 without a gap.
    stale : int
        Points of checkpoints made by another solver or jointdyn version
        (not reused).
    """

    chunks: tuple
    stale: int

    @property
    def reused(self) -> int:
        """Points reused."""
        return sum(c.done for c in self.chunks)


def _read(path: Path, names, line: int):
    """(key, ChunkResult, visited gammas) of one file, or None if unreadable or malformed."""
    from ..dynamics import Restart

    try:
        with np.load(path, allow_pickle=False) as z:
            key = str(z["key"])
            visited = np.asarray(z["path"], dtype=np.float64)
            first, done = int(z["first"]), int(z["done"])
            arrays = {n: z[n] for n in names}
            restart = None if bool(z["cold"]) else Restart(*(z[n] for n in _RESTART))
    except (OSError, ValueError, KeyError, EOFError, TypeError, zipfile.BadZipFile):
        return None
    if done < 1 or any(a.shape[:1] != (done,) for a in arrays.values()) or visited.shape != (first + done,):
        return None
    return key, ChunkResult(line=line, first=first, done=done, arrays=arrays, restart=restart), visited


def load_line(line_dir: Path, key: str, names, line: int, gammas) -> LineCheckpoints:
    """The reusable chunks of a line visiting ``gammas`` (in sweep order)
    whose resume key is ``key``.

    ``names`` are the per-point arrays every chunk must hold. A chunk is
    reused when the gammas its line visited up to its last point are the
    first ones of ``gammas``.
    """
    gammas = np.asarray(gammas, dtype=np.float64)
    length = gammas.size
    chunks, stale, pos, reusing = [], 0, 0, True
    while pos < length:
        path = chunk_path(line_dir, pos)
        if not path.is_file():
            break
        got = _read(path, names, line)
        if got is None or got[1].first != pos or pos + got[1].done > length:
            break
        k, chunk, visited = got
        if not np.array_equal(visited, gammas[:pos + chunk.done]):
            break  # reached through other gammas: not the same inputs
        if k != key:
            reusing = False
        if reusing:
            chunks.append(chunk)
        else:
            stale += chunk.done
        pos += chunk.done
    return LineCheckpoints(chunks=tuple(chunks), stale=stale)
