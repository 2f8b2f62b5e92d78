"""Mirror symmetry of the bone plan (no `bpy`: plain pytest tests it): the pieces that
`dcg.bones.plan_bones` makes a mirror-symmetric plan with.

    plane = symmetry.skeleton_plane(skeleton)   # a Plane, or None: no symmetry, as before
    sides = symmetry.pair_limbs(plane, skeleton, limb_points, limb_ends)  # (side, pair)
    plane = symmetry.fitted_plane(plane, left, right, middle)   # refined on the pairs
    points = symmetry.settle(original, target, reach)   # joints moved toward their targets

The skeleton's plane is the best mirror plane of its nodes (`mirror_plane`, tolerant of small
asymmetries), else the shape's own when the surface mirrors itself closely (`shape_plane`: the
engine's Skeleton.mirror_plane), when it passes through the root. The limbs on either side
that mirror each other pair across it (`.L` / `.R`); the plan then mirrors across the shape's
own plane when the surface mirrors itself, else across the plane those pairs and the middle
fit best (`fitted_plane`: the nodes' plane is off by a degree or so, which would move every
joint of a long limb). The planner places the joints of a pair once, on the mean of one limb
and the mirror image of the other (`mean_polyline`), and gives the other limb their mirror
images; joints of the middle (unpaired limbs, the root) go onto the plane (`onto_plane`).
A joint only goes where it stays inside the mesh (a skeleton radius is the distance to the
surface): within MIRROR_REACH radii of its own limb's skeleton (`inside_tube`), or, for a
pair copied from its .L limb, where the shape's own mirror plane says its image lies deep
enough (`copies_inside`). A pair that can do neither moves at most MIRROR_REACH radii toward
its partner (`settle`) and mirrors only approximately, and a joint of the middle farther from
the plane stays where it is.
"""

from dataclasses import dataclass

import numpy as np

#: A mirror plane is accepted when the skeleton's nodes mirrored across it lie this close to
#: nodes (mean, in bounding-box diagonals); limbs' sides and pairs use the same tolerance.
MIRROR_TOLERANCE = 0.03
#: The shape's own mirror plane stands in for the nodes' when the surface mirrors itself across
#: it this closely (mean, in bounding-box diagonals): spot 0.0002, cow 0.0002; a scan in a pose
#: (armadillo 0.011) or a posed horse (0.04) is left to its nodes.
SHAPE_TOLERANCE = 0.005
#: A pair of limbs whose skeletons differ is made the .L one and its mirror image only when the
#: surface mirrors itself this closely (mean, in bounding-box diagonals): a modelled character
#: (Q_Dragon 0.000002, Mannequiny 0.0001), not a pose (Q_Zombie 0.0017; see copies_inside).
COPY_TOLERANCE = 0.001
#: How far from its own limb's skeleton a joint may go to mirror (inside_tube), and the farthest
#: it moves toward its mirror image or the plane when it cannot, in skeleton radii (the radius is
#: the distance to the surface: below 1 the joint stays inside the mesh).
MIRROR_REACH = 0.9
#: The plane fitted to the pairs replaces the nodes' only within acos(this) of it (25 deg).
FITTED_AGREEMENT = 0.9
#: Rounds of reweighting of the fitted plane (each weighs points by how far they are off).
FITTED_ROUNDS = 20


@dataclass(frozen=True)
class Plane:
    """The mirror plane normal . x = offset (normal a unit 3-vector; error as mirror_plane's)."""

    normal: np.ndarray
    offset: float
    error: float

    def signed(self, points):
        """#P signed distances of points (#P by 3) to the plane, positive on the .L side."""
        return np.asarray(points, dtype=float) @ self.normal - self.offset

    def reflect(self, points):
        """points (#P by 3, or one 3-vector) mirrored across the plane."""
        points = np.asarray(points, dtype=float)
        return points - 2.0 * self.signed(points)[..., None] * self.normal

    def reflect_direction(self, vectors):
        """Directions (#P by 3, or one 3-vector) mirrored: the normal's component flips."""
        vectors = np.asarray(vectors, dtype=float)
        return vectors - 2.0 * (vectors @ self.normal)[..., None] * self.normal

    def project(self, points):
        """points moved onto the plane along its normal."""
        points = np.asarray(points, dtype=float)
        return points - self.signed(points)[..., None] * self.normal


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


