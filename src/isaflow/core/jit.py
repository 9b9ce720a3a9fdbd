"""``njit`` with an on-disk cache that many processes can share safely, and compile accounting.

Every kernel of the package is decorated with :func:`njit` (``numba.njit``'s
options).  Numba's own file cache is not safe to fill from several processes:
an entry compiled in one process and loaded beside entries compiled in another
can name its callees' machine code differently (seen: a cached
``relax_resume`` that segfaulted on every load, in a cache filled by two
workflow jobs at once, numba#10128), and two processes saving overloads of one
function can number them alike.  So here a cache is filled by **one process
only**, then sealed:

- A *generation* is a folder ``<NUMBA_CACHE_DIR>/<name>`` (one per method, and
  ``default`` for processes that never name one).  A process uses exactly one:
  :func:`use` binds it (``isaflow.run`` binds a run to its method's) before any
  kernel is loaded; otherwise the first kernel loaded binds ``default``.
- If the generation holds a ``MANIFEST.json`` whose files, numba and Python
  versions and CPU all match, the process only reads it (``read``).  Otherwise
  the first process to get the folder's exclusive lock wipes it and fills it
  (``write``): :func:`use` with a ``fill`` function (a method's warm-up,
  compiling every kernel signature its runs use) fills and seals it at once;
  a ``default`` writer seals at exit (if it compiled anything), so a process
  without ``fill`` never waits for a writer (which may live as long as a test
  session).  A process
  that can neither read a sealed generation nor write it (another is writing,
  or the seal is damaged while others read it) compiles in memory only
  (``private``).  Readers hold
  a shared lock, so a folder is never wiped under them.
- A process may also *read* other methods' sealed generations (:func:`read_also`,
  e.g. the claims job, which calls every method's code): a kernel of package
  ``isaflow.methods.<name>`` then loads from generation ``<name>``, under a
  shared lock held for the process's life; nothing is ever written there.
- A damaged, partial or foreign cache is therefore rebuilt or ignored, never
  loaded; in ``read`` mode a kernel missing from the cache is compiled in
  memory and counted (:func:`counters` ``gaps``), never saved.

``numba:compile`` events are timed at the outermost level (a kernel's callees
compile inside it).
"""

import atexit
import fcntl
import hashlib
import json
import os
import platform
import shutil
import sys
import time
from pathlib import Path

import numba
from numba.core import event
from numba.core.caching import (CompileResultCacheImpl, FunctionCache, IndexDataCacheFile, _CacheLocator,
                                 _SourceFileBackedLocatorMixin)

MANIFEST = "MANIFEST.json"
_COUNTERS = {"compiled": 0, "compile_s": 0.0, "loaded": 0, "load_s": 0.0, "gaps": []}
_STATE = {"name": None, "mode": None, "folder": None, "fd": None}
_EXTRA = {}  # {package prefix 'isaflow.methods.<name>': (folder, fd)} of generations read beside this one (read_also)


def counters():
    """{'compiled': numba compiles, 'compile_s': s compiling (outermost), 'loaded': entries loaded from the
    cache, 'load_s': s loading them, 'gaps': kernels compiled in a read-only process (not in its generation),
    'generation', 'mode'}."""
    return dict(_COUNTERS, gaps=list(_COUNTERS["gaps"]), generation=_STATE["name"], mode=_STATE["mode"])


class _CompileClock(event.Listener):
    def __init__(self):
        self.depth, self.t0 = 0, 0.0

    def on_start(self, ev):
        if self.depth == 0:
            self.t0 = time.perf_counter()
        self.depth += 1

    def on_end(self, ev):
        self.depth -= 1
        _COUNTERS["compiled"] += 1
        if self.depth == 0:
            _COUNTERS["compile_s"] += time.perf_counter() - self.t0


event.register("numba:compile", _CompileClock())


def _report_gaps():
    if _COUNTERS["gaps"]:
        names = ", ".join(sorted(set(_COUNTERS["gaps"])))
        _warn(f"{len(_COUNTERS['gaps'])} kernel signature(s) not in the cache {_STATE['folder']}, compiled in "
              f"memory: {names}")


atexit.register(_report_gaps)


