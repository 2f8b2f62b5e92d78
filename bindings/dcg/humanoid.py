"""Retarget-ready bone names (no `bpy`: plain pytest tests it): a humanoid skeleton's bones
named after Mixamo's rig, so that animation libraries made for it retarget onto ours.

    plan = dcg.bones.plan_bones(skeleton, names="mixamo")   # humanoid: Hips, Spine, ...
    body = dcg.humanoid.find_humanoid(skeleton)             # a Humanoid, or None
    plane = dcg.humanoid.plan_plane(skeleton)               # what its Left/Right mirror across
    dcg.humanoid.is_mixamo(plan)                            # did the names apply?

A skeleton is humanoid (`find_humanoid`) when it has five ends and a mirror plane
(`dcg.symmetry`), the links that close its cycles left out (a loop around a handle of the
surface, as at a mannequin's segmented knee, has no bone in the Mixamo plan): one end on the
plane (the head), two pairs mirrored across it, the pair farther from the head the feet, the
other the hands; the two legs meet at one node (the pelvis), both arms at another between it
and the head (the chest). A hand may be a node that
FINGERS or more ends leave (the engine's Prongs.fingers; at most five): its fingers are named
after Mixamo's too, the one standing apart from the others the thumb, then index, middle, ring
and pinky by their distance from it across the hand. Any other skeleton (a tail, toes,
no mirror plane, arms that leave the body at two places) keeps the descriptive names, and
`plan_bones` says so by returning the "dcg" plan (`is_mixamo`).

The plan is rooted at the pelvis and has Mixamo's chains, each bone named by its place in
its chain (`CHAIN_NAMES`: fewer bones where a limb has fewer polyline segments):

    Hips > Spine > Spine1 > Spine2 > Neck > Head > HeadTop_End
    Spine2 > LeftShoulder > LeftArm > LeftForeArm > LeftHand      (Right... likewise)
    Hips > LeftUpLeg > LeftLeg > LeftFoot > LeftToeBase           (Right... likewise)
    LeftHand > LeftHandThumb1 > LeftHandThumb2 > LeftHandThumb3   (Index, Middle, Ring, Pinky)

Hips is the spine's first bone (its head at the pelvis), the legs its children (not
connected: they start at its head). Left is the .L side of the plan (the side the plane's
normal points to: +X, the character's left for a model facing -Y, as Blender's .L). The
joints are the planner's own (`dcg.bones.articulations`, mirrored across the plane), drawn on
straight stretches to CHAIN_FRACTIONS of their chain; the count per chain is Mixamo's, so
`bone_detail` does not apply.
"""

from collections import deque
from dataclasses import dataclass, replace
from types import SimpleNamespace

import numpy as np

from . import naming, symmetry
from .skeleton import measured_polyline_radii
from .bones import limbs, plan_bones
from .bones import plan_plane as bones_plan_plane