def tolerance(positions):
    """MIRROR_TOLERANCE in the skeleton's units (its nodes' bounding-box diagonal)."""
    return MIRROR_TOLERANCE * float(np.linalg.norm(np.ptp(positions, axis=0)))


def skeleton_plane(skeleton):
    """The skeleton's mirror plane (a Plane) when it has one: `mirror_plane` of its nodes with
    an error of at most MIRROR_TOLERANCE, else the shape's own plane (`shape_plane`), the root
    within MIRROR_TOLERANCE of it; else None."""
    positions = np.asarray(skeleton.positions, dtype=float).reshape(-1, 3)
    if not 0 <= skeleton.root < len(positions):
        return None
    found = mirror_plane(positions)
    if found is not None and found[2] <= MIRROR_TOLERANCE:
        plane = Plane(np.asarray(found[0], dtype=float), float(found[1]), float(found[2]))
    else:
        plane = shape_plane(skeleton)
    if plane is None or abs(plane.signed(positions[skeleton.root])) > tolerance(positions):
        return None
    return plane


def shape_plane(skeleton):
    """The mirror plane of the shape itself (the engine's Skeleton.mirror_plane, found on the
    surface: cpp/include/dcg/symmetry.h) when the shape mirrors itself across it within
    SHAPE_TOLERANCE, else None. An exactly symmetric shape can have a skeleton that is not (an
    end point on one of two horns, end balls placed a little differently on either side, as
    spot's): its limbs then pair across this plane instead of the nodes'."""
    error = float(getattr(skeleton, "mirror_error", 1.0))
    plane = np.asarray(getattr(skeleton, "mirror_plane", np.zeros(4)), dtype=float)
    if error > SHAPE_TOLERANCE or not np.isclose(np.linalg.norm(plane[:3]), 1.0):
        return None
    return Plane(plane[:3], float(plane[3]), error)


def copy_plane(skeleton):
    """shape_plane(skeleton) when the surface mirrors itself within COPY_TOLERANCE (a limb may
    then be made its partner's mirror image, copies_inside), else None."""
    plane = shape_plane(skeleton)
    return plane if plane is not None and plane.error <= COPY_TOLERANCE else None


def limb_sides(skeleton, limb_points, limb_ends=None):
    """Return (side, pair) per limb (limb_points: each limb's polyline points): side "L" or
    "R" for a limb paired with its mirror image across the skeleton's mirror plane
    (`skeleton_plane`), pair the pair's index; (None, -1) for the limbs of the middle,
    unpaired ones and every limb of a shape with no mirror plane. See `pair_limbs`."""
    return pair_limbs(skeleton_plane(skeleton), skeleton, limb_points, limb_ends)


def pair_limbs(plane, skeleton, limb_points, limb_ends=None):
    """`limb_sides` across `plane` (a Plane, or None: no pairs). Limbs whose centres lie
    farther than MIRROR_TOLERANCE from the plane pair with the one on the other side nearest
    to their mirror image (both ways, within twice the tolerance). With `limb_ends` (the node
    each limb ends at) two limbs pair only when those nodes are of one kind, so that their
    bones' names pair too (an arm that ends in a hand on one side and at a fingertip on the
    other is no mirror image of the other arm). Two limbs that start at one point off the plane
    do not pair (their first bones could not mirror each other: a rotated Q_Frog's hind legs
    both hang from one joint on its right side)."""
    none = [(None, -1)] * len(limb_points)
    if plane is None:
        return none
    near = tolerance(np.asarray(skeleton.positions, dtype=float).reshape(-1, 3))
    centres = np.array([np.mean(points, axis=0) for points in limb_points]).reshape(-1, 3)
    signed = plane.signed(centres)
    left, right = np.flatnonzero(signed > near), np.flatnonzero(signed < -near)
    if not len(left) or not len(right):
        return none
    gaps = np.linalg.norm(plane.reflect(centres[left])[:, None] - centres[right][None], axis=2)
    starts = np.array([points[0] for points in limb_points]).reshape(-1, 3)
    shared = (starts[left][:, None] == starts[right][None]).all(axis=2)  # one node
    gaps[shared & (np.abs(plane.signed(starts[left]))[:, None] > near)] = np.inf
    if limb_ends is not None:
        kinds = np.array([str(k) for k in skeleton.kinds])[np.asarray(limb_ends, dtype=int)]
        gaps[kinds[left][:, None] != kinds[right][None]] = np.inf
    result = list(none)
    for row, i in enumerate(left):
        column = int(gaps[row].argmin())
        if gaps[:, column].argmin() == row and gaps[row, column] <= 2 * near:
            result[i], result[right[column]] = ("L", row), ("R", row)
    return result


