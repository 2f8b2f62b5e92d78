"""The bone plan of a DCG skeleton: the one planner behind the add-on's armature, the batch's
.weights.npz and `dcg.skin_weights(V, F, skeleton)` (no `bpy`: plain pytest tests it).

    plan = dcg.bones.plan_bones(skeleton, bone_detail=0.5)   # [BoneSpec], parents first
    arrays = dcg.bones.bone_arrays(plan)   # names, heads, tails, parents (-1), links, kinds,
                                           # z_axes, rolls
    plane = dcg.bones.plan_plane(skeleton) # the mirror plane of the plan (or None)

One chain of bones per limb: a chain of skeleton links through connection nodes (nodes
of degree 2), from a branching node or the root to the next branching node or an end, so a
leg is one limb from the hip joint to the foot. The limb's joints are placed where it bends
and where it narrows (`articulations`: the limb's polyline fitted exactly by dynamic
programming, joints drawn to radius minima); `bone_detail` says how many (0 = one bone per
limb, 1 = about one per polyline segment). Chains are laid out breadth-first from the
skeleton's root: the chain of a limb starts at the node nearer the root and its first bone
is the child of the bone that arrived at that node. A link that closes a cycle (genus > 0)
is a limb of its own whose first bone is parented without `use_connect`, so the armature
stays a tree while every cycle keeps its bones. A pair of limbs whose first node lies by the
first stretch of a limb of the middle hangs from that limb's joint there instead, by a bone
across to that node (`hang_from_middle`: Q_Knight's arms from its chest). A connection node
between two joints of a limb has no bone ending at it; every node of degree other than 2 has.
The bone ending at an end node stops END_INSET radii short of it (the node is the prong's tip
on the surface; the joint sits inside the rounded tip, where an artist's last joint goes).

Bone kinds: a bone whose tail is a skeleton node takes that node's kind ("end", "joint",
"connection"); a bone whose tail is an inner polyline point is a "connection" (such points
have two neighbours, like connection nodes); `link` is the link of the bone's last
segment. Names are the limb's (`dcg.naming`: ``spine``, ``head``, ``tail``, ``arm``,
``front_leg``, ...) plus a counter per name from the root outward: ``spine.001``, ``head.002``.
With `root_bone` (the default) the plan starts with ``root``, of kind "root": a control on
the floor under the body that every chain hangs from and that deforms nothing (`add_root`).

Symmetry (`dcg.symmetry`): when the skeleton has a mirror plane through its root, the limbs
on either side that mirror each other (and end at nodes of one kind; on a surface that mirrors
itself, also those whose ends and starts mirror each other) pair: both get the same
joints, fitted once on their mean, one limb's the mirror images of the other's, and
Blender's side suffixes, the two chains sharing their counters bone by bone
(``arm.001.L`` / ``arm.001.R``, ``hind_leg.003.L`` / ``hind_leg.003.R``: what X-Axis
Mirror, Symmetrize and Paste Pose Flipped pair; a .R bone is named after its .L partner).
The middle's joints (its limbs', the root) lie on the plane. Joints mirror exactly where they
stay inside the mesh for it (`symmetrize`: within symmetry.MIRROR_REACH radii of their own
limb's skeleton, or copied from the .L limb when the surface mirrors itself); a pair that can
do neither moves at most MIRROR_REACH radii toward its partner and mirrors approximately.
A limb of the middle that the engine ended on one of two mirror-image features (spot's head on
one horn) ends where it leaves the plane, on it (`_middle_ends`); a joint off the plane from
which two limbs of mirror-image ends hang, one across the plane, is planned where that one
crosses it (`dcg.junctions`: Q_Frog's hind legs); limbs that should pair and do not are
counted by `unpaired_limbs` (the add-on warns of them).
.L is the side the plane's normal points to (its largest component positive: +X for a model
mirrored across x = 0). The middle's limbs and every limb of a shape with no mirror plane
keep the plain names, and a shape with no mirror plane keeps its joints where they were.

Rolls (`dcg.rolls`): each bone's local Z axis (`z_axis`) is the part normal to it of its
chain's reference direction (where the limb bends to), so it turns one way along the chain;
a .R chain's reference is the mirror image of its .L partner's and a middle chain's lies in
the mirror plane, so paired bones' axes mirror. `roll` is Blender's EditBone.roll for that
axis in the skeleton's coordinates (the add-on aligns each bone's roll to `z_axis` in the
armature's own space instead, which also holds under object transforms).
"""

from collections import deque
from dataclasses import dataclass, replace

import numpy as np

from . import junctions, naming, rolls, symmetry, tips
from .skeleton import measured_polyline_radii
from .symmetry import MIRROR_TOLERANCE, limb_sides, mirror_plane  # noqa: F401 (this API)

KINDS = ("end", "joint", "connection", "root")
#: The default `bone_detail` (the add-on's panel, its CLI and `dcg batch` start from it).
BONE_DETAIL = 0.5
#: How bones are named: by limb and side ("dcg", the default: `dcg.naming`) or after Mixamo's
#: rig when the skeleton is humanoid ("mixamo", `dcg.humanoid`).
BONE_NAME_CONVENTIONS = ("dcg", "mixamo")
BONE_NAMES = "dcg"
#: Bones per link of a limb at bone_detail 1 (capped by the limb's polyline segments).
BONES_PER_LINK = 5.0
#: Below bone_detail 0.5 a limb gets at most LIMB_CAP x d / (1 - 2 d) bones (d the detail), so
#: that lowering it thins long, thin limbs first (see bone_count).
LIMB_CAP = 22.0
#: How much a narrowing (the radius dipping below the widest part on both sides, 0..1)
#: draws a joint, against the squared distance of the polyline to the bones (in radii^2).
NARROWING = 1.0
#: How strongly a joint is drawn to the fraction of its limb's arc length a plan asks for
#: (`articulations`' fractions), against the squared distances in radii^2.
PRIOR = 10.0
#: No bone spans more of its limb's arc length than LONGEST_BONE x the limb's mean bone (arc
#: length / bones), unless it spans one polyline segment (`articulations`).
LONGEST_BONE = 3.0
#: The cost (in the squared mean radii of `articulations`) of each bone longer than that: far
#: above any fit, but finite, so that a plan always exists.
OVERLONG = 1e6
#: A limb's polyline point where it turns back by more than this many degrees is dropped
#: (`unfolded`).
FOLD_BACK = 120.0
#: An end bone's tail stops this many radii (at its head) short of the end node.
END_INSET = 1.0
#: Whether a plan starts with a root bone (`add_root`): a control on the floor under the body,
#: parent of every other bone and weighting no vertex (kind "root"), what game engines move a
#: character by and Rigify's rigs start from (10 of the 14 rigged characters' artists made one).
ROOT_BONE = True
#: The root bone's name.
ROOT_NAME = "root"
#: The up direction, across which the root bone's floor lies (Blender's world +Z).
UP = (0.0, 0.0, 1.0)
#: The model's own origin, in the skeleton's coordinates: its file's coordinate origin (the
#: add-on passes its object's origin). The root bone stands on the floor under it when it is
#: over the body's footprint, where game characters' artists put it (`add_root`).
ORIGIN = (0.0, 0.0, 0.0)
#: The root bone's head moves onto the mirror plane along the floor when the plane stands
#: within this many degrees of upright, else along the plane's normal (`add_root`).
UPRIGHT_PLANE = 45.0
#: An unpaired limb whose joints keep within this fraction of its length of the mirror plane runs
#: along it, and may end in a thin tip a little off it yet be of the middle (`_in_the_middle`).
ALONG_PLANE = 0.25
#: A pair of limbs hangs from a joint on the first link of a limb of the middle that leaves
#: the same node when their first node lies nearer to that joint than this fraction of its
#: distance from that node (`hang_from_middle`: Q_Knight's arms from its chest, not its belly).
HANG_NEARER = 0.5
#: A limb of the middle whose end lies off the mirror plane for at most this many radii (where
#: it leaves the plane) of its length ends there instead (`_middle_ends`: spot's head on a horn).
TWIN_TIP = 3.0


