"""The rig operator on the objects users really have: modifiers, shape keys, transforms,
negative scale, shared mesh data, someone else's armature, Edit Mode."""

import bpy
import numpy as np
import pytest

from conftest import add_mesh, capsule, scene_counts


def rig(**kwargs):
    return bpy.ops.object.dcg_auto_rig(**kwargs)


def dcg_armature():
    arms = [o for o in bpy.data.objects if o.type == "ARMATURE" and "dcg_rig" in o]
    assert len(arms) == 1
    return arms[0]


def bones_world(arm):
    """The deforming bones' heads and tails in world space (the root bone stands on the
    world's floor, wherever the mesh's own axes point)."""
    from dcg_rig import armature

    heads, tails = armature.bone_world_segments(arm, deforming=True)
    return np.vstack([heads, tails])


def test_rotation_scale_not_applied_and_negative_scale():
    obj = add_mesh("capsule", *capsule(), location=(1.0, 2.0, 3.0),
                   rotation=(0.3, -0.7, 1.1))
    obj.scale = (-1.5, 1.5, 1.5)  # mirrored: the triangles' winding flips in world space
    bpy.context.view_layer.update()
    assert rig(weights="ENVELOPE") == {"FINISHED"}
    points = bones_world(dcg_armature())
    # The capsule's axis is local z: in world space the bones lie along the mapped axis.
    matrix = np.array(obj.matrix_world)
    local = (points - matrix[:3, 3]) @ np.linalg.inv(matrix[:3, :3]).T
    assert np.abs(local[:, :2]).max() < 0.35
    assert np.abs(local[:, 2]).max() < 1.35


def test_shape_keys_are_kept_and_still_work():
    obj = add_mesh("capsule", *capsule())
    obj.shape_key_add(name="Basis")
    key = obj.shape_key_add(name="Bulge")
    for point in key.data:
        point.co *= 1.2
    assert rig(weights="ENVELOPE") == {"FINISHED"}
    assert obj.data.shape_keys is not None and len(obj.data.shape_keys.key_blocks) == 2
    obj.data.shape_keys.key_blocks["Bulge"].value = 1.0
    bpy.context.view_layer.update()


def test_shared_mesh_data_is_refused_with_the_reason():
    first = add_mesh("first", *capsule())
    second = bpy.data.objects.new("second", first.data)
    bpy.context.scene.collection.objects.link(second)
    before = scene_counts()
    with pytest.raises(RuntimeError, match="shares its mesh data"):
        rig()
    assert scene_counts() == before


def test_an_existing_foreign_armature_modifier_is_disabled_with_a_warning():
    obj = add_mesh("capsule", *capsule())
    other = bpy.data.objects.new("Their Rig", bpy.data.armatures.new("Their Rig"))
    bpy.context.scene.collection.objects.link(other)
    modifier = obj.modifiers.new("Their Armature", "ARMATURE")
    modifier.object = other
    bpy.context.view_layer.objects.active = obj
    assert rig(weights="ENVELOPE") == {"FINISHED"}
    assert "Their Rig" in bpy.data.objects  # never deleted
    assert not obj.modifiers["Their Armature"].show_viewport
    assert any(m.type == "ARMATURE" and m.object == dcg_armature() and m.show_viewport
               for m in obj.modifiers)


def test_a_fallback_skeleton_is_rigged_with_a_warning(dcg):
    """When stages 4-8 fail the engine returns its fallback skeleton; the user is told so."""
    import dataclasses

    from dcg_rig import mesh_io, rigging

    obj = add_mesh("capsule", *capsule())
    skeleton = dcg.extract_skeleton(*mesh_io.evaluated_world_mesh(bpy.context, obj))
    assert skeleton.method == "dcg" and rigging.fallback_warning(skeleton.method) is None
    fallback = dataclasses.replace(skeleton, method="interim_graph (fallback: no prong)")
    result = rigging.apply_rig(bpy.context, obj, fallback, "ENVELOPE")
    assert result.warnings and "fallback skeleton" in result.warnings[0]
    assert "no prong" in result.warnings[0]


def test_edit_mode_is_refused_by_poll():
    add_mesh("capsule", *capsule())
    bpy.ops.object.mode_set(mode="EDIT")
    try:
        with pytest.raises(RuntimeError, match="Object Mode"):
            rig()
    finally:
        bpy.ops.object.mode_set(mode="OBJECT")
    assert not [o for o in bpy.data.objects if o.type == "ARMATURE"]


def test_a_multi_part_mesh_is_rigged_as_one_object():
    V1, F1 = capsule()
    V2 = V1 + np.array([2.0, 0.0, 0.0])
    V = np.vstack([V1, V2])
    F = np.vstack([F1, F1 + len(V1)])
    obj = add_mesh("two capsules", V, F)
    assert rig(weights="ENVELOPE") == {"FINISHED"}
    sums = np.array([sum(g.weight for g in v.groups) for v in obj.data.vertices])
    assert np.allclose(sums, 1.0, atol=1e-3)


def test_nan_coordinates_are_an_error_report_that_changes_nothing():
    obj = add_mesh("broken", *capsule())
    obj.data.vertices[5].co = (float("nan"), 0.0, 0.0)  # after validate(), which would fix it
    before = scene_counts()
    with pytest.raises(RuntimeError, match="DCG: .*(NaN|finite|nan)"):
        rig()
    assert scene_counts() == before


def test_a_flat_mesh_is_an_error_report_or_a_rig_never_a_crash():
    V = np.array([[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0]], dtype=float)
    F = np.array([[0, 1, 2], [0, 2, 3], [0, 2, 1], [0, 3, 2]])
    add_mesh("flat", V, F)
    before = scene_counts()
    try:
        result = rig(weights="ENVELOPE")
    except RuntimeError as error:
        assert "DCG:" in str(error)
        assert scene_counts() == before
    else:
        assert result == {"FINISHED"}
