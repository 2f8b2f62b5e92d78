"""Bind a mesh to its DCG armature: vertex groups, weights, Armature modifier, parenting.

Methods (the `weights` setting):

- ``DCG`` (the default): the engine's own weights, `dcg.skin_weights`: bone heat on the
  mesh itself, each part by the bones it sees (a large mesh: on the engine's working mesh,
  carried back), every vertex weighted (open, several parts, any scale). Computed on the
  mesh's own vertices and triangles in world space, with the plan's bones in world space.
  Should the engine refuse the mesh (or be too old to have weights), envelope weights take
  over, with a warning.
- ``BLENDER``: Automatic Weights (bone heat). It fails silently (see ENVIRONMENT.md), so
  every vertex's weight sum is checked; on failure the mesh and armature data are scaled
  by 100 and bone heat runs again; vertices still unweighted get envelope weights, with a
  warning.
- ``ENVELOPE``: `skinning.envelope_weights` from the bones and the skeleton radii.
- ``NONE``: the modifier and one empty vertex group per bone, for painting by hand.

Every method but ``NONE`` ends with at most 4 influences per vertex, summing to 1.
"""

import bpy
import numpy as np
from mathutils import Matrix

from . import _engine, armature, mesh_io, skinning

RETRY_SCALE = 100.0


def group_names(plan):
    """The vertex group of each bone of `plan` (column order): its name, None for the root
    bone, which deforms nothing and gets no group (as Blender's own binding does)."""
    return [None if spec.kind == "root" else spec.name for spec in plan]


def apply_weights(context, mesh_obj, arm_obj, plan, method, prepared=None,
                  engine_options=None):
    """Bind `mesh_obj` to `arm_obj` with `method`; return a list of warnings for the user.

    `prepared`: the stage-0 result of the skeleton run when it was computed from exactly
    these vertices and triangles (see `rigging.reusable_prepared`); DCG weights then skip
    their own stage 0. `engine_options`: the engine's keyword arguments (dcg.OPTIONS names,
    the skeleton's included); DCG weights use theirs (max_influences, heat, ...)."""
    warnings = []
    names = group_names(plan)
    if method == "DCG":
        warnings += _dcg_weights(mesh_obj, plan, prepared, engine_options)
    elif method == "BLENDER":
        warnings += _bone_heat_checked(context, mesh_obj, arm_obj, plan)
    else:
        mesh_io.empty_groups(mesh_obj, names)
        if method == "ENVELOPE":
            mesh_io.write_groups(mesh_obj, names, *_envelope(mesh_obj, plan, None))
    armature.bind(mesh_obj, arm_obj)
    return warnings


def mesh_triangles(mesh):
    """Return the #T by 3 int64 vertex indices of the triangles of a mesh datablock (its
    polygons triangulated as Blender displays them)."""
    mesh.calc_loop_triangles()
    F = np.empty(len(mesh.loop_triangles) * 3, dtype=np.int32)
    mesh.loop_triangles.foreach_get("vertices", F)
    return F.reshape(-1, 3).astype(np.int64)


def _dcg_weights(mesh_obj, plan, prepared=None, engine_options=None):
    """The engine's bone heat weights written to the vertex groups; envelope weights (with a
    warning) when the engine cannot weight this mesh. Return the warnings."""
    names = group_names(plan)
    engine = _engine.require()
    skin_weights = getattr(engine, "skin_weights", None)
    V = mesh_io.world_vertices(mesh_obj)
    F = mesh_triangles(mesh_obj.data)
    warnings = []
    weights = None
    if skin_weights is None:
        warnings.append("this build of the engine has no weights: used envelope weights")
    else:
        try:
            # The engine's own defaults (dcg.OPTIONS) for whatever engine_options leave out.
            weights = skin_weights(V, F, plan, prepared=prepared, **(engine_options or {}))
        except ValueError as error:
            warnings.append(f"the engine could not weight {mesh_obj.name} ({error}): used "
                            "envelope weights")
    if weights is None:
        rows, cols, values = _envelope(mesh_obj, plan, None)
    else:
        rows, cols, values = weights
        missing = np.flatnonzero(skinning.weight_sums(rows, values, len(V)) <= 0)
        if len(missing):  # not expected: the engine weights every vertex
            warnings.append(f"the engine left {len(missing)} of {len(V)} vertices "
                            "unweighted: gave them envelope weights")
            extra = _envelope(mesh_obj, plan, missing)
            rows, cols, values = (np.concatenate([a, b]) for a, b in
                                  zip((rows, cols, values), extra))
    mesh_io.write_groups(mesh_obj, names, rows, cols, values)
    return warnings


