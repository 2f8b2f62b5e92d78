"""dcg.load_mesh: formats, dtypes and the errors a user sees for files that cannot be read."""

import numpy as np
import pytest

import dcg


def test_load_bundled_spot(repo):
    V, F = dcg.load_mesh(repo / "data" / "spot.obj")
    assert V.dtype == np.float64 and V.shape == (2930, 3)
    assert F.dtype == np.int64 and F.shape == (5856, 3)
    assert F.min() >= 0 and F.max() < len(V)


def test_load_off(repo):
    V, F = dcg.load_mesh(str(repo / "data" / "meshes" / "eight.off"))
    assert V.shape == (766, 3) and F.shape == (1536, 3)


def test_missing_file_is_os_error_naming_the_path(tmp_path):
    path = tmp_path / "nope.obj"
    with pytest.raises(OSError, match="nope.obj.*no such file"):
        dcg.load_mesh(path)


def test_directory_is_os_error(tmp_path):
    with pytest.raises(OSError, match="directory"):
        dcg.load_mesh(tmp_path)


def test_empty_file_is_value_error(tmp_path):
    path = tmp_path / "empty.obj"
    path.write_text("")
    with pytest.raises(ValueError, match="empty"):
        dcg.load_mesh(path)


def test_out_of_range_face_index_is_a_clear_error(tmp_path):
    path = tmp_path / "bad.obj"
    path.write_text("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\nf 1 2 7\n")
    with pytest.raises((ValueError, OSError), match="bad.obj"):
        dcg.load_mesh(path)


def test_unknown_extension_is_os_error(tmp_path):
    path = tmp_path / "mesh.abc"
    path.write_text("v 0 0 0\n")
    with pytest.raises(OSError, match="unsupported format"):
        dcg.load_mesh(path)


@pytest.mark.parametrize("name", ["hand.obj", "horse.ply", "cheetah.off"])
def test_load_public_meshes(meshes_dir, name):
    V, F = dcg.load_mesh(meshes_dir / name)
    assert len(V) > 100 and len(F) > 100
    assert np.isfinite(V).all()
