"""Junctions of the bone plan that the engine put off a mirror plane (no `bpy`: plain pytest
tests it; `dcg.bones` plans with it).

    skeleton = junctions.onto_plane(skeleton, plane, chains, sides)   # the same, or a view

Two limbs whose ends mirror each other (a frog's hind legs) can hang from one joint node that
the engine placed off the mirror plane, by one of the two hips: then one leg leaves it
straight down and the other runs across the back, over the plane, to its own hip. Their first
bones cannot mirror each other, so they did not pair (no .L / .R names, and the add-on warned
of them: Q_Frog). The plan moves such a node to where the crossing limb meets the plane:
both limbs then start on the plane, one over the other's first stretch reflected, and pair.
A limb of the middle may leave the node as well (Q_Goblin's head, under a noise of 1e-5 of its
diagonal, from a chest joint 0.26 off the plane with both arms): it then starts there too.
The crossing limb may cross in a later link than its first (Q_Frog under another such noise:
its hips' joint 0.7 off the plane, the leg's first link up to a connection node of the back,
the second across): the links before the crossing then shrink to the new point.
"""

import types

import numpy as np

from . import symmetry
from .skeleton import measured_polyline_radii


def onto_plane(skeleton, plane, chains, sides):
    """`skeleton`, or a view of it (the attributes `dcg.bones` reads) in which each junction
    that qualifies (`_crossing`) lies where its crossing limb meets `plane`: that limb's link
    that crosses starts there (the links before it, if any, shrink to that point, their nodes
    with them), the other limb's first link starts there and runs through the old
    node, a limb of the middle that leaves the node too starts there instead, and the link
    arriving at the node ends there, its last points that lie off the plane (farther than
    symmetry.tolerance) dropped. chains: dcg.bones.limbs(skeleton);
    sides: (side, pair) per limb, as dcg.bones plans them."""
    positions = np.asarray(skeleton.positions, dtype=float).reshape(-1, 3)
    links = np.asarray(skeleton.links, dtype=np.int64).reshape(-1, 2)
    degree = np.bincount(links.ravel(), minlength=len(positions))
    near = symmetry.tolerance(positions)
    moves = [move for node in np.flatnonzero(degree >= 3)
             if (move := _crossing(plane, skeleton, chains, sides, int(node), degree, near))]
    if not moves:
        return skeleton
    view = _view(skeleton)
    for node, crossing, other, arriving, middle in moves:
        _move(view, plane, node, crossing, other, arriving, middle, near)
    return view


def _crossing(plane, skeleton, chains, sides, node, degree, near):
    """(node, the crossing limb's links up to the one that crosses as (link, its first node),
    the other limb's first link, the arriving link, the first links of the limbs of the middle)
    when two unpaired limbs leave `node`, off the plane, for ends that mirror each other within
    `near`, one link arrives at it along the skeleton's tree, and exactly one of the two
    crosses the plane; else None. Other limbs may leave it for ends on the plane (Q_Goblin's
    head, from its chest)."""
    positions = np.asarray(skeleton.positions, dtype=float).reshape(-1, 3)
    side = plane.signed(positions[node])
    if abs(side) <= near:
        return None
    leaving = [limb for limb, (limb_side, _) in zip(chains, sides)
               if limb[0][1] == node and limb_side is None and degree[limb[-1][2]] == 1]
    off = [abs(plane.signed(positions[limb[-1][2]])) > near for limb in leaving]
    middle = [limb[0][0] for limb, away in zip(leaving, off) if not away]
    leaving = [limb for limb, away in zip(leaving, off) if away]
    arriving = [limb[-1][0] for limb in chains if limb[-1][2] == node and limb[-1][3]]
    if len(leaving) != 2 or len(arriving) != 1 or degree[node] != 3 + len(middle):
        return None
    ends = positions[[limb[-1][2] for limb in leaving]]
    if np.linalg.norm(plane.reflect(ends[0]) - ends[1]) > near:
        return None
    crosses = [_crosses_at(plane, skeleton, limb, side) for limb in leaving]
    if sum(at is not None for at in crosses) != 1:
        return None
    first = 0 if crosses[0] is not None else 1
    crossing, other, at = leaving[first], leaving[1 - first], crosses[first]
    steps = [(link, start) for link, start, _, _ in crossing[:at + 1]]
    return node, steps, other[0][0], arriving[0], middle


