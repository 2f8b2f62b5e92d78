"""Bone rolls of the bone plan (no `bpy`: plain pytest tests it): each bone's local Z axis,
one way along a whole chain and mirrored between the sides, and Blender's roll angle for it.

    side, up = rolls.skeleton_frame(positions, plane)
    reference = rolls.chain_reference(joints, side, up)       # one unit vector per chain
    z_axes = rolls.z_axes(heads, tails, reference, side, up)   # #B by 3, unit, normal to bones
    roll = rolls.blender_roll(head, tail, z_axis)              # EditBone.roll for that Z axis

A chain's reference is the direction its joints bend towards (from the chord between its
first and last joint to the joint farthest from it), so that each bone's Z axis lies in the
plane the limb bends in and the limb bends about the bones' X axes, as in Blender's own rigs;
a straight chain takes the skeleton's side axis crossed with the chain (for a leg: forward)
or, along the side axis itself (an arm held out), the skeleton's up axis. Each bone's Z axis
is the part of the reference normal to the bone. The planner gives a .R chain the mirror
image of its .L partner's reference and keeps a chain of the middle's reference in the
mirror plane, so paired bones' axes mirror: for the plane x = 0, roll_R = -roll_L, what
Blender's Symmetrize makes.
"""

import numpy as np

#: A chain is straight when no joint lies farther than this from its chord (in chord lengths).
STRAIGHT = 0.05
#: A bone within asin(PARALLEL) of its reference direction takes the previous bone's Z axis
#: (or the skeleton frame's) instead: the part normal to it would be noise.
PARALLEL = 0.2


def unit(vector):
    """vector / |vector| (the zero vector stays zero)."""
    length = float(np.linalg.norm(vector))
    return vector / length if length > 0 else vector


def _normal_part(vector, axis):
    """The part of `vector` normal to the unit `axis`."""
    return vector - (vector @ axis) * axis


def skeleton_frame(positions, plane=None):
    """(side, up): two unit axes of the skeleton (#N by 3 node positions) that straight chains
    take their roll from. side: the mirror plane's normal, else the nodes' axis of least
    spread; up: the nodes' axis of largest spread normal to it. Each with its largest
    component positive."""
    positions = np.asarray(positions, dtype=float).reshape(-1, 3)
    spread = np.linalg.svd(positions - positions.mean(axis=0))[2] if len(positions) > 1 \
        else np.eye(3)
    if len(spread) < 3:
        spread = np.eye(3)
    side = np.asarray(plane.normal, dtype=float) if plane is not None else spread[-1]
    up = next((unit(_normal_part(axis, side)) for axis in spread
               if np.linalg.norm(_normal_part(axis, side)) > 0.5), _any_normal(side))
    return _positive(side), _positive(up)


def _positive(axis):
    """`axis` or -axis, whichever has its largest component positive."""
    return axis if axis[np.argmax(np.abs(axis))] >= 0 else -axis


def _any_normal(axis):
    """A unit vector normal to the unit `axis`."""
    other = np.eye(3)[int(np.argmin(np.abs(axis)))]
    return unit(np.cross(axis, other))


def chain_reference(joints, side, up, plane=None):
    """The unit reference direction of a chain of joints (#J by 3, first to last): towards
    the joint farthest from the chord when that is more than STRAIGHT chord lengths away,
    else side x chord (up where the chord runs along the side axis). With `plane` (a chain of
    the middle) its part in the plane: then a self-mirrored bone's axes mirror themselves."""
    joints = np.asarray(joints, dtype=float).reshape(-1, 3)
    chord = joints[-1] - joints[0]
    if np.linalg.norm(chord) == 0 and len(joints) > 2:
        chord = joints[1] - joints[0]
    axis = unit(chord)
    reference = _straight_reference(axis, side, up)
    offsets = np.array([_normal_part(p - joints[0], axis) for p in joints[1:-1]]).reshape(-1, 3)
    if len(offsets):
        far = offsets[int(np.argmax(np.linalg.norm(offsets, axis=1)))]
        if np.linalg.norm(far) > STRAIGHT * np.linalg.norm(chord):
            reference = unit(far)
    if plane is not None:
        flat = _normal_part(reference, np.asarray(plane.normal, dtype=float))
        reference = unit(flat) if np.linalg.norm(flat) > PARALLEL else \
            _straight_reference(axis, side, up)
    return reference


def _straight_reference(axis, side, up):
    """side x axis, or where `axis` runs (nearly) along the side axis the part of up normal
    to it (side itself where both fail, for a zero axis)."""
    across = np.cross(side, axis)
    if np.linalg.norm(across) > PARALLEL:
        return unit(across)
    along_up = _normal_part(up, axis) if np.linalg.norm(axis) > 0 else side
    return unit(along_up) if np.linalg.norm(along_up) > 0 else side


def z_axes(heads, tails, reference, side, up):
    """#B by 3 unit Z axes of a chain's bones (heads, tails #B by 3, in chain order): the part
    of `reference` normal to each bone; for a bone within asin(PARALLEL) of it the previous
    bone's Z axis made normal to this one (the first bone: the skeleton frame's choice)."""
    heads, tails = np.asarray(heads, dtype=float), np.asarray(tails, dtype=float)
    result = np.zeros_like(heads)
    previous = None
    for b, (head, tail) in enumerate(zip(heads, tails)):
        along = unit(tail - head)
        choices = [reference] + ([previous] if previous is not None else [])
        z = next((_normal_part(c, along) for c in choices
                  if np.linalg.norm(_normal_part(c, along)) > PARALLEL), None)
        if z is None:
            z = _normal_part(_straight_reference(along, side, up), along)
        result[b] = previous = unit(z)
    return result


def roll_zero_axes(y_axis):
    """(x, z): the X and Z axes Blender gives a bone along the unit `y_axis` at roll 0 (the
    minimal rotation from +Y; Blender's vec_roll_to_mat3_normalized, its thresholds too)."""
    x, y, z = (float(c) for c in y_axis)
    theta, across = 1.0 + y, x * x + z * z
    if theta > 6.1e-3 or across > 2.5e-4 ** 2:
        if theta <= 6.1e-3:  # close to -Y: theta from x and z (Blender's series for sqrt)
            theta = across * 0.5 + across * across * 0.125
        return (np.array([1.0 - x * x / theta, -x, -x * z / theta]),
                np.array([-x * z / theta, -z, 1.0 - z * z / theta]))
    return np.array([-1.0, 0.0, 0.0]), np.array([0.0, 0.0, 1.0])  # along -Y


def blender_roll(head, tail, z_axis):
    """The roll (radians, -pi..pi) of Blender's bone from `head` to `tail` whose Z axis is
    (the part normal to the bone of) `z_axis`: the angle about the bone's Y axis from its
    roll-0 Z axis (roll_zero_axes) to z_axis."""
    y_axis = unit(np.asarray(tail, dtype=float) - np.asarray(head, dtype=float))
    x0, z0 = roll_zero_axes(y_axis)
    z_axis = np.asarray(z_axis, dtype=float)
    return float(np.arctan2(z_axis @ x0, z_axis @ z0))
