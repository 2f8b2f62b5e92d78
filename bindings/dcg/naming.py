"""Descriptive bone names (no `bpy`: plain pytest tests it): each limb's chain of bones is named
after what the limb is, so that an animator reads the rig in Blender's outliner.

    names = naming.chain_names(skeleton, chains, sides, plane, limb_points, degree)
    name_of = naming.namer()           # name_of("hind_leg", "L", pair, index) -> hind_leg.002.L

What a limb is follows from the skeleton's shape, not from a template. Up is the axis along
which the most ends stand on the ground (`up_axis`: +Z, Blender's, on ties; of a model turned
away from the axes, the direction in its mirror plane). On a shape with a mirror plane:

- a limb that ends at an end (a prong's tip) and pairs with its mirror image is a **leg** when
  its end stands on the ground (within GROUND of the skeleton's height above its lowest node),
  else an **arm**; several pairs of legs are numbered from the head outward (``leg1``, ``leg2``,
  ...), two pairs are ``front_leg`` and ``hind_leg``; FINGERS or more paired tips leaving one
  node off the plane are **finger**s (a hand's) or **toe**s (on the ground: a foot's);
- an unpaired limb that starts or ends on the plane and ends at an end is the **head** when
  its end is the highest of them off the ground, else a **tail** (``tail1``, ``tail2``, ...
  when several), or a **leg** when its end stands on the ground off the plane (two legs that
  the skeleton runs down between as one); an unpaired limb off the plane is a leg or an arm;
- a limb between two joints is the **spine** in the middle; on a side, it takes the name of
  the limbs it leads to when they share one (an arm's upper part before the fingers branch),
  else it is a **limb**; a link that closes a cycle is a **loop**.

A shape with no mirror plane has no sides to tell legs from arms by, or a head from a tail:
its tips are **limb**s (``limb1``, ``limb2``, ...), the rest the **spine**.

Bones are numbered along each name from the root outward (``spine.001``, ``spine.002``, ...),
and a pair's two chains share their numbers bone by bone with Blender's side suffixes
(``arm.003.L`` / ``arm.003.R``): what X-Axis Mirror, Symmetrize and Paste Pose Flipped pair.
Each bone's kind (end, joint, connection) stays in BoneSpec.kind.
"""

import numpy as np

from . import symmetry
from .rolls import unit

#: An end stands on the ground when it lies within this fraction of the skeleton's height
#: (along `up_axis`) above its lowest node: a leg's foot, not a hand or a wing tip.
GROUND = 0.15
#: Paired tips that leave one node off the mirror plane, at least this many: a hand's fingers
#: (or a foot's toes), not two limbs that fork.
FINGERS = 3
#: Up is an axis along which the skeleton spreads at least this fraction of its widest extent
#: (see `up_axis`).
SPREAD = 0.25
#: The up found from the shape gives way to the caller's when it is farther than this many
#: degrees from it (`scene_up`: upside down in the scene).
UPSIDE_DOWN = 135.0
#: An axis within this many degrees of the mirror plane may be up (a model built along the
#: axes); a plane turned farther from all of them is searched UP_CIRCLE directions around.
ALIGNED = 15.0
UP_CIRCLE = 24
#: The candidate up directions in order of preference when as many ends stand on the ground
#: along each: Blender's +Z, then +Y (OBJ's and glTF's up), then the rest.
UP_CANDIDATES = np.array([[0, 0, 1], [0, 1, 0], [1, 0, 0], [0, 0, -1], [0, -1, 0], [-1, 0, 0]],
                         dtype=float)


def up_axis(positions, ends, plane=None):
    """The skeleton's up (a unit 3-vector): of the candidates (`_up_candidates`), those along
    which the nodes (#N by 3 `positions`) spread at least SPREAD times as far as along the widest
    (not a T-pose's depth, where every end stands at the front), the one with the most of `ends`
    (node indices) standing on the ground at its bottom (within GROUND of the height); the first
    such on ties."""
    positions = np.asarray(positions, dtype=float).reshape(-1, 3)
    axes = _up_candidates(plane)
    heights = [positions @ axis for axis in axes]
    spans = [float(np.ptp(height)) for height in heights]
    best, best_score = axes[0], -1
    for axis, height, span in zip(axes, heights, spans):
        if span < SPREAD * max(spans):
            continue
        score = int((height[ends] <= height.min() + GROUND * span).sum())
        if score > best_score:
            best, best_score = axis, score
    return best


