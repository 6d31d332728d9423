"""The Python package: meshing with settings and configs, the mesh's arrays and report, writing
and checking every format, the typed errors with the command line's messages, progress."""

import json
import subprocess

import numpy as np
import pytest

import blmesh
from conftest import BOX, ROOT

KINDS = ["tetrahedron", "pyramid", "prism", "hexahedron"]


def test_box_mesh_has_layers_and_a_core(box_mesh):
    m = box_mesh
    assert m.points.shape[1] == 3 and m.points.dtype == np.float64
    assert sorted(m.cells) == sorted(KINDS)
    counts = m.report["cells"]
    assert len(m.cells["prism"]) == counts["prisms"] > 0
    assert len(m.cells["tetrahedron"]) == counts["tetrahedra"] > 0
    assert len(m.points) == counts["points"]
    for kind, nodes in m.cells.items():
        assert nodes.shape[1] == {"tetrahedron": 4, "pyramid": 5, "prism": 6, "hexahedron": 8}[kind]
        assert nodes.size == 0 or (nodes.min() >= 0 and nodes.max() < len(m.points))
        assert m.cell_zones[kind].shape == (len(nodes),)
    assert m.zone_names == ["boundary_layer", "core"]
    assert set(np.unique(m.cell_zones["prism"])) == {0}
    assert m.report["layers"]["layers_max"] >= 10
    assert m.report["check"]["validity"]["invalid_cells"] == 0


def test_boundary_faces_carry_the_patches(box_mesh):
    b = box_mesh.boundary
    assert "farfield" in b.patch_names and "xmin" in b.patch_names
    assert b.triangles.shape == (len(b.triangle_patches), 3)
    assert b.quads.shape == (len(b.quad_patches), 4)
    used = set(b.triangle_patches) | set(b.quad_patches)
    assert used <= set(range(len(b.patch_names)))
    assert len(b.triangles) > 0


def test_the_summary_and_check_of_the_mesh_in_memory(box_mesh):
    assert "prisms" in str(box_mesh) and "prism" in repr(box_mesh)
    report = blmesh.check(box_mesh)
    assert report["accepted"] is True
    assert report["cells"] == {kind: len(nodes) for kind, nodes in box_mesh.cells.items()}


@pytest.mark.parametrize("name", ["box.vtu", "box.msh", "box.cgns"])
def test_written_meshes_pass_check(box_mesh, tmp_path, name):
    if name.endswith(".cgns") and not blmesh._native.CGNS:
        pytest.skip("built without the CGNS library")
    path = tmp_path / name
    box_mesh.write(path)
    report = blmesh.check(path)
    assert report["accepted"] is True, report
    assert report["points"] == len(box_mesh.points)


@pytest.mark.parametrize(
    "name", ["box.su2", "box.mesh", "box.meshb", "box.b8.ugrid", "case/constant/polyMesh", "ascii.msh"]
)
def test_every_other_format_is_written(box_mesh, tmp_path, name):
    path = tmp_path / name
    box_mesh.write(path, ascii=name == "ascii.msh")
    assert path.exists()
    if name == "ascii.msh":
        assert path.read_bytes().startswith(b"$MeshFormat\n4.1 0 ")


def test_report_and_pictures_are_written(box_mesh, tmp_path):
    box_mesh.write_report(tmp_path / "r.json")
    assert json.loads((tmp_path / "r.json").read_text())["cells"] == box_mesh.report["cells"]
    box_mesh.write_pictures(tmp_path / "pictures")
    assert any(p.suffix == ".png" for p in (tmp_path / "pictures").iterdir())


def test_config_dict_and_settings_give_the_same_mesh():
    by_settings = blmesh.mesh(BOX, first_height=0.01, growth=1.3, layers=3, no_core=True)
    config = {"layers": {"first_height": 0.01, "growth": 1.3, "count": 3}}
    by_config = blmesh.mesh(BOX, config=config, no_core=True)
    assert by_settings.report["cells"] == by_config.report["cells"]
    assert np.array_equal(by_settings.points, by_config.points)
    assert "bl_top" in by_settings.boundary.patch_names


def test_settings_override_a_toml_config(tmp_path):
    path = tmp_path / "c.toml"
    path.write_text("[layers]\nfirst_height = 0.01\ngrowth = 1.3\ncount = 3\ntransition = false\n")
    m = blmesh.mesh(BOX, config=path, layers=2, no_core=True)
    assert m.report["layers"]["layers_max"] == 2


def cli(*args):
    exe = ROOT / "target" / "release" / "blmesh"
    if not exe.exists():
        pytest.skip("no target/release/blmesh to compare messages with")
    return subprocess.run([str(exe), *map(str, args)], capture_output=True, text=True)


