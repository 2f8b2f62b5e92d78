"""dcg.bones: the one bone planner (the add-on's armature, the batch's .weights.npz and
dcg.skin_weights of a skeleton), on hand-made skeletons whose plan is known."""

import dataclasses
import types

import numpy as np
import pytest

import dcg
from conftest import shared_skeleton
from dcg import bones, junctions, metrics, symmetry


def limb_plan(skeleton, *args, **kwargs):
    """plan_bones without its root bone: the limbs' chains that these tests (and test_naming's,
    test_humanoid's) look at; the root bone has tests of its own (test_root_bone.py)."""
    return bones.plan_bones(skeleton, *args, root_bone=False, **kwargs)


@pytest.fixture
def no_inset(monkeypatch):
    """End bones' tails exactly at their end nodes (END_INSET 0), for tests of the chains."""
    monkeypatch.setattr(bones, "END_INSET", 0.0)


def skeleton_of(positions, kinds, links, polylines=None, root=0, radii=None):
    """A skeleton of straight links, but for the polylines given (None: that link straight)."""
    positions = np.asarray(positions, dtype=float)
    polylines = [positions[[a, b]] if line is None else line
                 for line, (a, b) in zip(polylines or [None] * len(links), links)]
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
    plan = limb_plan(y_shape(), bone_detail=1.0)
    assert len(plan) == 3 + 1 + 1
    seen = set()
    for spec in plan:
        assert spec.parent is None or spec.parent in seen
        seen.add(spec.name)
    ends = sorted(s.name for s in plan if s.kind == "end")
    # The two lower arms mirror each other and stand on the ground: legs; the upper one the head.
    assert ends == ["head.003", "leg.001.L", "leg.001.R"]
    assert {s.node for s in plan if s.kind == "end"} == {1, 2, 3}
    assert all(np.linalg.norm(s.tail - s.head) > 0 for s in plan)


def test_the_first_arm_is_a_connected_chain_of_its_polyline(no_inset):
    plan = limb_plan(y_shape(), bone_detail=1.0)
    arm = [s for s in plan if s.link == 0]
    assert [s.name for s in arm] == ["head.001", "head.002", "head.003"]
    assert [s.parent for s in arm] == [None, "head.001", "head.002"]
    assert [s.use_connect for s in arm] == [False, True, True]
    assert np.allclose([s.head for s in arm], y_shape().polylines[0][:-1])
    assert np.allclose([s.tail for s in arm], y_shape().polylines[0][1:])
    assert [s.node for s in arm] == [-1, -1, 1]


def test_bone_detail_zero_gives_one_bone_per_link(no_inset):
    plan = limb_plan(y_shape(), bone_detail=0.0)
    assert len(plan) == 3
    assert all(s.parent is None for s in plan)  # all start at the root node
    assert np.allclose(plan[0].tail, [0, 0, 1])  # straight to the node, inner points dropped


def test_chains_run_away_from_the_root_whatever_the_links_order(no_inset):
    skeleton = path_from_an_end()
    plan = limb_plan(skeleton, bone_detail=0.0)
    assert [(s.name, s.parent, s.use_connect) for s in plan] == [
        ("spine.001", None, False), ("limb1.001", "spine.001", True),
        ("limb2.001", "spine.001", True)]  # no mirror plane: limbs, numbered in plan order
    assert np.allclose(plan[0].head, skeleton.positions[0])
    assert np.allclose(plan[1].head, skeleton.positions[1])
    assert np.allclose(plan[1].tail, skeleton.positions[2])  # link [2, 1] taken backwards
    assert [s.link for s in plan] == [0, 1, 2]
    assert plan[0].head_radius == pytest.approx(0.1) and plan[0].tail_radius == 0.3


def test_a_cycle_keeps_every_link_and_the_hierarchy_stays_a_tree():
    ring = skeleton_of([[0, 0, 0], [1, 0, 0], [0, 1, 0]], ["joint"] * 3,
                       [[0, 1], [1, 2], [2, 0]])
    plan = limb_plan(ring, bone_detail=0.0)
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
    plan = limb_plan(skeleton, bone_detail=0.0)
    assert [s.link for s in plan] == [0, 1] and [s.parent for s in plan] == [None, None]
    assert np.allclose(plan[1].head, [5, 0, 1])  # that part starts at its widest node


def test_zero_length_segments_are_merged_away():
    polyline = [[0, 0, 0], [0, 0, 0.5], [0, 0, 0.5], [0, 0, 1]]
    skeleton = skeleton_of([[0, 0, 0], [0, 0, 1]], ["end", "end"], [[0, 1]], [polyline])
    plan = limb_plan(skeleton, bone_detail=1.0)
    assert len(plan) == 2 and np.allclose(plan[0].tail, plan[1].head)


def test_bone_arrays_index_the_parents_in_plan_order():
    plan = limb_plan(y_shape(), bone_detail=1.0)
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


# --- joints at articulations --------------------------------------------------------------------

def bent_tube(bend_at=3, count=10):
    """One link, an L of `count` evenly spaced points bent at point `bend_at`, even radii."""
    points = [[0, 0, float(i)] for i in range(bend_at + 1)]
    points += [[float(i), 0, float(bend_at)] for i in range(1, count - bend_at)]
    return skeleton_of([points[0], points[-1]], ["joint", "end"], [[0, 1]], [points],
                       radii=[0.2, 0.2])


def straight_chain(radii):
    """A straight limb of len(radii) - 1 links (5 points each) through connection nodes."""
    count = len(radii)
    positions = [[0, 0, float(i)] for i in range(count)]
    kinds = ["joint"] + ["connection"] * (count - 2) + ["end"]
    links = [[i, i + 1] for i in range(count - 1)]
    polylines = [[[0, 0, i + t] for t in np.linspace(0, 1, 5)] for i in range(count - 1)]
    return skeleton_of(positions, kinds, links, polylines, radii=radii)


def test_a_bent_tube_gets_its_joint_at_the_bend():
    for bend_at in (2, 3, 6):
        skeleton = bent_tube(bend_at)
        points = skeleton.polylines[0]
        assert bones.articulations(points, np.full(len(points), 0.2), 2) == [0, bend_at, 9]
        plan = limb_plan(skeleton, bone_detail=0.4)  # round(0.4 x 5 x 1) = 2 bones
        assert len(plan) == 2
        assert np.allclose(plan[0].tail, points[bend_at]) and plan[0].kind == "connection"
        assert plan[1].kind == "end" and plan[1].node == 1


def test_two_bends_are_both_found_exactly():
    points = np.array([[0, 0, 0], [0, 0, 1], [1, 0, 1], [2, 0, 1], [3, 0, 1], [4, 0, 1],
                       [4, 0, 2], [4, 0, 3]], float)
    assert bones.articulations(points, np.full(len(points), 0.1), 3) == [0, 1, 5, 7]


def test_a_long_straight_span_is_split_though_the_bends_lie_elsewhere():
    # 20 straight segments, then a zigzag of 10: by the bends alone the joints fall at points 0,
    # 1, 19 and 27 to 30, and the bone from 1 to 19 is 3.3 mean bones (arc length / 6) long.
    straight = [[0.5 * i, 0, 0] for i in range(21)]
    zigzag = [[10 + 0.5 * i, 0, 0.4 * (i % 2)] for i in range(1, 11)]
    points = np.array(straight + zigzag, float)
    arc = np.concatenate([[0], np.cumsum(np.linalg.norm(np.diff(points, axis=0), axis=1))])
    joints = bones.articulations(points, np.full(len(points), 0.2), 6)
    longest = np.diff(arc[joints]).max()
    assert longest <= bones.LONGEST_BONE * arc[-1] / 6
    assert sum(1 for j in joints if j > 20) >= 3  # the zigzag still holds most joints


