"""Keys for numba's on-disk caches: the digest of the sources a package's kernels can compile in.

numba keys a cached function on its own source file's timestamp. A kernel that calls, and inlines,
functions of other modules (the tracking loop in ``tracking/link_kernel.py`` calls the centroid of
``tracking/detect.py``; the simulator's integrators call the models and forces) or reads their
module-level constants, which numba freezes at compile time, keeps a stale cache when only a callee's
module is edited: it would run the old code. So every kernel of a registered package is cached under an
explicit key: its own file's stamp together with the SHA-256 of its package's *kernel closure*
(:func:`source_digest`, computed once per process) and, optionally, a key of the package's run-time
extensions.

The kernel closure (:func:`kernel_sources`) is every ``.py`` file of the package that defines a numba
kernel, and every module of this distribution that those files import, followed transitively through
``import`` statements found anywhere in them (read with :mod:`ast`, without importing anything). A
kernel can only reach a module its own module imports, so a file outside the closure (a benchmark
helper, the solver's Python driver) is edited without recompiling anything, while a constant edited in
a shared module outside the package (``cageless/units.py``) does recompile. A cache written under
another digest no longer matches; numba recompiles and overwrites it. :func:`clear` removes a package's
cache files when asked. The digest is remembered beside the package's numba cache with the times, size and
inode of every ``.py`` file of the package and of the closure outside it, and read from there while none of
them has changed (0.1 s of CPU less at the start of a ``cageless track``).

:func:`register` must run before the package's first kernel is decorated: each package calls it from its
``__init__``. The caches stay where numba puts them (``NUMBA_CACHE_DIR``, else ``__pycache__`` beside the
sources, else numba's user-wide cache directory), except that an installed package's are never written beside
its sources (:func:`installed`).
"""

from __future__ import annotations

import ast
import hashlib
import os
import re
import sys
from collections.abc import Callable, Hashable
from functools import lru_cache
from pathlib import Path
from types import SimpleNamespace
from typing import Any

from numba.core import caching

__all__ = ["SourcesLocator", "clear", "installed", "is_compiled", "kernel_sources", "register", "source_digest"]

#: numba's cache implementation (renamed from ``_CacheImpl`` in numba 0.61), and its locator of caches in
#: ``__pycache__`` beside the sources.
_IMPL = getattr(caching, "CacheImpl", None) or getattr(caching, "_CacheImpl")
_IN_TREE = getattr(caching, "InTreeCacheLocator", None) or getattr(caching, "_InTreeCacheLocator")
#: Folders that hold installed distributions: no cache is written inside them (see :func:`installed`).
_INSTALL_DIRS = {"site-packages", "dist-packages"}
#: The registered package folders, each with the key of its run-time extensions (or None).
_ROOTS: dict[Path, Callable[[], Hashable] | None] = {}


#: A file defines a kernel when it mentions numba and one of its compiling decorators or calls.
_KERNEL = re.compile(r"\b(njit|jit|cfunc|vectorize|guvectorize|register_jitable|overload|overload_method|"
                     r"jitclass|generated_jit)\b")
#: Absolute imports followed into other folders: this distribution's only (never numpy, numba, ...).
_TOP = __name__.split(".")[0]


def _module_file(base: Path) -> Path | None:
    """``base.py`` or ``base/__init__.py``, whichever exists."""
    for f in (base.with_suffix(".py"), base / "__init__.py"):
        if f.is_file():
            return f.resolve()
    return None


def _absolute(name: str) -> Path | None:
    """The file of module ``name`` of this distribution, found from its nearest imported parent package."""
    parts = name.split(".")
    if parts[0] != _TOP:
        return None
    for k in range(len(parts), 0, -1):
        mod = sys.modules.get(".".join(parts[:k]))
        if mod is None:
            continue
        if k == len(parts):
            f = getattr(mod, "__file__", None)
            return Path(f).resolve() if f else None
        found = (_module_file(Path(p).joinpath(*parts[k:])) for p in getattr(mod, "__path__", None) or [])
        return next((f for f in found if f is not None), None)
    return None


