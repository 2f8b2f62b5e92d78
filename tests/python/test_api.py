"""The Python API contract: extract_skeleton, Skeleton, the JSON schema, Extractor, options."""

import json

import numpy as np
import pytest

import dcg
from conftest import REPO, cube

FAST = {"samples": 1200, "target_faces": 5000}


@pytest.fixture(scope="module")
def spot(repo):
    return dcg.load_mesh(repo / "data" / "spot.obj")


@pytest.fixture(scope="module")
def spot_skeleton(spot):
    return dcg.extract_skeleton(*spot, **FAST)


def test_options_table_has_the_design_defaults():
    o = dcg.OPTIONS
    assert o["tau"].default == pytest.approx(0.85)
    assert o["samples"].default == 4000 and o["samples"].kind == "int"
    assert o["target_faces"].default == 20000
    assert o["geodesic_sources"].default == 128
    assert o["rays"].default == 64
    assert o["min_gap"].default == pytest.approx(0.005)
    assert o["min_gap"].unit == "normalized length"
    assert o["snake_iterations"].default == 100
    assert o["repair"].default == "auto" and o["repair"].choices == ("auto", "none")
    for info in o.values():
        assert info.description, info.name
        assert info.stage, info.name
        if info.kind != "choice":
            assert info.minimum <= info.default <= info.maximum, info.name
    # The weights' options are in the same table, their defaults the engine's.
    assert o["max_influences"].default == 4 and o["max_influences"].stage == "weights"
    assert o["heat"].default == pytest.approx(4.0)
    assert o["upsample"].default == 0 and o["upsample"].stage == "prepare"


def test_the_skeleton_cli_offers_the_skeleton_options_and_batch_all():
    from dcg import cli
    from dcg.options import SKELETON_OPTIONS

    parser = cli.build_parser()
    skeleton = parser.parse_args(["skeleton", "in.obj", "-o", "out.json", "--tau", "0.7"])
    assert skeleton.tau == pytest.approx(0.7)
    assert "max_influences" not in vars(skeleton) and "tau" in SKELETON_OPTIONS
    batch = parser.parse_args(["batch", "in", "out", "--max-influences", "3"])
    assert batch.max_influences == 3


@pytest.mark.parametrize("bad", [{"tau": 2.0}, {"samples": -5}, {"samples": 10.5},
                                 {"repair": "maybe"}, {"taux": 0.8}, {"tau": "high"}])
def test_bad_options_raise_value_error(spot, bad):
    with pytest.raises(ValueError, match=next(iter(bad)).rstrip("x")):
        dcg.extract_skeleton(*spot, **bad)


def test_skeleton_fields(spot, spot_skeleton):
    s = spot_skeleton
    V, F = spot
    k = s.node_count
    assert k >= 2
    assert s.positions.shape == (k, 3) and s.positions.dtype == np.float64
    assert s.kinds.shape == (k,) and set(s.kinds) <= {"end", "joint", "connection"}
    assert s.radii.shape == (k,) and (s.radii > 0).all()
    assert s.links.shape[1] == 2 and s.links.dtype == np.int64
    assert len(s.polylines) == len(s.links)
    for (a, b), poly in zip(s.links, s.polylines):
        assert poly.shape[1] == 3 and len(poly) >= 2
        np.testing.assert_allclose(poly[0], s.positions[a])
        np.testing.assert_allclose(poly[-1], s.positions[b])
    assert 0 <= s.root < k
    assert s.face_labels.shape == (len(F),)
    assert list(s.timings)[-1] == "total"
    # The run's own time: the stages' sum, less the time stage 3 and the mirror plane after it
    # (on the same thread) ran beside stages 1-2.
    stages = sum(v for name, v in s.timings.items() if name != "total")
    beside = min(s.timings["prongs"] + s.timings.get("symmetry", 0.0),
                 s.timings["voronoi_balls"] + s.timings["domain_balls"])
    assert stages - beside - 1e-9 <= s.timings["total"] <= stages + 1e-9
    # In the input's coordinates: nodes lie within the mesh's bounding box.
    assert (s.positions >= V.min(0) - 1e-9).all() and (s.positions <= V.max(0) + 1e-9).all()
    assert s.genus == 0 and not s.repaired


