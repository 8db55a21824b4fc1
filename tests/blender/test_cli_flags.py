# SPDX-License-Identifier: GPL-3.0-or-later
"""Every flag of every `./exsynth run` job has an effect or is refused.

For each flag, a small job is run twice, without and with the flag (or with
two values of it); the files the second run writes must differ from the
first's, or the run must be refused with exit code 2 under the flag's name
(a flag that goes with another one), or stop at the memory budget. The
table is checked against the parser, so a new flag without a case fails."""

import os
import shutil

import numpy as np
import pytest

from exsynth import cli, demo
from exsynth.io.mesh_files import read_obj
from helpers import BUNNY_OBJ, COW_OBJ, TEXTURES, write_grid_obj

CRACKED = os.path.join(TEXTURES, "crackedground.png")
WOOD = os.path.join(TEXTURES, "drkwood2.png")
DIFFERS, REFUSED, BUDGET = "differs", "refused", "budget"
TINY_BUDGET = ["--memory-budget", "1e-7"]  # about 100 bytes: every job is over it


def case(after, before=(), drop=(), instead=(), expect=DIFFERS):
    """The base job plus `before`, then plus `after`; `drop` leaves base arguments out of both runs,
    `instead` out of the second only (`after` is an alternative input to them)."""
    return {"after": list(after), "before": list(before), "drop": list(drop), "instead": list(instead),
            "expect": expect}


BASES = {
    "voxelize": ["--mesh", BUNNY_OBJ, "--resolution", "12", "--out", "{o}/v.npy"],
    "solid": ["--exemplar", CRACKED, "--size", "16", "--levels", "2", "--iterations", "1", "--out", "{o}/s.npy"],
    "image": ["--exemplar", CRACKED, "--width", "32", "--height", "32", "--out", "{o}/i.png"],
    "field": ["--mesh", BUNNY_OBJ, "--preset", "around_axis", "--out", "{o}/f.npy"],
    "analogy": ["--b", BUNNY_OBJ, "--preset", "spikes", "--resolution", "24", "--pattern-size", "0.4",
                "--out", "{o}/a.npy"],
    "surface": ["--mesh", "{i}/grid.obj", "--exemplar", CRACKED, "--face-resolution", "4", "--out", "{o}/a.obj",
                "--texture-out", "{o}/t.png"],
    "points": ["--preset", "bumps", "--size", "1", "1", "--out", "{o}/p.ply"],
}
BAKE = ["--mesh", COW_OBJ, "--bake-out", "{o}/b.png", "--bake-size", "32"]
PAIR = ["--a", "{i}/cube.obj", "--a-prime", "{i}/big_cube.obj"]
TARGET = ["--target", "{i}/cube.obj", "--scale", "6"]

