"""python3 -m tailor.tiles: tiles mapped as Dask tasks equal the single-process chunked map byte for
byte, whatever the worker count; re-runs keep unchanged tiles; errors leave nothing half-written."""
import json
import mmap
import os
import pathlib
import shutil
import struct
import subprocess
import sys
import zlib

import numpy as np
import pytest

import tailor
from conftest import DATA, GRAVEL, bumpy_grid

tiles = pytest.importorskip("tailor.tiles")
pytest.importorskip("distributed")

HORSE = DATA / "meshes" / "horse.ply"
TEXTURE = GRAVEL
CELL = -4  # horse.ply spans 0.18 units: 20 cells of 1/16


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
    assert (out / "tiles" / "texture.png").read_bytes() == TEXTURE.read_bytes()

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
        assert gltf["images"] == [{"uri": "texture.png"}]  # beside it: tailor's reader takes it too
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


def test_a_parent_whose_faces_collapse_when_welded_has_no_content(tmp_path):
    # A grid, and far from it faces whose distinct vertices share one position: the leaf maps them
    # (they are distinct vertices), the parent welds its children's copies by position, and then
    # holds no face. That parent is a node without content, not an error, and a rerun keeps it.
    n = 12
    i, j = np.meshgrid(np.arange(n + 1), np.arange(n + 1), indexing="xy")
    grid = np.stack([i.ravel() / n, j.ravel() / n, 0.1 * np.sin(i.ravel() / 3.0)], axis=1)
    a = (np.arange(n)[None, :] + (n + 1) * np.arange(n)[:, None]).ravel()
    grid_faces = np.concatenate([np.stack([a, a + 1, a + n + 2], 1), np.stack([a, a + n + 2, a + n + 1], 1)])
    far = np.full((12, 3), 50.0)
    far_faces = len(grid) + np.array([[k, k + 1, k + 2] for k in range(10)])
    mesh = tmp_path / "far.ply"
    write_ply(mesh, np.concatenate([grid, far]), np.concatenate([grid_faces, far_faces]))
    out = tmp_path / "tiles"
    args = [mesh, "-o", out, "--workers", 0, "--chunk-cell", -2, "--json"]
    code, stdout, stderr = run_tiles(*args)
    assert code == 0, stderr
    summary = json.loads(stdout)
    assert summary["faces"] == len(grid_faces) + len(far_faces)
    tileset = json.loads((out / "tileset.json").read_text())
    nodes, empty, todo = [], [], [tileset["root"]]
    while todo:
        node = todo.pop()
        todo.extend(node.get("children", []))
        if "content" in node:
            nodes.append(node)
            assert (out / node["content"]["uri"]).is_file()
        elif node is not tileset["root"]:
            empty.append(node)
    # The far faces' parents (one per level above their leaf), each above a node with content.
    assert empty and all(node.get("children") for node in empty)
    code, stdout, stderr = run_tiles(*args)
    assert code == 0, stderr
    again = json.loads(stdout)
    assert again["written"] == 0 and again["kept"] == again["tiles"] == summary["tiles"]


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

    # A tile cut short and another node's level-of-detail file replaced: those two nodes are
    # written again, as they were.
    damaged = sorted((out / "tiles").iterdir())[0]
    damaged.write_bytes(damaged.read_bytes()[:100])
    coarse = next(p for p in sorted((out / "lod").iterdir()) if p.stem != damaged.stem)
    coarse_bytes = coarse.read_bytes()
    coarse.write_bytes(b"junk")
    code, stdout, stderr = run_tiles(shuffled, "-o", out, *args)
    assert code == 0, stderr
    assert json.loads(stdout)["written"] == 2
    assert {p.name: p.read_bytes() for p in (out / "tiles").iterdir()} == {n: b for n, (_, b) in before.items()}
    assert coarse.read_bytes() == coarse_bytes
    before = {p.name: (p.stat().st_mtime_ns, p.read_bytes()) for p in (out / "tiles").iterdir()}

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
    # Not a power of two: refused with the options, before any work; one under the cell, once the
    # cell is known.
    code, _, stderr = run_tiles(HORSE, "-o", out, "--workers", 0, "--chunk-cell", CELL, "--tile-size", 0.3)
    assert code == 2 and "--tile-size must be the chunk cell times a power of two (a power of two), got 0.3" in stderr
    code, _, stderr = run_tiles(HORSE, "-o", out, "--workers", 0, "--chunk-cell", CELL, "--tile-size", 2.0**(CELL - 1))
    assert code == 1 and "--tile-size must be the chunk cell (0.0625) times a power of two, got 0.03125" in stderr
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
    assert code == 1 and "bad.png: not a readable PNG, JPEG" in stderr and stderr.count("\n") == 1
    assert folder_bytes(out) == good
    assert sorted(p.name for p in tmp_path.iterdir()) == ["bad.png", "tiles"]
    # A folder of something else is not replaced.
    other = tmp_path / "other"
    other.mkdir()
    (other / "keep.txt").write_text("mine")
    code, _, stderr = run_tiles(HORSE, "-o", other, "--workers", 0)
    assert code == 1 and "not a folder of tiles" in stderr
    assert (other / "keep.txt").read_text() == "mine"
    # OUTDIR a file, or in a folder that does not exist: one line naming it, nothing written.
    for given, message in ((other / "keep.txt", "exists and is not a folder"), (other / "no" / "t", "does not exist")):
        code, _, stderr = run_tiles(HORSE, "-o", given, "--workers", 0)
        assert code == 1 and stderr.count("\n") == 1 and str(given) in stderr and message in stderr, stderr
    assert sorted(p.name for p in other.iterdir()) == ["keep.txt"]


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


def write_png(path, pixels):
    """An 8-bit PNG of a (H, W) or (H, W, 3) uint8 array."""
    pixels = np.ascontiguousarray(pixels, np.uint8)
    height, width = pixels.shape[:2]
    raw = b"".join(b"\0" + pixels[y].tobytes() for y in range(height))

    def chunk(kind, body):
        return struct.pack(">I", len(body)) + kind + body + struct.pack(">I", zlib.crc32(kind + body))

    header = struct.pack(">IIBBBBB", width, height, 8, {2: 0, 3: 2}[pixels.ndim], 0, 0, 0)
    body = chunk(b"IHDR", header) + chunk(b"IDAT", zlib.compress(raw)) + chunk(b"IEND", b"")
    path.write_bytes(b"\x89PNG\r\n\x1a\n" + body)


def content_nodes(tileset):
    """Every tile of a tileset that has content."""
    out, todo = [], [tileset["root"]]
    while todo:
        node = todo.pop()
        todo.extend(node.get("children", []))
        if "content" in node:
            out.append(node)
    return out


