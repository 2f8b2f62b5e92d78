"""The DCG tab of the 3D View's sidebar (N panel) and the Object > Animation menu entry."""

import bpy

from . import _engine, armature, editing, properties, rigging

#: Engine options shown in the main panel; the others go to "Advanced".
MAIN_OPTIONS = ("tau", "target_faces", "repair")


def _wrapped(layout, text, width=48):
    """Draw `text` as several labels of about `width` characters."""
    line = ""
    for word in text.split():
        if line and len(line) + len(word) > width:
            layout.label(text=line)
            line = ""
        line = f"{line} {word}".strip()
    if line:
        layout.label(text=line)


class VIEW3D_PT_dcg_rig(bpy.types.Panel):
    """Rig the active mesh with the DCG skeleton."""

    bl_space_type = "VIEW_3D"
    bl_region_type = "UI"
    bl_category = "DCG"
    bl_label = "DCG Rig"

    def draw(self, context):
        layout = self.layout
        error = _engine.error()
        if error is not None:
            box = layout.box()
            box.alert = True
            box.label(text="The DCG engine is not available", icon="ERROR")
            _wrapped(box, error)
            return
        obj = context.active_object
        if obj is not None and obj.type == "MESH":
            layout.label(text=f"{obj.name}: {len(obj.data.polygons)} faces", icon="MESH_DATA")
        elif obj is not None and editing.PREVIEW_OF in obj:
            self._draw_skeleton_editing(layout, obj)
        else:
            layout.label(text="Select a mesh object", icon="INFO")
        settings = properties.settings(context)
        layout.operator_menu_enum("dcg.preset", "preset", text="Preset", icon="PRESET")
        col = layout.column(align=True)
        for name in MAIN_OPTIONS:
            if hasattr(settings, name):
                col.prop(settings, name)
        col = layout.column(align=True)
        col.prop(settings, "weights")
        col.prop(settings, "bone_detail", slider=True)
        col.prop(settings, "bone_names")
        col.prop(settings, "root_bone")
        row = layout.row()
        row.scale_y = 1.5
        row.operator("object.dcg_auto_rig", icon="ARMATURE_DATA")
        row = layout.row(align=True)
        row.operator("object.dcg_preview", icon="HIDE_OFF")
        row.operator("object.dcg_clear", icon="X", text="Clear")
        layout.operator("dcg.load_mesh", icon="FILEBROWSER")
        if obj is not None and obj.type == "MESH":
            skeleton = editing.preview_skeleton(obj.name)
            if skeleton is not None and editing.is_edited(skeleton):
                layout.label(text="Rig binds the edited preview skeleton", icon="BONE_DATA")
            self._draw_last_rig(layout, obj)

    @staticmethod
    def _draw_skeleton_editing(layout, arm_obj):
        """The preview skeleton is active: how to edit it, Mirror, and what Rig will do."""
        box = layout.box()
        mesh_name = arm_obj[editing.PREVIEW_OF]
        box.label(text=f"Preview skeleton of {mesh_name}", icon="ARMATURE_DATA")
        _wrapped(box, "Tab into Edit Mode: move joints, delete spurious bones, extrude. "
                      f"Then select {mesh_name} and Rig with DCG: it binds these bones.")
        if editing.MIRROR_PLANE in arm_obj:
            if arm_obj.data.use_mirror_x:
                box.label(text="X-Axis Mirror is on: edits mirror as you make them")
            row = box.row(align=True)
            row.operator("dcg.mirror_skeleton", text="Mirror L to R").source = "L"
            row.operator("dcg.mirror_skeleton", text="Mirror R to L").source = "R"
        state = "edited" if editing.is_edited(arm_obj) else "as planned"
        box.label(text=f"{len(arm_obj.data.bones)} bones, {state}")

    @staticmethod
    def _draw_last_rig(layout, obj):
        """Show the bone counts and stage timings of the active mesh's rig, if any."""
        rigs = armature.find_rigs(obj)
        if not rigs:
            return
        rig = rigs[0]
        box = layout.box()
        kinds = [b.get("dcg_kind", "?") for b in rig.data.bones]
        box.label(text=f"{rig.name}: {len(kinds)} bones", icon="BONE_DATA")
        box.label(text=", ".join(f"{kinds.count(k)} {k}" for k in ("end", "joint",
                                                                   "connection")))
        if rigging.fallback_warning(rig.get("dcg_method", "dcg")):
            box.label(text="Fallback skeleton: the DCG failed on this mesh", icon="ERROR")
        timings = rig.get("dcg_timings")
        if timings:
            col = box.column(align=True)
            for stage, seconds in timings.items():
                col.label(text=f"{stage}: {seconds:.3f} s")


class VIEW3D_PT_dcg_rig_advanced(bpy.types.Panel):
    """The engine options not in the main panel."""

    bl_space_type = "VIEW_3D"
    bl_region_type = "UI"
    bl_category = "DCG"
    bl_label = "Advanced"
    bl_parent_id = "VIEW3D_PT_dcg_rig"
    bl_options = {"DEFAULT_CLOSED"}

    @classmethod
    def poll(cls, context):
        return _engine.error() is None

    def draw(self, context):
        settings = properties.settings(context)
        col = self.layout.column(align=True)
        for spec in properties.ENGINE_SPECS:
            if spec.name not in MAIN_OPTIONS and spec.stage != "weights":
                col.prop(settings, spec.name)
        # The weights' own options: only the DCG weights method uses them.
        col = self.layout.column(align=True)
        col.label(text="DCG weights")
        col.active = settings.weights == "DCG"
        for spec in properties.ENGINE_SPECS:
            if spec.stage == "weights":
                col.prop(settings, spec.name)


def menu_entry(self, context):
    """Object > Animation: the Rig operator."""
    self.layout.separator()
    self.layout.operator("object.dcg_auto_rig", icon="ARMATURE_DATA")


CLASSES = (VIEW3D_PT_dcg_rig, VIEW3D_PT_dcg_rig_advanced)
