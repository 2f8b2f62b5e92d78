"""Skeleton -> Blender armature: bones, names, kinds, colors; finding and clearing rigs.

The bones come from the engine package's planner (`dcg.bones.plan_bones`, the one
`dcg batch` uses too) in world space; the armature object sits at the
mesh's world transform, so its rest pose matches the skeleton exactly. Each bone's roll turns
its local Z axis onto the plan's `z_axis` (carried into the armature's space, so that it
holds under any object transform, mirrors included). Bones are handled by name across mode
switches (EditBone references die when edit mode ends).
"""

import bpy
import numpy as np

from . import mesh_io

RIG_PROPERTY = "dcg_rig"  #: custom property that marks an armature object as a DCG rig
MODIFIER_NAME = "DCG Rig"

#: Colors by kind (normal, selected, active): end red, joint purple, connection blue, the root
#: (a control that deforms nothing) yellow.
KIND_COLORS = {
    "end": ((0.90, 0.12, 0.10), (1.00, 0.45, 0.40), (1.00, 0.75, 0.70)),
    "joint": ((0.60, 0.15, 0.85), (0.80, 0.45, 1.00), (0.92, 0.75, 1.00)),
    "connection": ((0.10, 0.35, 0.95), (0.40, 0.60, 1.00), (0.75, 0.85, 1.00)),
    "root": ((0.95, 0.75, 0.10), (1.00, 0.88, 0.40), (1.00, 0.95, 0.70)),
}


def blender_4():
    """Return True on Blender 4.0 and later (bone collections instead of bone groups)."""
    return bpy.app.version >= (4, 0, 0)


def _link_like(obj, like):
    """Link `obj` into the collections of `like` (the scene collection when it has none)."""
    collections = list(like.users_collection) or [bpy.context.scene.collection]
    for collection in collections:
        collection.objects.link(obj)


def build_armature(context, mesh_obj, plan, collection=None, name=None):
    """Return a new armature object for `mesh_obj` with the bones of `plan` (world space),
    named `name` ("<mesh> DCG Rig" by default), in `collection` (default: the mesh's).

    Leaves object mode active and `mesh_obj` the active object again.
    """
    name = name or f"{mesh_obj.name} DCG Rig"
    data = bpy.data.armatures.new(name)
    arm_obj = bpy.data.objects.new(name, data)
    arm_obj[RIG_PROPERTY] = True
    arm_obj.matrix_world = mesh_obj.matrix_world.copy()
    if collection is None:
        _link_like(arm_obj, mesh_obj)
    else:
        collection.objects.link(arm_obj)
    data.show_names = False
    arm_obj.show_in_front = True

    to_local = np.array(mesh_obj.matrix_world.inverted(), dtype=float)
    view_layer = context.view_layer
    view_layer.objects.active = arm_obj
    bpy.ops.object.mode_set(mode="EDIT")
    try:
        for spec in plan:
            bone = data.edit_bones.new(spec.name)
            bone.head = to_local[:3, :3] @ spec.head + to_local[:3, 3]
            bone.tail = to_local[:3, :3] @ spec.tail + to_local[:3, 3]
        for spec in plan:
            if spec.parent is not None:
                bone = data.edit_bones[spec.name]
                bone.parent = data.edit_bones[spec.parent]
                bone.use_connect = spec.use_connect
        _set_rolls(data, plan, to_local[:3, :3])
    finally:
        bpy.ops.object.mode_set(mode="OBJECT")
        view_layer.objects.active = mesh_obj
    for spec in plan:
        bone = data.bones[spec.name]
        bone["dcg_kind"] = spec.kind
        bone["dcg_node"] = spec.node
        bone["dcg_link"] = spec.link
        bone["dcg_radii"] = (float(spec.head_radius), float(spec.tail_radius))
        bone.use_deform = spec.kind != "root"
        if spec.kind == "root" and hasattr(bone, "display_type"):  # Blender 4.1+
            bone.display_type = "WIRE"  # a thin line under the body, not a fat octahedron
    _color_bones(arm_obj, plan)
    return arm_obj


def _set_rolls(data, plan, to_local):
    """Roll each edit bone so that its Z axis is the plan's `z_axis` taken into the armature's
    space by the 3 x 3 `to_local` (so that in world space it is `z_axis` again; align_roll
    takes the part normal to the bone). After parenting: connecting may move a head."""
    for spec in plan:
        z_axis = to_local @ np.asarray(spec.z_axis, dtype=float)
        data.edit_bones[spec.name].align_roll(z_axis.tolist())


def _color_bones(arm_obj, plan):
    """Color the bones by kind: bone groups on Blender 3.x, bone collections on 4.x."""
    kinds = [k for k in KIND_COLORS if any(spec.kind == k for spec in plan)]
    if blender_4():
        collections = {kind: arm_obj.data.collections.new(kind) for kind in kinds}
        for spec in plan:
            bone = arm_obj.data.bones[spec.name]
            collections[spec.kind].assign(bone)
            bone.color.palette = "CUSTOM"
            normal, select, active = KIND_COLORS[spec.kind]
            bone.color.custom.normal, bone.color.custom.select = normal, select
            bone.color.custom.active = active
        return
    groups = {}
    for kind in kinds:
        group = arm_obj.pose.bone_groups.new(name=kind)
        group.color_set = "CUSTOM"
        group.colors.normal, group.colors.select, group.colors.active = KIND_COLORS[kind]
        groups[kind] = group
    for spec in plan:
        arm_obj.pose.bones[spec.name].bone_group = groups[spec.kind]


