"""exsynth.io.outputs: a job's output files appear all together or not at all
(plain Python: the module has no bpy)."""
import os

import pytest
from fsmarks import immutable

from exsynth.io.outputs import OutputFiles, OutputPathError


def test_files_appear_only_when_the_block_ends(tmp_path):
    with OutputFiles() as files:
        a = files.add("--out", str(tmp_path / "a.npy"), (".npy",))
        b = files.add("--mesh-out", str(tmp_path / "new" / "deeper" / "b.obj"), (".obj",))
        assert a.endswith(".npy") and b.endswith(".obj")  # writers that add extensions keep them
        assert os.path.dirname(a) == str(tmp_path)  # same folder: the rename cannot cross filesystems
        for path in (a, b):
            with open(path, "w") as f:
                f.write("data")
        assert not (tmp_path / "a.npy").exists()
    assert (tmp_path / "a.npy").read_text() == "data"
    assert (tmp_path / "new" / "deeper" / "b.obj").read_text() == "data"
    assert sorted(os.listdir(tmp_path)) == ["a.npy", "new"]  # no temporary left


def test_a_failure_leaves_no_new_file_and_the_old_one_untouched(tmp_path):
    old = tmp_path / "a.npy"
    old.write_text("the artist's earlier result")
    with pytest.raises(RuntimeError, match="engine failed"):
        with OutputFiles() as files:
            with open(files.add("--out", str(old), (".npy",)), "w") as f:
                f.write("half")
            files.add("--mesh-out", str(tmp_path / "sub" / "m.obj"), (".obj",))
            raise RuntimeError("engine failed")
    assert old.read_text() == "the artist's earlier result"
    assert os.listdir(tmp_path) == ["a.npy"]  # the new folder went too


def test_ctrl_c_discards_too(tmp_path):
    with pytest.raises(KeyboardInterrupt):
        with OutputFiles() as files:
            with open(files.add("--out", str(tmp_path / "a.png"), (".png",)), "w") as f:
                f.write("x")
            raise KeyboardInterrupt
    assert os.listdir(tmp_path) == []


def test_a_file_the_writer_never_wrote_fails_the_job(tmp_path):
    """Blender's OBJ exporter reports success and writes nothing on some paths."""
    with pytest.raises(OSError, match=r"--out: nothing was written to .*b\.obj"):
        with OutputFiles() as files:
            with open(files.add("--mesh-out", str(tmp_path / "a.obj"), (".obj",)), "w") as f:
                f.write("v 0 0 0\n")
            files.add("--out", str(tmp_path / "b.obj"), (".obj",))
    assert os.listdir(tmp_path) == []  # all or none: a.obj is not left alone either


@pytest.mark.parametrize("make, message", [
    (lambda d: str(d), r"is a folder; give a file name, e.g. .*result\.obj"),
    (lambda d: "/proc/exsynth_test.obj", r"cannot write /proc/exsynth_test\.obj"),
    (lambda d: (d / "f.txt").write_text("") or str(d / "f.txt" / "x.obj"), r"f\.txt is a file, not a folder"),
    (lambda d: str(d / "x.fbx"), r"unsupported file type '\.fbx' \(use \.obj\)"),
])
def test_unwritable_paths_are_refused_before_anything_runs(tmp_path, make, message):
    path = make(tmp_path)
    before = sorted(os.listdir(tmp_path))
    with pytest.raises(OutputPathError, match="--out: .*" + message):
        with OutputFiles() as files:
            files.add("--out", path, (".obj",))
    assert sorted(os.listdir(tmp_path)) == before


def test_the_same_path_twice_is_refused(tmp_path):
    with pytest.raises(OutputPathError, match="--mesh-out: .* is also another output"):
        with OutputFiles() as files:
            files.add("--out", str(tmp_path / "a.obj"), (".obj",))
            files.add("--mesh-out", str(tmp_path / "a.obj"), (".obj",))


def _three_outputs(tmp_path, files):
    """Declares a.obj, a.mtl and t.png (as `run surface` does) and writes new contents."""
    temps = [files.add(opt, str(tmp_path / name), (os.path.splitext(name)[1],))
             for opt, name in (("--out", "a.obj"), ("--out (its .mtl)", "a.mtl"), ("--texture-out", "t.png"))]
    for temp in temps:
        with open(temp, "w") as f:
            f.write("new")


def test_a_rename_that_fails_puts_every_file_back(tmp_path):
    """All or none even when the last rename fails: the first two new files
    are taken out again and the old ones put back, under the user's names."""
    for name in ("a.obj", "a.mtl", "t.png"):
        (tmp_path / name).write_text("old " + name)
    with pytest.raises(OSError, match=r"--texture-out: cannot replace .*t\.png \(Is a directory\)") as info:
        with OutputFiles() as files:
            _three_outputs(tmp_path, files)
            (tmp_path / "t.png").unlink()
            (tmp_path / "t.png").mkdir()  # appears after the check: os.rename onto it fails
    assert ".exsynth-" not in str(info.value)  # the user's path, not the temporary one
    assert (tmp_path / "a.obj").read_text() == "old a.obj"
    assert (tmp_path / "a.mtl").read_text() == "old a.mtl"
    assert sorted(os.listdir(tmp_path)) == ["a.mtl", "a.obj", "t.png"]  # no temporary or moved-aside file


def test_replacing_existing_files_keeps_no_old_copy(tmp_path):
    for name in ("a.obj", "a.mtl", "t.png"):
        (tmp_path / name).write_text("old")
    with OutputFiles() as files:
        _three_outputs(tmp_path, files)
    assert sorted(os.listdir(tmp_path)) == ["a.mtl", "a.obj", "t.png"]
    assert all((tmp_path / n).read_text() == "new" for n in ("a.obj", "a.mtl", "t.png"))


@pytest.mark.skipif(os.geteuid() != 0, reason="marking a file immutable needs root (CAP_LINUX_IMMUTABLE)")
def test_an_immutable_existing_output_is_refused_before_the_job(tmp_path):
    png = tmp_path / "t.png"
    png.write_text("old")
    with immutable(png):
        with pytest.raises(OutputPathError, match=r"--texture-out: .*t\.png exists and cannot be replaced "
                                                  r"\(it is marked immutable"):
            with OutputFiles() as files:
                _three_outputs(tmp_path, files)
        assert sorted(os.listdir(tmp_path)) == ["t.png"] and png.read_text() == "old"
