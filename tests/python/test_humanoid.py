"""dcg.humanoid: retarget-ready (Mixamo) bone names for humanoid skeletons, on hand-made
skeletons and on real characters with their artists' rigs."""

import types

import numpy as np
import pytest

import dcg
from dcg import bones, humanoid
from test_bones import limb_plan

MIXAMO_BODY = {"Hips", "Spine", "Spine1", "Spine2", "Neck", "Head", "HeadTop_End"}
MIXAMO_LIMBS = {side + name for side in ("Left", "Right") for name in (
    "Shoulder", "Arm", "ForeArm", "Hand", "UpLeg", "Leg", "Foot", "ToeBase")}


def stick_figure(nodes, kinds, links, root=0, samples=9):
    """A skeleton whose links are straight polylines of `samples` points."""
    positions = np.asarray(nodes, dtype=float)
    polylines = [np.linspace(positions[a], positions[b], samples) for a, b in links]
    return types.SimpleNamespace(
        positions=positions, kinds=np.array(kinds), links=np.array(links),
        polylines=polylines, root=root, radii=np.full(len(positions), 0.05))


def person():
    """Pelvis 0, chest 1, a head end, and hands and feet on either side of x = 0 (.L on +X);
    the root at the chest."""
    return stick_figure(
        [[0, 0, 1.0], [0, 0, 1.5], [0, 0, 1.9], [0.8, 0, 1.45], [-0.8, 0, 1.45],
         [0.2, 0.05, 0.0], [-0.2, 0.05, 0.0]],
        ["joint", "joint", "end", "end", "end", "end", "end"],
        [[0, 1], [1, 2], [1, 3], [1, 4], [0, 5], [0, 6]], root=1)


def person_of_one_joint():
    """A person whose head, arms and legs all leave the body at one joint (node 0)."""
    return stick_figure(
        [[0, 0, 1.0], [0, 0, 1.9], [0.8, 0, 1.45], [-0.8, 0, 1.45], [0.2, 0.05, 0.0],
         [-0.2, 0.05, 0.0]],
        ["joint", "end", "end", "end", "end", "end"],
        [[0, 1], [0, 2], [0, 3], [0, 4], [0, 5]], root=0)


def test_a_person_gets_mixamos_names_and_hierarchy():
    plan = limb_plan(person(), names="mixamo")
    named = {spec.name: spec for spec in plan}
    assert humanoid.is_mixamo(plan)
    assert set(named) == MIXAMO_BODY | MIXAMO_LIMBS
    assert [spec.name for spec in plan if spec.parent is None] == ["Hips"]
    expected_parents = {"Spine": "Hips", "LeftUpLeg": "Hips", "RightUpLeg": "Hips",
                        "Neck": "Spine2", "LeftShoulder": "Spine2", "LeftArm": "LeftShoulder",
                        "LeftForeArm": "LeftArm", "LeftHand": "LeftForeArm",
                        "RightLeg": "RightUpLeg", "Head": "Neck", "HeadTop_End": "Head"}
    for name, parent in expected_parents.items():
        assert named[name].parent == parent, name
    seen = set()
    for spec in plan:  # parents first
        assert spec.parent is None or spec.parent in seen
        seen.add(spec.name)
    # Hips starts at the pelvis and points up the spine; the legs start at the hips, away from
    # the pelvis (the pelvis-to-hip piece has no bone) and not connected to Hips.
    assert np.allclose(named["Hips"].head, [0, 0, 1.0]) and named["Hips"].tail[2] > 1.0
    assert not named["LeftUpLeg"].use_connect and named["LeftUpLeg"].head[0] > 0.02
    assert named["LeftHand"].tail[0] > 0.5 and named["RightHand"].tail[0] < -0.5
    assert named["LeftToeBase"].tail[2] < 0.2 and named["LeftToeBase"].tail[0] > 0


def test_arms_and_legs_leaving_the_body_at_one_node_still_name_a_spine():
    plan = limb_plan(person_of_one_joint(), names="mixamo")
    named = {spec.name: spec for spec in plan}
    assert humanoid.is_mixamo(plan)
    assert {"Hips", "Spine", "Neck", "Head"} <= set(named)
    assert named["LeftShoulder"].parent in humanoid.CHEST_BONES
    assert named["LeftUpLeg"].parent == "Hips"


