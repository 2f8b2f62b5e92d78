"""Vertex weights in numpy (no `bpy`: plain pytest can test this).

Weights are sparse triplets: `rows` (vertex indices), `cols` (bone indices) and `values`,
as read from or written to Blender's vertex groups.
"""

import numpy as np

MAX_INFLUENCES = 4


def segment_distances(points, heads, tails):
    """Return (#P by #B distances, #P by #B parameters t in [0, 1]) from points to bones.

    points  #P by 3, heads and tails  #B by 3.
    """
    axis = tails - heads
    length2 = np.maximum(np.einsum("ij,ij->i", axis, axis), 1e-300)
    rel = points[:, None, :] - heads[None, :, :]
    t = np.clip(np.einsum("pbj,bj->pb", rel, axis) / length2, 0.0, 1.0)
    nearest = heads[None, :, :] + t[..., None] * axis[None, :, :]
    return np.linalg.norm(points[:, None, :] - nearest, axis=2), t


def envelope_weights(points, heads, tails, head_radii, tail_radii,
                     max_influences=MAX_INFLUENCES, chunk=2048):
    """Return sparse weights (rows, cols, values) of `points` to bones by envelope distance.

    Each bone is a capsule whose radius goes from its head radius to its tail radius (the
    skeleton's distance to the surface), but never less than the bone's distance to its
    nearest point: on a coarse mesh the faces pass closer to an end point than any vertex
    does, and a tip vertex several radii from its own bone went to the wider bones around it
    (posing the bone then left its own tip in place). A point's distance to a bone is
    measured in units of that radius, q = d / r, and weighted 1 / q^4 over its
    `max_influences` nearest bones, then normalized. Never fails: every point gets weights
    summing to 1.

    points  #P by 3, heads/tails  #B by 3, head_radii/tail_radii  #B.
    """
    points = np.asarray(points, dtype=float).reshape(-1, 3)
    heads = np.asarray(heads, dtype=float).reshape(-1, 3)
    tails = np.asarray(tails, dtype=float).reshape(-1, 3)
    scale = max(float(np.linalg.norm(np.ptp(np.vstack([heads, tails]), axis=0))), 1e-12)
    head_radii = np.maximum(np.asarray(head_radii, dtype=float), 1e-3 * scale)
    tail_radii = np.maximum(np.asarray(tail_radii, dtype=float), 1e-3 * scale)
    keep = min(max_influences, len(heads))
    nearest_point = np.full(len(heads), np.inf)
    for begin in range(0, len(points), chunk):
        distance, _ = segment_distances(points[begin:begin + chunk], heads, tails)
        nearest_point = np.minimum(nearest_point, distance.min(axis=0, initial=np.inf))
    reach = np.where(np.isfinite(nearest_point), nearest_point, 0.0)
    head_radii = np.maximum(head_radii, reach)
    tail_radii = np.maximum(tail_radii, reach)
    rows, cols, values = [], [], []
    for begin in range(0, len(points), chunk):
        block = points[begin:begin + chunk]
        distance, t = segment_distances(block, heads, tails)
        radius = head_radii[None, :] + t * (tail_radii - head_radii)[None, :]
        q = np.maximum(distance / radius, 1e-3)
        nearest = np.argsort(q, axis=1, kind="stable")[:, :keep]
        weight = np.take_along_axis(q, nearest, axis=1) ** -4.0
        weight /= weight.sum(axis=1, keepdims=True)
        rows.append(np.repeat(np.arange(begin, begin + len(block)), keep))
        cols.append(nearest.ravel())
        values.append(weight.ravel())
    if not rows:
        return np.zeros(0, np.int64), np.zeros(0, np.int64), np.zeros(0)
    return np.concatenate(rows), np.concatenate(cols), np.concatenate(values)


def weight_sums(rows, values, count):
    """Return the #count per-vertex sums of sparse weights."""
    return np.bincount(rows, weights=values, minlength=count)


def normalize_and_prune(rows, cols, values, max_influences=MAX_INFLUENCES):
    """Return sparse weights with at most `max_influences` per vertex, summing to 1.

    Zero and negative weights are dropped; vertices without positive weights stay absent.
    """
    rows, cols, values = (np.asarray(a) for a in (rows, cols, values))
    positive = values > 0
    rows, cols, values = rows[positive], cols[positive], values[positive]
    order = np.lexsort((-values, rows))
    rows, cols, values = rows[order], cols[order], values[order]
    first = np.searchsorted(rows, rows, side="left")
    keep = np.arange(len(rows)) - first < max_influences
    rows, cols, values = rows[keep], cols[keep], values[keep]
    sums = np.bincount(rows, weights=values, minlength=int(rows.max()) + 1 if len(rows) else 0)
    return rows, cols, values / sums[rows]