#: Bone names of each chain by how many bones it has (the most: Mixamo's own chain). The
#: trunk runs from the pelvis to the chest, the neck from the chest to the head's end; where
#: the legs and arms leave the body at one node the "torso" from there to the head is both.
CHAIN_NAMES = {
    "trunk": {1: ("Hips",), 2: ("Hips", "Spine"), 3: ("Hips", "Spine", "Spine1"),
              4: ("Hips", "Spine", "Spine1", "Spine2")},
    "neck": {1: ("Head",), 2: ("Neck", "Head"), 3: ("Neck", "Head", "HeadTop_End")},
    "torso": {2: ("Hips", "Head"), 3: ("Hips", "Spine", "Head"),
              4: ("Hips", "Spine", "Neck", "Head"),
              5: ("Hips", "Spine", "Neck", "Head", "HeadTop_End"),
              6: ("Hips", "Spine", "Spine1", "Neck", "Head", "HeadTop_End"),
              7: ("Hips", "Spine", "Spine1", "Spine2", "Neck", "Head", "HeadTop_End")},
    "arm": {1: ("Arm",), 2: ("Arm", "ForeArm"), 3: ("Arm", "ForeArm", "Hand"),
            4: ("Shoulder", "Arm", "ForeArm", "Hand")},
    # an arm that leaves the body at the pelvis's node (one torso joint): it first runs up
    # the torso's side, where it has no bone
    "low arm": {1: ("Arm",), 2: ("Arm", "ForeArm"), 3: ("Arm", "ForeArm", "Hand"),
                4: ("Shoulder", "Arm", "ForeArm", "Hand"),
                5: (None, "Shoulder", "Arm", "ForeArm", "Hand")},
    "leg": {1: ("UpLeg",), 2: ("UpLeg", "Leg"), 3: ("UpLeg", "Leg", "Foot"),
            4: ("UpLeg", "Leg", "Foot", "ToeBase"),
            5: (None, "UpLeg", "Leg", "Foot", "ToeBase")},
}
# A finger's bones (its chain's name: the finger's, "Thumb" ... "Pinky"; the side comes first).
FINGER_NAMES = ("Thumb", "Index", "Middle", "Ring", "Pinky")
CHAIN_NAMES.update({finger: {count: tuple(f"Hand{finger}{i}" for i in range(1, count + 1))
                             for count in (1, 2, 3)} for finger in FINGER_NAMES})
#: A leg's first bone of five runs from the pelvis out to the hip (None: no bone there): the
#: thigh's bone, UpLeg, starts at the hip as Hips' child, as in Mixamo's rig.
#: Where the inner joints of each chain of Mixamo's full count are drawn to on a limb that
#: is straight there (fractions of the chain's arc length, first to last: hip, knee, ankle,
#: ball of the foot; shoulder, elbow, wrist; skull base...), measured on the rigged
#: characters' artists' skeletons; bends and narrowings still place them where they are
#: (dcg.bones.articulations, PRIOR).
CHAIN_FRACTIONS = {
    "trunk": (0.25, 0.5, 0.75),
    "neck": (0.3, 0.85),
    "torso": (0.12, 0.3, 0.45, 0.6, 0.75, 0.95),
    "arm": (0.22, 0.54, 0.87),
    "low arm": (0.25, 0.39, 0.68, 0.88),
    "leg": (0.15, 0.52, 0.85, 0.93),
    **{finger: (0.4, 0.7) for finger in FINGER_NAMES},
}
#: A node that at least this many ends leave (through connection nodes only) is a hand with
#: its fingers: the descriptive names' count (dcg.naming).
FINGERS = naming.FINGERS
#: The bones the arms hang from, the first there is: the top of the spine.
CHEST_BONES = ("Spine2", "Spine1", "Spine", "Hips")
SIDE_NAMES = {"L": "Left", "R": "Right"}
#: Hands and feet pair when each lies this close to the other's mirror image (in bounding-box
#: diagonals of the skeleton's nodes: a pose or a scan is not exactly symmetric).
PAIR_TOLERANCE = 0.1
#: Upright: the cosine between the pelvis's directions to the head and to the feet is below
#: minus this (a quadruped's legs stand across its spine: about 0), and so is the cosine between
#: the directions from between the hands to the head and to between the feet (the humanoids
#: of the bench -0.81 to -1.00; spot, whose four legs leave one joint, -0.18).
UPRIGHT = 0.5


@dataclass(frozen=True)
class Humanoid:
    """The nodes of a humanoid skeleton: hands and feet by side ({"L": node, "R": node})."""

    head: int
    chest: int
    pelvis: int
    hands: dict
    feet: dict
    fingers: dict = None  #: {"L": {finger name: end node}, "R": ...} where a hand has fingers


def _tree_parents(links, node_count, start):
    """Parent of each node in the tree `links` walked from `start` (-1 at the start; -2 at a
    node no link reaches), or None when the links are not one tree over their nodes."""
    if len(links) != len(np.unique(links)) - 1:
        return None
    incident = [[] for _ in range(node_count)]
    for a, b in links:
        incident[a].append(b)
        incident[b].append(a)
    parents = np.full(node_count, -2, dtype=np.int64)
    parents[start] = -1
    queue = deque([start])
    while queue:
        node = queue.popleft()
        for other in incident[node]:
            if parents[other] == -2:
                parents[other] = node
                queue.append(other)
    reached = (parents != -2) | (np.bincount(links.ravel(), minlength=node_count) == 0)
    return parents if reached.all() else None


