"""Locate and import the `dcg` engine package without ever failing at import time.

Search order:

1. ``_vendor/dcg`` inside this add-on (the legacy zip for Blender 3.x and the build output
   vendor the package there), imported as a subpackage of the add-on;
2. the folders in the environment variable ``DCG_PYTHONPATH`` (``os.pathsep``-separated),
   for development and for the batch workers;
3. a plain ``import dcg``: the Blender 4.2+ extension lists the engine's wheel in its
   manifest, and Blender installs it into the extensions' own site-packages;
4. ``<repository>/build/python`` when the add-on runs from the source tree
   (``addon/dcg_rig/../../build/python``).

No folder is ever added to ``sys.path`` (the extensions platform forbids it): 1 is a relative
import, 2 and 4 load the package from its folder by file location. The first failure reasons
are kept so that the UI and the CLI can show them instead of crashing.
"""

import importlib
import importlib.util
import os
import sys

_HERE = os.path.dirname(os.path.abspath(__file__))

_module = None
_error = None


class EngineUnavailable(RuntimeError):
    """The `dcg` package could not be imported; the message says where it was looked for."""


def _folders(paths):
    """The `dcg` package folders under `paths` that exist."""
    return [os.path.join(p, "dcg") for p in paths
            if os.path.isfile(os.path.join(p, "dcg", "__init__.py"))]


def _from_folder(folder):
    """Import the package in `folder` as the top-level module `dcg`, by file location."""
    spec = importlib.util.spec_from_file_location(
        "dcg", os.path.join(folder, "__init__.py"), submodule_search_locations=[folder])
    module = importlib.util.module_from_spec(spec)
    sys.modules["dcg"] = module
    try:
        spec.loader.exec_module(module)
    except BaseException:
        for name in [n for n in sys.modules if n == "dcg" or n.startswith("dcg.")]:
            del sys.modules[name]
        raise
    return module


def _attempts():
    """(where, how) pairs in search order; `how()` returns the module or raises ImportError."""
    attempts = []
    if os.path.isfile(os.path.join(_HERE, "_vendor", "dcg", "__init__.py")) and __package__:
        attempts.append(("the add-on's _vendor/dcg",
                         lambda: importlib.import_module(__package__ + "._vendor.dcg")))
    env = [p for p in os.environ.get("DCG_PYTHONPATH", "").split(os.pathsep) if p]
    attempts += [(folder, lambda f=folder: _from_folder(f)) for folder in _folders(env)]
    attempts.append(("the installed dcg package (the extension's wheel)",
                     lambda: importlib.import_module("dcg")))
    source_build = os.path.normpath(os.path.join(_HERE, "..", "..", "build", "python"))
    attempts += [(folder, lambda f=folder: _from_folder(f)) for folder in _folders([source_build])]
    return attempts


def _try_import():
    """Import `dcg` from the first place that holds a working one; return (module, error)."""
    if "dcg" in sys.modules and hasattr(sys.modules["dcg"], "extract_skeleton"):
        return sys.modules["dcg"], None
    failures = []
    for where, how in _attempts():
        try:
            return how(), None
        except ImportError as exc:
            failures.append(f"{where}: {exc}")
    return None, ("the dcg engine package could not be imported (install the extension's "
                  "wheel, build it with `make build`, or set DCG_PYTHONPATH); tried "
                  + "; ".join(failures))


def load():
    """Return the `dcg` module, or None when it cannot be imported (see `error()`)."""
    global _module, _error
    if _module is None and _error is None:
        _module, _error = _try_import()
    return _module


def error():
    """Return why `dcg` could not be imported, or None when it imports."""
    load()
    return _error


def require():
    """Return the `dcg` module or raise EngineUnavailable with the reason."""
    module = load()
    if module is None:
        raise EngineUnavailable(_error)
    return module