def test_a_polyline_that_goes_out_and_back_loses_the_fold_but_keeps_bends_and_nodes():
    # Along x: 0, 1, 2, out to 3.5, back to 2.2 and 2.6 (Mannequiny's elbow route, which
    # goes around a wall inside the shape), on to 4, then a right angle up to z = 2.
    points = np.array([[0, 0, 0], [1, 0, 0], [2, 0, 0], [3.5, 0, 0.1], [2.2, 0, 0],
                       [2.6, 0, 0], [4, 0, 0], [4, 0, 1], [4, 0, 2]], float)
    inner = np.full(len(points), -1)
    inner[[0, -1]] = [0, 1]
    assert bones.unfolded(points, inner).tolist() == [0, 1, 2, 4, 5, 6, 7, 8]
    at_node = inner.copy()
    at_node[3] = 7  # a node where it turns back stays (links meet there), the way back goes
    assert bones.unfolded(points, at_node).tolist() == [0, 1, 2, 3, 6, 7, 8]
    # And the limb's polyline is the unfolded one (the node at its far end kept).
    skeleton = skeleton_of([points[0], points[-1]], ["joint", "end"], [[0, 1]], [points],
                           radii=[0.2, 0.2])
    kept = bones.limb_polyline(skeleton, bones.limbs(skeleton)[0])
    assert np.allclose(kept[0], points[[0, 1, 2, 4, 5, 6, 7, 8]])
    assert kept[1].tolist() == [0, -1, -1, -1, -1, -1, -1, 1]
    assert len(kept[2]) == 7 and len(kept[3]) == 8


def test_a_straight_limb_gets_its_joint_where_it_narrows(no_inset):
    for thin in (1, 2, 3):
        radii = [0.3] * 5
        radii[thin] = 0.1
        skeleton = straight_chain(radii)
        plan = limb_plan(skeleton, bone_detail=0.1)  # round(0.1 x 5 x 4 links) = 2
        assert len(plan) == 2
        assert plan[0].node == thin and plan[0].kind == "connection"
        assert np.allclose(plan[0].tail, skeleton.positions[thin])
        assert plan[0].tail_radius == pytest.approx(0.1)
    # Without a narrowing a straight limb has nothing to prefer but fit: any split is exact.
    plan = limb_plan(straight_chain([0.3] * 5), bone_detail=0.1)
    assert len(plan) == 2 and np.allclose(plan[1].tail, [0, 0, 4])


def test_a_link_narrowing_between_its_nodes_draws_the_joint_there(no_inset):
    """One straight link of 7 points between two nodes as wide as each other: the engine's
    polyline_radii (each point's distance to the surface) put the joint where the link narrows
    between them, a neck inside one link; a skeleton without them (an older document)
    interpolates the nodes' radii and sees no narrowing."""
    polyline = [[0, 0, z] for z in range(7)]
    for thin in (2, 4):
        radii = np.full(7, 0.3)
        radii[thin] = 0.1
        skeleton = skeleton_of([[0, 0, 0], [0, 0, 6]], ["end", "end"], [[0, 1]], [polyline],
                               radii=[0.3, 0.3])
        skeleton.polyline_radii = [radii]
        plan = limb_plan(skeleton, bone_detail=0.4)  # round(0.4 x 5 x 1 link) = 2
        assert len(plan) == 2 and np.allclose(plan[0].tail, [0, 0, thin])
        assert plan[0].tail_radius == pytest.approx(0.1)
        _, _, _, measured = bones.limb_polyline(skeleton, bones.limbs(skeleton)[0])
        np.testing.assert_allclose(measured, radii)
        skeleton.polyline_radii = [radii[:-1]]  # not one per point: not used
        assert np.allclose(bones.limb_polyline(skeleton, bones.limbs(skeleton)[0])[3], 0.3)


def test_an_unpaired_limb_that_leaves_the_mirror_plane_is_no_part_of_the_middle():
    """Only an unpaired limb that stays on the mirror plane (its end within MIRROR_REACH of its
    radius there) has its joints drawn onto it: one that leaves it (SkinnedCylinder's two
    halves, ending on opposite rims of its caps while its nodes' plane runs across its axis;
    a tail swung to one side) keeps them where they are."""
    plane = bones.symmetry.Plane(np.array([1.0, 0.0, 0.0]), 0.0, 0.0)
    reach = bones.symmetry.MIRROR_REACH

    def limb(end_x):
        return types.SimpleNamespace(original=np.array([[0, 0, 0], [0.05, 0, 1], [end_x, 0, 2]]),
                                     own_radii=np.array([0.3, 0.3, 0.2]))
    # the end's depth is its bone's head's radius (0.3: bones._depths)
    assert bones._in_the_middle(plane, limb(0.0))
    assert bones._in_the_middle(plane, limb(-0.99 * reach * 0.3))
    assert not bones._in_the_middle(plane, limb(1.01 * reach * 0.3))
    assert not bones._in_the_middle(plane, limb(2.0))


def test_a_limb_along_the_mirror_plane_that_ends_in_a_thin_tip_off_it_is_of_the_middle():
    """A limb that runs along the plane and ends in a thin tip a little off it (Q_Snake's head
    and tongue) is of the middle: its end within MIRROR_REACH of its deepest joint's depth of
    the plane. A stub that sticks out across the plane as far is not, nor is a tip farther off."""
    plane = bones.symmetry.Plane(np.array([1.0, 0.0, 0.0]), 0.0, 0.0)
    reach = bones.symmetry.MIRROR_REACH

    def limb(points, radii):
        return types.SimpleNamespace(original=np.array(points, dtype=float),
                                     own_radii=np.array(radii, dtype=float))
    radii = [0.3, 0.3, 0.3, 0.01, 0.01]  # the tip's depth: 0.01, its bone's head's

    def head(tip_x):
        return limb([[0, 0, 0], [0.1, 0, 1], [0, 0, 2], [0.05, 0, 2.5], [tip_x, 0, 2.6]], radii)
    assert bones._in_the_middle(plane, head(0.99 * reach * 0.3))
    assert not bones._in_the_middle(plane, head(1.01 * reach * 0.3))
    stub = limb([[0, 0, 0], [0.1, 0, 0.02], [0.2, 0, 0.04]], [0.3, 0.01, 0.01])
    assert bones._in_the_middle(plane, limb(stub.original[:, [2, 1, 0]], stub.own_radii))
    assert not bones._in_the_middle(plane, stub)


def test_a_limb_runs_through_connection_nodes_and_stops_at_branches(no_inset):
    skeleton = straight_chain([0.3, 0.3, 0.2, 0.3, 0.1])
    plan = limb_plan(skeleton, bone_detail=0.0)
    assert len(plan) == 1  # one limb of four links, one bone
    assert np.allclose(plan[0].head, [0, 0, 0]) and np.allclose(plan[0].tail, [0, 0, 4])
    assert (plan[0].kind, plan[0].node, plan[0].link) == ("end", 4, 3)
    # y_shape's root joint branches three ways: three limbs, three bones at detail 0.
    assert len(limb_plan(y_shape(), bone_detail=0.0)) == 3
    assert [len(limb) for limb in bones.limbs(skeleton)] == [4]


