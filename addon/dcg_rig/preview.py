"""The "DCG Preview" collection: the skeleton shown without rigging, and the kind materials.

The preview holds one object per node kind (small spheres at the nodes, colored like the
bones) and one edge object with the link polylines. The next preview or a rig replaces it.
"""

import bpy
import numpy as np

from . import geometry, mesh_io
from .armature import KIND_COLORS

COLLECTION_NAME = "DCG Preview"


def kind_material(kind):
    """Return the material "DCG <kind>": emissive in renders, the kind's color in Solid mode."""
    name = f"DCG {kind}"
    material = bpy.data.materials.get(name)
    if material is not None:
        return material
    color = KIND_COLORS[kind][0]
    material = bpy.data.materials.new(name)
    material.diffuse_color = (*color, 1.0)
    if material.node_tree is None:  # Blender < 5.0 (5.0 always has one; use_nodes is deprecated)
        material.use_nodes = True
    nodes, links = material.node_tree.nodes, material.node_tree.links
    nodes.clear()
    emission = nodes.new("ShaderNodeEmission")
    emission.inputs["Color"].default_value = (*color, 1.0)
    emission.inputs["Strength"].default_value = 2.0
    output = nodes.new("ShaderNodeOutputMaterial")
    links.new(emission.outputs["Emission"], output.inputs["Surface"])
    return material


def add_mesh_object(name, V, F, collection, material=None):
    """Return a new object in `collection` with the mesh (V, F) and `material`."""
    obj = bpy.data.objects.new(name, mesh_io.mesh_from_arrays(name, V, F))
    if material is not None:
        obj.data.materials.append(material)
    collection.objects.link(obj)
    return obj


def clear_preview():
    """Remove the preview collection, its objects and their meshes."""
    collection = bpy.data.collections.get(COLLECTION_NAME)
    if collection is None:
        return
    active = bpy.context.object
    if active is not None and active.mode != "OBJECT" and active.name in collection.objects:
        bpy.ops.object.mode_set(mode="OBJECT")  # the preview skeleton in Edit Mode: leave it
    for obj in list(collection.objects):
        data, blocks = obj.data, bpy.data.armatures if obj.type == "ARMATURE" else bpy.data.meshes
        bpy.data.objects.remove(obj)
        if data is not None and data.users == 0:
            blocks.remove(data)
    bpy.data.collections.remove(collection)


def node_sizes(skeleton, fraction=0.35):
    """Return sphere radii for the nodes: a fraction of each node's radius, kept between
    0.4% and 2% of the skeleton's size so that every node stays visible."""
    positions = np.asarray(skeleton.positions, dtype=float).reshape(-1, 3)
    size = max(float(np.linalg.norm(np.ptp(positions, axis=0))), 1e-9)
    return np.clip(fraction * np.asarray(skeleton.radii, dtype=float), 0.004 * size,
                   0.02 * size)


def stage_geometry(extractor):
    """Return {"domain balls": (centers, radii), "prongs": (positions, radii)} in the input's
    coordinates from an Extractor that has run (stages it lacks are left out)."""
    prepared = extractor.prepare()
    scale, offset = float(prepared.scale), np.asarray(prepared.offset, dtype=float)
    balls = extractor.domain_balls()
    result = {"domain balls": (balls.centers * scale + offset, balls.radii * scale)}
    if hasattr(extractor, "prongs"):
        prongs = extractor.prongs()
        size = np.full(len(prongs.positions), 0.012 * scale)
        result["prongs"] = (prongs.positions * scale + offset, size)
    return result


def build_preview(context, skeleton, stages=None):
    """Replace the preview collection by the nodes and links of `skeleton` (world space) and
    the intermediate `stages` (see `stage_geometry`): domain balls drawn as wireframes,
    prong peaks as red spheres."""
    clear_preview()
    collection = bpy.data.collections.new(COLLECTION_NAME)
    context.scene.collection.children.link(collection)
    for name, (centers, radii) in (stages or {}).items():
        if len(centers) == 0:
            continue
        V, F = geometry.spheres(centers, radii)
        material = kind_material("end") if name == "prongs" else None
        obj = add_mesh_object(f"DCG {name}", V, F, collection, material)
        if name == "domain balls":
            obj.display_type = "WIRE"
            obj.hide_render = True
        obj.show_in_front = True
    positions = np.asarray(skeleton.positions, dtype=float).reshape(-1, 3)
    kinds = np.asarray([str(k) for k in skeleton.kinds])
    sizes = node_sizes(skeleton)
    for kind in KIND_COLORS:
        chosen = kinds == kind
        if chosen.any():
            V, F = geometry.spheres(positions[chosen], sizes[chosen])
            obj = add_mesh_object(f"DCG {kind} nodes", V, F, collection, kind_material(kind))
            obj.show_in_front = True
    points, edges = [], []
    for polyline in skeleton.polylines:
        polyline = np.asarray(polyline, dtype=float).reshape(-1, 3)
        start = sum(len(p) for p in points)
        edges += [(start + i, start + i + 1) for i in range(len(polyline) - 1)]
        points.append(polyline)
    mesh = bpy.data.meshes.new("DCG links")
    mesh.from_pydata(np.concatenate(points).tolist() if points else [], edges, [])
    links = bpy.data.objects.new("DCG links", mesh)
    links.show_in_front = True
    collection.objects.link(links)
    return collection
