"""exsynth.io.mesh_files: face indices Blender's importers would drop silently."""
import numpy as np
import pytest

from exsynth.io.mesh_files import MeshFileError, check_indices

from conftest import ASSETS

TRIANGLE = "v 0 0 0\nv 1 0 0\nv 0 1 0\n"


@pytest.mark.parametrize("text, message", [
    (TRIANGLE + "f 1 2 4\n", r"4: face vertex 4 is out of range \(the file has 3 vertices"),
    (TRIANGLE + "f 1 2 0\n", "4: face vertex 0 is out of range"),
    (TRIANGLE + "f -1 -2 -4\n", "4: face vertex -4 is out of range"),
    ("v 0 0 0\nf 1 2 3\nv 1 0 0\nv 0 1 0\n", r"2: face vertex 2"),  # used before it is defined
    (TRIANGLE + "f 1 2 x\n", "4: 'x' is not a vertex index"),
    ("v 0 0 0\nv nan 0 0\nv 0 1 0\nf 1 2 3\n", "2: vertex 1 is not three finite numbers"),
    ("v 0 0 0\nv 1 0\nv 0 1 0\nf 1 2 3\n", "2: vertex 1 is not three finite numbers"),
])
def test_obj_bad_faces_are_named(tmp_path, text, message):
    path = tmp_path / "m.obj"
    path.write_text(text)
    with pytest.raises(MeshFileError, match="--mesh: .*m.obj line " + message):
        check_indices("--mesh", str(path))


def test_good_obj_files_pass(tmp_path):
    path = tmp_path / "m.obj"
    path.write_text(TRIANGLE + "vt 0 0\nf 1/1 2/1 3/1\nf -3 -2 -1\nl 1 2\n")
    check_indices("--mesh", str(path))
    check_indices("--mesh", str(ASSETS / "meshes" / "bunny.obj"))


def ply(faces):
    return ("ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\n"
            f"element face {len(faces)}\nproperty list uchar int vertex_indices\nend_header\n"
            "0 0 0\n1 0 0\n0 1 0\n" + "".join(f"{len(f)} {' '.join(map(str, f))}\n" for f in faces))


def test_ascii_ply(tmp_path):
    path = tmp_path / "m.ply"
    path.write_text(ply([[0, 1, 2]]))
    check_indices("--b", str(path))
    path.write_text(ply([[0, 1, 2], [0, 1, 3]]))
    with pytest.raises(MeshFileError, match=r"--b: .* line 14: face vertex 3 is out of range \(the file has 3"):
        check_indices("--b", str(path))


def test_write_obj_keeps_tiny_coordinates_and_read_obj_reads_them_back(tmp_path):
    from exsynth.io.mesh_files import read_obj, write_obj

    rng = np.random.default_rng(1)
    v = rng.normal(size=(10, 3)) * 1e-6
    f = np.array([[0, 1, 2], [2, 3, 4], [9, 8, 7]], np.int32)
    path = tmp_path / "tiny.obj"
    write_obj(str(path), "tiny", v, f)
    v2, f2 = read_obj("--mesh", str(path))
    np.testing.assert_allclose(v2, v, rtol=1e-8)
    np.testing.assert_array_equal(f2, f)


def test_read_obj_fans_polygons_and_keeps_loose_vertices(tmp_path):
    from exsynth.io.mesh_files import read_obj

    path = tmp_path / "quad.obj"
    path.write_text("v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nv 5 5 5\nf 1 2 3 4\nf -5 -4 -3\n")
    v, f = read_obj("--mesh", str(path))
    assert v.shape == (5, 3)
    np.testing.assert_array_equal(f, [[0, 1, 2], [0, 2, 3], [0, 1, 2]])