def test_a_material_is_named_by_every_tile_and_written_once(tmp_path):
    # The brick photo as colour, with a normal map, roughness and occlusion derived from one height
    # field, named by a material description as `tailor tile --set` writes one (files relative to
    # the JSON's folder, roles from "role", "normal" or the names).
    colour = DATA / "textures" / "brick-gray-512.png"
    folder = tmp_path / "brick"
    folder.mkdir()
    y, x = np.mgrid[0:512, 0:512] / 512.0 * 2 * np.pi
    height = np.sin(8 * x) * np.cos(4 * y)
    n = np.stack([-np.gradient(height, axis=1) * 30, np.gradient(height, axis=0) * 30, np.ones_like(height)], -1)
    n /= np.linalg.norm(n, axis=-1, keepdims=True)
    write_png(folder / "bricks_normal.png", np.round((n * 0.5 + 0.5) * 255))
    write_png(folder / "bricks_roughness.png", np.round(127 + 100 * height))
    write_png(folder / "bricks_ao.png", np.round(200 + 50 * height))
    material = folder / "material.json"
    material.write_text(
        json.dumps(
            {
                "maps": [
                    {"file": str(colour), "role": "color"},
                    {"file": "bricks_normal.png", "normal": True},
                    {"file": "bricks_roughness.png"},
                    {"file": "bricks_ao.png"},
                ]
            }
        )
    )
    common = [HORSE, "--chunk-cell", CELL, "--workers", 0, "--json"]
    out = tmp_path / "tiles"
    code, stdout, stderr = run_tiles(*common, "-o", out, "--material", material)
    assert code == 0, stderr
    summary = json.loads(stdout)
    # The maps once in tiles/: the colour map as it is, the normal map and the packed occlusion /
    # roughness / metallic image as `tailor map --material` embeds them.
    loaded = tailor.load_material(material)
    assert (out / "tiles" / "material_color.png").read_bytes() == colour.read_bytes()
    assert (out / "tiles" / "material_normal.png").read_bytes() == loaded["normal_png"]
    assert (out / "tiles" / "material_orm.png").read_bytes() == loaded["orm_png"]
    expected = {"material_color.png", "material_normal.png", "material_orm.png"}
    nodes = content_nodes(json.loads((out / "tileset.json").read_text()))
    assert len(nodes) == summary["tiles"] > summary["leaves"]
    for node in nodes:
        positions, uvs, faces, gltf = read_glb(out / node["content"]["uri"])
        assert {image["uri"] for image in gltf["images"]} == expected and len(gltf["images"]) == 3
        assert all("bufferView" not in image for image in gltf["images"])
        uri = lambda ref: gltf["images"][gltf["textures"][ref["index"]]["source"]]["uri"]  # noqa: E731
        m = gltf["materials"][0]
        pbr = m["pbrMetallicRoughness"]
        assert uri(pbr["baseColorTexture"]) == "material_color.png"
        assert uri(m["normalTexture"]) == "material_normal.png"
        assert uri(pbr["metallicRoughnessTexture"]) == uri(m["occlusionTexture"]) == "material_orm.png"
        assert "TANGENT" in gltf["meshes"][0]["primitives"][0]["attributes"]
        # The BIN chunk holds the geometry only.
        assert gltf["buffers"][0]["byteLength"] == sum(v["byteLength"] for v in gltf["bufferViews"])
    # The first map's size sets the repeat, as --texture does with that map: the same UVs.
    code, _, stderr = run_tiles(*common, "-o", tmp_path / "texture", "--texture", colour)
    assert code == 0, stderr
    for node in nodes:
        with_material = read_glb(out / node["content"]["uri"])
        with_texture = read_glb(tmp_path / "texture" / node["content"]["uri"])
        for a, b in zip(with_material[:3], with_texture[:3]):
            assert np.array_equal(a, b)
    # --texture and --material together: one line, bad usage, nothing written.
    code, _, stderr = run_tiles(*common, "-o", tmp_path / "both", "--material", material, "--texture", colour)
    assert code == 2 and stderr.count("\n") == 1 and "give --texture or --material, not both" in stderr
    assert not (tmp_path / "both").exists()
    code, _, stderr = run_tiles(*common, "-o", tmp_path / "both", "--scale", 5, "--texels-per-unit", 5)
    assert code == 2 and stderr.count("\n") == 1 and "give --scale or --texels-per-unit, not both" in stderr
    assert not (tmp_path / "both").exists()
    code, _, stderr = run_tiles(*common, "-o", tmp_path / "bad", "--material", tmp_path / "missing.json")
    assert code == 1 and stderr.count("\n") == 1 and stderr.startswith("tailor.tiles: error: ")
    assert not (tmp_path / "bad").exists()


def node_transform(gltf):
    """The 4x4 matrix of the glTF scene's one node (TRS or matrix; the .glb writer's one node)."""
    (node,) = gltf["nodes"]
    if "matrix" in node:
        return np.array(node["matrix"], dtype=np.float64).reshape(4, 4).T  # column-major
    x, y, z, w = node.get("rotation", [0, 0, 0, 1])
    r = np.array(
        [
            [1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)],
            [2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)],
            [2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)],
        ]
    )
    m = np.eye(4)
    m[:3, :3] = r * np.array(node.get("scale", [1, 1, 1]))[None, :]
    m[:3, 3] = node.get("translation", [0, 0, 0])
    return m


# 3D Tiles 1.1, "y-up to z-up": a client turns glTF content Z up by this matrix, after the glTF
# node's transform and before the tile's.
Y_UP_TO_Z_UP = np.array([[1, 0, 0, 0], [0, 0, -1, 0], [0, 1, 0, 0], [0, 0, 0, 1]], dtype=np.float64)


@pytest.mark.parametrize("up", ["y", "z"])
def test_bounding_boxes_hold_the_content_as_a_client_places_it(tmp_path, up):
    out = tmp_path / "tiles"
    args = ["--chunk-cell", CELL, "--texture-size", 128, "--workers", 0, "--up", up]
    code, _, stderr = run_tiles(HORSE, "-o", out, *args)
    assert code == 0, stderr
    tileset = json.loads((out / "tileset.json").read_text())
    assert "transform" not in tileset["root"]
    mesh = tailor.load(HORSE)
    nodes = content_nodes(tileset)
    assert len(nodes) > 10
    for node in nodes:
        positions, _, _, gltf = read_glb(out / node["content"]["uri"])
        m = Y_UP_TO_Z_UP @ node_transform(gltf)
        placed = positions.astype(np.float64) @ m[:3, :3].T + m[:3, 3]
        if up == "z":  # the node and the client's turn cancel: the tileset's frame is the mesh's own
            assert np.allclose(placed, positions, atol=1e-7)
        else:
            assert np.array_equal(placed, positions[:, [0, 2, 1]] * np.array([1, -1, 1]))
        box = np.array(node["boundingVolume"]["box"], dtype=np.float64)
        centre, axes = box[:3], box[3:].reshape(3, 3)
        # In the box's own frame: every point inside, and the content reaches each face (a tight box).
        local = (placed - centre) @ axes.T / np.sum(axes * axes, axis=1)
        assert np.all(np.abs(local) <= 1 + 1e-5), node["content"]["uri"]
        assert np.allclose(np.abs(local).max(axis=0), 1, atol=1e-4), node["content"]["uri"]
    # Each child's box inside its parent's (the corners of one in the other's frame).
    def local_of(box, points):
        box = np.array(box["boundingVolume"]["box"], dtype=np.float64)
        axes = box[3:].reshape(3, 3)
        return (points - box[:3]) @ axes.T / np.sum(axes * axes, axis=1)

    todo = [tileset["root"]]
    while todo:
        parent = todo.pop()
        for child in parent.get("children", []):
            box = np.array(child["boundingVolume"]["box"], dtype=np.float64)
            signs = np.array([[a, b, c] for a in (-1, 1) for b in (-1, 1) for c in (-1, 1)], dtype=np.float64)
            corners = box[:3] + signs @ box[3:].reshape(3, 3)
            assert np.all(np.abs(local_of(parent, corners)) <= 1 + 1e-5)
            todo.append(child)
    # The root's box around the whole mesh: its own coordinates with --up z, turned with --up y.
    root = np.array(tileset["root"]["boundingVolume"]["box"])
    lo, hi = mesh.positions.min(axis=0).astype(np.float64), mesh.positions.max(axis=0).astype(np.float64)
    centre = (lo + hi) / 2
    expected = centre if up == "z" else np.array([centre[0], -centre[2], centre[1]])
    assert np.allclose(root[:3], expected, atol=1e-7)
    # --up x: one line, bad usage.
    code, _, stderr = run_tiles(HORSE, "-o", tmp_path / "x", "--workers", 0, "--up", "x")
    assert code == 2 and stderr == "tailor.tiles: error: --up must be y or z, got 'x'\n"
    # Densities and sizes that are not positive numbers: one line each, bad usage, nothing written.
    for option, value, said in (
        ("--tile-size", 0, "--tile-size must be a positive number"),
        ("--tile-size", "nan", "--tile-size must be a positive number"),
        ("--scale", 0, "--scale must be between 0.001 and 1e7 pixels per unit, got 0"),  # as tailor map says
        ("--texels-per-unit", -1, "--texels-per-unit must be a positive number"),
    ):
        code, _, stderr = run_tiles(HORSE, "-o", tmp_path / "bad", "--workers", 0, option, value)
        assert code == 2 and stderr.count("\n") == 1, stderr
        assert stderr.startswith("tailor.tiles: error: " + said), stderr
        assert not (tmp_path / "bad").exists()
    # A worker count no machine runs as local processes: refused before any starts.
    code, _, stderr = run_tiles(HORSE, "-o", tmp_path / "bad", "--workers", 1000000)
    assert code == 2 and stderr.count("\n") == 1 and "--workers must be in 0.." in stderr, stderr
    assert not (tmp_path / "bad").exists()
    # What argparse itself rejects is one line too, without argparse's usage block.
    for args in (("--workers", "abc"), ("--threads",)):
        code, _, stderr = run_tiles(HORSE, "-o", tmp_path / "bad", *args)
        assert code == 2 and stderr.count("\n") == 1 and stderr.startswith("tailor.tiles: error: argument "), stderr
        assert stderr.endswith("(run python3 -m tailor.tiles --help)\n"), stderr


# === The streamed input: a binary little-endian PLY partitioned without loading it whole ===