def scene_up(found, given, plane=None):
    """The up the names follow when the caller knows the model's (`given`, a 3-vector: the
    add-on's world +Z) and `up_axis` found `found` (unit): `found`, unless it points against
    `given` (more than UPSIDE_DOWN degrees from it), then `given` (turned into `plane`, which
    holds up). A model does not stand on its head in its scene: raised wings' tips make the
    top look like the ground (a flying wasp: its sting was named its head). A quarter turn is
    believed: an OFF file's Y-up model lies in a Blender scene, and its feet still name it."""
    given = unit(np.asarray(given, dtype=float).reshape(3))
    if float(found @ given) >= np.cos(np.radians(UPSIDE_DOWN)):
        return found
    if plane is not None:
        normal = np.asarray(plane.normal, dtype=float)
        given = given - (given @ normal) * normal
    return unit(given)


def _up_candidates(plane):
    """UP_CANDIDATES; with a mirror plane (up lies in it), those within ALIGNED of it, moved into
    it; when the plane is turned away from the axes (none is), UP_CIRCLE directions around it."""
    if plane is None:
        return list(UP_CANDIDATES)
    normal = np.asarray(plane.normal, dtype=float)
    axes = [axis - (axis @ normal) * normal for axis in UP_CANDIDATES
            if abs(float(axis @ normal)) <= np.sin(np.radians(ALIGNED))]
    if axes:
        return [axis / np.linalg.norm(axis) for axis in axes]
    first = UP_CANDIDATES[int(np.argmin(np.abs(UP_CANDIDATES @ normal)))]
    first = first - (first @ normal) * normal
    first /= np.linalg.norm(first)
    second = np.cross(normal, first)
    angles = np.linspace(0, 2 * np.pi, UP_CIRCLE, endpoint=False)
    return [np.cos(a) * first + np.sin(a) * second for a in angles]


def chain_names(skeleton, chains, sides, plane, limb_points, degree, up=None):
    """The name of each limb's chain (chains: dcg.bones.limbs; sides: (side, pair) per limb;
    plane: the plan's mirror plane or None; limb_points: each limb's joints, first to last, as
    planned; degree: the links at each node; up: the model's up when the caller knows it, else
    None: `up_axis`), as the module's text says; a .R limb gets its .L partner's name."""
    positions = np.asarray(skeleton.positions, dtype=float).reshape(-1, 3)
    starts = [limb[0][1] for limb in chains]
    ends = [limb[-1][2] for limb in chains]
    tips = [bool(limb[-1][3] and degree[end] == 1) for limb, end in zip(chains, ends)]
    loops = [not limb[0][3] for limb in chains]
    base, head = _base_names(positions, plane, sides, limb_points, starts, ends, tips, loops,
                             up)
    names = _numbered(positions, base, ends, tips, sides, head)
    _inherit(names, base, starts, ends, sides)
    for left, right in symmetry.partners(sides).items():
        names[right] = names[left]
    return names


def _base_names(positions, plane, sides, limb_points, starts, ends, tips, loops, up=None):
    """(each limb's name before numbering, the head's limb or None): see the module's text."""
    found = up_axis(positions, [end for end, tip in zip(ends, tips) if tip], plane)
    up = found if up is None else scene_up(found, up, plane)
    height = positions @ up
    grounded = height[ends] <= height.min() + GROUND * np.ptp(height)
    if plane is None:
        return ["loop" if loop else "limb" if tip else "spine"
                for tip, loop in zip(tips, loops)], None
    near = symmetry.tolerance(positions)
    last = np.array([np.asarray(points)[-1] for points in limb_points]).reshape(-1, 3)
    off_plane = np.abs(plane.signed(last)) > near
    middle = _middle(plane, near, limb_points, tips, sides)
    highest = [k for k in middle if not grounded[k]]
    head = max(highest, key=lambda k: height[ends[k]]) if highest else None
    fanned = _fanned(plane, near, positions, starts, tips, sides)
    base = []
    for k, (tip, loop, (side, _)) in enumerate(zip(tips, loops, sides)):
        if loop:
            base.append("loop")
        elif not tip:
            base.append("spine" if side is None else "limb")
        elif k == head:
            base.append("head")
        elif k in middle and not (grounded[k] and off_plane[k]):
            base.append("tail")
        elif fanned.get(starts[k], 0) >= FINGERS:
            base.append("toe" if grounded[k] else "finger")
        else:
            base.append("leg" if grounded[k] else "arm")
    return base, head