@dataclass
class BoneSpec:
    """One planned bone, in the skeleton's coordinates."""

    name: str
    head: np.ndarray           #: 3 head position
    tail: np.ndarray           #: 3 tail position
    parent: str | None         #: parent bone name, None for bones at the root
    use_connect: bool          #: head attached to the parent's tail
    kind: str                  #: "end", "joint", "connection" or "root" (deforms nothing)
    node: int                  #: skeleton node at the tail, -1 for an inner polyline point
    link: int                  #: skeleton link of the bone's last segment (root bone: -1)
    head_radius: float         #: skeleton radius at the head (distance to the surface)
    tail_radius: float         #: skeleton radius at the tail
    z_axis: np.ndarray         #: 3 the bone's local Z axis (unit, normal to it; dcg.rolls)
    roll: float                #: Blender's roll (radians) that gives that Z axis, here


@dataclass
class LimbJoints:
    """One limb's joints before its bones are made (#J = its bones + 1, first to last)."""

    original: np.ndarray       #: #J by 3 where the limb's own polyline has them
    target: np.ndarray         #: #J by 3 where symmetry wants them (`original` without)
    radii: np.ndarray          #: #J skeleton radius at each joint (a pair's: the two's mean)
    own_radii: np.ndarray      #: #J the limb's own radius there (how far a joint may move)
    nodes: np.ndarray          #: #J skeleton node at each joint, -1 between nodes
    links: np.ndarray          #: #J-1 skeleton link of each bone's last segment
    points: np.ndarray = None  #: #J by 3 where they go (symmetrize; `original` until then)

    def __post_init__(self):
        if self.points is None:
            self.points = np.array(self.original, dtype=float)


def bone_count(links, segments, bone_detail):
    """How many bones a limb of `links` links and `segments` polyline segments gets:
    max(1, round(bone_detail x BONES_PER_LINK x links)), at most one per segment, and below
    0.5 at most round(LIMB_CAP x d / (1 - 2 d)) (d = bone_detail: 3 at 0.1, 7 at 0.2, 16 at
    0.3, 44 at 0.4, no cap from 0.5 up). So 0 gives one bone per limb, 0.5 (the default) 2.5
    per link, 0.8 and above one per segment.

    Why the cap: a long, thin limb has many links (the engine's connection points follow its
    thickness: Q_Zombie's legs 10 each), so by links alone it keeps many bones where an
    animator lowering the detail wants few. At the same mean bone count over the 14 rigged
    characters, capped plans are closer to the artists' (CD-J2J 4.53 against 4.87 at about 26
    bones, 4.28 against 4.46 at about 37, 4.11 against 4.15 at about 50)."""
    detail = min(max(float(bone_detail), 0.0), 1.0)
    count = int(round(detail * BONES_PER_LINK * links))
    if detail < 0.5:
        count = min(count, int(round(LIMB_CAP * detail / (1.0 - 2.0 * detail))))
    return max(1, min(segments, count))


def articulations(points, radii, bones, fractions=None):
    """Return the indices of the points of a limb (#P by 3, radii #P) kept as joints: the
    two ends and bones - 1 inner points (every point when bones >= #P - 1).

    The joints are the ones of least cost, found exactly (dynamic programming, O(bones P^2)
    time, O(P^2) memory: a limb has tens of points, 4 per link as the engine samples them):
    the squared distances of the limb's points to the bones, in squared mean radii (so joints
    go where the centre line bends), less NARROWING x the narrowing at each inner joint
    (where the limb is thinner than its widest part on both sides: a knee, a wrist, a neck),
    plus, with `fractions` (bones - 1 of them, first joint to last), PRIOR x the squared
    difference between each inner joint's fraction of the limb's arc length and its own (where
    a knee goes on a straight leg), plus OVERLONG for each bone longer than LONGEST_BONE x the
    limb's mean bone (`_overlong`).

    Why the longest bone: the bends draw the joints, so a straight span of a limb that bends
    elsewhere got none, however long: Q_Zombie's 22-bone leg crossed its straight knee with
    one bone of 12% of its height. Over the 14 rigged characters the bound brings the mean
    CD-J2J from 3.62 to 3.58 (Q_Zombie 3.19 to 2.97, Q_Spider 4.07 to 3.81; Mannequiny 1.63
    to 1.74, 1.67 once `unfolded` dropped its elbows' fold-backs), CD-B2B 2.674 to 2.667,
    CD-J2B unchanged; 2 and 4 mean bones gave 3.62 and 3.60.
    """
    count = len(points)
    segments = count - 1
    if count <= 2 or bones >= segments:
        return list(range(count))
    scale = max(float(np.mean(radii)), 1e-12) ** 2
    points = np.asarray(points, dtype=float)
    cost = _fit_costs(points) / scale + _overlong(points, bones)
    gain = np.zeros(count)
    gain[1:-1] = NARROWING * _narrowing(np.asarray(radii, dtype=float))[1:-1]
    prior = np.zeros((bones + 1, count))
    if fractions is not None:
        at = symmetry.arc_fractions(np.asarray(points, dtype=float))
        prior[1:bones] = PRIOR * (at[None, :] - np.asarray(fractions, dtype=float)[:, None]) ** 2
    best = np.full(count, np.inf)
    best[0] = 0.0
    choice = np.zeros((bones + 1, count), dtype=np.int64)
    for k in range(1, bones + 1):  # best[b]: least cost of k bones from point 0 to point b
        total = best[:, None] + cost - gain[None, :] + prior[k][None, :]
        choice[k] = np.argmin(total, axis=0)
        best = total[choice[k], np.arange(count)]
    keep = [segments]
    for k in range(bones, 0, -1):
        keep.append(int(choice[k, keep[-1]]))
    return keep[::-1]


def _fit_costs(points):
    """#P by #P: cost[a, b] (a < b) the sum of the squared distances of points a+1..b-1 to the
    line through points a and b (inf where a >= b), from prefix sums: O(P^2) memory."""
    count = len(points)
    first = np.concatenate([np.zeros((1, 3)), np.cumsum(points, axis=0)])
    second = np.concatenate([np.zeros((1, 3, 3)),
                             np.cumsum(points[:, :, None] * points[:, None, :], axis=0)])
    a, b = np.triu_indices(count, 1)
    n = (b - a - 1).astype(float)[:, None]                   # inner points a+1..b-1
    s1 = first[b] - first[a + 1]
    s2 = second[b] - second[a + 1]
    pa = points[a]
    centred = s2 - pa[:, :, None] * s1[:, None, :] - s1[:, :, None] * pa[:, None, :] \
        + n[:, :, None] * pa[:, :, None] * pa[:, None, :]  # sum of (p - pa)(p - pa)^T
    axis = points[b] - pa
    axis /= np.maximum(np.linalg.norm(axis, axis=1, keepdims=True), 1e-300)
    along = np.einsum("si,sij,sj->s", axis, centred, axis)
    cost = np.full((count, count), np.inf)
    cost[a, b] = np.maximum(np.trace(centred, axis1=1, axis2=2) - along, 0.0)
    return cost


def _overlong(points, bones):
    """#P by #P: OVERLONG where a bone from point a to point b over two or more segments of the
    limb's polyline (points #P by 3) spans more arc length than LONGEST_BONE x its mean bone
    (arc length / bones), else 0."""
    arc = symmetry.arc_lengths(points)
    index = np.arange(len(points))
    span = arc[None, :] - arc[:, None]
    too_long = (span > LONGEST_BONE * arc[-1] / bones) & (index[None, :] - index[:, None] > 1)
    return np.where(too_long, OVERLONG, 0.0)