def write_layout_ply(path, vertices, faces, *, vertex_props, face_props, counts=None, header_faces=None, cut=0):
    """A binary little-endian PLY: vertices and faces as numpy structured arrays of the given
    fields ((name, PLY type, numpy type) each; the face list is ("vertex_indices", count type,
    index type) with numpy types). counts: per-face list lengths (default 3)."""
    lines = ["ply", "format binary_little_endian 1.0", "element vertex %d" % len(vertices)]
    lines += ["property %s %s" % (t, n) for n, t, _ in vertex_props]
    lines.append("element face %d" % (len(faces) if header_faces is None else header_faces))
    body = b""
    for n, t, _ in face_props:
        lines.append("property list %s %s %s" % (t[0], t[1], n) if isinstance(t, tuple) else "property %s %s" % (t, n))
    vdt = np.dtype([(n, d) for n, _, d in vertex_props])
    v = np.zeros(len(vertices), dtype=vdt)
    for k, axis in enumerate("xyz"):
        v[axis] = vertices[:, k]
    body += v.tobytes()
    out = bytearray()
    for f_index, face in enumerate(faces):
        for n, t, d in face_props:
            if isinstance(t, tuple):
                count = 3 if counts is None else counts[f_index]
                out += np.array([count], dtype=d[0]).tobytes()
                out += np.array(list(face) + [face[0]] * (count - 3), dtype=d[1])[:count].tobytes()
            else:
                out += np.array([7], dtype=d).tobytes()
    body += bytes(out)
    data = ("\n".join(lines) + "\nend_header\n").encode() + body
    path.write_bytes(data[: len(data) - cut])
    return path


def horse_arrays():
    mesh = tailor.load(str(HORSE))
    return mesh.positions.astype(np.float64), mesh.faces.astype(np.int64)


def canonical_tile_in_numpy(positions, faces):
    """What tailor.canonical_tile is documented to do, written out in numpy."""
    faces = np.asarray(faces, dtype=np.int64)
    c = positions[faces]

    def less(a, b):
        return (a[:, 0] < b[:, 0]) | (
            (a[:, 0] == b[:, 0]) & ((a[:, 1] < b[:, 1]) | ((a[:, 1] == b[:, 1]) & (a[:, 2] < b[:, 2])))
        )

    first = np.zeros(faces.shape[0], dtype=np.int64)
    first[less(c[:, 1], c[:, 0])] = 1
    smallest = np.take_along_axis(c, first[:, None, None], axis=1)[:, 0]
    first[less(c[:, 2], smallest)] = 2
    faces = np.take_along_axis(faces, (first[:, None] + np.arange(3)[None, :]) % 3, axis=1)
    words = np.ascontiguousarray(positions[faces].reshape(-1, 9)).view(np.uint32).astype(np.uint64)
    h = np.full(faces.shape[0], 0xCBF29CE484222325, dtype=np.uint64)
    for k in range(9):
        h = (h ^ words[:, k]) * np.uint64(0x100000001B3)
    faces = faces[np.argsort(h, kind="stable")]
    _, first_use = np.unique(faces.ravel(), return_index=True)
    by_use = np.unique(faces.ravel())[np.argsort(first_use)]
    new_id = np.empty(positions.shape[0], dtype=np.uint32)
    new_id[by_use] = np.arange(by_use.shape[0], dtype=np.uint32)
    return positions[by_use], new_id[faces]


def compact_tile_in_numpy(ids, corners):
    """What tailor._compact_tile is documented to do, written out in numpy (read_tile's former form)."""
    s = np.sort(ids, axis=1)
    order = np.lexsort((s[:, 2], s[:, 1], s[:, 0]))  # stable: the first of equals is the earliest
    s = s[order]
    keep = np.ones(ids.shape[0], dtype=bool)
    keep[order[np.flatnonzero((s[1:] == s[:-1]).all(axis=1)) + 1]] = False
    kept = np.flatnonzero(keep)
    used, first, compact = np.unique(ids[kept].ravel(), return_index=True, return_inverse=True)
    positions = corners[kept].reshape(-1, 3)[first]
    return positions, compact.reshape(-1, 3).astype(np.uint32), kept


def test_a_streamed_tile_is_read_back_with_its_ids_compacted_and_repeated_faces_dropped():
    positions, faces = horse_arrays()
    # Faces that repeat others (turned, and with the other winding) after them, and a fan of 40
    # faces around a new lowest vertex with two repeats (a list longer than the short lists' path).
    fan = np.array([[0, 2 + i, 3 + i] for i in range(40)] + [[3, 0, 2], [12, 11, 0]], dtype=np.int64)
    fan[fan > 0] += faces.max()  # the fan's own vertices, above the horse's
    ring = np.array([[0.0, 0.0, -1.0]] + [[np.cos(a), np.sin(a), -1.0] for a in np.linspace(0, 6, 42)])
    positions = np.concatenate([positions, ring[1:]])
    positions = np.concatenate([ring[:1], positions])  # vertex 0 is the fan's centre
    ids = np.concatenate([faces + 1, np.roll(faces[:50] + 1, 1, axis=1), faces[100:120, ::-1] + 1, fan])
    ids = ids[np.random.default_rng(3).permutation(ids.shape[0])]
    corners = positions[ids].astype(np.float32)
    want = compact_tile_in_numpy(ids, corners)
    assert want[2].shape[0] == ids.shape[0] - 72
    for spread in (1, 1000):  # ids over a short range (a table), then too spread for one (a sort)
        got = tailor._tailor._compact_tile(ids * spread, corners)
        assert got[0].dtype == np.float32 and got[1].dtype == np.uint32 and got[2].dtype == np.int64
        for a, b in zip(got, want):
            assert np.array_equal(a, b)
    empty = tailor._tailor._compact_tile(np.empty((0, 3), np.int64), np.empty((0, 3, 3), np.float32))
    assert [a.shape[0] for a in empty] == [0, 0, 0]
    extreme = np.array([[np.iinfo(np.int64).min, 0, np.iinfo(np.int64).max]], dtype=np.int64)
    p, f, kept = tailor._tailor._compact_tile(extreme, np.zeros((1, 3, 3), np.float32))
    assert f.tolist() == [[0, 1, 2]] and p.shape == (3, 3) and kept.tolist() == [0]


def partition_block_in_numpy(ids, corners, e, level, index_dtype):
    """What tailor._partition_block is documented to do, written out in numpy."""
    from tailor import tiles_stream

    cells = tailor.chunk_cells(corners, e).astype(np.int64)
    packed = tiles_stream._pack(cells)
    key = tiles_stream._pack(cells >> level) if level else packed
    order = np.argsort(key, kind="stable")
    records = np.empty(ids.shape[0], dtype=[("i", index_dtype, 3), ("p", "<f4", (3, 3))])
    records["i"], records["p"] = ids, corners
    key = key[order]
    starts = np.flatnonzero(np.r_[True, key[1:] != key[:-1]])
    grouped = records[order].view(np.uint8).reshape(ids.shape[0], -1)
    return grouped, key[starts], np.r_[starts, key.shape[0]], np.unique(packed)


def test_a_block_of_the_partition_is_its_records_grouped_by_tile():
    positions, faces = horse_arrays()
    positions = (positions - positions.mean(axis=0)).astype(np.float32)  # cells on both sides of zero
    order = np.random.default_rng(11).permutation(faces.shape[0])
    corners = np.ascontiguousarray(positions[faces[order]])
    # A face's cell is its centroid's: the corners summed smallest first in doubles, exactly.
    for e in (CELL, CELL - 3):
        sorted_corners = np.sort(corners.astype(np.float64), axis=1)
        thrice = (sorted_corners[:, 0] + sorted_corners[:, 1]) + sorted_corners[:, 2]
        want = np.floor(thrice * (2.0**-e / 3.0) - 0.41421356237309503)  # the grid's offset (chunks.h)
        assert np.array_equal(tailor.chunk_cells(corners, e), want)
        assert (want < 0).any() and (want >= 0).any()
    for index_dtype, base in (("<u4", 0), ("<u8", 1 << 33)):  # the wide ids of a mesh past 2^32 vertices
        ids = faces[order] + base
        for e in (CELL, CELL - 3):
            for level in (0, 1, 3):
                got = tailor._tailor._partition_block(ids, corners, e, level, np.dtype(index_dtype).itemsize)
                want = partition_block_in_numpy(ids, corners, e, level, index_dtype)
                assert [a.dtype for a in got] == [np.uint8, np.int64, np.int64, np.int64]
                for a, b in zip(got, want):
                    assert np.array_equal(a, b)
                assert got[1].shape[0] > 1
    empty = tailor._tailor._partition_block(np.empty((0, 3), np.int64), np.empty((0, 3, 3), np.float32), CELL, 1, 4)
    assert [a.shape[0] for a in empty] == [0, 0, 1, 0]
    with pytest.raises(tailor.Error, match="2.20 chunk cells or more from the origin"):
        tailor._tailor._partition_block(ids[:1], corners[:1] * np.float32(1e30), -60, 0, 8)
    for corner in range(3):  # a face with a NaN coordinate has no cell, wherever the NaN is
        bad = corners[:1].copy()
        bad[0, corner, 1] = np.nan
        with pytest.raises(tailor.Error, match="chunk cells"):
            tailor.chunk_cells(bad, CELL)
    with pytest.raises(tailor.Error, match="corners must be beside the ids, a row each"):
        tailor._tailor._partition_block(ids[:2], corners[:1], CELL, 0, 8)
    with pytest.raises(tailor.Error, match="corners must be an .F, 3, 3. float32 array"):
        tailor._tailor._partition_block(ids[:1], corners[:1, :2], CELL, 0, 8)
    with pytest.raises(tailor.Error, match="vertex id 4294967296 of face 0 does not fit 4 bytes"):
        tailor._tailor._partition_block(np.array([[0, 1, 1 << 32]]), corners[:1], CELL, 0, 4)


