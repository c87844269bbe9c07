"""The Python package tested like the CLI: the same numbers as `lambert solve` and
`lambert viewfactors`, array scenes equal to TOML scenes, file round trips in the CLI's
formats, and clear exceptions for bad input."""

import csv
import os
import shutil
import subprocess
import warnings
from pathlib import Path

import numpy as np
import pytest

import lambert

ROOT = Path(__file__).resolve().parents[2]
FURNACE = ROOT / "cases" / "cube_furnace" / "scene.toml"


def cli() -> str:
    """The CLI binary: $LAMBERT_BIN, else the workspace's release or debug build."""
    for c in (os.environ.get("LAMBERT_BIN"), ROOT / "target/release/lambert", ROOT / "target/debug/lambert"):
        if c and Path(c).is_file():
            return str(c)
    if os.environ.get("CI"):
        pytest.fail("no lambert binary: build it (cargo build) or set LAMBERT_BIN")
    pytest.skip("no lambert binary built")


def run_cli(*args: str) -> subprocess.CompletedProcess:
    return subprocess.run([cli(), *args, "--quiet"], capture_output=True, text=True, check=True)


def read_rows(path):
    with open(path, newline="") as f:
        return list(csv.DictReader(f))


# The unit-cube furnace's six faces (inward normals), as in cases/cube_furnace/scene.toml.
FACES = {
    "floor": ((0, 0, 0), (1, 0, 0), (0, 1, 0)),
    "ceiling": ((0, 0, 1), (0, 1, 0), (1, 0, 0)),
    "wall_y0": ((0, 0, 0), (0, 0, 1), (1, 0, 0)),
    "wall_y1": ((0, 1, 0), (1, 0, 0), (0, 0, 1)),
    "wall_x0": ((0, 0, 0), (0, 1, 0), (0, 0, 1)),
    "wall_x1": ((1, 0, 0), (0, 0, 1), (0, 1, 0)),
}


def furnace_arrays(n=4):
    """Vertices, quads and surface ids of the furnace with n × n patches per face."""
    verts, faces, ids = [], [], []
    for name, (o, u, v) in FACES.items():
        o, u, v = map(np.array, (o, u, v))
        base = len(verts)
        for b in range(n + 1):
            for a in range(n + 1):
                verts.append(o + u * a / n + v * b / n)
        for b in range(n):
            for a in range(n):
                k = base + b * (n + 1) + a
                faces.append([k, k + 1, k + n + 2, k + n + 1])
                ids.append(name)
    return np.array(verts, dtype=float), np.array(faces), np.array(ids)


def furnace_from_arrays():
    v, f, ids = furnace_arrays()
    walls = {w: 0.0 for w in FACES if w.startswith("wall")}
    return lambert.Scene.from_arrays(
        v,
        f,
        ids,
        emissivity={"floor": 0.8, "ceiling": 0.6, **{w: 0.5 for w in walls}},
        temperature={"floor": 1000.0, "ceiling": 400.0},
        heat_flux=walls,
    )


def test_furnace_heat_rates_equal_the_cli_to_the_last_digit(tmp_path):
    scene = lambert.Scene.load(FURNACE)
    result = scene.solve()
    out = tmp_path / "cli.csv"
    run_cli("solve", str(FURNACE), "-o", str(out))
    rows = read_rows(out)
    assert [r["surface"] for r in rows] == result.surface.names
    for r, q in zip(rows, result.surface.heat_rate):
        assert float(r["heat_rate"]) == q
    saved = tmp_path / "py.csv"
    result.save(saved)
    assert saved.read_bytes() == out.read_bytes()
    assert abs(result.heat_balance()) < 1e-6 * np.abs(result.surface.heat_rate).max()


def test_view_factors_equal_the_cli_file(tmp_path):
    scene = lambert.Scene.load(FURNACE)
    for patches in (False, True):
        vf = scene.view_factors(patches=patches)
        out = tmp_path / "cli.csv"
        args = ["viewfactors", str(FURNACE), "-o", str(out)] + (["--patches"] if patches else [])
        run_cli(*args)
        saved = tmp_path / "py.csv"
        vf.save(saved)
        assert saved.read_bytes() == out.read_bytes(), f"patches={patches}"


def test_from_arrays_matches_the_toml_scene():
    toml = lambert.Scene.load(FURNACE)
    arr = furnace_from_arrays()
    assert arr.surface_names == toml.surface_names
    np.testing.assert_allclose(arr.surface_areas, toml.surface_areas, rtol=1e-15)
    np.testing.assert_array_equal(arr.emissivity, toml.emissivity)
    a, t = arr.solve(), toml.solve()
    # The same patches in another order: equal up to summation round-off.
    np.testing.assert_allclose(a.surface.heat_rate, t.surface.heat_rate, rtol=1e-9)
    fa, ft = arr.view_factors().dense(), toml.view_factors().dense()
    np.testing.assert_allclose(fa, ft, atol=1e-12)