def _narrowing(radii):
    """#P: 1 - r / (the smaller of the largest radii before and after), 0 where not thinner."""
    before = np.maximum.accumulate(radii)
    after = np.maximum.accumulate(radii[::-1])[::-1]
    wide = np.minimum(before, after)
    return np.clip(1.0 - np.divide(radii, wide, out=np.ones_like(radii), where=wide > 0), 0, 1)


def _traversal(skeleton):
    """Yield (link, from_node, to_node, is_tree_link) breadth-first from the root.

    Nodes the root cannot reach start their own traversal (largest radius first), so every
    link is visited exactly once whatever the graph looks like.
    """
    links = np.asarray(skeleton.links, dtype=np.int64).reshape(-1, 2)
    node_count = len(skeleton.positions)
    incident = [[] for _ in range(node_count)]
    for index, (a, b) in enumerate(links):
        incident[a].append(index)
        if b != a:
            incident[b].append(index)
    radii = np.asarray(skeleton.radii, dtype=float)
    starts = [int(skeleton.root)] if 0 <= skeleton.root < node_count else []
    starts += [int(i) for i in np.argsort(-radii, kind="stable")]
    visited = np.zeros(node_count, dtype=bool)
    used = np.zeros(len(links), dtype=bool)
    for start in starts:
        if visited[start]:
            continue
        visited[start] = True
        queue = deque([start])
        while queue:
            node = queue.popleft()
            for index in incident[node]:
                if used[index]:
                    continue
                used[index] = True
                a, b = links[index]
                other = int(b if a == node else a)
                tree = not visited[other]
                if tree:
                    visited[other] = True
                    queue.append(other)
                yield index, node, other, tree


def _degrees(skeleton):
    """The number of links at each node (#N int64; a loop link counts twice)."""
    links = np.asarray(skeleton.links, dtype=np.int64).reshape(-1, 2)
    return np.bincount(links.ravel(), minlength=len(skeleton.positions))


def limbs(skeleton):
    """Return the skeleton's limbs: lists of (link, from_node, to_node, is_tree_link), each a
    chain of links in traversal order (see _traversal) that passes through nodes of degree 2
    (not the root) and stops at a branching node, an end or a link that closes a cycle."""
    degree = _degrees(skeleton)
    result, open_at = [], {}  # open_at: node -> the limb a tree link brought there
    for step in _traversal(skeleton):
        link, start, stop, tree = step
        through = tree and degree[start] == 2 and start != skeleton.root
        limb = open_at.pop(start, None) if through else None
        if limb is None:
            limb = []
            result.append(limb)
        limb.append(step)
        if tree:
            open_at[stop] = limb
    return result


def limb_polyline(skeleton, limb):
    """Return (points #P by 3, nodes #P, segment_links #P-1, radii #P) of a limb: its links'
    polylines joined, from its first node, the skeleton's nodes where they fall (nodes[i] the
    node at point i, -1 between nodes), the link of each segment, and the skeleton radius at
    each point: the nodes' radii, and between them the distance to the surface the engine
    measured there (`polyline_radii`: where the limb narrows between nodes, a neck or a wrist),
    else (a skeleton without them) the nodes' radii linear in arc length. A limb that ends at
    an end node has its rounded tip run on along its line (`dcg.tips.straightened`)."""
    positions = np.asarray(skeleton.positions, dtype=float).reshape(-1, 3)
    measured = measured_polyline_radii(skeleton)
    points, nodes, segment_links, inner_radii = [positions[limb[0][1]]], [limb[0][1]], [], [np.nan]
    for link, start, stop, _ in limb:
        polyline = np.asarray(skeleton.polylines[link], dtype=float).reshape(-1, 3)
        radii = np.asarray(() if measured is None else measured[link], dtype=float)
        if len(radii) != len(polyline):  # none measured: the nodes' radii interpolate
            radii = np.full(len(polyline), np.nan)
        if int(skeleton.links[link][0]) != start:
            polyline, radii = polyline[::-1], radii[::-1]
        inner = list(polyline[1:-1])
        points += inner + [positions[stop]]
        nodes += [-1] * len(inner) + [stop]
        segment_links += [link] * (len(inner) + 1)
        inner_radii += list(radii[1:-1]) + [np.nan]  # a node keeps its own radius
    points, nodes = np.array(points), np.array(nodes)
    keep = unfolded(points, nodes)
    points, nodes, inner_radii = points[keep], nodes[keep], np.array(inner_radii)[keep]
    segment_links = np.array(segment_links, dtype=np.int64)[keep[1:] - 1]
    arc = symmetry.arc_lengths(points)
    at = np.flatnonzero(nodes >= 0)
    radii = np.interp(arc, arc[at], np.asarray(skeleton.radii, dtype=float)[nodes[at]])
    known = np.isfinite(inner_radii) & (inner_radii > 0)
    radii[known] = inner_radii[known]
    if str(skeleton.kinds[nodes[-1]]) == "end":
        points = tips.straightened(points, radii)
    return points, nodes, segment_links, radii


def unfolded(points, nodes):
    """The indices of the points of a polyline (#P by 3; nodes #P, -1 between nodes) kept once
    its fold-backs are gone: an inner point where the polyline turns back on itself (by more
    than FOLD_BACK degrees from the kept point before it to the next) is dropped, and so on
    back while the points before turn back too; the ends and the nodes are always kept.

    Why: a link the engine routed around a wall inside the shape can go out and back (each
    elbow of Mannequiny, whose segmented arm is 59 parts in one: 0.40 -> 0.50 -> 0.42 along
    the arm, and two legs of Q_Spider), and a joint on such a point gave bones that point back
    along the limb (12 of the 23 such bone pairs of the meshes `make bench` rigs; the others
    turn back at a node, where two links of the graph run side by side)."""
    limit = np.cos(np.radians(FOLD_BACK))
    keep = [0]
    for index in range(1, len(points)):
        while len(keep) >= 2 and nodes[keep[-1]] < 0:
            before = points[keep[-1]] - points[keep[-2]]
            after = points[index] - points[keep[-1]]
            scale = float(np.linalg.norm(before) * np.linalg.norm(after))
            if not (scale > 0 and before @ after < limit * scale):
                break
            keep.pop()
        keep.append(index)
    return np.array(keep, dtype=np.int64)


def plan_bones(skeleton, bone_detail=BONE_DETAIL, names=BONE_NAMES, limb_fractions=None,
               root_bone=ROOT_BONE, up=None, origin=ORIGIN):
    """Return the list of BoneSpec for `skeleton`, parents before children.

    `skeleton` needs positions (#N by 3), kinds (#N), radii (#N), links (#L by 2),
    polylines (#L arrays, from links[l, 0] to links[l, 1]) and root. One chain of bones per
    limb (see `limbs`), `bone_count` bones (set by `bone_detail`) with their joints at the
    limb's articulations (`articulations`); with a mirror plane the plan mirrors itself
    (`symmetrize`). Each bone's roll comes from its chain (`dcg.rolls`). Segments shorter
    than 1e-6 of the skeleton's size are merged away (Blender deletes zero-length bones).

    names: "dcg" (the limb's name and a counter, ``arm.002.L``: `dcg.naming`) or "mixamo"
    (`dcg.humanoid`: a humanoid skeleton's bones named and counted after Mixamo's rig,
    ``LeftForeArm``; any other skeleton keeps the "dcg" names). limb_fractions: {node: the
    fractions of arc length the inner joints of the limb that ends at that node are drawn to
    (see `articulations`)}: that limb gets one bone more than fractions (fewer if it has fewer
    polyline segments, then no fractions) instead of `bone_detail`'s count (what the "mixamo"
    plan asks for). up: the model's up direction when the caller knows it (the add-on:
    Blender's world +Z; `dcg batch`: its format's): the root bone's floor lies across it, and
    the names take it where the shape's own up points against it (`dcg.naming.scene_up`: a
    flying wasp's raised wings looked like feet); None (a file of unknown up): UP for the
    floor and the shape's own up for the names (`dcg.naming.up_axis`). root_bone: start the
    plan with a root bone on the floor across up, under `origin` (the model's own origin,
    ORIGIN by default: its file's) when that is over the body, else (or with None) under the
    middle of the body (`add_root`).
    """
    check_bone_names(names)
    names_up, up = up, (UP if up is None else up)
    plan = plane = None
    if names == "mixamo":
        from . import humanoid  # it plans with this function

        plan = humanoid.mixamo_plan(skeleton)
    if plan is None:
        plan, plane = _limb_plan(skeleton, bone_detail, limb_fractions, up, names_up)
    elif root_bone:
        plane = humanoid.plan_plane(skeleton)  # what the Mixamo plan's pairs mirror across
    return add_root(plan, skeleton, plane, up, origin) if root_bone else plan


