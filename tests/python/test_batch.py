"""`python -m dcg batch` (dcg.batch): a folder of meshes on a 2-worker Dask LocalCluster,
results, index.jsonl, resuming, a worker killed mid-run, and the Blender (--glb) path."""

import base64
import io
import json
import os
import shutil
import signal
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pytest

import dcg
from conftest import cube, shared_skeleton, uv_sphere

distributed = pytest.importorskip("distributed")
from dcg import batch, batch_blender  # noqa: E402  (after the skip: it needs no Dask to import)

FAST = {"samples": 1000, "target_faces": 3000}
FAST_FLAGS = ["--samples", "1000", "--target-faces", "3000"]


def write_obj(path, V, F):
    path.parent.mkdir(parents=True, exist_ok=True)
    # .tolist(): Python floats, whose repr is the number (numpy 2's is "np.float64(...)").
    lines = [f"v {x!r} {y!r} {z!r}" for x, y, z in V.tolist()] + [
        f"f {a + 1} {b + 1} {c + 1}" for a, b, c in F]
    path.write_text("\n".join(lines) + "\n")


def write_off(path, V, F):
    path.parent.mkdir(parents=True, exist_ok=True)
    lines = ["OFF", f"{len(V)} {len(F)} 0"] + [f"{x!r} {y!r} {z!r}" for x, y, z in V.tolist()]
    path.write_text("\n".join(lines + [f"3 {a} {b} {c}" for a, b, c in F]) + "\n")


def write_stl(path, V, F):
    path.parent.mkdir(parents=True, exist_ok=True)
    out = ["solid box"]
    for face in F:
        a, b, c = V[face]
        n = np.cross(b - a, c - a)
        n = n / np.linalg.norm(n)
        out += [f"facet normal {n[0]} {n[1]} {n[2]}", "outer loop"]
        out += [f"vertex {p[0]} {p[1]} {p[2]}" for p in (a, b, c)]
        out += ["endloop", "endfacet"]
    path.write_text("\n".join(out + ["endsolid box"]) + "\n")


def make_library(root: Path, repo: Path, extra: int = 0) -> Path:
    """6 good meshes (3 synthetic, 3 from data/), an open one, a corrupt one, and `extra`
    more good synthetic ones."""
    V, F = uv_sphere()
    write_obj(root / "sphere.obj", V, F)
    write_off(root / "shapes" / "capsule.off", V * [0.6, 0.6, 2.0], F)
    V, F = cube()
    write_stl(root / "shapes" / "long box.stl", V * [1.0, 1.0, 4.0], F)
    (root / "repo").mkdir()
    shutil.copy(repo / "data" / "spot.obj", root / "repo" / "spot.obj")
    shutil.copy(repo / "data" / "meshes" / "torus.off", root / "repo" / "torus.off")
    shutil.copy(repo / "data" / "meshes" / "eight.off", root / "repo" / "eight.off")
    V, F = uv_sphere(rings=12, segments=16)
    write_off(root / "open" / "cup.off", V, F[40:])  # the top cap removed: a hole
    (root / "broken.obj").write_text("v 0 0 0\nv 1 nonsense\nf 1 2 9\n")
    for i in range(extra):
        V, F = uv_sphere(rings=10 + i, segments=14)
        write_off(root / "extra" / f"blob{i}.off", V * [1.0, 1.5 + i, 1.0], F)
    return root


def run_cli(*args, timeout=240):
    env = dict(os.environ)
    env["PYTHONPATH"] = str(Path(dcg.__file__).resolve().parents[1])
    return subprocess.run(["/usr/bin/python3", "-m", "dcg", "batch", *map(str, args)],
                          env=env, capture_output=True, text=True, timeout=timeout)


def read_lines(path: Path):
    return [json.loads(line) for line in path.read_text().splitlines()]