CASES = {
    "voxelize": {
        "--resolution": [case(["--resolution", "16"])],
        "--voxel-size": [case(["--voxel-size", "0.02"])],
        "--padding": [case(["--padding", "3"])],
        "--supersample": [case(["--supersample", "1"])],
        "--mesh-out": [case(["--mesh-out", "{o}/m.obj"])],
        "--memory-budget": [case(TINY_BUDGET, expect=BUDGET)],
    },
    "solid": {
        "--exemplar-y": [case(["--exemplar-y", WOOD])],
        "--exemplar-z": [case(["--exemplar-z", WOOD])],
        "--size": [case(["--size", "20"])],
        "--levels": [case(["--levels", "1"])],
        "--iterations": [case(["--iterations", "2"])],
        "--method": [case(["--method", "{other}"])],
        "--feature-weight": [case(["--feature-weight", "0"])],
        "--feature-threshold": [case(["--feature-threshold", "0.3"])],
        "--feature-scale": [case(["--feature-scale", "6"])],
        "--rotate-exemplar": [case(["--rotate-exemplar", "off"])],
        "--histogram-values": [case(["--histogram-values", "0"])],
        "--structure-sigma": [case(["--structure-sigma", "2"])],
        "--seed": [case(["--seed", "1"])],
        "--alpha": [case(["--alpha"])],
        "--scale": [case(["--scale", "2"], before=["--out", "{o}/s.vdb"], drop=["--out", "{o}/s.npy"]),
                    case(["--scale", "2"], before=BAKE)],
        "--mesh": [case(BAKE)],
        "--bake-out": [case(["--bake-out", "{o}/b.png"], expect=REFUSED)],  # its effect: the --mesh case
        "--bake-size": [case(["--bake-size", "16"], before=BAKE), case(["--bake-size", "16"], expect=REFUSED)],
        "--bake-interpolation": [case(["--bake-interpolation", "linear"], before=BAKE),
                                 case(["--bake-interpolation", "linear"], expect=REFUSED)],
        "--mesh-out": [case(["--mesh-out", "{o}/m.obj"], before=BAKE),
                       case(["--mesh-out", "{o}/m.obj"], expect=REFUSED)],
        "--memory-budget": [case(TINY_BUDGET, expect=BUDGET)],
    },
    "image": {
        "--tileable": [case(["--tileable"])],
        "--method": [case(["--method", "{other}"])],
        "--levels": [case(["--levels", "1"], before=["--method", "optimization"]),
                     case(["--levels", "1"], expect=REFUSED)],
        "--iterations": [case(["--iterations", "2"], before=["--method", "optimization"]),
                         case(["--iterations", "2"], expect=REFUSED)],
        "--seed": [case(["--seed", "1"])],
        "--alpha": [case(["--alpha"])],
        "--memory-budget": [case(TINY_BUDGET, expect=BUDGET)],
    },
    "field": {
        "--preset": [case(["--preset", "along_axis"])],
        "--paint": [case(["--paint", "{i}/field_bunny.npy"], instead=["--preset", "around_axis"])],
        "--axis": [case(["--axis", "x"])],
        "--curve": [case(["--curve", "{i}/curve2.npy"], before=["--preset", "along_curve", "--curve", "{i}/curve.npy"]),
                    case(["--curve", "{i}/curve.npy"], expect=REFUSED)],
    },
    "analogy": {
        "--preset": [case(["--preset", "grooves"])],
        "--a": [case(PAIR, instead=["--preset", "spikes", "--pattern-size", "0.4"]),
                case(["--a", "{i}/cube.obj"], instead=["--preset", "spikes", "--pattern-size", "0.4"],
                     expect=REFUSED)],
        "--a-prime": [case(["--a-prime", "{i}/big_cube.obj"], expect=REFUSED)],
        "--a-region": [case(["--a-region", "{i}/face.obj"], before=PAIR,
                            drop=["--preset", "spikes", "--pattern-size", "0.4"]),
                       case(["--a-region", "{i}/face.obj"], expect=REFUSED)],
        "--field-preset": [case(["--field-preset", "along_axis"])],
        "--field": [case(["--field", "{i}/field_bunny.npy"])],
        "--axis": [case(["--axis", "1", "0", "0"])],
        "--curve": [case(["--curve", "{i}/curve2.npy"],
                         before=["--field-preset", "along_curve", "--curve", "{i}/curve.npy"]),
                    case(["--curve", "{i}/curve.npy"], expect=REFUSED)],
        "--resolution": [case(["--resolution", "28"])],
        "--pattern-size": [case(["--pattern-size", "0.6"]),
                           case(["--pattern-size", "0.6"], before=PAIR, drop=["--preset", "spikes", "--pattern-size", "0.4"],
                                expect=REFUSED)],
        "--dilation": [case(["--dilation", "0.25"], before=["--preset", "dilate"]),
                       case(["--dilation", "0.25"], expect=REFUSED)],
        "--spike-height": [case(["--spike-height", "0.5"]),
                           case(["--spike-height", "0.5"], before=["--preset", "grooves"], expect=REFUSED)],
        "--memory-budget": [case(TINY_BUDGET, expect=BUDGET)],
    },
    "surface": {
        "--height": [case(["--height", CRACKED])],
        "--alpha": [case(["--alpha"])],
        "--method": [case(["--method", "{other}"])],
        "--texels-per-unit": [case(["--texels-per-unit", "6"], drop=["--face-resolution", "4"])],
        "--face-resolution": [case(["--face-resolution", "6"])],
        "--exemplar-scale": [case(["--exemplar-scale", "2"])],
        "--field-preset": [case(["--field-preset", "around_axis"], before=["--axis", "1", "0", "0"])],
        "--field": [case(["--field", "{i}/field_grid.npy"])],
        "--axis": [case(["--axis", "0", "1", "0"], before=["--axis", "1", "0", "0"]),
                   case(["--axis", "0", "1", "0"], before=["--field", "{i}/field_grid.npy"], expect=REFUSED)],
        "--segments": [case(["--segments", "3"])],
        "--height-scale": [case(["--height-scale", "0.05"], before=["--height", CRACKED]),
                           case(["--height-scale", "0.05"], expect=REFUSED)],
        "--height-out": [case(["--height-out", "{o}/h.png"], before=["--height", CRACKED]),
                         case(["--height-out", "{o}/h.png"], expect=REFUSED)],
        "--seed": [case(["--seed", "1"])],
        "--memory-budget": [case(TINY_BUDGET, expect=BUDGET)],
    },
    "points": {
        "--exemplar": [case(["--exemplar", "{i}/exemplar.ply"], instead=["--preset", "bumps"])],
        "--preset": [case(["--preset", "weave"])],
        "--size": [case(["--size", "1.5", "1.5"])],
        "--target": [case(TARGET, instead=["--size", "1", "1"])],
        "--field-preset": [case(["--field-preset", "along_axis"], before=TARGET, drop=["--size", "1", "1"]),
                           case(["--field-preset", "along_axis"], expect=REFUSED)],
        "--axis": [case(["--axis", "1", "0", "0"], before=TARGET, drop=["--size", "1", "1"]),
                   case(["--axis", "1", "0", "0"], expect=REFUSED)],
        "--curve": [case(["--curve", "{i}/curve2.npy"], before=TARGET + ["--field-preset", "along_curve", "--curve",
                                                                          "{i}/curve.npy"], drop=["--size", "1", "1"]),
                    case(["--curve", "{i}/curve.npy"], expect=REFUSED)],
        "--field": [case(["--field", "{i}/field_cube.npy"], before=TARGET, drop=["--size", "1", "1"]),
                    case(["--field", "{i}/field_cube.npy"], expect=REFUSED)],
        "--scale": [case(["--scale", "5"], before=TARGET, drop=["--size", "1", "1"]),
                    case(["--scale", "5"], expect=REFUSED)],
        "--patch-size": [case(["--patch-size", "0.3"])],
        "--density": [case(["--density", "4000"]),
                      case(["--density", "4000"], before=["--exemplar", "{i}/exemplar.ply"], drop=["--preset", "bumps"],
                           expect=REFUSED)],
        "--pixel-size": [case(["--pixel-size", "0.02"], before=["--exemplar", "{i}/height.png", "--pixel-size", "0.01"],
                              drop=["--preset", "bumps"]),
                         case(["--pixel-size", "0.02"], expect=REFUSED)],
        "--height-scale": [case(["--height-scale", "2"], before=["--exemplar", "{i}/height.png"],
                                drop=["--preset", "bumps"]),
                           case(["--height-scale", "2"], expect=REFUSED)],
        "--mesh-out": [case(["--mesh-out", "{o}/m.obj"])],
        "--seed": [case(["--seed", "1"])],
        "--memory-budget": [case(TINY_BUDGET, expect=BUDGET)],
    },
}


