"""The one jit helper of jointdyn.

Every compiled function in the package is decorated with :func:`jit`, which
fixes the Numba options once: no Python objects (``nopython``), compiled code
cached on disk (``cache=True``) so that a second process loads it instead of
compiling, and the GIL released so that threads (Dask workers) run kernels in
parallel. ``fastmath`` stays off: the contact laws compare forces with slip
limits and need IEEE semantics for ties and infinities.
"""

from __future__ import annotations

import numba

__all__ = ["jit", "specialize"]


def jit(*args, **kwargs):
    """``numba.njit`` with the project's fixed options (cache, nogil, no fastmath)."""
    opts = dict(cache=True, nogil=True, fastmath=False, error_model="numpy")
    opts.update(kwargs)
    if args and callable(args[0]) and len(args) == 1:
        return numba.njit(**opts)(args[0])
    return numba.njit(*args, **opts)


_SPECIALIZED: dict = {}


def _source_tag(obj) -> str:
    """Hash of the source file defining a bound kernel (cache invalidation)."""
    import hashlib
    import inspect

    fn = getattr(obj, "py_func", obj)
    try:
        with open(inspect.getfile(fn), "rb") as fh:
            data = fh.read()
    except (OSError, TypeError):
        data = repr(fn).encode()
    return hashlib.sha1(data).hexdigest()[:10]


def specialize(template, **bindings):
    """Compile ``template`` with some of its global names bound to kernels.

    Numba cannot cache a function that takes another compiled function as an
    argument across processes (the argument's type is keyed by a per-process
    id), so generic loops (drivers, integrators, harmonic balance) are written
    as plain-Python templates that call a global placeholder such as
    ``STEP``; this returns a compiled, disk-cached copy in which the
    placeholders are the given kernels. The copy's cache name carries the
    bound kernels' names and a hash of their source files, so that changing
    a law recompiles every loop that inlines it.

    Parameters
    ----------
    template : function
        Plain Python function written in the Numba subset.
    **bindings
        ``PLACEHOLDER=kernel`` pairs.

    Returns
    -------
    numba dispatcher
        Memoised per (template, bindings) within the process.
    """
    import types

    key = (template, tuple(sorted((k, id(v)) for k, v in bindings.items())))
    hit = _SPECIALIZED.get(key)
    if hit is not None:
        return hit
    g = dict(template.__globals__)
    g.update(bindings)
    fn = types.FunctionType(
        template.__code__, g, template.__name__, template.__defaults__, template.__closure__
    )
    tag = "_".join(
        f"{k}_{getattr(v, '__name__', 'k')}_{_source_tag(v)}" for k, v in sorted(bindings.items())
    )
    fn.__qualname__ = f"{template.__qualname__}__{tag}"
    fn.__module__ = template.__module__
    fn.__doc__ = template.__doc__
    disp = jit(fn)
    _SPECIALIZED[key] = disp
    return disp
