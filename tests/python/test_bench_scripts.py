"""The bench scripts that `make bench` runs with the system Python start and parse their
arguments (make bench is not part of make test; a script broken by a change elsewhere, as
bench_batch.py was by cli._add_option_flags, would otherwise show only there)."""

import os
import subprocess
from pathlib import Path

import pytest

import dcg

SCRIPTS = ["bench.py", "bench_batch.py", "bench_big.py", "bench_compare.py",
           "bench_rig_quality.py", "make_stress_set.py", "make_big_mesh.py"]


@pytest.mark.parametrize("script", SCRIPTS)
def test_bench_script_prints_its_usage(repo, script):
    env = dict(os.environ, PYTHONPATH=str(Path(dcg.__file__).resolve().parents[1]))
    result = subprocess.run(["/usr/bin/python3", str(repo / "scripts" / script), "--help"],
                            env=env, capture_output=True, text=True, timeout=120)
    assert result.returncode == 0, result.stderr
    assert "usage:" in result.stdout
