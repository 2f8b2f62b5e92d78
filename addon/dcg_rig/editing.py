"""The editable preview skeleton: the armature Preview Skeleton shows, which the user may edit
before Rig with DCG binds it.

Preview Skeleton adds, beside the nodes and links, an armature of the bones Rig would make
("<mesh> DCG Skeleton", in the "DCG Preview" collection, not bound to anything). The user
edits it like any armature, in its Edit Mode: moves a joint (a bone's tail and the heads
connected to it), deletes a spurious end's bones, extrudes a bone, mirrors an edit to the
other side (X-Axis Mirror where the mesh's mirror plane is the armature's x = 0, else the
DCG panel's Mirror buttons, `mirror_edit`). Rig with DCG on that mesh then binds the edited
bones as they are (`edited_plan`) instead of planning them again; an armature left as it
was planned changes nothing (Rig plans from the skeleton, with the panel's bone settings).
Clear, Rig and a new preview remove it; the Tau slider does not redraw an edited one.
"""

import json

import bpy
import numpy as np

from . import _engine, armature

PREVIEW_OF = "dcg_preview_of"  #: the mesh object's name, on the preview armature
PLANNED = "dcg_planned"        #: the bones as planned (JSON), to tell an edit
MIRROR_PLANE = "dcg_mirror_plane"  #: (nx, ny, nz, offset) in world space, when there is one
#: A bone moved by more than this fraction of the armature's size, or turned about itself by
#: more than acos(ROLL_COSINE) (0.8 degrees), was edited.
MOVED = 1e-4
ROLL_COSINE = 0.9999


def add_editable_skeleton(context, mesh_obj, plan, plane, collection):
    """Add the armature of `plan` (world space) for `mesh_obj` to `collection`; return it.
    `plane`: the plan's mirror plane (dcg.symmetry.Plane) or None."""
    arm_obj = armature.build_armature(context, mesh_obj, plan, collection=collection,
                                      name=f"{mesh_obj.name} DCG Skeleton")
    del arm_obj[armature.RIG_PROPERTY]  # not a rig until Rig binds it
    arm_obj[PREVIEW_OF] = mesh_obj.name
    arm_obj[PLANNED] = json.dumps(_bones_state(arm_obj))
    if plane is not None:
        arm_obj[MIRROR_PLANE] = [*map(float, plane.normal), float(plane.offset)]
        arm_obj.data.use_mirror_x = _is_local_x_mirror(arm_obj, plane, plan)
    return arm_obj


def _is_local_x_mirror(arm_obj, plane, plan):
    """True when the mirror plane is the armature's own x = 0 (Blender's X-Axis Mirror), within
    1e-3 of the plan's size (its bones' extent: the object's dimensions are not yet
    evaluated)."""
    matrix = np.array(arm_obj.matrix_world, dtype=float)
    normal = matrix[:3, :3].T @ plane.normal
    length = float(np.linalg.norm(normal))
    offset = (plane.offset - plane.normal @ matrix[:3, 3]) / max(length, 1e-12)
    ends = np.array([point for spec in plan for point in (spec.head, spec.tail)])
    size = max(float(np.linalg.norm(np.ptp(ends, axis=0))), 1e-12)
    return bool(abs(normal[0]) > 0.999 * length and abs(offset) < 1e-3 * size)


def _bones_state(arm_obj):
    """{name: [head, tail, z axis, parent]} of the armature's bones (local space, rounded)."""
    return {bone.name: [np.round(bone.head_local, 5).tolist(),
                        np.round(bone.tail_local, 5).tolist(),
                        np.round(np.array(bone.matrix_local)[:3, 2], 5).tolist(),
                        bone.parent.name if bone.parent else None]
            for bone in arm_obj.data.bones}


def preview_skeleton(mesh_name):
    """The preview armature made for the mesh object `mesh_name`, or None."""
    return next((o for o in bpy.data.objects
                 if o.type == "ARMATURE" and o.get(PREVIEW_OF) == mesh_name), None)


def is_edited(arm_obj):
    """True when the preview armature's bones differ from what was planned (added, deleted,
    renamed, re-parented, moved or rolled; in Edit Mode it counts as edited)."""
    if arm_obj.mode == "EDIT":  # the bones catch up with the edit bones on leaving it
        return True
    planned = json.loads(arm_obj.get(PLANNED, "{}"))
    state = _bones_state(arm_obj)
    if planned.keys() != state.keys():
        return True
    if not state:
        return False
    ends = np.array([bone[:2] for bone in planned.values()]).reshape(-1, 3)
    size = max(float(np.linalg.norm(np.ptp(ends, axis=0))), 1e-9)
    for name, (head, tail, z_axis, parent) in state.items():
        old_head, old_tail, old_z, old_parent = planned[name]
        moved = np.linalg.norm(np.subtract([head, tail], [old_head, old_tail]), axis=1).max()
        turned = np.dot(z_axis, old_z) / max(np.linalg.norm(z_axis) * np.linalg.norm(old_z),
                                             1e-12)
        if parent != old_parent or moved > MOVED * size or turned < ROLL_COSINE:
            return True
    return False


