"""Descriptive bone names (dcg.naming): each limb's chain named after what the shape says it is."""

import re

import numpy as np
import pytest

import dcg
from conftest import shared_skeleton
from dcg import bones, naming
from test_bones import body, limb_plan, skeleton_of


def chains_of(plan):
    """{chain name without the counter: number of bones}, e.g. {"arm.L": 2, "head": 1}."""
    found = {}
    for spec in plan:
        chain = re.sub(r"\.\d{3}", "", spec.name)
        found[chain] = found.get(chain, 0) + 1
    return found


def rotated(skeleton, matrix):
    """`skeleton` with positions and polylines turned by the 3x3 `matrix`."""
    return skeleton_of(skeleton.positions @ matrix.T, skeleton.kinds, skeleton.links,
                       [polyline @ matrix.T for polyline in skeleton.polylines],
                       root=skeleton.root, radii=skeleton.radii)


def quadruped():
    """A spine along Y (hips joint 0 at y=0, shoulders joint 1 at y=1, a little higher), four
    legs down to the ground at z=-1, a neck and head up in front, a tail behind."""
    positions = [[0, 0, 0], [0, 1, 0.1],
                 [0.3, 0, -1], [-0.3, 0, -1], [0.3, 1, -1], [-0.3, 1, -1],
                 [0, 1.6, 0.7], [0, -0.7, -0.2]]
    kinds = ["joint", "joint", "end", "end", "end", "end", "end", "end"]
    links = [[0, 1], [0, 2], [0, 3], [1, 4], [1, 5], [1, 6], [0, 7]]
    return skeleton_of(positions, kinds, links, root=0)


def test_a_person_gets_arms_legs_a_head_and_a_spine():
    plan = limb_plan(body(), bone_detail=1.0)
    assert chains_of(plan) == {"spine": 1, "head": 1, "arm.L": 2, "arm.R": 2, "leg.L": 2,
                               "leg.R": 2}
    legs = [spec for spec in plan if spec.name.startswith("leg.")]
    assert all(spec.node in (3, 4, 5, 6) for spec in legs)  # the limbs that reach the ground


def test_the_names_follow_the_ground_not_the_axes():
    # The same person Y-up (an OBJ's convention) and standing on its head along Y: up is found
    # where the feet stand, and the names do not change.
    person = chains_of(limb_plan(body(), bone_detail=1.0))
    for matrix, up in (([[1, 0, 0], [0, 0, 1], [0, -1, 0]], [0, 1, 0]),
                       ([[1, 0, 0], [0, 0, -1], [0, 1, 0]], [0, -1, 0])):
        turned = rotated(body(), np.array(matrix, dtype=float))
        assert chains_of(limb_plan(turned, bone_detail=1.0)) == person
        feet_hands_head = [2, 4, 6, 8, 10]
        assert np.allclose(naming.up_axis(turned.positions, feet_hands_head,
                                          bones.plan_plane(turned)), up)


@pytest.mark.parametrize("seed", range(5))
def test_any_orientation_gives_paired_names(seed):
    # A plane turned away from every axis (no candidate up lies in it): still named, .L / .R
    # pairing bone by bone.
    matrix = np.linalg.qr(np.random.default_rng(seed).normal(size=(3, 3)))[0]
    plan = limb_plan(rotated(quadruped(), matrix), bone_detail=0.0)
    found = chains_of(plan)
    assert len(plan) == 7
    assert all(found[c] == found[c[:-1] + "R"] for c in found if c.endswith(".L"))
    assert sum(c.endswith(".L") for c in found) == 2


def test_a_quadruped_gets_front_and_hind_legs_a_head_and_a_tail():
    plan = limb_plan(quadruped(), bone_detail=0.0)
    by_node = {spec.node: spec.name for spec in plan}
    assert by_node[4] == "front_leg.001.L" and by_node[5] == "front_leg.001.R"  # by the head
    assert by_node[2] == "hind_leg.001.L" and by_node[3] == "hind_leg.001.R"
    assert by_node[6] == "head.001" and by_node[7] == "tail.001"
    assert by_node[1] == "spine.001"


