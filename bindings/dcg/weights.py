"""Skinning weights (stage 9): bone heat on the input mesh itself, for the input's vertices.

    import dcg
    V, F = dcg.load_mesh("hand.obj")
    skeleton = dcg.extract_skeleton(V, F)
    weights = dcg.skin_weights(V, F, skeleton)            # the bones of dcg.bones.plan_bones
    rows, cols, values = weights                           # sparse triplets (numpy)
    W = weights.dense()                                    # #V x #B, rows sum to 1

    # a bone plan (any objects with .head and .tail), or explicit heads and tails:
    weights = dcg.skin_weights(V, F, dcg.bones.plan_bones(skeleton, bone_detail=1.0))
    weights = dcg.skin_weights(V, F, heads, tails, max_influences=4)

    # a large input (more than 2.5 x target_faces faces) is solved on stage 0's working mesh:
    # reuse an Extractor's instead of running stage 0 again (ignored for other inputs)
    ex = dcg.Extractor(V, F)
    weights = dcg.skin_weights(V, F, heads, tails, prepared=ex.prepare())

Bones are segments in the mesh's own coordinates (Blender: world space when V is). Every vertex
gets between 1 and max_influences weights, positive and summing to 1, whatever the mesh: open,
several parts (each weighted by the bones it sees, as Blender's bone heat does), non-manifold,
at any scale (the work is done in normalized units). See cpp/include/dcg/weights.h.
"""

from __future__ import annotations

from typing import Callable, Optional, Tuple

import numpy as np

from . import _core
from .bones import bone_arrays, deforms, plan_bones
from .options import normalize_options

#: Per-vertex bone weights as sparse triplets (rows, cols: int64; values: float64), sorted by
#: vertex then decreasing weight, with the counts of what happened (cpp/include/dcg/weights.h).
#: Unpacks as (rows, cols, values); dense() is the #V x #B matrix.
SkinWeights = _core.SkinWeights


def _points(name, array) -> np.ndarray:
    try:
        array = np.ascontiguousarray(array, dtype=np.float64)
    except (TypeError, ValueError) as error:
        raise ValueError(f"{name} must be a #B x 3 array of numbers: {error}") from None
    if array.ndim == 1 and array.size == 3:
        array = array.reshape(1, 3)
    if array.ndim != 2 or array.shape[1] != 3:
        raise ValueError(f"{name} must be a #B x 3 array of points, got shape {array.shape}")
    return array


def _bones(bones, tails, parents=None, deform=None):
    """Heads, tails, parents (None: found from the bones' ends) and deform flags (None: all
    deform) from (heads, tails) arrays, a Skeleton or a list of bone objects (with .parent, a
    name of another, when they have it; with .kind, a "root" bone deforms nothing)."""
    if tails is not None:
        heads, tails = _points("heads", bones), _points("tails", tails)
    elif hasattr(bones, "polylines") and hasattr(bones, "links"):
        plan = bone_arrays(plan_bones(bones))
        heads, tails, parents = plan["heads"], plan["tails"], plan["parents"]
        deform = deforms(plan["kinds"])
    else:
        try:
            items = list(bones)
        except TypeError:
            raise ValueError("bones must be a Skeleton, a list of bones with .head and .tail, "
                             "or heads with tails") from None
        if items and all(hasattr(b, "head") and hasattr(b, "tail") for b in items):
            heads = _points("heads", [np.asarray(b.head, dtype=float) for b in items])
            tails = _points("tails", [np.asarray(b.tail, dtype=float) for b in items])
            if parents is None and all(hasattr(b, "parent") and hasattr(b, "name") for b in items):
                index = {b.name: i for i, b in enumerate(items)}
                parents = [index.get(b.parent, -1) for b in items]  # None or unknown: a root
            if deform is None and all(hasattr(b, "kind") for b in items):
                deform = deforms([b.kind for b in items])
        else:
            raise ValueError("bones must be a Skeleton, a non-empty list of bones with .head "
                             "and .tail, or heads with tails")
    if len(heads) != len(tails):
        raise ValueError(f"got {len(heads)} heads and {len(tails)} tails")
    if len(heads) == 0:
        raise ValueError("weights need at least one bone")
    if parents is not None:
        parents = np.asarray(parents).reshape(-1)
        if len(parents) != len(heads) or not np.issubdtype(parents.dtype, np.integer):
            raise ValueError(f"parents must be {len(heads)} bone indices (-1: a root), got "
                             f"{parents.dtype} x {len(parents)}")
        parents = parents.astype(np.int64)
    if deform is not None:
        deform = np.asarray(deform).reshape(-1)
        if len(deform) != len(heads) or deform.dtype != bool:
            raise ValueError(f"deform must be {len(heads)} booleans, got {deform.dtype} x "
                             f"{len(deform)}")
    return heads, tails, parents, deform