def _limb_plan(skeleton, bone_detail, limb_fractions, up=UP, names_up=None):
    """(plan_bones' chains of bones, one per limb, without a root bone ("dcg" names, after
    `names_up`: see plan_bones), the plane they mirror across: plan_plane's across `up`)."""
    positions = np.asarray(skeleton.positions, dtype=float).reshape(-1, 3)
    extent = np.ptp(positions, axis=0) if len(positions) else np.zeros(3)
    min_length = 1e-6 * max(float(np.linalg.norm(extent)), 1e-12)
    skeleton, chains, polylines, plane, sides = _planned_limbs(skeleton, up)
    if plane is not None:
        polylines = _middle_ends(plane, skeleton, chains, sides, polylines)
    segments = [len(polyline[0]) - 1 for polyline in polylines]
    asked = [(limb_fractions or {}).get(limb[-1][2]) for limb in chains]
    wanted = _paired_counts([
        bone_count(len(limb), count, bone_detail) if ask is None else min(len(ask) + 1, count)
        for limb, count, ask in zip(chains, segments, asked)], segments, sides)
    fractions = [ask if ask is not None and len(ask) + 1 == count else None
                 for ask, count in zip(asked, wanted)]
    joints = limb_joints(plane, polylines, sides, wanted, min_length, fractions)
    hosts = {}
    if plane is not None:
        symmetrize(plane, skeleton, chains, sides, joints, polylines)
        if limb_fractions is None:  # a Mixamo plan hangs its arms from its own chest
            hosts = hang_from_middle(chains, sides, joints)
    frame = _references(plane, positions, sides, joints)
    return _chain_bones(skeleton, chains, sides, plane, joints, frame, names_up, hosts), plane


def hang_from_middle(chains, sides, joints):
    """{limb: (host limb, joint index)}: the paired limbs that hang from a joint of a limb of
    the middle rather than from the branching node they start at; their joints (LimbJoints per
    limb) change in place: the ones before the pair's first node go (the first joint index at
    which either limb has a node, so that the two still pair joint by joint), and the first
    joint is the host's.

    A pair hangs when a limb of the middle that starts at the same node has a joint on its
    first link (after the node itself) nearer to each limb's joint at that index than
    HANG_NEARER x that joint's distance from the start; the host is the one such joint of
    least ratio (the larger of the two limbs'), so the pair still mirrors.

    Why: the engine joins every part that meets a wide body at one node, so Q_Knight's arms,
    legs and head all left one node in its belly, and the arms ran up through the chest to
    the shoulders (bones inside the chest that moved it with the arm). Now they hang from
    the head chain's joint level with the shoulders, by a bone across to them where an
    animator puts a clavicle. Only the middle's first link counts (the body's centre line
    next to the node), so cow.off's hind legs do not hang from its tail. Over the rigged
    characters: CD-J2J / J2B / B2B Q_Knight 2.966 / 2.313 / 2.030 -> 3.060 / 2.305 / 2.011
    (its artist's clavicles start lower, at the top of the spine), CesiumMan 2.694 / 1.614 /
    1.498 -> 2.713 / 1.555 / 1.441, no other.
    """
    hosts = {}
    for i, j in symmetry.partners(sides).items():
        cut = min(_first_node(joints[i]), _first_node(joints[j]))  # pairs' joints pair by index
        found = _host(chains, sides, joints, (i, j), cut)
        if found is None:
            continue
        for k in (i, j):
            _hang(joints[k], joints[found[0]], found[1], cut)
            hosts[k] = found
    return hosts


def _first_node(limb_points):
    """Index of a limb's first joint after its start that is a skeleton node."""
    return next(i for i in range(1, len(limb_points.nodes)) if limb_points.nodes[i] >= 0)


def _host(chains, sides, joints, pair, cut):
    """(host limb, joint index) the two limbs of `pair` would hang from by their joints `cut`
    (see hang_from_middle), or None."""
    start = chains[pair[0]][0][1]
    if any(chains[k][0][1] != start for k in pair):
        return None
    firsts = [joints[k].points[cut] for k in pair]
    reaches = [HANG_NEARER * np.linalg.norm(point - joints[k].points[0])
               for k, point in zip(pair, firsts)]
    best = None
    for m, (limb, (side, _)) in enumerate(zip(chains, sides)):
        if side is not None or limb[0][1] != start:
            continue
        for at in range(1, _first_node(joints[m]) + 1):
            worst = max(np.linalg.norm(joints[m].points[at] - point) / max(reach, 1e-300)
                        for point, reach in zip(firsts, reaches))
            if 1e-6 < worst < 1.0 and (best is None or worst < best[0]):  # no 0-length bone
                best = (worst, m, at)
    return None if best is None else best[1:]


def _hang(limb_points, host_points, at, cut):
    """Limb joints from the host's joint `at` straight to the limb's joint `cut`, in place."""
    keep = np.concatenate([[0], np.arange(cut, len(limb_points.nodes))])
    links = np.asarray(limb_points.links)[keep[1:] - 1]
    for field in ("original", "target", "radii", "own_radii", "nodes", "points"):
        setattr(limb_points, field, np.array(getattr(limb_points, field)[keep]))
    limb_points.links = links
    for field in ("original", "target", "points"):
        getattr(limb_points, field)[0] = host_points.points[at]
    limb_points.radii[0] = limb_points.own_radii[0] = host_points.radii[at]


def add_root(plan, skeleton, plane=None, up=UP, origin=None):
    """`plan` (BoneSpecs, parents first) headed by a root bone (kind "root", named ROOT_NAME,
    no vertex weights) that every bone without a parent gets as its parent (not connected).
    Its head lies on the floor across `up` (the lowest point of the skeleton's balls, each
    node's position less its radius) under `origin`, the model's own origin, when that is over
    the balls' footprint (`_root_foot`), else under the centre of their bounding box, where a
    standing character's origin is (moved onto `plane`, the plan's mirror plane, when there
    is one, so that it stays its own mirror image for X-Axis Mirror and Paste Pose Flipped:
    along the floor onto a plane within UPRIGHT_PLANE degrees of upright; along a level
    plane's normal, off the floor, only when some bones are sided (a model lying on its side),
    since only the mirror tools need it there: a cylinder mirrored across its middle keeps its
    root on the floor). Its tail stands straight up
    from it, as high as the first bone's head (the skeleton's root, the pelvis of a humanoid;
    a snake's is its head), so that turning the root about its own axis turns the body about
    the vertical; up the plane's steepest line when it is on a plane a little off upright (it
    stays its own mirror image); on a level plane with sided bones (a model lying on its side)
    the tail is the skeleton's root itself, which is on the plane."""
    if not plan:
        return plan
    up = np.asarray(up, dtype=float).reshape(3)
    up = up / max(float(np.linalg.norm(up)), 1e-300)
    positions = np.asarray(skeleton.positions, dtype=float).reshape(-1, 3)
    radii = np.asarray(skeleton.radii, dtype=float).reshape(-1)
    low, high = balls_box(positions, radii)
    over = _root_foot(positions, radii, up, origin)
    head = over - (over @ up - float(np.min(positions @ up - radii))) * up
    level = plane is not None and lies_level(plane, up)
    middle = plane is not None and (has_sided_bones(plan) or not level)  # on the plane
    if middle:  # a level plane: along its normal (off the floor), else along the floor
        head = plane.project(head) if level else _onto_plane_along_floor(plane, head, up)
    top = np.array(plan[0].head, dtype=float)
    if middle and level:  # lying on its side: toward the skeleton's root, on the plane too
        tail = top
    else:  # as steep as the plane it stays on lets it: straight up when that stands upright
        rise = up - float(up @ plane.normal) * plane.normal if middle else up
        rise = rise / max(float(np.linalg.norm(rise)), 1e-300)
        tail = head + rise * float((top - head) @ up) / float(rise @ up)
    if np.linalg.norm(tail - head) <= 1e-6 * max(float(np.linalg.norm(high - low)), 1e-300):
        tail = head + up * max(float(radii.max()), 1e-6 * float(np.linalg.norm(high - low)))
    side, frame_up = rolls.skeleton_frame(positions, plane)
    ends = np.array([head, tail])
    z_axis = rolls.z_axes(ends[:1], ends[1:], rolls.chain_reference(ends, side, frame_up),
                          side, frame_up)[0]
    root = BoneSpec(ROOT_NAME, head, tail, None, False, "root", -1, -1, 0.0, 0.0, z_axis,
                    rolls.blender_roll(head, tail, z_axis))
    children = [replace(spec, parent=ROOT_NAME) if spec.parent is None else spec
                for spec in plan]
    return [root] + children