def test_fingers_fan_from_a_hand_and_the_arm_keeps_its_name():
    # Arms out to hands at x = +-1 (joints 1 and 2), three fingers from each; legs to the ground.
    positions = [[0, 0, 0], [1, 0, 0.5], [-1, 0, 0.5]]
    links = [[0, 1], [0, 2]]
    for side in (1, -1):
        hand = 1 if side > 0 else 2
        for dz in (-0.1, 0, 0.1):
            positions.append([side * 1.3, 0, 0.5 + dz])
            links.append([hand, len(positions) - 1])
    for side in (1, -1):
        positions.append([side * 0.3, 0, -1.5])
        links.append([0, len(positions) - 1])
    positions.append([0, 0, 1.2])
    links.append([0, len(positions) - 1])
    kinds = ["joint"] * 3 + ["end"] * (len(positions) - 3)
    plan = limb_plan(skeleton_of(positions, kinds, links, root=0), bone_detail=0.0)
    found = chains_of(plan)
    assert found["arm.L"] == found["arm.R"] == 1  # the arm up to the hand
    assert sum(found.get(f"finger{i}.L", 0) for i in (1, 2, 3)) == 3
    assert found["leg.L"] == found["leg.R"] == 1 and found["head"] == 1


def test_without_a_mirror_plane_tips_are_limbs():
    skewed = body(lean=0.9, arm_drop=1.5)
    assert bones.plan_plane(skewed) is None
    names = chains_of(limb_plan(skewed, bone_detail=0.0))
    assert set(names) == {"spine", "limb1", "limb2", "limb3", "limb4", "limb5"}


@pytest.mark.parametrize("name, chains", [
    ("spot.obj", {"front_leg.L", "front_leg.R", "hind_leg.L", "hind_leg.R", "head", "tail"}),
    ("cow.off", {"front_leg.L", "front_leg.R", "hind_leg.L", "hind_leg.R", "head", "tail"}),
    ("knight.off", {"arm.L", "arm.R", "leg.L", "leg.R", "head"}),
    # Its fingers (the engine's Prongs.fingers) and the hand's own end fan from one node.
    ("rigged/Mannequiny.obj", {"arm.L", "arm.R", "leg.L", "leg.R", "head"}
     | {f"finger{i}.{side}" for i in range(1, 5) for side in "LR"}),
])
def test_public_meshes_get_the_names_of_their_limbs(meshes_dir, name, chains):
    V, F = dcg.load_mesh(str(meshes_dir / name))
    plan = limb_plan(shared_skeleton(V, F, name))
    found = chains_of(plan)
    assert set(found) - {"spine"} == chains
    for chain in found:  # a pair's chains have as many bones, named alike
        if chain.endswith(".L"):
            assert found[chain] == found[chain[:-1] + "R"]


def flying_insect():
    """A wasp in flight, standing on z: a thorax joint (the root), a head end at the top front,
    a sting end at the bottom, two pairs of wings raised above everything and a pair of legs
    hanging in the air: along -z four ends (the wing tips) look like feet on the ground."""
    positions = [[0, 0, 2], [0, 0.8, 2.6], [0, -0.3, 0.5], [1.2, 0.3, 3.6], [-1.2, 0.3, 3.6],
                 [1.1, -0.4, 3.5], [-1.1, -0.4, 3.5], [0.6, 0.3, 1.2], [-0.6, 0.3, 1.2]]
    kinds = ["joint"] + ["end"] * 8
    return skeleton_of(positions, kinds, [[0, k] for k in range(1, 9)], root=0,
                       radii=[0.3] + [0.1] * 8)


def test_a_flying_insect_is_named_upright_in_its_scene():
    """Its own up (where most ends stand) is upside down: its raised wings' tips look like
    feet, and the sting, highest along it, became the head. Told the scene's up (the add-on's
    world +Z), the head is the highest end of the middle and the sting the tail; a quarter
    turn from the scene's up is believed (a Y-up file's model lying in a Blender scene)."""
    insect = flying_insect()

    def chain_at(plan, node):
        return next(re.sub(r"\.\d{3}", "", s.name) for s in plan if s.node == node)
    inferred = limb_plan(insect, bone_detail=0.0)
    assert (chain_at(inferred, 2), chain_at(inferred, 1)) == ("head", "tail")  # upside down
    upright = limb_plan(insect, bone_detail=0.0, up=(0.0, 0.0, 1.0))
    assert (chain_at(upright, 1), chain_at(upright, 2)) == ("head", "tail")
    assert not any(name.startswith("leg") for name in chains_of(upright))  # nothing stands
    found = naming.up_axis(insect.positions, list(range(1, 9)), bones.plan_plane(insect))
    assert np.allclose(naming.scene_up(found, (0, 0, 1)), [0, 0, 1])
    assert np.allclose(naming.scene_up(np.array([0.0, 1.0, 0.0]), (0, 0, 1)), [0, 1, 0])