def more_pairs(sides, other):
    """`sides` (pair_limbs') with the pairs of `other` (the same limbs paired across another
    plane) whose two limbs `sides` left unpaired, numbered after its own."""
    result = list(sides)
    number = max([pair for _, pair in sides] + [-1]) + 1
    for pair in sorted({pair for _, pair in other if pair >= 0}):
        limbs = [k for k, (_, p) in enumerate(other) if p == pair]
        if all(result[k][0] is None for k in limbs):
            for k in limbs:
                result[k] = (other[k][0], number)
            number += 1
    return result


def pair_by_ends(plane, skeleton, limb_starts, limb_ends, tips, sides):
    """`sides` (pair_limbs') with more pairs on a shape that mirrors itself: two limbs that did
    not pair, end at end nodes of one kind off the plane that mirror each other and start at one
    node on the plane (or at two that mirror each other), all within MIRROR_TOLERANCE, pair
    though their paths differ (Q_Horse's front legs: one runs along the belly from the hips,
    its mirror image does not). The planner then gives the .R limb the mirror image of the .L
    one where the shape allows (copies_inside). The .L limb is the one on the normal's side.
    tips: per limb, whether its end node has degree 1."""
    positions = np.asarray(skeleton.positions, dtype=float).reshape(-1, 3)
    near = tolerance(positions)
    kinds = np.array([str(k) for k in skeleton.kinds])
    free = [k for k, (side, _) in enumerate(sides) if side is None
            and tips[k] and kinds[limb_ends[k]] == "end"
            and abs(plane.signed(positions[limb_ends[k]])) > near]
    result = list(sides)
    pair = max([number for _, number in sides] + [-1]) + 1
    for a in (k for k in free if plane.signed(positions[limb_ends[k]]) > 0):
        image = plane.reflect(positions[[limb_ends[a], limb_starts[a]]])
        best = None
        for b in (k for k in free if result[k][0] is None and k != a):
            end_gap = np.linalg.norm(image[0] - positions[limb_ends[b]])
            start_gap = (abs(plane.signed(positions[limb_starts[a]]))
                         if limb_starts[a] == limb_starts[b]
                         else np.linalg.norm(image[1] - positions[limb_starts[b]]))
            if end_gap <= near and start_gap <= near and (
                    best is None or end_gap < best[0]):
                best = (end_gap, b)
        if best is not None:
            result[a], result[best[1]] = ("L", pair), ("R", pair)
            pair += 1
    return result


def arc_lengths(points):
    """#P: each point's arc length along the polyline `points` (#P by 3), from its first."""
    return np.concatenate([[0.0], np.cumsum(np.linalg.norm(np.diff(points, axis=0), axis=1))])


def arc_fractions(points):
    """#P: each point's arc length along the polyline `points`, over the whole (0 to 1)."""
    arc = arc_lengths(points)
    return arc / arc[-1] if arc[-1] > 0 else np.linspace(0.0, 1.0, len(points))


def resample(values, at, where):
    """values (#P, or #P by k) given at the increasing fractions `at`, linear at `where`."""
    values = np.asarray(values, dtype=float)
    if values.ndim == 1:
        return np.interp(where, at, values)
    return np.stack([np.interp(where, at, column) for column in values.T], axis=1)


