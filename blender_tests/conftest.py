"""Fixtures for the tests that run inside Blender (see run.py)."""

import os
import sys
from pathlib import Path

import bpy
import numpy as np
import pytest

REPO = Path(__file__).resolve().parents[1]


@pytest.fixture(scope="session")
def repo():
    return REPO


#: True when run.py installed the add-on as a Blender 4.2+ extension (else the legacy add-on).
AS_EXTENSION = bool(os.environ.get("DCG_EXTENSION"))


def addon_dir():
    """The folder of the enabled add-on (the installed extension, or the build output)."""
    return Path(sys.modules["dcg_rig"].__file__).resolve().parent


def blender_command(script, *args):
    """The command that runs the Python file `script` with `args` in a new headless Blender:
    the Blender application when this is one, else this interpreter (PyPI's `bpy` module)."""
    args = [str(a) for a in args]
    if bpy.app.binary_path:
        return [bpy.app.binary_path, "-b", "--factory-startup", "--python-exit-code", "1",
                "--python", str(script), "--", *args]
    return [sys.executable, str(script), "--", *args]


@pytest.fixture(scope="session")
def dcg():
    """The engine package the add-on imported."""
    from dcg_rig import _engine

    return _engine.require()


def shared_skeleton(dcg, V, F, name, **options):
    """dcg.extract_skeleton(V, F, **options) of the shared mesh `name`, checked to be a DCG
    skeleton: the engine's fallback must not pass a test on a shared mesh silently."""
    skeleton = dcg.extract_skeleton(V, F, **options)
    assert skeleton.method == "dcg", f"{name}: the engine fell back: {skeleton.method}"
    return skeleton


def _clear_scene():
    for obj in list(bpy.data.objects):
        bpy.data.objects.remove(obj)
    for blocks in (bpy.data.meshes, bpy.data.armatures, bpy.data.collections,
                   bpy.data.materials, bpy.data.cameras, bpy.data.images):
        for block in list(blocks):
            if block.users == 0 or blocks is bpy.data.collections:
                blocks.remove(block)


@pytest.fixture(autouse=True)
def scene():
    """An empty scene with the DCG settings at their defaults, in Object Mode."""
    if bpy.context.object is not None and bpy.context.object.mode != "OBJECT":
        bpy.ops.object.mode_set(mode="OBJECT")
    _clear_scene()
    bpy.ops.dcg.preset(preset="DEFAULT")
    yield bpy.context.scene
    _clear_scene()


def add_mesh(name, V, F, location=(0.0, 0.0, 0.0), rotation=(0.0, 0.0, 0.0), scale=1.0):
    """Link a mesh object made of (V, F), make it the only selected and the active object."""
    from dcg_rig import mesh_io

    obj = bpy.data.objects.new(name, mesh_io.mesh_from_arrays(name, V, F))
    obj.location, obj.rotation_euler, obj.scale = location, rotation, (scale,) * 3
    bpy.context.scene.collection.objects.link(obj)
    for other in bpy.context.view_layer.objects:
        other.select_set(False)
    obj.select_set(True)
    bpy.context.view_layer.objects.active = obj
    bpy.context.view_layer.update()
    return obj


def capsule(length=2.0, radius=0.35, rings=24, segments=24):
    """A closed capsule along z (two prongs), outward triangles."""
    points = [(0.0, 0.0, -length / 2 - radius)]
    for i in range(1, rings):
        theta = np.pi * i / rings
        z = -np.cos(theta) * radius + (length / 2 if theta > np.pi / 2 else -length / 2)
        for j in range(segments):
            phi = 2 * np.pi * j / segments
            points.append((radius * np.sin(theta) * np.cos(phi),
                           radius * np.sin(theta) * np.sin(phi), z))
    points.append((0.0, 0.0, length / 2 + radius))
    top, faces = len(points) - 1, []

    def at(i, j):
        return 1 + (i - 1) * segments + j % segments

    for j in range(segments):
        faces.append((0, at(1, j + 1), at(1, j)))
        faces.append((top, at(rings - 1, j), at(rings - 1, j + 1)))
    for i in range(1, rings - 1):
        for j in range(segments):
            faces.append((at(i, j), at(i, j + 1), at(i + 1, j + 1)))
            faces.append((at(i, j), at(i + 1, j + 1), at(i + 1, j)))
    return np.array(points, dtype=float), np.array(faces, dtype=np.int64)


def scene_counts():
    """A summary of what the scene holds, to check that a failure changed nothing."""
    return {
        "objects": sorted(o.name for o in bpy.data.objects),
        "armatures": len(bpy.data.armatures),
        "meshes": len(bpy.data.meshes),
        "collections": len(bpy.data.collections),
        "modifiers": {o.name: [m.name for m in o.modifiers] for o in bpy.data.objects},
        "groups": {o.name: [g.name for g in o.vertex_groups] for o in bpy.data.objects},
        "parents": {o.name: o.parent.name if o.parent else None for o in bpy.data.objects},
        "mesh data": {m.name: _mesh_digest(m) for m in bpy.data.meshes},
    }


def _mesh_digest(mesh):
    """Vertex coordinates and polygon vertex indices of a mesh datablock, as bytes."""
    co = np.empty(len(mesh.vertices) * 3, dtype=np.float32)
    mesh.vertices.foreach_get("co", co)
    loops = np.empty(len(mesh.loops), dtype=np.int32)
    mesh.loops.foreach_get("vertex_index", loops)
    return co.tobytes() + loops.tobytes()


def pytest_configure(config):
    config.addinivalue_line("markers", "slow: a test that takes more than a few seconds")
    os.environ.setdefault("DCG_MESHES", str(REPO.parent / "shared" / "meshes"))
