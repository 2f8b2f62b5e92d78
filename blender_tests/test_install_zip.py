"""The legacy zip (make addon, Blender 3.x) installs, enables and rigs in a clean Blender.
The extension (Blender 4.2+) has its own tests in test_extension.py."""

import importlib.util
import os
import subprocess
import zipfile

import bpy
import pytest
from conftest import AS_EXTENSION

SCRIPT = """
import sys, bpy, addon_utils
import numpy as np
bpy.ops.preferences.addon_install(filepath=sys.argv[-1])
module = addon_utils.enable("dcg_rig", default_set=True, handle_error=None)
assert module is not None, "not enabled"
print("DCG-INSTALLED-AT", module.__file__)
bpy.ops.mesh.primitive_cylinder_add(vertices=32, radius=0.3, depth=2.0)
bpy.ops.object.dcg_auto_rig(weights="ENVELOPE")
arm = [o for o in bpy.data.objects if o.type == "ARMATURE"]
assert len(arm) == 1 and len(arm[0].data.bones) > 0, "no rig"
print("DCG-RIGGED", len(arm[0].data.bones))
"""


@pytest.mark.skipif(AS_EXTENSION, reason="Blender 4.2+ installs the extension (test_extension.py)")
def test_the_zip_installs_enables_and_rigs_in_a_clean_blender(repo, tmp_path):
    spec = importlib.util.spec_from_file_location("make_addon_zip",
                                                  repo / "scripts" / "make_addon_zip.py")
    maker = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(maker)
    archive = tmp_path / "dcg_rig.zip"
    source = os.path.join(os.environ["BLENDER_USER_SCRIPTS"], "addons", "dcg_rig")
    assert maker.make_zip(source, archive) > 5
    assert "dcg_rig/blender_manifest.toml" not in zipfile.ZipFile(archive).namelist()
    script = tmp_path / "install.py"
    script.write_text(SCRIPT)
    clean = tmp_path / "clean"
    env = {k: v for k, v in os.environ.items()
           if k not in ("DCG_PYTHONPATH", "PYTHONPATH", "BLENDER_USER_SCRIPTS")}
    env.update(BLENDER_USER_CONFIG=str(clean / "config"),
               BLENDER_USER_SCRIPTS=str(clean / "scripts"))
    result = subprocess.run([bpy.app.binary_path, "-b", "--factory-startup",
                             "--python-exit-code", "1", "--python", str(script), "--",
                             str(archive)], capture_output=True, text=True, env=env,
                            timeout=300)
    output = result.stdout + result.stderr
    assert result.returncode == 0, output
    installed = next(line for line in output.splitlines() if "DCG-INSTALLED-AT" in line)
    assert str(clean) in installed
    assert "DCG-RIGGED" in output