def _warn(msg):
    print(f"numba cache: {msg}", file=sys.stderr, flush=True)


def root():
    """The cache's root folder: NUMBA_CACHE_DIR (isaflow/__init__ names it after the package's sources)."""
    return Path(os.environ.get("NUMBA_CACHE_DIR") or Path.home() / ".cache" / "isaflow-numba")


def _machine():
    import llvmlite.binding as ll

    return {"numba": numba.__version__, "python": platform.python_version(), "machine": platform.machine(),
            "cpu": ll.get_host_cpu_name(), "features": ll.get_host_cpu_features().flatten()}


def _files(folder):
    out = {}
    for p in sorted(folder.rglob("*")):
        if p.is_file() and p.name not in (MANIFEST, ".lock") and ".tmp." not in p.name:
            out[str(p.relative_to(folder))] = hashlib.sha256(p.read_bytes()).hexdigest()
    return out


def _sealed(folder):
    """True if folder holds a manifest matching this machine and every file it lists."""
    try:
        m = json.loads((folder / MANIFEST).read_text())
        if m["machine"] != _machine():
            return False
        files = _files(folder)  # hashed once (per listed file it hashed the folder again: 0.69 s for 91 files)
        return all(files.get(k) == v for k, v in m["files"].items())
    except (OSError, ValueError, KeyError, TypeError):
        return False


def _seal():
    folder = _STATE["folder"]
    tmp = folder / f"{MANIFEST}.tmp.{os.getpid()}"
    tmp.write_text(json.dumps({"machine": _machine(), "files": _files(folder)}, indent=0))
    os.replace(tmp, folder / MANIFEST)
    fcntl.flock(_STATE["fd"], fcntl.LOCK_SH)  # a reader from now on: others may read, nobody may wipe
    _STATE["mode"] = "read"


def _shared(fd, wait):
    """Take the shared lock of a generation's folder: True once held; wait=False: False if a writer holds it."""
    try:
        fcntl.flock(fd, fcntl.LOCK_SH if wait else fcntl.LOCK_SH | fcntl.LOCK_NB)
        return True
    except BlockingIOError:
        return False


def _private(why):
    """Compile in memory: this process reads nothing, so it holds no lock (another may fill the folder)."""
    fcntl.flock(_STATE["fd"], fcntl.LOCK_UN)
    _STATE["mode"] = "private"
    _warn(f"{_STATE['folder']}: {why}; compiling in memory")
    return "private"


def use(name, fill=None):
    """Bind this process to generation ``name`` (before any kernel is loaded) and return its mode.

    fill: called to compile every kernel into a generation this process has to write, which is then
    sealed; without it (the ``default`` generation) a writer seals at exit.  A process already bound
    keeps its generation (returns its mode)."""
    if _STATE["name"] is not None:
        return _STATE["mode"]
    folder = root() / name
    folder.mkdir(parents=True, exist_ok=True)
    fd = os.open(folder / ".lock", os.O_RDWR | os.O_CREAT, 0o644)
    _STATE.update(name=name, folder=folder, fd=fd)  # the fd stays open: the lock lives with the process
    # waits while a writer fills the folder; a writer without fill seals only at its exit: never wait for it
    if not _shared(fd, wait=fill is not None):
        return _private("being written by another process")
    if _sealed(folder):
        _STATE["mode"] = "read"
        return "read"
    fcntl.flock(fd, fcntl.LOCK_UN)
    try:
        fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)  # only if no other process reads or writes it
    except BlockingIOError:  # another process reads a damaged seal, or writes: wait for a writer that fills
        if _shared(fd, wait=fill is not None) and _sealed(folder):
            _STATE["mode"] = "read"
            return "read"
        return _private("in use and not sealed (damaged, or being written)")
    if _sealed(folder):  # sealed by another process between the two locks
        fcntl.flock(fd, fcntl.LOCK_SH)
        _STATE["mode"] = "read"
        return "read"
    for p in folder.iterdir():
        if p.name != ".lock":
            shutil.rmtree(p) if p.is_dir() else p.unlink()
    _STATE["mode"] = "write"
    if fill is None:
        # sealed only if it saved something: an empty seal (a test session that ran no kernel) would make every
        # later process compile all its kernels in memory, where an unsealed folder is filled by the next one
        atexit.register(lambda: _STATE["mode"] == "write" and _COUNTERS["compiled"] and _seal())
    else:
        fill()
        _seal()
    return _STATE["mode"]