def test_the_bone_count_follows_bone_detail():
    skeleton = straight_chain([0.3, 0.25, 0.2, 0.3, 0.25, 0.2, 0.1])  # 6 links, 24 segments
    counts = [len(limb_plan(skeleton, bone_detail=d)) for d in np.linspace(0, 1, 11)]
    assert counts == sorted(counts)  # never fewer bones for more detail
    assert counts[0] == 1 and counts[-1] == 24 and counts[5] == 15  # 0.5: 2.5 per link
    assert bones.bone_count(6, 24, 0.5) == 15 and bones.bone_count(6, 24, 2.0) == 24
    assert bones.bone_count(6, 24, -1.0) == 1
    # Below 0.5 a long limb (many links) is capped: it thins first as the detail goes down.
    assert [bones.bone_count(20, 80, d) for d in (0.1, 0.2, 0.3, 0.4, 0.5)] == [3, 7, 16, 40, 50]
    counts = [bones.bone_count(20, 80, d) for d in np.linspace(0, 1, 101)]
    assert counts == sorted(counts)
    plan = limb_plan(skeleton, bone_detail=0.5)
    for spec, child in zip(plan[:-1], plan[1:]):  # one connected chain, parents first
        assert child.parent == spec.name and child.use_connect
        assert np.allclose(child.head, spec.tail)


def test_an_end_bone_stops_short_of_its_tip_by_the_radius_at_its_head():
    skeleton = straight_chain([0.3, 0.3, 0.3, 0.3, 0.2])
    plan = limb_plan(skeleton, bone_detail=0.1)  # two bones: 0 -> 2 -> 4 (z)
    end = plan[-1]
    assert end.kind == "end" and end.node == 4 and end.head_radius == pytest.approx(0.3)
    assert np.allclose(end.tail, [0, 0, 4 - bones.END_INSET * 0.3])
    assert np.allclose(plan[0].tail, end.head)  # inner joints stay where they were
    # Never more than half the bone: a short end bone keeps half its length.
    short = skeleton_of([[0, 0, 0], [0, 0, 0.2]], ["joint", "end"], [[0, 1]], radii=[1, 1])
    (only,) = limb_plan(short)
    assert np.allclose(only.tail, [0, 0, 0.1])
    # An end node that branches on (degree > 1) keeps its bone's tail, its children's head.
    forked = skeleton_of([[0, 0, 0], [0, 0, 1], [0, 1, 2], [0, -1, 2]],
                         ["joint", "end", "end", "end"], [[0, 1], [1, 2], [1, 3]])
    first = limb_plan(forked, bone_detail=0.0)[0]
    assert first.node == 1 and np.allclose(first.tail, [0, 0, 1])


# --- sides: .L / .R across a mirror plane ------------------------------------------------------

def body(lean=0.0, arm_drop=0.0):
    """A spine (root joint 0 at the hips, up to a chest joint 1, a head end 2), two legs and
    two arms of two links each (knees, elbows: connection nodes). `lean` moves the head end
    sideways, `arm_drop` lowers the right arm's hand (asymmetries)."""
    positions = [[0, 0, 0], [0, 0, 1], [lean, 0, 1.6],
                 [0.3, 0, -0.6], [0.3, 0, -1.2], [-0.3, 0, -0.6], [-0.3, 0, -1.2],
                 [0.6, 0, 1], [1.2, 0, 1], [-0.6, 0, 1], [-1.2, 0, 1 - arm_drop]]
    kinds = ["joint", "joint", "end", "connection", "end", "connection", "end",
             "connection", "end", "connection", "end"]
    links = [[0, 1], [1, 2], [0, 3], [3, 4], [0, 5], [5, 6], [1, 7], [7, 8], [1, 9], [9, 10]]
    return skeleton_of(positions, kinds, links, root=0)


def test_paired_limbs_get_mirrored_names_and_the_middle_keeps_its_own():
    plan = limb_plan(body(), bone_detail=1.0)
    names = {s.name: s for s in plan}
    left = sorted(n for n in names if n.endswith(".L"))
    right = sorted(n for n in names if n.endswith(".R"))
    assert len(left) == len(right) == 4 and [n[:-2] for n in left] == [n[:-2] for n in right]
    for name in left:  # heads and tails mirror across x = 0
        other = names[name[:-1] + "R"]
        assert np.allclose(names[name].head * [-1, 1, 1], other.head)
        assert np.allclose(names[name].tail * [-1, 1, 1], other.tail)
        assert names[name].head[0] >= 0 and names[name].tail[0] > 0  # .L on +X
    middle = [n for n in names if not n.endswith((".L", ".R"))]
    assert sorted(middle) == ["head.001", "spine.001"]
    normal, offset, error = bones.mirror_plane(body().positions)
    assert np.allclose(normal, [1, 0, 0]) and abs(offset) < 1e-9 and error < 1e-9


def test_a_small_asymmetry_is_tolerated_a_large_one_is_not():
    plan = limb_plan(body(lean=0.05, arm_drop=0.05), bone_detail=1.0)
    assert sum(s.name.endswith(".L") for s in plan) == 4
    assert sum(s.name.endswith(".R") for s in plan) == 4
    skewed = limb_plan(body(lean=0.9, arm_drop=1.5), bone_detail=1.0)
    assert not any(s.name.endswith((".L", ".R")) for s in skewed)
    assert sorted(s.name for s in skewed if s.kind == "end") == [
        "limb1.002", "limb2.002", "limb3.001", "limb4.002", "limb5.002"]  # limbs in plan order


# --- symmetry: paired limbs mirror each other, the middle lies on the plane --------------------

def jittered_body(jitter=0.02, arm_drop=0.03, lean=0.03, seed=0):
    """body() with 4 inner points per link, every point but the root moved by up to `jitter`
    (seeded), the right hand lowered and the head leaning: a symmetric skeleton drawn a little
    asymmetrically, as the engine draws a symmetric mesh's. Radii 0.1 everywhere."""
    rng = np.random.default_rng(seed)
    shape = body(lean=lean, arm_drop=arm_drop)
    positions = shape.positions.copy()
    positions[1:] += rng.uniform(-jitter, jitter, size=positions[1:].shape)
    polylines = []
    for a, b in shape.links:
        inner = positions[a] + np.linspace(0, 1, 6)[1:-1, None] * (positions[b] - positions[a])
        inner += rng.uniform(-jitter, jitter, size=inner.shape)
        polylines.append(np.vstack([positions[a], inner, positions[b]]))
    return skeleton_of(positions, shape.kinds, shape.links, polylines, root=0)


def mirror_partners(plan):
    """[(left, right)] BoneSpecs named X.L / X.R; asserts that every sided name pairs."""
    names = {spec.name: spec for spec in plan}
    sided = [name for name in names if name.endswith((".L", ".R"))]
    for name in sided:
        assert name[:-1] + ("R" if name.endswith("L") else "L") in names, name
    return [(names[n], names[n[:-1] + "R"]) for n in sorted(sided) if n.endswith(".L")]