def test_sparse_matrix_holds_reciprocity_and_closure():
    scene = lambert.Scene.load(FURNACE)
    for patches in (False, True):
        vf = scene.view_factors(patches=patches)
        f = vf.matrix
        assert f.format == "csr" and f.shape == (len(vf.names), len(vf.names))
        af = vf.areas[:, None] * f.toarray()
        np.testing.assert_allclose(af, af.T, atol=1e-9 * vf.areas.max())
        np.testing.assert_allclose(f.sum(axis=1), 1.0, atol=1e-8)
        np.testing.assert_allclose(vf.row_sums, f.sum(axis=1), rtol=1e-14)
        assert vf.std_error.shape == f.shape and (vf.std_error.data >= 0).all()
        assert vf.method_names(int(vf.method.data[0])) in {"analytic", "analytic-shadowed", "hemicube"} or "+" in vf.method_names(int(vf.method.data[0]))


def test_saved_view_factors_feed_the_cli_and_the_binding(tmp_path):
    scene = lambert.Scene.load(FURNACE)
    vf = scene.view_factors(patches=True)
    path = tmp_path / "vf.csv"
    vf.save(path)
    back = scene.read_view_factors(path)
    np.testing.assert_array_equal(back.matrix.toarray(), vf.matrix.toarray())
    py = scene.solve(view_factors=back)
    out = tmp_path / "cli.csv"
    run_cli("solve", str(FURNACE), "--viewfactors", str(path), "-o", str(out))
    for r, q in zip(read_rows(out), py.surface.heat_rate):
        assert float(r["heat_rate"]) == q


def test_view_factors_of_another_scene_are_refused(tmp_path):
    scene = lambert.Scene.load(FURNACE)
    path = tmp_path / "vf.csv"
    scene.view_factors().save(path)
    v, f, ids = furnace_arrays()
    other = lambert.Scene.from_arrays(v * 2.0, f, ids, emissivity=0.5, heat_flux=0.0)
    with pytest.raises(lambert.InputError, match="vf.csv"):
        other.read_view_factors(path)


def test_one_and_two_threads_give_the_same_numbers():
    scene = lambert.Scene.load(FURNACE)
    one = scene.solve(threads=1)
    two = scene.solve(threads=2)
    np.testing.assert_array_equal(one.patch.heat_rate, two.patch.heat_rate)
    v1 = scene.view_factors(method="mc-cosine", samples=2000, seed=3, threads=1, patches=True)
    v2 = scene.view_factors(method="mc-cosine", samples=2000, seed=3, threads=2, patches=True)
    np.testing.assert_array_equal(v1.matrix.toarray(), v2.matrix.toarray())
    np.testing.assert_array_equal(v1.std_error.toarray(), v2.std_error.toarray())


def test_pyvista_round_trip():
    pv = pytest.importorskip("pyvista")
    scene = furnace_from_arrays()
    result = scene.solve()
    mesh = result.to_pyvista()
    assert mesh.n_cells == len(scene.patch_names)
    np.testing.assert_array_equal(mesh.cell_data["heat_rate"], result.patch.heat_rate)
    mesh.cell_data["surface_id"] = mesh.cell_data["surface"]
    mesh.cell_data["emissivity"] = scene.emissivity[mesh.cell_data["surface"]]
    t = np.full(mesh.n_cells, np.nan)
    q = np.full(mesh.n_cells, np.nan)
    s = mesh.cell_data["surface"]
    t[s == 0], t[s == 1] = 1000.0, 400.0
    q[s >= 2] = 0.0
    mesh.cell_data["temperature"], mesh.cell_data["heat_flux"] = t, q
    back = lambert.Scene.from_pyvista(mesh)
    again = back.solve()
    np.testing.assert_allclose(again.surface.heat_rate, result.surface.heat_rate, rtol=1e-12)
    assert isinstance(mesh, pv.PolyData)


