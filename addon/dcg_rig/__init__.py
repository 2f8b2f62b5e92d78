"""dcg-rig: one-click automatic rigging with the Domain Connected Graph skeleton.

The operator `object.dcg_auto_rig` (Object > Animation > Rig with DCG, or the sidebar's DCG tab) turns
the active mesh into a rigged character: the engine (`dcg`, C++) extracts the skeleton of
the evaluated mesh in world space, `armature` builds end, joint and connection bones and
`weights` binds the mesh. `cli.py` does the same headlessly (`make rig`).

The bone plan is the engine package's (`dcg.bones`). The modules without `bpy` (options,
skinning, geometry, worker, _engine) are tested by plain pytest; this file only registers
when it runs inside Blender.
"""

bl_info = {
    "name": "DCG Rig",
    "author": "dcg-rig developers",
    "version": (0, 1, 0),
    "blender": (3, 4, 0),
    "location": "View3D > Sidebar > DCG, and Object > Animation > Rig with DCG",
    "description": "One-click automatic rigging from the Domain Connected Graph skeleton",
    "category": "Rigging",
}

try:
    import bpy
except ImportError:  # plain Python (pytest on the pure modules)
    bpy = None

if bpy is not None:
    from bpy.props import PointerProperty

    from . import live, operators, properties, ui

    _CLASSES = (properties.DCGRigSettings, *operators.CLASSES, *ui.CLASSES)

    @bpy.app.handlers.persistent
    def _forget_live_preview(*_):
        """A loaded file has no preview of ours: drop the kept extractor (live.py)."""
        live.forget()

    def register():
        for cls in _CLASSES:
            bpy.utils.register_class(cls)
        bpy.types.Scene.dcg_rig = PointerProperty(type=properties.DCGRigSettings)
        bpy.types.VIEW3D_MT_object_animation.append(ui.menu_entry)
        bpy.app.handlers.load_post.append(_forget_live_preview)

    def unregister():
        if _forget_live_preview in bpy.app.handlers.load_post:
            bpy.app.handlers.load_post.remove(_forget_live_preview)
        live.forget()
        bpy.types.VIEW3D_MT_object_animation.remove(ui.menu_entry)
        del bpy.types.Scene.dcg_rig
        for cls in reversed(_CLASSES):
            bpy.utils.unregister_class(cls)