@pytest.mark.parametrize("seed", [0, 1, 2])
def test_a_slightly_asymmetric_skeleton_comes_out_exactly_mirrored(seed):
    skeleton = jittered_body(seed=seed)
    plan = limb_plan(skeleton, bone_detail=0.5)
    plane = bones.plan_plane(skeleton)
    assert plane is not None and abs(plane.normal[0]) > 0.99
    pairs = mirror_partners(plan)
    assert len(pairs) >= 4
    before = []  # how far the input's paired joints were from mirroring each other
    for left, right in pairs:
        assert np.allclose(plane.reflect(left.head), right.head, atol=1e-12)
        assert np.allclose(plane.reflect(left.tail), right.tail, atol=1e-12)
        assert left.head_radius == right.head_radius and left.kind == right.kind
        before.append(np.linalg.norm(plane.reflect(skeleton.positions[left.node])
                                     - skeleton.positions[right.node]))
    assert max(before) > 0.01  # the input was not mirrored: the plan was made so
    middle = [spec for spec in plan if not spec.name.endswith((".L", ".R"))]
    assert middle and all(abs(plane.signed(spec.head)) < 1e-12 for spec in middle)
    assert all(abs(plane.signed(spec.tail)) < 1e-12 for spec in middle)
    for spec in plan:  # every joint stays within MIRROR_REACH radii of the limb it came from
        nearest = min(np.min(np.linalg.norm(polyline - spec.head, axis=1))
                      for polyline in skeleton.polylines)
        assert nearest <= bones.symmetry.MIRROR_REACH * 0.1 + 1e-12


def test_joints_move_at_most_their_reach_toward_a_far_partner(no_inset):
    # The right hand 0.2 lower: halfway would move each hand 0.1, more than 0.9 x 0.05. That
    # arm does not tilt the plane either: the legs and the elbows still mirror across x = 0.
    skeleton = body(arm_drop=0.2)
    skeleton.radii = np.full(len(skeleton.positions), 0.05)
    plan = limb_plan(skeleton, bone_detail=0.0)
    plane = bones.plan_plane(skeleton)
    assert np.allclose(plane.normal, [1, 0, 0], atol=1e-6) and abs(plane.offset) < 1e-6
    hands = {spec.name: spec for spec in plan if spec.node in (8, 10)}
    left, right = hands["arm.001.L"], hands["arm.001.R"]
    reach = bones.symmetry.MIRROR_REACH * 0.05
    for spec, node in ((left, 8), (right, 10)):
        assert np.linalg.norm(spec.tail - skeleton.positions[node]) == pytest.approx(reach)
    gap = np.linalg.norm(plane.reflect(left.tail) - right.tail)
    assert 0 < gap < np.linalg.norm(plane.reflect(skeleton.positions[8])
                                    - skeleton.positions[10])
    legs = [pair for pair in mirror_partners(plan) if pair[0].node == 4]  # still exact
    assert legs and np.allclose(plane.reflect(legs[0][0].tail), legs[0][1].tail)


def test_a_pair_too_far_apart_mirrors_exactly_when_the_shape_mirrors_itself(no_inset):
    # The right hand 0.2 lower again, but the surface mirrors itself across x = 0 (the engine's
    # Skeleton.mirror_plane): the skeleton is what differs, so the .L arm stays as it is and the
    # .R arm gets its mirror image. On a surface that mirrors itself less closely (0.004 of the
    # diagonal: a pose, above COPY_TOLERANCE) the arms stay approximate, as above.
    skeleton = body(arm_drop=0.2)
    skeleton.radii = np.full(len(skeleton.positions), 0.05)
    skeleton.mirror_plane, skeleton.mirror_error = np.array([1.0, 0, 0, 0]), 1e-4
    plan = limb_plan(skeleton, bone_detail=0.0)
    plane = bones.plan_plane(skeleton)
    assert np.allclose(plane.normal, [1, 0, 0]) and plane.offset == 0  # the shape's own
    pairs = mirror_partners(plan)
    assert len(pairs) == 2  # the legs, the arms (one bone a limb)
    for left, right in pairs:
        assert np.allclose(plane.reflect(left.head), right.head, atol=1e-12)
        assert np.allclose(plane.reflect(left.tail), right.tail, atol=1e-12)
    hands = {spec.name: spec for spec in plan if spec.node in (8, 10)}
    assert np.allclose(hands["arm.001.L"].tail, skeleton.positions[8])
    skeleton.mirror_error = 0.004
    assert 0.004 > bones.symmetry.COPY_TOLERANCE
    assert np.allclose(bones.plan_plane(skeleton).normal, [1, 0, 0])  # still the shape's plane
    hands = {spec.name: spec for spec in limb_plan(skeleton, bone_detail=0.0)
             if spec.node in (8, 10)}
    gap = np.linalg.norm(plane.reflect(hands["arm.001.L"].tail) - hands["arm.001.R"].tail)
    assert gap == pytest.approx(0.2 - 2 * bones.symmetry.MIRROR_REACH * 0.05)


def test_a_middle_end_on_one_of_two_twin_features_ends_on_the_plane(no_inset):
    # The head's end on one of two horns (as the engine put spot's): the head ends where its
    # limb leaves the plane, on it, when the surface mirrors itself; a pose keeps it on the horn.
    skeleton = body()
    skeleton.positions[2] = [0.2, 0, 1.55]
    skeleton.polylines[1] = np.array([[0, 0, 1], [0, 0, 1.2], [0, 0, 1.4], [0.1, 0, 1.5],
                                      [0.2, 0, 1.55]])
    skeleton.mirror_plane, skeleton.mirror_error = np.array([1.0, 0, 0, 0]), 1e-4
    (head,) = [spec for spec in limb_plan(skeleton, bone_detail=1.0) if spec.node == 2]
    assert head.kind == "end" and np.allclose(head.tail, [0, 0, 1.4])
    skeleton.mirror_error = 0.004  # above COPY_TOLERANCE: the shape's own asymmetry
    (head,) = [spec for spec in limb_plan(skeleton, bone_detail=1.0) if spec.node == 2]
    assert np.allclose(head.tail, [0.2, 0, 1.55])
    skeleton.mirror_error = 1e-4  # the twin tip longer than TWIN_TIP radii: a limb of its own
    skeleton.positions[2] = [0.4, 0, 1.55]
    skeleton.polylines[1][-1] = [0.4, 0, 1.55]
    (head,) = [spec for spec in limb_plan(skeleton, bone_detail=1.0) if spec.node == 2]
    assert np.allclose(head.tail, [0.4, 0, 1.55])


def test_limbs_that_should_pair_but_do_not_are_counted():
    # The right leg hangs from the chest, the left from the hips: their feet mirror each other
    # on a shape that mirrors itself, but the limbs do not; the add-on warns of them.
    skeleton = body()
    skeleton.links[4] = [1, 5]
    skeleton.polylines[4] = skeleton.positions[[1, 5]]
    assert bones.unpaired_limbs(skeleton) == 0  # no plane of the shape: nothing expected
    skeleton.mirror_plane, skeleton.mirror_error = np.array([1.0, 0, 0, 0]), 1e-4
    feet = [spec.name for spec in limb_plan(skeleton) if spec.node in (4, 6)]
    assert len(feet) == 2 and not any(name.endswith((".L", ".R")) for name in feet)
    assert bones.unpaired_limbs(skeleton) == 2
    symmetric = body()
    symmetric.mirror_plane, symmetric.mirror_error = np.array([1.0, 0, 0, 0]), 1e-4
    assert bones.unpaired_limbs(symmetric) == 0