def _path(parents, node):
    """Nodes from the walk's start to `node`."""
    path = [node]
    while parents[path[-1]] >= 0:
        path.append(int(parents[path[-1]]))
    return path[::-1]


def _branch(path_a, path_b):
    """The last node two paths from the same start share."""
    shared = 0
    while shared < min(len(path_a), len(path_b)) and path_a[shared] == path_b[shared]:
        shared += 1
    return path_a[shared - 1]


def _paired_ends(plane, positions, ends, tolerance):
    """(head, [(.L end, .R end), (.L, .R)]) of five end nodes: the four that pair best as
    mirror images across `plane` (each within `tolerance` of the other's mirror image) and
    the one left over; None when no four pair."""
    best = None
    for head in ends:
        rest = ends[ends != head]
        left, right = rest[plane.signed(positions[rest]) > 0], rest[plane.signed(
            positions[rest]) <= 0]
        if len(left) != 2 or len(right) != 2:
            continue
        mirrored = plane.reflect(positions[left])
        for order in (right, right[::-1]):
            gaps = np.linalg.norm(mirrored - positions[order], axis=1)
            if gaps.max() <= tolerance and (best is None or gaps.sum() < best[0]):
                best = (gaps.sum(), int(head), list(zip(left.tolist(), order.tolist())))
    return None if best is None else best[1:]


def _unit(vector):
    """`vector` over its length (a zero vector stays zero)."""
    return vector / max(float(np.linalg.norm(vector)), 1e-12)


def _direction(positions, start, nodes):
    """Unit vector from node `start` to the mean of `nodes`."""
    return _unit(positions[list(nodes)].mean(axis=0) - positions[start])


def find_humanoid(skeleton):
    """The Humanoid of `skeleton` (see the module's text), or None when it is not one."""
    positions = np.asarray(skeleton.positions, dtype=float).reshape(-1, 3)
    links = np.asarray(skeleton.links, dtype=np.int64).reshape(-1, 2)[_tree_links(skeleton)]
    degree = np.bincount(links.ravel(), minlength=len(positions))
    plane = symmetry.skeleton_plane(skeleton)
    if plane is None:
        return None
    fans = {node: tips for node, tips in _fans(links, degree).items()
            if abs(plane.signed(positions[node])) > symmetry.tolerance(positions)}
    fingered = {tip for tips in fans.values() for tip in tips}
    ends = np.array(sorted(set(np.flatnonzero(degree == 1)) - fingered | set(fans)),
                    dtype=np.int64)
    if len(ends) != 5:
        return None
    tolerance = PAIR_TOLERANCE * float(np.linalg.norm(np.ptp(positions, axis=0)))
    paired = _paired_ends(plane, positions, ends, tolerance)
    parents = None if paired is None else _tree_parents(links, len(positions), paired[0])
    if parents is None:
        return None
    head, pairs = paired
    reach = [np.linalg.norm(positions[list(pair)] - positions[head], axis=1).mean()
             for pair in pairs]
    (hand_l, hand_r), (foot_l, foot_r) = pairs if reach[0] < reach[1] else pairs[::-1]
    to = {node: _path(parents, node) for node in (hand_l, hand_r, foot_l, foot_r)}
    pelvis = _branch(to[foot_l], to[foot_r])
    chests = {_branch(to[hand_l], to[hand_r]), _branch(to[hand_l], to[foot_l]),
              _branch(to[hand_r], to[foot_r])}
    chest = chests.pop() if len(chests) == 1 else None
    if chest is None or to[foot_l].index(chest) > to[foot_l].index(pelvis):
        return None  # the arms leave the body at two places, or below the legs
    # Upright: the legs go on from the trunk, away from the head (a quadruped's stand across),
    # and seen from between the hands, the head and the feet lie on opposite sides (a
    # quadruped's four legs may leave one joint of the trunk, which the legs then leave away
    # from the head, as spot's do: its front feet stand below its head, between it and no one).
    up = _direction(positions, pelvis, [head])
    if float(up @ _direction(positions, pelvis, [foot_l, foot_r])) > -UPRIGHT:
        return None
    hands = positions[[hand_l, hand_r]].mean(axis=0)
    feet = positions[[foot_l, foot_r]].mean(axis=0)
    if float(_unit(positions[head] - hands) @ _unit(feet - hands)) > -UPRIGHT:
        return None
    if set(fans) - {hand_l, hand_r} or any(len(tips) > len(FINGER_NAMES) for tips in
                                          fans.values()):
        return None  # toes, a head of several ends, more than five fingers
    fingers = {side: _fingers(positions, fans[hand], positions[hand] - positions[chest])
               for side, hand in (("L", hand_l), ("R", hand_r)) if hand in fans}
    return Humanoid(head, chest, pelvis, {"L": hand_l, "R": hand_r},
                    {"L": foot_l, "R": foot_r}, fingers or None)