def edited_plan(engine, mesh_obj):
    """The bone plan (world space) of the preview armature of `mesh_obj` when the user edited
    it, else None (no preview armature, or one as planned)."""
    arm_obj = preview_skeleton(mesh_obj.name)
    if arm_obj is None or not is_edited(arm_obj):
        return None
    return plan_of_armature(engine, arm_obj)


def _parents_first(bones):
    """Blender's bones, each after its parent (breadth-first from the roots)."""
    ordered, queue = [], [b for b in bones if b.parent is None]
    while queue:
        bone = queue.pop(0)
        ordered.append(bone)
        queue.extend(bone.children)
    return ordered


def plan_of_armature(engine, arm_obj):
    """The armature's bones as a bone plan ([dcg.bones.BoneSpec], world space, parents
    first): kinds, nodes and radii as planned, a bone the user added taking its parent's
    kind and radius (a "connection" under the root, which deforms nothing); each bone's Z axis
    its own (its roll)."""
    matrix = np.array(arm_obj.matrix_world, dtype=float)
    rotation, offset = matrix[:3, :3], matrix[:3, 3]
    plan, by_name = [], {}
    for bone in _parents_first(arm_obj.data.bones):
        head = rotation @ np.array(bone.head_local) + offset
        tail = rotation @ np.array(bone.tail_local) + offset
        z_axis = rotation @ np.array(bone.matrix_local)[:3, 2]
        z_axis /= max(float(np.linalg.norm(z_axis)), 1e-12)
        parent = by_name.get(bone.parent.name) if bone.parent else None
        fallback = parent.tail_radius if parent else 0.1 * float(np.linalg.norm(tail - head))
        radii = bone.get("dcg_radii", (fallback, fallback))
        spec = engine.bones.BoneSpec(
            bone.name, head, tail, parent.name if parent else None, bone.use_connect,
            str(bone.get("dcg_kind", _added_kind(parent))),
            int(bone.get("dcg_node", -1)), int(bone.get("dcg_link", -1)), float(radii[0]),
            float(radii[1]), z_axis, engine.rolls.blender_roll(head, tail, z_axis))
        plan.append(spec)
        by_name[spec.name] = spec
    return plan


def _added_kind(parent):
    """The kind of a bone the user added under `parent` (a BoneSpec or None)."""
    return parent.kind if parent is not None and parent.kind != "root" else "connection"


def partner_name(name):
    """The other side's name (``arm.002.L`` / ``arm.002.R``, ``LeftArm`` / ``RightArm``: the
    pairs Blender's own mirror tools make, bpy.utils.flip_name), or None for a bone of the
    middle."""
    flipped = bpy.utils.flip_name(name)
    return None if flipped == name else flipped


def side_of(name):
    """"L", "R" or None (the middle) from a bone's name."""
    if name.endswith(".L") or name.startswith("Left"):
        return "L"
    if name.endswith(".R") or name.startswith("Right"):
        return "R"
    return None


def mirror_edit(arm_obj, source="L"):
    """Give each bone of the other side the mirror image (across the armature's mirror
    plane) of its partner on the `source` side ("L" or "R"): the selected ones in Edit Mode
    when any is selected, else all. Return (bones mirrored, source bones without a partner).
    The armature must be the active object; its mode is kept."""
    stored = arm_obj.get(MIRROR_PLANE)
    if stored is None:
        raise ValueError(f"{arm_obj.name} has no mirror plane: the shape is not symmetric")
    plane = _engine.require().symmetry.Plane(np.array(stored[:3], dtype=float),
                                             float(stored[3]), 0.0)
    matrix = np.array(arm_obj.matrix_world, dtype=float)
    inverse = np.linalg.inv(matrix)

    def reflect(point):  # an armature-space point mirrored across the world-space plane
        world = plane.reflect(matrix[:3, :3] @ np.array(point) + matrix[:3, 3])
        return inverse[:3, :3] @ world + inverse[:3, 3]

    mode = arm_obj.mode
    if mode != "EDIT":
        bpy.ops.object.mode_set(mode="EDIT")
    try:
        bones = arm_obj.data.edit_bones
        selected = [b for b in bones if b.select or b.select_head or b.select_tail]
        sources = [b for b in (selected or bones) if side_of(b.name) == source]
        done = missing = 0
        for bone in sources:
            other = bones.get(partner_name(bone.name))
            if other is None:
                missing += 1
                continue
            z_world = plane.reflect_direction(matrix[:3, :3] @ np.array(bone.z_axis))
            other.head, other.tail = reflect(bone.head).tolist(), reflect(bone.tail).tolist()
            other.align_roll((inverse[:3, :3] @ z_world).tolist())
            done += 1
    finally:
        if mode != "EDIT":
            bpy.ops.object.mode_set(mode=mode)
    return done, missing
