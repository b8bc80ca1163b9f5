"""The one jit helper of jointdyn.

Every compiled function in the package is decorated with :func:`jit`, which
fixes the Numba options once: no Python objects (``nopython``), compiled code
cached on disk (``cache=True``) so that a second process loads it instead of
compiling, and the GIL released so that threads (Dask workers) run kernels in
parallel. ``fastmath`` stays off: the contact laws compare forces with slip
limits and need IEEE semantics for ties and infinities.

Loading from the disk cache is kept light (:class:`_LoadingCache`): Numba
installs all of its compiler's typing and lowering registries before every
cache load, which imports most of Numba, cffi and more, although code loaded
from the cache needs only Numba's runtime. A process that finds everything
in the cache (a command run a second time) skips that work; a process that
compiles gets the registries from Numba's compiler, which installs them
itself before compiling.
"""

from __future__ import annotations

import os
import sys

import numba
from numba.core import environment as _environment
from numba.core.caching import CompileResultCacheImpl, FunctionCache, _CacheLocator
from numba.core.runtime import nrt

__all__ = ["jit", "specialize", "ANNOUNCE_ENV", "COMPILING_NOTE"]

#: environment variable that asks the main process to say on stderr, once,
#: that it compiles (set by the ``jointdyn`` process, :func:`jointdyn.cli.console`)
ANNOUNCE_ENV = "JOINTDYN_ANNOUNCE_COMPILING"
#: what it says
COMPILING_NOTE = ("jointdyn: compiling, first run only (the compiled kernels are cached on disk for every later "
                  "run; this can take minutes)")
_ANNOUNCED: list = []


def _note_compiling() -> None:
    """A kernel was not in the disk cache (a cold cache: the first run after
    installing or upgrading): say so on stderr, once per process, in the
    main process of a ``jointdyn`` command (not in its sweep workers, not
    for callers of the Python API, whose stderr is theirs)."""
    if _ANNOUNCED or os.environ.get(ANNOUNCE_ENV) != "1":
        return
    import multiprocessing

    if multiprocessing.parent_process() is not None:
        return
    _ANNOUNCED.append(True)
    print(COMPILING_NOTE, file=sys.stderr, flush=True)


#: environment variable naming the folder of jointdyn's compiled kernels (default: a per-version folder
#: of the user's cache directory, :func:`cache_root`)
CACHE_ENV = "JOINTDYN_CACHE_DIR"
_PACKAGE_DIR = os.path.dirname(os.path.abspath(__file__))
_STAMPS: dict = {}


def _user_cache_home() -> str:
    """The platform's per-user cache directory (XDG on Linux, ~/Library/Caches, %LOCALAPPDATA%)."""
    if sys.platform == "win32":
        return os.environ.get("LOCALAPPDATA") or os.path.join(os.path.expanduser("~"), "AppData", "Local")
    if sys.platform == "darwin":
        return os.path.join(os.path.expanduser("~"), "Library", "Caches")
    return os.environ.get("XDG_CACHE_HOME") or os.path.join(os.path.expanduser("~"), ".cache")


def cache_root() -> str:
    """Folder of jointdyn's compiled kernels: ``$JOINTDYN_CACHE_DIR``, else ``$NUMBA_CACHE_DIR/jointdyn``,
    else ``jointdyn`` in the user's cache directory; then a subfolder per jointdyn version and Python.

    Outside the installed package, so that reinstalling the same version (a new virtual
    environment, ``pip install --force-reinstall``, an unwritable site-packages) finds the
    kernels compiled before; one folder per version, which the user may delete.
    """
    # the package is imported before any of its modules (no import here: the package imports this one)
    version = getattr(sys.modules.get(__package__), "__version__", "unknown")
    root = os.environ.get(CACHE_ENV)
    if not root:
        numba_dir = os.environ.get("NUMBA_CACHE_DIR")
        root = os.path.join(numba_dir, "jointdyn") if numba_dir else os.path.join(_user_cache_home(), "jointdyn")
    return os.path.join(root, f"{version}-py{sys.version_info[0]}{sys.version_info[1]}")


