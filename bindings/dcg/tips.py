"""The rounded tip of a limb that ends at an end node (no `bpy`: plain pytest tests it;
`dcg.bones` plans with it).

    points = tips.straightened(points, radii)   # a limb's polyline, its tip on its own line

An end node is the centre of the last ball of a prong, inside its tip. Where the tip is flat or
blunt (a cylinder's cap, a stubby foot), the engine ends the link at one of many equally far
balls, in a corner of the cap, and the last stretch of the polyline turns off the limb's line
towards that corner. The end bone then pointed at the rim (SkinnedCylinder's two end bones
leant 16 degrees off its axis, one to each side). That stretch lies inside the rounded tip:
every point of it has the end node inside its own ball, so the shape gives it no direction of
its own. The plan runs it on along the limb's line instead.
"""

import numpy as np

from . import symmetry


def straightened(points, radii):
    """`points` (a limb's polyline, #P by 3, ending at its end node; radii #P: the skeleton
    radius at each point) with the points after the tip's base on the limb's line.

    The tip's base is the first point of the last run of points whose ball (radius radii)
    holds the end node. The limb's line runs through the base from the point at least the
    base's radius of arc before it. Each later point moves onto that line, as far along it
    as it lies (at least the base, at most the end node), so all of them stay inside the
    base's ball, and so inside the shape. A polyline that is all tip (a stub), or whose end
    node lies behind its base, is returned as it was.

    Over the 14 rigged characters (bone_detail 0.5): mean CD-J2J / J2B / B2B 3.578 / 2.297 /
    2.633 -> 3.503 / 2.185 / 2.596; SkinnedCylinder 2.797 / 1.550 / 0.615 -> 1.887 / 0.191 /
    0.154, its bones on its axis; worse only Q_Knight, CD-J2J +0.023 (its stubby feet lie in
    its shins' last balls, so their toes no longer turn forward) and Fox +0.006.
    """
    points = np.asarray(points, dtype=float)
    radii = np.asarray(radii, dtype=float)
    holds_end = np.linalg.norm(points - points[-1], axis=1) <= radii
    base = len(points) - 1
    while base > 0 and holds_end[base - 1]:
        base -= 1
    if base == 0 or base == len(points) - 1:
        return points
    arc = symmetry.arc_lengths(points)
    before = base - 1
    while before > 0 and arc[base] - arc[before] < radii[base]:
        before -= 1
    direction = points[base] - points[before]
    direction /= max(float(np.linalg.norm(direction)), 1e-300)
    along = (points[base + 1:] - points[base]) @ direction
    if along[-1] <= 0.0:
        return points
    result = points.copy()
    result[base + 1:] = points[base] + np.clip(along, 0.0, along[-1])[:, None] * direction
    return result