def test_json_schema_and_round_trip(spot_skeleton):
    s = spot_skeleton
    doc = json.loads(s.to_json())
    assert doc["format"] == "dcg-skeleton/1"
    assert set(doc) >= {"format", "mesh", "options", "nodes", "links", "root", "timings"}
    assert set(doc["mesh"]) == {"vertices", "faces", "genus", "repaired"}
    assert doc["mesh"]["vertices"] == 2930 and doc["mesh"]["faces"] == 5856
    assert doc["options"]["samples"] == FAST["samples"] and doc["options"]["tau"] == 0.85
    node = doc["nodes"][0]
    assert set(node) == {"id", "kind", "position", "radius", "significance"}
    assert [n["id"] for n in doc["nodes"]] == list(range(s.node_count))
    assert set(doc["links"][0]) == {"a", "b", "polyline", "radii"}
    assert len(doc["links"][0]["radii"]) == len(doc["links"][0]["polyline"])
    assert "total" in doc["timings"]
    back = dcg.Skeleton.from_json(s.to_json())
    np.testing.assert_allclose(back.positions, s.positions)
    np.testing.assert_array_equal(back.links, s.links)
    assert list(back.kinds) == list(s.kinds)
    for theirs, ours in zip(back.polyline_radii, s.polyline_radii):
        np.testing.assert_allclose(theirs, ours)
    # A document written before the polylines' radii were kept reads with none: the bone
    # planner then interpolates the nodes' radii (dcg.bones.limb_polyline).
    for link in doc["links"]:
        del link["radii"]
    assert dcg.Skeleton.from_dict(doc).polyline_radii == []


def test_extractor_stages_are_kept_and_consistent(spot):
    ex = dcg.Extractor(*spot, **FAST)
    prepared = ex.prepare()
    diag = np.linalg.norm(prepared.vertices.max(0) - prepared.vertices.min(0))
    assert diag == pytest.approx(1.0, rel=1e-6)
    assert prepared.report["closed_manifold"]
    assert prepared.map_face.shape == (2930,)
    # input = working * scale + offset
    V = spot[0]
    np.testing.assert_allclose(np.linalg.norm(V.max(0) - V.min(0)), prepared.scale, rtol=1e-6)
    balls = ex.domain_balls()
    assert len(balls.centers) == len(balls.radii) > 0
    assert (balls.radii >= ex.options["min_radius"]).all()
    gap = ex.options["min_gap"]
    d = np.linalg.norm(balls.centers[:, None] - balls.centers[None], axis=2)
    rr = balls.radii[:, None] + balls.radii[None] + gap
    np.fill_diagonal(d, np.inf)
    assert (d > rr).all(), "domain balls intersect"
    assert ex.skeleton() is ex.skeleton()


def test_same_input_same_skeleton(spot, spot_skeleton):
    again = dcg.extract_skeleton(*spot, **FAST)
    np.testing.assert_array_equal(again.positions, spot_skeleton.positions)
    np.testing.assert_array_equal(again.links, spot_skeleton.links)


def test_progress_reports_and_cancel(spot):
    seen = []
    dcg.extract_skeleton(*spot, progress=lambda stage, f: seen.append((stage, f)), **FAST)
    fractions = [f for _, f in seen]
    assert fractions == sorted(fractions) and fractions[-1] == 1.0
    with pytest.raises(dcg.Cancelled):
        dcg.extract_skeleton(*spot, progress=lambda stage, f: False, **FAST)


def test_prongs_beside_the_balls_change_nothing_and_cancel(spot, spot_skeleton):
    """skeleton() runs stage 3 on a second thread beside stages 1-2: the same skeleton as one
    thread running them in turn (whose total is then the stages' sum), and a cancel while both
    run, or while this thread waits for stage 3, stops both."""
    try:
        dcg.limit_threads(1)
        alone = dcg.extract_skeleton(*spot, **FAST)
    finally:
        dcg.limit_threads(0)
    np.testing.assert_array_equal(alone.positions, spot_skeleton.positions)
    np.testing.assert_array_equal(alone.links, spot_skeleton.links)
    assert alone.timings["total"] == pytest.approx(
        sum(v for name, v in alone.timings.items() if name != "total"))
    for stage in ("voronoi_balls", "domain_balls", "prongs"):
        with pytest.raises(dcg.Cancelled):
            dcg.extract_skeleton(*spot, progress=lambda s, f, stage=stage: s != stage, **FAST)
    again = dcg.extract_skeleton(*spot, **FAST)
    np.testing.assert_array_equal(again.positions, spot_skeleton.positions)


def test_exception_in_progress_callback_propagates(spot):
    def boom(stage, fraction):
        raise KeyError("from the callback")

    with pytest.raises(KeyError, match="from the callback"):
        dcg.extract_skeleton(*spot, progress=boom, **FAST)


@pytest.mark.parametrize("V,F,match", [
    (np.zeros((5, 2)), np.zeros((4, 3), dtype=int), "n x 3"),
    (np.zeros((5, 3)), np.zeros((4, 4), dtype=int), "m x 3"),
    (np.zeros((5, 3)), np.full((4, 3), 0.5), "integer"),
    (np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0], [np.nan, 0, 1]]), cube()[1][:4] % 4, "finite|NaN"),
    (cube()[0], np.array([[0, 1, 2], [0, 2, 3], [0, 3, 99], [1, 2, 3]]), "99"),
    (cube()[0], np.array([[0, 1, 2], [0, 2, -1], [0, 3, 1], [1, 2, 3]]), "-1"),
    (cube()[0][:3], np.array([[0, 1, 2]]), "at least 4|4 vertices"),
])
def test_bad_meshes_raise_value_error(V, F, match):
    with pytest.raises(ValueError, match=match):
        dcg.extract_skeleton(V, F)