def nearest_fractions(plane, points_l, points_r):
    """#P_L: for each point of the .L limb (points_l #P_L by 3), the fraction of arc length
    along the .R limb (points_r) of the point nearest to its mirror image across `plane`,
    never decreasing along the limb, 0 and 1 at its two ends (its nodes)."""
    t, distance = _on_segments(plane.reflect(points_l), points_r)
    segment = distance.argmin(axis=1)
    at_r = arc_fractions(points_r)
    where = at_r[segment] + t[np.arange(len(points_l)), segment] * np.diff(at_r)[segment]
    where[0], where[-1] = 0.0, 1.0
    return np.maximum.accumulate(where)


def mean_polyline(plane, left, right, where):
    """The mean of a pair of limbs: (points, radii) at the .L limb's points, each the midpoint
    of the .L limb's point and the mirror image of the .R limb's point at the fraction of arc
    length `where` (#P_L) along it, radii the mean of the two. left, right: (points #P by 3,
    radii #P) of each limb, from the node nearer the root."""
    (points_l, radii_l), (points_r, radii_r) = left, right
    at_r = arc_fractions(points_r)
    mirrored = plane.reflect(resample(points_r, at_r, where))
    return (points_l + mirrored) / 2.0, (radii_l + resample(radii_r, at_r, where)) / 2.0


def fitted_plane(plane, limb_pairs, middle):
    """The plane that paired limbs mirror each other across and the middle's points lie on,
    fitted robustly (least absolute deviations, by iteratively reweighted least squares) so
    that most points mirror exactly and a limb that is no mirror image of its partner (an
    arm raised on one side) does not tilt the plane: FITTED_ROUNDS rounds from `plane` (the
    skeleton's) of matching each .L limb's points with the nearest points of the mirrored .R
    limb (`nearest_fractions`), then a normal from the directions from each .R point to its
    .L point (each a vote, weighted by 1 / its angle to the normal, less for points near the
    plane, whose direction says little) and an offset from the pairs' midpoints and the
    middle's points (weighted by 1 / their distance to the plane). limb_pairs: [(points_l,
    points_r)] #P by 3 each, middle: #M by 3. `plane` when there are no pairs, or where the
    fit turns more than acos(FITTED_AGREEMENT) away from it."""
    if not limb_pairs:
        return plane
    middle = np.asarray(middle, dtype=float).reshape(-1, 3)
    everything = np.concatenate([np.concatenate(pair) for pair in limb_pairs] + [middle])
    floor = 1e-9 * max(float(np.linalg.norm(np.ptp(everything, axis=0))), 1e-300)
    fitted = plane
    for _ in range(FITTED_ROUNDS):
        left, right = _matching_points(fitted, limb_pairs)
        normal = _voted_normal(left - right, fitted.normal, floor)
        if normal @ plane.normal < FITTED_AGREEMENT:  # the pairs do not say where it is
            return plane
        centres = np.concatenate([(left + right) / 2.0, middle]) @ normal
        weights = 1.0 / np.maximum(np.abs(centres - fitted.offset), floor)
        fitted = Plane(normal, float(np.sum(weights * centres) / np.sum(weights)), plane.error)
    return fitted


def _voted_normal(differences, normal, floor):
    """The unit direction the rows of `differences` (#P by 3) agree on, on the side of
    `normal` (the last estimate): their first singular vector, each row made a unit vote
    weighted by 1 / its angle to `normal` and by its length over the median (at most 1)."""
    length = np.linalg.norm(differences, axis=1)
    use = length > floor
    if not use.any():
        return normal
    votes = differences[use] / length[use, None]
    votes *= np.where(votes @ normal < 0, -1.0, 1.0)[:, None]
    angle = np.linalg.norm(votes - (votes @ normal)[:, None] * normal, axis=1)
    weight = np.minimum(length[use] / np.median(length[use]), 1.0) / np.maximum(angle, 1e-9)
    result = np.linalg.svd(votes * np.sqrt(weight)[:, None], full_matrices=False)[2][0]
    return result if result @ normal >= 0 else -result


def _matching_points(plane, limb_pairs):
    """(left, right) #P by 3: each .L limb's points and the .R limb's matching ones across
    `plane` (nearest_fractions), all pairs one after the other."""
    left, right = [], []
    for points_l, points_r in limb_pairs:
        where = nearest_fractions(plane, points_l, points_r)
        left.append(points_l)
        right.append(resample(points_r, arc_fractions(points_r), where))
    return np.concatenate(left), np.concatenate(right)