def _module_files(modname: str, seen: set) -> None:
    """Source files of jointdyn module ``modname`` and of the jointdyn modules whose compiled
    functions it references at module level (what Numba may inline into its kernels), recursively."""
    if modname in seen:
        return
    mod = sys.modules.get(modname)
    path = getattr(mod, "__file__", None)
    if not path:
        return
    seen.add(modname)
    for value in list(vars(mod).values()):
        other = getattr(getattr(value, "py_func", value), "__module__", None)
        if isinstance(other, str) and other.startswith("jointdyn.") and callable(value):
            _module_files(other, seen)


def source_stamp(modname: str) -> str:
    """Hash of the source of jointdyn module ``modname`` and of every jointdyn module whose compiled
    functions it may inline (:func:`_module_files`): changing a shared helper recompiles every kernel
    that inlines it, and a reinstall with the same sources keeps the compiled kernels."""
    hit = _STAMPS.get(modname)
    if hit is not None:
        return hit
    import hashlib

    seen: set = set()
    _module_files(modname, seen)
    h = hashlib.sha1()
    for name in sorted(seen):
        h.update(name.encode())
        try:
            with open(sys.modules[name].__file__, "rb") as fh:
                h.update(fh.read())
        except OSError:
            h.update(b"?")
    _STAMPS[modname] = stamp = h.hexdigest()[:16]
    return stamp


class _PackageLocator(_CacheLocator):
    """Numba cache locator of jointdyn's functions: :func:`cache_root`, the module's path inside
    the package as subfolder, files named by the source stamp (:func:`source_stamp`), so that
    several source trees of one version (developers' worktrees) keep their own kernels side by side."""

    def __init__(self, py_func, py_file):
        rel = os.path.relpath(os.path.dirname(os.path.abspath(py_file)), _PACKAGE_DIR)
        self._cache_path = os.path.normpath(os.path.join(cache_root(), rel))
        self._lineno = py_func.__code__.co_firstlineno
        self._stamp = source_stamp(py_func.__module__)

    def get_cache_path(self):
        return self._cache_path

    def get_source_stamp(self):
        return self._stamp

    def get_disambiguator(self):
        return f"{self._lineno}-{self._stamp}"

    @classmethod
    def from_function(cls, py_func, py_file):
        inside = os.path.abspath(py_file).startswith(_PACKAGE_DIR + os.sep)
        if not inside or not str(getattr(py_func, "__module__", "")).startswith("jointdyn."):
            return None
        self = cls(py_func, py_file)
        try:
            self.ensure_cache_path()
        except OSError:  # not writable: Numba's own locators (next to the sources, or its user-wide folder)
            return None
        return self


class _PackageCacheImpl(CompileResultCacheImpl):
    _locator_classes = [_PackageLocator, *CompileResultCacheImpl._locator_classes]


class _LoadingCache(FunctionCache):
    """Numba's disk cache of one function, loading with the runtime only.

    ``FunctionCache.load_overload`` refreshes the target context first
    (installs every typing and lowering registry of the CPU target, a few
    tenths of a second of imports); the compiled code it loads calls
    Numba's runtime (NRT) and C helpers only, and the environments it
    rebuilds import their own modules. The compiler refreshes both contexts
    before it compiles (``numba.core.compiler.CompilerBase``), so a cache
    miss compiles as before. Files go to :func:`cache_root` (:class:`_PackageLocator`).
    """

    _impl_class = _PackageCacheImpl

    def load_overload(self, sig, target_context):
        nrt.rtsys.initialize(target_context)
        _environment._rebuild_env = _rebuild_env_unimported
        try:
            with self._guard_against_spurious_io_errors():
                return self._load_overload(sig, target_context)
        finally:
            _environment._rebuild_env = _NUMBA_REBUILD_ENV


#: Numba's own rebuilder of a compiled function's environment (put back after every load)
_NUMBA_REBUILD_ENV = _environment._rebuild_env