def test_bad_surface_raises_the_command_lines_message(tmp_path):
    bad = tmp_path / "open.obj"
    bad.write_text("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n")
    with pytest.raises(blmesh.InputError) as e:
        blmesh.mesh(bad)
    assert "invalid surface" in str(e.value)
    out = cli("mesh", bad, "-o", tmp_path / "x.vtu")
    assert out.returncode == 1 and out.stderr.strip() == f"error: {e.value}"


def test_missing_file_and_unknown_format_are_input_errors(tmp_path, box_mesh):
    with pytest.raises(blmesh.InputError, match="cannot read"):
        blmesh.mesh(tmp_path / "nothing.stl")
    with pytest.raises(blmesh.InputError, match="unknown output format"):
        box_mesh.write(tmp_path / "box.xyz")
    with pytest.raises(blmesh.InputError, match="cannot read"):
        blmesh.check(tmp_path / "nothing.vtu")
    assert issubclass(blmesh.InputError, ValueError) and issubclass(blmesh.InputError, blmesh.BlmeshError)


def test_bad_parameter_message_is_the_command_lines(tmp_path):
    with pytest.raises(blmesh.InputError) as e:
        blmesh.mesh(BOX, first_height=-1.0)
    assert "first_height" in str(e.value) and "positive" in str(e.value)
    out = cli("mesh", BOX, "-o", tmp_path / "x.vtu", "--first-height", "-1")
    assert out.returncode == 1 and out.stderr.strip() == f"error: {e.value}"


def test_unknown_setting_lists_the_valid_ones():
    with pytest.raises(blmesh.InputError) as e:
        blmesh.mesh(BOX, layer=10)
    message = str(e.value)
    assert "unknown field `layer`" in message
    for valid in ["first_height", "growth", "layers", "thickness", "no_core"]:
        assert valid in message
    with pytest.raises(blmesh.InputError, match="not both"):
        blmesh.mesh(BOX, layers=3, thickness=0.1)
    with pytest.raises(blmesh.InputError, match="unknown field `layer`"):
        blmesh.mesh(BOX, config={"layer": {"count": 3}})


def test_progress_reaches_every_stage():
    seen = []
    blmesh.mesh(BOX, first_height=0.01, layers=3, no_core=True, progress=lambda s, f: seen.append((s, f)))
    stages = [s for s, _ in seen]
    for stage in ["validate", "features", "normals", "layers", "check"]:
        assert (stage, 1.0) in seen, stages
    assert all(0.0 <= f <= 1.0 for _, f in seen)


def test_a_failing_progress_callback_raises_after_the_run():
    def fail(stage, fraction):
        raise KeyError("stop")

    with pytest.raises(KeyError):
        blmesh.mesh(BOX, first_height=0.01, layers=3, no_core=True, progress=fail)
    blmesh.mesh(BOX, first_height=0.01, layers=3, no_core=True, progress=True)


def test_info_describes_a_surface():
    info = blmesh.info(BOX)
    assert info["triangles"] > 0 and [p["name"] for p in info["patches"]][:2] == ["xmin", "xmax"]
    assert info["validation"] == "valid" or "valid" in json.dumps(info["validation"]).lower()


def test_to_meshio_round_trips_through_a_file(box_mesh, tmp_path):
    meshio = pytest.importorskip("meshio")
    m = box_mesh.to_meshio()
    assert {c.type for c in m.cells} == {"tetra", "pyramid", "wedge", "hexahedron"}
    path = tmp_path / "meshio.vtu"
    meshio.write(path, m)
    report = blmesh.check(path)
    assert report["validity"]["invalid_cells"] == 0, report["validity"]


def test_to_pyvista_cells_are_positive_and_fill_the_domain(box_mesh):
    pytest.importorskip("pyvista")
    grid = box_mesh.to_pyvista()
    assert grid.n_cells == sum(len(n) for n in box_mesh.cells.values())
    volumes = grid.compute_cell_sizes(length=False, area=False)["Volume"]
    assert volumes.min() > 0
    assert volumes.sum() == pytest.approx(box_mesh.report["check"]["volume"]["cells"], rel=1e-9)
    assert len(grid.cell_data["zone"]) == grid.n_cells


def test_other_threads_run_while_meshing():
    """The GIL is released while meshing: a ticking thread is never held up for long."""
    import threading
    import time

    ticks, stop = [time.perf_counter()], threading.Event()

    def tick():
        while not stop.is_set():
            ticks.append(time.perf_counter())
            time.sleep(0.001)

    thread = threading.Thread(target=tick)
    thread.start()
    start = time.perf_counter()
    try:
        blmesh.mesh(BOX, layers=5)
    finally:
        stop.set()
        thread.join()
    took = time.perf_counter() - start
    assert max(b - a for a, b in zip(ticks, ticks[1:])) < max(0.25, took / 4), took
