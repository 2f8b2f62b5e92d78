"""Locate and import the `dcg` engine package without ever failing at import time.

Search order:

1. ``dcg_rig/_vendor`` next to this file (the build output and the installable zip vendor
   the package there);
2. the folders in the environment variable ``DCG_PYTHONPATH`` (``os.pathsep``-separated);
3. ``<repository>/build/python`` when the add-on runs from the source tree
   (``addon/dcg_rig/../../build/python``);
4. a plain ``import dcg`` (whatever ``sys.path`` already holds).

Blender ignores ``PYTHONPATH`` by default, hence the explicit search. The first failure
reason is kept so that the UI and the CLI can show it instead of crashing.
"""

import importlib
import os
import sys

_HERE = os.path.dirname(os.path.abspath(__file__))

_module = None
_error = None


class EngineUnavailable(RuntimeError):
    """The `dcg` package could not be imported; the message says where it was looked for."""


def candidate_paths():
    """Return the folders searched for the `dcg` package, in order (existing ones only)."""
    paths = [os.path.join(_HERE, "_vendor")]
    paths += [p for p in os.environ.get("DCG_PYTHONPATH", "").split(os.pathsep) if p]
    paths.append(os.path.normpath(os.path.join(_HERE, "..", "..", "build", "python")))
    return [p for p in paths if os.path.isdir(os.path.join(p, "dcg"))]


def _try_import():
    """Import `dcg` from the first candidate folder that holds it; return (module, error)."""
    failures = []
    for path in candidate_paths():
        sys.path.insert(0, path)
        try:
            return importlib.import_module("dcg"), None
        except ImportError as exc:
            failures.append(f"{path}: {exc}")
            sys.path.remove(path)
            sys.modules.pop("dcg", None)
    try:
        return importlib.import_module("dcg"), None
    except ImportError as exc:
        failures.append(f"sys.path: {exc}")
    return None, ("the dcg engine package could not be imported (build it with `make build`"
                  " or set DCG_PYTHONPATH); tried " + "; ".join(failures))


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