def balls_box(positions, radii):
    """(low, high): the bounding box of the skeleton's balls (positions #N by 3, radii #N),
    about the mesh's."""
    return (positions - radii[:, None]).min(axis=0), (positions + radii[:, None]).max(axis=0)


def _root_foot(positions, radii, up, origin):
    """The point the root bone stands under: `origin` (a 3-vector, or None) when it lies over
    the footprint of the balls (positions #N by 3, radii #N) across unit `up` (within their
    extent along both directions of the floor), else the centre of their bounding box.

    Why the origin: an artist puts a character's origin on the floor under it, where game
    engines move it from (the rigged characters' root joints), and in Blender it is the
    object's origin the user sees and moves; 13 of the 14 rigged characters' origins lie
    over their footprint. It brings the mean CD-J2J / J2B / B2B from 3.70 / 2.40 / 2.73 to
    3.63 / 2.31 / 2.67 (Q_Wasp's origin lies 14% of its size from its bounding box's centre,
    Fox's and Q_Horse's 6%). An origin off the footprint (a model far from its file's origin)
    says nothing of where the body stands."""
    low, high = balls_box(positions, radii)
    centre = (low + high) / 2.0
    if origin is None:
        return centre
    origin = np.asarray(origin, dtype=float).reshape(3)
    floor = np.linalg.svd(up.reshape(1, 3))[2][1:]  # two unit directions across up
    along = positions @ floor.T
    over = floor @ origin
    inside = (over >= (along - radii[:, None]).min(axis=0)) & \
        (over <= (along + radii[:, None]).max(axis=0))
    return origin if bool(inside.all()) else centre


def has_sided_bones(plan):
    """Whether some bones of `plan` are named .L / .R (the ones the mirror tools pair)."""
    return any(spec.name.endswith((".L", ".R")) for spec in plan)


def _onto_plane_along_floor(plane, point, up):
    """`point` (on the floor) moved onto `plane` (one that does not lie level) along the floor
    (across `up`), so that it stays on the floor too."""
    across = _normal_along_floor(plane, up)
    across /= np.linalg.norm(across)
    return point - float(plane.signed(point)) / float(plane.normal @ across) * across


def lies_level(plane, up=UP):
    """Whether a mirror plane is turned more than UPRIGHT_PLANE degrees from upright across
    `up`: a model lying on its side, whose `.L` / `.R` bones are then upper and lower ones
    and whose root bone leaves the floor for the plane (`add_root`); the add-on says so. (A
    model standing as tall as it is wide that mirrors top to bottom, a cylinder, pairs nothing
    across it: `mirrors_top_to_bottom`.)"""
    if plane is None:
        return False
    along_floor = float(np.linalg.norm(_normal_along_floor(plane, up)))
    return along_floor < np.cos(np.radians(UPRIGHT_PLANE))


def _normal_along_floor(plane, up):
    """The part of the plane's (unit) normal across `up`: its length is the cosine of the
    plane's angle from upright."""
    up = np.asarray(up, dtype=float).reshape(3)
    up = up / max(float(np.linalg.norm(up)), 1e-300)
    normal = np.asarray(plane.normal, dtype=float)
    return normal - (normal @ up) * up


def deforms(kinds) -> np.ndarray:
    """#B booleans: which bones of these kinds (a plan's, bone_arrays' "kinds") weight
    vertices; the root bone does not."""
    return np.asarray(kinds, dtype=str) != "root"


def check_bone_names(names):
    """ValueError unless `names` is one of BONE_NAME_CONVENTIONS."""
    if names not in BONE_NAME_CONVENTIONS:
        raise ValueError(f"bone_names (the naming convention) must be one of "
                         f"{', '.join(BONE_NAME_CONVENTIONS)}, got {names!r}")


def plan_plane(skeleton, up=UP):
    """The plane (a symmetry.Plane) that plan_bones mirrors the bones of `skeleton` across
    (with the same `up`), or None when it has no mirror plane: the shape's own
    (symmetry.shape_plane) when the surface mirrors itself across a plane that agrees with the
    skeleton's (within FITTED_AGREEMENT), else the skeleton's (symmetry.skeleton_plane) fitted
    to the limbs that pair across it (`symmetry.fitted_plane`); None for a level plane of a
    model that stands at least as tall as it is wide (`mirrors_top_to_bottom`)."""
    return _plan_symmetry(skeleton, up)[1]


def _plan_symmetry(skeleton, up=UP):
    """(chains, plane, sides) of `skeleton`: its limbs and `_symmetry` of them."""
    _, chains, _, plane, sides = _planned_limbs(skeleton, up)
    return chains, plane, sides


def _planned_limbs(skeleton, up=UP):
    """(the skeleton as planned, its limbs, their polylines (`limb_polyline`), plane, sides):
    `skeleton` and `_symmetry` of its limbs, unless a junction of two limbs of mirror-image
    ends lies off the plane (`dcg.junctions.onto_plane`: Q_Frog's hind legs): then a view of
    it with that junction on the plane, and the symmetry of that."""
    chains = limbs(skeleton)
    polylines = [limb_polyline(skeleton, limb) for limb in chains]
    plane, sides = _symmetry(skeleton, chains, polylines, up)
    if plane is not None:
        moved = junctions.onto_plane(skeleton, plane, chains, sides)
        if moved is not skeleton:
            skeleton = moved
            polylines = [limb_polyline(skeleton, limb) for limb in chains]
            plane, sides = _symmetry(skeleton, chains, polylines, up)
    return skeleton, chains, polylines, plane, sides


def mirrors_top_to_bottom(plane, skeleton, up=UP):
    """Whether `plane` lies level across `up` (`lies_level`) while the skeleton's balls
    stand at least as tall along `up` as they reach across it: an upright cylinder or
    hourglass mirrored across its middle, not a model lying on its side (which is longer than
    it is tall). Its upper and lower halves are no left and right: the planner pairs nothing
    across such a plane, so that no bone gets a side that Blender's X-mirror tools would
    misread, and the root bone stays on the floor."""
    if not lies_level(plane, up):
        return False
    up = np.asarray(up, dtype=float).reshape(3)
    up = up / max(float(np.linalg.norm(up)), 1e-300)
    positions = np.asarray(skeleton.positions, dtype=float).reshape(-1, 3)
    radii = np.asarray(skeleton.radii, dtype=float).reshape(-1)
    gaps = positions[:, None] - positions[None]  # the nodes are tens to hundreds
    along = gaps @ up
    across = np.linalg.norm(gaps - along[..., None] * up, axis=2)
    reach = radii[:, None] + radii[None]  # each pair's balls' farthest points apart
    return float((np.abs(along) + reach).max()) >= float((across + reach).max())


