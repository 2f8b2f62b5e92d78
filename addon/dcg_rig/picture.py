"""A picture of a rig, rendered headlessly: the mesh, with the bones drawn in front.

Armatures do not render, so the bones are stood in for by octahedral meshes colored by kind
(end red, joint purple, connection blue, the root yellow, as in the viewport). Two Workbench
renders (it works without a GPU) are composited with numpy: the mesh alone, then the bones
alone on a transparent film, laid over the mesh like Blender's "In Front" display. Everything
made for the picture is removed afterwards and the scene's render settings are restored.
"""

import os
import tempfile

import bpy
import numpy as np
from mathutils import Vector

from . import armature, geometry, mesh_io

BONE_OPACITY = 0.9
BACKGROUND = (0.55, 0.57, 0.6)


def _render_to_pixels(scene, path):
    """Render the scene's camera view to `path` (PNG); return its #H by #W by 4 pixels."""
    scene.render.filepath = path
    bpy.ops.render.render(write_still=True)
    image = bpy.data.images.load(path, check_existing=False)
    try:
        width, height = image.size
        pixels = np.empty(width * height * 4, dtype=np.float32)
        image.pixels.foreach_get(pixels)
    finally:
        bpy.data.images.remove(image)
    return pixels.reshape(height, width, 4)


def _save_pixels(pixels, path):
    height, width = pixels.shape[:2]
    image = bpy.data.images.new("dcg picture", width, height, alpha=True)
    try:
        image.pixels.foreach_set(np.ascontiguousarray(pixels, dtype=np.float32).ravel())
        image.filepath_raw = path
        image.file_format = "PNG"
        image.save()
    finally:
        bpy.data.images.remove(image)


def _bone_objects(scene, arm_obj, size):
    """Link one stand-in mesh object per bone kind; return them."""
    heads, tails = armature.bone_world_segments(arm_obj)
    kinds = np.array([b.get("dcg_kind", "connection") for b in arm_obj.data.bones])
    widths = np.maximum(0.15 * np.linalg.norm(tails - heads, axis=1), 0.004 * size)
    widths[kinds == "root"] = 0.006 * size  # drawn thin, as the viewport's wire (4.1+)
    made = []
    for kind, colors in armature.KIND_COLORS.items():
        chosen = kinds == kind
        if not chosen.any():
            continue
        V, F = geometry.octahedral_bones(heads[chosen], tails[chosen], widths[chosen])
        obj = bpy.data.objects.new(f"dcg picture {kind}",
                                   mesh_io.mesh_from_arrays(f"dcg picture {kind}", V, F))
        obj.color = (*colors[0], 1.0)
        scene.collection.objects.link(obj)
        made.append(obj)
    return made


def render_rig_picture(context, path, arm_obj, mesh_obj, resolution=(960, 720)):
    """Write a PNG picture of `mesh_obj` rigged by `arm_obj` to `path`."""
    scene = context.scene
    corners = np.array([mesh_obj.matrix_world @ Vector(c) for c in mesh_obj.bound_box])
    low, high = corners.min(axis=0), corners.max(axis=0)
    bones = _bone_objects(scene, arm_obj, float(np.linalg.norm(high - low)))
    camera = bpy.data.objects.new("dcg picture camera", bpy.data.cameras.new("dcg picture"))
    scene.collection.objects.link(camera)
    # Look at the long side of the shape, a little from the front and from above.
    side = (1.0, -0.45, 0.35) if high[1] - low[1] > high[0] - low[0] else (0.45, -1.0, 0.35)
    location, direction = geometry.frame_camera(low, high, camera.data.angle, side)
    camera.location = location
    camera.rotation_euler = Vector(direction).to_track_quat("-Z", "Y").to_euler()

    render, shading = scene.render, scene.display.shading
    saved = {"camera": scene.camera, "world": scene.world, "engine": render.engine,
             "x": render.resolution_x, "y": render.resolution_y,
             "percentage": render.resolution_percentage, "film": render.film_transparent,
             "filepath": render.filepath, "format": render.image_settings.file_format,
             "color_mode": render.image_settings.color_mode, "light": shading.light,
             "color_type": shading.color_type, "mesh_color": tuple(mesh_obj.color),
             "mesh_hidden": mesh_obj.hide_render,
             "view": (scene.view_settings.view_transform, scene.view_settings.look)}
    world = bpy.data.worlds.new("dcg picture")
    world.color = BACKGROUND
    others = [o for o in scene.objects if o not in bones and o is not mesh_obj
              and not o.hide_render]
    with tempfile.TemporaryDirectory() as folder:
        try:
            scene.camera, scene.world = camera, world
            render.engine = "BLENDER_WORKBENCH"
            render.resolution_x, render.resolution_y = resolution
            render.resolution_percentage = 100
            render.image_settings.file_format = "PNG"
            render.image_settings.color_mode = "RGBA"
            # The kind colors as they are: AgX (the default since 4.0) would desaturate them.
            scene.view_settings.view_transform, scene.view_settings.look = "Standard", "None"
            shading.light, shading.color_type = "STUDIO", "OBJECT"
            mesh_obj.color = (0.85, 0.85, 0.85, 1.0)
            for obj in others:
                obj.hide_render = True
            for obj in bones:
                obj.hide_render = True
            render.film_transparent = False
            body = _render_to_pixels(scene, os.path.join(folder, "mesh.png"))
            for obj in bones:
                obj.hide_render = False
            mesh_obj.hide_render = True
            render.film_transparent = True
            front = _render_to_pixels(scene, os.path.join(folder, "bones.png"))
        finally:
            for obj in others:
                obj.hide_render = False
            scene.camera, scene.world = saved["camera"], saved["world"]
            render.engine, render.film_transparent = saved["engine"], saved["film"]
            render.resolution_x, render.resolution_y = saved["x"], saved["y"]
            render.resolution_percentage = saved["percentage"]
            render.filepath = saved["filepath"]
            render.image_settings.file_format = saved["format"]
            render.image_settings.color_mode = saved["color_mode"]
            scene.view_settings.view_transform, scene.view_settings.look = saved["view"]
            shading.light, shading.color_type = saved["light"], saved["color_type"]
            mesh_obj.color, mesh_obj.hide_render = saved["mesh_color"], saved["mesh_hidden"]
            for obj in bones + [camera]:
                data = obj.data
                bpy.data.objects.remove(obj)
                (bpy.data.meshes if isinstance(data, bpy.types.Mesh)
                 else bpy.data.cameras).remove(data)
            bpy.data.worlds.remove(world)
    alpha = BONE_OPACITY * front[..., 3:4]
    picture = body.copy()
    picture[..., :3] = body[..., :3] * (1.0 - alpha) + front[..., :3] * alpha
    picture[..., 3] = 1.0
    _save_pixels(picture, os.path.abspath(path))
    return path