def test_open_mesh_without_repair_names_the_problem():
    V, F = cube(open_faces=1)
    with pytest.raises(ValueError, match="border edge"):
        dcg.extract_skeleton(V, F, repair="none")


def test_sphere_gives_a_small_centred_skeleton(sphere):
    V, F = sphere
    s = dcg.extract_skeleton(V, F, samples=1500)
    assert s.node_count >= 1
    assert np.linalg.norm(s.positions, axis=1).max() < 1.0


def test_retune_reruns_only_the_stages_after_the_prongs(spot):
    ex = dcg.Extractor(*spot, **FAST)
    before = ex.skeleton()
    graph, ends = ex.domain_graph(), ex.end_points()
    labels = np.array(graph.face_labels)
    ex.retune(0.95)
    after = ex.skeleton()
    assert after is not before and ex.options["tau"] == 0.95
    fresh = dcg.extract_skeleton(*spot, **{**FAST, "tau": 0.95})
    np.testing.assert_array_equal(after.positions, fresh.positions)
    np.testing.assert_array_equal(after.links, fresh.links)
    assert list(after.kinds).count("end") > list(before.kinds).count("end")
    assert after.options["tau"] == 0.95
    # What was taken before the retune is still whole (the engine's own results were dropped).
    np.testing.assert_array_equal(graph.face_labels, labels)
    assert len(ends.centers) == list(before.kinds).count("end")
    stages = [name for name, _ in ex.timings]
    assert stages.count("voronoi_balls") == stages.count("connection_points") == 1
    assert "retune" in stages
    with pytest.raises(ValueError):
        ex.retune(1.5)
    assert ex.options["tau"] == 0.95


def test_repair_summary_says_what_stage_0_did(meshes_dir):
    from conftest import combine, uv_sphere

    V, F = uv_sphere()
    assert dcg.repair_summary(dcg.Extractor(V, F).prepare()) is None, "used as it is"
    V2, F2 = combine((V, F), (V + [3.0, 0, 0], F))
    united = dcg.repair_summary(dcg.Extractor(V2, F2).prepare())
    assert united.startswith("the mesh has 2 parts") and "union of its closed parts" in united
    V, F = cube(open_faces=2)
    wrapped = dcg.repair_summary(dcg.Extractor(V, F).prepare())
    assert "border edges" in wrapped and "alpha wrap" in wrapped
    # Q_Wasp's wings are one-quad fins on non-manifold edges: left out, and said so.
    V, F = dcg.load_mesh(meshes_dir / "rigged" / "Q_Wasp.obj")
    prepared = dcg.Extractor(V, F).prepare()
    assert prepared.wrap_alpha == 0 and prepared.report["fin_faces"] == 4
    assert "leaving out 4 faces of zero-volume fins" in dcg.repair_summary(prepared)
    # Mannequiny's ankles and feet enclose two specks of void between them: filled, and said so.
    V, F = dcg.load_mesh(meshes_dir / "rigged" / "Mannequiny.obj")
    prepared = dcg.Extractor(V, F).prepare()
    assert prepared.report["cavities"] == 2
    assert "2 cavities enclosed between the parts filled" in dcg.repair_summary(prepared)


def test_limit_threads_caps_the_engines_threads_and_lifts_again():
    import os

    try:
        assert dcg.limit_threads(1) == 1
        V, F = dcg.load_mesh(str(REPO / "data" / "spot.obj"))
        assert dcg.extract_skeleton(V, F).method == "dcg"  # runs on one thread
    finally:
        lifted = dcg.limit_threads(0)  # TBB's default: the cores it may use (affinity, quota)
        assert 1 <= lifted <= len(os.sched_getaffinity(0))
    for bad in (-1, 1.5, True, "2"):
        with pytest.raises(ValueError, match="whole number"):
            dcg.limit_threads(bad)


def test_a_module_built_before_numpy_2_support_refuses_numpy_2_on_import():
    # pybind11 < 2.12 calls numpy C functions that numpy 2 dropped: a crash at the first array
    # (Debian 12's pybind11 2.10 with pyenv's numpy 2 segfaulted in Extractor()).
    with pytest.raises(ImportError, match="pybind11 2.10.*numpy 2.4.6"):
        dcg._check_numpy((2, 10), "2.4.6")
    dcg._check_numpy((2, 10), "1.26.4")  # numpy 1: fine
    dcg._check_numpy((2, 13), "2.2.4")  # pybind11 2.13 supports numpy 2
    assert tuple(dcg._core.pybind11_version) >= (2, 6)