def _envelope(mesh_obj, plan, vertices):
    """Return sparse envelope weights (rows, cols, values) of the mesh's vertices (or of
    the subset `vertices`, an index array) to the bones of `plan` that deform (not the root)."""
    points = mesh_io.world_vertices(mesh_obj)
    index = np.arange(len(points)) if vertices is None else np.asarray(vertices)
    deform = [s for s in plan if s.kind != "root"]
    rows, cols, values = skinning.envelope_weights(
        points[index], np.array([s.head for s in deform]), np.array([s.tail for s in deform]),
        [s.head_radius for s in deform], [s.tail_radius for s in deform])
    columns = np.array([i for i, s in enumerate(plan) if s.kind != "root"], dtype=np.int64)
    return index[rows], columns[np.asarray(cols, dtype=np.int64)], values


def _bone_heat_checked(context, mesh_obj, arm_obj, plan):
    """Automatic Weights, checked, retried at scale 100, completed by envelope weights."""
    names = group_names(plan)
    count = len(mesh_obj.data.vertices)
    warnings = []
    _bone_heat(context, mesh_obj, arm_obj)
    weights = mesh_io.read_groups(mesh_obj, names)
    if (skinning.weight_sums(weights[0], weights[2], count) <= 0).any():
        armature.detach(mesh_obj, arm_obj)
        _bone_heat_scaled(context, mesh_obj, arm_obj)
        weights = mesh_io.read_groups(mesh_obj, names)
    rows, cols, values = skinning.normalize_and_prune(*weights)
    missing = np.flatnonzero(skinning.weight_sums(rows, values, count) <= 0)
    if len(missing):
        warnings.append(f"Automatic Weights left {len(missing)} of {count} vertices "
                        "unweighted: gave them envelope weights")
        extra = _envelope(mesh_obj, plan, missing)
        rows, cols, values = (np.concatenate([a, b]) for a, b in zip((rows, cols, values),
                                                                      extra))
    mesh_io.write_groups(mesh_obj, names, rows, cols, values)
    return warnings


def _bone_heat(context, mesh_obj, arm_obj):
    """Run Blender's parent_set(ARMATURE_AUTO), then restore the selection and active object."""
    view_layer = context.view_layer
    selected = [o for o in view_layer.objects if o.select_get()]
    active = view_layer.objects.active
    try:
        for obj in selected:
            obj.select_set(False)
        mesh_obj.select_set(True)
        arm_obj.select_set(True)
        view_layer.objects.active = arm_obj
        bpy.ops.object.parent_set(type="ARMATURE_AUTO")
    finally:
        arm_obj.select_set(False)
        mesh_obj.select_set(False)
        for obj in selected:
            obj.select_set(True)
        view_layer.objects.active = active


def _bone_heat_scaled(context, mesh_obj, arm_obj):
    """Bone heat with mesh and armature data scaled by RETRY_SCALE (object scale would not
    help: the parent inverse keeps the factor); the mesh coordinates are restored exactly."""
    saved = mesh_io.local_vertices(mesh_obj.data)
    scale = Matrix.Scale(RETRY_SCALE, 4)
    mesh_obj.data.transform(scale)
    arm_obj.data.transform(scale)
    try:
        _bone_heat(context, mesh_obj, arm_obj)
    finally:
        mesh_io.set_local_vertices(mesh_obj.data, saved)
        arm_obj.data.transform(scale.inverted())