@pytest.mark.parametrize(
    "change, message",
    [
        (lambda a: {**a, "vertices": a["vertices"][:, :2]}, "vertices has shape"),
        (lambda a: {**a, "faces": a["faces"][:, :2]}, "faces has shape"),
        (lambda a: {**a, "surface_ids": a["surface_ids"][:-1]}, "surface_ids has shape"),
        (lambda a: {**a, "vertices": np.where(np.arange(len(a["vertices"]))[:, None] == 3, np.nan, a["vertices"])}, r"vertices\[3\] has a NaN"),
        (lambda a: {**a, "emissivity": -0.5}, "emissivity is -0.5"),
        (lambda a: {**a, "faces": np.where(a["faces"] == 0, 999, a["faces"])}, "refers to vertex 999"),
        (lambda a: {**a, "faces": np.where(a["faces"] == 0, -1, a["faces"])}, "refers to vertex -1"),
        (lambda a: {**a, "temperature": -10.0}, "temperature is -10"),
        (lambda a: {**a, "temperature": np.nan}, "temperature"),
        (lambda a: {**a, "heat_flux": 0.0, "temperature": 300.0}, "not both"),
        (lambda a: {**a, "emissivity": [0.5, 0.5]}, "emissivity has shape"),
    ],
)
def test_bad_arrays_raise_clear_exceptions(change, message):
    v, f, ids = furnace_arrays(1)
    args = change({"vertices": v, "faces": f, "surface_ids": ids, "emissivity": 0.5, "temperature": 300.0})
    with pytest.raises(ValueError, match=message) as e:
        lambert.Scene.from_arrays(args.pop("vertices"), args.pop("faces"), args.pop("surface_ids"), **args)
    assert isinstance(e.value, lambert.Error)


def test_a_degenerate_face_names_its_surface():
    v = np.array([[0, 0, 0], [1, 0, 0], [2, 0, 0.0]])
    with pytest.raises(lambert.InputError, match="surface 'plate': face 0: the polygon has zero area"):
        lambert.Scene.from_arrays(v, [[0, 1, 2]], ["plate"])


def test_bad_options_and_files_raise():
    scene = lambert.Scene.load(FURNACE)
    with pytest.raises(lambert.UsageError, match="unknown method 'fast'"):
        scene.view_factors(method="fast")
    with pytest.raises(lambert.UsageError, match="tolerance must be in"):
        scene.view_factors(tolerance=2.0)
    with pytest.raises(lambert.UsageError, match="unknown exchange"):
        scene.solve(exchange="sideways")
    with pytest.raises(lambert.UsageError, match="threads=0"):
        scene.solve(threads=0)
    with pytest.raises(lambert.InputError, match="nowhere.toml"):
        lambert.Scene.load("nowhere.toml")


def test_an_open_scene_warns_and_solves_with_ambient():
    v = np.array([[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0], [0, 0, 1], [1, 0, 1], [1, 1, 1], [0, 1, 1.0]])
    # Two facing unit squares 1 m apart in a 300 K environment.
    scene = lambert.Scene.from_arrays(
        v, [[0, 1, 2, 3], [4, 7, 6, 5]], ["low", "high"], temperature={"low": 500.0, "high": 300.0}, ambient=300.0
    )
    assert not scene.is_closed
    vf = scene.view_factors()
    assert vf.matrix[0, 1] == pytest.approx(0.19982489569838738, abs=1e-9)
    r = scene.solve()
    assert r.heat_balance() == pytest.approx(0.0, abs=1e-6 * abs(r.surface.heat_rate).max())
    assert r.surface.heat_rate[0] > 0 > r.surface.heat_rate[1]


def test_progress_callback_hears_the_stages_and_the_counts():
    scene = lambert.Scene.load(FURNACE)
    heard = []
    vf = scene.view_factors(patches=True, progress=heard.append)
    assert [e.phase for e in heard if e.done is None and e.stage is None] == ["view factors", "done"]
    # The library's phases, as they start: the set-up, then the rows.
    assert [e.stage for e in heard if e.done is None and e.stage] == ["bvh", "view factors"]
    counts = [e for e in heard if e.done is not None]
    assert counts, heard
    assert counts[-1].phase == "pairs" and counts[-1].done == counts[-1].total > 0
    assert all(e.stage == "view factors" for e in counts)
    assert all(a.done <= b.done for a, b in zip(counts, counts[1:]))
    # Listening changes no number.
    quiet = scene.view_factors(patches=True)
    assert (vf.matrix != quiet.matrix).nnz == 0
    heard.clear()
    r = scene.solve(progress=heard.append)
    assert [e.phase for e in heard if e.done is None and e.stage is None] == ["solve", "done"]
    stages = [e.stage for e in heard if e.done is None and e.stage]
    assert stages == ["bvh", "view factors", "enforcement", "solve"], stages
    assert np.array_equal(r.surface.heat_rate, scene.solve().surface.heat_rate)


def test_a_failing_progress_callback_raises_once_the_run_is_done():
    scene = lambert.Scene.load(FURNACE)

    def refuse(event):
        if event.done is not None:
            raise RuntimeError("stop here")

    with pytest.raises(RuntimeError, match="stop here"):
        scene.view_factors(progress=refuse)


