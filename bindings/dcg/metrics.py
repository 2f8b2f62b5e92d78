"""Measures of a rig against an artist's: skinning weights and skeleton (numpy only, no bpy).

    from dcg import metrics
    rig = metrics.read_rig_info("Fox.rig.txt", vertex_count=len(V))   # RigNet's rig_info
    heads, tails = metrics.joint_bones(rig.joints, rig.parents)       # one bone per joint
    W = dcg.skin_weights(V, F, heads, tails, parents=rig.parents).dense()  # #V x #J: joints
    metrics.weight_metrics(V, W, rig.weights, rig.joints, rig.parents)
    # {"l1", "precision", "recall", "deformation_error", "unweighted"}
    metrics.skeleton_metrics(V, heads, tails, rig.joints, rig.parents)
    # {"cd_j2j", "cd_j2b", "cd_b2b"}, in % of the mesh's longest bounding-box side
    metrics.j2j_parts(V, heads, tails, rig.joints, rig.parents)        # CD-J2J's directions

The weights protocol: bone j has its head at joint j and its tail at the mean of j's children;
a leaf continues the direction from its parent by half that length; the weight of bone j is the
weight of joint j (RigNet's convention: a bone's weights belong to the joint at its head).

Shapes follow libigl: V #V x 3, joints #J x 3, parents #J (-1 for a root), W #V x #J,
heads / tails #B x 3. Every random step takes a seed.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path
from typing import Dict, List, Tuple

import numpy as np

#: A weight above this counts as an influence (RigNet's and MagicArticulate's threshold).
INFLUENCE = 1e-4


@dataclass
class RigInfo:
    """An artist's rig read from RigNet's rig_info text."""

    names: List[str]        #: #J joint names, in file order
    joints: np.ndarray      #: #J x 3 joint positions (bone heads)
    parents: np.ndarray     #: #J int64 parent joint index, -1 for a root
    root: int               #: index of the `root` line's joint
    weights: np.ndarray     #: #V x #J skinning weights (a row of zeros where no `skin` line)


def parse_rig_info(text: str, vertex_count: int | None = None) -> RigInfo:
    """RigInfo from rig_info text (`joints`, `root`, `hier`, `skin` lines, any order).

    vertex_count: rows of the weights (default: the largest skinned vertex + 1).
    ValueError for an unknown joint name or line kind.
    """
    lines = [line.split() for line in text.splitlines() if line.strip()]
    names = [w[1] for w in lines if w[0] == "joints"]
    index = {name: i for i, name in enumerate(names)}
    joints = np.array([[float(x) for x in w[2:5]] for w in lines if w[0] == "joints"])
    parents = np.full(len(names), -1, dtype=np.int64)
    skins, root = [], 0
    for words in lines:
        kind = words[0]
        try:
            if kind == "root":
                root = index[words[1]]
            elif kind == "hier":
                parents[index[words[2]]] = index[words[1]]
            elif kind == "skin":
                skins.append((int(words[1]), [(index[j], float(w))
                                              for j, w in zip(words[2::2], words[3::2])]))
            elif kind != "joints":
                raise ValueError(f"unknown rig_info line kind {kind!r}")
        except KeyError as error:
            raise ValueError(f"rig_info names an unknown joint {error}") from None
    count = vertex_count if vertex_count is not None else 1 + max((v for v, _ in skins),
                                                                  default=-1)
    weights = np.zeros((count, len(names)))
    for vertex, pairs in skins:
        for joint, weight in pairs:
            weights[vertex, joint] += weight
    return RigInfo(names, joints.reshape(-1, 3), parents, root, weights)


def read_rig_info(path, vertex_count: int | None = None) -> RigInfo:
    """RigInfo of a rig_info file (`NAME.rig.txt`); see parse_rig_info."""
    return parse_rig_info(Path(path).read_text(), vertex_count)


def rigged_characters(folder) -> List[Tuple[str, Path, Path]]:
    """(name, NAME.obj, NAME.rig.txt) of every character of `folder` with both, sorted."""
    folder = Path(folder)
    return [(obj.stem, obj, obj.with_suffix(".rig.txt")) for obj in sorted(folder.glob("*.obj"))
            if obj.with_suffix(".rig.txt").is_file()]


# --- the weights protocol ----------------------------------------------------------------------

def joint_bones(joints, parents) -> Tuple[np.ndarray, np.ndarray]:
    """Heads and tails (#J x 3 each) of one bone per joint.

    Head at the joint; tail at the mean of its children, or for a leaf the joint plus half the
    vector from its parent. A bone that would have no length (a joint on its children's mean,
    a leaf on its parent, a lone root) points up +Z by half the mean length of the others
    (Blender deletes zero-length bones).
    """
    joints = np.asarray(joints, dtype=float).reshape(-1, 3)
    parents = np.asarray(parents, dtype=np.int64)
    sums, counts = np.zeros_like(joints), np.zeros(len(joints))
    children = np.flatnonzero(parents >= 0)
    np.add.at(sums, parents[children], joints[children])
    np.add.at(counts, parents[children], 1)
    tails = sums / np.maximum(counts, 1)[:, None]
    leaves = (counts == 0) & (parents >= 0)
    tails[leaves] = joints[leaves] + 0.5 * (joints[leaves] - joints[parents[leaves]])
    tails[(counts == 0) & (parents < 0)] = joints[(counts == 0) & (parents < 0)]
    lengths = np.linalg.norm(tails - joints, axis=1)
    extent = max(float(np.linalg.norm(np.ptp(joints, axis=0))), 1.0)
    flat = lengths <= 1e-9 * extent
    fallback = 0.5 * lengths[~flat].mean() if np.any(~flat) else 0.05 * extent
    tails[flat] = joints[flat] + [0.0, 0.0, fallback]
    return joints.copy(), tails


def parent_segments(joints, parents) -> Tuple[np.ndarray, np.ndarray]:
    """The skeleton's bones as MagicArticulate counts them: one segment per parent-child pair
    (heads at parents, tails at children), #E x 3 each."""
    joints = np.asarray(joints, dtype=float).reshape(-1, 3)
    children = np.flatnonzero(np.asarray(parents) >= 0)
    return joints[np.asarray(parents)[children]], joints[children]


# --- weights -----------------------------------------------------------------------------------

def normalized(W) -> np.ndarray:
    """W with each row scaled to sum 1 (rows of zeros stay zero), as Blender's armature
    modifier reads vertex groups."""
    W = np.asarray(W, dtype=float)
    sums = W.sum(axis=1, keepdims=True)
    return np.divide(W, sums, out=np.zeros_like(W), where=sums > 0)


def weight_l1(W, W_ref) -> float:
    """Mean over vertices of sum_j |W - W_ref| (0 equal .. 2 disjoint, for normalized rows)."""
    return float(np.abs(np.asarray(W) - np.asarray(W_ref)).sum(axis=1).mean())


def influence_precision_recall(W, W_ref, threshold=INFLUENCE) -> Tuple[float, float]:
    """Per-vertex precision and recall of the influences (weights > threshold) of W against
    W_ref, each the mean over the vertices where it is defined (a predicted, resp. reference,
    influence exists); 1.0 when defined nowhere."""
    ours, theirs = np.asarray(W) > threshold, np.asarray(W_ref) > threshold
    both = (ours & theirs).sum(axis=1)
    return _mean_ratio(both, ours.sum(axis=1)), _mean_ratio(both, theirs.sum(axis=1))


def _mean_ratio(numerators, denominators) -> float:
    defined = denominators > 0
    return float(np.mean(numerators[defined] / denominators[defined])) if defined.any() else 1.0


def unweighted_vertices(W) -> int:
    """Vertices with no positive weight."""
    return int(np.sum(np.asarray(W).sum(axis=1) <= 0))


def _rotations(axes, angles) -> np.ndarray:
    """Rodrigues: #R x 3 x 3 rotations by `angles` (radians) about unit `axes` (#R x 3)."""
    K = np.zeros((len(axes), 3, 3))
    K[:, 0, 1], K[:, 0, 2], K[:, 1, 2] = -axes[:, 2], axes[:, 1], -axes[:, 0]
    K -= K.transpose(0, 2, 1)
    s, c = np.sin(angles)[:, None, None], np.cos(angles)[:, None, None]
    return np.eye(3) + s * K + (1 - c) * K @ K


def _parents_first(parents) -> List[int]:
    """Joint indices ordered so that every parent comes before its children."""
    children = [[] for _ in parents]
    for child, parent in enumerate(parents):
        if parent >= 0:
            children[parent].append(child)
    order = [j for j, p in enumerate(parents) if p < 0]
    for j in order:
        order.extend(children[j])
    return order


def random_pose(joints, parents, max_degrees=35.0, rng=None) -> Tuple[np.ndarray, np.ndarray]:
    """World transforms (R #J x 3 x 3, t #J x 3) of a pose in which each joint turns its
    subtree by up to max_degrees about a random axis through its rest position (uniform axis,
    uniform angle), children following their parents. Rest pose = identity."""
    joints = np.asarray(joints, dtype=float).reshape(-1, 3)
    rng = np.random.default_rng(rng)
    axes = rng.normal(size=(len(joints), 3))
    axes /= np.linalg.norm(axes, axis=1, keepdims=True)
    local = _rotations(axes, np.radians(rng.uniform(0.0, max_degrees, len(joints))))
    R, t = np.zeros_like(local), np.zeros_like(joints)
    for j in _parents_first(parents):
        shift = joints[j] - local[j] @ joints[j]
        p = parents[j]
        R[j], t[j] = (local[j], shift) if p < 0 else (R[p] @ local[j], R[p] @ shift + t[p])
    return R, t


def linear_blend_skinning(V, W, R, t) -> np.ndarray:
    """V posed by the joint transforms (R #J x 3 x 3, t #J x 3) with weights W (#V x #J),
    rows normalized; a vertex with no weight stays where it is (Blender's armature modifier)."""
    V = np.asarray(V, dtype=float)
    W = normalized(W)
    moved = np.einsum("vj,jab,vb->va", W, R, V) + W @ t
    rest = W.sum(axis=1) <= 0
    moved[rest] = V[rest]
    return moved


def deformation_error(V, W, W_ref, joints, parents, poses=5, max_degrees=35.0,
                      seed=0) -> float:
    """Mean distance between V posed with W and with W_ref (linear blend skinning) over
    `poses` random poses (random_pose, seeded), in % of V's bounding-box diagonal."""
    rng = np.random.default_rng(seed)
    V = np.asarray(V, dtype=float)
    diagonal = float(np.linalg.norm(np.ptp(V, axis=0))) or 1.0
    errors = []
    for _ in range(poses):
        R, t = random_pose(joints, parents, max_degrees, rng)
        gap = linear_blend_skinning(V, W, R, t) - linear_blend_skinning(V, W_ref, R, t)
        errors.append(np.linalg.norm(gap, axis=1).mean())
    return 100.0 * float(np.mean(errors)) / diagonal


def weight_metrics(V, W, W_ref, joints, parents, seed=0) -> Dict[str, float]:
    """All weight measures of W (#V x #J, column j = joint j's bone) against the artist's
    W_ref: l1, precision, recall (of normalized rows), deformation_error (% of the diagonal)
    and unweighted (vertices W leaves with nothing)."""
    W, W_ref = normalized(W), normalized(W_ref)
    precision, recall = influence_precision_recall(W, W_ref)
    return {"l1": weight_l1(W, W_ref), "precision": precision, "recall": recall,
            "deformation_error": deformation_error(V, W, W_ref, joints, parents, seed=seed),
            "unweighted": unweighted_vertices(W)}


# --- skeletons ---------------------------------------------------------------------------------

def segment_distances(points, heads, tails) -> np.ndarray:
    """#P x #S distances of points (#P x 3) to the segments heads[s]-tails[s] (#S x 3 each)."""
    points = np.asarray(points, dtype=float).reshape(-1, 1, 3)
    heads, tails = np.asarray(heads, dtype=float), np.asarray(tails, dtype=float)
    ab = tails - heads
    length2 = np.einsum("sa,sa->s", ab, ab)
    along = np.einsum("psa,sa->ps", points - heads, ab)
    t = np.clip(np.divide(along, length2, out=np.zeros_like(along), where=length2 > 0), 0, 1)
    return np.linalg.norm(points - (heads + t[..., None] * ab), axis=2)


def point_distances(a, b) -> np.ndarray:
    """#A x #B distances between two point sets."""
    a, b = np.asarray(a, dtype=float).reshape(-1, 3), np.asarray(b, dtype=float).reshape(-1, 3)
    return np.linalg.norm(a[:, None, :] - b[None, :, :], axis=2)


def _symmetric(a_to_b, b_to_a) -> float:
    """Half the sum of the two directions' mean nearest distances."""
    return 0.5 * float(a_to_b.min(axis=1).mean() + b_to_a.min(axis=1).mean())


def chamfer_j2j(joints_a, joints_b) -> float:
    """Symmetric chamfer distance between two joint sets."""
    d = point_distances(joints_a, joints_b)
    return _symmetric(d, d.T)


def chamfer_j2b(joints_a, bones_a, joints_b, bones_b) -> float:
    """Joints of each side to the other side's bone segments (bones_* = (heads, tails))."""
    return _symmetric(segment_distances(joints_a, *bones_b),
                      segment_distances(joints_b, *bones_a))


def bone_samples(heads, tails, step) -> np.ndarray:
    """Points along every segment, both ends included, at most `step` apart."""
    samples = []
    for head, tail in zip(np.asarray(heads, dtype=float), np.asarray(tails, dtype=float)):
        count = max(2, int(np.ceil(np.linalg.norm(tail - head) / step)) + 1)
        samples.append(head + np.linspace(0.0, 1.0, count)[:, None] * (tail - head))
    return np.concatenate(samples) if samples else np.zeros((0, 3))


def chamfer_b2b(bones_a, bones_b, step) -> float:
    """Symmetric chamfer distance between points sampled `step` apart along both bone sets."""
    return chamfer_j2j(bone_samples(*bones_a, step), bone_samples(*bones_b, step))


#: A joint farther than this (% of the longest side) from every bone of the other skeleton
#: counts as "far" in `j2j_parts`: a limb one side rigged and the other did not.
FAR_JOINT = 5.0


def j2j_parts(V, heads, tails, joints, parents, far=FAR_JOINT) -> Dict[str, float]:
    """CD-J2J split into what makes it, in % of V's longest bounding-box side (arguments as
    `skeleton_metrics`; CD-J2J is the mean of the two directions):

    - "j2j_ours": the mean distance from our joints to the artist's nearest joint, and
      "j2j_ours_far" the part of that mean from our joints farther than `far` from every
      artist bone (limbs the artist did not rig: wings, a tail, extra end bones);
    - "j2j_theirs": the mean distance from the artist's joints to our nearest joint, and
      "j2j_theirs_far" the part from their joints farther than `far` from all our bones (a
      root on the floor, a hub outside the body: joints our skeleton does not reach).
    """
    side, ours, our_joints, joints, theirs = _both_skeletons(V, heads, tails, joints, parents)
    if not len(theirs[0]):  # one joint, no bone: distances to the joint itself
        theirs = (joints, joints)
    nearest = point_distances(our_joints, joints) * (100.0 / side)
    to_ours, to_theirs = nearest.min(axis=1), nearest.min(axis=0)
    ours_far = segment_distances(our_joints, *theirs).min(axis=1) * (100.0 / side) > far
    theirs_far = segment_distances(joints, *ours).min(axis=1) * (100.0 / side) > far
    return {"j2j_ours": float(to_ours.mean()),
            "j2j_ours_far": float(np.where(ours_far, to_ours, 0.0).mean()),
            "j2j_theirs": float(to_theirs.mean()),
            "j2j_theirs_far": float(np.where(theirs_far, to_theirs, 0.0).mean())}


def unique_points(points, tolerance=1e-9) -> np.ndarray:
    """The points of #P x 3 with duplicates (closer than tolerance x extent) dropped."""
    points = np.asarray(points, dtype=float).reshape(-1, 3)
    extent = max(float(np.linalg.norm(np.ptp(points, axis=0))) if len(points) else 0.0, 1e-300)
    keys = np.round(points / (tolerance * extent)).astype(np.int64)
    return points[np.sort(np.unique(keys, axis=0, return_index=True)[1])]


def _both_skeletons(V, heads, tails, joints, parents):
    """What `skeleton_metrics` and `j2j_parts` measure: (V's longest bounding-box side, our
    bones (heads, tails), our joints (their distinct heads and tails), the artist's joints
    #J x 3, the artist's bones (parent_segments))."""
    side = float(np.ptp(np.asarray(V, dtype=float), axis=0).max()) or 1.0
    ours = (np.asarray(heads, dtype=float), np.asarray(tails, dtype=float))
    joints = np.asarray(joints, dtype=float).reshape(-1, 3)
    return (side, ours, unique_points(np.concatenate(ours)), joints,
            parent_segments(joints, parents))


def skeleton_metrics(V, heads, tails, joints, parents, step=0.005) -> Dict[str, float]:
    """CD-J2J, CD-J2B and CD-B2B of a rig's bones (heads, tails #B x 3: its joints are the
    distinct heads and tails) against an artist's skeleton (joints #J x 3, parents: bones
    from each parent to each child), in % of V's longest bounding-box side (MagicArticulate's
    normalization). B2B samples both bone sets `step` x the longest side apart."""
    side, ours, our_joints, joints, theirs = _both_skeletons(V, heads, tails, joints, parents)
    return {"cd_j2j": 100.0 * chamfer_j2j(our_joints, joints) / side,
            "cd_j2b": 100.0 * chamfer_j2b(our_joints, ours, joints, theirs) / side,
            "cd_b2b": 100.0 * chamfer_b2b(ours, theirs, step * side) / side}


def kept_joints(joints, parents, keep) -> Tuple[np.ndarray, np.ndarray]:
    """The skeleton of the joints where `keep` (#J booleans) is true: (joints #K x 3, parents
    #K), each kept joint's parent its nearest kept ancestor (-1 when none). What the rig-quality
    bench uses to leave out the artist's joints that lie outside the mesh (a root on the floor,
    a hub above the body, IK targets), whose bones no skeleton inside the shape can follow."""
    joints = np.asarray(joints, dtype=float).reshape(-1, 3)
    parents = np.asarray(parents, dtype=np.int64)
    keep = np.asarray(keep, dtype=bool)
    if keep.shape != parents.shape or len(joints) != len(parents):
        raise ValueError(f"kept_joints: {len(joints)} joints, {len(parents)} parents and "
                         f"{keep.size} flags")
    index = np.full(len(keep), -1, dtype=np.int64)
    index[keep] = np.arange(int(keep.sum()))
    kept_parents = []
    for j in np.flatnonzero(keep):
        p, steps = int(parents[j]), 0
        while p >= 0 and not keep[p] and steps <= len(parents):  # steps: a cycle cannot hang it
            p, steps = int(parents[p]), steps + 1
        kept_parents.append(int(index[p]) if p >= 0 else -1)  # index: -1 where dropped
    return joints[keep], np.array(kept_parents, dtype=np.int64)


# --- symmetry ----------------------------------------------------------------------------------

def mirror_pairs(names) -> List[Tuple[int, int]]:
    """(l, r) index pairs of the bones named `X.L` and `X.R` (Blender's side suffixes), in
    the order of the .L bones."""
    index = {str(name): b for b, name in enumerate(names)}
    return [(b, index[str(name)[:-1] + "R"]) for b, name in enumerate(names)
            if str(name).endswith(".L") and str(name)[:-1] + "R" in index]


def mirror_error(V, names, heads, tails, normal, offset) -> Dict[str, float]:
    """How far a rig's paired bones (names `X.L` / `X.R`, heads and tails #B x 3) are from
    mirroring each other across the plane normal . x = offset (normal a unit 3-vector): the
    mean and the largest distance from each .L bone's head and tail mirrored to its .R
    partner's, in % of V's longest bounding-box side ("mirror_mean", "mirror_max", None
    without pairs), and the number of pairs and of bones with a side suffix but no partner
    ("pairs", "unpaired")."""
    side = float(np.ptp(np.asarray(V, dtype=float), axis=0).max()) or 1.0
    normal = np.asarray(normal, dtype=float)
    pairs = mirror_pairs(names)
    sided = sum(str(name).endswith((".L", ".R")) for name in names)
    result = {"mirror_mean": None, "mirror_max": None, "pairs": len(pairs),
              "unpaired": sided - 2 * len(pairs)}
    if not pairs:
        return result
    left, right = np.array(pairs).T
    ends = [np.asarray(heads, dtype=float), np.asarray(tails, dtype=float)]
    points_l = np.concatenate([end[left] for end in ends])
    points_r = np.concatenate([end[right] for end in ends])
    mirrored = points_l - 2.0 * (points_l @ normal - offset)[:, None] * normal
    distances = 100.0 * np.linalg.norm(mirrored - points_r, axis=1) / side
    result.update(mirror_mean=float(distances.mean()), mirror_max=float(distances.max()))
    return result
