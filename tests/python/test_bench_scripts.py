"""The bench scripts that `make bench` runs with the system Python start and parse their
arguments (make bench is not part of make test; a script broken by a change elsewhere, as
bench_batch.py was by cli._add_option_flags, would otherwise show only there)."""

import os
import subprocess
from pathlib import Path

import numpy as np
import pytest

import dcg

SCRIPTS = ["bench.py", "bench_batch.py", "bench_big.py", "bench_compare.py",
           "bench_retune.py", "bench_rig_quality.py", "bench_noise.py", "make_stress_set.py",
           "make_big_mesh.py"]


@pytest.mark.parametrize("script", SCRIPTS)
def test_bench_script_prints_its_usage(repo, script):
    env = dict(os.environ, PYTHONPATH=str(Path(dcg.__file__).resolve().parents[1]))
    result = subprocess.run(["/usr/bin/python3", str(repo / "scripts" / script), "--help"],
                            env=env, capture_output=True, text=True, timeout=120)
    assert result.returncode == 0, result.stderr
    assert "usage:" in result.stdout


def test_bench_retune_times_each_tau_and_checks_the_limits(repo, tmp_path):
    import bench_retune  # scripts/ is on sys.path (conftest)

    spot = repo / "data" / "spot.obj"
    faces, full, best = bench_retune.measure(spot, [0.7, 0.95], rounds=2)
    assert faces == 5856 and full > 0
    assert sorted(best) == [0.7, 0.95]
    for rethreshold, skeleton, ends in best.values():
        assert 0 < rethreshold <= skeleton and ends >= 1
    # The retuned skeleton is the one a fresh run at that tau gives: here, its ends.
    V, F = dcg.load_mesh(spot)
    fresh = dcg.extract_skeleton(V, F, tau=0.7)
    assert best[0.7][2] == int((fresh.kinds == "end").sum())
    # Limits: the re-threshold from 90k faces, the new skeleton on hand.obj only.
    assert "missed" in bench_retune.verdicts("hand.obj", 9556, 0.001, 0.5)
    assert "met" in bench_retune.verdicts("hand.obj", 9556, 0.001, 0.1)
    assert "missed" in bench_retune.verdicts("horse.ply", 96966, 0.06, 0.1)
    assert bench_retune.verdicts("spot.obj", 5856, 1.0, 1.0) == "-"


def test_bench_noise_counts_what_a_tiny_noise_changes(repo, meshes_dir):
    import bench_noise

    row = bench_noise.measure(repo / "data" / "spot.obj", 2, 1e-5)
    assert [row[key] for key in ("ends", "components", "cycles", "unpaired")] == [6, 1, 0, 0]
    assert row["kept"] == "2 of 2" and row["others"] == "-"
    base = {"ends": 6, "joints": 1, "components": 1, "cycles": 0, "unpaired": 0}
    assert bench_noise.differs(base, dict(base, joints=2)) == []  # joints are not compared
    assert bench_noise.differs(base, dict(base, ends=5, unpaired=2)) == ["ends", "unpaired"]
    V = np.random.default_rng(0).random((1000, 3))
    moved = bench_noise.noisy(V, 1, 1e-3) - V
    assert np.allclose(bench_noise.noisy(V, 1, 1e-3) - V, moved)  # a draw is a draw
    assert 0.5e-3 < moved.std() / np.linalg.norm(np.ptp(V, axis=0)) < 2e-3
    text = "\n".join(bench_noise.report([row], 2, 1e-5))
    assert "Kept: 2 of 2 draws; 1 of 1 meshes in every draw." in text
    assert "| spot.obj | 6 |" in text
    meshes = bench_noise.default_meshes(meshes_dir, meshes_dir / "rigged")
    names = {path.name for path in meshes}
    assert {"spot.obj", "kitten.off", "Q_Goblin.obj"} <= names  # closed ones, and the rigged
    assert "wolf-open.obj" not in names  # open: MANIFEST's closed column says no


def test_bench_says_when_mcf_made_different_skeletons_in_its_runs():
    import bench  # scripts/ is on sys.path (conftest)

    varied = {"runs_seconds": [0.0978, 0.146, 0.185], "runs_skeleton_vertices": [138, 137, 140]}
    assert bench.mcf_spread(varied) == ("MCF differs between runs: 137-140 skeleton vertices, "
                                        "0.098-0.185 s over 3 runs (median used)")
    assert bench.mcf_spread({"runs_seconds": [0.022, 0.023],
                             "runs_skeleton_vertices": [48, 48]}) == ""  # the same skeleton
    assert bench.mcf_spread({"runs_seconds": [0.5], "runs_skeleton_vertices": [48]}) == ""
    assert bench.mcf_spread({}) == ""  # MCF did not run


