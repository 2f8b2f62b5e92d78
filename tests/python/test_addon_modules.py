"""The add-on's modules that need no Blender (options, skinning, geometry, worker, live),
tested with plain Python so that their logic is checked without starting Blender."""

import sys
from pathlib import Path

import numpy as np
import pytest

sys.path.insert(0, str(Path(__file__).resolve().parents[2] / "addon"))

from dcg_rig import geometry, live, options, skinning, worker  # noqa: E402

import dcg  # noqa: E402


def test_envelope_weights_are_normalized_with_at_most_four_influences():
    rng = np.random.default_rng(1)
    points = rng.normal(size=(300, 3))
    heads = rng.normal(size=(9, 3))
    tails = heads + rng.normal(size=(9, 3))
    rows, cols, values = skinning.envelope_weights(points, heads, tails, np.full(9, 0.2),
                                                   np.full(9, 0.2))
    rows, cols, values = skinning.normalize_and_prune(rows, cols, values)
    sums = skinning.weight_sums(rows, values, len(points))
    assert np.allclose(sums, 1.0)
    assert np.bincount(rows, minlength=len(points)).max() <= 4
    assert (values > 0).all() and cols.max() < 9


def test_envelope_weights_give_a_tip_to_its_own_thin_bone():
    # A coarse mesh: the end bone's tail radius (its distance to the faces) is a tenth of its
    # distance to the nearest vertex, the tip. Measured in that radius the tip was 10 radii
    # from its own bone and under 2 from the wide bone beside it, and got none of the end
    # bone's weight; the radius now reaches the bone's nearest point.
    heads = np.array([[0.0, 0, 0], [0.0, 0, 0]])
    tails = np.array([[-2.0, 0, 0], [2.0, 0, 0]])  # a wide body bone, a thin end bone
    head_radii, tail_radii = np.array([1.0, 0.1]), np.array([1.0, 0.01])
    tip = np.array([[2.1, 0, 0]])
    body = np.array([[-1.0, 1.0, 0], [-1.0, -1.0, 0], [1.0, 1.0, 0], [1.0, -1.0, 0]])
    points = np.vstack([body, tip])
    rows, cols, values = skinning.envelope_weights(points, heads, tails, head_radii, tail_radii)
    tip_weight = values[(rows == len(points) - 1) & (cols == 1)].sum()
    assert tip_weight > 0.9
    body_weight = values[(rows == 0) & (cols == 0)].sum()  # the body keeps its own bone
    assert body_weight > 0.5


def test_engine_kwargs_undo_blenders_float32_rounding():
    specs = options.option_specs(dcg.OPTIONS)
    kwargs = options.engine_kwargs(specs, {"tau": np.float32(0.85), "repair": "none"})
    assert kwargs == {"tau": 0.85, "repair": "none"}
    assert dcg.normalize_options(kwargs)["tau"] == 0.85  # accepted by the engine as they are


def test_option_specs_cover_every_engine_option_and_presets_are_valid():
    specs = options.option_specs(dcg.OPTIONS)
    assert [s.name for s in specs] == list(dcg.OPTIONS)
    for preset, _, _ in options.PRESET_ITEMS:
        values = options.preset_values(specs, preset)
        dcg.normalize_options(options.engine_kwargs(specs, values))


def test_the_detailed_preset_remeshes_a_small_input_and_the_default_keeps_it():
    # The engine keeps an input under target_faces / 2.5 faces as it is (upsample 0); the
    # Detailed preset asks for more detail than a small input has, so it remeshes (upsample 1).
    from conftest import uv_sphere

    V, F = uv_sphere(rings=40, segments=48)  # 3,744 faces: small, and kept by the default
    specs = options.option_specs(dcg.OPTIONS)
    for preset, remeshed in (("DEFAULT", False), ("DETAILED", True)):
        kwargs = options.engine_kwargs(specs, options.preset_values(specs, preset))
        assert dcg.Extractor(V, F, **kwargs).prepare().remeshed == remeshed, preset


def test_frame_camera_sees_the_whole_box():
    low, high = np.array([-1.0, -2.0, 0.0]), np.array([1.0, 2.0, 3.0])
    fov = 0.69
    location, direction = geometry.frame_camera(low, high, fov)
    corners = np.array([[x, y, z] for x in (low[0], high[0]) for y in (low[1], high[1])
                        for z in (low[2], high[2])])
    rays = corners - location
    angles = np.arccos(rays @ direction / np.linalg.norm(rays, axis=1))
    assert (angles < fov / 2).all()


def test_octahedral_bones_have_six_vertices_and_eight_faces_each():
    V, F = geometry.octahedral_bones(np.zeros((2, 3)), np.array([[0, 0, 1], [1, 0, 0]]), 0.1)
    assert V.shape == (12, 3) and F.shape == (16, 3) and F.max() == 11


def _sphere():
    from conftest import uv_sphere

    return uv_sphere()


def test_skeleton_job_runs_in_a_thread_and_reports_progress():
    V, F = _sphere()
    job = worker.SkeletonJob(dcg, V, F, {}).start()
    assert job.wait(60)
    assert job.error is None and not job.cancelled
    assert len(job.skeleton.positions) > 0 and job.fraction == pytest.approx(1.0)


def test_skeleton_job_cancels():
    V, F = _sphere()
    job = worker.SkeletonJob(dcg, V, F, {})
    job.cancel()
    job.start()
    assert job.wait(60)
    assert job.cancelled and job.skeleton is None and job.error is None


def test_the_kept_preview_is_reused_only_for_the_same_mesh_and_options(repo):
    V, F = dcg.load_mesh(repo / "data" / "spot.obj")
    options = {"samples": 1200, "target_faces": 5000, "tau": 0.85}
    extractor = dcg.Extractor(V, F, **options)
    extractor.skeleton()
    live.remember("spot", live.fingerprint(V, F), options, extractor)
    try:
        moved = V.copy()
        moved[0, 0] += 1e-6
        assert live.matching("spot", moved, F, options) is None
        assert live.matching("cow", V, F, options) is None
        assert live.matching("spot", V, F, {**options, "samples": 900}) is None
        assert live.matching("spot", V, F, {**options, "tau": 0.95}) is extractor
        assert extractor.options["tau"] == 0.95  # retuned to the asked tau
        live.forget()
        assert live.kept_for("spot") is None
    finally:
        live.forget()
