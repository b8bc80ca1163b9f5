"""The one cache helper of jointdyn.

Two kinds of memoisation are used across the package:

* by value, for small hashable keys (harmonics and samples of a Fourier
  matrix, a template and its bound kernels): :func:`functools.lru_cache`,
  re-exported here as :func:`by_value` with a bounded size;
* by identity, for data derived from an object that is immutable but not
  hashable (a :class:`~jointdyn.System` holds arrays): :func:`by_identity`
  keeps the result while the object lives and drops it when the object is
  garbage collected, so an id can never be reused for a stale entry.
"""

from __future__ import annotations

import functools
import weakref

__all__ = ["by_value", "by_identity"]


def by_value(maxsize: int = 64):
    """``functools.lru_cache(maxsize)``: memoise a function of hashable arguments."""
    return functools.lru_cache(maxsize=maxsize)


def by_identity(fn):
    """Memoise ``fn(obj, *args)`` per live ``obj`` (identity) and hashable ``args``.

    The entry is evicted when ``obj`` is garbage collected (``obj`` must
    support weak references). The cached value must not be mutated by
    callers.
    """
    store: dict = {}

    @functools.wraps(fn)
    def wrapper(obj, *args):
        key = (id(obj), args)
        hit = store.get(key)
        if hit is not None and hit[0]() is obj:
            return hit[1]
        value = fn(obj, *args)
        if not any(k[0] == id(obj) for k in store):
            weakref.finalize(obj, _evict, store, id(obj))
        store[key] = (weakref.ref(obj), value)
        return value

    wrapper.cache_clear = store.clear
    return wrapper


def _evict(store: dict, oid: int) -> None:
    for key in [k for k in store if k[0] == oid]:
        del store[key]
