"""python3 -m tailor.tiles: tiles mapped as Dask tasks equal the single-process chunked map byte for
byte, whatever the worker count; re-runs keep unchanged tiles; errors leave nothing half-written."""
import json
import os
import pathlib
import struct
import subprocess
import sys

import numpy as np
import pytest

import tailor
from conftest import DATA, GRAVEL

tiles = pytest.importorskip("tailor.tiles")
pytest.importorskip("distributed")

HORSE = DATA / "meshes" / "horse.ply"
TEXTURE = GRAVEL
CELL = -4  # horse.ply spans 0.18 units: 23 cells of 1/16


def read_glb(path):
    """(positions (V, 3), TEXCOORD_0 (V, 2), faces (F, 3)) and the glTF JSON of a .glb."""
    data = pathlib.Path(path).read_bytes()
    (json_length,) = struct.unpack_from("<I", data, 12)
    gltf = json.loads(data[20 : 20 + json_length])
    bin_start = 20 + json_length + 8

    def accessor(index, dtype, width):
        a = gltf["accessors"][index]
        view = gltf["bufferViews"][a["bufferView"]]
        start = bin_start + view.get("byteOffset", 0) + a.get("byteOffset", 0)
        return np.frombuffer(data, dtype=dtype, count=a["count"] * width, offset=start).reshape(-1, width)

    prim = gltf["meshes"][0]["primitives"][0]
    return (
        accessor(prim["attributes"]["POSITION"], np.float32, 3),
        accessor(prim["attributes"]["TEXCOORD_0"], np.float32, 2),
        accessor(prim["indices"], np.uint32, 1).reshape(-1, 3),
        gltf,
    )


def folder_bytes(folder):
    return {str(p.relative_to(folder)): p.read_bytes() for p in sorted(pathlib.Path(folder).rglob("*")) if p.is_file()}


def run_tiles(*args, env=None):
    env = dict(os.environ, PYTHONPATH=os.pathsep.join(sys.path), **(env or {}))
    done = subprocess.run(
        [sys.executable, "-m", "tailor.tiles", *map(str, args)], capture_output=True, text=True, env=env, timeout=300
    )
    return done.returncode, done.stdout, done.stderr