def read_also(*names, package="isaflow.methods.{}"):
    """Load the kernels of methods ``names`` from their own generations too (read only, after :func:`use` and
    before any of their kernels is loaded): the kernels of package ``package.format(name)`` and its
    sub-packages.  A generation that is not sealed, or is being written, is skipped (its kernels compile in
    memory, counted as gaps).  Returns the packages read this way."""
    for name in names:
        key = package.format(name)
        folder = root() / name
        if name == _STATE["name"] or key in _EXTRA or not folder.is_dir():
            continue
        fd = os.open(folder / ".lock", os.O_RDWR | os.O_CREAT, 0o644)
        if _shared(fd, wait=False) and _sealed(folder):
            _EXTRA[key] = (folder, fd)  # the fd stays open: the shared lock lives with the process
        else:
            os.close(fd)  # releases the lock
    return list(_EXTRA)


def _extra(package):
    """The folder of the generation read beside this process's one that holds package's kernels, or None."""
    for key, (folder, _) in _EXTRA.items():
        if package == key or package.startswith(key + "."):
            return folder
    return None


class _Locator(_SourceFileBackedLocatorMixin, _CacheLocator):
    """A kernel's folder inside this process's generation: <generation>/<its package>; nothing made on import."""

    def __init__(self, py_func, py_file):
        self._py_file, self._lineno = py_file, py_func.__code__.co_firstlineno
        self._package = py_func.__module__.rsplit(".", 1)[0]

    def get_cache_path(self):
        if _STATE["name"] is None:
            use("default")
        return str((_extra(self._package) or _STATE["folder"]) / self._package)

    def read_only(self):
        """True for a kernel of a generation read beside this process's own (read_also)."""
        return _extra(self._package) is not None

    @classmethod
    def from_function(cls, py_func, py_file):
        return cls(py_func, py_file) if os.path.exists(py_file) else None


class _Impl(CompileResultCacheImpl):
    _locator_classes = [_Locator]


class _Cache(FunctionCache):
    """numba's FunctionCache inside this process's generation, by the generation's mode (module docstring)."""

    _impl_class = _Impl

    def __init__(self, py_func):  # no folder until the first load: the generation is bound then
        self._name, self._py_func = repr(py_func), py_func
        self._impl = _Impl(py_func)
        self._file = None
        self.enable()

    @property
    def cache_path(self):
        return self._impl.locator.get_cache_path()

    def _cache_file_here(self):
        if self._file is None:
            self._file = IndexDataCacheFile(self.cache_path, self._impl.filename_base,
                                            self._impl.locator.get_source_stamp())
        return self._file

    def load_overload(self, sig, target_context):
        f = self._cache_file_here()
        extra = self._impl.locator.read_only()
        if _STATE["mode"] == "private" and not extra:
            return None
        t0 = time.perf_counter()
        target_context.refresh()
        data = f.load(self._index_key(sig, target_context.codegen()))
        if data is None:
            if _STATE["mode"] == "read" or extra:
                _COUNTERS["gaps"].append(self._py_func.__qualname__)
            return None
        cres = self._impl.rebuild(target_context, data)
        _COUNTERS["loaded"] += 1
        _COUNTERS["load_s"] += time.perf_counter() - t0
        return cres

    def save_overload(self, sig, data):
        f = self._cache_file_here()
        if _STATE["mode"] != "write" or self._impl.locator.read_only() or not self._impl.check_cachable(data):
            return
        os.makedirs(self.cache_path, exist_ok=True)
        f.save(self._index_key(sig, data.codegen), self._impl.reduce(data))

    def flush(self):
        self._cache_file_here().flush()


def njit(*args, **options):
    """numba.njit with the same options; ``cache=True`` caches in this process's generation."""
    cache = options.pop("cache", False)

    def wrap(func):
        dispatcher = numba.njit(**options)(func)
        if cache:
            dispatcher._cache = _Cache(dispatcher.py_func)
        return dispatcher

    if args and callable(args[0]):
        return wrap(args[0])
    return wrap
