"""scripts/bench_compare.py: the speed regression check of `make bench`, on made-up summaries
(nothing here is timed)."""

import json

import bench_compare as bc
import pytest


def mesh(total, mcf=None, error=None):
    """A summary record: our total, MCF's seconds (None: MCF did not run)."""
    return {"total": total, "mcf_seconds": mcf,
            "ours_over_mcf": total / mcf if mcf and total else None,
            "stages": {"prepare": total / 2, "voronoi_balls": total / 2} if total else {},
            "error": error}


@pytest.fixture
def reference():
    return {"public/horse.ply": mesh(2.0, 4.0), "public/hand.obj": mesh(0.3, 0.5),
            "stress/scan-open.obj": mesh(0.4), "stress/pinched-blobs.obj": mesh(0.5)}


def status(rows, key):
    return next(r for r in rows if r["mesh"] == key)["status"]


def test_the_same_run_has_no_regression(reference):
    rows, factor = bc.compare(reference, reference)
    assert factor == 1.0
    assert bc.regressions(rows) == []
    assert {r["status"] for r in rows} == {bc.OK}


def test_a_30_percent_worse_ratio_is_flagged_and_20_is_not(reference):
    current = dict(reference)
    current["public/horse.ply"] = mesh(2.0 * 1.3, 4.0)
    current["public/hand.obj"] = mesh(0.3 * 1.2, 0.5)
    rows, _ = bc.compare(reference, current)
    assert status(rows, "public/horse.ply") == bc.REGRESSED
    assert status(rows, "public/hand.obj") == bc.OK
    assert [r["mesh"] for r in bc.regressions(rows)] == ["public/horse.ply"]
    horse = next(r for r in rows if r["mesh"] == "public/horse.ply")
    assert horse["change"] == pytest.approx(0.3)
    assert horse["stage"][0] in ("prepare", "voronoi_balls")


def test_a_slower_machine_is_no_regression(reference):
    """Everything, MCF included, 2.5x slower: the ratios do not move, and the meshes without
    MCF are scaled by MCF's median slow-down."""
    current = {k: mesh(r["total"] * 2.5, r["mcf_seconds"] and r["mcf_seconds"] * 2.5)
               for k, r in reference.items()}
    rows, factor = bc.compare(reference, current)
    assert factor == pytest.approx(2.5)
    assert bc.regressions(rows) == []


def test_a_mesh_without_mcf_is_compared_through_the_machine_factor(reference):
    current = {k: mesh(r["total"] * 2, r["mcf_seconds"] and r["mcf_seconds"] * 2)
               for k, r in reference.items()}
    current["stress/scan-open.obj"] = mesh(0.4 * 2 * 1.3)  # 30% worse on a 2x slower machine
    current["stress/pinched-blobs.obj"] = mesh(0.5 * 2 * 1.2)  # 20% worse
    rows, _ = bc.compare(reference, current)
    assert status(rows, "stress/scan-open.obj") == bc.REGRESSED
    assert status(rows, "stress/pinched-blobs.obj") == bc.OK
    scan = next(r for r in rows if r["mesh"] == "stress/scan-open.obj")
    assert scan["basis"] == "total / machine"


def test_new_and_missing_meshes_are_reported_not_flagged(reference):
    current = dict(reference)
    del current["public/hand.obj"]
    current["rigged/Fox.obj"] = mesh(0.2, 0.05)
    rows, _ = bc.compare(reference, current)
    assert status(rows, "public/hand.obj") == bc.MISSING
    assert status(rows, "rigged/Fox.obj") == bc.NEW
    assert bc.regressions(rows) == []
    table = bc.format_table(rows, 1.0)
    assert "rigged/Fox.obj | new" in table and "public/hand.obj | missing" in table


def test_a_mesh_failing_now_is_a_regression(reference):
    current = dict(reference)
    current["public/hand.obj"] = mesh(None, 0.5, error="InputError: bad")
    rows, _ = bc.compare(reference, current)
    assert status(rows, "public/hand.obj") == bc.ERROR
    assert len(bc.regressions(rows)) == 1


def test_jitter_of_a_few_milliseconds_is_not_flagged():
    reference = {"stress/tiny.obj": mesh(0.010, 0.020)}
    current = {"stress/tiny.obj": mesh(0.015, 0.020)}  # +50%, but 5 ms
    rows, _ = bc.compare(reference, current)
    assert rows[0]["status"] == bc.OK and "min-seconds" in rows[0]["note"]
    rows, _ = bc.compare(reference, current, min_seconds=0.001)
    assert rows[0]["status"] == bc.REGRESSED


def test_mcf_taking_a_few_milliseconds_is_no_yardstick(reference):
    """MCF on a few hundred faces: 47 ms in the reference, 19 ms now (it swings so from run to
    run) while ours got faster. Our ratio to it doubled; our total against the machine did not
    grow, and that is what is compared."""
    reference = dict(reference, **{"rigged/Fox.obj": mesh(0.134, 0.047)})
    current = dict(reference, **{"rigged/Fox.obj": mesh(0.103, 0.019)})
    rows, _ = bc.compare(reference, current)
    fox = next(r for r in rows if r["mesh"] == "rigged/Fox.obj")
    assert fox["status"] == bc.OK and fox["basis"] == "total / machine"
    rows, _ = bc.compare(reference, current, mcf_min_seconds=0.01)
    assert status(rows, "rigged/Fox.obj") == bc.REGRESSED  # what the ratio alone said


def test_no_mcf_anywhere_is_not_compared_rather_than_guessed():
    reference = {"stress/scan-open.obj": mesh(0.4)}
    rows, factor = bc.compare(reference, {"stress/scan-open.obj": mesh(0.9)})
    assert factor is None and rows[0]["status"] == bc.NOT_COMPARED


def write(path, meshes):
    path.write_text(json.dumps({"format": "dcg-bench-summary/1", "meshes": meshes}))
    return path


def test_main_exit_status_and_table(tmp_path, reference, capsys):
    ref = write(tmp_path / "ref.json", reference)
    worse = dict(reference, **{"public/horse.ply": mesh(2.6, 4.0)})
    assert bc.main([str(write(tmp_path / "same.json", reference)), "--reference", str(ref)]) == 0
    assert bc.main([str(write(tmp_path / "worse.json", worse)), "--reference", str(ref)]) == 1
    out = capsys.readouterr().out
    assert "| public/horse.ply | **REGRESSED** | ours/MCF | 0.500 | 0.650 | +30% |" in out
    assert "1 regression(s) over 25% (public/horse.ply)" in out
    (tmp_path / "bad.json").write_text("[]")
    assert bc.main([str(tmp_path / "bad.json"), "--reference", str(ref)]) == 2
    assert bc.main([str(tmp_path / "absent.json"), "--reference", str(ref)]) == 2


def test_the_committed_reference_reads(repo):
    path = repo / "scripts" / "bench_reference.json"
    if not path.is_file():
        pytest.skip("no committed reference yet")
    meshes = bc.load_summary(path)
    assert meshes and all("ours_over_mcf" in m and "stages" in m for m in meshes.values())
    assert any(k.startswith("stress/") for k in meshes)