def test_batch_rigs_a_folder_records_the_failure_and_resumes(repo, tmp_path):
    library = make_library(tmp_path / "in", repo)
    out = tmp_path / "out"
    first = run_cli(library, out, "--workers", "2", *FAST_FLAGS)
    assert first.returncode == 1, first.stdout + first.stderr  # 1: a model failed
    assert "7 ok, 1 failed" in first.stdout and "models/min" in first.stdout
    assert "[8/8]" in first.stderr and "models/min" in first.stderr  # the progress lines

    records = read_lines(out / "index.jsonl")
    assert sorted(r["path"] for r in records) == sorted(batch.find_models(library))
    assert len(records) == 8
    by_path = {r["path"]: r for r in records}
    failed = [r for r in records if r["status"] != "ok"]
    assert [r["path"] for r in failed] == ["broken.obj"]
    assert "broken.obj" in failed[0]["message"] and failed[0]["outputs"] == {}
    assert not list(out.glob("broken.obj*"))
    assert by_path["open/cup.off"]["status"] == "ok" and by_path["open/cup.off"]["repaired"]
    assert by_path["repo/spot.obj"]["faces"] == 5856
    for record in records:
        assert record["seconds"] >= 0 and "worker" in record
        if record["status"] != "ok":
            continue
        doc = json.loads((out / (record["path"] + ".json")).read_text())
        assert doc["format"] == "dcg-skeleton/1" and doc["mesh"]["faces"] == record["faces"]
        assert doc["options"]["samples"] == 1000
        with np.load(out / (record["path"] + ".weights.npz")) as npz:
            assert int(npz["vertices"]) == record["vertices"]
            assert str(npz["status"]) == record["weights"]
            if record["weights"] == "ok":
                W = npz["weights"]
                assert W.shape == (record["vertices"], len(npz["bone_names"]))
                assert np.allclose(W.sum(axis=1), 1.0, atol=1e-4)
    assert not [p for p in out.rglob(".*")], "temporary files left behind"

    stamps = {p: p.stat().st_mtime_ns for p in out.rglob("*") if p.is_file()}
    second = run_cli(library, out, "--workers", "2", *FAST_FLAGS)
    assert second.returncode == 0, second.stdout + second.stderr
    assert "nothing to do" in second.stdout and "8 models" in second.stdout
    assert {p: p.stat().st_mtime_ns for p in out.rglob("*") if p.is_file()} == stamps

    # Changed input or options: only what changed runs again.
    (library / "sphere.obj").write_text((library / "sphere.obj").read_text() + "# edited\n")
    third = run_cli(library, out, "--workers", "1", *FAST_FLAGS)
    assert "1 ok, 0 failed, 7 skipped" in third.stdout, third.stdout + third.stderr
    assert len(read_lines(out / "index.jsonl")) == 8


@pytest.fixture(scope="module")
def client():
    cluster = distributed.LocalCluster(n_workers=2, threads_per_worker=1, processes=True,
                                       dashboard_address=None)
    with distributed.Client(cluster) as c:
        yield c
    cluster.close()


def test_a_worker_killed_mid_run_loses_nothing(repo, tmp_path, client):
    library = make_library(tmp_path / "in", repo, extra=1)
    (library / "broken.obj").unlink()
    models = batch.find_models(library)
    assert len(models) == 8
    pids = client.run(os.getpid)
    killed, seen, in_flight = [], [], {}

    def kill_a_busy_worker(record):
        seen.append(record["path"])
        if killed:
            return
        busy = [(w, keys) for w, keys in client.processing().items() if keys and w in pids]
        assert busy, "no worker busy after the first result: nothing to kill"
        worker, keys = busy[0]
        os.kill(pids[worker], signal.SIGKILL)
        killed.append(pids[worker])
        in_flight.update((key.split("-", 3)[3], worker) for key in keys)

    out = tmp_path / "out"
    summary = batch.run(library, out, options=FAST, client=client, progress=None,
                        on_result=kill_a_busy_worker)
    assert killed and len(seen) == 8
    assert sorted(seen) == models, "every model's result written exactly once"
    assert summary.ok == 8 and summary.failed == 0
    records = read_lines(out / "index.jsonl")
    assert sorted(r["path"] for r in records) == models
    assert all(r["status"] == "ok" for r in records)
    assert in_flight
    for path, dead_worker in in_flight.items():  # what it held was rigged by another worker
        assert next(r for r in records if r["path"] == path)["worker"] != dead_worker
    for path in models:
        assert (out / (path + ".json")).is_file() and (out / (path + ".weights.npz")).is_file()
    assert not [p for p in out.rglob(".*")]
    with pytest.raises(ProcessLookupError):
        os.kill(killed[0], 0)


def addon_bone_detail():
    """The add-on's default bone detail (its bpy-free options module)."""
    sys.path.insert(0, str(Path(__file__).resolve().parents[2] / "addon"))
    try:
        from dcg_rig import options
    finally:
        sys.path.pop(0)
    return options.ADDON_DEFAULTS["bone_detail"]