def test_limbs_whose_ends_and_starts_mirror_pair_on_a_shape_that_mirrors_itself(no_inset):
    # The right leg's path bulges back (as Q_Horse's front leg runs along its belly): the legs'
    # polylines no longer mirror, their ends and starts do. On a surface that mirrors itself
    # they pair and the right leg becomes the left one's mirror image; else they stay apart.
    skeleton = body()
    skeleton.polylines[4] = np.array([[0, 0, 0], [-0.05, 0.9, -0.1], [-0.25, 0.9, -0.5],
                                      [-0.3, 0, -0.6]])
    chains = bones.limbs(skeleton)
    points = [bones.limb_polyline(skeleton, limb)[0] for limb in chains]
    ends = [limb[-1][2] for limb in chains]
    sides = dict(zip(ends, bones.limb_sides(skeleton, points, ends)))
    assert sides[4][0] is None and sides[6][0] is None  # too different to pair as they are
    assert bones.unpaired_limbs(skeleton) == 0  # (no plane of the shape: nothing expected)
    skeleton.mirror_plane, skeleton.mirror_error = np.array([1.0, 0, 0, 0]), 1e-4
    plan = limb_plan(skeleton, bone_detail=1.0)
    feet = {spec.node: spec for spec in plan if spec.node in (4, 6)}
    assert feet[4].name == feet[6].name[:-1] + "L" and feet[6].name.endswith(".R")
    plane = bones.plan_plane(skeleton)
    for left, right in mirror_partners(plan):
        assert np.allclose(plane.reflect(left.head), right.head, atol=1e-12)
        assert np.allclose(plane.reflect(left.tail), right.tail, atol=1e-12)
    assert bones.unpaired_limbs(skeleton) == 0


def frog_hips(foot_x=1.0, tail=False, via=False):
    """Q_Frog's hind legs: both hang from one joint 0.3 to the right of the mirror plane x = 0,
    the right leg straight down, the left one first across the plane to its own hip; the spine
    arrives at that joint from a joint on the plane, drifting off it on the way. With `tail`,
    a limb of the middle leaves that joint too, for an end on the plane (node 7). With `via`,
    the left leg's first link ends at a connection node still right of the plane (node 7, or
    8 with `tail`) and its second crosses."""
    positions = [[0, 0, 0.5], [0.3, 0, 0], [1, 0, -1], [foot_x, 0, -3], [-1, 0, -1],
                 [-1, 0, -3], [0, 0, 1.5]]
    kinds = ["joint", "joint", "connection", "end", "connection", "end", "end"]
    links = [[0, 1], [1, 2], [2, 3], [1, 4], [4, 5], [0, 6]]
    polylines = [[[0, 0, 0.5], [0.02, 0, 0.3], [0.2, 0, 0.1], [0.3, 0, 0]], None, None,
                 [[0.3, 0, 0], [-0.3, 0, 0], [-1, 0, -1]], None, None]
    if tail:
        positions.append([0, 2, -0.5])
        kinds.append("end")
        links.append([1, 7])
        polylines.append(None)
    if via:  # 1 -> (0.15, 0, 0) -> across
        positions.append([0.15, 0, 0])
        kinds.append("connection")
        links[3] = [len(positions) - 1, 4]
        polylines[3] = [[0.15, 0, 0], [-0.3, 0, 0], [-1, 0, -1]]
        links.append([1, len(positions) - 1])
        polylines.append(None)
    return skeleton_of(positions, kinds, links, polylines)


def test_limbs_from_one_joint_off_the_plane_pair_from_where_one_crosses_it():
    skeleton = frog_hips()
    before = [np.array(line) for line in skeleton.polylines]
    plan = limb_plan(skeleton, bone_detail=1.0)
    names = {spec.name: spec for spec in plan}
    assert len(mirror_partners(plan)) == 3  # hip, thigh, shin
    for side in ("L", "R"):  # both legs start where the left one crossed the plane
        assert np.allclose(names[f"leg.001.{side}"].head, [0, 0, 0], atol=0.01)
    assert np.allclose(names["leg.001.L"].tail, [0.3, 0, 0], atol=0.01)  # via the old joint
    assert np.allclose(names["leg.001.R"].tail, [-0.3, 0, 0], atol=0.02)  # its mirror image
    spine = [spec for spec in plan if spec.name.startswith("spine.")]
    assert np.allclose(spine[-1].tail, [0, 0, 0], atol=0.01)  # the spine ends there too,
    assert all(abs(spec.tail[0]) < 0.03 for spec in spine)  # its drift off the plane dropped
    assert np.allclose(skeleton.positions[1], [0.3, 0, 0])  # the skeleton itself is unchanged
    assert all(np.array_equal(a, b) for a, b in zip(before, skeleton.polylines))


def test_limbs_from_one_joint_off_the_plane_pair_though_a_limb_of_the_middle_leaves_it_too():
    # Q_Goblin under a noise of 1e-5 of its diagonal: both arms and the head leave one chest
    # joint 0.26 off the plane, and the arms did not pair.
    plan = limb_plan(frog_hips(tail=True), bone_detail=1.0)
    names = {spec.name: spec for spec in plan}
    assert len(mirror_partners(plan)) == 3  # hip, thigh, shin
    for side in ("L", "R"):
        assert np.allclose(names[f"leg.001.{side}"].head, [0, 0, 0], atol=0.01)
    tail = [spec for spec in plan if spec.node == 7]
    assert len(tail) == 1 and abs(tail[0].head[0]) < 0.01 and abs(tail[0].tail[0]) < 0.01


def test_limbs_from_one_joint_off_the_plane_pair_when_one_crosses_it_in_a_later_link():
    # Q_Frog under a noise of 1e-5 of its diagonal (numpy draw 2): its hips' joint lies 0.7
    # off the plane, one leg's first link runs up to a connection node of the back on the
    # joint's side and its second across, and the legs did not pair.
    for tail in (False, True):
        skeleton = frog_hips(tail=tail, via=True)
        plan = limb_plan(skeleton, bone_detail=1.0)
        names = {spec.name: spec for spec in plan}
        assert len(mirror_partners(plan)) == 3  # hip, thigh, shin
        head = names["leg.001.L"].head  # both legs start where the left one crossed the plane
        assert np.allclose(names["leg.001.R"].head, head, atol=1e-9)
        assert abs(bones.plan_plane(skeleton).signed(head)) < 1e-9
        assert np.allclose(head, [0, 0, 0], atol=0.02)
        assert np.allclose(names["leg.001.L"].tail, [0.3, 0, 0], atol=0.01)  # the old joint
        assert all(np.linalg.norm(spec.tail - spec.head) > 0.1 for spec in plan)
    assert bones.unpaired_limbs(frog_hips(via=True)) == 0


def test_a_joint_off_the_plane_stays_where_its_limbs_ends_do_not_mirror():
    skeleton = frog_hips(foot_x=1.6)  # one foot 0.6 farther out than the other
    plane = bones.plan_plane(skeleton)
    chains, _, sides = bones._plan_symmetry(skeleton)
    assert plane is None or junctions.onto_plane(skeleton, plane, chains, sides) is skeleton
    assert not mirror_partners(limb_plan(skeleton, bone_detail=1.0))


