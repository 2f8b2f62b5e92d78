"""The rigging pipeline shared by the operators and the CLI.

1. `object_mesh`: the evaluated world-space triangles of a mesh object (checked);
2. the engine: `dcg.extract_skeleton` (blocking here, or in a `worker.SkeletonJob`);
3. `apply_rig`: armature, weights, modifier; replaces earlier DCG rigs and the preview.

Nothing in the scene changes before step 3, and step 3 checks what can fail before it
touches the scene, so an error leaves the scene as it was.
"""

from dataclasses import dataclass, field

import bpy

from . import _engine, armature, mesh_io, options, preview, weights


class RigError(Exception):
    """A failure the user can act on; the message is the reason shown in the report."""


@dataclass
class RigResult:
    """What `apply_rig` made: the armature object, its bone count and warnings."""

    armature: object
    bone_count: int
    warnings: list = field(default_factory=list)


def object_mesh(context, obj):
    """Return (V, F) of `obj` evaluated, triangulated, in world space; RigError if unusable."""
    if obj is None or obj.type != "MESH":
        raise RigError("select a mesh object to rig")
    V, F = mesh_io.evaluated_world_mesh(context, obj)
    if len(V) < 4 or len(F) < 4:
        raise RigError(f"{obj.name} has {len(V)} vertices and {len(F)} triangles after its "
                       "modifiers: the engine needs at least 4 of each")
    return V, F


def check_riggable(obj):
    """Raise RigError when rigging `obj` would change other objects: its mesh data is shared
    (vertex group weights live in the mesh, so every user would be rigged)."""
    users = [o.name for o in bpy.data.objects if o.data == obj.data and o != obj]
    if users:
        raise RigError(f"{obj.name} shares its mesh data with {', '.join(sorted(users))}: "
                       "make it single-user first (Object > Relations > Make Single User > "
                       "Object & Data)")


def disable_foreign_armatures(mesh_obj, arm_obj):
    """Turn off the Armature modifiers of `mesh_obj` that use another armature than
    `arm_obj` (they would deform the mesh a second time); return a warning per modifier."""
    warnings = []
    for modifier in mesh_obj.modifiers:
        if modifier.type == "ARMATURE" and modifier.object != arm_obj and (
                modifier.show_viewport or modifier.show_render):
            modifier.show_viewport = modifier.show_render = False
            owner = modifier.object.name if modifier.object else "no armature"
            warnings.append(f"turned off the Armature modifier '{modifier.name}' ({owner}) "
                            "so the mesh is not deformed twice")
    return warnings


def reusable_prepared(mesh_obj, prepared):
    """Return `prepared` (the skeleton run's stage 0, computed from the evaluated mesh) when
    the weights may reuse it: the evaluated mesh is the mesh's own vertices and triangles
    (no enabled modifier, no shape key), so the stage-0 map fits them; else None."""
    if prepared is None or mesh_obj.data.shape_keys is not None:
        return None
    if any(m.show_viewport for m in mesh_obj.modifiers):
        return None
    if len(getattr(prepared, "map_face", ())) != len(mesh_obj.data.vertices):
        return None
    return prepared


def plan_bones(skeleton, bone_detail, bone_names, root_bone=options.ADDON_DEFAULTS["root_bone"],
               origin=None):
    """(the bone plan of `skeleton`, warnings): the package's planner (dcg.bones.plan_bones)
    at `bone_detail`, named by `bone_names` ("DCG" or "MIXAMO") with world +Z as the scene's
    up, with a root bone on the floor across it when `root_bone`, under `origin` (the mesh
    object's origin in world space; None: the world's) when that is over the body, and what the
    user should be told of it
    (dcg.rig_warnings.plan_warnings: the fallback skeleton, Mixamo's names asked of a skeleton
    that is not humanoid, limbs of a shape that mirrors itself that did not pair, paired bones
    mirrored across a plane that lies level, paired bones that do not mirror each other);
    `dcg batch` records the same."""
    engine = _engine.require()
    where = {} if origin is None else {"origin": tuple(origin)}
    plan = engine.bones.plan_bones(skeleton, bone_detail, bone_names.lower(),
                                   root_bone=bool(root_bone), up=engine.bones.UP, **where)
    return plan, engine.rig_warnings.plan_warnings(skeleton, plan, bone_names.lower(),
                                                   bool(root_bone), engine.bones.UP)


def apply_rig(context, mesh_obj, skeleton, weight_method=options.ADDON_DEFAULTS["weights"],
              bone_detail=options.ADDON_DEFAULTS["bone_detail"], prepared=None,
              engine_options=None, bone_names=options.ADDON_DEFAULTS["bone_names"], plan=None,
              root_bone=options.ADDON_DEFAULTS["root_bone"]):
    """Rig `mesh_obj` from `skeleton` (world coordinates); return a RigResult.

    The bones are `plan` when given (world space: the edited preview skeleton), else the
    planner's (`plan_bones` at `bone_detail` with `bone_names` and `root_bone`).
    Transactional: the mesh's earlier DCG rigs are detached (not deleted) while the new rig is
    built and bound. On success they are deleted along with the preview; on failure the new
    armature is deleted and the earlier binding (vertex groups, modifiers, parent) is
    restored, then the exception propagates.
    """
    if plan is None:
        plan, warnings = plan_bones(skeleton, bone_detail, bone_names, root_bone,
                                    mesh_obj.matrix_world.translation)
    else:  # the edited preview's bones: only the skeleton's own warning applies
        warnings = [text for text in [fallback_warning(skeleton.method)] if text]
    if not plan:
        raise RigError(f"the skeleton of {mesh_obj.name} has no bones "
                       f"({len(skeleton.positions)} nodes, {len(skeleton.links)} links)")
    old_rigs = armature.find_rigs(mesh_obj)
    saved = armature.BindingSnapshot(mesh_obj, old_rigs)
    arm_obj = None
    try:
        for old in old_rigs:
            armature.detach(mesh_obj, old)
        arm_obj = armature.build_armature(context, mesh_obj, plan)
        warnings += weights.apply_weights(context, mesh_obj, arm_obj, plan, weight_method,
                                         reusable_prepared(mesh_obj, prepared), engine_options)
    except BaseException:
        if arm_obj is not None:
            armature.detach(mesh_obj, arm_obj)
            armature.remove_armature(arm_obj)
        saved.restore()
        raise
    for old in old_rigs:
        armature.remove_armature(old)
    preview.clear_preview()
    warnings += disable_foreign_armatures(mesh_obj, arm_obj)
    return RigResult(arm_obj, len(plan), warnings)


def fallback_warning(method):
    """What to tell the user when the engine gave its fallback skeleton (method
    "interim_graph (fallback: <reason>)"), or None for a DCG skeleton or without the engine
    (dcg.rig_warnings.fallback_warning)."""
    engine = _engine.load()
    return engine.rig_warnings.fallback_warning(method) if engine else None