@pytest.mark.parametrize("bone_detail", [None, 0.0, 1.0])
def test_the_npz_holds_the_bones_the_addon_makes(repo, bone_detail):
    V, F = dcg.load_mesh(repo / "data" / "spot.obj")
    skeleton = shared_skeleton(V, F, "spot.obj", **FAST)
    detail = addon_bone_detail() if bone_detail is None else bone_detail
    data, status = (batch.weights_npz(V, F, skeleton) if bone_detail is None else
                    batch.weights_npz(V, F, skeleton, bone_detail=bone_detail))
    assert status == "ok"
    plan = dcg.bones.plan_bones(skeleton, detail)  # what rigging.apply_rig builds
    with np.load(io.BytesIO(data)) as npz:
        assert list(npz["bone_names"]) == [spec.name for spec in plan]
        assert np.array_equal(npz["bone_heads"], [spec.head for spec in plan])
        assert np.array_equal(npz["bone_tails"], [spec.tail for spec in plan])
        parents = [None if p < 0 else str(npz["bone_names"][p]) for p in npz["bone_parents"]]
        assert parents == [spec.parent for spec in plan]
        assert list(npz["bone_kinds"]) == [spec.kind for spec in plan]
        assert np.array_equal(npz["bone_z_axes"], [spec.z_axis for spec in plan])
        assert np.array_equal(npz["bone_rolls"], [spec.roll for spec in plan])
        assert npz["weights"].shape == (len(V), len(plan))
        # One tree chained away from the root bone: parents first, each head at its parent's
        # tail but the root bone's children (it stands straight up under the body, they hang
        # from it at the skeleton's root, as high as its tail); the root bone (first, the only
        # one without a parent) weights no vertex.
        for b, parent in enumerate(npz["bone_parents"]):
            assert parent < b
            if parent > 0:
                assert np.allclose(npz["bone_heads"][b], npz["bone_tails"][parent])
            elif parent == 0:
                assert np.isclose(npz["bone_heads"][b][2], npz["bone_tails"][0][2])  # up +Z
        assert npz["bone_kinds"][0] == "root" and list(npz["bone_parents"]).count(-1) == 1
        assert not npz["weights"][:, 0].any() and np.allclose(npz["weights"].sum(axis=1), 1)
        # Its children start at the root node, moved onto the mirror plane (spot mirrors
        # itself) by at most MIRROR_REACH of its radius.
        limbs = npz["bone_heads"][npz["bone_parents"] == 0]
        assert np.allclose(limbs, limbs[0])
        reach = dcg.bones.symmetry.MIRROR_REACH * skeleton.radii[skeleton.root]
        assert np.linalg.norm(limbs[0] - skeleton.positions[skeleton.root]) <= reach
        assert set(npz["bone_links"][1:].tolist()) <= set(range(len(skeleton.links)))
        assert npz["bone_links"][0] == -1  # the root bone is no link's


def test_weights_npz_says_unavailable_instead_of_making_weights_up(repo, monkeypatch):
    V, F = dcg.load_mesh(repo / "data" / "meshes" / "torus.off")
    skeleton = dcg.extract_skeleton(V, F, **FAST)
    monkeypatch.delattr(dcg, "skin_weights", raising=False)
    data, status = batch.weights_npz(V, F, skeleton)
    assert status.startswith("unavailable")
    with np.load(io.BytesIO(data)) as npz:
        assert "weights" not in npz and str(npz["status"]) == status
        assert len(npz["bone_names"]) > 0


def test_rig_model_reports_errors_and_timeouts_as_records(tmp_path, repo):
    missing = batch.rig_model(batch.Job("gone.obj", str(tmp_path / "gone.obj"), FAST))
    assert missing["record"]["status"] == "error" and missing["files"] == {}
    assert "gone.obj" in missing["record"]["message"]
    spot = str(repo / "data" / "spot.obj")
    late = batch.rig_model(batch.Job("spot.obj", spot, FAST, timeout=1e-6))
    assert late["record"]["status"] == "error" and "timed out" in late["record"]["message"]