def test_tiles_are_the_chunked_map_for_any_worker_count(tmp_path):
    common = [HORSE, "--chunk-cell", CELL, "--texture", TEXTURE, "--json"]
    outputs = {}
    for workers in (0, 1, 2):
        out = tmp_path / ("w%d" % workers)
        code, stdout, stderr = run_tiles(*common, "-o", out, "--workers", workers)
        assert code == 0, stderr
        summary = json.loads(stdout)
        assert summary["written"] == summary["tiles"] > 10 and summary["kept"] == 0
        outputs[workers] = folder_bytes(out)
    # Byte for byte the same folder, whatever the number of workers.
    assert outputs[1] == outputs[0] and outputs[2] == outputs[0]
    # A worker process killed after writing a tile, before reporting it: Dask runs the task again.
    marker = tmp_path / "killed"
    out = tmp_path / "killed_run"
    kill = {"TAILOR_TILES_KILL_ONCE": "0_0_0_0=%s" % marker}
    code, stdout, stderr = run_tiles(*common, "-o", out, "--workers", 2, env=kill)
    assert code == 0, stderr
    assert marker.exists() and folder_bytes(out) == outputs[0]
    out = tmp_path / "w2"
    tileset = json.loads((out / "tileset.json").read_text())
    assert tileset["asset"]["version"] == "1.1"
    nodes = []

    def walk(node, depth):
        nodes.append((depth, node))
        for child in node.get("children", []):
            assert child["geometricError"] <= node["geometricError"]
            walk(child, depth + 1)

    walk(tileset["root"], 0)
    leaves = [n for _, n in nodes if "children" not in n]
    parents = [n for _, n in nodes if "children" in n and "content" in n]
    assert len(leaves) == summary["leaves"] and len(parents) == summary["tiles"] - summary["leaves"] > 2
    assert all(n["geometricError"] == 0 for n in leaves)
    assert all(n["refine"] == "REPLACE" and n["geometricError"] > 0 for n in parents)
    assert (out / "texture.png").read_bytes() == TEXTURE.read_bytes()

    # Every face of the mesh in exactly one leaf tile, with the UVs of `tailor map --chunks on` (both
    # with their default field following: auto, from the texture).
    mesh = tailor.load(HORSE)
    with pytest.warns(UserWarning, match="does not wrap"):  # the example texture is not a tile: fine here
        whole = tailor.map(
            mesh,
            texture=TEXTURE,
            chunks="on",
            chunk_cell=CELL,
            unit_scale=1.0,
            scale=summary["texels_per_unit"],
        )
    assert whole.stats["mapping"]["texels_per_unit"] == summary["texels_per_unit"]
    reference = {}
    corners = mesh.positions[mesh.faces]
    for f in range(mesh.face_count):
        for r in range(3):
            turn = [(r + k) % 3 for k in range(3)]
            reference[corners[f, turn].tobytes()] = whole.corner_uvs[f, turn]
    seen = 0
    vertices = set()  # (position, uv) of every leaf vertex
    for child in leaves:
        positions, uvs, faces, gltf = read_glb(out / child["content"]["uri"])
        assert gltf["images"] == [{"uri": "../texture.png"}]
        assert gltf["samplers"][0]["wrapS"] == 10497
        # The box holds the tile (glTF Y up -> tileset Z up: x, -z, y).
        box = np.array(child["boundingVolume"]["box"])
        turned = np.stack([positions[:, 0], -positions[:, 2], positions[:, 1]], axis=1)
        half = np.array([box[3], box[7], box[11]])
        assert np.all(np.abs(turned - box[:3]) <= half * (1 + 1e-6) + 1e-9)
        for f in range(faces.shape[0]):
            expected = reference.pop(positions[faces[f]].tobytes())
            got = uvs[faces[f]] * np.array([1, -1], dtype=np.float32)
            assert np.array_equal(got, expected), (child["content"]["uri"], f)
        seen += faces.shape[0]
        vertices |= {positions[v].tobytes() + uvs[v].tobytes() for v in range(positions.shape[0])}
    assert seen == mesh.face_count
    # Parents: fewer faces than their children, every vertex one of the leaves' with its UV bit for bit.
    for parent in parents:
        positions, uvs, faces, _ = read_glb(out / parent["content"]["uri"])
        below = sum(read_glb(out / c["content"]["uri"])[2].shape[0] for c in parent["children"])
        assert 0 < faces.shape[0] < below
        assert all(positions[v].tobytes() + uvs[v].tobytes() in vertices for v in range(positions.shape[0]))


def write_ply(path, positions, faces):
    header = (
        "ply\nformat binary_little_endian 1.0\nelement vertex %d\nproperty float x\nproperty float y\n"
        "property float z\nelement face %d\nproperty list uchar int vertex_indices\nend_header\n"
        % (positions.shape[0], faces.shape[0])
    )
    rows = np.zeros(faces.shape[0], dtype=[("n", "u1"), ("v", "<i4", 3)])
    rows["n"] = 3
    rows["v"] = faces
    with open(path, "wb") as f:
        f.write(header.encode())
        f.write(positions.astype("<f4").tobytes())
        f.write(rows.tobytes())


def test_a_rerun_rewrites_only_the_tiles_that_changed(tmp_path):
    out = tmp_path / "tiles"
    args = ["--chunk-cell", CELL, "--texture-size", 256, "--texels-per-unit", 2048, "--workers", 0, "--json"]
    code, stdout, stderr = run_tiles(HORSE, "-o", out, *args)
    assert code == 0, stderr
    first = json.loads(stdout)
    before = {p.name: (p.stat().st_mtime_ns, p.read_bytes()) for p in (out / "tiles").iterdir()}

    # The same surface in another face and vertex order: nothing is written.
    mesh = tailor.load(HORSE)
    rng = np.random.default_rng(3)
    perm = rng.permutation(mesh.vertex_count)
    inverse = np.empty_like(perm)
    inverse[perm] = np.arange(perm.shape[0])
    faces = inverse[mesh.faces][rng.permutation(mesh.face_count)]
    shuffled = tmp_path / "shuffled.ply"
    write_ply(shuffled, mesh.positions[perm], faces)
    code, stdout, stderr = run_tiles(shuffled, "-o", out, *args, "--workers", 1)
    assert code == 0, stderr
    assert json.loads(stdout)["written"] == 0
    assert {p.name: (p.stat().st_mtime_ns, p.read_bytes()) for p in (out / "tiles").iterdir()} == before

    # A ball of faces removed around one vertex: only the tiles it touches are written again.
    centre = mesh.positions[mesh.faces[0, 0]]
    centroids = mesh.positions[mesh.faces].mean(axis=1)
    keep = np.linalg.norm(centroids - centre, axis=1) > 0.02
    edited = tmp_path / "edited.ply"
    write_ply(edited, mesh.positions, mesh.faces[keep])
    code, stdout, stderr = run_tiles(edited, "-o", out, *args)
    assert code == 0, stderr
    summary = json.loads(stdout)
    assert 0 < summary["written"] < first["tiles"] // 2
    assert summary["kept"] + summary["written"] == summary["tiles"]
    after = {p.name: (p.stat().st_mtime_ns, p.read_bytes()) for p in (out / "tiles").iterdir()}
    changed = {name for name in after if after[name] != before.get(name)}
    assert len(changed) == summary["written"]
    # The kept tiles and the rewritten ones are what a fresh run writes.
    fresh = tmp_path / "fresh"
    code, _, stderr = run_tiles(edited, "-o", fresh, *args)
    assert code == 0, stderr
    assert folder_bytes(fresh) == folder_bytes(out)


