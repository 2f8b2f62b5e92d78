"""`/usr/bin/python3 -m dcg skeleton IN -o OUT.json`: output file, timings, exit codes."""

import json
import os
import subprocess
import sys
from pathlib import Path

import pytest

import dcg


def run_cli(*args, cwd=None):
    env = dict(os.environ)
    env["PYTHONPATH"] = str(Path(dcg.__file__).resolve().parents[1])
    return subprocess.run(["/usr/bin/python3", "-m", "dcg", *map(str, args)], env=env, cwd=cwd,
                          capture_output=True, text=True, timeout=300)


def test_cli_writes_json_and_prints_timings(repo, tmp_path):
    out = tmp_path / "spot.json"
    result = run_cli("skeleton", repo / "data" / "spot.obj", "-o", out, "--samples", "1000",
                     "--target-faces", "5000", "--tau", "0.8")
    assert result.returncode == 0, result.stderr
    doc = json.loads(out.read_text())
    assert doc["format"] == "dcg-skeleton/1"
    assert doc["options"]["tau"] == 0.8 and doc["options"]["samples"] == 1000
    assert "total" in result.stdout and "prepare" in result.stdout


def test_cli_says_how_it_repaired_a_mesh(meshes_dir, tmp_path):
    out = tmp_path / "wasp.json"
    result = run_cli("skeleton", meshes_dir / "rigged" / "Q_Wasp.obj", "-o", out)
    assert result.returncode == 0, result.stderr
    assert "repaired: the mesh has 13 parts" in result.stdout
    assert "union of its closed parts" in result.stdout
    result = run_cli("skeleton", meshes_dir / "hand.obj", "-o", out)
    assert "repaired:" not in result.stdout


def test_cli_on_public_hand(meshes_dir, tmp_path):
    out = tmp_path / "hand.json"
    result = run_cli("skeleton", meshes_dir / "hand.obj", "-o", out)
    assert result.returncode == 0, result.stderr
    doc = json.loads(out.read_text())
    assert doc["mesh"]["faces"] == 9556 and len(doc["nodes"]) >= 2
    for link in doc["links"]:
        assert doc["nodes"][link["a"]]["position"] == pytest.approx(link["polyline"][0])


@pytest.mark.parametrize("args,match", [
    (["skeleton", "/nonexistent.obj", "-o", "x.json"], "no such file"),
    (["skeleton", "data/spot.obj", "-o", "x.json", "--tau", "3"], "tau"),
])
def test_cli_errors_exit_non_zero_with_the_reason(repo, tmp_path, args, match):
    result = run_cli(*args, cwd=tmp_path if "nonexistent" in args[1] else repo)
    assert result.returncode != 0
    assert match in result.stderr
    assert "Traceback" not in result.stderr
