"""scripts/make_stress_set.py (the bench's stress set) and scripts/mesh_parts.py (its parts and
the inside % by parts): numpy only, no engine, nothing timed."""

import make_stress_set as stress
import mesh_parts
import numpy as np
import pytest


@pytest.fixture(scope="module")
def small_set(tmp_path_factory):
    """The small meshes of the set, written twice."""
    names = [name for name, *_ in stress.SHAPES if "k." not in name]  # not biped-30k, ...-100k
    outs = [tmp_path_factory.mktemp(f"stress{i}") for i in range(2)]
    for out in outs:
        args = ["--out", str(out)] + [a for n in names for a in ("--only", n)]
        assert stress.main(args) == 0
    return names, outs


def test_the_set_is_written_the_same_every_time(small_set):
    names, (a, b) = small_set
    for name in names + ["MANIFEST.tsv"]:
        assert (a / name).read_bytes() == (b / name).read_bytes(), name


def test_manifest_has_the_public_columns_and_the_right_topology(small_set, repo):
    names, (out, _) = small_set
    lines = (out / "MANIFEST.tsv").read_text().splitlines()
    assert lines[0].split("\t") == stress.MANIFEST_COLUMNS
    public = repo.parent / "shared" / "meshes" / "MANIFEST.tsv"
    if public.is_file():
        assert public.read_text().splitlines()[0].split("\t") == stress.MANIFEST_COLUMNS
    rows = {r[0]: dict(zip(stress.MANIFEST_COLUMNS, r)) for r in
            (line.split("\t") for line in lines[1:])}
    assert sorted(rows) == sorted(names)
    expect = {"spheres-chain4.obj": ("yes", "4"), "spheres-disjoint.obj": ("yes", "3"),
              "body-eyes-inside.obj": ("yes", "3"), "pinched-blobs.obj": ("no", "2"),
              "scan-open.obj": ("no", "1"), "lowpoly-biped.obj": ("yes", "8"),
              "lowpoly-quadruped.obj": ("yes", "8")}
    for name, (closed, parts) in expect.items():
        assert (rows[name]["closed"], rows[name]["components"]) == (closed, parts), name
    assert "pinched" in rows["pinched-blobs.obj"]["notes"]
    for name in ("lowpoly-biped.obj", "lowpoly-quadruped.obj"):
        assert 1000 <= int(rows[name]["face_count"]) <= 3000


def test_every_closed_piece_faces_outwards():
    for name, build, *_ in stress.SHAPES:
        if "k." in name:
            continue
        V, F = mesh_parts.weld_exact(*build())
        parts = mesh_parts.face_parts(F)
        for part in range(parts.max() + 1):
            T = V[F[parts == part]]
            volume = np.einsum("ij,ij->i", T[:, 0], np.cross(T[:, 1], T[:, 2])).sum() / 6
            assert volume > 0, (name, part)


def test_subdivided_figures_keep_their_parts():
    V, F = stress.subdivided(stress.lowpoly_biped, 1)
    assert len(F) == 4 * len(stress.lowpoly_biped()[1])
    assert mesh_parts.topology(mesh_parts.weld_exact(V, F)[1])["parts"] == 8


def test_inside_by_parts_where_parity_is_wrong():
    """Two overlapping spheres: a point in the overlap is inside both (parity over the whole
    would say outside); a point between two disjoint spheres is outside."""
    V, F = stress.spheres_chain4()
    overlap, beyond = [0.7, 0, 0], [6.0, 0, 0]
    inside = mesh_parts.inside_any_part([overlap, [0, 0, 0], beyond], V, F)
    assert inside.tolist() == [True, True, False]
    V, F = stress.spheres_disjoint()
    assert mesh_parts.inside_any_part([[1.7, 0.15, 0], [2.4, 0.3, 0]], V, F).tolist() == [
        False, True]


def test_winding_numbers_of_a_closed_and_an_open_sphere():
    V, F = stress.uv_sphere(12, 16)
    w = mesh_parts.winding_numbers([[0, 0, 0], [0.5, 0.2, 0], [2, 0, 0]], V, F)
    assert w == pytest.approx([1, 1, 0], abs=1e-9)
    top = F[V[F].mean(axis=1)[:, 2] > 0]  # the upper half only
    assert mesh_parts.winding_numbers([[0, 0, 0]], V, top)[0] == pytest.approx(0.5, abs=0.02)


