"""dcg.metrics: weights and skeleton measures on hand-made cases whose answer is known."""

import numpy as np
import pytest

from dcg import metrics

RIG_TEXT = """joints hips 0 0 1
joints spine 0 0 2
joints head 0 0 3
joints leg 0.5 0 1
root hips
hier hips spine
hier spine head
hier hips leg
skin 0 hips 0.75 spine 0.25
skin 2 head 1.0
"""
CHAIN = np.array([[0.0, 0, 0], [1, 0, 0], [2, 0, 0]])
CHAIN_PARENTS = np.array([-1, 0, 1])


def test_parse_rig_info_reads_joints_hierarchy_root_and_weights():
    rig = metrics.parse_rig_info(RIG_TEXT)
    assert rig.names == ["hips", "spine", "head", "leg"]
    np.testing.assert_array_equal(rig.joints[3], [0.5, 0, 1])
    np.testing.assert_array_equal(rig.parents, [-1, 0, 1, 0])
    assert rig.root == 0
    np.testing.assert_allclose(rig.weights, [[0.75, 0.25, 0, 0], [0, 0, 0, 0], [0, 0, 1, 0]])


def test_parse_rig_info_takes_the_vertex_count_and_rejects_unknown_joints():
    assert metrics.parse_rig_info(RIG_TEXT, vertex_count=5).weights.shape == (5, 4)
    with pytest.raises(ValueError, match="unknown joint"):
        metrics.parse_rig_info(RIG_TEXT + "skin 1 tail 1.0\n")


def test_read_rig_info_and_rigged_characters(tmp_path):
    (tmp_path / "a.obj").write_text("v 0 0 0\n")
    (tmp_path / "a.rig.txt").write_text(RIG_TEXT)
    (tmp_path / "b.obj").write_text("v 0 0 0\n")  # no rig: left out
    found = metrics.rigged_characters(tmp_path)
    assert [(name, obj.name, rig.name) for name, obj, rig in found] == [
        ("a", "a.obj", "a.rig.txt")]
    assert metrics.read_rig_info(found[0][2]).names[0] == "hips"


def test_joint_bones_children_mean_and_leaves_half_their_parent_bone():
    rig = metrics.parse_rig_info(RIG_TEXT)
    heads, tails = metrics.joint_bones(rig.joints, rig.parents)
    np.testing.assert_array_equal(heads, rig.joints)
    np.testing.assert_allclose(tails[0], [0.25, 0, 1.5])   # mean of spine and leg
    np.testing.assert_allclose(tails[1], [0, 0, 3])        # its one child
    np.testing.assert_allclose(tails[2], [0, 0, 3.5])      # leaf: half of spine -> head
    np.testing.assert_allclose(tails[3], [0.75, 0, 1])     # leaf: half of hips -> leg


def test_joint_bones_gives_a_coincident_joint_a_length():
    joints = np.array([[0.0, 0, 0], [0, 0, 0], [2, 0, 0]])  # two roots in one place
    heads, tails = metrics.joint_bones(joints, [-1, 0, 1])
    lengths = np.linalg.norm(tails - heads, axis=1)
    assert np.all(lengths > 0)
    np.testing.assert_allclose(tails[0], [0, 0, 0.5 * np.mean(lengths[1:])])


def test_parent_segments_one_per_child():
    heads, tails = metrics.parent_segments(CHAIN, CHAIN_PARENTS)
    np.testing.assert_array_equal(heads, CHAIN[:2])
    np.testing.assert_array_equal(tails, CHAIN[1:])


def one_hot(columns, count):
    return np.eye(count)[columns]


def test_l1_precision_recall_of_identical_and_disjoint_weights():
    W = one_hot([0, 1, 2, 1], 3)
    assert metrics.weight_l1(W, W) == 0
    assert metrics.influence_precision_recall(W, W) == (1.0, 1.0)
    other = one_hot([1, 2, 0, 0], 3)
    assert metrics.weight_l1(W, other) == pytest.approx(2.0)
    assert metrics.influence_precision_recall(W, other) == (0.0, 0.0)