def test_a_block_gathers_its_corners_from_the_vertex_rows():
    # The streamed vertex element as a PLY holds it: rows of x, y, z and one more property, after
    # a header of an odd length (the floats unaligned).
    positions, faces = horse_arrays()
    rows = np.zeros(positions.shape[0], dtype=[("x", "<f4"), ("y", "<f4"), ("z", "<f4"), ("s", "<f4")])
    for k, axis in enumerate("xyz"):
        rows[axis] = positions[:, k]
    data = b"header!" + rows.tobytes()
    ids = faces[np.random.default_rng(3).permutation(faces.shape[0])].astype(np.int64)
    got = tailor._tailor._gather_corners(data, 7, 16, rows.shape[0], ids)
    assert got.dtype == np.float32 and np.array_equal(got, positions.astype(np.float32)[ids])
    assert tailor._tailor._gather_corners(data, 7, 16, rows.shape[0], np.empty((0, 3), np.int64)).shape == (0, 3, 3)
    for bad in (rows.shape[0], -1):
        with pytest.raises(tailor.Error, match="vertex id %d of face 1 is not below %d" % (bad, rows.shape[0])):
            tailor._tailor._gather_corners(data, 7, 16, rows.shape[0], np.array([[0, 1, 2], [3, bad, 4]]))
    with pytest.raises(tailor.Error, match="does not fit a buffer of"):  # one row more than the bytes hold
        tailor._tailor._gather_corners(data, 7, 16, rows.shape[0] + 1, ids[:1])
    with pytest.raises(tailor.Error, match="does not fit a buffer of"):
        tailor._tailor._gather_corners(data, len(data) - 11, 16, 1, ids[:1] * 0)
    assert tailor._tailor._gather_corners(data, len(data) - 12, 16, 1, ids[:1] * 0).shape == (1, 3, 3)
    with pytest.raises(tailor.Error, match="source must be a contiguous buffer"):
        tailor._tailor._gather_corners(np.arange(24, dtype="<f4")[::-2], 0, 12, 1, np.zeros((1, 3), np.int64))
    with pytest.raises(tailor.Error, match="ids must be an .F, 3. array of integers"):
        tailor._tailor._gather_corners(data, 7, 16, rows.shape[0], np.array([[0.9, 1.5, 2.2]]))


