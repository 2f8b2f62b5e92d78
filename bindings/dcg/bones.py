"""The bone plan of a DCG skeleton: the one planner behind the add-on's armature, the batch's
.weights.npz and `dcg.skin_weights(V, F, skeleton)` (no `bpy`: plain pytest tests it).

    plan = dcg.bones.plan_bones(skeleton, bone_detail=0.5)   # [BoneSpec], parents first
    arrays = dcg.bones.bone_arrays(plan)   # names, heads, tails, parents (-1), links, kinds

One chain of bones per link, following the link's polyline (simplified by `bone_detail`).
Chains are laid out breadth-first from the skeleton's root: the chain of a link starts at
the node nearer the root and its first bone is the child of the bone that arrived at that
node. A link that closes a cycle (genus > 0) gets a chain whose first bone is parented
without `use_connect`, so the armature stays a tree while every link keeps its bones.

Bone kinds: a bone whose tail is a skeleton node takes that node's kind ("end", "joint",
"connection"); a bone whose tail is an inner polyline point is a "connection" (such points
have two neighbours, like connection nodes). Names are the kind plus a counter per kind,
in creation order: ``end.001``, ``joint.001``, ``connection.012``.
"""

from collections import deque
from dataclasses import dataclass

import numpy as np

KINDS = ("end", "joint", "connection")
#: The default `bone_detail` (the add-on's panel, its CLI and `dcg batch` start from it).
BONE_DETAIL = 0.5


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
    link: int                  #: skeleton link the bone belongs to
    head_radius: float         #: skeleton radius at the head (distance to the surface)
    tail_radius: float         #: skeleton radius at the tail


def simplify_polyline(points, bone_detail):
    """Return the indices of the points of `points` (#P by 3) kept as bone ends.

    The two ends are always kept. Of the P - 2 inner points, round(bone_detail * (P - 2))
    are kept, chosen greedily: each step adds the point farthest from the current
    simplified polyline (on a straight run, the middle of the longest span). So 0 gives one
    bone per link and 1 one bone per polyline segment.
    """
    points = np.asarray(points, dtype=float)
    count = len(points)
    if count <= 2:
        return list(range(count))
    wanted = int(round(min(max(bone_detail, 0.0), 1.0) * (count - 2)))
    kept = [0, count - 1]
    for _ in range(wanted):
        best = None  # (deviation, span, index)
        for a, b in zip(kept[:-1], kept[1:]):
            if b - a < 2:
                continue
            deviation = _distances_to_segment(points[a + 1:b], points[a], points[b])
            span = float(np.linalg.norm(points[b] - points[a]))
            i = int(np.argmax(deviation))
            if deviation[i] > 1e-9 * span:
                candidate = (float(deviation[i]), span, a + 1 + i)
            else:
                candidate = (0.0, span, (a + b) // 2)
            if best is None or candidate[:2] > best[:2]:
                best = candidate
        kept = sorted(kept + [best[2]])
    return kept


def _distances_to_segment(points, a, b):
    """Return the distance of each of `points` (#P by 3) to the segment from `a` to `b`."""
    ab = b - a
    length2 = float(ab @ ab)
    t = np.zeros(len(points)) if length2 == 0 else np.clip((points - a) @ ab / length2, 0, 1)
    return np.linalg.norm(points - (a + t[:, None] * ab), axis=1)


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


def plan_bones(skeleton, bone_detail=BONE_DETAIL):
    """Return the list of BoneSpec for `skeleton`, parents before children.

    `skeleton` needs positions (#N by 3), kinds (#N), radii (#N), links (#L by 2),
    polylines (#L arrays, from links[l, 0] to links[l, 1]) and root. Segments shorter than
    1e-6 of the skeleton's size are merged away (Blender deletes zero-length bones).
    """
    positions = np.asarray(skeleton.positions, dtype=float).reshape(-1, 3)
    kinds = [str(k) for k in skeleton.kinds]
    radii = np.asarray(skeleton.radii, dtype=float)
    extent = np.ptp(positions, axis=0) if len(positions) else np.zeros(3)
    min_length = 1e-6 * max(float(np.linalg.norm(extent)), 1e-12)
    counters = dict.fromkeys(KINDS, 0)
    tail_bone = {}  # node -> name of the bone whose tail is that node
    bones = []
    for link, start, stop, tree in _traversal(skeleton):
        points = np.asarray(skeleton.polylines[link], dtype=float).reshape(-1, 3)
        if int(skeleton.links[link][0]) != start:
            points = points[::-1]
        points = points[simplify_polyline(points, bone_detail)]
        points[0], points[-1] = positions[start], positions[stop]
        keep = [0]
        for i in range(1, len(points)):
            if np.linalg.norm(points[i] - points[keep[-1]]) > min_length:
                keep.append(i)
        if len(keep) > 1 and keep[-1] != len(points) - 1:
            keep[-1] = len(points) - 1
        points = points[keep]
        arc = np.concatenate([[0.0], np.cumsum(np.linalg.norm(np.diff(points, axis=0),
                                                              axis=1))])
        fraction = arc / arc[-1] if arc[-1] > 0 else arc
        radius = radii[start] + fraction * (radii[stop] - radii[start])
        parent = tail_bone.get(start)
        for i in range(len(points) - 1):
            last = i == len(points) - 2
            kind = kinds[stop] if last else "connection"
            counters[kind] = counters.get(kind, 0) + 1
            name = f"{kind}.{counters[kind]:03d}"
            bones.append(BoneSpec(name, points[i].copy(), points[i + 1].copy(), parent,
                                  parent is not None and (i > 0 or tree), kind,
                                  stop if last else -1, link, float(radius[i]),
                                  float(radius[i + 1])))
            parent = name
        if tree:
            tail_bone[stop] = parent
    return bones


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