def _symmetry(skeleton, chains, polylines, up=UP):
    """(plane, sides): the plan's mirror plane (see plan_plane) and the (side, pair) of each
    limb (symmetry.pair_limbs across the skeleton's plane; limbs pair when they end at nodes
    of one kind; where the plane is the surface's own, also limbs that pair across that one,
    symmetry.more_pairs; on a surface that mirrors itself within COPY_TOLERANCE also limbs
    whose ends and starts mirror each other, symmetry.pair_by_ends); no plane and no pairs
    across a plane that `mirrors_top_to_bottom`."""
    plane = symmetry.skeleton_plane(skeleton)
    ends = [limb[-1][2] for limb in chains]
    sides = symmetry.pair_limbs(plane, skeleton, [polyline[0] for polyline in polylines], ends)
    if plane is not None:
        shape = symmetry.shape_plane(skeleton)
        agreement = 0.0 if shape is None else float(shape.normal @ plane.normal)
        if abs(agreement) >= symmetry.FITTED_AGREEMENT:  # the surface's own: exact
            plane = shape if agreement > 0 else symmetry.Plane(-shape.normal, -shape.offset,
                                                               shape.error)
            sides = symmetry.more_pairs(sides, symmetry.pair_limbs(
                plane, skeleton, [polyline[0] for polyline in polylines], ends))
            if symmetry.copy_plane(skeleton) is not None:
                sides = symmetry.pair_by_ends(plane, skeleton, [limb[0][1] for limb in chains],
                                              ends, _degrees(skeleton)[ends] == 1, sides)
        else:
            plane = _fitted_plane(plane, polylines, sides)
    if plane is not None and mirrors_top_to_bottom(plane, skeleton, up):
        return None, symmetry.pair_limbs(None, skeleton, [polyline[0] for polyline in polylines])
    return plane, sides


def unpaired_limbs(skeleton, up=UP):
    """The number of limbs of a shape that mirrors itself (symmetry.shape_plane) that end at an
    end node off the plane whose mirror image is the end of another such limb, yet did not
    pair: their skeletons differ more than pairing tolerates (a leg hanging from the hips on one
    side and from the chest on the other), so they keep plain names and no mirror image. 0
    without such a plane, or when the plan mirrors nothing (`plan_plane` across `up`). What
    the add-on warns of."""
    if symmetry.shape_plane(skeleton) is None:
        return 0
    chains, plane, sides = _plan_symmetry(skeleton, up)
    if plane is None:
        return 0
    positions = np.asarray(skeleton.positions, dtype=float).reshape(-1, 3)
    degree = _degrees(skeleton)
    near = symmetry.tolerance(positions)
    ends = np.array([limb[-1][2] for limb, (side, _) in zip(chains, sides)
                     if side is None and degree[limb[-1][2]] == 1
                     and abs(plane.signed(positions[limb[-1][2]])) > near], dtype=np.int64)
    if len(ends) < 2:
        return 0
    images = plane.reflect(positions[ends])
    gaps = np.linalg.norm(images[:, None] - positions[ends][None], axis=2)
    np.fill_diagonal(gaps, np.inf)
    return int((gaps.min(axis=1) <= near).sum())


def _middle_ends(plane, skeleton, chains, sides, polylines):
    """`polylines` (limb_polyline's per limb), those of the middle's limbs that end on one of
    two mirror-image features cut where they leave the plane (`_cut_at_plane`): spot's head ends
    on one of its horns, whose mirror image is no end of the skeleton. Only on a surface that
    mirrors itself within symmetry.COPY_TOLERANCE (elsewhere an end off the plane is the shape's
    own), and not a limb whose end's mirror image is an end too (a leg that did not pair)."""
    if symmetry.copy_plane(skeleton) is None:
        return polylines
    positions = np.asarray(skeleton.positions, dtype=float).reshape(-1, 3)
    degree = _degrees(skeleton)
    ends = np.flatnonzero(degree == 1)
    near = symmetry.tolerance(positions)
    result = list(polylines)
    for k, (limb, (side, _)) in enumerate(zip(chains, sides)):
        end = limb[-1][2]
        if side is not None or degree[end] != 1:
            continue
        others = positions[ends[ends != end]]
        image = plane.reflect(positions[end])
        if len(others) and np.linalg.norm(others - image, axis=1).min() <= near:
            continue
        result[k] = _cut_at_plane(plane, polylines[k])
    return result


def _cut_at_plane(plane, polyline):
    """A limb's polyline (limb_polyline's) that ends off the plane, farther than MIRROR_REACH
    radii (at the last point near the plane) and only for its last TWIN_TIP such radii of arc
    length, cut at its last point within MIRROR_REACH radii of the plane, that point moved onto
    the plane and given the end node; any other polyline as it is."""
    points, nodes, segment_links, radii = polyline
    close = np.abs(plane.signed(points[:-1])) <= symmetry.MIRROR_REACH * radii[:-1]
    last = int(np.flatnonzero(close)[-1]) if close.any() else 0
    if last == 0 or abs(plane.signed(points[-1])) <= symmetry.MIRROR_REACH * radii[last]:
        return polyline
    if np.linalg.norm(np.diff(points[last:], axis=0), axis=1).sum() > TWIN_TIP * radii[last]:
        return polyline
    points = np.vstack([points[:last], plane.project(points[last])])
    return points, np.append(nodes[:last], nodes[-1]), segment_links[:last], radii[:last + 1]


def _fitted_plane(plane, polylines, sides):
    """symmetry.fitted_plane of the paired limbs and the middle's polyline points."""
    limb_pairs = [(polylines[i][0], polylines[j][0]) for i, j in symmetry.partners(sides).items()]
    middle = [polylines[i][0] for i, (side, _) in enumerate(sides) if side is None]
    return symmetry.fitted_plane(plane, limb_pairs, np.concatenate([np.zeros((0, 3))] + middle))


def limb_joints(plane, polylines, sides, counts, min_length, fractions=None):
    """Return a LimbJoints per limb (polylines: limb_polyline's per limb; sides: (side, pair)
    per limb; counts: bones per limb). A limb of the middle or of a shape without a mirror
    plane gets its own articulations; the two limbs of a pair the articulations of their mean
    (`symmetry.mean_polyline`): the .L limb's joints there and the .R limb's their mirror
    images, both as targets for `symmetrize`, the joints' own places as originals."""
    joints = [None] * len(polylines)
    fractions = fractions or [None] * len(polylines)
    for i, j in symmetry.partners(sides).items():
        joints[i], joints[j] = _paired_joints(plane, polylines[i], polylines[j], counts[i],
                                              min_length, fractions[i])
    for i, (points, nodes, segment_links, radii) in enumerate(polylines):
        if joints[i] is None:
            keep = np.array(_drop_short(
                points, articulations(points, radii, counts[i], fractions[i]), min_length))
            joints[i] = LimbJoints(points[keep], points[keep], radii[keep], radii[keep],
                                   nodes[keep], segment_links[keep[1:] - 1])
    return joints


def _paired_joints(plane, left, right, count, min_length, fractions=None):
    """(LimbJoints of the .L limb, of the .R limb) of a pair (see limb_joints). The joints are
    the articulations of the pair's mean at equal fractions of arc length (both limbs' shapes
    count alike there); their targets are the midpoints of each .L joint and the mirror image
    of the .R limb's point nearest to its own (so that a joint moves across its limb, not
    along it), and the mirror images of those."""
    points_l, nodes_l, links_l, radii_l = left
    points_r, nodes_r, links_r, radii_r = right
    ends = (points_l, radii_l), (points_r, radii_r)
    shape, shape_radii = symmetry.mean_polyline(plane, *ends, symmetry.arc_fractions(points_l))
    keep = np.array(_drop_short(shape, articulations(shape, shape_radii, count, fractions),
                                min_length))
    where = symmetry.nearest_fractions(plane, points_l, points_r)
    mean, radii = symmetry.mean_polyline(plane, *ends, where)
    at_r, where = symmetry.arc_fractions(points_r), where[keep]
    first = LimbJoints(points_l[keep], mean[keep], radii[keep], radii_l[keep], nodes_l[keep],
                       links_l[keep[1:] - 1])
    second = LimbJoints(symmetry.resample(points_r, at_r, where), plane.reflect(mean[keep]),
                        radii[keep], symmetry.resample(radii_r, at_r, where),
                        _nodes_at(where, at_r, nodes_r), _links_at(where[1:], at_r, links_r))
    return first, second