def test_a_record_carries_the_warnings_the_addon_would_give(tmp_path, repo):
    """The add-on warns of a model lying on its side and of Mixamo names asked of a body that
    is not humanoid; a batch run is not silent about them either: each record's "warnings"
    (dcg.rig_warnings), the progress line and the summary. Spot's OBJ stands (+Y up): no
    warning; the same mesh turned onto its side (x and y swapped: its mirror plane level)
    gets one."""
    V, F = dcg.load_mesh(repo / "data" / "spot.obj")
    write_obj(tmp_path / "side.obj", V[:, [1, 0, 2]], F)
    standing = batch.rig_model(batch.Job("spot.obj", str(repo / "data" / "spot.obj"), FAST))
    assert standing["record"]["status"] == "ok" and standing["record"]["warnings"] == []
    lying = batch.rig_model(batch.Job("side.obj", str(tmp_path / "side.obj"), FAST))
    assert [w for w in lying["record"]["warnings"] if "lies level" in w], lying["record"]
    named = batch.rig_model(batch.Job("spot.obj", str(repo / "data" / "spot.obj"), FAST,
                                      bone_names="mixamo"))
    assert [w for w in named["record"]["warnings"] if "not humanoid" in w], named["record"]

    summary = batch.Summary(found=2)
    for result in (standing, lying):
        summary.count(result["record"])
    assert summary.ok == 2 and summary.warned == [("side.obj", lying["record"]["warnings"])]
    assert "1 of the ok models have warnings" in summary.text()
    assert "warning: side.obj: the mirror plane lies level" in summary.text()
    stream = io.StringIO()
    progress = batch.Progress(2, stream)
    progress.update(lying["record"])
    assert "ok side.obj" in stream.getvalue() and "warning" in stream.getvalue()


def test_find_models_skips_hidden_files_and_the_output_inside(tmp_path):
    write_off(tmp_path / "a.off", *cube())
    write_off(tmp_path / ".hidden.off", *cube())
    write_off(tmp_path / "out" / "x.off", *cube())
    (tmp_path / "notes.txt").write_text("no mesh")
    (tmp_path / "scene.fbx").write_text("")
    assert batch.find_models(tmp_path, exclude=tmp_path / "out") == ["a.off"]
    assert batch.find_models(tmp_path, glb=True, exclude=tmp_path / "out") == ["a.off",
                                                                               "scene.fbx"]


def test_jobs_are_submitted_largest_input_first(tmp_path):
    # The longest models start first, so that no worker idles at the end behind a big one.
    sizes = {"b.off": 300, "a.off": 100, "c.off": 300, "d.off": 2000}
    for name, size in sizes.items():
        (tmp_path / name).write_bytes(b"x" * size)
    jobs = [batch.Job(name, str(tmp_path / name), {}) for name in sorted(sizes)]
    jobs.append(batch.Job("gone.off", str(tmp_path / "gone.off"), {}))  # vanished: last
    assert [j.path for j in batch.largest_first(jobs)] == ["d.off", "b.off", "c.off", "a.off",
                                                          "gone.off"]


def test_bad_arguments_exit_2_with_the_reason(tmp_path):
    result = run_cli(tmp_path / "absent", tmp_path / "out")
    assert result.returncode == 2 and "does not exist" in result.stderr
    result = run_cli(tmp_path, tmp_path / "out", "--tau", "7")
    assert result.returncode != 0 and "tau" in result.stderr
    assert "Traceback" not in result.stderr


def write_gltf(path, V, F):
    """A minimal glTF 2.0 file (one mesh, buffers embedded as base64)."""
    positions = np.asarray(V, dtype=np.float32).tobytes()
    indices = np.asarray(F, dtype=np.uint32).tobytes()
    data = base64.b64encode(positions + indices).decode()
    doc = {
        "asset": {"version": "2.0"}, "scene": 0, "scenes": [{"nodes": [0]}],
        "nodes": [{"mesh": 0, "name": "blob"}],
        "meshes": [{"primitives": [{"attributes": {"POSITION": 0}, "indices": 1}]}],
        "buffers": [{"byteLength": len(positions) + len(indices),
                     "uri": "data:application/octet-stream;base64," + data}],
        "bufferViews": [{"buffer": 0, "byteLength": len(positions), "target": 34962},
                        {"buffer": 0, "byteOffset": len(positions),
                         "byteLength": len(indices), "target": 34963}],
        "accessors": [{"bufferView": 0, "componentType": 5126, "count": len(V), "type": "VEC3",
                       "min": np.min(V, axis=0).tolist(), "max": np.max(V, axis=0).tolist()},
                      {"bufferView": 1, "componentType": 5125, "count": 3 * len(F),
                       "type": "SCALAR"}],
    }
    path.write_text(json.dumps(doc))