def test_errors_are_one_line_and_leave_the_output_as_it_was(tmp_path):
    out = tmp_path / "tiles"
    code, _, stderr = run_tiles(tmp_path / "missing.ply", "-o", out, "--workers", 0)
    assert code == 1 and stderr.count("\n") == 1 and stderr.startswith("tailor.tiles: error: ")
    assert not out.exists() and list(tmp_path.iterdir()) == []
    code, _, stderr = run_tiles(HORSE, "-o", out, "--workers", 0, "--chunk-cell", CELL, "--tile-size", 0.3)
    assert code == 1 and "--tile-size must be the chunk cell" in stderr
    assert list(tmp_path.iterdir()) == []
    # A tile of 2x2x2 cells; then a bad texture: the folder written before stays as it was.
    code, stdout, stderr = run_tiles(HORSE, "-o", out, "--workers", 0, "--chunk-cell", CELL, "--tile-size", 0.125)
    assert code == 0, stderr
    assert "tailor.tiles: " in stdout
    code, _, stderr = run_tiles(HORSE, "-o", out, "--workers", 0, "--chunk-cell", CELL, "--tile-size", 0.125, "--no-lod")
    assert code == 0, stderr
    root = json.loads((out / "tileset.json").read_text())["root"]
    assert root["refine"] == "ADD" and all("children" not in c for c in root["children"])
    assert not (out / "lod").exists()
    good = folder_bytes(out)
    bad = tmp_path / "bad.png"
    bad.write_bytes(b"not an image")
    code, _, stderr = run_tiles(HORSE, "-o", out, "--workers", 0, "--texture", bad)
    assert code == 1 and "not a PNG or JPEG" in stderr and stderr.count("\n") == 1
    assert folder_bytes(out) == good
    assert sorted(p.name for p in tmp_path.iterdir()) == ["bad.png", "tiles"]
    # A folder of something else is not replaced.
    other = tmp_path / "other"
    other.mkdir()
    (other / "keep.txt").write_text("mine")
    code, _, stderr = run_tiles(HORSE, "-o", other, "--workers", 0)
    assert code == 1 and "not a folder of tiles" in stderr
    assert (other / "keep.txt").read_text() == "mine"


@pytest.mark.filterwarnings("ignore:make_current is deprecated:DeprecationWarning")  # Debian's tornado and Dask
def test_a_running_scheduler_gives_the_same_tiles(tmp_path):
    from distributed import LocalCluster

    common = [HORSE, "--chunk-cell", CELL, "--texture-size", 128, "--json"]
    code, _, stderr = run_tiles(*common, "-o", tmp_path / "here", "--workers", 0)
    assert code == 0, stderr
    with LocalCluster(n_workers=1, threads_per_worker=1, processes=True, dashboard_address=None) as cluster:
        code, stdout, stderr = run_tiles(*common, "-o", tmp_path / "there", "--scheduler", cluster.scheduler_address)
    assert code == 0, stderr
    assert json.loads(stdout)["workers"] is None
    assert folder_bytes(tmp_path / "there") == folder_bytes(tmp_path / "here")