def test_other_shapes_keep_the_descriptive_names():
    # A quadruped's five ends (four legs and a head) pair like a person's, but its legs stand
    # across its spine: not upright, not humanoid.
    quadruped = stick_figure(
        [[0, -0.5, 1], [0, 0.5, 1], [0, 1.0, 1.3], [0.3, 0.5, 0], [-0.3, 0.5, 0],
         [0.3, -0.5, 0], [-0.3, -0.5, 0]],
        ["joint", "joint", "end", "end", "end", "end", "end"],
        [[0, 1], [1, 2], [1, 3], [1, 4], [0, 5], [0, 6]])
    extra_end = person()
    extra_end.positions = np.vstack([extra_end.positions, [[0, -0.6, 0.9]]])  # a tail
    extra_end.kinds = np.append(extra_end.kinds, "end")
    extra_end.links = np.vstack([extra_end.links, [[0, 7]]])
    extra_end.polylines = extra_end.polylines + [np.linspace([0, 0, 1.0], [0, -0.6, 0.9], 9)]
    extra_end.radii = np.full(8, 0.05)
    # A quadruped whose legs and neck all leave one joint in the middle of its body (spot's
    # skeleton): seen from that joint its hind legs go on away from its head, but its front
    # feet stand under its head, not between it and the hind feet.
    one_joint = stick_figure(
        [[0, 0, 0.8], [0, 1.2, 1.6], [0.3, 0.5, 0], [-0.3, 0.5, 0], [0.25, -0.9, 0],
         [-0.25, -0.9, 0]],
        ["joint", "end", "end", "end", "end", "end"],
        [[0, 1], [0, 2], [0, 3], [0, 4], [0, 5]])
    for skeleton in (quadruped, extra_end, one_joint):
        assert humanoid.find_humanoid(skeleton) is None
        plan = limb_plan(skeleton, names="mixamo")
        assert not humanoid.is_mixamo(plan)
        assert [s.name for s in plan] == [s.name for s in limb_plan(skeleton)]


def test_an_unknown_convention_is_refused():
    with pytest.raises(ValueError, match="mixamo"):
        limb_plan(person(), names="unreal")


@pytest.mark.parametrize("name", ["Q_Knight", "Q_Goblin", "CesiumMan"])
def test_real_characters_are_humanoid_left_is_the_artists_left_and_mirrors(meshes_dir, name):
    """The artists' rigs name their sides (Foot.L, LowerArm.L; CesiumMan: by position), and
    our Left bones lie on the same side as theirs."""
    V, F = dcg.load_mesh(str(meshes_dir / "rigged" / f"{name}.obj"))
    skeleton = dcg.extract_skeleton(V, F)
    plan = limb_plan(skeleton, names="mixamo")
    named = {spec.name: spec for spec in plan}
    assert set(named) == MIXAMO_BODY | MIXAMO_LIMBS
    joints = {}
    for line in open(meshes_dir / "rigged" / f"{name}.rig.txt"):
        if line.startswith("joints "):
            fields = line.split()
            joints[fields[1]] = np.array(fields[2:5], dtype=float)
    for ours in ("LeftHand", "LeftFoot"):
        # the artist's joint nearest to our bone's tail is on the same side of the middle
        # as our bone (the artist's .L side where the rig names sides)
        nearest = min(joints, key=lambda j: np.linalg.norm(joints[j] - named[ours].tail))
        if nearest.endswith((".L", ".R")):
            assert nearest.endswith(".L"), (ours, nearest)
        right = named[ours.replace("Left", "Right")].tail
        assert np.linalg.norm(joints[nearest] - named[ours].tail) < np.linalg.norm(
            joints[nearest] - right), ours
    # Left and Right bones mirror each other across the plan's plane, within 1% of the size
    plane, size = humanoid.plan_plane(skeleton), float(np.ptp(V, axis=0).max())
    for left in (n for n in named if n.startswith("Left")):
        right = named["Right" + left[len("Left"):]]
        for a, b in ((named[left].head, right.head), (named[left].tail, right.tail)):
            assert np.linalg.norm(plane.reflect(a) - b) < 0.01 * size, left


def test_the_batch_gets_the_same_mixamo_bones(meshes_dir, tmp_path):
    import io

    from dcg import batch_blender, batch_worker

    V, F = dcg.load_mesh(str(meshes_dir / "knight.off"))
    skeleton = dcg.extract_skeleton(V, F)
    data, status = batch_worker.weights_npz(V, F, skeleton, bone_names="mixamo")
    assert status == "ok"
    with np.load(io.BytesIO(data)) as npz:
        names = list(npz["bone_names"])
    assert names == [spec.name for spec in bones.plan_bones(skeleton, names="mixamo")]
    assert "Hips" in names and "LeftForeArm" in names
    flags = batch_blender.cli_flags({}, 0.5, "mixamo")  # the .glb: the add-on's CLI
    assert flags[flags.index("--bone-names") + 1] == "mixamo"
    pytest.importorskip("distributed")
    from dcg import batch

    with pytest.raises(ValueError, match="bone_names"):
        batch.run(meshes_dir, tmp_path, bone_names="unreal", progress=None)