def test_bench_refuses_a_dcg_bench_older_than_its_library(tmp_path):
    import bench

    binary, library = tmp_path / "dcg_bench", tmp_path / "libdcg.a"
    binary.write_text("")
    assert bench.stale_binary(binary) is None  # no library beside it: nothing to compare
    library.write_text("")
    os.utime(binary, (1000, 1000))
    os.utime(library, (2000, 2000))
    assert "is older than" in bench.stale_binary(binary)  # linked before the engine changed
    os.utime(binary, (3000, 3000))
    assert bench.stale_binary(binary) is None


def test_rig_quality_sets_each_cd_beside_the_one_before_issue_17(tmp_path):
    import json

    import bench_rig_quality as rq  # scripts/ is on sys.path (conftest)

    before = {"cd_j2j": 3.0, "cd_j2b": 2.0, "cd_b2b": 1.0}
    row = {"name": "A", "cd_j2j": 2.5, "cd_j2b": 2.004, "cd_b2b": 1.2}
    compared = rq.against_before(row, before)
    assert compared["change_cd_j2j"] == pytest.approx(-0.5)
    assert compared["before_cd_b2b"] == 1.0
    assert compared["worse"] == "B2B"  # J2B grew by less than WORSE_BY
    assert rq.against_before(row, None) == {"worse": "-"}
    # The table: a character measured then, one that was not, the mean of those compared.
    path = tmp_path / "before.json"
    path.write_text(json.dumps({"commit": "abc", "characters": {"A": before}}))
    rows = [row, {"name": "B", "cd_j2j": 9.0, "cd_j2b": 9.0, "cd_b2b": 9.0}]
    lines = rq.before_table(rows, path)
    assert "Worse in at least one: A." in lines[1]
    assert lines[-2].startswith("| A | 3.000 | 2.500 | -0.500 |") and lines[-2].endswith("| B2B |")
    assert lines[-1].startswith("| **mean of 1** |") and lines[-1].endswith("| 1 of 1 |")
    assert not any(line.startswith("| B |") for line in lines)
    assert rq.before_table(rows, tmp_path / "missing.json") == []


def test_rig_quality_before_names_every_rigged_character(meshes_dir):
    import json

    import bench_rig_quality as rq
    from dcg import metrics

    before = json.loads(rq.BEFORE.read_text())["characters"]
    names = {name for name, _, _ in metrics.rigged_characters(meshes_dir / "rigged")}
    assert names, f"no rigged characters in {meshes_dir / 'rigged'}"
    assert names <= set(before), sorted(names - set(before))
    assert all(set(rq.METRICS) <= set(cds) for cds in before.values())


def test_rig_quality_stands_each_character_on_its_files_floor():
    import bench_rig_quality as rq

    box = np.array([[x, y, z] for x in (-1, 1) for y in (-1, 1) for z in (-1, 1)], dtype=float)
    standing_on_z = box * [1, 1, 2] + [0, 0, 2]  # lowest point z = 0
    assert np.array_equal(rq.floor_up(standing_on_z), [0, 0, 1])
    standing_on_y = box * [1, 2, 1] + [0, 2.0, 0]  # glTF's up: y = 0 (the cylinder's file)
    assert np.array_equal(rq.floor_up(standing_on_y), [0, 1, 0])
    flying = box * [2, 2, 1] + [0, 0, 1.2]  # above z = 0 but nearer it than the other planes
    assert np.array_equal(rq.floor_up(flying), [0, 0, 1])
    assert np.array_equal(rq.floor_up(box), [0, 0, 1])  # centred: Z first on ties


def test_the_stages_0_3_target_times_their_span_not_the_sum_of_overlapping_stages():
    import bench  # scripts/ is on sys.path (conftest)

    # hand.obj as the last make bench timed it: stage 3 and the mirror plane on the second
    # thread beside stages 1-2; the engine's total leaves out the 0.1136 s they overlapped.
    stages = {"prepare": 0.015, "voronoi_balls": 0.112, "domain_balls": 0.0026, "prongs": 0.083,
              "symmetry": 0.038, "end_points": 0.0019, "connection_points": 0.037,
              "domain_graph": 0.014, "remap": 0.0028, "skeleton": 0.0013}
    row = {"mesh": "hand.obj", "stages": stages, "total": 0.194}
    assert bench.elapsed_0_3(row) == pytest.approx(0.015 + 0.112 + 0.0026 + 0.083 + 0.038
                                                    - (sum(stages.values()) - 0.194))
    assert bench.elapsed_0_3(row) == pytest.approx(0.137, abs=0.001)
    lines, _ = bench.target_lines([row], list(stages))
    assert "**met**" in next(line for line in lines if line.startswith("| stages 0-3 ")
                             and "hand.obj" in line)
    # On one thread nothing overlaps: the span is the four stages' sum (0.2126: missed).
    alone = dict(row, total=sum(stages.values()))
    assert bench.elapsed_0_3(alone) == pytest.approx(0.015 + 0.112 + 0.0026 + 0.083)
    lines, _ = bench.target_lines([alone], list(stages))
    assert "**missed**" in next(line for line in lines if line.startswith("| stages 0-3 ")
                                and "hand.obj" in line)