def _imports(path: Path) -> set[Path]:
    """The files of this distribution that ``path`` imports, anywhere in it (relative imports by folder)."""
    out: set[Path | None] = set()
    for node in ast.walk(ast.parse(path.read_bytes(), filename=str(path))):
        if isinstance(node, ast.Import):
            out |= {_absolute(a.name) for a in node.names}
        elif isinstance(node, ast.ImportFrom) and node.level:
            base = path.parent if node.level == 1 else path.parents[node.level - 2]
            target = base.joinpath(*node.module.split(".")) if node.module else base
            out |= {_module_file(target), *(_module_file(target / a.name) for a in node.names)}
        elif isinstance(node, ast.ImportFrom) and node.module:
            out |= {_absolute(node.module), *(_absolute(f"{node.module}.{a.name}") for a in node.names)}
    return {p for p in out if p is not None}


def kernel_sources(root: str | Path) -> list[Path]:
    """The kernel closure of the package in ``root``: its files that define numba kernels and every module of
    this distribution they import, transitively (sorted, resolved paths)."""
    root = Path(root).resolve()
    todo = [p for p in root.rglob("*.py")
            if "numba" in (text := p.read_text(encoding="utf-8")) and _KERNEL.search(text)]
    seen: set[Path] = set()
    while todo:
        path = todo.pop()
        if path not in seen:
            seen.add(path)
            todo.extend(_imports(path) - seen)
    return sorted(seen)


@lru_cache(maxsize=None)
def _digest(root: Path) -> str:
    """:func:`source_digest`, from the stamp of the last computation when no file it covered has changed (see
    :func:`_stamp`), else computed (and stamped)."""
    stamp = _stamp(root)
    known = _read_stamp(stamp, root) if stamp is not None else None
    if known is not None:
        return known
    closure = kernel_sources(root)
    h = hashlib.sha256()
    for path in closure:
        h.update(Path(os.path.relpath(path, root)).as_posix().encode())
        h.update(path.read_bytes())
    digest = h.hexdigest()
    if stamp is not None:
        _write_stamp(stamp, root, closure, digest)
    return digest


#: Files changed this recently (ns) are not stamped: a file's times have the kernel's clock tick as their
#: resolution, so an edit that keeps the size within the same tick would not show (git's "racy" entries).
_RACY_NS = 2_000_000_000


def _stamp(root: Path) -> Path | None:
    """Where the digest of ``root``'s kernel closure is remembered: beside numba's cache of the package (the
    folder its kernels' cache files go to), or ``None`` when numba offers no such folder."""
    stub = SimpleNamespace(__code__=SimpleNamespace(co_firstlineno=0))
    try:
        locators = SourcesLocator.base_locators(stub, str(root / "__init__.py"))
        return Path(locators[0].get_cache_path()) / "cageless-kernel-closure.json" if locators else None
    except Exception:  # noqa: BLE001 - numba's private locators: without one, compute the digest each time
        return None


def _file_key(path: Path) -> list[int]:
    st = path.stat()
    return [st.st_mtime_ns, st.st_ctime_ns, st.st_size, st.st_ino]


def _tree_keys(root: Path) -> dict[str, list[int]]:
    """Every ``.py`` file under ``root`` with its times, size and inode: a file added, removed or edited anywhere
    in the package can change which files are kernels and what they import."""
    return {str(p): _file_key(p) for p in sorted(root.rglob("*.py"))}


def _read_stamp(stamp: Path, root: Path) -> str | None:
    """The remembered digest, if every file of the package and of the closure outside it is as it was then."""
    import json

    try:
        saved = json.loads(stamp.read_text())
        if saved.get("root") != str(root) or saved.get("tree") != _tree_keys(root):
            return None
        if any(_file_key(Path(f)) != key for f, key in saved["outside"].items()):
            return None
        return str(saved["digest"])
    except (OSError, ValueError, KeyError, TypeError, AttributeError):
        return None


def _write_stamp(stamp: Path, root: Path, closure: list[Path], digest: str) -> None:
    import json
    import time

    try:
        tree = _tree_keys(root)
        outside = {str(p): _file_key(p) for p in closure if not p.is_relative_to(root)}
        newest = max(max(k[0], k[1]) for k in [*tree.values(), *outside.values()])
        if newest > time.time_ns() - _RACY_NS:
            return
        from cageless.atomic import atomic_write_text

        stamp.parent.mkdir(parents=True, exist_ok=True)
        atomic_write_text(stamp, json.dumps({"root": str(root), "digest": digest, "tree": tree, "outside": outside}))
    except (OSError, ValueError):  # a read-only cache folder: compute the digest each time
        pass