def test_inside_tube_and_copies_inside():
    line = np.array([[0.0, 0, 0], [1, 0, 0], [1, 1, 0]])
    radii = np.array([0.1, 0.2, 0.1])
    points = [[0.5, 0.13, 0], [0.5, 0.14, 0], [1.1, 0.5, 0], [1.2, 0.5, 0], [1.0, 1.1, 0]]
    # the radius along the first segment is 0.15 at its middle (x 0.9: 0.135), 0.15 along the
    # second at y 0.5 (0.135), 0.1 at the last point (0.09)
    assert symmetry.inside_tube(points, line, radii).tolist() == [True, False, True, False,
                                                                   False]
    assert symmetry.inside_tube([[0.5, 0.14, 0]], line, radii, reach=1.0).tolist() == [True]
    plane = symmetry.Plane(np.array([1.0, 0, 0]), 0.0, 0.0)
    tilted = symmetry.Plane(np.array([np.cos(0.01), np.sin(0.01), 0]), 0.0, 0.0)
    shape = symmetry.Plane(np.array([1.0, 0, 0]), 0.0, 0.001)  # mirrors within 0.001 x diagonal
    assert shape.error <= symmetry.COPY_TOLERANCE
    deep = [[1.0, 0, 0], [1.0, 0, 0]]
    # across the shape's own plane: its error (0.001 x 10) against 0.9 x the depth
    assert symmetry.copies_inside(plane, shape, 10.0, deep, [0.02, 0.01]).tolist() == [True,
                                                                                      False]
    # across a plane 0.01 rad off it: the images lie 0.02 apart at x = 1 as well
    assert symmetry.copies_inside(tilted, shape, 10.0, deep, [0.04, 0.03]).tolist() == [True,
                                                                                       False]
    assert not symmetry.copies_inside(plane, None, 10.0, deep, [1.0, 1.0]).any()
    posed = symmetry.Plane(shape.normal, 0.0, 2 * symmetry.COPY_TOLERANCE)  # not copied from
    assert not symmetry.copies_inside(plane, posed, 10.0, deep, [1.0, 1.0]).any()


#: How close (a share of the longest side) to two of Mannequiny's segments a joint outside them
#: must be: in the gap between two (where the mannequin articulates; the engine's wrapped
#: surface spans it).
GAP = 0.03


def test_the_rigged_characters_pairs_mirror_exactly_and_stay_inside(meshes_dir):
    """On the rigged characters whose surfaces mirror themselves (all but the snake and the
    cylinder have pairs), every .L bone is its .R partner's mirror image across the plan's plane,
    where the skeletons differ too (Q_Dragon's wings branch differently on either side,
    Mannequiny's upper arms' polylines double back, Q_Frog's hind legs hang from one joint by
    its right hip), and no joint leaves the mesh for that.
    Mannequiny is made of separate segments: a joint may fall in the gap between two (a spine
    joint where its chest and belly pieces meet, the surface narrowing there; a hairline seam
    on Debian 13's CGAL), within GAP of both."""
    import mesh_parts

    folder = meshes_dir / "rigged"
    for name in ("Mannequiny", "Q_Dragon", "Q_Male_Casual", "Q_Goblin", "Q_Frog"):
        V, F = dcg.load_mesh(folder / f"{name}.obj")
        skeleton = shared_skeleton(V, F, name)
        plane = bones.plan_plane(skeleton)
        assert plane is not None and skeleton.mirror_error < bones.symmetry.SHAPE_TOLERANCE
        plan = limb_plan(skeleton)
        arrays = bones.bone_arrays(plan)
        mirror = metrics.mirror_error(V, arrays["names"], arrays["heads"], arrays["tails"],
                                          plane.normal, plane.offset)
        assert mirror["pairs"] >= 20 and mirror["unpaired"] == 0, name
        assert bones.unpaired_limbs(skeleton) == 0, name  # what the add-on warns of
        assert mirror["mirror_max"] < 1e-9, name
        joints = metrics.unique_points(np.concatenate([arrays["heads"], arrays["tails"]]))
        inside = mesh_parts.inside_any_part(joints, V, F)
        side = float(np.ptp(np.asarray(V), axis=0).max())
        parts = mesh_parts.face_parts(F)
        for joint in joints[~inside]:
            near = [metrics.point_distances(joint, V[np.unique(F[parts == k])]).min()
                    for k in range(parts.max() + 1)]
            assert name == "Mannequiny" and np.sum(np.array(near) < GAP * side) >= 2, (name, joint)


def belly_hub(shoulder=1.0):
    """Q_Knight's layout: one joint node 0 in the belly from which a head chain (through a
    neck node 1 at height 1), two legs and two arms leave; each arm's first link runs up
    through the chest to its shoulder node (at `shoulder`), then out to the hand."""
    positions = [[0, 0, 0], [0, 0, 1], [0, 0, 1.6],
                 [0.5, 0, shoulder], [1.2, 0, shoulder], [-0.5, 0, shoulder], [-1.2, 0, shoulder],
                 [0.3, 0, -0.6], [0.3, 0, -1.2], [-0.3, 0, -0.6], [-0.3, 0, -1.2]]
    kinds = ["joint", "connection", "end", "connection", "end", "connection", "end",
             "connection", "end", "connection", "end"]
    links = [[0, 1], [1, 2], [0, 3], [3, 4], [0, 5], [5, 6], [0, 7], [7, 8], [0, 9], [9, 10]]
    polylines = [[[0, 0, 0], [0, 0, 0.5], [0, 0, 1]], None,
                 [[0, 0, 0], [0.25, 0, 0.5 * shoulder], [0.5, 0, shoulder]], None,
                 [[0, 0, 0], [-0.25, 0, 0.5 * shoulder], [-0.5, 0, shoulder]], None,
                 None, None, None, None]
    return skeleton_of(positions, kinds, links, polylines, root=0)


def test_arms_that_reach_the_middle_by_their_first_node_hang_from_it(no_inset):
    plan = limb_plan(belly_hub(), bone_detail=1.0)
    names = {spec.name: spec for spec in plan}
    order = [spec.name for spec in plan]
    for side, x in (("L", 0.5), ("R", -0.5)):  # a bone across from the neck to the shoulder
        first = names[f"arm.001.{side}"]
        assert np.allclose(first.head, [0, 0, 1]) and np.allclose(first.tail, [x, 0, 1])
        host = names[first.parent]
        assert host.name.startswith("head.") and np.allclose(host.tail, [0, 0, 1])
        assert not first.use_connect and order.index(host.name) < order.index(first.name)
        assert [n for n in order if n.startswith("arm.") and n.endswith(side)] == [
            f"arm.001.{side}", f"arm.002.{side}"]  # nothing left inside the chest
        leg = names[f"leg.001.{side}"]  # the legs' first nodes are far from the head chain
        assert np.allclose(leg.head, [0, 0, 0]) and leg.parent is None
    arrays = bones.bone_arrays(plan)
    mirror = metrics.mirror_error(np.asarray(belly_hub().positions), arrays["names"],
                                  arrays["heads"], arrays["tails"], [1, 0, 0], 0.0)
    assert mirror["unpaired"] == 0 and mirror["mirror_max"] < 1e-12


def test_fingers_of_a_hanging_arm_hang_from_its_hand(no_inset):
    skeleton = belly_hub()  # three fingers from each hand (nodes 4 and 6, joints now)
    positions, kinds = [list(p) for p in skeleton.positions], list(skeleton.kinds)
    links, polylines = [list(link) for link in skeleton.links], list(skeleton.polylines)
    for hand, x in ((4, 1.5), (6, -1.5)):
        kinds[hand] = "joint"
        for z in (0.9, 1.0, 1.1):
            positions.append([x, 0, z])
            kinds.append("end")
            links.append([hand, len(positions) - 1])
            polylines.append(np.array([positions[hand], positions[-1]], dtype=float))
    plan = limb_plan(skeleton_of(positions, kinds, links, polylines), bone_detail=1.0)
    placed = set()
    for spec in plan:  # parents first
        assert spec.parent is None or spec.parent in placed, spec.name
        placed.add(spec.name)
    names = {spec.name: spec for spec in plan}
    fingers = [spec for spec in plan if spec.name.startswith("finger")]
    assert len(fingers) == 6
    for finger in fingers:  # each from the last bone of its own side's arm
        side = finger.name[-1]
        assert finger.parent == f"arm.002.{side}" and finger.use_connect
        assert names[finger.parent].parent == f"arm.001.{side}"