def _fans(links, degree):
    """{node: the end nodes whose limbs (through nodes of degree 2) start there} for the nodes
    that FINGERS or more ends leave (off the mirror plane: hands with their fingers)."""
    incident = [[] for _ in degree]
    for a, b in links:
        incident[a].append(int(b))
        incident[b].append(int(a))
    starts = {}
    for end in np.flatnonzero(degree == 1):
        previous, node = int(end), incident[end][0]
        while degree[node] == 2:
            previous, node = node, next(n for n in incident[node] if n != previous)
        starts.setdefault(node, []).append(int(end))
    return {node: tips for node, tips in starts.items() if len(tips) >= FINGERS}


def _fingers(positions, tips, arm):
    """{finger name: end node} of a hand's finger tips (arm: the direction the arm reaches
    out in): the thumb the one farthest from the others on average, then index, middle, ring
    and pinky by their distance from it across the hand (normal to the arm: not how long they
    are)."""
    points = positions[tips]
    gaps = np.linalg.norm(points[:, None] - points[None], axis=2)
    thumb = int(np.argmax(gaps.sum(axis=1)))
    across = points - np.outer(points @ _unit(arm), _unit(arm))
    order = np.argsort(np.linalg.norm(across - across[thumb], axis=1), kind="stable")
    return dict(zip(FINGER_NAMES, [tips[k] for k in order]))


def _tree_links(skeleton):
    """The indices of the links of `skeleton` but those that close a cycle (dcg.bones.limbs)
    and the links left hanging from where they were, up to a node of degree 3 or an end: a loop
    around a handle of the surface (a mannequin's segmented knee) has no bone in the Mixamo
    plan, and the limb it was on is one chain again."""
    links = np.asarray(skeleton.links, dtype=np.int64).reshape(-1, 2)
    closing = {limb[0][0] for limb in limbs(skeleton) if not limb[0][3]}
    kept = set(range(len(links))) - closing
    kinds = [str(kind) for kind in skeleton.kinds]
    loose = [int(node) for link in closing for node in links[link]]
    while loose:  # a node that only a closing link held to the rest is left out with its link
        node = loose.pop()
        at = [i for i in kept if node in links[i]]
        if len(at) == 1 and kinds[node] != "end":
            kept.discard(at[0])
            loose.append(int(links[at[0]][0] if links[at[0]][1] == node else links[at[0]][1]))
    return sorted(kept)


def _rooted(skeleton, root, kept=None):
    """A view of `skeleton` with another root and only the links `kept` (`_tree_links`, found
    when not given): what plan_bones reads."""
    kept = _tree_links(skeleton) if kept is None else kept
    radii = measured_polyline_radii(skeleton)
    return SimpleNamespace(positions=skeleton.positions, kinds=skeleton.kinds,
                           radii=skeleton.radii,
                           links=np.asarray(skeleton.links, dtype=np.int64).reshape(-1, 2)[kept],
                           polylines=[skeleton.polylines[i] for i in kept], root=int(root),
                           polyline_radii=[] if radii is None else [radii[i] for i in kept])


