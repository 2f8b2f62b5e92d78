"""Triangle meshes that stand for bones and nodes, and camera framing (no `bpy`).

Used by the preview (viewport) and by the CLI's render, where armatures are invisible.
"""

import numpy as np


def icosphere(subdivisions=1):
    """Return (V #V by 3, F #F by 3) of a unit icosphere."""
    t = (1.0 + 5.0 ** 0.5) / 2.0
    vertices = [(-1, t, 0), (1, t, 0), (-1, -t, 0), (1, -t, 0), (0, -1, t), (0, 1, t),
                (0, -1, -t), (0, 1, -t), (t, 0, -1), (t, 0, 1), (-t, 0, -1), (-t, 0, 1)]
    faces = [(0, 11, 5), (0, 5, 1), (0, 1, 7), (0, 7, 10), (0, 10, 11), (1, 5, 9), (5, 11, 4),
             (11, 10, 2), (10, 7, 6), (7, 1, 8), (3, 9, 4), (3, 4, 2), (3, 2, 6), (3, 6, 8),
             (3, 8, 9), (4, 9, 5), (2, 4, 11), (6, 2, 10), (8, 6, 7), (9, 8, 1)]
    vertices = [np.array(v, dtype=float) / np.linalg.norm(v) for v in vertices]
    for _ in range(subdivisions):
        midpoint = {}
        refined = []
        for a, b, c in faces:
            ab, bc, ca = (_midpoint(vertices, midpoint, i, j) for i, j in ((a, b), (b, c),
                                                                             (c, a)))
            refined += [(a, ab, ca), (b, bc, ab), (c, ca, bc), (ab, bc, ca)]
        faces = refined
    return np.array(vertices), np.array(faces, dtype=np.int64)


def _midpoint(vertices, cache, i, j):
    """Return the index of the unit-length midpoint of edge (i, j), adding it once."""
    key = (min(i, j), max(i, j))
    if key not in cache:
        m = vertices[i] + vertices[j]
        vertices.append(m / np.linalg.norm(m))
        cache[key] = len(vertices) - 1
    return cache[key]


def spheres(centers, radii, subdivisions=1):
    """Return (V, F) of one icosphere per center (#C by 3) with radius radii (#C)."""
    unit_v, unit_f = icosphere(subdivisions)
    centers = np.asarray(centers, dtype=float).reshape(-1, 3)
    radii = np.broadcast_to(np.asarray(radii, dtype=float), (len(centers),))
    V = (centers[:, None, :] + radii[:, None, None] * unit_v[None]).reshape(-1, 3)
    F = (np.arange(len(centers))[:, None, None] * len(unit_v) + unit_f[None]).reshape(-1, 3)
    return V, F


def octahedral_bones(heads, tails, widths):
    """Return (V, F) of Blender-like octahedral bone shapes (6 vertices, 8 faces each).

    heads, tails  #B by 3; widths  #B half-widths of the square at a tenth of the length.
    """
    heads = np.asarray(heads, dtype=float).reshape(-1, 3)
    tails = np.asarray(tails, dtype=float).reshape(-1, 3)
    widths = np.broadcast_to(np.asarray(widths, dtype=float), (len(heads),))
    axis = tails - heads
    length = np.maximum(np.linalg.norm(axis, axis=1), 1e-300)
    direction = axis / length[:, None]
    helper = np.where(np.abs(direction[:, [2]]) < 0.9, [[0.0, 0.0, 1.0]], [[1.0, 0.0, 0.0]])
    u = np.cross(direction, helper)
    u /= np.linalg.norm(u, axis=1, keepdims=True)
    v = np.cross(direction, u)
    ring = heads + 0.1 * axis
    V = np.stack([heads,
                  ring + widths[:, None] * u, ring + widths[:, None] * v,
                  ring - widths[:, None] * u, ring - widths[:, None] * v,
                  tails], axis=1).reshape(-1, 3)
    one = np.array([(0, 2, 1), (0, 3, 2), (0, 4, 3), (0, 1, 4),
                    (5, 1, 2), (5, 2, 3), (5, 3, 4), (5, 4, 1)], dtype=np.int64)
    F = (np.arange(len(heads))[:, None, None] * 6 + one[None]).reshape(-1, 3)
    return V, F


def frame_camera(bbox_min, bbox_max, fov, view_direction=(1.0, -1.6, 0.8), margin=1.1):
    """Return (camera location, unit view direction) that shows the whole box.

    The camera looks along -view_direction at the box center from the distance where the
    box's bounding sphere fits a cone of angle `fov` (radians), times `margin`.
    """
    bbox_min, bbox_max = np.asarray(bbox_min, float), np.asarray(bbox_max, float)
    center = (bbox_min + bbox_max) / 2.0
    radius = max(float(np.linalg.norm(bbox_max - bbox_min)) / 2.0, 1e-9)
    direction = np.asarray(view_direction, dtype=float)
    direction /= np.linalg.norm(direction)
    distance = margin * radius / np.sin(fov / 2.0)
    return center + distance * direction, -direction