def _crosses_at(plane, skeleton, limb, side):
    """The index in `limb` of its first link that reaches the other side of the plane than
    `side` (the signed distance of the limb's first node), None when none does."""
    for index, (link, start, _, _) in enumerate(limb):
        if (np.sign(plane.signed(_from(skeleton, link, start))) != np.sign(side)).any():
            return index
    return None


def _from(skeleton, link, node):
    """The polyline of `link` starting at `node` (#P by 3)."""
    polyline = np.asarray(skeleton.polylines[link], dtype=float).reshape(-1, 3)
    return polyline if int(skeleton.links[link][0]) == node else polyline[::-1]


def _view(skeleton):
    """A copy of what dcg.bones reads of `skeleton`, its arrays its own."""
    radii = measured_polyline_radii(skeleton)
    return types.SimpleNamespace(
        positions=np.array(skeleton.positions, dtype=float).reshape(-1, 3),
        kinds=np.asarray(skeleton.kinds), links=np.asarray(skeleton.links, dtype=np.int64),
        polylines=[np.array(p, dtype=float).reshape(-1, 3) for p in skeleton.polylines],
        polyline_radii=None if radii is None else [np.array(r, dtype=float) for r in radii],
        root=skeleton.root, radii=np.array(skeleton.radii, dtype=float),
        mirror_plane=getattr(skeleton, "mirror_plane", np.zeros(4)),
        mirror_error=getattr(skeleton, "mirror_error", 1.0))


def _move(view, plane, node, crossing, other, arriving, middle, near):
    """Move `node` of the view onto the plane where the last of the `crossing` links meets it
    (see onto_plane); the links before it shrink to that point, their nodes with them; link
    `other` then starts there and runs through the old node, and the links in `middle` start
    there instead of at the old node."""
    link, start = crossing[-1]
    points, radii = _link(view, link, start)
    signed = plane.signed(points)
    i = int(np.flatnonzero(np.sign(signed[1:]) != np.sign(plane.signed(view.positions[node])))
            [0])  # the segment i, i + 1
    t = signed[i] / (signed[i] - signed[i + 1])
    point = points[i] + t * (points[i + 1] - points[i])
    radius = radii[i] + t * (radii[i + 1] - radii[i])
    _set_link(view, link, start, np.vstack([point, points[i + 1:]]),
              np.concatenate([[radius], radii[i + 1:]]))
    for link, start in crossing[:-1]:  # the stretch on the node's side: now a point
        _set_link(view, link, start, np.vstack([point, point]), np.array([radius, radius]))
        stop = int(view.links[link][1] if int(view.links[link][0]) == start else
                   view.links[link][0])
        view.positions[stop], view.radii[stop] = point, radius
    points, radii = _link(view, other, node)
    _set_link(view, other, node, np.vstack([point, points]), np.concatenate([[radius], radii]))
    for link in middle:  # from the new point on, the old one left out
        points, radii = _link(view, link, node)
        _set_link(view, link, node, np.vstack([point, points[1:]]),
                  np.concatenate([[radius], radii[1:]]))
    points, radii = _link(view, arriving, node)  # from the node back to where it came from
    on_plane = np.flatnonzero(np.abs(plane.signed(points[1:-1])) <= near)
    first = 1 + int(on_plane[0]) if len(on_plane) else len(points) - 1
    _set_link(view, arriving, node, np.vstack([point, points[first:]]),
              np.concatenate([[radius], radii[first:]]))
    view.positions[node] = point
    view.radii[node] = radius


def _link(view, link, node):
    """(points, radii) of `link` from `node`; radii from the view's measured ones, else its
    nodes' radii linear in arc length."""
    forward = int(view.links[link][0]) == node
    points = view.polylines[link] if forward else view.polylines[link][::-1]
    measured = None if view.polyline_radii is None else view.polyline_radii[link]
    if measured is None or len(measured) != len(points):
        ends = view.radii[view.links[link]]
        at = symmetry.arc_fractions(view.polylines[link])
        measured = ends[0] + at * (ends[1] - ends[0])
    radii = np.asarray(measured, dtype=float)
    return points, radii if forward else radii[::-1]


def _set_link(view, link, node, points, radii):
    """Store (points, radii), given from `node`, as `link`'s polyline in its own direction."""
    forward = int(view.links[link][0]) == node
    view.polylines[link] = points if forward else points[::-1]
    if view.polyline_radii is not None:
        view.polyline_radii[link] = radii if forward else radii[::-1]
