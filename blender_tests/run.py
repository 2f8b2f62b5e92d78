"""Run the Blender test suite inside Blender, with the add-on installed the way users install it.

Blender 4.2+ (an application, or PyPI's `bpy` module in a venv), the extension zip of
`make extension`:

    BLENDER_USER_RESOURCES=<empty folder> DCG_EXTENSION=out/dcg_rig-0.1.0.zip \\
        .venv/bpy-4.2/bin/python blender_tests/run.py -- [--junitxml X] [pytest args]

installs the zip into that clean user folder's `user_default` repository and enables it
(bpy.ops.extensions.package_install_files, as Get Extensions > Install from Disk does), so
Blender itself installs the engine's wheel.

Blender 3.x (Debian 12's `blender`), the legacy add-on of the build output:

    BLENDER_USER_SCRIPTS=build/blender_scripts blender -b --factory-startup \\
        --python-exit-code 1 --python blender_tests/run.py -- [--junitxml X] [pytest args]

enables `dcg_rig` from BLENDER_USER_SCRIPTS (never the user's own add-ons folder).

Either way the tests import the add-on as `dcg_rig` (the extension's modules are aliased under
that name), run pytest on this folder and exit with pytest's status. `scripts/run-tests.sh`
(make test) calls it both ways.
"""

import os
import sys

import bpy  # first: as PyPI's module, it puts Blender's own modules on sys.path

import addon_utils  # noqa: E402

HERE = os.path.dirname(os.path.abspath(__file__))


def _fail(message):
    print(f"error: {message}", file=sys.stderr, flush=True)
    sys.exit(2)


def enable_legacy_addon():
    scripts = os.environ.get("BLENDER_USER_SCRIPTS")
    if not scripts or not os.path.isdir(os.path.join(scripts, "addons", "dcg_rig")):
        _fail(f"BLENDER_USER_SCRIPTS={scripts!r} holds no addons/dcg_rig (build first: make build)")
    return addon_utils.enable("dcg_rig", default_set=True, handle_error=None)


def install_extension(archive):
    """Install and enable the extension zip `archive` in the user_default repository."""
    resources = os.environ.get("BLENDER_USER_RESOURCES")
    if not resources or not archive.endswith(".zip") or not os.path.isfile(archive):
        _fail(f"DCG_EXTENSION={archive!r} (a zip) and BLENDER_USER_RESOURCES (a clean folder) "
              "are needed; build it with `make extension`")
    if os.path.isdir(os.path.join(bpy.utils.user_resource("EXTENSIONS"), "user_default", "dcg_rig")):
        _fail(f"BLENDER_USER_RESOURCES={resources} already holds dcg_rig: give a clean folder")
    result = bpy.ops.extensions.package_install_files(
        filepath=os.path.abspath(archive), repo="user_default", enable_on_install=True)
    if result != {"FINISHED"}:
        _fail(f"installing {archive} returned {result}")
    name = "bl_ext.user_default.dcg_rig"
    module = sys.modules.get(name)
    if module is None or not hasattr(bpy.types.Scene, "dcg_rig"):
        _fail(f"{archive} installed but {name} is not enabled")
    alias_as_dcg_rig(name)
    return module


def alias_as_dcg_rig(name):
    """Make `import dcg_rig` and `from dcg_rig import x` give the extension's own modules."""
    import importlib
    import pkgutil

    package = sys.modules[name]
    for info in pkgutil.iter_modules(package.__path__):
        importlib.import_module(f"{name}.{info.name}")
    for key in [k for k in sys.modules if k == name or k.startswith(name + ".")]:
        sys.modules["dcg_rig" + key[len(name):]] = sys.modules[key]


def main():
    args = sys.argv[sys.argv.index("--") + 1:] if "--" in sys.argv else []
    archive = os.environ.get("DCG_EXTENSION")
    module = install_extension(archive) if archive else enable_legacy_addon()
    if module is None:
        _fail("the dcg_rig add-on could not be enabled")
    print(f"dcg_rig enabled from {os.path.dirname(module.__file__)} "
          f"(Blender {bpy.app.version_string}, {'extension' if archive else 'legacy add-on'})",
          flush=True)
    import pytest

    sys.exit(pytest.main([HERE, "-q", "-p", "no:cacheprovider", "--rootdir", HERE, *args]))


main()