def _subparsers():
    return next(a for a in cli._parser()._actions if a.dest == "job").choices


def _flags(parser):
    return {a.option_strings[0]: a for a in parser._actions if a.option_strings and a.option_strings[0] != "-h"}


def test_every_flag_of_every_job_has_a_case():
    jobs = _subparsers()
    assert set(jobs) == set(CASES) | {"demo"}
    for job, parser in jobs.items():
        if job == "demo":
            continue
        optional = {f for f, a in _flags(parser).items() if not a.required} - set(BASES[job][::2])
        assert optional - set(CASES[job]) == set(), f"{job}: flags without a case"
        assert set(CASES[job]) - set(_flags(parser)) == set(), f"{job}: cases for flags it does not have"


@pytest.fixture(scope="module")
def inputs(tmp_path_factory):
    d = tmp_path_factory.mktemp("inputs")
    write_grid_obj(d / "grid.obj", 2)
    for name, half in (("cube", 1.0), ("big_cube", 1.15)):
        _write_cube(d / f"{name}.obj", half)
    (d / "face.obj").write_text("v -1 -1 1\nv 1 -1 1\nv 1 1 1\nv -1 1 1\nf 1 2 3 4\n")
    bunny, _ = read_obj("--mesh", BUNNY_OBJ)
    lo, hi = bunny.min(0), bunny.max(0)
    mid = (lo + hi) / 2
    np.save(d / "field_bunny.npy", np.tile(np.float32([1, 0, 0]), (len(bunny), 1)))
    np.save(d / "field_grid.npy", np.tile(np.float32([1, 1, 0]), (9, 1)))
    np.save(d / "field_cube.npy", np.tile(np.float32([1, 1, 0]), (8, 1)))
    np.save(d / "curve.npy", np.array([[mid[0], lo[1] - 1, mid[2]], [mid[0], hi[1] + 1, mid[2]]], np.float64))
    np.save(d / "curve2.npy", np.array([[lo[0] - 1, mid[1], mid[2]], [hi[0] + 1, mid[1], mid[2]]], np.float64))
    shutil.copy(CRACKED, d / "height.png")
    assert cli.main(["points", "--preset", "bumps", "--size", "1", "1", "--out", str(d / "exemplar.ply")]) == 0
    return d