def skin_weights(V, F, bones, tails=None, *, parents=None, deform=None, prepared=None,
                 progress: Optional[Callable[[str, float], Optional[bool]]] = None,
                 **options) -> SkinWeights:
    """Bone heat skinning weights of the vertices of (V #V x 3, F #F x 3).

    bones: a #B x 3 array of heads with `tails` (#B x 3), or a dcg.Skeleton (its bones as
    dcg.bones.plan_bones plans them at the default bone_detail: the add-on's and the batch's
    bones, in plan order), or a list of objects with .head and .tail (a plan of another
    bone_detail). Bones are in V's coordinates. Column b of the result is bone b. parents: #B
    indices of each bone's parent (-1 at a root) for heads and tails; a Skeleton or a plan
    brings its own; else a bone's parent is the first bone whose tail is at its head. The bone
    tree limits which bones share a vertex (bone_reach, far_weight). deform: #B booleans, False
    for a bone that weights no vertex (a control: the plan's "root" bone, which a Skeleton or
    a plan marks itself); its column stays empty.

    The weights solve on (V, F) itself (welded cracks, degenerate faces dropped), unless it has
    more than 2.5 x target_faces faces: then on stage 0's working mesh, the one the skeleton gets
    with the same options. prepared: a dcg.PreparedMesh of this same (V, F)
    (Extractor.prepare()) to reuse in that case instead of running stage 0 again (checked, and
    unused for a smaller input). options: any of dcg.OPTIONS; the weights use max_influences
    (4), heat (4.0), min_weight (0.05), bone_reach (3), far_weight (0.1), tie_tolerance (3e-4),
    target_faces (what is large) and,
    for a large input, stage 0's (repair, upsample, seed); the skeleton's other options are
    checked and unused, so the same **options work for both calls. progress(stage, fraction) is
    called from the calling thread; return False to cancel (raises dcg.Cancelled). The GIL is
    released while the engine works.

    Returns SkinWeights (unpacks as rows, cols, values): every vertex has 1..max_influences
    positive weights summing to 1. ValueError for bad arrays, bones or options.
    """
    from . import as_mesh

    V, F = as_mesh(V, F)
    heads, tails, parents, deform = _bones(bones, tails, parents, deform)
    clean = normalize_options(options)
    if prepared is not None:
        map_face = np.ascontiguousarray(prepared.map_face, dtype=np.int64).reshape(-1)
        if len(map_face) != len(V):
            raise ValueError(f"prepared maps {len(map_face)} vertices but V has {len(V)}: "
                             "pass the PreparedMesh of this mesh")
    if prepared is None or not _core.weights_on_working_mesh(len(F), clean):
        return _core.skin_weights(V, F, heads, tails, clean, progress, parents, deform)
    return _core.skin_weights_prepared(
        np.ascontiguousarray(prepared.vertices, dtype=np.float64),
        np.ascontiguousarray(prepared.faces, dtype=np.int64), float(prepared.scale),
        np.asarray(prepared.offset, dtype=np.float64).reshape(3), map_face,
        np.ascontiguousarray(prepared.map_barycentric, dtype=np.float64).reshape(-1, 3),
        heads, tails, clean, progress, parents, deform)


class BoneHeat(_core.BoneHeat):
    """Bone heat on a closed mesh, precomputed once (cotangent Laplacian, vertex areas, ray
    tracing structure); solve() then takes any set of bones: what an interactive bone-detail
    slider needs.

        heat = dcg.BoneHeat(V, F)                 # V #V x 3, F #F x 3, closed and oriented
        W = heat.solve(heads, tails)              # #V x #B, rows sum to about 1
        W = heat.solve(dcg.bones.plan_bones(skeleton, bone_detail=1.0), heat=2.0)

    Unlike skin_weights, the weights are the heat's own on (V, F) (no stage 0, no pruning to
    max_influences, no fading of faint weights), clipped to [0, 1]. Not thread-safe.
    """

    def __init__(self, V, F):
        from . import as_mesh

        super().__init__(*as_mesh(V, F))

    def solve(self, bones, tails=None, *, parents=None, deform=None,
              progress: Optional[Callable[[str, float], Optional[bool]]] = None,
              **options) -> np.ndarray:
        """#V x #B weights for `bones` (as skin_weights takes them, parents and deform
        included, in V's coordinates; a bone that does not deform has a column of zeros).

        options: heat and tie_tolerance (any of dcg.OPTIONS is accepted). The GIL is released
        while it works; progress(stage, fraction) returning False raises dcg.Cancelled.
        """
        heads, tails, parents, deform = _bones(bones, tails, parents, deform)
        return super().solve(heads, tails, normalize_options(options), progress, parents, deform)