def partners(sides):
    """{i: j} for each pair of limbs (sides: pair_limbs' (side, pair) per limb), i the .L limb
    and j its .R partner."""
    right = {pair: j for j, (side, pair) in enumerate(sides) if side == "R"}
    return {i: right[pair] for i, (side, pair) in enumerate(sides)
            if side == "L" and pair in right}


def node_partners(node_pairs):
    """{node: partner} of `node_pairs` ((a, b): the nodes two paired limbs start or end at, in
    order of priority; a node both limbs share is its own partner). A node keeps its first
    partner: a later pair that would give it another is left out."""
    partner = {}
    for a, b in node_pairs:
        if a not in partner and b not in partner:
            partner[a], partner[b] = b, a
    return partner


def inside_tube(points, line, radii, reach=MIRROR_REACH):
    """#P booleans: whether each of `points` (#P by 3) lies within `reach` x the radius of a
    limb's polyline (line #Q by 3, radii #Q, the radius linear along each segment) from it: in
    the tube of skeleton balls along the limb, so inside the mesh for reach < 1 (a radius is the
    distance to the surface)."""
    points = np.asarray(points, dtype=float).reshape(-1, 3)
    line, radii = np.asarray(line, dtype=float), np.asarray(radii, dtype=float)
    if len(line) < 2:
        return np.linalg.norm(points - line[0], axis=1) <= reach * radii[0]
    t, distance = _on_segments(points, line)
    radius = radii[:-1][None] * (1.0 - t) + radii[1:][None] * t
    return (distance <= reach * radius).any(axis=1)


def _on_segments(points, line):
    """(t, distance), each #P by #S: where the point of each segment of the polyline `line`
    (#S + 1 by 3) nearest to each of `points` (#P by 3) lies along it (0 at its start, 1 at its
    end), and how far it is."""
    heads, step = line[:-1], np.diff(line, axis=0)
    length2 = np.einsum("sa,sa->s", step, step)
    along = np.einsum("psa,sa->ps", points[:, None] - heads[None], step)
    t = np.clip(np.divide(along, length2, out=np.zeros_like(along), where=length2 > 0), 0, 1)
    return t, np.linalg.norm(points[:, None] - (heads[None] + t[..., None] * step), axis=2)


def copies_inside(plane, shape, diagonal, points, depths):
    """#P booleans: whether the mirror images across `plane` of `points` (#P by 3, each `depths`
    deep inside the shape) lie inside the shape too, as far as the shape's own mirror plane
    tells (`shape`: shape_plane's; all False without one, or when the surface mirrors itself
    less closely than COPY_TOLERANCE: a pose or a scan, whose limbs may differ more than the
    mean says). The shape mirrors itself across `shape` within shape.error x `diagonal` (its
    bounding-box diagonal), so an image across it is about as deep as its point; across `plane`
    it lies farther off by the gap between the two images. True where that gap plus the
    shape's error is at most MIRROR_REACH x the depth."""
    points = np.asarray(points, dtype=float).reshape(-1, 3)
    if shape is None or shape.error > COPY_TOLERANCE:
        return np.zeros(len(points), dtype=bool)
    gap = np.linalg.norm(plane.reflect(points) - shape.reflect(points), axis=1)
    return gap + shape.error * diagonal <= MIRROR_REACH * np.asarray(depths, dtype=float)


def onto_plane(plane, points, reach):
    """points (#J by 3) projected onto the plane where that moves them at most `reach` (#J);
    the others stay where they are (a limb off to one side is no part of the middle)."""
    points = np.asarray(points, dtype=float)
    close = np.abs(plane.signed(points)) <= np.asarray(reach, dtype=float)
    return np.where(close[..., None], plane.project(points), points)


def settle(original, target, reach):
    """The joints (#J by 3) moved from `original` to `target`, each at most `reach` (#J) far:
    one farther away stops that far along the way there."""
    original, target = np.asarray(original, dtype=float), np.asarray(target, dtype=float)
    step = target - original
    distance = np.linalg.norm(step, axis=-1)
    limit = np.asarray(reach, dtype=float)
    scale = np.divide(limit, distance, out=np.ones_like(distance), where=distance > limit)
    return original + step * scale[..., None]