def _write_cube(path, half):
    corners = [(x, y, z) for x in (-half, half) for y in (-half, half) for z in (-half, half)]
    quads = [(1, 3, 4, 2), (5, 6, 8, 7), (1, 2, 6, 5), (3, 7, 8, 4), (1, 5, 7, 3), (2, 4, 8, 6)]
    path.write_text("".join(f"v {x} {y} {z}\n" for x, y, z in corners) + "".join(f"f {a} {b} {c} {d}\n"
                                                                               for a, b, c, d in quads))


_RUNS = {}


def _run(capsys, job, args, tmp_root, inputs):
    """(exit code, stderr, {file: bytes}) of one run; the same arguments run once per module."""
    key = (job, tuple(args))
    if key not in _RUNS:
        out = tmp_root / f"run{len(_RUNS)}"
        out.mkdir()
        filled = [a.format(o=out, i=inputs) for a in args]
        code = cli.main([job, *filled])
        err = capsys.readouterr().err
        _RUNS[key] = (code, err, {p: (out / p).read_bytes() for p in sorted(os.listdir(out))})
    return _RUNS[key]


def _without(args, flags):
    """`args` without each flag of `flags` and its value(s)."""
    args = list(args)
    for flag in (f for f in flags if f.startswith("--")):
        at = args.index(flag)
        n = next((j for j in range(at + 1, len(args)) if args[j].startswith("--")), len(args)) - at
        del args[at:at + n]
    return args


def _other_choice(job, flag):
    action = _flags(_subparsers()[job])[flag]
    return next(c for c in action.choices if c != action.default)


@pytest.mark.parametrize("job, flag, k", [(j, f, k) for j in CASES for f in CASES[j] for k in range(len(CASES[j][f]))])
def test_a_flag_changes_the_output_or_is_refused(tmp_path_factory, capsys, inputs, job, flag, k):
    c = CASES[job][flag][k]
    base = _without(BASES[job], c["drop"])
    before = base + c["before"]
    after = _without(base, c["instead"]) + c["before"] + [_other_choice(job, flag) if a == "{other}" else a
                                                          for a in c["after"]]
    root = tmp_path_factory.getbasetemp()
    code0, err0, files0 = _run(capsys, job, before, root, inputs)
    assert code0 == 0, err0
    code, err, files = _run(capsys, job, after, root, inputs)
    assert "Traceback" not in err
    if c["expect"] == DIFFERS:
        assert code == 0, err
        assert files != files0, f"{job} {flag}: the same files with and without it"
    elif c["expect"] == REFUSED:
        assert code == 2 and flag in err, err
        assert files == {}
    else:
        assert code == 1 and "memory budget" in err, err
        assert files == {}


DEMO_FLAGS = {"--resolution": "24", "--samples": "2", "--solid-size": "48"}


def test_every_demo_flag_reaches_its_stage(tmp_path, monkeypatch):
    """The demo renders for a minute; here its stages are recorded, not run."""
    assert set(_flags(_subparsers()["demo"])) - {"--assets", "--out"} == set(DEMO_FLAGS)
    calls = []
    for stage in ("run", "run_solid", "run_analogy", "run_surface"):
        monkeypatch.setattr(demo, stage, lambda *a, _s=stage, **kw: calls.append((_s, a[-1], kw)) and None)
    assets = os.path.dirname(TEXTURES)

    def stages(*extra):
        calls.clear()
        assert cli.main(["demo", "--assets", assets, "--out", str(tmp_path), *extra]) == 0
        return list(calls)

    base = stages()
    assert [c[0] for c in base] == ["run", "run_solid", "run_analogy", "run_surface"]
    for flag, value in DEMO_FLAGS.items():
        assert stages(flag, value) != base, f"demo {flag} reaches no stage"