def test_progress_true_draws_a_tqdm_bar_when_tqdm_is_installed(monkeypatch):
    import sys
    import types

    bars = []

    class FakeBar:
        def __init__(self, total, **kw):
            self.total, self.n, self.closed = total, 0, False
            bars.append(self)

        def update(self, k):
            self.n += k

        def close(self):
            self.closed = True

    fake = types.ModuleType("tqdm.auto")
    fake.tqdm = FakeBar
    monkeypatch.setitem(sys.modules, "tqdm", types.ModuleType("tqdm"))
    monkeypatch.setitem(sys.modules, "tqdm.auto", fake)
    lambert.Scene.load(FURNACE).view_factors(patches=True, progress=True)
    assert bars and bars[-1].n == bars[-1].total > 0 and all(b.closed for b in bars)


SENSORS = np.array([[0.5, 0.5, 0.5], [0.25, 0.7, 0.0], [0.3, 0.2, 0.6], [0.9, 0.1, 0.95]])
SENSOR_NORMALS = np.array([[0, 0, 1], [0, 0, 1], [1, -2, 0.5], [-1, 1, -1]], dtype=float)


@pytest.mark.parametrize("patches", [False, True])
def test_point_view_factors_equal_the_cli_to_the_last_digit(tmp_path, patches):
    scene = lambert.Scene.load(FURNACE)
    F = scene.point_view_factors(SENSORS, SENSOR_NORMALS, patches=patches)
    cols = scene.patch_names if patches else scene.surface_names
    assert F.shape == (len(SENSORS), len(cols))
    # Inside a closed furnace every row sums to 1; a sensor on the floor sees none of it.
    np.testing.assert_allclose(F.sum(axis=1), 1.0, rtol=0, atol=1e-13)
    assert F[1, [k for k, c in enumerate(cols) if c.startswith("floor")]].sum() == 0.0
    points = tmp_path / "sensors.csv"
    with open(points, "w") as f:
        f.write("name,x,y,z,nx,ny,nz\n")
        for k, (p, n) in enumerate(zip(SENSORS, SENSOR_NORMALS)):
            f.write(",".join([f"s{k}", *map(repr, p.tolist()), *map(repr, n.tolist())]) + "\n")
    out = tmp_path / "out.csv"
    run_cli("viewfactors", str(FURNACE), "--points", str(points), "-o", str(out), *(["--patches"] if patches else []))
    expected = np.zeros_like(F)
    for row in read_rows(out):
        expected[int(row["from"][1:]), cols.index(row["to"])] = float(row["factor"])
    assert np.array_equal(F, expected)


def test_point_view_factors_refuse_bad_arrays():
    scene = lambert.Scene.load(FURNACE)
    p, n = SENSORS[:1], SENSOR_NORMALS[:1]
    for points, normals, match in [
        (p[0], n[0], r"points has shape \(3,\); expected \(n, 3\)"),
        (p[:, :2], n[:, :2], r"points has shape \(1, 2\)"),
        (p, SENSOR_NORMALS[:2], r"normals has shape \(2, 3\); expected the shape of points"),
        ([[0.5, np.nan, 0.5]], n, r"point 0: y is NaN"),
        (p, [[0.0, 0.0, 0.0]], r"point 0: the normal \(0, 0, 0\) has length 0"),
        (p, [[0.0, np.inf, 1.0]], r"point 0: ny is inf"),
    ]:
        with pytest.raises(lambert.InputError, match=match):
            scene.point_view_factors(points, normals)
    with pytest.raises(ValueError):
        scene.point_view_factors([["a", "b", "c"]], n)


def test_point_view_factors_warn_for_a_point_outside_and_keep_numbers_on_any_thread_count():
    scene = lambert.Scene.load(FURNACE)
    outside = np.vstack([SENSORS, [[0.5, 0.5, -1.0]]])
    normals = np.vstack([SENSOR_NORMALS, [[0, 0, 1]]])
    with pytest.warns(lambert.LambertWarning, match=r"1 point\(s\) do not see a whole hemisphere.*point 4"):
        F = scene.point_view_factors(outside, normals, threads=1)
    assert not F[4].any()
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        assert np.array_equal(F, scene.point_view_factors(outside, normals, threads=2))
    heard = []
    scene.point_view_factors(SENSORS, SENSOR_NORMALS, progress=heard.append)
    assert heard[0] == ("point view factors", None, None, None) and heard[-1].phase == "done"
    assert any(e.phase == "point-patch pairs" and e.done == e.total == 4 * 96 for e in heard)