def test_precision_and_recall_count_influences_above_the_threshold():
    W = np.array([[0.5, 0.5, 0.0], [1.0, 0.0, 0.0]])
    ref = np.array([[1.0, 0.0, 0.0], [0.5, 0.0, 0.5 - 1e-5]])
    precision, recall = metrics.influence_precision_recall(W, ref)
    assert precision == pytest.approx((0.5 + 1.0) / 2)
    assert recall == pytest.approx((1.0 + 0.5) / 2)
    assert metrics.weight_l1(W, ref) == pytest.approx((1.0 + 1.0 - 1e-5) / 2)


def test_unweighted_and_normalized():
    W = np.array([[0.0, 0.0], [2.0, 2.0]])
    assert metrics.unweighted_vertices(W) == 1
    np.testing.assert_array_equal(metrics.normalized(W), [[0, 0], [0.5, 0.5]])


def test_random_pose_keeps_bone_lengths_and_the_root_in_place():
    R, t = metrics.random_pose(CHAIN, CHAIN_PARENTS, 35.0, rng=3)
    np.testing.assert_allclose(R @ R.transpose(0, 2, 1), np.broadcast_to(np.eye(3), R.shape),
                               atol=1e-12)
    moved = np.einsum("jab,jb->ja", R, CHAIN) + t
    np.testing.assert_allclose(moved[0], CHAIN[0], atol=1e-12)
    # joint j moves with its parent's transform: the rest bone lengths stay
    parent_moved = np.einsum("jab,jb->ja", R[CHAIN_PARENTS[1:]], CHAIN[1:]) + t[CHAIN_PARENTS[1:]]
    np.testing.assert_allclose(np.linalg.norm(parent_moved - moved[:-1], axis=1), 1.0)
    angles = np.degrees(np.arccos(np.clip((np.trace(R[0]) - 1) / 2, -1, 1)))
    assert 0 <= angles <= 35.0 + 1e-9


def test_linear_blend_skinning_of_a_known_pose():
    quarter = np.array([[0.0, -1, 0], [1, 0, 0], [0, 0, 1]])   # 90 degrees about +Z
    R = np.stack([np.eye(3), quarter])
    t = np.array([[0.0, 0, 0], [0, 0, 0]])
    V = np.array([[1.0, 0, 0], [1, 0, 0], [1, 0, 0]])
    W = np.array([[1.0, 0], [0, 1], [0, 0]])                   # the last: no weight
    np.testing.assert_allclose(metrics.linear_blend_skinning(V, W, R, t),
                               [[1, 0, 0], [0, 1, 0], [1, 0, 0]], atol=1e-12)


def test_deformation_error_zero_for_identical_weights_and_seeded():
    V = np.array([[0.5, 0.2, 0], [1.5, -0.2, 0], [2.2, 0.1, 0]])
    W, other = one_hot([0, 1, 2], 3), one_hot([0, 0, 1], 3)
    assert metrics.deformation_error(V, W, W, CHAIN, CHAIN_PARENTS) == 0
    error = metrics.deformation_error(V, other, W, CHAIN, CHAIN_PARENTS, seed=7)
    assert error > 0
    assert metrics.deformation_error(V, other, W, CHAIN, CHAIN_PARENTS, seed=7) == error
    assert metrics.deformation_error(V, other, W, CHAIN, CHAIN_PARENTS, max_degrees=0) == 0


def test_weight_metrics_of_identical_weights():
    V = np.array([[0.5, 0.2, 0], [1.5, -0.2, 0], [2.2, 0.1, 0]])
    W = one_hot([0, 1, 2], 3)
    assert metrics.weight_metrics(V, W, W, CHAIN, CHAIN_PARENTS) == {
        "l1": 0.0, "precision": 1.0, "recall": 1.0, "deformation_error": 0.0, "unweighted": 0}


