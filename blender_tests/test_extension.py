"""The Blender 4.2+ extension (make extension): what run.py installed from the zip into a clean
user folder, and the same zip installed again in a new Blender process."""

import glob
import os
import subprocess
import sys
import zipfile

import bpy
import pytest
from conftest import AS_EXTENSION, addon_dir, blender_command

pytestmark = pytest.mark.skipif(not AS_EXTENSION, reason="the legacy add-on runs here (Blender 3.x "
                                "has no extensions; test_install_zip.py tests its zip)")

ARCHIVE = os.environ.get("DCG_EXTENSION", "")


def test_the_addon_is_the_installed_extension_with_relative_imports_only():
    folder = addon_dir()
    assert sys.modules["dcg_rig"].__name__ == "bl_ext.user_default.dcg_rig"
    assert str(folder.parent) == os.path.realpath(
        bpy.utils.user_resource("EXTENSIONS", path="user_default"))
    assert not (folder / "_vendor").exists()
    for path in folder.glob("*.py"):
        text = path.read_text()
        assert "sys.path.insert" not in text or path.name == "cli.py", path
        assert "import dcg_rig" not in text or path.name == "cli.py", path


def test_the_engine_comes_from_the_wheel_blender_installed(dcg):
    site = os.path.realpath(bpy.utils.user_resource("EXTENSIONS", path=".local"))
    assert os.path.realpath(dcg.__file__).startswith(site), dcg.__file__
    assert os.path.realpath(dcg._core.__file__).startswith(site)
    # auditwheel's copies of Embree, TBB, GMP and MPFR sit beside it (dcg.libs/).
    libs = glob.glob(os.path.join(os.path.dirname(os.path.dirname(dcg.__file__)), "dcg.libs", "*"))
    assert any("embree" in os.path.basename(lib) for lib in libs), libs


def test_the_manifest_lists_the_wheels_and_passes_blenders_validation(tmp_path):
    with zipfile.ZipFile(ARCHIVE) as archive:
        names = archive.namelist()
        manifest = archive.read("blender_manifest.toml").decode()
    wheels = [n for n in names if n.startswith("wheels/") and n.endswith(".whl")]
    assert wheels and all(f'"./{w}"' in manifest for w in wheels)
    assert 'blender_version_min = "4.2.0"' in manifest and "SPDX:GPL-3.0-or-later" in manifest
    # What `blender --command extension validate` runs (a PyPI bpy has no blender binary).
    tool = os.path.join(bpy.utils.system_resource("SCRIPTS"), "addons_core", "bl_pkg", "cli",
                        "blender_ext.py")
    assert os.path.isfile(tool), tool
    result = subprocess.run([sys.executable, tool, "validate", ARCHIVE], capture_output=True,
                            text=True, timeout=120)
    assert result.returncode == 0 and "error" not in result.stdout.lower(), \
        result.stdout + result.stderr


INSTALL = """
import os, sys, bpy
archive = sys.argv[sys.argv.index("--") + 1]
bpy.ops.wm.read_factory_settings(use_empty=True)
bpy.ops.extensions.package_install_files(filepath=archive, repo="user_default",
                                         enable_on_install=True)
module = sys.modules.get("bl_ext.user_default.dcg_rig")
assert module is not None and hasattr(bpy.types.Scene, "dcg_rig"), "not enabled"
print("DCG-INSTALLED-AT", module.__file__)
bpy.ops.mesh.primitive_cylinder_add(vertices=32, radius=0.3, depth=2.0)
bpy.ops.object.dcg_auto_rig(weights="DCG")
arm = [o for o in bpy.data.objects if o.type == "ARMATURE"]
assert len(arm) == 1 and len(arm[0].data.bones) > 0, "no rig"
print("DCG-RIGGED", len(arm[0].data.bones), len(arm[0].data.collections))
"""


def test_the_zip_installs_enables_and_rigs_in_another_clean_user_folder(tmp_path):
    script = tmp_path / "install.py"
    script.write_text(INSTALL)
    clean = tmp_path / "clean"
    env = {k: v for k, v in os.environ.items() if k not in ("DCG_PYTHONPATH", "PYTHONPATH")}
    env["BLENDER_USER_RESOURCES"] = str(clean)
    result = subprocess.run(blender_command(script, ARCHIVE), capture_output=True, text=True,
                            env=env, timeout=300)
    output = result.stdout + result.stderr
    assert result.returncode == 0, output
    installed = next(line for line in output.splitlines() if "DCG-INSTALLED-AT" in line)
    assert str(clean) in installed
    rigged = next(line for line in output.splitlines() if line.startswith("DCG-RIGGED"))
    assert int(rigged.split()[2]) > 0  # bone collections by kind
