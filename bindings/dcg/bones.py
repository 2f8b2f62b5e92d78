"""The bone plan of a DCG skeleton: the one planner behind the add-on's armature, the batch's
.weights.npz and `dcg.skin_weights(V, F, skeleton)` (no `bpy`: plain pytest tests it).

    plan = dcg.bones.plan_bones(skeleton, bone_detail=0.5)   # [BoneSpec], parents first
    arrays = dcg.bones.bone_arrays(plan)   # names, heads, tails, parents (-1), links, kinds

One chain of bones per limb: a chain of skeleton links through connection nodes (nodes
of degree 2), from a branching node or the root to the next branching node or an end, so a
leg is one limb from the hip joint to the foot. The limb's joints are placed where it bends
and where it narrows (`articulations`: the limb's polyline fitted exactly by dynamic
programming, joints drawn to radius minima); `bone_detail` says how many (0 = one bone per
limb, 1 = about one per polyline segment). Chains are laid out breadth-first from the
skeleton's root: the chain of a limb starts at the node nearer the root and its first bone
is the child of the bone that arrived at that node. A link that closes a cycle (genus > 0)
is a limb of its own whose first bone is parented without `use_connect`, so the armature
stays a tree while every cycle keeps its bones. A connection node between two joints of a
limb has no bone ending at it; every node of degree other than 2 has. The bone ending at
an end node stops END_INSET radii short of it (the node is the prong's tip on the surface;
the joint sits inside the rounded tip, where an artist's last joint goes).

Bone kinds: a bone whose tail is a skeleton node takes that node's kind ("end", "joint",
"connection"); a bone whose tail is an inner polyline point is a "connection" (such points
have two neighbours, like connection nodes); `link` is the link of the bone's last
segment. Names are the kind plus a counter per kind, in creation order: ``end.001``,
``joint.001``, ``connection.012``. When the skeleton has a mirror plane (`mirror_plane`,
tolerant of small asymmetries) through its root, the limbs on either side that mirror each
other (`limb_sides`) get the same number of bones and Blender's side suffixes, the two
chains sharing their counters bone by bone (``connection.004.L`` / ``connection.004.R``,
``end.002.L`` / ``end.002.R``: what X-Axis Mirror, Symmetrize and Paste Pose Flipped pair);
.L is the side the plane's normal points to (its largest component positive: +X for a
model mirrored across x = 0). The middle's limbs and every limb of a shape with no mirror
plane keep the plain names.
"""

from collections import deque
from dataclasses import dataclass

import numpy as np

KINDS = ("end", "joint", "connection")
#: The default `bone_detail` (the add-on's panel, its CLI and `dcg batch` start from it).
BONE_DETAIL = 0.5
#: Bones per link of a limb at bone_detail 1 (capped by the limb's polyline segments).
BONES_PER_LINK = 5.0
#: How much a narrowing (the radius dipping below the widest part on both sides, 0..1)
#: draws a joint, against the squared distance of the polyline to the bones (in radii^2).
NARROWING = 1.0
#: An end bone's tail stops this many radii (at its head) short of the end node.
END_INSET = 1.0
#: A mirror plane is accepted when the skeleton's nodes mirrored across it lie this close to
#: nodes (mean, in bounding-box diagonals); limbs' sides and pairs use the same tolerance.
MIRROR_TOLERANCE = 0.03


@dataclass
class BoneSpec:
    """One planned bone, in the skeleton's coordinates."""

    name: str
    head: np.ndarray           #: 3 head position
    tail: np.ndarray           #: 3 tail position
    parent: str | None         #: parent bone name, None for bones at the root
    use_connect: bool          #: head attached to the parent's tail
    kind: str                  #: "end", "joint" or "connection"
    node: int                  #: skeleton node at the tail, -1 for an inner polyline point
    link: int                  #: skeleton link of the bone's last segment
    head_radius: float         #: skeleton radius at the head (distance to the surface)
    tail_radius: float         #: skeleton radius at the tail


def bone_count(links, segments, bone_detail):
    """How many bones a limb of `links` links and `segments` polyline segments gets:
    max(1, round(bone_detail x BONES_PER_LINK x links)), at most one per segment. So 0 gives
    one bone per limb, 0.5 (the default) 2.5 per link, 0.8 and above one per segment."""
    detail = min(max(float(bone_detail), 0.0), 1.0)
    return max(1, min(segments, int(round(detail * BONES_PER_LINK * links))))


