"""Shared fixtures: the repository, the public meshes (DCG_MESHES) and small synthetic shapes."""

import os
from pathlib import Path

import numpy as np
import pytest

REPO = Path(__file__).resolve().parents[2]


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


def uv_sphere(rings: int = 16, segments: int = 24, radius: float = 1.0):
    """A closed, outward-oriented UV sphere."""
    verts = [[0, 0, radius]]
    for i in range(1, rings):
        theta = np.pi * i / rings
        for j in range(segments):
            phi = 2 * np.pi * j / segments
            verts.append([radius * np.sin(theta) * np.cos(phi),
                          radius * np.sin(theta) * np.sin(phi), radius * np.cos(theta)])
    verts.append([0, 0, -radius])
    faces = []
    bottom = len(verts) - 1

    def ring(i, j):
        return 1 + (i - 1) * segments + j % segments

    for j in range(segments):
        faces.append([0, ring(1, j), ring(1, j + 1)])
        faces.append([bottom, ring(rings - 1, j + 1), ring(rings - 1, j)])
    for i in range(1, rings - 1):
        for j in range(segments):
            a, b, c, d = ring(i, j), ring(i, j + 1), ring(i + 1, j), ring(i + 1, j + 1)
            faces += [[a, c, b], [b, c, d]]
    return np.array(verts, dtype=float), np.array(faces, dtype=np.int64)


@pytest.fixture
def sphere():
    return uv_sphere()
