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

from dataclasses import dataclass, field
from typing import Callable, Dict, Iterator, Optional, Tuple

import numpy as np

from . import _core
from .bones import bone_arrays, plan_bones
from .options import normalize_options

@dataclass
class SkinWeights:
    """Per-vertex bone weights as sparse triplets, sorted by vertex then decreasing weight.

    rows    #E int64 vertex index of each entry
    cols    #E int64 bone index of each entry (the order of the bones given)
    values  #E float64 weights in (0, 1]; each vertex's sum to 1
    vertex_count, bone_count   the shape of the dense matrix
    working_vertices  vertices of the mesh the heat was solved on (the welded input's, or the
                      working mesh's for a large input)
    unseen_vertices   working vertices that saw no bone (weighted by diffusion)
    blind_components  working-mesh parts that saw no bone (their nearest bone used)
    fallback_vertices input vertices left with nothing by the heat (given their nearest bone)
    timings           step -> seconds, then "total"

    Unpacks as (rows, cols, values).
    """

    rows: np.ndarray
    cols: np.ndarray
    values: np.ndarray
    vertex_count: int
    bone_count: int
    working_vertices: int = 0
    unseen_vertices: int = 0
    blind_components: int = 0
    fallback_vertices: int = 0
    timings: Dict[str, float] = field(default_factory=dict)

    def __iter__(self) -> Iterator[np.ndarray]:
        return iter((self.rows, self.cols, self.values))

    def dense(self) -> np.ndarray:
        """The #V x #B weight matrix."""
        W = np.zeros((self.vertex_count, self.bone_count))
        np.add.at(W, (self.rows, self.cols), self.values)
        return W

    @classmethod
    def _from_core(cls, d) -> "SkinWeights":
        return cls(
            rows=np.asarray(d["rows"], dtype=np.int64),
            cols=np.asarray(d["cols"], dtype=np.int64),
            values=np.asarray(d["values"], dtype=np.float64),
            vertex_count=int(d["vertex_count"]), bone_count=int(d["bone_count"]),
            working_vertices=int(d["working_vertices"]),
            unseen_vertices=int(d["unseen_vertices"]),
            blind_components=int(d["blind_components"]),
            fallback_vertices=int(d["fallback_vertices"]),
            timings={name: float(s) for name, s in d["timings"]})


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


def _bones(bones, tails) -> Tuple[np.ndarray, np.ndarray]:
    """Heads and tails from (heads, tails) arrays, a Skeleton or a list of bone objects."""
    if tails is not None:
        heads, tails = _points("heads", bones), _points("tails", tails)
    elif hasattr(bones, "polylines") and hasattr(bones, "links"):
        plan = bone_arrays(plan_bones(bones))
        heads, tails = plan["heads"], plan["tails"]
    else:
        try:
            items = list(bones)
        except TypeError:
            raise ValueError("bones must be a Skeleton, a list of bones with .head and .tail, "
                             "or heads with tails") from None
        if items and all(hasattr(b, "head") and hasattr(b, "tail") for b in items):
            heads = _points("heads", [np.asarray(b.head, dtype=float) for b in items])
            tails = _points("tails", [np.asarray(b.tail, dtype=float) for b in items])
        else:
            raise ValueError("bones must be a Skeleton, a non-empty list of bones with .head "
                             "and .tail, or heads with tails")
    if len(heads) != len(tails):
        raise ValueError(f"got {len(heads)} heads and {len(tails)} tails")
    if len(heads) == 0:
        raise ValueError("weights need at least one bone")
    return heads, tails


def skin_weights(V, F, bones, tails=None, *, prepared=None,
                 progress: Optional[Callable[[str, float], Optional[bool]]] = None,
                 **options) -> SkinWeights:
    """Bone heat skinning weights of the vertices of (V #V x 3, F #F x 3).

    bones: a #B x 3 array of heads with `tails` (#B x 3), or a dcg.Skeleton (its bones as
    dcg.bones.plan_bones plans them at the default bone_detail: the add-on's and the batch's
    bones, in plan order), or a list of objects with .head and .tail (a plan of another
    bone_detail). Bones are in V's coordinates. Column b of the result is bone b.

    The weights solve on (V, F) itself (welded cracks, degenerate faces dropped), unless it has
    more than 2.5 x target_faces faces: then on stage 0's working mesh, the one the skeleton gets
    with the same options. prepared: a dcg.PreparedMesh of this same (V, F)
    (Extractor.prepare()) to reuse in that case instead of running stage 0 again (checked, and
    unused for a smaller input). options: any of dcg.OPTIONS; the weights use max_influences
    (4), heat (4.0), min_weight (0.05), tie_tolerance (1e-4), target_faces (what is large) and,
    for a large input, stage 0's (repair, upsample, seed); the skeleton's other options are
    checked and unused, so the same **options work for both calls. progress(stage, fraction) is
    called from the calling thread; return False to cancel (raises dcg.Cancelled). The GIL is
    released while the engine works.

    Returns SkinWeights (unpacks as rows, cols, values): every vertex has 1..max_influences
    positive weights summing to 1. ValueError for bad arrays, bones or options.
    """
    from . import as_mesh

    V, F = as_mesh(V, F)
    heads, tails = _bones(bones, tails)
    clean = normalize_options(options)
    if prepared is not None:
        map_face = np.ascontiguousarray(prepared.map_face, dtype=np.int64).reshape(-1)
        if len(map_face) != len(V):
            raise ValueError(f"prepared maps {len(map_face)} vertices but V has {len(V)}: "
                             "pass the PreparedMesh of this mesh")
    if prepared is None or not _core.weights_on_working_mesh(len(F), clean):
        d = _core.skin_weights(V, F, heads, tails, clean, progress)
    else:
        d = _core.skin_weights_prepared(
            np.ascontiguousarray(prepared.vertices, dtype=np.float64),
            np.ascontiguousarray(prepared.faces, dtype=np.int64), float(prepared.scale),
            np.asarray(prepared.offset, dtype=np.float64).reshape(3), map_face,
            np.ascontiguousarray(prepared.map_barycentric, dtype=np.float64).reshape(-1, 3),
            heads, tails, clean, progress)
    return SkinWeights._from_core(d)
