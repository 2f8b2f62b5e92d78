"""The plan's root bone (dcg.bones.add_root): a control on the floor under the body, parent of
every other bone, weighting nothing."""

import dataclasses

import numpy as np
import pytest

import dcg
from dcg import bones, humanoid, symmetry
from test_bones import body, limb_plan, skeleton_of
from test_humanoid import person


def test_the_root_bone_stands_on_the_floor_under_the_body_and_parents_every_limb():
    skeleton = body()  # radii 0.1, feet at z = -1.2, the hips (the root node) at the origin
    plan = bones.plan_bones(skeleton, bone_detail=1.0)
    root = plan[0]
    assert (root.name, root.kind, root.parent, root.node, root.link) == (
        bones.ROOT_NAME, "root", None, -1, -1)
    # The floor under the lowest ball, under the middle of the balls' box: x from -1.3 to 1.3.
    assert np.allclose(root.head, [0.0, 0.0, -1.3])
    assert np.allclose(root.tail, skeleton.positions[skeleton.root])
    # Every limb hangs from it, and the rest of the plan is the limbs' as they were.
    limbs = limb_plan(skeleton, bone_detail=1.0)
    assert [spec.name for spec in plan[1:]] == [spec.name for spec in limbs]
    assert [spec.parent for spec in plan[1:]] == [
        bones.ROOT_NAME if spec.parent is None else spec.parent for spec in limbs]
    assert not any(spec.use_connect for spec in plan if spec.parent == bones.ROOT_NAME)
    # A middle bone: its Z axis normal to it and in the mirror plane (x = 0), so it mirrors
    # onto itself.
    assert abs(root.z_axis @ (root.tail - root.head)) < 1e-9
    assert abs(root.z_axis[0]) < 1e-9 and np.isclose(np.linalg.norm(root.z_axis), 1.0)


def test_the_floor_lies_across_the_up_direction_given():
    skeleton = body()  # flat: every node at y = 0
    root = bones.plan_bones(skeleton, up=(0.0, 1.0, 0.0), origin=None)[0]
    assert np.allclose(root.head, [0.0, -0.1, 0.2])  # under the middle of the balls' box
    root = bones.plan_bones(skeleton, up=(0.0, 1.0, 0.0))[0]
    assert np.allclose(root.head, [0.0, -0.1, 0.0])  # under the origin, over the body
    assert bones.plan_bones(skeleton, root_bone=False)[0].kind != "root"
    # A body lying on its side (up along the mirror plane's normal) keeps its root bone in
    # the plane, a bone of the middle, rather than beside one half.
    root = bones.plan_bones(skeleton, up=(1.0, 0.0, 0.0), origin=None)[0]
    assert np.allclose(root.head, [0.0, 0.0, 0.2])


def test_the_root_bone_stands_under_the_models_origin_when_that_is_over_the_body():
    """Where a game character's artist puts its origin, and the Blender object's origin the
    user sees: on the floor under the body. Off the body's footprint it says nothing of where
    the body stands; off the mirror plane the root still goes onto the plane."""
    skeleton = body()  # feet at z = -1.2 (floor -1.3), the balls' box x -1.3..1.3, y -0.1..0.1
    assert np.allclose(bones.plan_bones(skeleton, origin=(0.6, 0.05, 2.0))[0].head,
                       [0.0, 0.05, -1.3])  # onto the plane x = 0 along the floor
    assert np.allclose(bones.plan_bones(skeleton, origin=(0.6, 0.5, 0.0))[0].head,
                       [0.0, 0.0, -1.3])  # y = 0.5: off the footprint, under the centre
    turned = bones.plan_bones(skeleton, up=(0.0, 1.0, 0.0), origin=(0.0, 5.0, -0.5))[0]
    assert np.allclose(turned.head, [0.0, -0.1, -0.5])  # any height: it drops to the floor
    assert np.allclose(bones.plan_bones(skeleton, up=(0.0, 1.0, 0.0),
                                        origin=(0.0, 0.0, -2.0))[0].head, [0.0, -0.1, 0.2])


