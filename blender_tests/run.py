"""Run the Blender test suite inside Blender:

    BLENDER_USER_SCRIPTS=build/blender_scripts blender -b --factory-startup \\
        --python-exit-code 1 --python blender_tests/run.py -- [--junitxml X] [pytest args]

Enables the add-on `dcg_rig` from BLENDER_USER_SCRIPTS (the build output, never the user's
own add-ons folder), then runs pytest on this folder with Blender's Python, and exits with
pytest's status. `scripts/run-tests.sh` (make test) calls it this way.
"""

import os
import sys

import addon_utils
import bpy

HERE = os.path.dirname(os.path.abspath(__file__))


def main():
    args = sys.argv[sys.argv.index("--") + 1:] if "--" in sys.argv else []
    scripts = os.environ.get("BLENDER_USER_SCRIPTS")
    if not scripts or not os.path.isdir(os.path.join(scripts, "addons", "dcg_rig")):
        print(f"error: BLENDER_USER_SCRIPTS={scripts!r} holds no addons/dcg_rig "
              "(build first: make build)", file=sys.stderr)
        sys.exit(2)
    module = addon_utils.enable("dcg_rig", default_set=True, handle_error=None)
    if module is None:
        print("error: the dcg_rig add-on could not be enabled", file=sys.stderr)
        sys.exit(2)
    print(f"dcg_rig enabled from {os.path.dirname(module.__file__)} "
          f"(Blender {bpy.app.version_string})", flush=True)
    import pytest

    sys.exit(pytest.main([HERE, "-q", "-p", "no:cacheprovider", "--rootdir", HERE, *args]))


main()