def find_rigs(mesh_obj):
    """Return the DCG armature objects that deform or parent `mesh_obj` (no duplicates)."""
    rigs = [m.object for m in mesh_obj.modifiers
            if m.type == "ARMATURE" and m.object is not None and RIG_PROPERTY in m.object]
    parent = mesh_obj.parent
    if parent is not None and parent.type == "ARMATURE" and RIG_PROPERTY in parent:
        rigs.append(parent)
    return list(dict.fromkeys(rigs))


def detach(mesh_obj, arm_obj):
    """Remove what binds `mesh_obj` to `arm_obj`: its Armature modifiers, the vertex groups
    named after its bones, and the parenting (the mesh keeps its world transform)."""
    for modifier in [m for m in mesh_obj.modifiers
                     if m.type == "ARMATURE" and m.object == arm_obj]:
        mesh_obj.modifiers.remove(modifier)
    names = {bone.name for bone in arm_obj.data.bones}
    for group in [g for g in mesh_obj.vertex_groups if g.name in names]:
        mesh_obj.vertex_groups.remove(group)
    if mesh_obj.parent == arm_obj:
        world = mesh_obj.matrix_world.copy()
        mesh_obj.parent = None
        mesh_obj.matrix_world = world


def remove_armature(arm_obj):
    """Delete an armature object, and its data when nothing else uses it."""
    data = arm_obj.data
    bpy.data.objects.remove(arm_obj)
    if data.users == 0:
        bpy.data.armatures.remove(data)


def clear_rigs(mesh_obj):
    """Detach and delete every DCG rig of `mesh_obj`; return how many were removed."""
    rigs = find_rigs(mesh_obj)
    for arm_obj in rigs:
        detach(mesh_obj, arm_obj)
        remove_armature(arm_obj)
    return len(rigs)


def bind(mesh_obj, arm_obj):
    """Parent `mesh_obj` to `arm_obj` (world transform kept) and give it an Armature modifier
    (Blender puts deform modifiers before generative ones); return the modifier."""
    world = mesh_obj.matrix_world.copy()
    mesh_obj.parent = arm_obj
    mesh_obj.matrix_parent_inverse = arm_obj.matrix_world.inverted()
    mesh_obj.matrix_world = world
    modifier = next((m for m in mesh_obj.modifiers
                     if m.type == "ARMATURE" and m.object == arm_obj), None)
    if modifier is None:
        modifier = mesh_obj.modifiers.new(MODIFIER_NAME, "ARMATURE")
        modifier.object = arm_obj
    modifier.name = MODIFIER_NAME
    return modifier


def bone_world_segments(arm_obj, deforming=False):
    """Return (heads, tails) #B by 3 of the rest bones in world space, in bone order (only
    those that deform, not the root bone, when `deforming`)."""
    matrix = np.array(arm_obj.matrix_world, dtype=float)
    bones = [b for b in arm_obj.data.bones if b.use_deform or not deforming]
    heads = np.array([b.head_local for b in bones], dtype=float).reshape(-1, 3)
    tails = np.array([b.tail_local for b in bones], dtype=float).reshape(-1, 3)
    return (heads @ matrix[:3, :3].T + matrix[:3, 3], tails @ matrix[:3, :3].T + matrix[:3, 3])



class BindingSnapshot:
    """What binds a mesh to its DCG rigs, saved so that a failed re-rig can put it back.

    Saves the parent and its inverse matrix, the world matrix, the Armature modifiers that
    use `rigs` (name, object, position in the stack, settings that matter) and every vertex
    group of the mesh with its weights.
    """

    def __init__(self, mesh_obj, rigs):
        self.mesh_obj = mesh_obj
        self.parent = mesh_obj.parent
        self.parent_inverse = mesh_obj.matrix_parent_inverse.copy()
        self.world = mesh_obj.matrix_world.copy()
        self.modifiers = [(i, m.name, m.object, m.use_vertex_groups, m.use_bone_envelopes,
                           m.use_deform_preserve_volume)
                          for i, m in enumerate(mesh_obj.modifiers)
                          if m.type == "ARMATURE" and m.object in rigs]
        # Every vertex group, in order, so that restoring keeps names, indices and locks.
        self.names = [group.name for group in mesh_obj.vertex_groups]
        self.locks = [group.lock_weight for group in mesh_obj.vertex_groups]
        self.active_group = mesh_obj.vertex_groups.active_index
        self.weights = mesh_io.read_groups(mesh_obj, self.names)

    def restore(self):
        """Put the saved binding back (the rigs themselves must still exist)."""
        obj = self.mesh_obj
        obj.vertex_groups.clear()
        mesh_io.write_groups(obj, self.names, *self.weights)
        for group, lock in zip(obj.vertex_groups, self.locks):
            group.lock_weight = lock
        obj.vertex_groups.active_index = self.active_group
        for index, name, rig, use_groups, use_envelopes, preserve in self.modifiers:
            modifier = obj.modifiers.get(name)
            if modifier is None or modifier.type != "ARMATURE":
                modifier = obj.modifiers.new(name, "ARMATURE")
            modifier.object = rig
            modifier.use_vertex_groups = use_groups
            modifier.use_bone_envelopes = use_envelopes
            modifier.use_deform_preserve_volume = preserve
            position = list(obj.modifiers).index(modifier)
            while position > index and position > 0:
                _move_modifier_up(obj, modifier)
                position -= 1
        obj.parent = self.parent
        obj.matrix_parent_inverse = self.parent_inverse
        obj.matrix_world = self.world


def _move_modifier_up(obj, modifier):
    """Move `modifier` one place up the stack of `obj` without an operator context."""
    if hasattr(obj.modifiers, "move"):  # Blender 3.5 and later
        index = list(obj.modifiers).index(modifier)
        obj.modifiers.move(index, index - 1)
        return
    with bpy.context.temp_override(object=obj):
        bpy.ops.object.modifier_move_up(modifier=modifier.name)