def test_a_tilted_mirror_plane_gets_the_root_on_the_floor_and_on_the_plane():
    # The floor turned 20 degrees about y: the mirror plane x = 0 stands 20 degrees from
    # upright. The root's head moves along the floor onto the plane (along the plane's normal
    # it would sink below the floor).
    skeleton = body()
    angle = np.radians(20.0)
    up = np.array([np.sin(angle), 0.0, np.cos(angle)])
    root = bones.plan_bones(skeleton, up=up)[0]
    positions, radii = np.asarray(skeleton.positions), np.asarray(skeleton.radii)
    floor = float(np.min(positions @ up - radii))
    assert abs(root.head @ up - floor) < 1e-9
    assert abs(root.head[0]) < 1e-9


def rearing_snake():
    """A snake's skeleton along x on the floor (balls of radius 0.2) that rears its head, the
    skeleton's root, up at one end: nodes tail, middle, neck, head (the root)."""
    positions = [[0.0, 0.0, 0.2], [1.0, 0.0, 0.2], [2.0, 0.0, 0.2], [2.2, 0.0, 1.5]]
    return skeleton_of(positions, ["end", "connection", "connection", "end"],
                       [[3, 2], [2, 1], [1, 0]], root=3, radii=np.full(4, 0.2))


def test_a_level_mirror_plane_lifts_the_root_only_when_bones_are_sided():
    """A plane that lies level (a shape mirrored top to bottom, like SkinnedCylinder across its
    middle; or a model lying on its side): the root bone leaves the floor for it only when
    some bones are .L / .R, whose mirror tools need the root on the plane; else it stays on
    the floor under the body."""
    skeleton = rearing_snake()
    plan = bones.plan_bones(skeleton, root_bone=False)
    level = symmetry.Plane(np.array([0.0, 0.0, 1.0]), 0.85, 0.0)
    root = bones.add_root(plan, skeleton, level)[0]
    assert np.isclose(root.head[2], 0.0)  # the floor: the lowest ball's bottom
    sided = [dataclasses.replace(spec, name=spec.name + ".L") for spec in plan]
    root = bones.add_root(sided, skeleton, level)[0]
    assert np.isclose(level.signed(root.head), 0.0)  # on the plane, off the floor
    assert np.allclose(root.tail, skeleton.positions[skeleton.root])  # toward the root node


def test_the_root_bone_stands_straight_up_even_under_a_body_off_its_centre():
    """The rearing snake's head, the skeleton's root, is over one end of its body: the root
    bone still stands straight up from the floor under the middle (turning it about its axis
    turns the snake about the vertical), as high as the head, not leaning over to it."""
    skeleton = rearing_snake()
    plan = bones.plan_bones(skeleton, origin=None)  # up +Z, no mirror plane
    root, top = plan[0], np.asarray(skeleton.positions[skeleton.root])
    assert np.allclose(root.head, [1.1, 0.0, 0.0])  # the floor under the balls' box's middle
    assert np.allclose(root.tail, [1.1, 0.0, 1.5])  # straight up, as high as the head
    assert np.linalg.norm((top - root.head)[:2]) > 1.0  # the head is off it


def test_a_root_on_a_tilted_mirror_plane_rises_up_the_plane_and_stays_on_it():
    # The floor turned 20 degrees about y (as above): the root bone cannot stand straight up
    # and stay its own mirror image; it rises up the plane's steepest line, as high as the hips.
    skeleton = body()
    angle = np.radians(20.0)
    up = np.array([np.sin(angle), 0.0, np.cos(angle)])
    root = bones.plan_bones(skeleton, up=up)[0]
    assert abs(root.head[0]) < 1e-9 and abs(root.tail[0]) < 1e-9  # on the plane x = 0
    assert np.isclose(root.tail @ up, np.asarray(skeleton.positions)[skeleton.root] @ up)
    along = (root.tail - root.head) / np.linalg.norm(root.tail - root.head)
    assert np.isclose(along @ up, np.cos(angle))  # as steep as the plane allows


def test_an_asymmetric_body_gets_its_root_onto_the_mirror_plane():
    skeleton = body(lean=0.05, arm_drop=0.05)  # the plane stays x = 0 (the limbs' fit)
    root = bones.plan_bones(skeleton)[0]
    plane = bones.plan_plane(skeleton)
    assert plane is not None and abs(plane.signed(root.head)) < 1e-9
    assert np.isclose(root.head[2], -1.3)


def test_a_mixamo_plan_hangs_its_hips_from_the_root_bone():
    plan = bones.plan_bones(person(), names="mixamo")
    assert humanoid.is_mixamo(plan)
    assert plan[0].name == bones.ROOT_NAME and plan[1].name == "Hips"
    assert plan[1].parent == bones.ROOT_NAME
    assert [spec.name for spec in plan if spec.parent is None] == [bones.ROOT_NAME]


