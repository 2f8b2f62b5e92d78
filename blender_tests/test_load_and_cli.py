"""Loading mesh files in Blender (dcg.load_mesh operator) and the headless CLI (make rig)."""

import subprocess
import sys

import bpy
import pytest
from conftest import addon_dir, blender_command, scene_counts


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
    """Run the enabled add-on's own cli.py (the installed extension's, on 4.2+)."""
    command = blender_command(addon_dir() / "cli.py", *args)
    return subprocess.run(command, capture_output=True, text=True, timeout=300)


@pytest.mark.parametrize("case", ["missing", "empty", "out_of_range"])
def test_cli_reports_bad_files_with_exit_status_1(repo, bad_files, case):
    result = run_cli(repo, bad_files[case])
    assert result.returncode == 1, result.stdout + result.stderr
    assert "error:" in result.stderr and bad_files[case].name in result.stderr


@pytest.fixture(scope="module")
def cli_outputs(repo, tmp_path_factory):
    """Run the CLI once on hand.obj (spot.obj without the public meshes) with every output."""
    import os

    meshes = os.environ.get("DCG_MESHES", "")
    source = os.path.join(meshes, "hand.obj")
    if not os.path.isfile(source):
        source = repo / "data" / "spot.obj"
    folder = tmp_path_factory.mktemp("cli")
    result = run_cli(repo, source, "-o", folder / "r.blend", "--glb", folder / "r.glb",
                     "--fbx", folder / "r.fbx", "--png", folder / "r.png",
                     "--resolution", 320, 240, "--weights", "ENVELOPE")
    assert result.returncode == 0, result.stdout + result.stderr
    with bpy.data.libraries.load(str(folder / "r.blend")) as (source_data, _):
        pass
    return folder


def saved_bone_count(blend):
    """The bone count of the DCG rig saved in `blend`, read with a library load."""
    with bpy.data.libraries.load(str(blend)) as (source, target):
        target.armatures = [n for n in source.armatures if "DCG Rig" in n]
    (armature,) = target.armatures
    count = len(armature.bones)
    bpy.data.armatures.remove(armature)
    return count


def test_cli_writes_blend_glb_fbx_and_png(cli_outputs):
    assert (cli_outputs / "r.glb").read_bytes()[:4] == b"glTF"
    assert (cli_outputs / "r.fbx").read_bytes()[:18] == b"Kaydara FBX Binary"
    assert (cli_outputs / "r.png").read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    image = bpy.data.images.load(str(cli_outputs / "r.png"))
    try:
        assert tuple(image.size) == (320, 240)
    finally:
        bpy.data.images.remove(image)
    assert saved_bone_count(cli_outputs / "r.blend") > 0


@pytest.mark.parametrize("name", ["r.glb", "r.fbx"])
def test_exported_files_reimport_as_a_skinned_mesh_with_the_same_bones(cli_outputs, name):
    path = str(cli_outputs / name)
    if name.endswith(".glb"):
        from dcg_rig import importing

        importing.ensure_numpy_bool_alias()  # Blender 3.4's glTF importer with numpy 1.24
        bpy.ops.import_scene.gltf(filepath=path)
    else:
        bpy.ops.import_scene.fbx(filepath=path)
    (arm,) = [o for o in bpy.data.objects if o.type == "ARMATURE"]
    meshes = [o for o in bpy.data.objects if o.type == "MESH"]
    assert len(arm.data.bones) == saved_bone_count(cli_outputs / "r.blend")
    assert "root" in arm.data.bones  # the root bone on the floor goes out with the rest
    skinned = [m for m in meshes if any(md.type == "ARMATURE" and md.object == arm
                                        for md in m.modifiers)]
    assert skinned and len(skinned[0].vertex_groups) > 0


def test_cli_rigs_a_gltf_file_replacing_the_rig_it_holds(repo, cli_outputs, tmp_path):
    result = run_cli(repo, cli_outputs / "r.glb", "-o", tmp_path / "again.blend",
                     "--weights", "ENVELOPE")
    assert result.returncode == 0, result.stdout + result.stderr
    with bpy.data.libraries.load(str(tmp_path / "again.blend")) as (source, _):
        assert len(source.armatures) == 1


def _appended_objects(blend):
    """The objects saved in `blend`, appended (not linked to the scene)."""
    with bpy.data.libraries.load(str(blend)) as (source, target):
        target.objects = list(source.objects)
    return [o for o in target.objects if o is not None]


def test_cli_rigs_the_model_of_a_skinned_gltf_not_its_bone_shape(repo, tmp_path):
    """Blender 4.0+'s glTF importer adds a hidden "Icosphere" (the bones' display shape) to a
    file with an armature; spot sorts after it and must be the mesh rigged, whole."""
    first = tmp_path / "spot.glb"
    result = run_cli(repo, repo / "data" / "spot.obj", "--glb", first, "--weights", "ENVELOPE")
    assert result.returncode == 0, result.stdout + result.stderr
    from dcg_rig import importing

    importing.ensure_numpy_bool_alias()
    bpy.ops.import_scene.gltf(filepath=str(first))
    (model,) = [o for o in bpy.data.objects if o.type == "MESH" and o.name.startswith("spot")]
    expected = len(model.data.vertices)
    result = run_cli(repo, first, "-o", tmp_path / "again.blend", "--glb", tmp_path / "again.glb",
                     "--weights", "ENVELOPE")
    assert result.returncode == 0, result.stdout + result.stderr
    objects = _appended_objects(tmp_path / "again.blend")
    meshes = [o for o in objects if o.type == "MESH"]
    assert [o.type for o in objects].count("ARMATURE") == 1
    assert len(meshes) == 1 and meshes[0].name.startswith("spot"), [o.name for o in objects]
    assert len(meshes[0].data.vertices) == expected
    unweighted = sum(1 for v in meshes[0].data.vertices if not any(g.weight > 0 for g in v.groups))
    assert unweighted == 0
    assert (tmp_path / "again.glb").stat().st_size > 0


def test_cli_rejects_unknown_formats(repo, tmp_path):
    path = tmp_path / "model.xyz"
    path.write_text("1 2 3\n")
    result = run_cli(repo, path)
    assert result.returncode == 1 and "unknown format" in result.stderr


def test_cli_names_a_humanoids_bones_after_mixamo(repo, tmp_path):
    import os

    source = os.path.join(os.environ.get("DCG_MESHES", ""), "knight.off")
    if not os.path.isfile(source):
        pytest.skip(f"{source} not found (set DCG_MESHES)")
    result = run_cli(repo, source, "-o", tmp_path / "k.blend", "--weights", "NONE",
                     "--bone-names", "mixamo", "--no-root-bone")
    assert result.returncode == 0, result.stdout + result.stderr
    with bpy.data.libraries.load(str(tmp_path / "k.blend")) as (source_data, target):
        target.armatures = [n for n in source_data.armatures if "DCG Rig" in n]
    (armature,) = target.armatures
    names = {bone.name for bone in armature.bones}
    bpy.data.armatures.remove(armature)
    assert {"Hips", "Spine", "Head", "LeftForeArm", "RightUpLeg", "LeftFoot"} <= names
    assert "root" not in names  # --no-root-bone: Hips is the root, as in Mixamo's own rig