def source_digest(root: Path) -> str:
    """SHA-256 over the relative path and bytes of every file of :func:`kernel_sources` (read once per process)."""
    return _digest(Path(root).resolve())


def _root_of(py_file: str) -> Path | None:
    try:
        path = Path(py_file).resolve()
    except OSError:
        return None
    return next((root for root in _ROOTS if path.is_relative_to(root)), None)


class SourcesLocator(caching._CacheLocator):
    """numba's own locator for a function of a registered package, with the package's source digest in its
    stamp."""

    def __init__(self, base: Any, root: Path) -> None:
        self._base = base
        self._root = root

    def ensure_cache_path(self) -> None:
        self._base.ensure_cache_path()

    def get_cache_path(self) -> str:
        return self._base.get_cache_path()

    def get_source_stamp(self) -> Any:
        extra = _ROOTS.get(self._root)
        return (self._base.get_source_stamp(), source_digest(self._root), extra() if extra else None)

    def get_disambiguator(self) -> str:
        return self._base.get_disambiguator()

    @classmethod
    def base_locators(cls, py_func: Any, py_file: str) -> list[Any]:
        """numba's own locators that accept ``py_file``, in its order of preference; for an installed
        package (:func:`installed`) not the one beside the sources."""
        out = []
        skip = _IN_TREE if installed(py_file) else None
        for other in _IMPL._locator_classes:
            if other is skip:
                continue
            if not (isinstance(other, type) and issubclass(other, SourcesLocator)):
                loc = other.from_function(py_func, py_file)
                if loc is not None:
                    out.append(loc)
        return out

    @classmethod
    def from_function(cls, py_func: Any, py_file: str) -> SourcesLocator | None:
        """The locator of a function of a registered package (None elsewhere: numba's own locators take it)."""
        root = _root_of(py_file)
        if root is None:
            return None
        base = cls.base_locators(py_func, py_file)
        return cls(base[0], root) if base else None


def installed(py_file: str | Path) -> bool:
    """Whether ``py_file`` belongs to an installed (not editable) distribution, under ``site-packages``.

    Its kernels are cached in numba's user-wide cache folder (``NUMBA_CACHE_DIR`` if set), not in
    ``__pycache__`` beside it: pip does not remove files it did not install, so after ``pip uninstall`` the
    cache files kept an empty ``cageless`` folder in ``site-packages``, which Python then imported as a
    namespace package in place of a later editable install (``pip install .`` and then ``pip install -e .``
    in the same environment: "cannot import name 'open_video' from 'cageless.tracking.io'").
    """
    return not _INSTALL_DIRS.isdisjoint(Path(py_file).parts)


def register(root: str | Path, extra: Callable[[], Hashable] | None = None) -> None:
    """Cache the kernels of the package in ``root`` under its source digest (and ``extra()``, a key of what
    compiles into them at run time); idempotent. Call before the package's first kernel is decorated."""
    _ROOTS[Path(root).resolve()] = extra
    if SourcesLocator not in _IMPL._locator_classes:
        _IMPL._locator_classes.insert(0, SourcesLocator)


def clear(root: str | Path) -> int:
    """Delete the numba cache files (``*.nbi``, ``*.nbc``) of the kernels under ``root`` wherever numba keeps them
    now; returns how many were deleted. The next run recompiles."""
    removed = 0
    for source in sorted(Path(root).resolve().rglob("*.py")):
        stub = SimpleNamespace(__code__=SimpleNamespace(co_firstlineno=0))
        dirs = {Path(loc.get_cache_path()) for loc in SourcesLocator.base_locators(stub, str(source))}
        for d in dirs:
            for pattern in (f"{source.stem}.*.nbi", f"{source.stem}.*.nbc"):
                for stale in d.glob(pattern):
                    stale.unlink(missing_ok=True)
                    removed += 1
    return removed


def is_compiled(dispatcher: Any) -> bool | None:
    """Whether ``dispatcher`` (a numba ``njit`` function with ``cache=True``) is compiled in this process or has an
    up-to-date entry in its on-disk cache; ``None`` when numba's cache cannot be read.

    numba's index file of a function records the source stamp it was written under; an index written under
    another stamp (other sources, another version) loads as empty, and the function will compile on its first
    call.
    """
    try:
        return bool(dispatcher.signatures) or bool(dispatcher._cache._cache_file._load_index())
    except Exception:  # noqa: BLE001 - a private numba interface: when it moves, say nothing rather than fail
        return None
