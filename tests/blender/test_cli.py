# SPDX-License-Identifier: GPL-3.0-or-later
"""The headless jobs behind `./exsynth run` (called in-process here)."""

import numpy as np
import pytest

from exsynth import _native, cli
from helpers import BUNNY_OBJ, enclosed_volume, read_obj

RES = ["--resolution", "40"]


@pytest.fixture(scope="module")
def bunny_arrays():
    return read_obj(BUNNY_OBJ)


def test_vdb_output_holds_both_grids(tmp_path, capsys):
    out = tmp_path / "bunny.vdb"
    assert cli.main(["voxelize", "--mesh", BUNNY_OBJ, *RES, "--out", str(out)]) == 0
    grids = _native.read_vdb(str(out))["grids"]
    assert set(grids) == {"density", "sdf"}
    assert grids["density"].shape == grids["sdf"].shape
    assert 0.0 <= grids["density"].min() and grids["density"].max() == pytest.approx(1.0)
    assert grids["sdf"].min() < 0.0 < grids["sdf"].max()
    assert "voxels of" in capsys.readouterr().out


def test_npy_output_is_z_y_x_2_in_file_coordinates(tmp_path, bunny_arrays):
    out = tmp_path / "bunny.npy"
    assert cli.main(["voxelize", "--mesh", BUNNY_OBJ, *RES, "--padding", "0", "--out", str(out)]) == 0
    grid = np.load(out)
    assert grid.dtype == np.float32 and grid.ndim == 4 and grid.shape[3] == 2
    density, sdf = grid[..., 0], grid[..., 1]
    assert np.all(sdf[density > 0.99] < 0) and np.all(sdf[density < 0.01] > 0)
    # No axis conversion: the grid's shape follows the OBJ's own extent.
    verts, faces = bunny_arrays
    extent = verts.max(axis=0) - verts.min(axis=0)
    h = extent.max() / 40
    np.testing.assert_allclose(grid.shape[2::-1], extent / h, atol=2)
    assert density.sum() * h**3 == pytest.approx(enclosed_volume(verts, faces), rel=0.02)


def test_mesh_out_writes_the_rebuilt_surface(tmp_path, bunny_arrays):
    out, mesh_out = tmp_path / "b.vdb", tmp_path / "sub" / "b.obj"
    assert cli.main(["voxelize", "--mesh", BUNNY_OBJ, *RES, "--out", str(out),
                     "--mesh-out", str(mesh_out)]) == 0
    verts, faces = read_obj(mesh_out)
    assert len(faces) > 1000
    assert enclosed_volume(verts, faces) == pytest.approx(enclosed_volume(*bunny_arrays), rel=0.03)


@pytest.mark.parametrize("ext", [".ply", ".stl"])
def test_ply_and_stl_inputs_give_the_obj_result(tmp_path, bunny_arrays, ext):
    verts, faces = bunny_arrays
    path = tmp_path / f"bunny{ext}"
    (write_ascii_ply if ext == ".ply" else write_ascii_stl)(path, verts, faces)
    for src, out in ((BUNNY_OBJ, "a.npy"), (str(path), "b.npy")):
        assert cli.main(["voxelize", "--mesh", src, *RES, "--out", str(tmp_path / out)]) == 0
    a, b = np.load(tmp_path / "a.npy"), np.load(tmp_path / "b.npy")
    assert a.shape == b.shape
    np.testing.assert_allclose(a[..., 0], b[..., 0], atol=1e-3)


@pytest.mark.parametrize("args, code, message", [
    (["--mesh", "/nonexistent/rabbit.obj", "--out", "x.vdb"], 2, "--mesh: no such file: /nonexistent/rabbit.obj"),
    (["--mesh", BUNNY_OBJ, "--out", "x.txt"], 2, "--out: unsupported file type '.txt'"),
    (["--mesh", BUNNY_OBJ, "--out", "x.vdb", "--mesh-out", "m.fbx"], 2, "--mesh-out: unsupported file type"),
    (["--mesh", BUNNY_OBJ, "--out", "x.vdb", "--resolution", "0"], 2, "--resolution must be > 0"),
    (["--mesh", BUNNY_OBJ, "--out", "x.vdb", "--resolution", "-3"], 2, "--resolution must be > 0"),
    (["--mesh", BUNNY_OBJ, "--out", "x.vdb", "--resolution", "400", "--memory-budget", "0.001"],
     1, "over the memory budget"),
])
def test_bad_arguments_fail_with_a_message(tmp_path, monkeypatch, capsys, args, code, message):
    monkeypatch.chdir(tmp_path)
    assert cli.main(["voxelize", *args]) == code
    assert message in capsys.readouterr().err
    assert not (tmp_path / "x.vdb").exists()


def test_unknown_mesh_format(tmp_path, capsys):
    path = tmp_path / "rabbit.fbx"
    path.write_text("not a mesh")
    assert cli.main(["voxelize", "--mesh", str(path), "--out", str(tmp_path / "x.vdb")]) == 2
    assert "--mesh: unsupported file type '.fbx' (use .obj, .ply, .stl)" in capsys.readouterr().err


def test_help_lists_the_jobs(capsys):
    assert cli.main(["--help"]) == 0
    out = capsys.readouterr().out
    assert "voxelize" in out and "demo" in out
    assert cli.main([]) == 2
    assert cli.main(["nosuchjob"]) == 2


def write_ascii_ply(path, verts, faces):
    header = (f"ply\nformat ascii 1.0\nelement vertex {len(verts)}\nproperty float x\n"
              f"property float y\nproperty float z\nelement face {len(faces)}\n"
              "property list uchar int vertex_indices\nend_header\n")
    with open(path, "w") as f:
        f.write(header)
        np.savetxt(f, verts, fmt="%.6f")
        np.savetxt(f, np.c_[np.full(len(faces), 3), faces], fmt="%d")


def write_ascii_stl(path, verts, faces):
    tri = verts[faces]
    normals = np.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0])
    normals /= np.linalg.norm(normals, axis=1, keepdims=True) + 1e-30
    blocks = [f"facet normal {n[0]:.6f} {n[1]:.6f} {n[2]:.6f}\nouter loop\n"
              + "".join(f"vertex {p[0]:.6f} {p[1]:.6f} {p[2]:.6f}\n" for p in t)
              + "endloop\nendfacet\n" for n, t in zip(normals, tri)]
    path.write_text("solid bunny\n" + "".join(blocks) + "endsolid bunny\n")
