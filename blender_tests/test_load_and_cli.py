"""Loading mesh files in Blender (dcg.load_mesh operator) and the headless CLI (make rig)."""

import subprocess
import sys

import bpy
import pytest
from conftest import scene_counts


@pytest.fixture
def bad_files(tmp_path):
    empty = tmp_path / "empty.obj"
    empty.write_text("")
    out_of_range = tmp_path / "out_of_range.obj"
    out_of_range.write_text("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 9\n")
    return {"missing": tmp_path / "missing.obj", "empty": empty, "out_of_range": out_of_range}


@pytest.mark.parametrize("case", ["missing", "empty", "out_of_range"])
def test_load_mesh_reports_bad_files_and_changes_nothing(bad_files, case):
    path = bad_files[case]
    before = scene_counts()
    with pytest.raises(RuntimeError) as error:
        bpy.ops.dcg.load_mesh(filepath=str(path))
    assert path.name in str(error.value)
    assert scene_counts() == before


def test_load_mesh_makes_an_active_object_y_up_for_obj(repo):
    assert bpy.ops.dcg.load_mesh(filepath=str(repo / "data" / "spot.obj")) == {"FINISHED"}
    obj = bpy.context.active_object
    assert obj.name == "spot" and len(obj.data.polygons) == 5856
    assert obj.rotation_euler.x == pytest.approx(1.5707963)


def run_cli(repo, *args):
    command = [bpy.app.binary_path, "-b", "--factory-startup", "--python",
               str(repo / "addon" / "dcg_rig" / "cli.py"), "--", *map(str, args)]
    return subprocess.run(command, capture_output=True, text=True, timeout=300)


@pytest.mark.parametrize("case", ["missing", "empty", "out_of_range"])
def test_cli_reports_bad_files_with_exit_status_1(repo, bad_files, case):
    result = run_cli(repo, bad_files[case])
    assert result.returncode == 1, result.stdout + result.stderr
    assert "error:" in result.stderr and bad_files[case].name in result.stderr


def test_cli_writes_blend_glb_and_png(repo, tmp_path):
    result = run_cli(repo, repo / "data" / "meshes" / "eight.off", "-o", tmp_path / "e.blend",
                     "--glb", tmp_path / "e.glb", "--png", tmp_path / "e.png",
                     "--resolution", 320, 240, "--weights", "ENVELOPE")
    assert result.returncode == 0, result.stdout + result.stderr
    assert (tmp_path / "e.glb").read_bytes()[:4] == b"glTF"
    assert (tmp_path / "e.png").read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    assert (tmp_path / "e.blend").stat().st_size > 0
    image = bpy.data.images.load(str(tmp_path / "e.png"))
    try:
        assert tuple(image.size) == (320, 240)
    finally:
        bpy.data.images.remove(image)
    # The saved scene holds the rig.
    with bpy.data.libraries.load(str(tmp_path / "e.blend")) as (source, _):
        assert any("DCG Rig" in name for name in source.armatures)
