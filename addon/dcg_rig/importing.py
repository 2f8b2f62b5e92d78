"""Mesh files into the scene for headless rigging: one mesh object, whatever the format.

- ``.off``, ``.ply``, ``.stl``: the engine's reader (`dcg.load_mesh` operator), the same
  triangles the Python API sees;
- ``.obj``: checked by the engine's reader first (clear errors for bad files), then imported
  with Blender's OBJ importer so that UVs and materials reach the exported .glb/.fbx;
- ``.fbx``, ``.glb``, ``.gltf``: Blender's importers. Earlier rigs in the file are dropped:
  the mesh objects are unparented (world transform kept), their Armature modifiers and
  vertex groups removed, and every other imported object deleted.

Several meshes are joined into one object (the engine repairs multi-part input).
"""

import os

import bpy

from . import _engine
from .rigging import RigError

ENGINE_FORMATS = (".off", ".ply", ".stl")
BLENDER_FORMATS = (".obj", ".fbx", ".glb", ".gltf")
FORMATS = ENGINE_FORMATS + BLENDER_FORMATS


def ensure_numpy_bool_alias():
    """Give numpy back its `np.bool` alias (removed in numpy 1.24), which the glTF importer
    of Blender 3.4 still uses; without it every .glb/.gltf import fails."""
    import numpy

    if "bool" not in numpy.__dict__:
        numpy.bool = bool


def _call_importer(extension, path, up):
    """Run Blender's importer for `extension`; `up` is "Y" or "Z" (OBJ only)."""
    if extension == ".obj":
        forward = "NEGATIVE_Z" if up == "Y" else "Y"
        if hasattr(bpy.ops.wm, "obj_import"):
            return bpy.ops.wm.obj_import(filepath=path, up_axis=up, forward_axis=forward)
        return bpy.ops.import_scene.obj(filepath=path, axis_up=up,
                                        axis_forward="-Z" if up == "Y" else "Y")
    if extension == ".fbx":
        return bpy.ops.import_scene.fbx(filepath=path)
    ensure_numpy_bool_alias()
    importer = bpy.ops.import_scene.gltf
    # Blender 4.0+ adds a hidden "Icosphere" for the bones' display unless told not to.
    options = {"disable_bone_shape": True} if _has_option(importer, "disable_bone_shape") else {}
    return importer(filepath=path, **options)


def _has_option(operator, name):
    """Whether the operator `operator` has a property `name` (importers differ by version)."""
    return name in operator.get_rna_type().properties.keys()


def _not_part_of_the_model(objects):
    """The imported objects that are helpers, not the model: the armatures' bone shapes and what
    an importer put in a not-exported collection (glTF's `glTF_not_exported`)."""
    helpers = set()
    for obj in objects:
        if obj.type == "ARMATURE" and obj.pose is not None:
            helpers.update(b.custom_shape for b in obj.pose.bones if b.custom_shape is not None)
        if any(c.name.startswith("glTF_not_exported") for c in obj.users_collection):
            helpers.add(obj)
    return helpers


def _model_meshes(context, objects):
    """The mesh objects of `objects` that make the model: with faces, not a helper, and
    visible (the hidden ones only when no mesh is visible)."""
    helpers = _not_part_of_the_model(objects)
    meshes = [o for o in objects
              if o.type == "MESH" and len(o.data.polygons) and o not in helpers]
    visible = [o for o in meshes if not o.hide_viewport and
               (o.name not in context.view_layer.objects or not o.hide_get())]
    return visible or meshes


def _single_mesh(context, objects, path):
    """Keep the mesh objects of `objects`, stripped of rigs and joined; delete the rest."""
    meshes = _model_meshes(context, objects)
    if not meshes:
        for obj in objects:
            bpy.data.objects.remove(obj)
        raise RigError(f"{os.path.basename(path)}: no mesh with faces in the file")
    for obj in objects:
        if obj not in meshes:
            bpy.data.objects.remove(obj)
    for obj in meshes:
        world = obj.matrix_world.copy()
        obj.parent = None
        obj.matrix_world = world
        for modifier in [m for m in obj.modifiers if m.type == "ARMATURE"]:
            obj.modifiers.remove(modifier)
        obj.vertex_groups.clear()
        obj.shape_key_clear()
    view_layer = context.view_layer
    view_layer.update()
    for obj in view_layer.objects:
        obj.select_set(obj in meshes)
    view_layer.objects.active = meshes[0]
    if len(meshes) > 1:
        bpy.ops.object.join()
    return view_layer.objects.active


def import_mesh_file(context, path, up="AUTO"):
    """Import the mesh file `path` as one active mesh object; return it (RigError on failure).

    `up`: "AUTO" (Y for OBJ, Z otherwise; glTF and FBX carry their own axes), "Y" or "Z".
    """
    path = os.path.abspath(path)
    extension = os.path.splitext(path)[1].lower()
    if extension not in FORMATS:
        raise RigError(f"{os.path.basename(path)}: unknown format {extension!r}; "
                       f"known: {', '.join(FORMATS)}")
    if extension in ENGINE_FORMATS:
        try:
            bpy.ops.dcg.load_mesh(filepath=path, up_axis=up)
        except RuntimeError as error:
            raise RigError(str(error).replace("Error: DCG: ", "").strip()) from None
        return context.view_layer.objects.active
    if extension == ".obj":
        _engine.require().load_mesh(path)  # OSError / ValueError naming the file and reason
    if not os.path.isfile(path):
        raise RigError(f"{path}: no such file")
    before = set(bpy.data.objects)
    try:
        _call_importer(extension, path, "Y" if up == "AUTO" else up)
    except RuntimeError as error:
        raise RigError(f"{os.path.basename(path)}: {str(error).strip()}") from None
    imported = [o for o in bpy.data.objects if o not in before]
    return _single_mesh(context, imported, path)
