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


def empty_groups(obj, names):
    """Give `obj` an empty vertex group per name (replacing same-named groups; None: none)."""
    for name in filter(None, names):
        group = obj.vertex_groups.get(name)
        if group is not None:
            obj.vertex_groups.remove(group)
        obj.vertex_groups.new(name=name)


def read_groups(obj, names):
    """Return the sparse weights (rows, cols, values) of the vertex groups named `names`
    (column i is names[i]; missing groups, or None, give no entries)."""
    column = {obj.vertex_groups[n].index: i for i, n in enumerate(names)
              if n is not None and n in obj.vertex_groups}
    rows, cols, values = [], [], []
    for vertex in obj.data.vertices:
        for element in vertex.groups:
            col = column.get(element.group)
            if col is not None and element.weight > 0:
                rows.append(vertex.index)
                cols.append(col)
                values.append(element.weight)
    return (np.array(rows, dtype=np.int64), np.array(cols, dtype=np.int64),
            np.array(values, dtype=float))


def write_groups(obj, names, rows, cols, values):
    """Replace the vertex groups `names` of `obj` by the sparse weights (rows, cols, values);
    a column whose name is None gets no group (ValueError if it holds a weight).

    Entries that share a group and a weight go in one call (full weights of 1, common
    far from the joints, batch well)."""
    empty_groups(obj, names)
    groups = [None if n is None else obj.vertex_groups[n] for n in names]
    rows, cols, values = (np.asarray(a) for a in (rows, cols, values))
    if not len(rows):
        return
    order = np.lexsort((values, cols))
    rows, cols, values = rows[order], cols[order], values[order]
    keys = np.stack([cols, values])
    starts = np.flatnonzero(np.r_[True, (np.diff(keys, axis=1) != 0).any(axis=0)])
    ends = np.r_[starts[1:], len(rows)]
    for start, end in zip(starts.tolist(), ends.tolist()):
        group = groups[int(cols[start])]
        if group is None:
            raise ValueError(f"bone {int(cols[start])} deforms nothing but has weights")
        group.add(rows[start:end].tolist(), float(values[start]), "REPLACE")