def test_the_survey_gives_the_box_and_the_cell_that_loading_gives(tmp_path):
    # The first streaming pass: the box of the referenced vertices and plan_chunks' cell. The horse
    # as it is (the coarse histogram's bin decides the cell), then scaled so that its median edge
    # sits on a boundary of the rounding to a power of two (the bin spans two cells: the second
    # pass finds the exact median), with an unused vertex far away that the box leaves out.
    from tailor import tiles_stream

    positions, faces = horse_arrays()
    positions = positions.astype(np.float32)
    corners = positions[faces].astype(np.float32)
    lengths = np.sort(tailor.chunk_edge_lengths(np.ascontiguousarray(corners)).ravel())
    median = float(lengths[lengths.shape[0] // 2])
    boundary = 2.0 ** (round(np.log2(256 * median)) + 0.5) / 256  # where the cell's exponent changes
    for scale, second_pass in ((1.0, False), (boundary / median, True)):
        scaled = (positions * np.float32(scale)).astype(np.float32)
        path = tmp_path / "h.ply"
        write_ply(path, np.concatenate([scaled, [[50.0, 50.0, 50.0]]]), faces)
        layout = tiles_stream.read_layout(str(path))
        for block_faces in (tiles_stream.BLOCK_FACES, 7000):
            survey = tiles_stream.survey(layout, None, block_faces)
            mesh = tailor.load(str(path))
            assert survey["faces"] == mesh.face_count
            assert np.array_equal(survey["lo"], scaled.min(axis=0))
            assert np.array_equal(survey["hi"], scaled.max(axis=0))
            assert survey["cell_exponent"] == tailor.plan_chunks(mesh)["cell_exponent"]
            assert (survey["median_edge"] is not None) == second_pass
            if second_pass:
                want = np.sort(tailor.chunk_edge_lengths(np.ascontiguousarray(scaled[faces])).ravel())
                assert survey["median_edge"] == float(want[want.shape[0] // 2])
    assert tiles_stream.survey(layout, -3)["cell_exponent"] == -3
    with pytest.raises(tailor.Error, match="histogram must be"):
        tailor._tailor._survey_block(corners, np.zeros(3, np.float32), np.zeros(3, np.float32), np.zeros(10, np.int64))


def test_a_tile_in_canonical_order_is_the_same_for_any_input_order():
    positions, faces = horse_arrays()
    positions = positions.astype(np.float32)
    p, f = tailor.canonical_tile(positions, faces.astype(np.uint32))
    ref_p, ref_f = canonical_tile_in_numpy(positions, faces)
    assert p.dtype == np.float32 and f.dtype == np.uint32
    assert np.array_equal(p, ref_p) and np.array_equal(f, ref_f)
    # Faces shuffled, each turned, vertices renumbered, an unused vertex added: the same arrays.
    rng = np.random.default_rng(5)
    order = rng.permutation(faces.shape[0])
    turn = rng.integers(0, 3, faces.shape[0])
    shuffled = np.take_along_axis(faces[order], (turn[:, None] + np.arange(3)) % 3, axis=1)
    renumber = rng.permutation(positions.shape[0] + 1)
    moved = np.empty((positions.shape[0] + 1, 3), np.float32)
    moved[renumber[: positions.shape[0]]] = positions
    moved[renumber[-1]] = 7.0
    p2, f2 = tailor.canonical_tile(moved, renumber[shuffled])
    assert np.array_equal(p2, p) and np.array_equal(f2, f)
    with pytest.raises(tailor.Error, match=r"face index 9 out of range \(mesh has 9 vertices\) \(face 1\)"):
        tailor.canonical_tile(positions[:9], np.array([[0, 1, 2], [3, 4, 9]]))
    # Indices are checked as they are given, not after a cast to uint32 (2^32 + 2 is not 2), and
    # float indices are refused as tailor.Mesh refuses them.
    for wrapped in (np.array([[0, 1, 2**32 + 2]], np.int64), np.array([[0, 1, 2**63]], np.uint64)):
        with pytest.raises(tailor.Error, match="out of range"):
            tailor.canonical_tile(positions[:9], wrapped)
    with pytest.raises(tailor.Error, match="faces must be int32, int64, uint32 or uint64, got float64"):
        tailor.canonical_tile(positions[:9], np.array([[0, 1, 2.0]]))
    with pytest.raises(tailor.Error, match="positions must be a"):
        tailor.canonical_tile(positions[:, :2], faces)
    # A NaN compares false both ways: its order would be the input's, so it is refused.
    nan = positions[:9].copy()
    nan[4, 1] = np.nan
    with pytest.raises(tailor.Error, match=r"^tailor.canonical_tile: vertex coordinate not finite or beyond .* \(vertex 4\)$"):
        tailor.canonical_tile(nan, np.array([[0, 1, 2], [3, 4, 5]]))


def test_a_streamed_ply_gives_the_in_memory_tiles(tmp_path):
    # The horse as it is (float x y z, normals, uchar int lists): auto cell; then cut coarser.
    for extra in ([], ["--chunk-cell", CELL, "--tile-size", 2.0**(CELL + 1)]):
        streamed, in_memory = tmp_path / "s", tmp_path / "m"
        code, stdout, stderr = run_tiles(HORSE, "-o", streamed, "--workers", 1, "--json", *extra)
        assert code == 0, stderr
        assert json.loads(stdout)["input"] == "streamed"
        code, stdout, stderr = run_tiles(HORSE, "-o", in_memory, "--workers", 0, "--in-memory", "--json", *extra)
        assert code == 0, stderr
        assert json.loads(stdout)["input"] == "in memory"
        assert folder_bytes(streamed) == folder_bytes(in_memory)
        assert not (streamed / "partition").exists()
        assert sorted(p.name for p in tmp_path.iterdir()) == ["m", "s"]
        for folder in (streamed, in_memory):
            for p in sorted(folder.rglob("*"), reverse=True):
                p.unlink() if p.is_file() else p.rmdir()
            folder.rmdir()
    # Another layout: double x y z among other properties, ushort indices counted by a char, a face
    # property, a face that repeats a vertex, a face that repeats another's vertices, an unused vertex.
    positions, faces = horse_arrays()
    positions = np.concatenate([positions, [[9.0, 9.0, 9.0]]])
    faces = np.concatenate([faces[:500], [[1, 1, 2]], faces[500:], faces[7:8]])
    ply = write_layout_ply(
        tmp_path / "other.ply",
        positions,
        faces,
        vertex_props=[("confidence", "uchar", "u1"), ("x", "double", "<f8"), ("y", "double", "<f8"),
                      ("quality", "float", "<f4"), ("z", "double", "<f8")],
        face_props=[("flags", "int", "<i4"), ("vertex_indices", ("char", "ushort"), ("i1", "<u2"))],
    )  # fmt: skip
    streamed, in_memory = tmp_path / "s2", tmp_path / "m2"
    code, stdout, stderr = run_tiles(ply, "-o", streamed, "--workers", 2, "--json", "--block-faces", 10000)
    assert code == 0, stderr
    summary = json.loads(stdout)
    assert summary["input"] == "streamed" and summary["faces"] == faces.shape[0] - 2
    code, _, stderr = run_tiles(ply, "-o", in_memory, "--workers", 0, "--in-memory")
    assert code == 0, stderr
    assert folder_bytes(streamed) == folder_bytes(in_memory)
    # A re-run keeps every tile.
    code, stdout, stderr = run_tiles(ply, "-o", streamed, "--workers", 0, "--json")
    assert code == 0, stderr
    summary = json.loads(stdout)
    assert summary["written"] == 0 and summary["kept"] == summary["tiles"]
    assert folder_bytes(streamed) == folder_bytes(in_memory)


def test_a_comment_that_says_end_header_does_not_end_the_header(tmp_path):
    # The header ends at the line whose first word is end_header, as tailor.load reads it.
    from tailor import tiles_stream

    plain = HORSE.read_bytes()
    tricked = tmp_path / "comment.ply"
    tricked.write_bytes(plain.replace(b"\nend_header\n", b"\ncomment end_header here\nend_header\n", 1))
    a, b = tiles_stream.read_layout(str(HORSE)), tiles_stream.read_layout(str(tricked))
    extra = len(b"comment end_header here\n")
    assert (b.vertex_count, b.face_count) == (a.vertex_count, a.face_count)
    assert (b.vertex_offset, b.face_offset) == (a.vertex_offset + extra, a.face_offset + extra)
    assert tailor.load(tricked).face_count == tailor.load(HORSE).face_count


def test_the_partition_in_parts_is_the_partition_in_one(tmp_path):
    # The file cut into ranges (as the driver and a cluster's workers share it): each tile's files,
    # read one after the other, hold the faces the one-range partition gives it, in the same order;
    # a range partitioned again (a task retried, or run twice at once) leaves a whole folder in place.
    from tailor import tiles_stream

    layout = tiles_stream.read_layout(str(HORSE))
    one = tiles_stream.partition_parts(layout, CELL, 1, tmp_path / "one", 1, block_faces=10000)
    parts = tiles_stream.partition_parts(layout, CELL, 1, tmp_path / "parts", 4, block_faces=10000)
    assert one[0] == parts[0] and one[2] == parts[2] and len(one[0]) > 4
    assert all(len(files) == 1 for files in one[1].values())
    assert max(len(files) for files in parts[1].values()) > 1
    for tile, files in parts[1].items():
        assert b"".join(pathlib.Path(f).read_bytes() for f in files) == pathlib.Path(one[1][tile][0]).read_bytes()
    first, end = tiles_stream.part_ranges(layout.face_count, 4, 10000)[1]
    folder = tiles_stream.part_folder(tmp_path / "parts", 1)
    before = {p.name: p.read_bytes() for p in folder.iterdir()}
    again = tiles_stream.partition(layout, CELL, 1, folder, first, end, 10000)
    assert {p.name: p.read_bytes() for p in folder.iterdir()} == before
    assert sum(again[0].values()) == end - first
    shutil.rmtree(folder)
    counts, cells = tiles_stream.partition(layout, CELL, 1, folder, first, end, 10000)
    assert counts == again[0] and np.array_equal(cells, again[1])
    assert {p.name: p.read_bytes() for p in folder.iterdir()} == before
    assert sorted(p.name for p in folder.parent.iterdir()) == ["part-%04d" % k for k in range(4)]


def test_a_bad_streamed_ply_is_one_line_and_leaves_nothing(tmp_path):
    positions, faces = horse_arrays()
    props = dict(
        vertex_props=[("x", "float", "<f4"), ("y", "float", "<f4"), ("z", "float", "<f4")],
        face_props=[("vertex_indices", ("uchar", "int"), ("u1", "<i4"))],
    )
    out = tmp_path / "out"
    bad_index = faces.copy()
    bad_index[900, 1] = positions.shape[0] + 5
    counts = np.full(faces.shape[0], 3)
    counts[1000] = 4
    # A face of two corners makes the file shorter than its header's triangles need: named, not
    # reported as a truncated file.
    short = np.full(faces.shape[0], 3)
    short[2000] = 2
    cases = {
        "truncated": (write_layout_ply(tmp_path / "truncated.ply", positions, faces, cut=100, **props), "truncated"),
        "index": (write_layout_ply(tmp_path / "index.ply", positions, bad_index, **props), "out of range"),
        "quad": (write_layout_ply(tmp_path / "quad.ply", positions, faces, counts=counts, **props), "has 4 vertices"),
        "segment": (
            write_layout_ply(tmp_path / "segment.ply", positions, faces, counts=short, **props),
            "face 2000 has 2 vertices",
        ),
        "count": (
            write_layout_ply(tmp_path / "count.ply", positions, faces, header_faces=faces.shape[0] + 10, **props),
            "truncated",
        ),
    }
    # A cell so small that the mesh reaches 2^20 cells from the origin: found while partitioning,
    # after the temporary folder (and its scratch folder) exist.
    cases["cells"] = (HORSE, "2^20 chunk cells or more from the origin")
    # The same, found by the partition's tasks on a cluster (the file cut into two ranges).
    cases["cells on a cluster"] = (HORSE, "2^20 chunk cells or more from the origin")
    for name, (ply, message) in cases.items():
        extra = ["--chunk-cell", -40] if name.startswith("cells") else []
        if name == "cells on a cluster":
            extra += ["--workers", 2, "--block-faces", 10000]
        code, _, stderr = run_tiles(ply, "-o", out, "--workers", 0, *extra)
        assert code == 1, name
        assert stderr.count("\n") == 1 and stderr.startswith("tailor.tiles: error: ") and message in stderr, stderr
        assert not out.exists()
        assert not [p for p in tmp_path.iterdir() if p.name.startswith(".")], name


def write_height_field(ply, n):
    """A binary PLY of an n x n grid of quads as 2 n^2 triangles over a wavy height field."""
    x, y = np.meshgrid(np.arange(n + 1, dtype=np.float32), np.arange(n + 1, dtype=np.float32))
    z = np.sin(x * 0.05) * np.cos(y * 0.07) * 3
    v = (np.stack([x.ravel(), y.ravel(), z.ravel()], 1) / np.float32(n)).astype("<f4")
    i = np.arange(n * n)
    a = (i // n) * (n + 1) + i % n
    f = np.empty(2 * n * n, dtype=[("n", "u1"), ("i", "<i4", 3)])
    f["n"] = 3
    f["i"][0::2] = np.stack([a, a + 1, a + n + 2], 1)
    f["i"][1::2] = np.stack([a, a + n + 2, a + n + 1], 1)
    with open(ply, "wb") as out:
        out.write(b"ply\nformat binary_little_endian 1.0\nelement vertex %d\n" % len(v))
        out.write(b"property float x\nproperty float y\nproperty float z\nelement face %d\n" % len(f))
        out.write(b"property list uchar int vertex_indices\nend_header\n")
        out.write(v.tobytes())
        out.write(f.tobytes())


def test_the_streamed_driver_holds_a_block_not_the_mesh(tmp_path):
    # A 2.9 M-face height field: the driver's peak memory through the partition, both paths.
    n = 1200
    ply = tmp_path / "grid.ply"
    write_height_field(ply, n)
    peaks = {}
    for path in ("streamed", "in memory"):
        extra = ["--in-memory"] if path == "in memory" else ["--block-faces", 32768]
        code, stdout, stderr = run_tiles(ply, "-o", tmp_path / "out", "--cut-only", "--json", *extra)
        assert code == 0, stderr
        summary = json.loads(stdout)
        assert summary["input"] == path and summary["faces"] == 2 * n * n
        peaks[path] = summary["driver_peak_rss"]
    assert not (tmp_path / "out").exists()
    # The interpreter, numpy and tailor take about 45 MB; a block of 32768 faces about 10 MB more,
    # the vertex element (kept mapped: under VERTEX_PAGES_KEPT) 17 MB; the face records, 37 MB, go.
    assert peaks["streamed"] < 90e6 and peaks["streamed"] < peaks["in memory"] / 2, peaks


def mapped_rss(path):
    """Resident bytes of this process's mappings of `path` (/proc/self/smaps)."""
    total, inside = 0, False
    for line in pathlib.Path("/proc/self/smaps").read_text().splitlines():
        if "-" in line.split(" ", 1)[0]:  # a mapping's first line: "start-end perms offset dev inode path"
            inside = line.endswith(" " + str(path))
        elif inside and line.startswith("Rss:"):
            total += int(line.split()[1]) * 1024
    return total


def test_the_vertex_pages_stay_mapped_up_to_a_budget_and_the_faces_are_released(tmp_path, monkeypatch):
    from tailor import tiles_stream

    ply = tmp_path / "grid.ply"
    write_height_field(ply, 300)  # 180,000 faces, 90,601 vertices: 1.1 MB of vertices, 2.3 MB of faces
    layout = tiles_stream.read_layout(ply)
    vertex_bytes = layout.vertex_count * layout.vertex_dtype.itemsize
    block_bytes = 4096 * layout.face_dtype.itemsize
    resident, surveys = {}, {}
    for budget in (0, tiles_stream.VERTEX_PAGES_KEPT):
        monkeypatch.setattr(tiles_stream, "VERTEX_PAGES_KEPT", budget)
        body = tiles_stream._Body(layout)
        try:
            for _ in body.blocks(4096):
                pass
            resident[budget] = mapped_rss(ply)
        finally:
            body.close()
        surveys[budget] = tiles_stream.survey(layout, None, block_faces=4096)
    # Under the budget the vertex element stays (every vertex was gathered; its last page, shared
    # with the first face records, goes with them), the face records go.
    kept = resident[tiles_stream.VERTEX_PAGES_KEPT]
    assert vertex_bytes - 2 * mmap.PAGESIZE <= kept < vertex_bytes + block_bytes + mmap.PAGESIZE, resident
    # Over it (a budget of 0) both go after every block.
    assert resident[0] < block_bytes + mmap.PAGESIZE, resident
    # The same survey either way.
    assert surveys[0].keys() == surveys[tiles_stream.VERTEX_PAGES_KEPT].keys()
    for key, value in surveys[0].items():
        assert np.array_equal(value, surveys[tiles_stream.VERTEX_PAGES_KEPT][key]), key


def test_a_node_written_twice_at_once_is_written_whole(tmp_path):
    # Dask runs a task again when it declares its worker lost, which may still be writing: two runs
    # then write the same node's simplified copy at once. Here the second writes the whole file while
    # the first has its temporary file open (before it writes: it is converting the positions).
    path = tmp_path / "lod" / "0_0_0_0.bin"
    path.parent.mkdir()
    positions = np.arange(12, dtype=np.float32).reshape(4, 3)
    faces = np.array([[0, 1, 2], [0, 2, 3]], dtype=np.uint32)
    uvs = np.linspace(0, 1, 12, dtype=np.float32).reshape(2, 3, 2)

    class Interleaved(np.ndarray):
        def astype(self, *args, **kwargs):
            tiles.save_coarse(path, positions, faces, uvs, 0.5)
            return np.asarray(self).astype(*args, **kwargs)

    tiles.save_coarse(path, positions.view(Interleaved), faces, uvs, 0.5)
    got = tiles.load_coarse(path)
    assert all(np.array_equal(a, b) for a, b in zip(got[:3], (positions, faces, uvs))) and got[3] == 0.5
    assert [p.name for p in path.parent.iterdir()] == [path.name]  # no temporary file left
    assert path.stat().st_mode & 0o777 == 0o666 & ~current_umask()


def current_umask():
    mask = os.umask(0)
    os.umask(mask)
    return mask


def test_one_run_at_a_time_writes_a_folder_and_nothing_but_its_tileset_is_replaced(tmp_path):
    import fcntl

    out = tmp_path / "out"
    common = [HORSE, "-o", out, "--workers", 0, "--chunk-cell", CELL, "--no-lod", "-q"]
    assert run_tiles(*common)[0] == 0
    good = folder_bytes(out)
    # While another run holds OUTDIR's lock (beside it), a second one refuses at once: it would link
    # that run's tiles as its own.
    lock = os.open(tmp_path / ".out.lock", os.O_RDWR | os.O_CREAT)
    fcntl.flock(lock, fcntl.LOCK_EX)
    code, _, stderr = run_tiles(*common, "--texture-size", 256)
    os.close(lock)
    assert code == 1 and stderr == "tailor.tiles: error: %s: another tailor.tiles run is writing it\n" % out
    assert folder_bytes(out) == good
    # A run removes its lock file, and what runs killed beside OUTDIR left (a pid's temporary folder).
    (tmp_path / ".out.tmp-999999" / "tiles").mkdir(parents=True)
    assert run_tiles(*common)[0] == 0
    assert sorted(p.name for p in tmp_path.iterdir()) == ["out"]
    # A file OUTDIR holds besides its tileset is never deleted: the run refuses, naming it.
    (out / "index.html").write_text("a viewer page")
    code, _, stderr = run_tiles(*common)
    assert code == 1 and "holds index.html, which is not part of its tileset" in stderr
    assert (out / "index.html").read_text() == "a viewer page"
    (out / "index.html").unlink()
    # Nor one inside its tiles' folders, nor an image by the name of the texture's in another format,
    # nor one by a name the tiles use where this folder's tiles (which name no image) do not put it.
    for foreign in ("tiles/notes.txt", "tiles/0_1_2_3.glb.bak", "texture.psd", "texture.png", "tiles/texture.jpg"):
        (out / foreign).write_text("mine")
        code, _, stderr = run_tiles(*common)
        assert code == 1 and "holds %s, which is not part of its tileset" % foreign in stderr, stderr
        assert (out / foreign).read_text() == "mine"
        (out / foreign).unlink()
    # Nor is the input, nor the texture, when it lies in OUTDIR.
    shutil.copy(HORSE, out / "scan.ply")
    code, _, stderr = run_tiles(out / "scan.ply", *common[1:])
    assert code == 1 and "scan.ply is inside" in stderr and (out / "scan.ply").is_file()
    (out / "scan.ply").unlink()
    shutil.copy(TEXTURE, out / "texture.png")
    code, _, stderr = run_tiles(*common, "--texture", out / "texture.png")
    assert code == 1 and "texture.png is inside" in stderr, stderr
    (out / "texture.png").unlink()
    assert folder_bytes(out) == good
    # A textured run puts its image in tiles/ and keeps it (and its time) on a re-run; a folder that
    # has it at the top with a manifest of format 2 is replaced whole, nothing left at the top.
    textured = tmp_path / "textured"
    with_texture = [HORSE, "-o", textured, "--workers", 0, "--chunk-cell", CELL, "--no-lod", "-q", "--texture", TEXTURE]
    assert run_tiles(*with_texture)[0] == 0
    image = textured / "tiles" / "texture.png"
    before = (image.stat().st_mtime_ns, folder_bytes(textured))
    assert run_tiles(*with_texture)[0] == 0
    assert (image.stat().st_mtime_ns, folder_bytes(textured)) == before
    image.rename(textured / "texture.png")
    manifest = json.loads((textured / "tailor-tiles.json").read_text())
    manifest["params"]["format"] = 2
    (textured / "tailor-tiles.json").write_text(json.dumps(manifest))
    code, stdout, stderr = run_tiles(*with_texture[:-3], "--json", "--texture", TEXTURE)
    assert code == 0 and json.loads(stdout)["kept"] == 0, stderr
    assert folder_bytes(textured) == before[1] and not (textured / "texture.png").exists()
    # A manifest of the wrong shape keeps nothing: every tile is written again, the same bytes.
    manifest = json.loads((out / "tailor-tiles.json").read_text())
    manifest["tiles"] = {name: dict(r, faces="many") for name, r in manifest["tiles"].items()}
    (out / "tailor-tiles.json").write_text(json.dumps(manifest))
    code, stdout, stderr = run_tiles(*common[:-1], "--json")
    assert code == 0, stderr
    assert json.loads(stdout)["kept"] == 0 and folder_bytes(out) == good


def test_a_texture_that_does_not_wrap_is_warned_of_as_tailor_map_does(tmp_path):
    photo = DATA / "textures" / "water-caustics-300.jpg"
    code, _, stderr = run_tiles(HORSE, "-o", tmp_path / "out", "--texture", photo, "--chunk-cell", CELL, "--workers",
                                0, "--no-lod")
    assert code == 0, stderr
    expected = "tailor.tiles: warning: %s does not wrap (wrap ratio " % photo
    assert stderr.count(expected) == 1 and "make it tileable with: tailor tile" in stderr, stderr


def test_closing_does_not_wait_for_a_cluster_start_that_cannot_end(monkeypatch):
    # A cluster's start that does not end (a scheduler that does not answer) is left behind.
    import argparse
    import threading
    import time

    release = threading.Event()
    monkeypatch.setattr(tiles, "start_client", lambda args, space=None: (release.wait(), None))
    monkeypatch.setattr(tiles, "CLIENT_CLOSE_WAIT", 0.5)
    start = tiles.ClientStart(argparse.Namespace(scheduler="tcp://127.0.0.1:1"))
    began = time.monotonic()
    start.close()
    start.close()  # waited for once, not at every close
    assert time.monotonic() - began < 0.9 and start.thread.is_alive()
    release.set()
    start.thread.join()


def test_a_terminated_run_cleans_up_like_an_interrupted_one(tmp_path):
    import signal
    import time

    # A 300k-face height field, so that the run is still mapping when the signal comes.
    n = 390
    x, y = np.meshgrid(np.arange(n + 1, dtype=np.float32), np.arange(n + 1, dtype=np.float32))
    positions = np.stack([x.ravel(), y.ravel(), np.sin(x * 0.1).ravel() * np.cos(y * 0.13).ravel()], axis=1)
    i = (np.arange(n)[None, :] + (n + 1) * np.arange(n)[:, None]).ravel()
    faces = np.concatenate([np.stack([i, i + 1, i + n + 2], 1), np.stack([i, i + n + 2, i + n + 1], 1)])
    mesh = tmp_path / "field.ply"
    records = np.zeros(faces.shape[0], dtype=[("n", "u1"), ("v", "<i4", 3)])
    records["n"], records["v"] = 3, faces
    header = (
        "ply\nformat binary_little_endian 1.0\nelement vertex %d\nproperty float x\nproperty float y\n"
        "property float z\nelement face %d\nproperty list uchar int vertex_indices\nend_header\n"
        % (positions.shape[0], faces.shape[0])
    )
    mesh.write_bytes(header.encode() + positions.astype("<f4").tobytes() + records.tobytes())
    out = tmp_path / "out"
    env = dict(os.environ, PYTHONPATH=os.pathsep.join(sys.path))
    run = subprocess.Popen(
        [sys.executable, "-m", "tailor.tiles", str(mesh), "-o", str(out), "--workers", "0", "--threads", "1", "-q"],
        env=env, stderr=subprocess.PIPE, text=True,
    )
    deadline = time.monotonic() + 120
    while not list(tmp_path.glob(".out.tmp-*")) and run.poll() is None and time.monotonic() < deadline:
        time.sleep(0.005)
    run.send_signal(signal.SIGTERM)
    _, stderr = run.communicate(timeout=120)
    assert run.returncode == 128 + signal.SIGTERM, stderr
    assert stderr == "tailor.tiles: terminated (SIGTERM); %s left as it was\n" % out
    assert sorted(p.name for p in tmp_path.iterdir()) == ["field.ply"]

    # Under nohup (SIGHUP ignored at start) a hang-up leaves the run going to its end.
    run = subprocess.Popen(
        [sys.executable, "-m", "tailor.tiles", str(mesh), "-o", str(out), "--workers", "0", "--threads", "1", "-q"],
        env=env, stderr=subprocess.PIPE, text=True, preexec_fn=lambda: signal.signal(signal.SIGHUP, signal.SIG_IGN),
    )
    deadline = time.monotonic() + 120
    while not list(tmp_path.glob(".out.tmp-*")) and run.poll() is None and time.monotonic() < deadline:
        time.sleep(0.005)
    run.send_signal(signal.SIGHUP)
    _, stderr = run.communicate(timeout=300)
    assert run.returncode == 0 and stderr == "", stderr
    assert (out / "tileset.json").is_file()


def test_a_run_beside_another_cluster_says_nothing(tmp_path):
    # Another Dask cluster (a second run at the same time) holds Dask's default dashboard port:
    # the local cluster takes a free port without a word.
    import socket

    held = socket.socket()
    try:
        held.bind(("127.0.0.1", 8787))
        held.listen()
    except OSError:  # already held by something else: the same situation
        pass
    try:
        code, _, stderr = run_tiles(HORSE, "-o", tmp_path / "out", "--workers", 1, "--chunk-cell", CELL, "--no-lod", "-q")
    finally:
        held.close()
    assert code == 0 and stderr == "", stderr


@pytest.mark.parametrize("signum", ["SIGTERM", "SIGINT", "SIGHUP"])
def test_a_signal_to_the_group_while_the_cluster_starts_prints_one_line(tmp_path, signum):
    # A terminal or a service manager signals the whole process group, here while the local
    # cluster's processes start: they hold it blocked, the driver alone answers, in one line, and
    # leaves no process behind. (Workers that died of it printed tracebacks, and the driver could
    # wait for their restarts at exit.)
    import signal
    import time

    import psutil

    run, out = start_in_own_group(tmp_path)
    driver = psutil.Process(run.pid)
    deadline = time.monotonic() + 60
    while run.poll() is None and time.monotonic() < deadline and len(driver.children(recursive=True)) < 3:
        time.sleep(0.002)
    os.killpg(run.pid, getattr(signal, signum))
    _, stderr = run.communicate(timeout=60)
    number = getattr(signal, signum)
    words = "interrupted" if number == signal.SIGINT else "terminated (%s)" % signum
    assert run.returncode == 128 + number, stderr
    assert stderr == "tailor.tiles: %s; %s left as it was\n" % (words, out)
    time.sleep(1)
    left = [
        p.info
        for p in psutil.process_iter(["pid", "status", "cmdline"])
        if p.info["status"] != psutil.STATUS_ZOMBIE and _group_of(p.pid) == run.pid  # a zombie has ended
    ]
    assert left == []


def start_in_own_group(tmp_path, **environment):
    """A 2-worker run of the horse into tmp_path/out, in a process group of its own, every group
    signal at its default (as a terminal's foreground job: not nohup, not in the background)."""
    out = tmp_path / "out"
    env = dict(os.environ, PYTHONPATH=os.pathsep.join(sys.path), **environment)
    run = subprocess.Popen(
        [sys.executable, "-m", "tailor.tiles", str(HORSE), "-o", str(out), "--workers", "2", "--chunk-cell", str(CELL),
         "--no-lod", "-q"],
        env=env, stderr=subprocess.PIPE, text=True, start_new_session=True, preexec_fn=_default_group_signals,
    )
    return run, out


def _default_group_signals():
    import signal

    for signum in tiles.GROUP_SIGNALS:
        signal.signal(signum, signal.SIG_DFL)


def _group_of(pid):
    try:
        return os.getpgid(pid)
    except OSError:
        return None


def test_ctrl_c_on_a_cluster_prints_one_line(tmp_path):
    import signal
    import time

    # Ctrl-C reaches the terminal's whole process group: the driver and every Dask worker. The
    # workers leave it to the driver, which closes the cluster and says so in one line.
    run, out = start_in_own_group(tmp_path)
    deadline = time.monotonic() + 120
    while not list(tmp_path.glob(".out.tmp-*/**/*.glb")) and run.poll() is None and time.monotonic() < deadline:
        time.sleep(0.005)
    os.killpg(run.pid, signal.SIGINT)
    _, stderr = run.communicate(timeout=120)
    assert run.returncode == 130, stderr
    assert stderr == "tailor.tiles: interrupted; %s left as it was\n" % out
    assert sorted(p.name for p in tmp_path.iterdir()) == []


def test_a_run_after_a_killed_one_says_nothing_of_it(tmp_path):
    import signal
    import time

    # A run killed outright (kill -9, the out-of-memory killer) leaves its workers' folders and
    # locks: in a folder of its own in the temporary directory, which no later cluster looks into.
    # In Dask's default, one folder that every cluster shares, the next run's workers removed them
    # with a line each.
    temporary = tmp_path / "tmp"
    temporary.mkdir()
    runs = tmp_path / "runs"
    runs.mkdir()
    run, out = start_in_own_group(runs, TMPDIR=str(temporary))
    deadline = time.monotonic() + 120
    while not list(runs.glob(".out.tmp-*/**/*.glb")) and time.monotonic() < deadline:
        assert run.poll() is None, run.communicate()[1]
        time.sleep(0.005)
    assert list(temporary.glob("*/**/worker-*")), "the workers were not up in 120 s"
    os.killpg(run.pid, signal.SIGKILL)
    run.communicate(timeout=60)
    left = sorted(temporary.iterdir())
    code, _, stderr = run_tiles(HORSE, "-o", out, "--workers", 2, "--chunk-cell", CELL, "--no-lod", "-q",
                                env={"TMPDIR": str(temporary)})
    assert code == 0 and stderr == "", stderr
    assert sorted(p.name for p in runs.iterdir()) == ["out"]  # the killed run's folder removed
    assert sorted(temporary.iterdir()) == left  # the finished run's own removed, the other untouched


def test_textures_are_read_as_tailor_map_reads_them(tmp_path):
    out = tmp_path / "out"
    common = [HORSE, "-o", out, "--workers", 0, "--chunk-cell", CELL, "--no-lod", "-q"]
    # Decoded whole, whatever --field-following says: a truncated image is refused, not copied.
    truncated = tmp_path / "truncated.png"
    truncated.write_bytes(GRAVEL.read_bytes()[:100])
    code, _, stderr = run_tiles(*common, "--texture", truncated, "--field-following", 1)
    assert code == 1 and "truncated.png: truncated or corrupt image data" in stderr and not out.exists()
    # A BMP colour map is readable but not a glTF image: refused, as tailor map refuses it.
    bmp = tmp_path / "colour.bmp"
    row = bytes(3 * 8)
    bmp.write_bytes(
        b"BM" + struct.pack("<IHHI", 54 + 8 * len(row), 0, 0, 54)
        + struct.pack("<IiiHHIIiiII", 40, 8, 8, 1, 24, 0, 8 * len(row), 2835, 2835, 0, 0) + row * 8
    )
    material = tmp_path / "material.json"
    material.write_text(json.dumps({"maps": [{"file": "colour.bmp", "role": "color"}]}))
    code, _, stderr = run_tiles(*common, "--material", material)
    assert code == 1 and "colour.bmp: texture is neither PNG nor JPEG" in stderr and not out.exists()
    # Named by what the bytes are: a PNG called .jpg is written as texture.png.
    disguised = tmp_path / "gravel.jpg"
    shutil.copy(GRAVEL, disguised)
    assert run_tiles(*common, "--texture", disguised)[0] == 0
    assert (out / "tiles" / "texture.png").read_bytes() == GRAVEL.read_bytes()
    assert not (out / "tiles" / "texture.jpg").exists()


def test_an_empty_value_is_refused_not_taken_for_the_option_left_out(tmp_path):
    # '--texture "$TEX"' with TEX unset would map without the texture, and -o '' name the working
    # folder.
    out = tmp_path / "out"
    for extra, name in ((["--texture", ""], "--texture"), (["--texture="], "--texture"), (["--material", ""], "--material"),
                        (["--scheduler", ""], "--scheduler")):
        code, _, stderr = run_tiles(HORSE, "-o", out, "--workers", 0, *extra)
        assert code == 2 and stderr == "tailor.tiles: error: %s was given an empty value: give one, or leave the option out\n" % name, stderr
    code, _, stderr = run_tiles(HORSE, "-o", "", "--workers", 0)
    assert code == 2 and "--output was given an empty value" in stderr, stderr
    code, _, stderr = run_tiles("", "-o", out, "--workers", 0)
    assert code == 2 and stderr == "tailor.tiles: error: the input was given as an empty path\n", stderr
    assert sorted(p.name for p in tmp_path.iterdir()) == []


def test_options_out_of_range_are_usage_errors(tmp_path):
    out = tmp_path / "out"
    for option, value, message in (
        ("--chunk-cell", 61, "--chunk-cell must be a whole number in -60..60"),
        ("--crack-rings", 1, "--crack-rings must be between 2 and 64 rings, got 1"),
        ("--max-stretch", 5, "--max-stretch must be between 0.01 and 4, got 5"),
        ("--field-following", 2, "--field-following must be auto or a number in [0, 1]"),
    ):
        code, _, stderr = run_tiles(HORSE, "-o", out, "--workers", 0, option, value)
        assert code == 2 and message in stderr and stderr.count("\n") == 1, stderr
    # A tile of more than 2^20 cells: refused naming --tile-size, loaded whole or streamed alike.
    for extra in ([], ["--in-memory"]):
        code, _, stderr = run_tiles(HORSE, "-o", out, "--workers", 0, "--chunk-cell", CELL, "--tile-size", 2**17, *extra)
        assert code == 1 and "--tile-size 131072 is 2^21 chunk cells of 0.0625; at most 2^20" in stderr, stderr
    # A FIFO is refused as tailor map refuses it (opening it would wait for a writer).
    fifo = tmp_path / "pipe.ply"
    os.mkfifo(fifo)
    code, _, stderr = run_tiles(fifo, "-o", out, "--workers", 0)
    assert code == 1 and "not a regular file" in stderr
    assert sorted(p.name for p in tmp_path.iterdir()) == ["pipe.ply"]


def test_positions_far_from_the_origin_are_warned_of(tmp_path):
    # A georeferenced scan (UTM coordinates) in 32-bit floats: its shape is rounded to 0.25 units
    # there, half an edge of this horse; tiles says so as tailor map does, streamed or loaded whole.
    mesh = tailor.load(HORSE)
    scaled = mesh.positions.astype(np.float64) * 500
    for name, offset, warned in (("utm.ply", (500000.0, 4000000.0, 100.0), True), ("local.ply", (0.0, 0.0, 0.0), False)):
        path = tmp_path / name
        write_ply(path, scaled + offset, mesh.faces)
        # Streamed or loaded whole, the automatic cell or a given one (no median measured for it).
        for extra in ([], ["--in-memory"], ["--chunk-cell", 5], ["--in-memory", "--chunk-cell", 5]):
            code, _, stderr = run_tiles(path, "-o", tmp_path / "out", "--workers", 0, "--no-lod", *extra)
            assert code == 0, stderr
            found = "warning: positions reach 4e+06 units from the origin, where 32-bit floats are 0.25 apart" in stderr
            assert found == warned, (extra, stderr)


def test_what_the_reader_read_past_is_warned_of(tmp_path):
    # An OFF header that counts one face of two: tiles warns as tailor map does, and maps the one.
    path = tmp_path / "short.off"
    path.write_text("OFF\n4 1 0\n0 0 0\n1 0 0\n0 1 0\n1 1 0\n3 0 1 2\n3 1 3 2\n")
    code, _, stderr = run_tiles(path, "-o", tmp_path / "out", "--workers", 0, "--no-lod", "--texture-size", 64)
    assert code == 0, stderr
    said = "1 line after the 1 face the OFF header declares (from line 8)"
    assert f"tailor.tiles: warning: {path}: not read: {said}\n" in stderr, stderr


def test_dropped_faces_are_said_as_tailor_map_says_them(tmp_path, tailor_binary):
    # A grid with two faces that repeat another's vertices and one that repeats a vertex: the
    # tiles drop them as the load does, and say so in tailor map's words, streamed or loaded.
    positions, faces = bumpy_grid(6)
    faces = np.concatenate([faces, faces[3:5], [[0, 0, 1]]]).astype(np.uint32)
    path = tmp_path / "grid.ply"
    write_ply(path, positions, faces)
    map_said = subprocess.run(
        [tailor_binary, "map", path, "-o", tmp_path / "x.glb"], capture_output=True, text=True, timeout=120
    ).stderr
    for extra in ([], ["--in-memory"]):
        out = tmp_path / ("out%d" % len(extra))
        code, _, stderr = run_tiles(path, "-o", out, "--workers", 0, *extra)
        assert code == 0, stderr
        lines = [l for l in stderr.splitlines() if "dropped" in l]
        assert lines == [
            "tailor.tiles: warning: %s: dropped 1 degenerate faces" % path,
            "tailor.tiles: warning: %s: dropped 2 duplicate faces" % path,
        ], (extra, stderr)
        for line in lines:
            assert line.replace("tailor.tiles:", "tailor:") in map_said, (line, map_said)
        assert json.loads((out / "tileset.json").read_text())["root"]


def test_help_shows_the_ranges_tailor_map_shows(tailor_binary):
    # The library's ranges, in the same words in both helps (argparse wraps its lines).
    map_help = " ".join(subprocess.run([tailor_binary, "map", "--help"], capture_output=True, text=True).stdout.split())
    code, out, _ = run_tiles("--help")
    tiles_help = " ".join(out.split())
    assert code == 0
    for flag in ("--scale", "--max-stretch", "--crack-rings"):
        text = tailor._tailor._range_text(flag)
        assert text and "(%s)" % text in map_help and text + "; default" in tiles_help, (flag, text)
    assert tailor._tailor._range_text("--bogus") == ""
