"""The add-on's DCG weights (the default): every vertex weighted by the engine's bone heat, where
Blender's Automatic Weights fails too (small scale, open meshes, parts that see no bone)."""

import numpy as np
import pytest

import bpy
from mathutils import Matrix
from conftest import add_mesh, capsule


def rig(**kwargs):
    return bpy.ops.object.dcg_auto_rig(**kwargs)


def check_weighted(obj, max_influences=4):
    """Every vertex has 1..max_influences groups with weights summing to 1."""
    counts = np.array([len(v.groups) for v in obj.data.vertices])
    sums = np.array([sum(g.weight for g in v.groups) for v in obj.data.vertices])
    assert counts.min() >= 1, f"{np.sum(counts == 0)} vertices have no group"
    assert counts.max() <= max_influences
    assert np.allclose(sums, 1.0, atol=1e-3), f"{np.sum(~np.isclose(sums, 1, atol=1e-3))} bad"


def test_dcg_is_the_default_weights_method_of_the_panel_and_the_operator():
    for rna in (bpy.context.scene.dcg_rig.bl_rna, bpy.ops.object.dcg_auto_rig.get_rna_type()):
        assert rna.properties["weights"].default == "DCG"


def test_the_weights_options_of_the_panel_reach_the_engine(repo):
    # The engine's weights options (dcg.OPTIONS, stage "weights") are settings of the add-on,
    # drawn under "DCG weights"; one influence per vertex is something the default never gives.
    settings = bpy.context.scene.dcg_rig
    assert settings.bl_rna.properties["max_influences"].default == 4
    bpy.ops.dcg.load_mesh(filepath=str(repo / "data" / "spot.obj"))
    obj = bpy.context.active_object
    assert rig(weights="DCG", max_influences=1) == {"FINISHED"}
    check_weighted(obj, max_influences=1)
    assert all(len(v.groups) == 1 for v in obj.data.vertices)


@pytest.mark.parametrize("scale", [0.01, 1.0])
def test_dcg_weights_every_vertex_of_spot(repo, scale):
    bpy.ops.dcg.load_mesh(filepath=str(repo / "data" / "spot.obj"))
    obj = bpy.context.active_object
    # Scale the mesh data (Blender's bone heat fails on it at 0.01), and move the object.
    obj.data.transform(Matrix.Scale(scale, 4))
    obj.location = (3.0, -1.0, 0.5)
    bpy.context.view_layer.update()
    assert rig(weights="DCG") == {"FINISHED"}
    check_weighted(obj)
    (arm,) = [o for o in bpy.data.objects if o.type == "ARMATURE"]
    names = {b.name for b in arm.data.bones if b.use_deform}  # not the root bone: no group
    assert {g.name for g in obj.vertex_groups} == names
    # Each end bone (a prong: leg, head, tail) is the strongest bone of some vertices.
    strongest = set()
    for vertex in obj.data.vertices:
        strongest.add(obj.vertex_groups[max(vertex.groups, key=lambda g: g.weight).group].name)
    ends = {b.name for b in arm.data.bones if b.get("dcg_kind") == "end"}
    assert ends and ends <= strongest, f"end bones owning no vertex: {sorted(ends - strongest)}"


def test_dcg_weights_an_open_multi_part_mesh():
    # A capsule with its top cap removed, and a small closed box floating inside it.
    V, F = capsule()
    keep = V[F].mean(axis=1)[:, 2] < 1.1
    box = np.array([[x, y, z] for x in (-0.1, 0.1) for y in (-0.1, 0.1) for z in (-0.1, 0.1)])
    box_faces = np.array([[0, 1, 3], [0, 3, 2], [4, 6, 7], [4, 7, 5], [0, 4, 5], [0, 5, 1],
                          [2, 3, 7], [2, 7, 6], [0, 2, 6], [0, 6, 4], [1, 5, 7], [1, 7, 3]])
    V2 = np.vstack([V, box])
    F2 = np.vstack([F[keep], box_faces + len(V)])
    obj = add_mesh("open", V2, F2, location=(1.0, 2.0, 0.0), scale=0.5)
    assert rig(weights="DCG") == {"FINISHED"}
    check_weighted(obj)