def test_pinched_vertex_and_borders_are_found():
    topo = mesh_parts.topology(mesh_parts.weld_exact(*stress.pinched_blobs())[1])
    assert (topo["pinched_vertices"], topo["parts"], topo["closed"]) == (1, 2, False)
    topo = mesh_parts.topology(mesh_parts.weld_exact(*stress.scan_open())[1])
    assert topo["border_edges"] > 0 and not topo["closed"]
    topo = mesh_parts.topology(stress.uv_sphere()[1])
    assert topo == {"border_edges": 0, "non_manifold_edges": 0, "pinched_vertices": 0,
                    "parts": 1, "closed": True, "genus": 0}


def test_skeleton_samples_follow_dcg_bench():
    skeleton = {"positions": [[0, 0, 0], [1, 0, 0]],
                "polylines": [[[0, 0, 0], [0.5, 0, 0], [1, 0, 0]]]}
    samples = mesh_parts.skeleton_samples(skeleton, 0.1)
    # 2 nodes, 1 inner polyline point, 4 samples inside each of the 2 segments of 0.5
    assert len(samples) == 2 + 1 + 2 * 4
    assert len(mesh_parts.graph_samples([[0, 0, 0], [1, 0, 0]], [[0, 1]], 0.1)) == 2 + 9


@pytest.mark.parametrize("name", ["lowpoly-biped.obj", "lowpoly-quadruped.obj",
                                  "body-eyes-touching.obj", "spheres-chain4.obj"])
def test_the_skeleton_of_a_closed_multi_part_mesh_is_inside_its_parts(small_set, name):
    """The union of the parts is remeshed into a surface that bulges out of the input a little
    at concave places; the skeleton is held inside the union itself (prepared.united), so every
    sample lies inside one of the input's parts (issue: lowpoly-biped had 1 of 412 outside)."""
    import dcg

    _, (out, _) = small_set
    V, F = dcg.load_mesh(out / name)
    inside = inside_by_parts(V, F, dcg.extract_skeleton(V, F))
    assert inside.all(), f"{(~inside).sum()} of {len(inside)} samples outside"


def inside_by_parts(V, F, skeleton):
    """Per skeleton sample (dcg_bench's: nodes, polyline points, every 0.5% of the diagonal):
    inside one of the parts of (V, F)."""
    Vw, Fw = mesh_parts.weld_exact(V, F)
    spacing = mesh_parts.SAMPLE_SPACING * float(np.linalg.norm(np.ptp(Vw, axis=0)))
    samples = mesh_parts.skeleton_samples(
        {"positions": np.asarray(skeleton.positions).tolist(),
         "polylines": [np.asarray(p).tolist() for p in skeleton.polylines]}, spacing)
    return mesh_parts.inside_any_part(samples, Vw, Fw, mesh_parts.face_parts(Fw))


@pytest.mark.parametrize("name, ends", [("wolf-open.obj", 6), ("rigged/Q_Male_Casual.obj", 5)])
def test_small_holes_filled_and_wrapped_keep_the_legs_apart(meshes_dir, name, ends):
    """Meshes whose holes are small but whose parts cross (no union): the filled mesh is wrapped
    finely. Wrapped at the size of their holes (4.1-4.3% of the diagonal), the legs were webbed
    together: 4 ends each, and 36% of Q_Male_Casual's skeleton between its legs, outside it."""
    import dcg

    if not (meshes_dir / name).is_file():
        pytest.skip(f"{name} not found")
    V, F = dcg.load_mesh(meshes_dir / name)
    skeleton = dcg.extract_skeleton(V, F)
    assert list(skeleton.kinds).count("end") == ends  # 4 legs, head, tail; 2 arms, 2 legs, head
    inside = inside_by_parts(V, F, skeleton)
    assert inside.mean() >= 0.99, f"{(~inside).sum()} of {len(inside)} samples outside"