def _chain_ends(body):
    """{node a chain ends at: (chain, side, the node it starts at)} (see CHAIN_NAMES)."""
    if body.chest == body.pelvis:
        chains = {body.head: ("torso", None, body.pelvis)}
    else:
        chains = {body.chest: ("trunk", None, body.pelvis),
                  body.head: ("neck", None, body.chest)}
    for side in ("L", "R"):
        arm = "low arm" if body.chest == body.pelvis else "arm"
        chains[body.hands[side]] = (arm, side, body.chest)
        chains[body.feet[side]] = ("leg", side, body.pelvis)
        for finger, tip in (body.fingers or {}).get(side, {}).items():
            chains[tip] = (finger, side, body.hands[side])
    return chains


def _chain_of(plan, by_name, end_node, start_node):
    """The bones of the chain that ends at `end_node`, first to last: from the bone whose tail
    is that node up to the one that leaves `start_node` (or a root); [] when no bone ends there."""
    bone = next((spec for spec in plan if spec.node == end_node), None)
    if bone is None:
        return []
    chain = [bone]
    while chain[-1].parent is not None and by_name[chain[-1].parent].node != start_node:
        chain.append(by_name[chain[-1].parent])
    return chain[::-1]


def mixamo_plan(skeleton):
    """The bone plan of a humanoid `skeleton` named after Mixamo's rig (the module's text), or
    None when it is not humanoid (the chains have Mixamo's counts, whatever the bone detail)."""
    body = find_humanoid(skeleton)
    if body is None:
        return None
    chains = _chain_ends(body)
    kept = _tree_links(skeleton)  # the view's links are these of the skeleton's
    plan = plan_bones(_rooted(skeleton, body.pelvis, kept), root_bone=False, limb_fractions={
        node: CHAIN_FRACTIONS[chain] for node, (chain, _, _) in chains.items()})
    by_name = {spec.name: spec for spec in plan}
    renamed, roles = {}, {}
    for node, (chain, side, start) in chains.items():
        bones = _chain_of(plan, by_name, node, start)
        names = CHAIN_NAMES[chain].get(len(bones))
        if names is None:
            return None  # no bone, or a torso of one bone: no Hips below the head
        for spec, name in zip(bones, names):
            renamed[spec.name] = None if name is None else SIDE_NAMES.get(side, "") + name
            roles[spec.name] = chain
    if len(renamed) != len(plan):
        return None  # a bone outside the chains: not the shape find_humanoid saw
    chest = next(name for name in CHEST_BONES if name in renamed.values())
    result = []
    for spec in plan:
        parent, connect = renamed.get(spec.parent), spec.use_connect
        if renamed[spec.name] is None:
            continue
        if parent is None and roles[spec.name] in ("arm", "low arm", "leg"):  # at the pelvis
            parent, connect = ("Hips" if roles[spec.name] == "leg" else chest), False
        result.append(replace(spec, name=renamed[spec.name], parent=parent,
                              use_connect=connect, link=kept[spec.link]))
    return _parents_first(result)


def _parents_first(plan):
    """`plan` reordered so that every bone comes after its parent (breadth-first)."""
    children = {}
    for spec in plan:
        children.setdefault(spec.parent, []).append(spec)
    ordered, queue = [], deque(children.get(None, []))
    while queue:
        spec = queue.popleft()
        ordered.append(spec)
        queue.extend(children.get(spec.name, []))
    return ordered


def plan_plane(skeleton):
    """The plane the Mixamo plan of a humanoid `skeleton` mirrors across (dcg.bones.plan_plane
    of the skeleton rooted at the pelvis), or None when it is not humanoid."""
    body = find_humanoid(skeleton)
    return None if body is None else bones_plan_plane(_rooted(skeleton, body.pelvis))


def is_mixamo(plan):
    """True when `plan` has the Mixamo names (plan_bones with names="mixamo" on a humanoid)."""
    return any(spec.name == "Hips" for spec in plan)