def glb_joints(glb: bytes):
    """{joint name: parent joint name or None} of the first skin of a glTF binary."""
    length = int.from_bytes(glb[12:16], "little")
    assert glb[16:20] == b"JSON"
    doc = json.loads(glb[20:20 + length])
    nodes = doc["nodes"]
    joints = doc["skins"][0]["joints"]
    parent_of = {child: index for index, node in enumerate(nodes)
                 for child in node.get("children", ())}
    return {nodes[j]["name"]: nodes[parent_of[j]]["name"] if parent_of.get(j) in joints
            else None for j in joints}


NO_BLENDER = pytest.mark.skipif(shutil.which("blender") is None,
                                reason="Blender is not installed")


@NO_BLENDER
def test_glb_rigs_in_blender_and_reads_gltf_input(repo, tmp_path, client):
    library = tmp_path / "in"
    library.mkdir()
    shutil.copy(repo / "data" / "meshes" / "torus.off", library / "torus.off")
    V, F = uv_sphere(rings=10, segments=12)
    write_gltf(library / "blob.gltf", V * [1.0, 1.0, 2.0], F)
    out = tmp_path / "out"
    started = time.perf_counter()
    summary = batch.run(library, out, options=FAST, glb=True, client=client, progress=None,
                        blender_cli=str(repo / "addon" / "dcg_rig" / "cli.py"))
    records = {r["path"]: r for r in read_lines(out / "index.jsonl")}
    assert summary.ok == 2, records
    for path in ("torus.off", "blob.gltf"):
        glb = (out / (path + ".glb")).read_bytes()
        assert glb[:4] == b"glTF" and records[path]["outputs"]["glb"] == path + ".glb"
        assert json.loads((out / (path + ".json")).read_text())["nodes"]
    assert records["blob.gltf"]["faces"] == len(F)
    # The glTF input reaches the engine as the add-on's rig sees it (one world-space mesh):
    # the .glb's bones and the .npz's are the same, names and parents.
    with np.load(out / "blob.gltf.weights.npz") as npz:
        names = [str(n) for n in npz["bone_names"]]
        expected = {name: None if p < 0 else names[p]
                    for name, p in zip(names, npz["bone_parents"])}
    assert glb_joints((out / "blob.gltf.glb").read_bytes()) == expected
    assert time.perf_counter() - started < 120


@NO_BLENDER
def test_the_addon_cli_is_the_installed_addons_or_the_one_given(repo, tmp_path, monkeypatch):
    monkeypatch.delenv(batch_blender.BLENDER_CLI_ENV, raising=False)
    given = repo / "addon" / "dcg_rig" / "cli.py"
    assert batch.find_addon_cli(str(given)) == given
    with pytest.raises(batch.BatchError, match="does not exist"):
        batch.find_addon_cli(str(tmp_path / "cli.py"))
    # Nothing installed in a clean user folder: the error says how to give it.
    monkeypatch.setenv("BLENDER_USER_SCRIPTS", str(tmp_path))
    with pytest.raises(batch.BatchError, match="--blender-cli"):
        batch.find_addon_cli()
    assert "not installed" in batch.check_glb_tools(None, None)
    # The legacy add-on of the build output, installed as BLENDER_USER_SCRIPTS installs it.
    scripts = Path(dcg.__file__).resolve().parents[2] / "blender_scripts"
    if not (scripts / "addons" / "dcg_rig" / "cli.py").is_file():
        pytest.skip(f"no assembled add-on in {scripts}")
    monkeypatch.setenv("BLENDER_USER_SCRIPTS", str(scripts))
    assert batch.find_addon_cli() == (scripts / "addons" / "dcg_rig" / "cli.py").resolve()


def test_a_model_that_keeps_killing_its_worker_is_a_failure_record():
    from distributed.scheduler import KilledWorker

    job = batch.Job("bad.off", "/in/bad.off", {})
    error = KilledWorker("dcg-rig-x-bad.off", None, 3)
    record, files = batch._record_of(job, (KilledWorker, error, None))
    assert record["status"] == "error" and "died" in record["message"] and files == {}
    record, _ = batch._record_of(job, (MemoryError, MemoryError("too big"), None))
    assert record["message"] == "MemoryError: too big"