def test_arms_whose_first_node_is_nearer_their_start_keep_it():
    # shoulders at 0.35: 0.61 from the belly, 0.5 from the nearest joint of the head chain
    plan = limb_plan(belly_hub(shoulder=0.35), bone_detail=1.0)
    first = next(spec for spec in plan if spec.name == "arm.001.L")
    assert np.allclose(first.head, [0, 0, 0]) and first.parent is None


def test_a_mixamo_plan_asks_its_own_chest_for_the_arms():
    fractions = {4: [0.5], 6: [0.5]}  # what humanoid.mixamo_plan passes: no hanging then
    plan = limb_plan(belly_hub(), bone_detail=1.0, limb_fractions=fractions)
    assert all(spec.parent is None for spec in plan if spec.name.startswith("arm.001"))


def test_q_knights_arms_hang_from_its_chest_level_with_its_shoulders(meshes_dir):
    """Q_Knight's arms, legs and head all leave one node in its belly; its arms hang from the
    head chain by a bone across to each shoulder, inside the mesh, and mirror."""
    import mesh_parts

    V, F = dcg.load_mesh(meshes_dir / "rigged" / "Q_Knight.obj")
    skeleton = shared_skeleton(V, F, "Q_Knight")
    plan = limb_plan(skeleton)
    names = {spec.name: spec for spec in plan}
    height = float(np.ptp(np.asarray(V)[:, 2]))
    plane = bones.plan_plane(skeleton)
    for side in ("L", "R"):
        first = names[f"arm.001.{side}"]
        assert names[first.parent].name.startswith("head.")
        across = first.tail - first.head  # from the chest's middle out to the shoulder
        assert abs(across[2]) < 0.05 * height, across
        assert abs(plane.normal @ first.head - plane.offset) < 1e-6 * height  # on the plane
        assert first.head[2] > 0.6 * height  # the shoulders' level, not the belly (0.36)
        samples = first.head + np.linspace(0, 1, 9)[:, None] * across
        assert mesh_parts.inside_any_part(samples, V, F).all()
    arrays = bones.bone_arrays(plan)
    mirror = metrics.mirror_error(V, arrays["names"], arrays["heads"], arrays["tails"],
                                  plane.normal, plane.offset)
    assert mirror["unpaired"] == 0 and mirror["mirror_max"] < 1e-9


def test_q_knights_chest_follows_its_spine_not_its_arms(meshes_dir):
    """Why its arms hang from the chest: their bones no longer run through it, so the chest's
    vertices (between the belly node and the shoulders, near the middle: 15) take little
    weight from the arm bones: at most 0.32, 0.09 on average (before: up to 1.0, 0.70)."""
    import scipy.sparse

    V, F = dcg.load_mesh(meshes_dir / "rigged" / "Q_Knight.obj")
    V = np.asarray(V)
    plan = bones.plan_bones(shared_skeleton(V, F, "Q_Knight"))
    rows, cols, values = dcg.skin_weights(V, F, plan)
    W = scipy.sparse.coo_matrix((values, (rows, cols)), shape=(len(V), len(plan))).toarray()
    low, height = V[:, 2].min(), np.ptp(V[:, 2])  # belly node at 0.36, shoulders at 0.66
    chest = ((np.abs(V[:, 0]) < 0.09 * height) & (V[:, 2] > low + 0.42 * height)
             & (V[:, 2] < low + 0.61 * height))
    arm = np.array([spec.name.startswith("arm.") for spec in plan])
    on_chest = W[chest][:, arm].sum(axis=1)
    assert chest.sum() >= 10
    assert on_chest.max() < 0.5 and on_chest.mean() < 0.2, on_chest.round(2)


def test_an_asymmetric_skeleton_is_rigged_as_it_is(no_inset):
    skeleton = body(lean=0.9, arm_drop=1.5)
    assert bones.plan_plane(skeleton) is None
    plan = limb_plan(skeleton, bone_detail=1.0)
    for spec in plan:  # every joint is a node of the skeleton, where it was
        for point in (spec.head, spec.tail):
            assert np.min(np.linalg.norm(skeleton.positions - point, axis=1)) < 1e-12


def _head_on_a_horn(skeleton, V):
    """Spot's skeleton with its head's end moved across to a horn (to the x of its highest
    vertex on +X, off the mirror plane x = 0), as the engine put it before it moved such ends
    to the middle (dcg/prongs.h, "Midline")."""
    positions = skeleton.positions.copy()
    ends = np.flatnonzero(np.asarray(skeleton.kinds) == "end")
    head = ends[np.argmax(positions[ends, 1])]  # spot stands along +Y: the hooves lie lowest
    V = np.asarray(V)
    horn = np.flatnonzero(V[:, 0] > 0)[np.argmax(V[V[:, 0] > 0, 1])]
    offset = np.array([V[horn, 0] - positions[head, 0], 0.0, 0.0])
    positions[head] += offset
    polylines = [line.copy() for line in skeleton.polylines]
    for (a, b), line in zip(skeleton.links.tolist(), polylines):
        line[[i for i, node in ((0, a), (-1, b)) if node == head]] += offset
    return dataclasses.replace(skeleton, positions=positions, polylines=polylines)


def test_an_exactly_symmetric_shape_pairs_its_limbs_across_its_own_plane(meshes_dir):
    """Spot mirrors itself across x = 0, but a skeleton of it whose nodes do not (the head's
    end on one horn, the hooves' end balls a little apart) still pairs its legs across the
    shape's own plane (Skeleton.mirror_plane) and they come out exactly mirrored; a skeleton
    without that plane (an older document's) keeps its nodes' verdict."""
    V, F = dcg.load_mesh(meshes_dir / "spot.obj")
    skeleton = _head_on_a_horn(shared_skeleton(V, F, "spot.obj"), V)
    nodes = bones.mirror_plane(skeleton.positions)
    assert nodes[2] > bones.symmetry.MIRROR_TOLERANCE  # no plane of the nodes
    assert skeleton.mirror_error < bones.symmetry.SHAPE_TOLERANCE / 10
    assert abs(skeleton.mirror_plane[0]) > 0.999 and abs(skeleton.mirror_plane[3]) < 1e-3
    plan = limb_plan(skeleton)
    pairs = mirror_partners(plan)
    hooves = [(left, right) for left, right in pairs if left.kind == "end"]
    assert len(hooves) == 2  # four legs, in two pairs; the head's end stays in the middle
    plane = bones.plan_plane(skeleton)
    for left, right in pairs:
        assert np.allclose(plane.reflect(left.head), right.head, atol=1e-9)
        assert np.allclose(plane.reflect(left.tail), right.tail, atol=1e-9)
        assert plane.signed(left.tail) > 0 > plane.signed(right.tail)  # .L on +X
    assert plane.normal[0] > 0.999
    older = dataclasses.replace(skeleton, mirror_plane=np.zeros(4), mirror_error=1.0)
    assert bones.plan_plane(older) is None
    assert not mirror_partners(limb_plan(older))
    assert dcg.Skeleton.from_json(skeleton.to_json()).mirror_error == skeleton.mirror_error