def articulations(points, radii, bones):
    """Return the indices of the points of a limb (#P by 3, radii #P) kept as joints: the
    two ends and bones - 1 inner points (every point when bones >= #P - 1).

    The joints are the ones of least cost, found exactly (dynamic programming, O(bones P^2)
    time, O(P^2) memory: a limb has tens of points, 4 per link as the engine samples them):
    the squared distances of the limb's points to the bones, in squared mean radii (so joints
    go where the centre line bends), less NARROWING x the narrowing at each inner joint
    (where the limb is thinner than its widest part on both sides: a knee, a wrist, a neck).
    """
    count = len(points)
    segments = count - 1
    if count <= 2 or bones >= segments:
        return list(range(count))
    scale = max(float(np.mean(radii)), 1e-12) ** 2
    cost = _fit_costs(np.asarray(points, dtype=float)) / scale
    gain = np.zeros(count)
    gain[1:-1] = NARROWING * _narrowing(np.asarray(radii, dtype=float))[1:-1]
    best = np.full(count, np.inf)
    best[0] = 0.0
    choice = np.zeros((bones + 1, count), dtype=np.int64)
    for k in range(1, bones + 1):  # best[b]: least cost of k bones from point 0 to point b
        total = best[:, None] + cost - gain[None, :]
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
    each point (the nodes' radii, linear in arc length between them)."""
    positions = np.asarray(skeleton.positions, dtype=float).reshape(-1, 3)
    points, nodes, segment_links = [positions[limb[0][1]]], [limb[0][1]], []
    for link, start, stop, _ in limb:
        polyline = np.asarray(skeleton.polylines[link], dtype=float).reshape(-1, 3)
        if int(skeleton.links[link][0]) != start:
            polyline = polyline[::-1]
        inner = list(polyline[1:-1])
        points += inner + [positions[stop]]
        nodes += [-1] * len(inner) + [stop]
        segment_links += [link] * (len(inner) + 1)
    points, nodes = np.array(points), np.array(nodes)
    arc = np.concatenate([[0.0], np.cumsum(np.linalg.norm(np.diff(points, axis=0), axis=1))])
    at = np.flatnonzero(nodes >= 0)
    radii = np.interp(arc, arc[at], np.asarray(skeleton.radii, dtype=float)[nodes[at]])
    return points, nodes, np.array(segment_links, dtype=np.int64), radii


def plan_bones(skeleton, bone_detail=BONE_DETAIL):
    """Return the list of BoneSpec for `skeleton`, parents before children.

    `skeleton` needs positions (#N by 3), kinds (#N), radii (#N), links (#L by 2),
    polylines (#L arrays, from links[l, 0] to links[l, 1]) and root. One chain of bones per
    limb (see `limbs`), `bone_count` bones (set by `bone_detail`) with their joints at the
    limb's articulations (`articulations`). Segments shorter than 1e-6 of the skeleton's
    size are merged away (Blender deletes zero-length bones).
    """
    positions = np.asarray(skeleton.positions, dtype=float).reshape(-1, 3)
    kinds = [str(k) for k in skeleton.kinds]
    extent = np.ptp(positions, axis=0) if len(positions) else np.zeros(3)
    min_length = 1e-6 * max(float(np.linalg.norm(extent)), 1e-12)
    degree = _degrees(skeleton)
    name_of = _namer()
    tail_bone = {}  # node -> name of the bone whose tail is that node
    bones = []
    chains = limbs(skeleton)
    polylines = [limb_polyline(skeleton, limb) for limb in chains]
    sides = limb_sides(skeleton, [polyline[0] for polyline in polylines])
    segments = [len(polyline[0]) - 1 for polyline in polylines]
    wanted = _paired_counts([bone_count(len(limb), count, bone_detail)
                             for limb, count in zip(chains, segments)], segments, sides)
    for limb, (points, nodes, segment_links, radii), (side, pair), count in zip(
            chains, polylines, sides, wanted):
        keep = _drop_short(points, articulations(points, radii, count), min_length)
        parent, first_tree = tail_bone.get(limb[0][1]), limb[0][3]
        for i, (a, b) in enumerate(zip(keep[:-1], keep[1:])):
            node = int(nodes[b])
            kind = kinds[node] if node >= 0 else "connection"
            name = name_of(kind, side, pair, i)
            inset = kind == "end" and degree[node] == 1
            bones.append(BoneSpec(name, points[a].copy(), _tail(points, radii, a, b, inset),
                                  parent, parent is not None and (i > 0 or first_tree), kind,
                                  node, int(segment_links[b - 1]), float(radii[a]),
                                  float(radii[b])))
            parent = name
        if limb[-1][3]:
            tail_bone[limb[-1][2]] = parent
    return bones


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


def _namer():
    """name(kind, side, pair, index): the kind plus a counter per kind (``end.001``); for a
    limb with a side ("L"/"R") the side suffix too, the two limbs of a pair sharing their
    counters bone by bone (``end.003.L`` / ``end.003.R``), counted apart from the others."""
    counters, waiting = {}, {}

    def name(kind, side=None, pair=-1, index=0):
        if side is None:
            counters[kind] = counters.get(kind, 0) + 1
            return f"{kind}.{counters[kind]:03d}"
        number = waiting.pop((pair, index, kind), None)
        if number is None:
            counters[kind, "sided"] = number = counters.get((kind, "sided"), 0) + 1
            if pair >= 0:
                waiting[pair, index, kind] = number
        return f"{kind}.{number:03d}.{side}"
    return name


def mirror_plane(points):
    """Return (normal, offset, error) of the best mirror plane n.x = offset of `points` (#P by
    3), or None (fewer than 2 points, no candidate). Candidates: the coordinate planes and
    the principal planes through the centroid, each refined twice (the plane through the
    midpoints of each point and its mirror image's nearest point); a plane with fewer than
    a quarter of the points farther than MIRROR_TOLERANCE from it is skipped (a flat shape
    lies in a plane that mirrors it trivially). error: the mean distance from each mirrored
    point to its nearest point, over the points' bounding-box diagonal. The normal's largest
    component is positive (its side is Blender's left, .L, for a model facing -Y)."""
    points = np.asarray(points, dtype=float).reshape(-1, 3)
    diagonal = float(np.linalg.norm(np.ptp(points, axis=0))) if len(points) else 0.0
    if len(points) < 2 or diagonal == 0:
        return None
    centre = points.mean(axis=0)
    best = None
    for normal in list(np.eye(3)) + list(np.linalg.svd(points - centre)[2]):
        offset = float(normal @ centre)
        for refinement in range(3):
            mirrored = points - 2 * (points @ normal - offset)[:, None] * normal
            distances = np.linalg.norm(mirrored[:, None] - points[None], axis=2)
            match = distances.argmin(axis=1)
            error = float(distances[np.arange(len(points)), match].mean()) / diagonal
            if refinement == 2:
                break
            gaps = points - points[match]
            gaps *= np.where(gaps @ normal < 0, -1.0, 1.0)[:, None]
            if np.linalg.norm(gaps.sum(axis=0)) > 1e-9 * diagonal:
                normal = gaps.sum(axis=0) / np.linalg.norm(gaps.sum(axis=0))
            offset = float(np.mean((points + points[match]) @ normal) / 2)
        off_plane = np.abs(points @ normal - offset) > MIRROR_TOLERANCE * diagonal
        if off_plane.mean() < 0.25:  # a plane the shape lies in mirrors it trivially
            continue
        if best is None or error < best[2]:
            best = (normal, offset, error)
    if best is None:
        return None
    normal, offset, error = best
    if normal[np.argmax(np.abs(normal))] < 0:
        normal, offset = -normal, -offset
    return normal, offset, error


def limb_sides(skeleton, limb_points):
    """Return (side, pair) per limb (limb_points: each limb's polyline points): side "L" or
    "R" for a limb paired with its mirror image across the skeleton's mirror plane
    (`mirror_plane` of the nodes, error at most MIRROR_TOLERANCE, the root on it), pair the
    pair's index; (None, -1) for the limbs of the middle, unpaired ones and every limb of a
    shape with no mirror plane."""
    none = [(None, -1)] * len(limb_points)
    positions = np.asarray(skeleton.positions, dtype=float).reshape(-1, 3)
    plane = mirror_plane(positions)
    if plane is None or plane[2] > MIRROR_TOLERANCE or not 0 <= skeleton.root < len(positions):
        return none
    normal, offset, _ = plane
    tolerance = MIRROR_TOLERANCE * float(np.linalg.norm(np.ptp(positions, axis=0)))
    if abs(positions[skeleton.root] @ normal - offset) > tolerance:
        return none
    centres = np.array([np.mean(points, axis=0) for points in limb_points]).reshape(-1, 3)
    signed = centres @ normal - offset
    mirrored = centres - 2 * signed[:, None] * normal
    left, right = np.flatnonzero(signed > tolerance), np.flatnonzero(signed < -tolerance)
    if not len(left) or not len(right):
        return none
    gaps = np.linalg.norm(mirrored[left][:, None] - centres[right][None], axis=2)
    result = list(none)
    for row, i in enumerate(left):
        column = int(gaps[row].argmin())
        if gaps[:, column].argmin() == row and gaps[row, column] <= 2 * tolerance:
            result[i], result[right[column]] = ("L", row), ("R", row)
    return result


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


def _tail(points, radii, a, b, inset):
    """The tail of the bone from point a to point b: point b, or with `inset` (an end bone)
    point b moved back towards the head by END_INSET x the radius at the head (at most half
    the bone), so the last joint sits inside the prong's rounded tip rather than on it."""
    tail = points[b].copy()
    if not inset or END_INSET <= 0:
        return tail
    direction = tail - points[a]
    length = float(np.linalg.norm(direction))
    if length == 0:
        return tail
    return tail - direction * min(END_INSET * float(radii[a]) / length, 0.5)


def bone_arrays(plan):
    """The plan as arrays, in plan order: names (#B str), heads and tails (#B by 3 float64),
    parents (#B int64 index into the plan, -1 at a root), links (#B int64, the skeleton link of
    each bone) and kinds (#B str)."""
    index = {spec.name: i for i, spec in enumerate(plan)}
    return {
        "names": np.array([spec.name for spec in plan], dtype=str),
        "heads": np.array([spec.head for spec in plan], dtype=np.float64).reshape(-1, 3),
        "tails": np.array([spec.tail for spec in plan], dtype=np.float64).reshape(-1, 3),
        "parents": np.array([-1 if spec.parent is None else index[spec.parent]
                             for spec in plan], dtype=np.int64),
        "links": np.array([spec.link for spec in plan], dtype=np.int64),
        "kinds": np.array([spec.kind for spec in plan], dtype=str),
    }
