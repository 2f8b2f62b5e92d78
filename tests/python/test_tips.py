"""dcg.tips: a limb's rounded tip runs on along its line, in the plan of a flat-capped
cylinder and on hand-made polylines."""

import numpy as np

import dcg
from conftest import shared_skeleton
from dcg import bones, tips


def stem_and_corner():
    """A limb of radius 1 along +y to y = 3, then (inside y = 3's ball) to a corner ball of
    radius 0.46 at (0, 3.54, -0.53): SkinnedCylinder's tip, as the engine routes it."""
    points = np.array([[0, 2, 0], [0, 2.5, 0], [0, 3, 0], [0, 3.25, -0.2], [0, 3.54, -0.53]])
    return points, np.array([1.0, 1.0, 0.96, 0.78, 0.46])


def test_a_tip_inside_the_last_ball_of_its_stem_runs_on_along_the_stem():
    points, radii = stem_and_corner()
    straight = tips.straightened(points, radii)
    assert np.allclose(straight[:3], points[:3])  # the stem, the tip's base included, stays
    assert np.allclose(straight[3:, [0, 2]], 0.0)  # the tip on the stem's line
    assert np.allclose(straight[3:, 1], [3.25, 3.54])  # as far along it as it lay
    assert np.all(np.linalg.norm(straight[3:] - points[2], axis=1) <= radii[2])


def test_a_prong_that_leaves_the_last_ball_keeps_its_turn():
    """A foot: the shin down to the ankle (radius 0.2), then forward 1.0 to the toe: the toe
    lies outside every ball of the shin, so nothing moves."""
    points = np.array([[0, 0, 2], [0, 0, 1], [0, 0, 0.3], [0, 0.5, 0.2], [0, 1.0, 0.1]])
    radii = np.array([0.3, 0.25, 0.2, 0.12, 0.06])
    assert np.array_equal(tips.straightened(points, radii), points)


def test_a_stub_that_is_all_tip_and_a_straight_limb_stay_as_they_are():
    stub = np.array([[0, 0, 0], [0, 0.3, 0.1], [0, 0.5, 0.3]])
    assert np.array_equal(tips.straightened(stub, [1.0, 0.8, 0.5]), stub)
    line = np.array([[0, 0, 0], [0, 1, 0], [0, 2, 0], [0, 2.5, 0]])
    assert np.allclose(tips.straightened(line, [1.0, 1.0, 0.9, 0.5]), line)


def test_a_tip_that_turns_back_behind_its_base_stays():
    points = np.array([[0, 0, 0], [0, 1, 0], [0, 0.8, 0.5]])
    radii = np.array([0.5, 1.0, 0.3])
    assert np.array_equal(tips.straightened(points, radii), points)


def test_skinned_cylinders_bones_run_along_its_axis(meshes_dir):
    """SkinnedCylinder (radius 1, y from 0 to 4, flat caps): the engine ends both links in
    corner balls of the caps, 0.53 off the axis. Before, the two end bones leant towards them
    (their tails 0.28 off the axis); now every bone lies within 0.05 of it, whichever the up."""
    V, F = dcg.load_mesh(meshes_dir / "rigged" / "SkinnedCylinder.obj")
    skeleton = shared_skeleton(V, F, "SkinnedCylinder")
    for up in ([0.0, 1.0, 0.0], [0.0, 0.0, 1.0]):
        plan = bones.bone_arrays(bones.plan_bones(skeleton, up=np.array(up), root_bone=False))
        assert list(plan["kinds"]).count("end") == 2
        for points in (plan["heads"], plan["tails"]):
            assert np.abs(points[:, [0, 2]]).max() < 0.05
        ends = plan["tails"][plan["kinds"] == "end"][:, 1]
        assert sorted(np.round(ends, 1)) == [1.0, 3.0]  # one radius short of each corner ball