def person_with_fingers():
    """person() whose hands (nodes 3 and 4) have five fingers each, pointing out along x: a
    thumb forward and below, index to pinky in a row behind it, the middle finger longest."""
    base = person()
    positions, links = [list(p) for p in base.positions], [list(link) for link in base.links]
    kinds = list(base.kinds)
    kinds[3] = kinds[4] = "joint"
    for hand, side in ((3, 1.0), (4, -1.0)):
        x, y, z = positions[hand]
        for dx, dy, dz in ((0.08, -0.12, -0.06), (0.2, -0.05, 0), (0.22, 0, 0),
                           (0.2, 0.05, 0), (0.16, 0.1, 0)):
            positions.append([x + side * dx, y + dy, z + dz])
            links.append([hand, len(positions) - 1])
            kinds.append("end")
    return stick_figure(positions, kinds, links, root=1)


def test_a_hands_fingers_get_mixamos_names():
    skeleton = person_with_fingers()
    body = humanoid.find_humanoid(skeleton)
    assert body is not None and set(body.fingers) == {"L", "R"}
    assert [body.fingers["L"][name] for name in humanoid.FINGER_NAMES] == [7, 8, 9, 10, 11]
    plan = limb_plan(skeleton, names="mixamo")
    named = {spec.name: spec for spec in plan}
    fingers = {f"{side}Hand{finger}{i}" for side in ("Left", "Right")
               for finger in humanoid.FINGER_NAMES for i in (1, 2, 3)}
    assert set(named) == MIXAMO_BODY | MIXAMO_LIMBS | fingers
    assert named["LeftHandThumb1"].parent == "LeftHand"
    assert named["RightHandPinky2"].parent == "RightHandPinky1"
    assert named["LeftHandIndex3"].tail[0] > 0 and named["RightHandIndex3"].tail[0] < 0


def test_real_fingers_are_named_after_the_artists(meshes_dir):
    """Mannequiny's hands: the engine finds the thumb and two fingers of each (Prongs.fingers),
    the hand's own end is the fourth; each finger's last bone ends nearest the artist's joint of
    the same finger (thumb_03.l, index_03.l, ...)."""
    V, F = dcg.load_mesh(str(meshes_dir / "rigged" / "Mannequiny.obj"))
    plan = {spec.name: spec for spec in limb_plan(dcg.extract_skeleton(V, F),
                                                         names="mixamo")}
    joints = {}
    for line in open(meshes_dir / "rigged" / "Mannequiny.rig.txt"):
        if line.startswith("joints ") and line.split()[1][-2:] in (".l", ".r"):
            fields = line.split()
            joints[fields[1]] = np.array(fields[2:5], dtype=float)
    checked = 0
    for side, suffix in (("Left", ".l"), ("Right", ".r")):
        for finger in humanoid.FINGER_NAMES:
            tips = [spec for name, spec in plan.items() if name.startswith(side + "Hand" + finger)]
            if not tips:
                continue
            tail = tips[-1].tail
            nearest = min(joints, key=lambda j: np.linalg.norm(joints[j] - tail))
            assert nearest.startswith(finger.lower()) and nearest.endswith(suffix), \
                (side, finger, nearest)
            checked += 1
    assert checked == 8  # thumb, index, middle and ring of each hand


def test_loops_in_the_legs_are_left_out_and_each_leg_stays_one_chain():
    # person() with a loop at each knee: a leg runs pelvis 0 -> knee -> foot, and a second path
    # knee -> a -> b -> knee goes around a handle (a mannequin's segmented knee). The link that
    # closes a loop and what hangs from it get no bone; the rest is Mixamo's.
    base = person()
    positions, links = list(base.positions), [[0, 1], [1, 2], [1, 3], [1, 4]]
    kinds = list(base.kinds)
    loops = []
    for side, foot in ((1, 5), (-1, 6)):
        knee = len(positions)
        positions += [[side * 0.2, 0.05, 0.5], [side * 0.25, 0.1, 0.45], [side * 0.25, 0.1, 0.55]]
        kinds += ["joint", "connection", "connection"]
        links += [[0, knee], [knee, foot]]
        loops += [len(links), len(links) + 1, len(links) + 2]
        links += [[knee, knee + 1], [knee + 1, knee + 2], [knee + 2, knee]]
    skeleton = stick_figure(positions, kinds, links, root=1)
    assert humanoid.find_humanoid(skeleton) is not None
    plan = limb_plan(skeleton, names="mixamo")
    assert humanoid.is_mixamo(plan)
    assert {spec.name for spec in plan} == MIXAMO_BODY | MIXAMO_LIMBS
    assert not any(spec.link in loops for spec in plan)  # the loops have no bone
    assert len(limb_plan(skeleton)) > len(plan)  # the descriptive plan keeps them