def _rebuild_env_unimported(modname, consts, env_name):
    """Numba's ``_rebuild_env`` without importing the function's module.

    A cached function's pickle rebuilds one environment per compiled
    function it contains, Numba's own array helpers included, and Numba
    imports the module of each to take its ``__dict__`` as the
    environment's globals (``numba.np.arrayobj`` alone costs tens of
    milliseconds). Only object-mode code reads those globals; jointdyn
    compiles in nopython mode, whose code reads the environment's constants
    only. The globals here hold the module's name, which is what Numba
    keeps of them when it pickles an environment again. Pickle looks the
    rebuilder up by name when it loads, so :meth:`_LoadingCache.load_overload`
    puts this one in place for the duration of a load.
    """
    env = _environment.lookup_environment(env_name)
    if env is not None:
        return env
    env = _environment.Environment({"__name__": modname})
    env.consts[:] = consts
    env.env_name = env_name
    _environment.Environment._memo[env_name] = env
    return env


class _LazyCache:
    """The disk cache of one function, made on its first use (a :class:`_LoadingCache`).

    Making a cache costs a few tenths of a millisecond (it locates and tests
    the cache directory and stamps the source file); most dispatchers are
    inlined helpers that are never compiled on their own, and a command
    loads a few of the others.
    """

    def __init__(self, py_func):
        self._py_func = py_func
        self._made = None

    def _cache(self) -> _LoadingCache:
        if self._made is None:
            self._made = _LoadingCache(self._py_func)
        return self._made

    def load_overload(self, sig, target_context):
        got = self._cache().load_overload(sig, target_context)
        if got is None:  # not cached: Numba compiles it next
            _note_compiling()
        return got

    def save_overload(self, sig, data):
        return self._cache().save_overload(sig, data)

    def __getattr__(self, name):  # the rest of Numba's cache interface (flush, cache_path, ...)
        if name in ("_py_func", "_made"):  # not set yet (an instance made without __init__)
            raise AttributeError(name)
        return getattr(self._cache(), name)


#: whether this Numba has the cache internals :class:`_LoadingCache` relies on (otherwise Numba's own
#: cache is kept: the loads are then slower, never different)
_LIGHT_LOADS = all(
    hasattr(FunctionCache, a) for a in ("_load_overload", "_guard_against_spurious_io_errors")
) and callable(getattr(_environment, "_rebuild_env", None)) and hasattr(_environment.Environment, "_memo")


def _with_cache(disp):
    """``disp`` (made without a cache) with a :class:`_LazyCache`, or Numba's own cache where this Numba
    does not have the internals :class:`_LoadingCache` relies on."""
    if not hasattr(disp, "enable_caching"):  # NUMBA_DISABLE_JIT: the plain function
        return disp
    if _LIGHT_LOADS:
        disp._cache = _LazyCache(disp.py_func)
    else:
        disp.enable_caching()
    return disp


def jit(*args, **kwargs):
    """``numba.njit`` with the project's fixed options (cache, nogil, no fastmath).

    The disk cache of a function is made on its first compilation or load
    (:class:`_LazyCache`), and loads with Numba's runtime only
    (:class:`_LoadingCache`).
    """
    opts = dict(cache=True, nogil=True, fastmath=False, error_model="numpy")
    opts.update(kwargs)
    if args and not (callable(args[0]) and len(args) == 1) or not opts["cache"]:
        return numba.njit(*args, **opts)  # explicit signatures compile at once: Numba's own cache
    opts["cache"] = False
    if args:
        return _with_cache(numba.njit(**opts)(args[0]))
    wrap = numba.njit(**opts)
    return lambda fn: _with_cache(wrap(fn))


_SPECIALIZED: dict = {}


def _source_tag(obj) -> str:
    """Hash of the source a bound kernel is compiled from (cache invalidation): for a jointdyn
    kernel its module and the modules it may inline (:func:`source_stamp`), for a plug-in the
    file defining it."""
    import hashlib
    import inspect

    fn = getattr(obj, "py_func", obj)
    mod = getattr(fn, "__module__", None)
    if isinstance(mod, str) and mod.startswith("jointdyn.") and mod in sys.modules:
        return source_stamp(mod)[:10]
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
