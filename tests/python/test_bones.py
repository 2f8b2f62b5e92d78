"""dcg.bones: the one bone planner (the add-on's armature, the batch's .weights.npz and
dcg.skin_weights of a skeleton), on hand-made skeletons whose plan is known."""

import types

import numpy as np
import pytest

from dcg import bones


def skeleton_of(positions, kinds, links, polylines=None, root=0, radii=None):
    positions = np.asarray(positions, dtype=float)
    if polylines is None:
        polylines = [positions[[a, b]] for a, b in links]
    return types.SimpleNamespace(
        positions=positions, kinds=np.array(kinds), links=np.array(links),
        polylines=[np.asarray(p, dtype=float) for p in polylines], root=root,
        radii=np.full(len(positions), 0.1) if radii is None else np.asarray(radii))


def y_shape():
    """A root joint with three arms, the first arm a 4-point polyline."""
    positions = [[0, 0, 0], [0, 0, 1], [1, 0, -1], [-1, 0, -1]]
    polylines = [[[0, 0, 0], [0.1, 0, 0.3], [-0.1, 0, 0.6], [0, 0, 1]],
                 [[0, 0, 0], [1, 0, -1]], [[0, 0, 0], [-1, 0, -1]]]
    return skeleton_of(positions, ["joint", "end", "end", "end"], [[0, 1], [0, 2], [0, 3]],
                       polylines)


def path_from_an_end():
    """end 0 - joint 1 - end 2 and joint 1 - end 3, root at end 0, links stored backwards
    (every polyline runs from links[l, 0], away from the root)."""
    positions = [[0, 0, 0], [0, 0, 1], [0, 0, 2], [1, 0, 1]]
    return skeleton_of(positions, ["end", "joint", "end", "end"], [[1, 0], [2, 1], [1, 3]],
                       root=0, radii=[0.1, 0.3, 0.1, 0.2])


def test_plan_bones_one_chain_per_link_parents_first():
    plan = bones.plan_bones(y_shape(), bone_detail=1.0)
    assert len(plan) == 3 + 1 + 1
    seen = set()
    for spec in plan:
        assert spec.parent is None or spec.parent in seen
        seen.add(spec.name)
    ends = sorted(s.name for s in plan if s.kind == "end")
    assert ends == ["end.001", "end.002", "end.003"]
    assert {s.node for s in plan if s.kind == "end"} == {1, 2, 3}
    assert all(np.linalg.norm(s.tail - s.head) > 0 for s in plan)


def test_the_first_arm_is_a_connected_chain_of_its_polyline():
    plan = bones.plan_bones(y_shape(), bone_detail=1.0)
    arm = [s for s in plan if s.link == 0]
    assert [s.name for s in arm] == ["connection.001", "connection.002", "end.001"]
    assert [s.parent for s in arm] == [None, "connection.001", "connection.002"]
    assert [s.use_connect for s in arm] == [False, True, True]
    assert np.allclose([s.head for s in arm], y_shape().polylines[0][:-1])
    assert np.allclose([s.tail for s in arm], y_shape().polylines[0][1:])
    assert [s.node for s in arm] == [-1, -1, 1]


def test_bone_detail_zero_gives_one_bone_per_link():
    plan = bones.plan_bones(y_shape(), bone_detail=0.0)
    assert len(plan) == 3
    assert all(s.parent is None for s in plan)  # all start at the root node
    assert np.allclose(plan[0].tail, [0, 0, 1])  # straight to the node, inner points dropped


def test_chains_run_away_from_the_root_whatever_the_links_order():
    skeleton = path_from_an_end()
    plan = bones.plan_bones(skeleton, bone_detail=0.0)
    assert [(s.name, s.parent, s.use_connect) for s in plan] == [
        ("joint.001", None, False), ("end.001", "joint.001", True),
        ("end.002", "joint.001", True)]
    assert np.allclose(plan[0].head, skeleton.positions[0])
    assert np.allclose(plan[1].head, skeleton.positions[1])
    assert np.allclose(plan[1].tail, skeleton.positions[2])  # link [2, 1] taken backwards
    assert [s.link for s in plan] == [0, 1, 2]
    assert plan[0].head_radius == pytest.approx(0.1) and plan[0].tail_radius == 0.3


def test_a_cycle_keeps_every_link_and_the_hierarchy_stays_a_tree():
    ring = skeleton_of([[0, 0, 0], [1, 0, 0], [0, 1, 0]], ["joint"] * 3,
                       [[0, 1], [1, 2], [2, 0]])
    plan = bones.plan_bones(ring, bone_detail=0.0)
    assert len(plan) == 3
    names = {s.name: s for s in plan}
    for spec in plan:  # following parents always ends at a root: no cycle
        chain, current = set(), spec
        while current.parent is not None:
            assert current.name not in chain
            chain.add(current.name)
            current = names[current.parent]
    assert sum(1 for s in plan if s.parent is not None and not s.use_connect) >= 1


def test_a_part_the_root_cannot_reach_gets_its_bones_too():
    skeleton = skeleton_of([[0, 0, 0], [0, 0, 1], [5, 0, 0], [5, 0, 1]],
                           ["end", "end", "end", "end"], [[0, 1], [2, 3]], root=0,
                           radii=[0.1, 0.1, 0.1, 0.5])
    plan = bones.plan_bones(skeleton, bone_detail=0.0)
    assert [s.link for s in plan] == [0, 1] and [s.parent for s in plan] == [None, None]
    assert np.allclose(plan[1].head, [5, 0, 1])  # that part starts at its widest node


def test_zero_length_segments_are_merged_away():
    polyline = [[0, 0, 0], [0, 0, 0.5], [0, 0, 0.5], [0, 0, 1]]
    skeleton = skeleton_of([[0, 0, 0], [0, 0, 1]], ["end", "end"], [[0, 1]], [polyline])
    plan = bones.plan_bones(skeleton, bone_detail=1.0)
    assert len(plan) == 2 and np.allclose(plan[0].tail, plan[1].head)


def test_bone_arrays_index_the_parents_in_plan_order():
    plan = bones.plan_bones(y_shape(), bone_detail=1.0)
    arrays = bones.bone_arrays(plan)
    assert list(arrays["names"]) == [s.name for s in plan]
    assert arrays["heads"].shape == arrays["tails"].shape == (len(plan), 3)
    for b, spec in enumerate(plan):
        parent = arrays["parents"][b]
        assert parent < b
        assert (parent < 0) == (spec.parent is None)
        if parent >= 0:
            assert arrays["names"][parent] == spec.parent
        assert arrays["kinds"][b] == spec.kind and arrays["links"][b] == spec.link
    empty = bones.bone_arrays([])
    assert empty["heads"].shape == (0, 3) and empty["parents"].dtype == np.int64
