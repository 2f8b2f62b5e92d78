"""dcg.rig_warnings: what the add-on shows and `dcg batch` records of a rig worse than asked."""

import dataclasses

import dcg
from conftest import shared_skeleton
from dcg import bones, rig_warnings

Y_UP = (0.0, 1.0, 0.0)  # spot.obj stands on y


def spot(meshes_dir):
    V, F = dcg.load_mesh(meshes_dir / "spot.obj")
    return shared_skeleton(V, F, "spot.obj")


def test_a_standing_symmetric_model_gets_no_warning(meshes_dir):
    skeleton = spot(meshes_dir)
    plan = bones.plan_bones(skeleton, up=Y_UP)
    assert rig_warnings.plan_warnings(skeleton, plan, up=Y_UP) == []


def test_the_fallback_skeleton_is_said_first_with_its_reason(meshes_dir):
    skeleton = dataclasses.replace(spot(meshes_dir),
                                   method="interim_graph (fallback: no prongs)")
    plan = bones.plan_bones(skeleton, names="mixamo", up=Y_UP)
    warnings = rig_warnings.plan_warnings(skeleton, plan, names="mixamo", up=Y_UP)
    assert warnings[0].startswith("the DCG skeleton failed (no prongs): rigged with the "
                                  "fallback skeleton")
    assert "not humanoid" in warnings[1] and len(warnings) == 2
    assert rig_warnings.is_fallback(skeleton.method)
    assert not rig_warnings.is_fallback("dcg") and rig_warnings.fallback_warning("dcg") is None
    assert "unknown reason" in rig_warnings.fallback_warning("interim_graph")


def test_a_model_on_its_side_is_said_to_lie_with_its_root_off_the_floor(meshes_dir):
    skeleton = spot(meshes_dir)  # across +Z, its mirror plane x = 0 stands; across +X it lies
    side = (1.0, 0.0, 0.0)
    for root_bone in (True, False):
        plan = bones.plan_bones(skeleton, root_bone=root_bone, up=side)
        (warning,) = rig_warnings.plan_warnings(skeleton, plan, root_bone=root_bone, up=side)
        assert warning.startswith("the mirror plane lies level")
        assert ("the root bone sits on that plane" in warning) == root_bone