def test_spots_head_ends_in_its_muzzle_on_the_mirror_plane(meshes_dir):
    """The default model's head bone: its highest point is a horn, yet the head's end is the
    muzzle's (the engine's midline move, Prongs.midline), on the plane x = 0, at the front
    (spot looks along -Z), ahead of and below the horns; two end bones in the middle, the
    head's and the tail's (Prongs.tails: the flap at the rump, behind every hoof), the
    hooves' in pairs."""
    V, F = dcg.load_mesh(meshes_dir / "spot.obj")
    skeleton = shared_skeleton(V, F, "spot.obj")
    plan = bones.bone_arrays(bones.plan_bones(skeleton))
    size = float(np.linalg.norm(np.ptp(V, axis=0)))
    ends = [i for i, kind in enumerate(plan["kinds"]) if kind == "end"]
    middle = [i for i in ends if not plan["names"][i].endswith((".L", ".R"))]
    assert len(ends) == 6 and len(middle) == 2, plan["names"]
    head, tail = sorted(middle, key=lambda i: plan["tails"][i][2])
    hooves = [plan["tails"][i] for i in ends if i not in middle]
    back = plan["tails"][tail]
    assert abs(back[0]) < 1e-3 * size
    assert back[2] > max(h[2] for h in hooves) + 0.05 * size  # behind the hind legs
    assert back[1] > max(h[1] for h in hooves) + 0.15 * size  # at the rump, not at the ground
    tip = plan["tails"][head]
    assert abs(tip[0]) < 1e-3 * size
    horn = V[np.argmax(V[:, 1])]  # its highest vertex, a horn's tip
    assert tip[2] < horn[2] - 0.03 * size  # ahead of the horns (not between them)
    assert tip[1] < horn[1] - 0.03 * size


def test_limbs_pair_only_when_they_end_alike():
    skeleton = body()
    skeleton.kinds[10] = "joint"  # the right hand: a branching node's kind
    chains = bones.limbs(skeleton)
    points = [bones.limb_polyline(skeleton, limb)[0] for limb in chains]
    ends = [limb[-1][2] for limb in chains]
    sides = bones.limb_sides(skeleton, points, ends)
    by_end = {end: side for end, (side, _) in zip(ends, sides)}
    assert by_end[8] is None and by_end[10] is None  # the arms no longer pair
    assert by_end[4] == "L" and by_end[6] == "R"      # the legs still do
    assert [s[0] for s in bones.limb_sides(skeleton, points)].count("L") == 2  # without ends


# --- rolls -------------------------------------------------------------------------------------

def test_rolls_turn_one_way_along_a_bent_chain():
    skeleton = bent_tube(bend_at=4)
    plan = limb_plan(skeleton, bone_detail=1.0)
    z = np.array([spec.z_axis for spec in plan])
    along = np.array([spec.tail - spec.head for spec in plan])
    assert np.allclose(np.einsum("bi,bi->b", z, along), 0, atol=1e-12)  # normal to each bone
    assert np.allclose(np.linalg.norm(z, axis=1), 1)
    assert np.allclose(z[:, 1], 0, atol=1e-12)  # in the plane the tube bends in (y = 0)
    assert (z @ z.T > -1e-12).all()  # no bone's axis flips against another's
    # Both legs of the L point their Z axes to the outside of the bend: -x, then +z.
    assert z[0] @ [-1, 0, 0] > 0.99 and z[-1] @ [0, 0, 1] > 0.99


def test_paired_bones_axes_mirror_and_the_middles_lie_in_the_plane():
    skeleton = jittered_body(seed=3)
    plan = limb_plan(skeleton, bone_detail=0.5)
    plane = bones.plan_plane(skeleton)
    for left, right in mirror_partners(plan):
        assert np.allclose(plane.reflect_direction(left.z_axis), right.z_axis, atol=1e-9)
    for spec in plan:
        if not spec.name.endswith((".L", ".R")):
            assert abs(spec.z_axis @ plane.normal) < 1e-9, spec.name


def test_blender_rolls_of_mirrored_bones_across_x_0_are_opposite():
    rng = np.random.default_rng(7)
    flip = np.array([-1.0, 1.0, 1.0])
    for _ in range(200):
        head, tail = rng.normal(size=3), rng.normal(size=3)
        along = (tail - head) / np.linalg.norm(tail - head)
        z = rng.normal(size=3)
        z -= (z @ along) * along
        z /= np.linalg.norm(z)
        roll = bones.rolls.blender_roll(head, tail, z)
        mirrored = bones.rolls.blender_roll(head * flip, tail * flip, z * flip)
        assert np.isclose(np.cos(roll), np.cos(mirrored)) and \
            np.isclose(np.sin(roll), -np.sin(mirrored))


def test_blender_roll_turns_the_roll_zero_axes_onto_the_z_axis():
    rng = np.random.default_rng(8)
    directions = list(rng.normal(size=(100, 3))) + [[0, 1, 0], [0, -1, 0], [1e-5, -1, 0],
                                                    [0.01, -1, 0.01], [1, 0, 0]]
    for direction in directions:
        y = np.asarray(direction, float) / np.linalg.norm(direction)
        x0, z0 = bones.rolls.roll_zero_axes(y)
        frame = np.column_stack([x0, y, z0])  # Blender's bone matrix at roll 0 (within 1e-4
        assert np.allclose(frame.T @ frame, np.eye(3), atol=1e-4)  # of -Y: -Y's own axes)
        assert np.linalg.det(frame) == pytest.approx(1.0, abs=1e-4)
        z = np.cross(y, rng.normal(size=3))
        z /= np.linalg.norm(z)
        roll = bones.rolls.blender_roll(np.zeros(3), y, z)
        # Blender: matrix = rotation about y by roll, times the roll-0 matrix.
        assert np.allclose(np.cos(roll) * z0 + np.sin(roll) * x0, z, atol=1e-4)
    x0, z0 = bones.rolls.roll_zero_axes(np.array([0.0, 1.0, 0.0]))
    assert np.allclose(x0, [1, 0, 0]) and np.allclose(z0, [0, 0, 1])


def test_bone_arrays_carry_the_z_axes_and_rolls():
    plan = limb_plan(jittered_body(), bone_detail=0.5)
    arrays = bones.bone_arrays(plan)
    assert arrays["z_axes"].shape == (len(plan), 3) and arrays["rolls"].shape == (len(plan),)
    assert np.array_equal(arrays["rolls"], [spec.roll for spec in plan])
    empty = bones.bone_arrays([])
    assert empty["z_axes"].shape == (0, 3) and empty["rolls"].shape == (0,)


def test_on_a_straight_limb_joints_go_to_the_fractions_asked_for():
    points = np.linspace([0, 0, 0], [0, 0, 2], 21)  # 20 segments of 0.1
    radii = np.full(21, 0.2)
    assert bones.articulations(points, radii, 3, fractions=(0.3, 0.8)) == [0, 6, 16, 20]
    # a bend still wins over a fraction asked for
    bent = points.copy()
    bent[11:, 0] = (np.arange(11, 21) - 10) * 0.1
    assert bones.articulations(bent, radii, 2, fractions=(0.3,)) == [0, 10, 20]