def test_segment_distances_inside_beyond_and_degenerate():
    d = metrics.segment_distances([[0.5, 1, 0], [3, 0, 0], [0, 0, 2]],
                                  [[0.0, 0, 0], [0, 0, 0]], [[1.0, 0, 0], [0, 0, 0]])
    np.testing.assert_allclose(d, [[1, np.hypot(0.5, 1)], [2, 3], [2, 2]])


def test_chamfer_distances_of_a_skeleton_against_itself_and_a_shifted_copy():
    bones = metrics.parent_segments(CHAIN, CHAIN_PARENTS)
    assert metrics.chamfer_j2j(CHAIN, CHAIN) == 0
    assert metrics.chamfer_j2b(CHAIN, bones, CHAIN, bones) == 0
    assert metrics.chamfer_b2b(bones, bones, 0.1) == 0
    shift = np.array([0, 0, 0.3])
    moved = (bones[0] + shift, bones[1] + shift)
    assert metrics.chamfer_j2j(CHAIN, CHAIN + shift) == pytest.approx(0.3)
    assert metrics.chamfer_j2b(CHAIN, bones, CHAIN + shift, moved) == pytest.approx(0.3)
    assert metrics.chamfer_b2b(bones, moved, 0.1) == pytest.approx(0.3)


def test_chamfer_is_symmetric_half_sum_of_directions():
    a = np.array([[0.0, 0, 0]])
    b = np.array([[1.0, 0, 0], [3.0, 0, 0]])
    # a -> b: 1; b -> a: (1 + 3) / 2 = 2; half the sum: 1.5
    assert metrics.chamfer_j2j(a, b) == pytest.approx(1.5)
    assert metrics.chamfer_j2j(b, a) == pytest.approx(1.5)


def test_bone_samples_at_most_step_apart_ends_included():
    samples = metrics.bone_samples([[0.0, 0, 0]], [[1.0, 0, 0]], 0.3)
    np.testing.assert_allclose(samples[:, 0], [0, 0.25, 0.5, 0.75, 1])


def test_skeleton_metrics_in_percent_of_the_longest_side():
    V = np.array([[0.0, -0.5, -0.5], [2, 0.5, 0.5]])            # longest side 2
    heads, tails = metrics.parent_segments(CHAIN, CHAIN_PARENTS)
    shift = np.array([0, 0, 0.1])
    same = metrics.skeleton_metrics(V, heads, tails, CHAIN, CHAIN_PARENTS)
    assert same == {"cd_j2j": 0.0, "cd_j2b": 0.0, "cd_b2b": 0.0}
    moved = metrics.skeleton_metrics(V, heads + shift, tails + shift, CHAIN, CHAIN_PARENTS)
    assert moved == pytest.approx({"cd_j2j": 5.0, "cd_j2b": 5.0, "cd_b2b": 5.0})


def test_j2j_parts_split_the_chamfer_into_its_directions_and_far_joints():
    V = np.array([[0.0, -0.5, -0.5], [2, 0.5, 0.5]])            # longest side 2
    heads, tails = metrics.parent_segments(CHAIN, CHAIN_PARENTS)
    # Ours: the chain and a wing 0.4 off its middle (20% of the side): its tip is far.
    ours_h = np.vstack([heads, [[1.0, 0, 0]]])
    ours_t = np.vstack([tails, [[1.0, 0.4, 0]]])
    # Theirs: the chain and a root 0.2 below its start (10%): far from our bones.
    theirs = np.vstack([CHAIN, [[0.0, 0, -0.2]]])
    parents = np.array([3, 0, 1, -1])
    parts = metrics.j2j_parts(V, ours_h, ours_t, theirs, parents)
    assert parts == pytest.approx({"j2j_ours": 20.0 / 4, "j2j_ours_far": 20.0 / 4,
                                   "j2j_theirs": 10.0 / 4, "j2j_theirs_far": 10.0 / 4})
    whole = metrics.skeleton_metrics(V, ours_h, ours_t, theirs, parents)["cd_j2j"]
    assert whole == pytest.approx(0.5 * (parts["j2j_ours"] + parts["j2j_theirs"]))
    # Nearer than `far`: counted in the mean, not as far.
    near = metrics.j2j_parts(V, ours_h, ours_t, theirs, parents, far=25.0)
    assert near["j2j_ours_far"] == 0.0 and near["j2j_theirs_far"] == 0.0
    one = metrics.j2j_parts(V, heads, tails, CHAIN[:1], [-1])   # one joint, no bone
    assert one["j2j_theirs"] == 0.0 and one["j2j_ours"] == pytest.approx(50.0)  # 0, 1, 2 of 2


