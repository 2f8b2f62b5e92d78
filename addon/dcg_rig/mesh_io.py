"""Blender meshes <-> numpy arrays (V float64 #V by 3, F int64 #F by 3)."""

import bpy
import numpy as np


def _world(points, matrix):
    """Return points (#P by 3) transformed by a 4x4 `mathutils.Matrix`."""
    m = np.array(matrix, dtype=float)
    return points @ m[:3, :3].T + m[:3, 3]


def evaluated_world_mesh(context, obj):
    """Return (V, F) of `obj` as the viewport shows it: modifiers applied, triangulated,
    in world space."""
    evaluated = obj.evaluated_get(context.evaluated_depsgraph_get())
    mesh = evaluated.to_mesh()
    try:
        mesh.calc_loop_triangles()
        V = np.empty(len(mesh.vertices) * 3, dtype=np.float32)
        mesh.vertices.foreach_get("co", V)
        F = np.empty(len(mesh.loop_triangles) * 3, dtype=np.int32)
        mesh.loop_triangles.foreach_get("vertices", F)
        matrix = evaluated.matrix_world.copy()
    finally:
        evaluated.to_mesh_clear()
    V = _world(V.reshape(-1, 3).astype(np.float64), matrix)
    return V, F.reshape(-1, 3).astype(np.int64)


def local_vertices(mesh):
    """Return the #V by 3 float32 coordinates of a mesh datablock (exact, for restoring)."""
    co = np.empty(len(mesh.vertices) * 3, dtype=np.float32)
    mesh.vertices.foreach_get("co", co)
    return co.reshape(-1, 3)


def set_local_vertices(mesh, co):
    """Set the coordinates of a mesh datablock from #V by 3 float32 `co`."""
    mesh.vertices.foreach_set("co", np.ascontiguousarray(co, dtype=np.float32).ravel())
    mesh.update()


def world_vertices(obj):
    """Return the #V by 3 world positions of the original (not evaluated) vertices of `obj`:
    the vertices that vertex groups weight."""
    return _world(local_vertices(obj.data).astype(np.float64), obj.matrix_world)


def mesh_from_arrays(name, V, F):
    """Return a new mesh datablock from V (#V by 3) and F (#F by 3)."""
    mesh = bpy.data.meshes.new(name)
    mesh.from_pydata(np.asarray(V, dtype=float).tolist(), [],
                     np.asarray(F, dtype=np.int64).tolist())
    mesh.validate()
    mesh.update()
    return mesh