def _nodes_at(where, at, nodes):
    """The node at each fraction of arc length `where` (0 first, 1 last) of a limb whose
    points lie at the fractions `at` with `nodes` (-1 between nodes): its end nodes at the
    ends; between them the nearest inner point's node when it lies within a quarter of the
    points' mean spacing, else -1."""
    where = np.asarray(where, dtype=float)
    result = np.full(len(where), -1, dtype=np.int64)
    inner = at[1:-1]
    if len(inner) and len(where) > 2:
        nearest = np.abs(inner[None, :] - where[1:-1, None]).argmin(axis=1)
        close = np.abs(inner[nearest] - where[1:-1]) <= 0.25 / max(len(at) - 1, 1)
        result[1:-1] = np.where(close, nodes[1:-1][nearest], -1)
    result[0], result[-1] = nodes[0], nodes[-1]
    return result


def _links_at(where, at, segment_links):
    """The link of the segment that ends at or just after each fraction `where` (> 0)."""
    segment = np.clip(np.searchsorted(at, where, side="left") - 1, 0, len(segment_links) - 1)
    return np.asarray(segment_links)[segment]


def symmetrize(plane, skeleton, chains, sides, joints, polylines):
    """Move the joints (LimbJoints per limb, in place: `points`; polylines: limb_polyline's per
    limb) so that the plan mirrors itself across `plane`: the nodes two paired limbs start or
    end at and a pair's other joints to where they mirror exactly when they stay inside the
    shape there (`_paired_points`, `_symmetric_nodes`), those of the middle (other limbs' first
    and branching nodes, the root) and the middle's joints onto the plane. A joint that cannot
    mirror exactly moves at most MIRROR_REACH radii (its own limb's radius there; an end's tip:
    the radius at its bone's head, by which END_INSET keeps the tail inside) toward where it
    would; a joint of the middle that the plane is farther from stays. Each limb then starts
    (and, but at a tip, ends) where its nodes went."""
    degree = _degrees(skeleton)
    inside = _mirror_test(plane, skeleton)
    nodes = _symmetric_nodes(plane, skeleton, chains, sides, inside)
    for i, j in symmetry.partners(sides).items():
        tip = degree[chains[i][-1][2]] == 1
        joints[i].points, joints[j].points = _paired_points(
            plane, joints[i], joints[j], (polylines[i], polylines[j]), tip, inside)
    for k, (limb, limb_points) in enumerate(zip(chains, joints)):
        if sides[k][0] is None and _in_the_middle(plane, limb_points):
            limb_points.points = symmetry.onto_plane(plane, limb_points.original,
                                                     symmetry.MIRROR_REACH * _depths(limb_points))
        start, end = limb[0][1], limb[-1][2]
        limb_points.points[0] = nodes[start]
        if degree[end] != 1:
            limb_points.points[-1] = nodes[end]


def _in_the_middle(plane, limb_points):
    """Whether an unpaired limb lies in the middle, its joints then drawn onto the plane: its
    end within MIRROR_REACH of its depth of it; or, for a limb that runs along the plane (no
    joint farther from it than ALONG_PLANE x the limb's length) and ends in a thin tip just off
    it, within MIRROR_REACH of its deepest joint's depth (Q_Snake's head, whose tongue's tip is
    0.054 off the plane and 0.003 deep: 6 of its joints were off the plane, 2 of them now on it;
    CD-J2J 4.86 -> 4.76, and no other limb of the public or rigged meshes changes). One whose
    end leaves the plane crosses it (a cylinder's two halves, their ends on opposite rims) or is
    off to one side, and keeps its joints where they are."""
    points = np.asarray(limb_points.original, dtype=float)
    offsets, depths = np.abs(plane.signed(points)), _depths(limb_points)
    if offsets[-1] <= symmetry.MIRROR_REACH * depths[-1]:
        return True
    along = float(offsets.max()) <= ALONG_PLANE * float(symmetry.arc_lengths(points)[-1])
    return along and offsets[-1] <= symmetry.MIRROR_REACH * float(depths.max())


def _depths(limb_points):
    """#J how deep each joint of a limb lies (its own radius; an end's tip: the radius at its
    bone's head, see symmetrize)."""
    depths = np.array(limb_points.own_radii, dtype=float)
    if len(depths) > 1:
        depths[-1] = depths[-2]
    return depths


def _mirror_test(plane, skeleton):
    """inside(points, depths): whether the mirror images of points that deep inside the shape
    lie inside it too (symmetry.copies_inside with the shape's own plane; all False when the
    surface does not mirror itself). The shape's diagonal: its nodes' plus twice the largest
    radius."""
    positions = np.asarray(skeleton.positions, dtype=float).reshape(-1, 3)
    radii = np.asarray(skeleton.radii, dtype=float)
    diagonal = float(np.linalg.norm(np.ptp(positions, axis=0))) + 2.0 * float(radii.max())
    shape = symmetry.shape_plane(skeleton)

    def inside(points, depths):
        return symmetry.copies_inside(plane, shape, diagonal, points, depths)
    return inside


def _paired_points(plane, left, right, polylines, tip, inside):
    """(points of the .L limb, of the .R limb) for a pair's joints (LimbJoints left and right,
    polylines their limb_polyline's; tip: they end at end nodes), mirroring exactly where that
    keeps every joint inside: (1) the targets (limb_joints: on the pair's mean) when each lies in
    its own limb's tube of skeleton balls (symmetry.inside_tube; at a tip, the end bone's
    inset tail); else (2) the .L limb's own joints and their mirror images when the shape
    mirrors itself closely enough there (`inside`: a pair whose skeletons differ, one wing's
    branching where the other's does not); else (3) each joint moved toward its target by at
    most MIRROR_REACH radii (symmetry.settle: the pair then mirrors approximately)."""
    fits = []
    for limb_points, (line, _, _, radii) in zip((left, right), polylines):
        target = np.asarray(limb_points.target, dtype=float)
        fit = symmetry.inside_tube(target, line, radii)
        if tip and len(target) > 1:
            tail = _tail(target[-2], target[-1], limb_points.radii[-2])
            fit[-1] = symmetry.inside_tube(tail, line, radii)[0]
        fits.append(fit.all())
    if all(fits):
        return np.array(left.target, dtype=float), np.array(right.target, dtype=float)
    own = np.array(left.original, dtype=float)
    if inside(own, _depths(left)).all():
        return own, plane.reflect(own)
    reach = symmetry.MIRROR_REACH
    return (symmetry.settle(left.original, left.target, reach * _depths(left)),
            symmetry.settle(right.original, right.target, reach * _depths(right)))


def _symmetric_nodes(plane, skeleton, chains, sides, inside):
    """{node: where it goes} for the nodes limbs start at or branch at (see symmetrize): two
    paired limbs' nodes as `_paired_nodes` places them, the others onto the plane where that
    moves them at most MIRROR_REACH radii."""
    positions = np.asarray(skeleton.positions, dtype=float).reshape(-1, 3)
    reach = symmetry.MIRROR_REACH * np.asarray(skeleton.radii, dtype=float)
    pairs = []
    for i, j in symmetry.partners(sides).items():
        pairs += [(chains[i][0][1], chains[j][0][1]), (chains[i][-1][2], chains[j][-1][2])]
    partner = symmetry.node_partners(pairs)
    result = {}
    for node, other in pairs:
        if node != other and partner.get(node) == other and node not in result:
            result[node], result[other] = _paired_nodes(
                plane, positions[node], positions[other], reach[node], reach[other], inside)
    ends = [node for limb in chains for node in (limb[0][1], limb[-1][2])]
    for node in ends:
        if node not in result:
            result[node] = symmetry.onto_plane(plane, positions[node], reach[node])
    return result