def test_a_real_characters_root_bone_is_at_its_feet(meshes_dir):
    V, F = dcg.load_mesh(str(meshes_dir / "rigged" / "Q_Knight.obj"))  # Z up, feet at z = 0
    V = np.asarray(V)
    skeleton = dcg.extract_skeleton(V, F)
    plan = bones.plan_bones(skeleton)
    root = plan[0]
    height = float(np.ptp(V[:, 2]))
    assert abs(root.head[2] - V[:, 2].min()) < 0.02 * height
    middle = (V.min(axis=0) + V.max(axis=0)) / 2
    assert np.linalg.norm(root.head[:2] - middle[:2]) < 0.02 * height
    assert root.tail[2] > root.head[2] + 0.3 * height  # up to the hips
    weights = dcg.skin_weights(V, F, plan)
    dense = weights.dense()
    assert weights.bone_count == len(plan) and not dense[:, 0].any()
    assert np.allclose(dense.sum(axis=1), 1.0)


def test_the_root_bone_options_of_the_batch_and_the_addon_cli():
    from dcg import batch_blender, batch_jobs

    assert batch_jobs.file_up("a/b.OBJ") == (0.0, 1.0, 0.0)
    assert batch_jobs.file_up("a/b.ply") == batch_jobs.file_up("b.glb") == (0.0, 0.0, 1.0)
    assert "--root-bone" in batch_blender.cli_flags({}, 0.5)
    assert "--no-root-bone" in batch_blender.cli_flags({}, 0.5, root_bone=False)


@pytest.mark.parametrize("root_bone", [True, False])
def test_the_npz_of_a_batch_has_the_root_bone_it_was_asked_for(repo, root_bone):
    import io

    from dcg import batch_worker

    V, F = dcg.load_mesh(str(repo / "data" / "spot.obj"))
    skeleton = dcg.extract_skeleton(V, F)
    data, status = batch_worker.weights_npz(V, F, skeleton, root_bone=root_bone,
                                            up=(0.0, 1.0, 0.0))  # spot.obj is Y up
    assert status == "ok"
    with np.load(io.BytesIO(data)) as npz:
        kinds = list(npz["bone_kinds"])
        assert (kinds[0] == "root") == root_bone and kinds.count("root") == int(root_bone)
        if root_bone:
            floor = float(np.asarray(V)[:, 1].min())
            assert abs(npz["bone_heads"][0][1] - floor) < 0.02 * float(np.ptp(V, axis=0).max())


def test_the_addon_defaults_are_the_planners():
    import sys
    from pathlib import Path

    sys.path.insert(0, str(Path(__file__).resolve().parents[2] / "addon"))
    try:
        from dcg_rig import options
    finally:
        sys.path.pop(0)
    assert options.ADDON_DEFAULTS["root_bone"] is bones.ROOT_BONE
    assert options.ADDON_DEFAULTS["bone_detail"] == bones.BONE_DETAIL


def test_a_mixamo_plans_root_bone_lies_on_the_plane_its_pairs_mirror_across(meshes_dir):
    V, F = dcg.load_mesh(str(meshes_dir / "knight.off"))  # its two planes 3 degrees apart
    skeleton = dcg.extract_skeleton(V, F)
    plan = bones.plan_bones(skeleton, names="mixamo")
    assert humanoid.is_mixamo(plan)
    plane = humanoid.plan_plane(skeleton)
    size = float(np.ptp(np.asarray(V), axis=0).max())
    assert abs(plane.signed(plan[0].head)) < 1e-9 * size


def test_a_mirror_plane_lies_level_past_the_upright_limit():
    from dcg.symmetry import Plane

    def plane(degrees_from_upright):
        angle = np.radians(degrees_from_upright)
        return Plane(np.array([np.cos(angle), 0.0, np.sin(angle)]), 0.0, 0.0)

    assert not bones.lies_level(plane(0.0)) and not bones.lies_level(plane(44.0))
    assert bones.lies_level(plane(46.0)) and bones.lies_level(plane(90.0))
    assert not bones.lies_level(None)
    assert not bones.lies_level(plane(90.0), up=(1.0, 0.0, 0.0))  # upright across x
