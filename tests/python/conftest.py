"""Shared fixtures: the repository, the public meshes (DCG_MESHES) and small synthetic shapes."""

import os
import sys
from pathlib import Path

import numpy as np
import pytest

REPO = Path(__file__).resolve().parents[2]
sys.path.append(str(REPO / "scripts"))  # the shapes of the stress set
from make_stress_set import combine, uv_sphere  # noqa: E402,F401 - the tests import them here


@pytest.fixture(scope="session")
def repo() -> Path:
    return REPO


@pytest.fixture(scope="session")
def meshes_dir() -> Path:
    """The public meshes (../shared/meshes by default); tests using them skip when absent."""
    path = Path(os.environ.get("DCG_MESHES", REPO.parent / "shared" / "meshes"))
    if not (path / "MANIFEST.tsv").is_file():
        pytest.skip(f"public meshes not found at {path} (set DCG_MESHES)")
    return path


def shared_skeleton(V, F, name, **options):
    """dcg.extract_skeleton(V, F, **options) of the shared mesh `name`, checked to be a DCG
    skeleton: the engine's fallback (method "interim_graph (fallback: ...)") must not pass a
    test on a shared mesh silently."""
    import dcg

    skeleton = dcg.extract_skeleton(V, F, **options)
    assert skeleton.method == "dcg", f"{name}: the engine fell back: {skeleton.method}"
    return skeleton


def cube(open_faces: int = 0):
    """A closed unit cube (8 vertices, 12 outward triangles); drop the last `open_faces`."""
    V = np.array([[x, y, z] for x in (0, 1) for y in (0, 1) for z in (0, 1)], dtype=float)
    F = np.array([
        [0, 1, 3], [0, 3, 2], [4, 6, 7], [4, 7, 5], [0, 4, 5], [0, 5, 1],
        [2, 3, 7], [2, 7, 6], [0, 2, 6], [0, 6, 4], [1, 5, 7], [1, 7, 3]], dtype=np.int64)
    return V, F[: len(F) - open_faces]


@pytest.fixture
def sphere():
    return uv_sphere()
