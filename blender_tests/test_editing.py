"""Editing the skeleton before binding, driven from Python as a user drives it: Preview
Skeleton's armature is edited in Edit Mode (a joint moved, a spurious end deleted, one side
mirrored onto the other) and Rig with DCG binds it as edited; retarget-ready (Mixamo) names."""

import contextlib
import os
from pathlib import Path

import bpy
import numpy as np
import pytest
from mathutils import Vector

MESHES = Path(os.environ.get("DCG_MESHES", ""))


def preview(**kwargs):
    return bpy.ops.object.dcg_preview(**kwargs)


def rig(**kwargs):
    return bpy.ops.object.dcg_auto_rig(**kwargs)


def preview_skeleton(mesh):
    from dcg_rig import editing

    arm = editing.preview_skeleton(mesh.name)
    assert arm is not None, "Preview Skeleton made no armature"
    return arm


def the_rig():
    (arm,) = [o for o in bpy.data.objects if o.type == "ARMATURE"]
    return arm


@contextlib.contextmanager
def edit_mode(arm, mesh):
    """The armature's edit bones in its Edit Mode; back to Object Mode with the mesh active."""
    view_layer = bpy.context.view_layer
    view_layer.objects.active = arm
    bpy.ops.object.mode_set(mode="EDIT")
    try:
        yield arm.data.edit_bones
    finally:
        bpy.ops.object.mode_set(mode="OBJECT")
        view_layer.objects.active = mesh


def world(arm, point):
    return np.array(arm.matrix_world @ Vector(point))


@pytest.fixture
def spot(repo):
    bpy.ops.dcg.load_mesh(filepath=str(repo / "data" / "spot.obj"))
    obj = bpy.context.active_object
    obj.location = (1.0, 2.0, 0.0)
    bpy.context.view_layer.update()
    return obj


@pytest.fixture
def knight():
    path = MESHES / "knight.off"  # symmetric and humanoid
    if not path.is_file():
        pytest.skip(f"{path} not found (set DCG_MESHES)")
    bpy.ops.dcg.load_mesh(filepath=str(path))
    return bpy.context.active_object


def test_preview_shows_the_bones_rig_would_make_and_rig_replaces_them(spot):
    from dcg_rig import armature, editing

    assert preview() == {"FINISHED"}
    skeleton = preview_skeleton(spot)
    assert skeleton.name in bpy.data.collections["DCG Preview"].objects
    assert armature.find_rigs(spot) == [] and armature.RIG_PROPERTY not in skeleton
    assert not editing.is_edited(skeleton)
    names = [bone.name for bone in skeleton.data.bones]
    assert rig(weights="ENVELOPE") == {"FINISHED"}
    assert [bone.name for bone in the_rig().data.bones] == names
    assert editing.preview_skeleton(spot.name) is None  # the rig replaced the preview


def test_rig_binds_the_edited_skeleton_a_joint_moved_and_an_end_deleted(spot):
    from dcg_rig import editing

    assert preview() == {"FINISHED"}
    skeleton = preview_skeleton(spot)
    bones = skeleton.data.bones
    end = next(b.name for b in bones if b.get("dcg_kind") == "end" and not b.children)
    joint = next(b.name for b in bones if b.children  # a node inside a limb
                 and all(c.use_connect for c in b.children))
    children, count = [c.name for c in bones[joint].children], len(bones)
    size = float(np.linalg.norm(skeleton.dimensions))
    with edit_mode(skeleton, spot) as edit_bones:
        edit_bones.remove(edit_bones[end])  # a spurious end
        edit_bones[joint].tail += Vector((0.0, 0.0, 0.03 * size))  # the joint moved up
        moved = world(skeleton, edit_bones[joint].tail)
    assert editing.is_edited(skeleton)
    assert rig() == {"FINISHED"}  # DCG weights, on the edited bones
    arm = the_rig()
    assert end not in arm.data.bones and len(arm.data.bones) == count - 1
    np.testing.assert_allclose(world(arm, arm.data.bones[joint].tail_local), moved,
                               atol=1e-5 * size)
    for child in children:  # the bones connected to the joint moved with it
        np.testing.assert_allclose(world(arm, arm.data.bones[child].head_local), moved,
                                   atol=1e-5 * size)
    sums = np.array([sum(g.weight for g in v.groups) for v in spot.data.vertices])
    assert np.all(sums > 0.99), "every vertex weighted to the edited bones"
    assert editing.preview_skeleton(spot.name) is None


def test_an_edited_skeleton_survives_a_tau_change_and_a_failed_rig(spot, monkeypatch):
    from dcg_rig import editing, weights

    assert preview() == {"FINISHED"}
    skeleton = preview_skeleton(spot)
    first = skeleton.data.bones[0].name
    with edit_mode(skeleton, spot) as edit_bones:
        edit_bones[first].tail += Vector((0.0, 0.05, 0.0))
    bpy.context.scene.dcg_rig.tau = 0.95  # would redraw an unedited preview
    assert preview_skeleton(spot) == skeleton and editing.is_edited(skeleton)
    monkeypatch.setattr(weights, "apply_weights",
                        lambda *a, **k: (_ for _ in ()).throw(ValueError("no weights")))
    with pytest.raises(RuntimeError, match="no weights"):
        rig()
    assert preview_skeleton(spot) == skeleton and editing.is_edited(skeleton)  # not lost