def _middle(plane, near, limb_points, tips, sides):
    """The tips of the middle: the unpaired tips that start or end on the mirror plane, within
    `near` of it (a tail; not a leg that did not pair, off the plane)."""
    return [k for k, (tip, (side, _)) in enumerate(zip(tips, sides))
            if tip and side is None
            and np.abs(plane.signed(np.asarray(limb_points[k])[[0, -1]])).min() <= near]


def _fanned(plane, near, positions, starts, tips, sides):
    """{node farther than `near` off the mirror plane: the paired tips that start there}."""
    fanned = {}
    for start, tip, (side, _) in zip(starts, tips, sides):
        if tip and side is not None and abs(plane.signed(positions[start])) > near:
            fanned[start] = fanned.get(start, 0) + 1
    return fanned


def _numbered(positions, base, ends, tips, sides, head):
    """The names from the base names: a tip's kind shared by several limbs (a pair counts once)
    numbered from the head outward (``leg1``, ``leg2``; two legs: ``front_leg``, ``hind_leg``)."""
    groups = {}
    for k, (name, tip, (side, _)) in enumerate(zip(base, tips, sides)):
        if tip and name != "head" and side != "R":
            groups.setdefault(name, []).append(k)
    names = list(base)
    for name, members in groups.items():
        if len(members) < 2:
            continue
        if head is not None:
            members = sorted(members, key=lambda k: float(np.linalg.norm(
                positions[ends[k]] - positions[ends[head]])))
        if name == "leg" and len(members) == 2 and head is not None \
                and all(sides[k][0] for k in members):
            labels = ["front_leg", "hind_leg"]
        else:
            labels = [f"{name}{i}" for i in range(1, len(members) + 1)]
        for k, label in zip(members, labels):
            names[k] = label
    return names


def _inherit(names, base, starts, ends, sides):
    """A side's limb between joints ("limb") takes the name of the limbs beyond it when they all
    have one (fingers and toes aside: the arm or leg they hang from), breadth-first outward so
    a chain of such limbs passes the name back to the body."""
    beyond = {}
    for k, start in enumerate(starts):
        beyond.setdefault(start, []).append(k)
    for k in reversed(range(len(base))):
        if base[k] != "limb" or sides[k][0] is None:
            continue
        below = [c for c in beyond.get(ends[k], []) if c != k]
        own = {names[c] for c in below if base[c] not in ("finger", "toe")}
        kinds = {base[c] for c in below}
        if len(own) == 1:
            names[k] = own.pop()
        elif not own and kinds and kinds <= {"finger", "toe"}:
            names[k] = "arm" if kinds == {"finger"} else "leg"


def namer():
    """name(chain, side, pair, index): the chain's name plus a counter per name (``spine.001``);
    for a limb with a side ("L"/"R") the side suffix too, the two limbs of a pair sharing their
    counters bone by bone (``arm.003.L`` / ``arm.003.R``)."""
    counters, waiting = {}, {}

    def name(chain, side=None, pair=-1, index=0):
        if side is None:
            counters[chain] = counters.get(chain, 0) + 1
            return f"{chain}.{counters[chain]:03d}"
        number = waiting.pop((pair, index, chain), None)
        if number is None:
            counters[chain, "sided"] = number = counters.get((chain, "sided"), 0) + 1
            if pair >= 0:
                waiting[pair, index, chain] = number
        return f"{chain}.{number:03d}.{side}"
    return name