def _paired_nodes(plane, node, other, reach, other_reach, inside):
    """(where a .L limb's node goes, where its partner on the .R side goes): halfway to each
    other's mirror image when neither moves farther than its reach (MIRROR_REACH radii), else
    the .L node and its mirror image where `inside` allows (see _paired_points), else each that
    far on its way."""
    target = (node + plane.reflect(other)) / 2.0
    if (np.linalg.norm(target - node) <= reach
            and np.linalg.norm(plane.reflect(target) - other) <= other_reach):
        return target, plane.reflect(target)
    if inside(node, reach / symmetry.MIRROR_REACH)[0]:
        return np.array(node, dtype=float), plane.reflect(node)
    return (symmetry.settle(node, target, reach),
            symmetry.settle(other, plane.reflect(target), other_reach))


def _references(plane, positions, sides, joints):
    """Each limb's roll reference (dcg.rolls.chain_reference): a .R limb's the mirror image of
    its .L partner's, a limb of the middle's kept in the mirror plane."""
    side, up = rolls.skeleton_frame(positions, plane)
    references = [rolls.chain_reference(limb_points.points, side, up,
                                        plane if limb_side is None else None)
                  for limb_points, (limb_side, _) in zip(joints, sides)]
    for i, j in symmetry.partners(sides).items():
        references[j] = plane.reflect_direction(references[i])
    return references, side, up


def _chain_bones(skeleton, chains, sides, plane, joints, frame, names_up=None, hosts=None):
    """The BoneSpecs of the limbs' chains (joints: LimbJoints per limb, final), in limb order
    but parents first (`_parents_first`: a limb that hangs from another's joint, hosts:
    hang_from_middle's, may come before it): named after their chains (`dcg.naming` with
    `names_up`: a .R bone after its .L partner), parented, with END_INSET tails and each
    chain's rolls (frame: what _references returns)."""
    hosts = hosts or {}
    references, side_axis, up = frame
    kinds = [str(k) for k in skeleton.kinds]
    degree = _degrees(skeleton)
    bone_kinds = [[kinds[n] if n >= 0 else "connection" for n in limb_points.nodes[1:]]
                  for limb_points in joints]
    chain_names = naming.chain_names(skeleton, chains, sides, plane,
                                     [limb_points.points for limb_points in joints], degree,
                                     names_up)
    name_of = naming.namer()
    names = [[name_of(chain_names[k], side, pair, i) for i in range(len(limb_points.points) - 1)]
             for k, ((side, pair), limb_points) in enumerate(zip(sides, joints))]
    tail_bone = {}  # node -> name of the bone whose tail is that node
    bones = []
    for k, (limb, limb_points) in enumerate(zip(chains, joints)):
        heads, tails = _limb_segments(limb_points, kinds, degree)
        z_axes = rolls.z_axes(heads, tails, references[k], side_axis, up)
        parent, first_tree = tail_bone.get(limb[0][1]), limb[0][3]
        if k in hosts:
            parent, first_tree = names[hosts[k][0]][hosts[k][1] - 1], False
        for i, (head, tail, z_axis) in enumerate(zip(heads, tails, z_axes)):
            bones.append(BoneSpec(
                names[k][i], head, tail, parent, parent is not None and (i > 0 or first_tree),
                bone_kinds[k][i], int(limb_points.nodes[i + 1]), int(limb_points.links[i]),
                float(limb_points.radii[i]), float(limb_points.radii[i + 1]), z_axis,
                rolls.blender_roll(head, tail, z_axis)))
            parent = names[k][i]
        if limb[-1][3]:
            tail_bone[limb[-1][2]] = parent
    return _parents_first(bones)


def _parents_first(plan):
    """`plan` (BoneSpecs) with each bone that comes before its parent moved to just after it,
    its own children after it in turn; the others keep their order."""
    placed, waiting, ordered = set(), {}, []
    for spec in plan:
        if spec.parent is not None and spec.parent not in placed:
            waiting.setdefault(spec.parent, []).append(spec)
            continue
        stack = [spec]
        while stack:
            ready = stack.pop()
            ordered.append(ready)
            placed.add(ready.name)
            stack.extend(reversed(waiting.pop(ready.name, [])))
    return ordered + [spec for specs in waiting.values() for spec in specs]


def _limb_segments(limb_points, kinds, degree):
    """(heads, tails) #B by 3 of a limb's bones: from joint to joint, the last one's tail
    inset (`_tail`) when the limb ends at an end node of degree 1 (a prong's tip)."""
    points = np.asarray(limb_points.points, dtype=float)
    heads, tails = points[:-1].copy(), points[1:].copy()
    end = int(limb_points.nodes[-1])
    if end >= 0 and kinds[end] == "end" and degree[end] == 1:
        tails[-1] = _tail(points[-2], points[-1], limb_points.radii[-2])
    return heads, tails


def _paired_counts(counts, segments, sides):
    """`counts` with the two limbs of each pair given the same count (the larger, at most
    either's segments), so that their bones pair name by name."""
    counts = list(counts)
    by_pair = {}
    for i, (side, pair) in enumerate(sides):
        if side is not None:
            by_pair.setdefault(pair, []).append(i)
    for members in by_pair.values():
        shared = min(max(counts[i] for i in members), min(segments[i] for i in members))
        for i in members:
            counts[i] = shared
    return counts


def _drop_short(points, keep, min_length):
    """`keep` without the points closer than min_length to the previous kept one (the last
    point stays, replacing the one before it)."""
    result = [keep[0]]
    for i in keep[1:]:
        if np.linalg.norm(points[i] - points[result[-1]]) > min_length:
            result.append(i)
    if len(result) > 1 and result[-1] != keep[-1]:
        result[-1] = keep[-1]
    return result


def _tail(head, tip, radius):
    """The tail of an end bone from `head` to the end node at `tip`: moved back towards the
    head by END_INSET x the radius at the head (at most half the bone), so that the last
    joint sits inside the prong's rounded tip rather than on it."""
    tail = np.array(tip, dtype=float)
    direction = tail - head
    length = float(np.linalg.norm(direction))
    if END_INSET <= 0 or length == 0:
        return tail
    return tail - direction * min(END_INSET * float(radius) / length, 0.5)


def bone_arrays(plan):
    """The plan as arrays, in plan order: names (#B str), heads and tails (#B by 3 float64),
    parents (#B int64 index into the plan, -1 at a root), links (#B int64, the skeleton link of
    each bone, -1 for the root bone), kinds (#B str), z_axes (#B by 3 float64, each bone's
    unit local Z axis) and rolls (#B float64, Blender's roll in radians for that axis, in the
    skeleton's coordinates)."""
    index = {spec.name: i for i, spec in enumerate(plan)}
    return {
        "names": np.array([spec.name for spec in plan], dtype=str),
        "heads": np.array([spec.head for spec in plan], dtype=np.float64).reshape(-1, 3),
        "tails": np.array([spec.tail for spec in plan], dtype=np.float64).reshape(-1, 3),
        "parents": np.array([-1 if spec.parent is None else index[spec.parent]
                             for spec in plan], dtype=np.int64),
        "links": np.array([spec.link for spec in plan], dtype=np.int64),
        "kinds": np.array([spec.kind for spec in plan], dtype=str),
        "z_axes": np.array([spec.z_axis for spec in plan], dtype=np.float64).reshape(-1, 3),
        "rolls": np.array([spec.roll for spec in plan], dtype=np.float64),
    }