def test_mirror_skeleton_edit_gives_the_other_side_the_mirror_image(knight):
    from dcg_rig import editing

    assert preview() == {"FINISHED"}
    skeleton = preview_skeleton(knight)
    plane = np.array(skeleton[editing.MIRROR_PLANE])
    normal, offset = plane[:3], plane[3]

    def reflect(point):
        return point - 2.0 * (point @ normal - offset) * normal

    left = next(b.name for b in skeleton.data.bones
                if b.name.endswith(".L") and b.get("dcg_kind") == "end")
    right = editing.partner_name(left)
    size = float(np.linalg.norm(skeleton.dimensions))
    with edit_mode(skeleton, knight) as edit_bones:
        edit_bones[left].tail += Vector((0.0, 0.04 * size, 0.02 * size))
    bones = skeleton.data.bones
    gap = np.linalg.norm(reflect(world(skeleton, bones[left].tail_local))
                         - world(skeleton, bones[right].tail_local))
    assert gap > 0.02 * size, "one side edited only"
    bpy.context.view_layer.objects.active = skeleton
    assert bpy.ops.dcg.mirror_skeleton(source="L") == {"FINISHED"}
    for bone in bones:
        other = editing.partner_name(bone.name)
        if editing.side_of(bone.name) == "L" and other in bones:
            for a, b in ((bone.head_local, bones[other].head_local),
                         (bone.tail_local, bones[other].tail_local)):
                np.testing.assert_allclose(reflect(world(skeleton, a)), world(skeleton, b),
                                           atol=1e-5 * size)


def _printed(capfd):
    out, err = capfd.readouterr()
    return out + err


def test_mixamo_names_for_a_humanoid_and_a_warning_for_a_cow(knight, spot, capfd):
    bpy.context.view_layer.objects.active = knight
    assert rig(weights="NONE", bone_names="MIXAMO") == {"FINISHED"}
    names = {bone.name for bone in the_rig().data.bones}
    assert {"Hips", "Spine", "Neck", "Head", "LeftArm", "LeftForeArm", "RightHand",
            "LeftUpLeg", "RightLeg", "LeftFoot"} <= names
    assert the_rig().data.bones["LeftUpLeg"].parent.name == "Hips"
    assert "mirrored pairs)" in _printed(capfd)  # LeftArm / RightArm, ...
    bpy.context.view_layer.objects.active = spot
    assert rig(weights="NONE", bone_names="MIXAMO") == {"FINISHED"}
    printed = _printed(capfd)
    assert "not humanoid" in printed
    assert "; 10 mirrored pairs)" in printed  # spot's four legs, across its own plane
    rigs = [o for o in bpy.data.objects if o.type == "ARMATURE" and spot.parent == o]
    assert rigs and not any(b.name == "Hips" for b in rigs[0].data.bones)


def test_clear_removes_the_preview_skeleton_even_in_its_edit_mode(spot):
    assert preview() == {"FINISHED"}
    skeleton = preview_skeleton(spot)
    bpy.context.view_layer.objects.active = skeleton
    bpy.ops.object.mode_set(mode="EDIT")
    assert bpy.ops.object.dcg_clear() == {"FINISHED"}
    assert bpy.data.collections.get("DCG Preview") is None
    assert not [o for o in bpy.data.objects if o.type == "ARMATURE"]
    assert bpy.context.mode == "OBJECT"


def test_posing_a_mixamo_hand_moves_that_hand_and_no_other_end(knight):
    """The Mixamo plan's own hierarchy (legs hanging unconnected from Hips, arms from the top
    of the spine) deforms like the descriptive one: the left hand's bone moves the left hand's
    tip, and the other hand, the feet and the head stay."""
    from mathutils import Matrix

    assert rig(bone_names="MIXAMO") == {"FINISHED"}  # DCG weights
    arm = the_rig()
    V0 = np.array([knight.matrix_world @ v.co for v in knight.data.vertices])
    diagonal = float(np.linalg.norm(np.ptp(V0, axis=0)))
    tips = {name: int(np.argmin(np.linalg.norm(
        V0 - world(arm, arm.data.bones[name].tail_local), axis=1)))
        for name in ("LeftHand", "RightHand", "LeftToeBase", "RightToeBase", "HeadTop_End")}
    pose_bone = arm.pose.bones["LeftHand"]
    pose_bone.rotation_mode = "QUATERNION"
    pose_bone.rotation_quaternion = Matrix.Rotation(np.pi / 4, 4, "X").to_quaternion()
    bpy.context.view_layer.update()
    evaluated = knight.evaluated_get(bpy.context.evaluated_depsgraph_get())
    mesh = evaluated.to_mesh()
    try:
        V1 = np.array([evaluated.matrix_world @ v.co for v in mesh.vertices])
    finally:
        evaluated.to_mesh_clear()
    moved = {name: float(np.linalg.norm(V1[i] - V0[i])) / diagonal for name, i in tips.items()}
    assert moved.pop("LeftHand") > 1e-3, "the hand's own tip moved"
    assert max(moved.values()) < 1e-4, moved


def test_mirror_skeleton_edit_of_mixamo_bones(knight):
    from dcg_rig import editing

    assert preview(bone_names="MIXAMO") == {"FINISHED"}
    skeleton = preview_skeleton(knight)
    assert "LeftForeArm" in skeleton.data.bones
    size = float(np.linalg.norm(skeleton.dimensions))
    with edit_mode(skeleton, knight) as edit_bones:
        edit_bones["RightForeArm"].tail += Vector((0.0, 0.03 * size, 0.0))
    bpy.context.view_layer.objects.active = skeleton
    assert bpy.ops.dcg.mirror_skeleton(source="R") == {"FINISHED"}
    plane = np.array(skeleton[editing.MIRROR_PLANE])
    bones = skeleton.data.bones
    mirrored = world(skeleton, bones["RightForeArm"].tail_local)
    mirrored -= 2.0 * (mirrored @ plane[:3] - plane[3]) * plane[:3]
    np.testing.assert_allclose(world(skeleton, bones["LeftForeArm"].tail_local), mirrored,
                               atol=1e-5 * size)