def test_unique_points_drops_shared_heads_and_tails():
    heads, tails = metrics.parent_segments(CHAIN, CHAIN_PARENTS)
    np.testing.assert_array_equal(metrics.unique_points(np.concatenate([heads, tails])), CHAIN)


def test_kept_joints_reparents_to_the_nearest_kept_ancestor():
    # 0 -> 1 -> 2 -> 3 and 1 -> 4; drop 0 (a floor root) and 2 (a joint off the body).
    joints = np.arange(15, dtype=float).reshape(5, 3)
    parents = np.array([-1, 0, 1, 2, 1])
    kept, kept_parents = metrics.kept_joints(joints, parents, [False, True, False, True, True])
    np.testing.assert_array_equal(kept, joints[[1, 3, 4]])
    np.testing.assert_array_equal(kept_parents, [-1, 0, 0])  # 3's parent is 1, now index 0
    kept, kept_parents = metrics.kept_joints(joints, parents, [True] * 5)
    np.testing.assert_array_equal(kept_parents, parents)
    with pytest.raises(ValueError):
        metrics.kept_joints(joints, parents, [True, False])


def test_the_shared_rigs_read_with_weights_summing_to_one(meshes_dir):
    characters = metrics.rigged_characters(meshes_dir / "rigged")
    if not characters:
        pytest.skip("no rigged characters")
    for name, _, rig_path in characters:
        rig = metrics.read_rig_info(rig_path)
        assert np.sum(rig.parents < 0) >= 1 and rig.parents[rig.root] == -1, name
        sums = rig.weights.sum(axis=1)
        assert np.all((np.abs(sums - 1) < 1e-3) | (sums == 0)), name


def test_mirror_error_of_paired_bones_in_percent_of_the_longest_side():
    V = np.array([[-5.0, 0, 0], [5, 0, 0], [0, 2, 0]])  # longest side 10
    names = ["arm.L", "arm.R", "spine", "leg.L", "leg.R", "tail.L"]
    heads = np.array([[1.0, 0, 0], [-1, 0, 0], [0, 0, 0], [1, 0, -1], [-1, 0.1, -1], [2, 0, 0]])
    tails = np.array([[2.0, 0, 0], [-2, 0, 0], [0, 1, 0], [1, 0, -2], [-1, 0.3, -2], [3, 0, 0]])
    assert metrics.mirror_pairs(names) == [(0, 1), (3, 4)]
    result = metrics.mirror_error(V, names, heads, tails, [1, 0, 0], 0.0)
    # |M(head) - head'|: 0, 0.1; tails: 0, 0.3 -> mean 0.1, max 0.3, over 10, in %.
    assert result["mirror_mean"] == pytest.approx(1.0)
    assert result["mirror_max"] == pytest.approx(3.0)
    assert result["pairs"] == 2 and result["unpaired"] == 1  # tail.L has no tail.R
    # Across another plane (x = 1) the same bones are far from mirrored.
    assert metrics.mirror_error(V, names, heads, tails, [1, 0, 0], 1.0)["mirror_mean"] > 10
    none = metrics.mirror_error(V, ["spine"], heads[2:3], tails[2:3], [1, 0, 0], 0.0)
    assert none["mirror_mean"] is None and none["pairs"] == 0
