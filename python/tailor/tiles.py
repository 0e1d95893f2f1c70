"""python3 -m tailor.tiles: a mesh mapped as tiles on a Dask cluster, written as OGC 3D Tiles 1.1.

    python3 -m tailor.tiles scan.ply -o scan_tiles --texture gravel.png --workers 2
    python3 -m tailor.tiles scan.ply -o scan_tiles --scheduler tcp://head:8786
    python3 -m tailor.tiles scan.ply -o scan_tiles --material tiled/material.json --up z

The mesh is cut by the chunked engine's rule (tailor.plan_chunks: a world grid whose planes sit
sqrt(2) - 1 cells off the origin's, cell side a power of two of world units); a tile is a cube of 2**k x 2**k x 2**k chunk
cells (--tile-size, world units). Each tile is one Dask task that maps its chunks with
tailor.ChunkedMapper and writes tiles/<x>_<y>_<z>.glb: a chunk's UVs depend on its own faces only,
so every tile holds the bits `tailor map --chunks on` gives those faces inside the whole mesh, for
any number of workers. The texture (or a PBR material's images: --material) is written once
in tiles/, beside the .glb files, and every .glb names it (image URIs in the same folder, which
tailor's own reader takes too), so that a 3D Tiles client downloads it once. --up z: Z-up
coordinates, turned Y up by each .glb's node as glTF wants and back to Z up by the client as 3D
Tiles prescribes; the bounding volumes follow either choice.

A binary little-endian PLY of triangles is partitioned by streaming it (tailor.tiles_stream: per-tile
files in a scratch folder, the driver never holds the whole mesh; the partition's ranges of the
file shared between the driver and the workers); other inputs are loaded whole.

A tile's faces are written in a canonical order (by their corners' coordinates), so its bytes do
not depend on the input file's face or vertex order. tailor-tiles.json records each tile's digest
(its geometry and the options); a re-run into the same folder maps and writes only the tiles whose
digest changed and keeps the others' files as they are (bytes and modification times).

Everything is written into a temporary folder beside OUTDIR, renamed into place at the end: a
failed run leaves OUTDIR as it was. With --scheduler the workers write the tiles themselves, so
OUTDIR must be on a file system every worker sees, and each worker must import the same tailor.
"""
import argparse
import contextlib
import functools
import glob
import hashlib
import json
import logging
import math
import multiprocessing
import multiprocessing.resource_tracker
import os
import pathlib
import re
import secrets
import shutil
import signal
import struct
import sys
import tempfile
import threading
import time
import warnings

import numpy as np

import tailor

from . import tiles_stream

MANIFEST = "tailor-tiles.json"
# Seconds the driver waits, when it stops, for the cluster's start to end before it exits anyway (a
# start takes a few seconds).
CLIENT_CLOSE_WAIT = 10
# What a terminal (Ctrl-C, closing it) or a service manager sends to a whole process group.
GROUP_SIGNALS = {signal.SIGINT, signal.SIGTERM, signal.SIGHUP}
FORMAT = 3  # of the manifest (and of where the images are): a different number means every tile is written again
# The streamed partition's ranges of the file (at least a block each): enough for every worker of a
# cluster to take several, so that the driver and the workers finish together.
PARTITION_PARTS = 256
# A tile is at most 2^20 chunk cells on a side: the streamed partition packs its coordinates in 21 bits
# (_partition_block); the in-memory path keeps the same limit, so that both cut the same tiles.
MAX_TILE_LEVEL = 20


class TilesError(Exception):
    """A one-line error the command prints as `tailor.tiles: error: ...`."""


# === Geometry ===


def texels_per_unit_for(mesh, scale):
    """The chunked engine's texel density for `tailor map --scale S` (unit scale 0): scale over the
    longest side of the referenced vertices' bounding box, rounded to a power of two."""
    used = np.zeros(mesh.vertex_count, dtype=bool)
    used[mesh.faces.ravel()] = True
    p = mesh.positions[used]
    return texels_per_unit_of_box(p.min(axis=0), p.max(axis=0), scale)


def texels_per_unit_of_box(lo, hi, scale):
    """texels_per_unit_for from the referenced vertices' bounding box (lo, hi: float32)."""
    longest = float((np.asarray(hi, dtype=np.float64) - np.asarray(lo, dtype=np.float64)).max())
    if not (longest > 0) or not math.isfinite(longest):
        raise TilesError("the mesh has no extent: give --texels-per-unit")
    x = math.log2(float(np.float32(scale)) / longest)
    return math.ldexp(1.0, int(math.copysign(math.floor(abs(x) + 0.5), x)))  # std::round: half away from 0


def tile_digest(positions, faces, params):
    h = hashlib.sha256()
    h.update(json.dumps(params, sort_keys=True).encode())
    h.update(np.ascontiguousarray(positions).tobytes())
    h.update(np.ascontiguousarray(faces).tobytes())
    return h.hexdigest()


# === The .glb: the library's writer, the texture referenced by URI ===


def tile_material(folder, params):
    """The tile's material for tailor.save_uvs: the images in tiles/ (written once by the driver),
    which the tile names by URI (write_tile_glb) without reading them; None for a plain material."""
    images = params["images"]
    if not images:
        return None
    roles = params.get("orm_roles", [])
    return {
        "color": str(image_path(folder, images["color"])) if "color" in images else None,
        "width": params["texture_size"][0],
        "height": params["texture_size"][1],
        "orm_roughness_metallic": "roughness_metallic" in roles,
        "orm_occlusion": "occlusion" in roles,
    }


def tile_mesh(name, positions, faces):
    mesh = tailor.Mesh(positions, faces)
    if mesh.face_count != faces.shape[0]:
        raise TilesError("tile %s: %d faces dropped as degenerate" % (name, faces.shape[0] - mesh.face_count))
    return mesh


def write_tile_glb(folder, name, mesh, corner_uvs, params):
    """tiles/<name>.glb; its images name the files beside it (one copy for every tile)."""
    path = glb_path(folder, name)
    material = tile_material(folder, params)
    uris = dict(params["images"]) if material is not None else {}
    tailor.save_uvs(
        str(path), mesh, corner_uvs, tuple(params["texture_size"]), material=material, up=params["up"], image_uris=uris
    )


# === The tasks: a leaf tile maps its chunks, a parent simplifies its children ===


def make_mapper(params, threads):
    return tailor.ChunkedMapper(
        params["cell_exponent"],
        params["texels_per_unit"],
        threads=threads,
        field_following=params["field_following"],
        max_stretch=params["max_stretch"],
        texture_size=tuple(params["texture_size"]),
        crack_rings=params["crack_rings"],
    )


def node_name(level, tile):
    return "%d_%d_%d_%d" % (level, tile[0], tile[1], tile[2])


def glb_path(folder, name):
    return pathlib.Path(folder) / "tiles" / (name + ".glb")


def image_path(folder, file):
    """An image every tile names: beside the .glb files, which name it without a folder."""
    return pathlib.Path(folder) / "tiles" / file


def coarse_path(folder, name):
    return pathlib.Path(folder) / "lod" / (name + ".bin")


def save_coarse(path, positions, faces, uvs, error):
    """What a node hands its parent: its content simplified to a quarter, and that step's error."""
    head = struct.pack("<QQd", positions.shape[0], faces.shape[0], error)
    # A temporary name of its own, as the library's writes take (".tailor-XXXXXX"): a task Dask runs
    # again while its first run, on a worker it declared lost, still writes must not write into the
    # same file (one run's truncation could leave zeros in what the other renames into place).
    folder = os.path.dirname(str(path)) or "."
    while True:
        tmp = os.path.join(folder, ".tailor-" + secrets.token_hex(3))
        try:  # 0666 less the umask, as a plain open() creates
            fd = os.open(tmp, os.O_WRONLY | os.O_CREAT | os.O_EXCL | os.O_CLOEXEC, 0o666)
            break
        except FileExistsError:
            continue
    try:
        with os.fdopen(fd, "wb") as f:
            for block in (head, positions.astype("<f4"), faces.astype("<u4"), uvs.astype("<f4")):
                f.write(block if isinstance(block, bytes) else block.tobytes())
        os.replace(tmp, path)
    except BaseException:
        pathlib.Path(tmp).unlink(missing_ok=True)
        raise


def load_coarse(path):
    data = pathlib.Path(path).read_bytes()
    v, f, error = struct.unpack_from("<QQd", data, 0) if len(data) >= 24 else (0, 0, 0.0)
    if len(data) < 24 or len(data) != 24 + 12 * v + 36 * f or not math.isfinite(error):
        raise TilesError(
            "lod/%s of the output folder is damaged (%d bytes, not what its header counts): remove the folder"
            % (pathlib.Path(path).name, len(data))
        )
    at = 24
    positions = np.frombuffer(data, "<f4", 3 * v, at).reshape(v, 3)
    at += 12 * v
    faces = np.frombuffer(data, "<u4", 3 * f, at).reshape(f, 3)
    at += 12 * f
    uvs = np.frombuffer(data, "<f4", 6 * f, at).reshape(f, 3, 2)
    return positions, faces, uvs, error


def clean(faces, uvs):
    """Without faces that repeat a vertex or another face's vertices (welding and collapses make
    some; tailor.Mesh would drop them)."""
    ok = (faces[:, 0] != faces[:, 1]) & (faces[:, 1] != faces[:, 2]) & (faces[:, 0] != faces[:, 2])
    faces, uvs = faces[ok], uvs[ok]
    first = np.sort(np.unique(np.sort(faces, axis=1), axis=0, return_index=True)[1])
    return faces[first], uvs[first]


def simplify(positions, faces, uvs, target):
    """tailor.simplify_uvs on arrays: the open borders (the node's sides) stay where they are. No
    face left after cleaning (faces on vertices that welding joined): empty arrays."""
    faces, uvs = clean(faces, uvs)
    if faces.shape[0] == 0:
        return np.empty((0, 3), np.float32), faces, uvs, 0.0
    r = tailor.simplify_uvs(tailor.Mesh(positions, faces), uvs, max(int(target), 1))
    f, t = clean(r["faces"], r["corner_uvs"])
    return r["positions"], f, t, r["error"]


def kept(keep_from, digest, folder, name, lod, record):
    """Links the previous run's files of this node into folder when its digest is the same and
    each file still has the size that run wrote (a truncated or replaced file is written again);
    record takes the sizes."""
    if not keep_from or keep_from.get("digest") != digest:
        return False
    pairs = [(keep_from["glb"], glb_path(folder, name), "glb_bytes")] if keep_from.get("faces", 1) > 0 else []
    if lod:
        pairs.append((keep_from["coarse"], coarse_path(folder, name), "coarse_bytes"))
    for old, _, size in pairs:
        try:
            if os.path.getsize(old) != keep_from.get(size):
                return False
        except OSError:
            return False
    for old, new, size in pairs:
        if os.path.exists(new):  # a retried task
            os.unlink(new)
        os.link(old, new)
        record[size] = keep_from[size]
    return True


def file_sizes(record, folder, lod):
    """The sizes of the node's files as written, which a later run checks before it keeps them."""
    name = record["name"]
    if record.get("faces", 1) > 0:
        record["glb_bytes"] = os.path.getsize(glb_path(folder, name))
    if lod:
        record["coarse_bytes"] = os.path.getsize(coarse_path(folder, name))
    return record


def finish_node(record, folder, positions, faces, uvs, params, lod, mesh=None):
    """Writes a node's .glb (and, with levels of detail, the quarter its parent starts from); mesh:
    tailor.Mesh(positions, faces) when the caller has it."""
    if mesh is None:
        mesh = tile_mesh(record["name"], positions, faces)
    write_tile_glb(folder, record["name"], mesh, uvs, params)
    if lod:
        p, f, t, error = simplify(positions, faces, uvs, faces.shape[0] / 4)
        save_coarse(coarse_path(folder, record["name"]), p, f, t, error)
        record["coarse_error"] = error
    record["written"] = True
    return file_sizes(record, folder, lod)


def leaf_record(job, positions, faces, params):
    return {
        "name": job["name"],
        "level": 0,
        "tile": job["tile"],
        "digest": tile_digest(positions, faces, params),
        "faces": int(faces.shape[0]),
        # A column at a time: numpy's reduction along axis 0 of 3 columns is several times slower.
        "min": [float(positions[:, k].min()) for k in range(3)],
        "max": [float(positions[:, k].max()) for k in range(3)],
        "error": 0.0,
        "coarse_error": 0.0,
    }


def map_tile(job, positions, faces, params, folder, keep_from, threads, lod):
    """A leaf: puts the tile in its canonical order, maps its chunks and writes tiles/<name>.glb, or
    links the previous run's files when the digest is the same. Returns the node's record."""
    positions, faces = tailor.canonical_tile(positions, faces)
    record = leaf_record(job, positions, faces, params)
    if kept(keep_from, record["digest"], folder, job["name"], lod, record):
        record["coarse_error"] = keep_from.get("coarse_error", 0.0)
        record["written"] = False
        return record
    mapper = make_mapper(params, threads)
    mesh = tile_mesh(job["name"], positions, faces)
    uv = np.empty((faces.shape[0], 3, 2), dtype=np.float32)
    for cell in mapper.set_mesh(mesh):
        chunk = mapper.chunk(cell)
        uv[chunk["faces"]] = chunk["corner_uvs"]
    del mapper
    record = finish_node(record, folder, positions, faces, uv, params, lod, mesh)
    # Test hook: TAILOR_TILES_KILL_ONCE=NAME=MARKER ends this worker process abruptly once, after
    # tile NAME's files are written and before its result is sent (tests/python/test_tiles.py).
    name, _, marker = os.environ.get("TAILOR_TILES_KILL_ONCE", "").partition("=")
    if name == job["name"] and marker and not os.path.exists(marker):
        pathlib.Path(marker).touch()
        os._exit(70)
    return record


def on_worker(task, *args):
    """A Dask task: task(*args)'s record, with the peak memory of the worker process that ran it."""
    record = task(*args)
    record["peak_rss"] = peak_rss()
    return record


def map_tile_file(job, paths, index_dtype, params, folder, keep_from, threads, lod):
    """A leaf from its files of the streamed partition (tiles_stream): read, then map_tile."""
    positions, faces = tiles_stream.read_tile(paths, np.dtype(index_dtype), params["cell_exponent"], params["tile_level"])
    return map_tile(job, positions, faces, params, folder, keep_from, threads, lod)


def run_shared(start, prefix, function, args):
    """function(*a) for each a of args, here and on the cluster at once: this process takes them from
    the front while the cluster, from when it is up, takes them from the back, as many at a time as
    it has threads (the driver need not wait for the cluster's start, nor the cluster for the
    driver). Returns the results in the order of args; raises the failure of the earliest failed."""
    results = [None] * len(args)
    errors = {}
    lock = threading.Lock()
    ends = [0, len(args)]  # the next from the front, one past the next from the back

    def claim(front):
        with lock:
            if ends[0] >= ends[1] or errors:
                return None
            if front:
                ends[0] += 1
                return ends[0] - 1
            ends[1] -= 1
            return ends[1]

    def fail(k, e):
        with lock:
            errors[k] = e

    def cluster_side():
        try:
            # Imported here: the client's thread may still be importing distributed, and this
            # process's share should not wait for it.
            from dask.distributed import as_completed

            client, _ = start.result()
            running, index = as_completed(), {}

            def submit():
                k = claim(False)
                if k is not None:
                    future = client.submit(function, *args[k], key="%s-%d" % (prefix, k))
                    index[future.key] = k
                    running.add(future)

            for _ in range(sum(client.nthreads().values())):
                submit()
            for future in running:
                try:
                    results[index[future.key]] = future.result()
                except Exception as e:
                    fail(index[future.key], e)
                submit()
        except BaseException as e:  # the cluster did not start: raised after this process's share
            fail(len(args), e)

    helper = threading.Thread(target=cluster_side, name="tailor.tiles shared parts", daemon=True)
    helper.start()
    while (k := claim(True)) is not None:
        try:
            results[k] = function(*args[k])
        except Exception as e:
            fail(k, e)
    helper.join()
    if errors:
        raise errors[min(errors)]
    return results


def build_parent(job, params, folder, keep_from, *children):
    """A parent: its children's quarters joined (vertices at one position welded, so that the
    children's shared sides can be simplified) and simplified to a quarter of the children's
    faces; its error is its own simplification's plus the largest a child's content had."""
    children = sorted(children, key=lambda r: r["name"])
    h = hashlib.sha256(json.dumps(params, sort_keys=True).encode())
    for c in children:
        h.update(("%s %s\n" % (c["name"], c["digest"])).encode())
    record = {
        "name": job["name"],
        "level": job["level"],
        "tile": job["tile"],
        "digest": h.hexdigest(),
        "min": np.min([c["min"] for c in children], axis=0).tolist(),
        "max": np.max([c["max"] for c in children], axis=0).tolist(),
        "children": [c["name"] for c in children],
    }
    below = max(c["error"] + c["coarse_error"] for c in children)
    if kept(keep_from, record["digest"], folder, job["name"], True, record):
        record.update(faces=keep_from["faces"], error=keep_from["error"], coarse_error=keep_from["coarse_error"])
        record["written"] = False
        return record
    parts = [load_coarse(coarse_path(folder, c["name"])) for c in children]
    positions = np.concatenate([p[0] for p in parts])
    offsets = np.cumsum([0] + [p[0].shape[0] for p in parts])
    faces = np.concatenate([p[1].astype(np.int64) + offsets[k] for k, p in enumerate(parts)])
    uvs = np.concatenate([p[2] for p in parts])
    positions, inverse = np.unique(positions, axis=0, return_inverse=True)
    faces = inverse.reshape(-1)[faces].astype(np.uint32)
    p, f, t, error = simplify(positions, faces, uvs, sum(c["faces"] for c in children) / 4)
    record.update(faces=int(f.shape[0]), error=below + error)
    if f.shape[0] == 0:  # the children's copies collapse where they are welded: a node without content
        save_coarse(coarse_path(folder, job["name"]), p, f, t, 0.0)
        record.update(coarse_error=0.0, written=True)
        return file_sizes(record, folder, True)
    return finish_node(record, folder, p, f, t, params, True)


def map_in_process(jobs, order, params, folder, threads, lod):
    """--workers 0: the tiles to write mapped together by one ChunkedMapper.set_mesh (the library's
    chunked map, its chunks in parallel on `threads` threads), then written one by one. Yields
    (job index, record) in `order`."""
    pending = []
    jobs = list(jobs)
    for i in order:
        job, p, f, keep = jobs[i]
        p, f = tailor.canonical_tile(p, f)
        jobs[i] = (job, p, f, keep)
        if keep and keep.get("digest") == tile_digest(p, f, params):
            yield i, map_tile(job, p, f, params, folder, keep, threads, lod)
        else:
            pending.append(i)
    if not pending:
        return
    offsets = np.cumsum([0] + [jobs[i][1].shape[0] for i in pending])
    face_offsets = np.cumsum([0] + [jobs[i][2].shape[0] for i in pending])
    positions = np.concatenate([jobs[i][1] for i in pending])
    faces = np.concatenate([jobs[i][2] + np.uint32(offsets[k]) for k, i in enumerate(pending)])
    mapper = make_mapper(params, threads)
    uv = np.empty((faces.shape[0], 3, 2), dtype=np.float32)
    for cell in mapper.set_mesh(tailor.Mesh(positions, faces)):
        chunk = mapper.chunk(cell)
        uv[chunk["faces"]] = chunk["corner_uvs"]
        mapper.remove_chunk(cell)
    del mapper
    for k, i in enumerate(pending):
        job, p, f, _ = jobs[i]
        record = leaf_record(job, p, f, params)
        yield i, finish_node(record, folder, p, f, uv[face_offsets[k] : face_offsets[k + 1]], params, lod)


def parent_levels(leaves):
    """The parents above the leaf tiles: level L groups the tiles whose coordinates agree after a
    shift by L (2 x 2 x 2 blocks), up to one root, or to the level where grouping stops helping
    (tiles on both sides of a zero coordinate never meet). Returns [[(tile, child names)], ...]."""
    levels = []
    below = {tuple(t): node_name(0, t) for t in leaves}
    level = 0
    while len(below) > 1 and level < 40:
        level += 1
        groups = {}
        for tile, name in sorted(below.items(), key=lambda item: item[1]):
            groups.setdefault(tuple(v >> 1 for v in tile), []).append(name)
        if len(groups) == len(below) and level > 1:
            break
        levels.append(sorted(groups.items(), key=lambda g: (g[0][2], g[0][1], g[0][0])))
        below = {tile: node_name(level, tile) for tile in groups}
    return levels


# === The tileset ===


def box_volume(lo, hi, up):
    """A 3D Tiles box around the mesh's coordinates lo..hi, in the tileset's Z-up frame. A client
    turns glTF content from Y up to Z up (x, y, z -> x, -z, y: 3D Tiles 1.1, "y-up to z-up") after
    the glTF node's transform. up "y": the coordinates are the glTF's, so the box is turned the
    same way; up "z": the node turns Z-up coordinates Y up (x, y, z -> x, z, -y), the client turns
    them back, and the box is in the mesh's own coordinates."""
    c = [(a + b) / 2 for a, b in zip(lo, hi)]
    h = [max((b - a) / 2, 1e-9) for a, b in zip(lo, hi)]
    if up == "z":
        return {"box": [c[0], c[1], c[2], h[0], 0, 0, 0, h[1], 0, 0, 0, h[2]]}
    return {"box": [c[0], -c[2], c[1], h[0], 0, 0, 0, h[2], 0, 0, 0, h[1]]}


def tileset_json(records, lod, up):
    """Leaves under their parents (refine REPLACE: a parent's simplified copy gives way to its
    children), or, without levels of detail, every leaf under one root (refine ADD)."""
    by_name = {r["name"]: r for r in records}
    lo = np.min([r["min"] for r in records], axis=0).tolist()
    hi = np.max([r["max"] for r in records], axis=0).tolist()
    diagonal = float(np.linalg.norm(np.subtract(hi, lo)))

    def node(r):
        out = {"boundingVolume": box_volume(r["min"], r["max"], up), "geometricError": float(r["error"])}
        if r["faces"] > 0:
            out["content"] = {"uri": "tiles/%s.glb" % r["name"]}
        if r.get("children"):
            out["refine"] = "REPLACE"
            out["children"] = [node(by_name[c]) for c in r["children"]]
        return out

    top_level = max(r["level"] for r in records) if lod else 0
    top = [r for r in records if r["level"] == top_level]
    if lod and len(top) == 1:
        root = node(top[0])
        error = max(root["geometricError"], diagonal)  # a client far away still shows the root
    else:
        root = {
            "boundingVolume": box_volume(lo, hi, up),
            "geometricError": diagonal,
            "refine": "REPLACE" if lod else "ADD",
            "children": [node(r) for r in top],
        }
        error = diagonal
    return {
        "asset": {"version": "1.1", "generator": "tailor %s (python3 -m tailor.tiles)" % tailor.__version__},
        "geometricError": error,
        "root": root,
    }


# === The run ===


PNG_SIGNATURE = b"\x89PNG\r\n\x1a\n"


def texture_image(path, notes, direction):
    """(suffix, bytes, [width, height], (field_following, crack_rings) that auto picks for it, or None
    without `direction`) of an image every tile names by URI, from one decoding: decoded whole as
    tailor map reads a texture (a truncated or corrupt file is an error here, not in a client's
    viewer), and PNG or JPEG, the images glTF allows, named by what its bytes are rather than by its
    file name. What tailor map says of a texture that does not wrap goes to notes."""
    try:
        width, height, wrap, following, rings = tailor._tailor._texture_look(path, os.fsdecode(path), direction)
    except tailor.Error as e:
        raise TilesError(str(e)) from None
    if wrap:
        notes.append(wrap)
    data = pathlib.Path(path).read_bytes()
    auto = (following, rings) if direction else None
    if data.startswith(PNG_SIGNATURE):
        return ".png", data, [width, height], auto
    if data.startswith(b"\xff\xd8\xff"):
        return ".jpg", data, [width, height], auto
    raise TilesError("%s: texture is neither PNG nor JPEG" % path)


def read_look(args):
    """What every tile's material shows, read once: images {role: (file name in tiles/,
    bytes)} (color, normal, orm), orm_roles (what the orm image serves as), size (the repeat in
    pixels, None without a texture) and auto ((field_following, crack_rings) that --field-following
    auto picks for the colour map, None without one or when the flag is a number)."""
    look = {"images": {}, "orm_roles": [], "size": None, "auto": None, "notes": []}
    direction = args.field_following == "auto"  # measured only for auto
    if args.texture:
        suffix, data, look["size"], look["auto"] = texture_image(args.texture, look["notes"], direction)
        look["images"]["color"] = ("texture" + suffix, data)
    elif args.material:
        m = tailor.load_material(args.material)
        look["size"] = [m["width"], m["height"]]
        look["notes"] = list(m["notes"])
        if m["symmetry"] == 4:
            look["notes"].append(
                "%s records quarter-turn tiles (symmetry 4); the tiles map them as plain tiles (symmetry 1)"
                % args.material
            )
        if m["color"]:
            suffix, data, _, look["auto"] = texture_image(m["color"], look["notes"], direction)
            look["images"]["color"] = ("material_color" + suffix, data)
        if m["normal_png"]:
            look["images"]["normal"] = ("material_normal.png", m["normal_png"])
        if m["orm_png"]:
            look["images"]["orm"] = ("material_orm.png", m["orm_png"])
            roles = (("occlusion", m["orm_occlusion"]), ("roughness_metallic", m["orm_roughness_metallic"]))
            look["orm_roles"] = [role for role, used in roles if used]
    return look


def plan_tiles(mesh, args, look):
    """The tiles: {tile: face ids}, and the parameters every tile's digest and mapping use."""
    plan = tailor.plan_chunks(mesh, args.chunk_cell)
    params = tile_params(args, look, plan["cell_exponent"], lambda: texels_per_unit_for(mesh, args.scale))
    level = params["tile_level"]
    tiles = {}
    cells = plan["cells"] >> level  # arithmetic shift: floor division by 2**level
    start, faces = plan["chunk_start"], plan["faces"]
    for k in range(cells.shape[0]):
        tiles.setdefault(tuple(int(v) for v in cells[k]), []).append(faces[start[k] : start[k + 1]])
    tiles = {t: np.concatenate(parts) for t, parts in tiles.items()}
    return plan, params, tiles


def tile_params(args, look, e, density):
    """The parameters every tile's digest and mapping use, for cell exponent e; density() gives the
    texel density of --scale (read only without --texels-per-unit)."""
    if args.tile_size is None:
        level = 0
    else:
        t = math.log2(args.tile_size) if args.tile_size > 0 else float("nan")
        if not (t == math.floor(t)) or t < e:
            raise TilesError(
                "--tile-size must be the chunk cell (%g) times a power of two, got %r" % (math.ldexp(1.0, e), args.tile_size)
            )
        level = int(t) - e
        if level > MAX_TILE_LEVEL:
            raise TilesError(
                "--tile-size %g is 2^%d chunk cells of %g; at most 2^%d" % (args.tile_size, level, math.ldexp(1.0, e),
                                                                             MAX_TILE_LEVEL)
            )
    tpu = args.texels_per_unit if args.texels_per_unit is not None else density()
    width, height = look["size"] if look["size"] else (args.texture_size, args.texture_size)
    field_following, crack_rings = resolve_field_following(args, look["auto"])
    params = {
        "format": FORMAT,
        "tailor": tailor.__version__,
        "cell_exponent": e,
        "tile_level": level,
        "texels_per_unit": float(np.float32(tpu)),
        "texture_size": [int(width), int(height)],
        "field_following": field_following,
        "max_stretch": args.max_stretch,
        "crack_rings": crack_rings,
        "lod": args.lod,
        "up": args.up,
        "images": {role: name for role, (name, _) in look["images"].items()},
        "orm_roles": look["orm_roles"],
    }
    return params


def resolve_field_following(args, auto):
    """(field_following, crack_rings) as tailor map resolves them: auto follows the direction of the
    texture (or of the material's colour map): `auto`, what read_look found for it (None without one)."""
    if args.field_following != "auto":  # a number in [0, 1] (parse_args)
        return float(args.field_following), args.crack_rings
    if auto is None:
        return 1.0, args.crack_rings
    value, rings = auto
    return float(value), (args.crack_rings if args.crack_rings is not None else int(rings))


class Progress:
    """`tiles: 12/40 (3 kept)` on one terminal line, updated in place; nothing when not a terminal."""

    def __init__(self, total, enabled):
        self.total, self.done, self.kept = total, 0, 0
        self.enabled = enabled and sys.stderr.isatty()
        self.last = 0.0

    def step(self, written):
        self.done += 1
        self.kept += 0 if written else 1
        now = time.monotonic()
        if self.enabled and (now - self.last > 0.1 or self.done == self.total):
            self.last = now
            bar = "#" * (30 * self.done // self.total)
            sys.stderr.write("\rtiles [%-30s] %d/%d (%d kept)" % (bar, self.done, self.total, self.kept))
            if self.done == self.total:
                sys.stderr.write("\n")
            sys.stderr.flush()


# What a folder of tiles holds: anything else in OUTDIR is not this tool's, and a run (which replaces
# the folder) refuses to delete it.
OWN_ENTRIES = {MANIFEST, "tileset.json"}
# The names of the images every tile names: in tiles/ (at the top before manifest format 3).
OWN_IMAGES = re.compile(r"(texture|material_color|material_normal|material_orm)\.(png|jpg)")
# The folders of tiles and of their simplified copies, and the names of the files in each.
OWN_FOLDERS = {
    "tiles": re.compile(r"\d+(_-?\d+){3}\.glb"),
    "lod": re.compile(r"\d+(_-?\d+){3}\.bin"),
}


def foreign_entry(outdir, old_params):
    """The first entry of outdir (a path relative to it) that a run does not write, or None.
    old_params: the manifest's parameters (None when unreadable), which say the images the run that
    wrote the folder named and where it put them (tiles/; the top before manifest format 3); an image
    of another name or place is the user's."""
    places, names = {"tiles", "top"}, None  # unreadable: any image name, in either place
    if isinstance(old_params, dict) and isinstance(old_params.get("images"), dict):
        format_ = old_params.get("format")
        places = {"top"} if isinstance(format_, int) and format_ < 3 else {"tiles"}
        names = {name for name in old_params["images"].values() if isinstance(name, str)}

    def own_image(name, place):
        return place in places and OWN_IMAGES.fullmatch(name) and (names is None or name in names)

    for entry in sorted(outdir.iterdir()):
        if entry.name in OWN_FOLDERS and entry.is_dir() and not entry.is_symlink():
            for inner in sorted(entry.iterdir()):
                own = OWN_FOLDERS[entry.name].fullmatch(inner.name) or (
                    entry.name == "tiles" and own_image(inner.name, "tiles")
                )
                if not (own and inner.is_file() and not inner.is_symlink()):
                    return "%s/%s" % (entry.name, inner.name)
        elif not ((entry.name in OWN_ENTRIES or own_image(entry.name, "top")) and entry.is_file()):
            return entry.name
    return None


def previous_output(outdir, params):
    """{tile name: its record and paths} of an earlier run into outdir with the same parameters (a
    record of the wrong shape is left out: that tile is written again). TilesError when outdir holds
    anything such a run does not write: replacing the folder would delete it."""
    if not outdir.exists():
        return {}
    manifest = outdir / MANIFEST
    if not manifest.is_file():
        if any(outdir.iterdir()):
            raise TilesError("%s exists and is not a folder of tiles written by tailor.tiles" % outdir)
        return {}
    try:
        old = json.loads(manifest.read_text())
    except ValueError:
        old = None
    foreign = foreign_entry(outdir, old.get("params") if isinstance(old, dict) else None)
    if foreign is not None:
        raise TilesError(
            "%s holds %s, which is not part of its tileset (a run replaces the folder): move it, or write "
            "the tiles elsewhere" % (outdir, foreign)
        )
    if not isinstance(old, dict) or old.get("params") != params or not isinstance(old.get("tiles"), dict):
        return {}
    out = {}
    for name, r in old["tiles"].items():
        if is_record(r):
            out[name] = dict(r, glb=str(glb_path(outdir, name)), coarse=str(coarse_path(outdir, name)))
    return out


def is_record(r):
    """Whether a manifest's tile record has the fields a kept tile reuses, of their types."""

    def number(x):
        return isinstance(x, (int, float)) and not isinstance(x, bool) and math.isfinite(x)

    return (
        isinstance(r, dict)
        and isinstance(r.get("digest"), str)
        and isinstance(r.get("faces"), int)
        and not isinstance(r.get("faces"), bool)
        and r["faces"] >= 0
        and number(r.get("error"))
        and number(r.get("coarse_error"))
    )


def lock_outdir(outdir, given):
    """Takes an exclusive lock on OUTDIR's lock file beside it (.NAME.lock) for the run: two runs into
    one folder would each link the other's tiles as their own. Returns (descriptor, path) for
    unlock_outdir; TilesError when another run holds it."""
    import fcntl

    path = outdir.parent / (".%s.lock" % outdir.name)
    while True:
        try:
            fd = os.open(path, os.O_RDWR | os.O_CREAT | os.O_CLOEXEC, 0o644)
        except OSError as e:
            raise TilesError("%s: cannot write beside it in %s (%s)" % (given, outdir.parent, e.strerror)) from None
        try:
            fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
        except BlockingIOError:
            os.close(fd)
            raise TilesError("%s: another tailor.tiles run is writing it" % given) from None
        except OSError as e:  # a file system without locks: the run goes on, unguarded
            print("tailor.tiles: warning: %s: cannot lock %s (%s): make sure no other run writes it"
                  % (given, path, e.strerror), file=sys.stderr)
            return fd, path
        try:
            if os.stat(path).st_ino == os.fstat(fd).st_ino:
                return fd, path
        except FileNotFoundError:
            pass
        os.close(fd)  # the run that held it removed the file meanwhile: lock the one there now


def unlock_outdir(lock):
    """Removes the lock file, then releases it (a run that opened the removed file sees that and
    takes the new one)."""
    fd, path = lock
    try:
        os.unlink(path)
    except OSError:
        pass
    os.close(fd)


def remove_stale(outdir):
    """The temporary and set-aside folders a run killed beside OUTDIR left (.NAME.tmp-PID,
    .NAME.old-PID): with the lock held, no live run owns them."""
    for kind in ("tmp", "old"):
        for path in outdir.parent.glob(".%s.%s-*" % (glob.escape(outdir.name), kind)):
            if path.name.rsplit("-", 1)[1].isdigit() and path.is_dir() and not path.is_symlink():
                shutil.rmtree(path, ignore_errors=True)


def start_client(args, space=None):
    """A Dask client: of the scheduler args.scheduler names, else of a local cluster of args.workers
    processes, whose folders for spilled data and locks are made inside `space` when given (Dask's
    default is one folder of the temporary directory that every cluster shares: a cluster's workers
    remove the locks a killed run left there, with a line each on the terminal). Returns (client,
    the local cluster or None)."""
    import dask
    from dask.distributed import Client, LocalCluster

    # For each task submitted, Dask's client reads the source of the first function on the stack
    # outside its ignored modules (for its dashboard): run_locked(), hundreds of lines tokenized per
    # task, or the whole script. Leaving out tailor, the script that runs it and the partition's
    # helper thread, it finds none. (Process-wide, as the settings below: a script that calls
    # main() is left out of the dashboard's code view too.)
    ignored = list(dask.config.get("distributed.diagnostics.computations.ignore-modules", []))
    ignored += [m for m in (r"tailor(\.|$)", "__main__", "runpy", "threading") if m not in ignored]
    dask.config.set({"distributed.diagnostics.computations.ignore-modules": ignored})
    if args.scheduler:
        try:
            return Client(args.scheduler), None
        except (ValueError, OSError, TimeoutError) as e:
            raise TilesError("--scheduler %s: %s" % (args.scheduler, e)) from None
    # Dask starts workers with MALLOC_TRIM_THRESHOLD_=65536, which turns off glibc's adaptive mmap
    # threshold: every large buffer of the mapping is then mapped and unmapped per tile (page
    # faults: 20-30 % more time on the 6.2 M-face horse). The workers here keep glibc's default.
    environ = dict(dask.config.get("distributed.nanny.pre-spawn-environ"))
    environ.pop("MALLOC_TRIM_THRESHOLD_", None)
    # Dask's monitors wake every process of the cluster many times a second: the statistical
    # profiler samples each task's stack every 10 ms, the event-loop watchdog ticks every 20 ms, the
    # memory monitor reads /proc every 100 ms. Beside tasks that keep every core busy they took
    # 11-18 % of the CPU (a worker's event loop 5.5 % of a core, the scheduler's 7.5 %); the tasks
    # here are seconds long and need none of that resolution.
    dask.config.set(
        {
            "distributed.nanny.pre-spawn-environ": environ,
            "distributed.worker.profile.enabled": False,
            "distributed.admin.tick.interval": "1s",
            "distributed.admin.system-monitor.interval": "2s",
            "distributed.worker.memory.monitor-interval": "1s",
        }
    )
    # The workers are forked from one server process that imported Dask, numpy and tailor once
    # (Python's forkserver), not each started afresh: on 2 cores the workers' start took 0.85 s of
    # processor time beside the driver's partition, 0.43 s forked. Only this start (a worker the
    # nanny starts again later is spawned), and the server preloads what the workers import, not
    # Dask's list (every optional package installed, pandas among them, imported into this process
    # first); where distributed has no such list, its own preload stands.
    import distributed.utils

    if getattr(distributed.utils, "_forkserver_preload_set", True) is False:
        multiprocessing.get_context("forkserver").set_forkserver_preload(
            ["distributed", "numpy", "tailor"]
        )
        distributed.utils._forkserver_preload_set = True
    # The scheduler's HTTP server (its health and metrics routes, no dashboard) on a free port: on
    # Dask's default, 8787, a second run at the same time printed a four-line warning.
    with dask.config.set({"distributed.worker.multiprocessing-method": "forkserver"}):
        cluster = LocalCluster(
            n_workers=args.workers,
            threads_per_worker=1,
            processes=True,
            dashboard_address=":0",
            scheduler_kwargs={"dashboard": False},
            silence_logs=logging.ERROR,
            local_directory=None if space is None else str(space),
        )
    client = Client(cluster)
    client.register_worker_plugin(_DriverAnswersInterrupts(), name="tailor-driver-answers-interrupts")
    return client, cluster


class _DriverAnswersInterrupts:
    """A Dask worker plugin for the local cluster's worker processes: Ctrl-C reaches every process
    of the terminal's group, and each worker printed a KeyboardInterrupt traceback while the driver
    closed the cluster. The driver alone answers it (setup runs on the worker's event loop, its
    process's main thread)."""

    def setup(self, worker):
        signal.signal(signal.SIGINT, signal.SIG_IGN)


class ClientStart:
    """start_client in a thread of its own, started while the driver still surveys and cuts the mesh:
    the local cluster's worker processes start and import tailor meanwhile, their folders in one of
    the run's own in the temporary directory (unless Dask's temporary-directory setting names
    another). result() waits for the start; close() waits too, then closes what it started and
    removes that folder."""

    def __init__(self, args):
        self.client = self.cluster = self.error = self.space = None
        self.closed = False
        self.before = {p.pid for p in multiprocessing.active_children()}  # not the cluster's
        self.thread = threading.Thread(target=self._run, args=(args,), name="tailor.tiles client", daemon=True)
        self.thread.start()

    def _run(self, args):
        try:
            # This thread, and so every process and thread it starts (the workers, the server they
            # are forked from, multiprocessing's resource tracker), holds the signals that a
            # terminal or a service manager sends to the whole process group blocked: the driver
            # answers them alone, closes the cluster (Dask stops a worker through a queue, and kills
            # it when that does not end it) and says so in one line. Workers that died of such a
            # signal printed their tracebacks, and their nannies started them again while the
            # driver closed the cluster, which could then wait for them at exit for minutes.
            signal.pthread_sigmask(signal.SIG_BLOCK, GROUP_SIGNALS)
            if not args.scheduler:
                # multiprocessing's resource tracker first: starting it unblocks SIGINT and SIGTERM in
                # the thread that starts it (Python's bpo-33613 guard), so they are blocked again
                # after it, before this thread starts any other process or thread. The tracker
                # itself ignores those two and keeps SIGHUP blocked.
                multiprocessing.resource_tracker.ensure_running()
                signal.pthread_sigmask(signal.SIG_BLOCK, GROUP_SIGNALS)
                import dask

                if not dask.config.get("temporary-directory", None):
                    self.space = tempfile.mkdtemp(prefix="tailor-tiles-")
            self.client, self.cluster = start_client(args, self.space)
            if self.cluster is not None:
                self.client.run(worker_ready)  # each worker imports tailor.tiles now, not at its first task
        except BaseException as e:  # raised again by result()
            self.error = e

    def result(self):
        self.thread.join()
        if self.error is not None:
            raise self.error
        return self.client, self.cluster

    def close(self):
        # Bounded, and waited for once: a start that cannot finish (a scheduler that does not
        # answer) must not hold the driver's exit (the thread is a daemon). A later close closes
        # what the start made by then.
        self.thread.join(0 if self.closed else CLIENT_CLOSE_WAIT)
        self.closed = True
        started = not self.thread.is_alive()
        try:
            if started:
                client, cluster, self.client, self.cluster = self.client, self.cluster, None, None
                if client is not None:
                    client.close()
                if cluster is not None:
                    cluster.close()
        finally:
            self.kill_left_workers()
            # After the cluster's close only: a nanny still open starts its worker again, which
            # makes the folder anew.
            if started and self.space is not None:
                shutil.rmtree(self.space, ignore_errors=True)

    def kill_left_workers(self):
        """Kills the worker processes of the cluster still alive after its close (one cut short by a
        second Ctrl-C, a start left behind): they hold SIGTERM blocked, and multiprocessing's exit
        hook, which ends its daemon children with SIGTERM and then waits for them, would wait
        forever."""
        for p in multiprocessing.active_children():
            if p.pid not in self.before:
                with contextlib.suppress(Exception):
                    p.kill()


def worker_ready():
    """Run on each worker of the local cluster once it is up: unpickling this function imports
    tailor.tiles (numpy, the library) there."""
    return os.getpid()


def peak_rss():
    """This process's peak resident memory in bytes (the driver's in run(), a worker's in a task):
    VmHWM, not getrusage's ru_maxrss, which execve keeps from the parent that forked this process."""
    try:
        with open("/proc/self/status") as f:
            for line in f:
                if line.startswith("VmHWM:"):
                    return int(line.split()[1]) * 1024
    except OSError:
        pass
    import resource

    return resource.getrusage(resource.RUSAGE_SELF).ru_maxrss * 1024


def check_outdir(outdir, given):
    """TilesError when OUTDIR cannot be written as a folder of tiles: the folder is renamed into
    place beside it, so its parent must be a writable folder, and OUTDIR itself a folder if it
    exists."""
    if outdir.exists() and not outdir.is_dir():
        raise TilesError("%s: exists and is not a folder" % given)
    if not outdir.parent.is_dir():
        raise TilesError("%s: the folder it would be in, %s, does not exist" % (given, outdir.parent))


def run(args):
    """The whole command (main() without its printing): the summary."""
    outdir = pathlib.Path(args.output).resolve()
    check_outdir(outdir, args.output)
    for given in (args.input, args.texture, args.material):
        source = pathlib.Path(given).resolve() if given else None
        if source is not None and (source == outdir or outdir in source.parents):
            raise TilesError("%s is inside %s, which a run replaces" % (given, args.output))
    lock = lock_outdir(outdir, args.output)
    try:
        remove_stale(outdir)
        return run_locked(args, outdir)
    finally:
        unlock_outdir(lock)


def warn_dropped(args, degenerate, duplicate):
    """tailor map's warnings of the faces the load drops (a streamed input learns the duplicates
    only from its tiles, after the map)."""
    if args.quiet:
        return
    for count, kind in ((degenerate, "degenerate"), (duplicate, "duplicate")):
        if count:
            print("tailor.tiles: warning: %s: dropped %d %s faces" % (args.input, count, kind), file=sys.stderr)


def warn_look(args, look):
    """The texture's or material's warnings, after the mesh's as tailor map orders them."""
    if not args.quiet:
        for note in look["notes"]:
            print("tailor.tiles: warning: %s" % note, file=sys.stderr)


def run_locked(args, outdir):
    t0 = time.monotonic()
    # A binary little-endian PLY of triangles is partitioned by streaming it (tiles_stream); any
    # other input is loaded whole and cut in memory (--in-memory, hidden, forces that for tests).
    layout = None if args.in_memory else tiles_stream.read_layout(args.input)
    mesh = None
    if layout is None:
        try:
            mesh = tailor.load(args.input)
        except tailor.Error as e:
            raise TilesError(str(e)) from None
    look = read_look(args)
    if not args.quiet:
        if mesh is not None and mesh.load_report["not_read"]:  # as tailor map warns of the same file
            print("tailor.tiles: warning: %s: not read: %s" % (args.input, mesh.load_report["not_read"]), file=sys.stderr)
    if mesh is not None:  # a streamed input's, after its survey (run_started)
        warn_dropped(args, mesh.load_report["degenerate_faces"], mesh.load_report["duplicate_faces"])
        warn_look(args, look)
    tmp = temporary_folder(outdir)
    start = None
    try:  # from the folder's creation on: a failure or a signal closes the cluster and removes it
        shutil.rmtree(tmp, ignore_errors=True)
        try:
            (tmp / "tiles").mkdir(parents=True)
        except OSError as e:
            raise TilesError(
                "%s: cannot write beside it in %s (%s)" % (args.output, outdir.parent, e.strerror)
            ) from None
        if not maps_in_process(args) and not args.cut_only:
            # The cluster starts in a thread of its own once the input's header is read (a streamed
            # PLY) or the mesh loaded: its worker processes start and import tailor while this
            # process surveys and cuts the mesh.
            start = ClientStart(args)
        summary = run_started(args, outdir, tmp, t0, layout, mesh, look, start)
    except BaseException:
        # The cluster first: a worker still running a task would write into the folder after it is
        # removed (a stray temporary folder beside OUTDIR until the next run). The folder goes even
        # when closing fails or a second Ctrl-C cuts it short.
        try:
            if start is not None:
                start.close()
        finally:
            shutil.rmtree(tmp, ignore_errors=True)
        raise
    finally:
        if start is not None:
            start.close()
    if not args.cut_only:  # the cluster's close included
        summary["seconds"]["total"] = time.monotonic() - t0
    return summary


def temporary_folder(outdir):
    """Where a run writes its output before renaming it into place as OUTDIR."""
    return outdir.parent / (".%s.tmp-%d" % (outdir.name, os.getpid()))


def maps_in_process(args):
    """--workers 0 without --scheduler: the tiles are mapped in this process, without Dask."""
    return args.workers == 0 and not args.scheduler


def run_started(args, outdir, tmp, t0, layout, mesh, look, start):
    """run_locked's work once the temporary folder tmp is made and the cluster (start) starting."""
    in_process = maps_in_process(args)
    if mesh is not None:
        plan, params, tiles = plan_tiles(mesh, args, look)
        chunk_count, cell_size = int(plan["cells"].shape[0]), plan["cell_size"]
        far = tailor._tailor._far_from_origin_warning(mesh)
    else:
        survey = tiles_stream.survey(layout, args.chunk_cell, args.block_faces)
        warn_dropped(args, layout.face_count - survey["faces"], 0)  # those that repeat a vertex
        warn_look(args, look)
        largest = float(max(np.abs(survey["lo"]).max(), np.abs(survey["hi"]).max()))
        far = tailor._tailor._far_from_origin_warning(largest, survey["about_median"])
        params = tile_params(
            args, look, survey["cell_exponent"], lambda: texels_per_unit_of_box(survey["lo"], survey["hi"], args.scale)
        )
        cell_size = math.ldexp(1.0, survey["cell_exponent"])
    if far and not args.quiet:
        print("tailor.tiles: warning: %s" % far, file=sys.stderr)
    old = previous_output(outdir, params)
    t_plan = time.monotonic()

    # The images every tile names, once in tiles/ (the previous run's file linked when it has the
    # same bytes, so that it keeps its time).
    for name, data in look["images"].values():
        previous = image_path(outdir, name)
        if previous.is_file() and previous.read_bytes() == data:
            os.link(previous, image_path(tmp, name))
        else:
            image_path(tmp, name).write_bytes(data)
    if args.lod:
        (tmp / "lod").mkdir()
    jobs = []
    scratch = tmp / "partition"
    if mesh is not None:
        positions = mesh.positions
        faces = mesh.faces
        for tile in sorted(tiles, key=lambda t: (t[2], t[1], t[0])):
            # The tile's own vertices; its canonical order is the task's work (in parallel).
            used, compact = np.unique(faces[tiles[tile]], return_inverse=True)
            p, f = positions[used], compact.reshape(-1, 3).astype(np.uint32)
            name = node_name(0, tile)
            jobs.append(({"name": name, "tile": list(tile)}, p, f, old.get(name)))
        del positions, faces, mesh
        sizes = [job[2].shape[0] for job in jobs]
    else:
        # One pass: each face appended to its tile's file in the scratch folder. With a local
        # cluster the file is cut into ranges of a few blocks, shared between this process and
        # the cluster's workers (a cluster of --scheduler may not see the input file).
        parts, run_parts = 1, None
        if start is not None and not args.scheduler:
            parts = PARTITION_PARTS
            run_parts = functools.partial(run_shared, start, "partition-%s" % tmp.name)
        counts, files, chunk_count = tiles_stream.partition_parts(
            layout, params["cell_exponent"], params["tile_level"], scratch, parts, run_parts, args.block_faces
        )
        index_dtype = layout.index_dtype.str
        for tile in sorted(counts, key=lambda t: (t[2], t[1], t[0])):
            name = node_name(0, tile)
            if in_process:  # mapped in this process: all of them
                p, f = tiles_stream.read_tile(
                    files[tile], layout.index_dtype, params["cell_exponent"], params["tile_level"]
                )
                jobs.append(({"name": name, "tile": list(tile)}, p, f, old.get(name)))
            else:
                jobs.append(({"name": name, "tile": list(tile), "files": files[tile]}, None, None, old.get(name)))
        sizes = [counts[tuple(job[0]["tile"])] for job in jobs]
        partitioned = sum(counts.values())
    levels = parent_levels([job[0]["tile"] for job in jobs]) if args.lod else []
    t_cut = time.monotonic()
    if args.cut_only:  # tests: the driver's work without the tasks; nothing is written
        shutil.rmtree(tmp, ignore_errors=True)
        return {
            "leaves": len(sizes),
            "faces": int(sum(sizes)),
            "input": "streamed" if layout is not None else "in memory",
            "driver_peak_rss": peak_rss(),
            "seconds": {"load_plan": t_plan - t0, "cut": t_cut - t_plan},
        }
    # Largest first, so that the last tasks to finish are small ones.
    order = sorted(range(len(jobs)), key=lambda i: -sizes[i])
    progress = Progress(len(jobs) + sum(len(groups) for groups in levels), not args.quiet)
    records = {}
    folder = str(tmp)
    if in_process:
        for i, record in map_in_process(jobs, order, params, folder, args.threads, args.lod):
            records[record["name"]] = record
            progress.step(record["written"])
        for level, groups in enumerate(levels, start=1):
            for tile, names in groups:
                job = {"name": node_name(level, tile), "level": level, "tile": list(tile)}
                kids = [records[n] for n in names]
                record = build_parent(job, params, folder, old.get(job["name"]), *kids)
                records[job["name"]] = record
                progress.step(record["written"])
    else:
        from dask.distributed import as_completed

        client, _ = start.result()
        threads = args.threads or 1
        futures = {}
        for i in order:
            job, p, f, keep = jobs[i]
            key = "tile-%s-%s" % (tmp.name, job["name"])
            if "files" in job:
                job = dict(job)
                paths = job.pop("files")
                futures[job["name"]] = client.submit(
                    on_worker,
                    map_tile_file,
                    job,
                    paths,
                    index_dtype,
                    params,
                    folder,
                    keep,
                    threads,
                    args.lod,
                    key=key,
                )
            else:
                # A tile loaded whole goes to its worker in the task itself (scattering it first
                # would send the same bytes); Dask warns about every such task of over 1 MB.
                with warnings.catch_warnings():
                    warnings.filterwarnings("ignore", message="Large object of size", category=UserWarning)
                    futures[job["name"]] = client.submit(
                        on_worker, map_tile, job, p, f, params, folder, keep, threads, args.lod, key=key
                    )
        del jobs[:]
        for level, groups in enumerate(levels, start=1):
            for tile, names in groups:
                job = {"name": node_name(level, tile), "level": level, "tile": list(tile)}
                kids = [futures[n] for n in names]
                futures[job["name"]] = client.submit(
                    on_worker,
                    build_parent,
                    job,
                    params,
                    folder,
                    old.get(job["name"]),
                    *kids,
                    key="tile-%s-%s" % (tmp.name, job["name"]),
                )
        for fut in as_completed(list(futures.values())):
            record = fut.result()
            records[record["name"]] = record
            progress.step(record["written"])
        # The cluster closed before the folder is finished: when a worker died, Dask computes
        # again the results it held, and such a task, still running, would write into the folder
        # after it is renamed into place (a stray temporary file in OUTDIR).
        futures.clear()
        start.close()
    records = sorted(records.values(), key=lambda r: (-r["level"], r["tile"][2], r["tile"][1], r["tile"][0]))
    shutil.rmtree(scratch, ignore_errors=True)
    # A worker process that died while writing a file (killed, out of memory) leaves that
    # write's temporary file (".tailor-XXXXXX", beside its target); every node is written now
    # (its task ran again elsewhere), so those are stray.
    for stray in tmp.rglob(".tailor-*"):
        stray.unlink(missing_ok=True)
    t_map = time.monotonic()
    (tmp / "tileset.json").write_text(json.dumps(tileset_json(records, args.lod, args.up), indent=1) + "\n")
    fields = ("digest", "faces", "error", "coarse_error", "glb_bytes", "coarse_bytes")
    manifest = {"params": params, "tiles": {r["name"]: {k: r[k] for k in fields if k in r} for r in records}}
    (tmp / MANIFEST).write_text(json.dumps(manifest, indent=1, sort_keys=True) + "\n")
    # Into place: the old folder aside, the new one in, the old one removed.
    aside = None
    if outdir.exists():
        aside = outdir.parent / (".%s.old-%d" % (outdir.name, os.getpid()))
        os.rename(outdir, aside)
    os.rename(tmp, outdir)
    if aside:
        shutil.rmtree(aside, ignore_errors=True)
    written = sum(1 for r in records if r["written"])
    if layout is not None:  # the tiles' tasks dropped the faces that repeat another's vertices
        warn_dropped(args, 0, partitioned - sum(int(r["faces"]) for r in records if r["level"] == 0))
    summary = {
        "tiles": len(records),
        "leaves": len(sizes),
        "levels": 1 + len(levels),
        "written": written,
        "kept": len(records) - written,
        "faces": sum(int(r["faces"]) for r in records if r["level"] == 0),
        "chunks": chunk_count,
        "cell_size": cell_size,
        "tile_size": cell_size * 2 ** params["tile_level"],
        "input": "streamed" if layout is not None else "in memory",
        "texels_per_unit": params["texels_per_unit"],
        "workers": args.workers if not args.scheduler else None,
        "driver_peak_rss": peak_rss(),
        # The largest peak of a worker process that ran a task (None without Dask).
        "worker_peak_rss": max((r.get("peak_rss", 0) for r in records), default=0) if not in_process else None,
        "seconds": {
            "load_plan": t_plan - t0,
            "cut": t_cut - t_plan,
            "map_write": t_map - t_cut,
        },
    }
    return summary


def usage_error(message):
    print("tailor.tiles: error: %s" % message, file=sys.stderr)
    sys.exit(2)


class _Parser(argparse.ArgumentParser):
    """argparse whose errors are one line, as the tool's other errors (argparse prints the whole
    usage block first)."""

    def error(self, message):
        usage_error("%s (run python3 -m tailor.tiles --help)" % message)


def parse_args(argv):
    p = _Parser(
        prog="python3 -m tailor.tiles",
        description="Maps a mesh as tiles (Dask tasks) and writes OGC 3D Tiles 1.1: OUTDIR/tileset.json, "
        "OUTDIR/tiles/*.glb and the shared texture.",
    )
    p.add_argument(
        "input",
        help="the mesh (.ply .obj .off .stl .glb). A binary little-endian PLY of triangles is partitioned by "
        "streaming it (never held whole: out of core); other inputs (OBJ, OFF, STL, glTF, ASCII or big-endian "
        "PLY, polygons) are loaded whole",
    )
    p.add_argument("-o", "--output", required=True, metavar="OUTDIR", help="the folder of the tileset (replaced)")
    p.add_argument(
        "--tile-size",
        type=float,
        metavar="L",
        help="side of a tile in world units: the chunk cell times a power of two (default: the chunk cell)",
    )
    p.add_argument(
        "--workers",
        type=int,
        default=os.cpu_count() or 1,
        metavar="N",
        help="worker processes of a local Dask cluster (default: one per core, at most max(256, 4 x cores)); "
        "0 maps in this process, without Dask",
    )
    p.add_argument("--scheduler", metavar="tcp://HOST:8786", help="a running Dask scheduler to use instead")
    p.add_argument(
        "--threads",
        type=int,
        default=0,
        metavar="T",
        help="threads of each tile's mapping (default: 1 per Dask worker; all cores with --workers 0)",
    )
    p.add_argument("--texture", metavar="T", help="PNG or JPEG texture: its size sets the repeat, tiles name it")
    p.add_argument(
        "--material",
        metavar="M",
        help="instead of --texture, a PBR material as tailor map --material (a folder of maps, or a JSON such as "
        "tailor tile --set's material.json): its maps' size sets the repeat; the tiles name its base colour, normal "
        "and occlusion/roughness/metallic images, written once in tiles/ beside the .glb files",
    )
    p.add_argument(
        "--up",
        default="y",
        metavar="y|z",
        help="up axis of the mesh's coordinates, as tailor map --up: z (scans, CAD) gives each .glb a node rotation "
        "that turns it Y up, so the tileset's Z up is the mesh's own (default y)",
    )
    defaults = tailor.MAP_DEFAULTS  # the library's, as tailor map and tailor.map take them
    p.add_argument(
        "--texture-size", type=int, default=defaults["texture_size"], help="pixels of one repeat without --texture"
    )
    p.add_argument(
        "--scale",
        type=float,
        help="as tailor map --scale (density from the bounding box; %s; default %g)"
        % (tailor._tailor._range_text("--scale"), defaults["scale"]),
    )
    p.add_argument(
        "--texels-per-unit",
        type=float,
        metavar="D",
        help="texture pixels per world unit (instead of --scale: does not depend on the bounding box)",
    )
    p.add_argument("--chunk-cell", type=int, metavar="E", help="chunk cell side 2**E world units (default: auto)")
    p.add_argument(
        "--field-following",
        default="auto",
        help="as tailor map: 0..1, or auto (default: 0 with 32 crack rings for a texture without a direction, else 1)",
    )
    p.add_argument(
        "--max-stretch",
        type=float,
        default=defaults["max_stretch"],
        help="as tailor map (%s; default %g)" % (tailor._tailor._range_text("--max-stretch"), defaults["max_stretch"]),
    )
    p.add_argument(
        "--crack-rings",
        type=int,
        default=None,
        help="as tailor map (%s; default %d)" % (tailor._tailor._range_text("--crack-rings"), defaults["crack_rings"]),
    )
    p.add_argument(
        "--no-lod",
        dest="lod",
        action="store_false",
        help="no levels of detail: the leaf tiles only, under one root (refine ADD)",
    )
    p.add_argument("-q", "--quiet", action="store_true", help="no progress bar and no summary")
    # Tests: the in-memory path for any input, and the streamed partition's block size.
    p.add_argument("--in-memory", action="store_true", help=argparse.SUPPRESS)
    p.add_argument("--block-faces", type=int, default=tiles_stream.BLOCK_FACES, help=argparse.SUPPRESS)
    p.add_argument("--cut-only", action="store_true", help=argparse.SUPPRESS)
    p.add_argument("--json", action="store_true", help="print the summary as JSON")
    args = p.parse_args(argv)
    # An empty value ('--texture "$TEX"' with TEX unset) would read as the option left out, and the
    # run would go on without what was asked for: no option here takes one (as tailor's CLI).
    for action in p._actions:
        if getattr(args, action.dest, None) == "":
            if not action.option_strings:
                usage_error("the %s was given as an empty path" % action.dest)
            usage_error("%s was given an empty value: give one, or leave the option out" % action.option_strings[-1])
    if args.texture and args.material:
        usage_error("give --texture or --material, not both (the material's colour map is the texture)")
    if args.up not in ("y", "z"):
        usage_error("--up must be y or z, got '%s'" % args.up)
    if args.scale is not None and args.texels_per_unit is not None:
        usage_error("give --scale or --texels-per-unit, not both (the density is one or the other)")
    for name, value in (("--tile-size", args.tile_size), ("--texels-per-unit", args.texels_per_unit)):
        if value is not None and not (0 < value < math.inf):
            usage_error("%s must be a positive number, got %s" % (name, value))
    if args.tile_size is not None and math.frexp(args.tile_size)[0] != 0.5:
        usage_error("--tile-size must be the chunk cell times a power of two (a power of two), got %r" % args.tile_size)
    if args.scale is None:
        args.scale = defaults["scale"]
    # The library's ranges and words, as tailor map and tailor.map check them (the value as the
    # mapping's float holds it).
    with np.errstate(over="ignore"):  # 1e39 is inf as a float, and refused as such
        floats = [("--scale", float(np.float32(args.scale))), ("--max-stretch", float(np.float32(args.max_stretch)))]
    # A whole number beyond any double (10**400) is just as far out of range.
    rings = None if args.crack_rings is None else float(max(-(2**63), min(args.crack_rings, 2**63)))
    for flag, value in floats + [("--crack-rings", rings)]:
        message = tailor._tailor._range_error(flag, value) if value is not None else ""
        if message:
            usage_error(message)
    if not 1 <= args.texture_size <= 65536:  # as tailor map and tailor eval take it
        usage_error("--texture-size must be in 1..65536, got %d" % args.texture_size)
    if args.chunk_cell is not None and not -60 <= args.chunk_cell <= 60:  # the library's (ChunkOptions)
        usage_error("--chunk-cell must be a whole number in -60..60 (the cell side is 2^N world units), got %d"
                    % args.chunk_cell)
    if args.field_following != "auto":
        try:
            value = float(args.field_following)
        except ValueError:
            value = float("nan")
        if not 0.0 <= value <= 1.0:
            usage_error("--field-following must be auto or a number in [0, 1], got '%s'" % args.field_following)
    # Each local worker is a process of ~100 MB before its first tile: a cap well above the cores,
    # so that a mistyped count fails here instead of starting processes until memory runs out.
    most_workers = max(256, 4 * (os.cpu_count() or 1))
    if args.workers < 0 or (args.workers > most_workers and not args.scheduler):
        p.error(
            "--workers must be in 0..%d (local worker processes; a larger cluster: start it and give --scheduler)"
            % most_workers
        )
    if args.threads < 0 or args.threads > 64:
        p.error("--threads must be in 0..64")
    return args


class Terminated(BaseException):
    """SIGTERM or SIGHUP (timeout, systemd, a batch scheduler): raised in the main thread, so that
    the run removes its temporary folder and closes its cluster, as on Ctrl-C."""

    def __init__(self, signum):
        super().__init__(signum)
        self.signum = signum


def _quiet_cluster():
    """From a Ctrl-C or a signal on: the local cluster's scheduler runs in this process and logs, as
    errors, the results it cannot gather from workers the signal ended, and asyncio the failed start
    of a worker the signal caught starting; the driver says what happened in its one line."""
    for name in ("distributed", "asyncio"):
        logger = logging.getLogger(name)
        logger.setLevel(logging.CRITICAL + 1)
        for handler in logger.handlers:
            handler.setLevel(logging.CRITICAL + 1)


def _terminate(signum, frame):
    for other in (signal.SIGTERM, signal.SIGHUP):  # a second signal must not cut the clean-up short
        signal.signal(other, signal.SIG_IGN)
    _quiet_cluster()
    raise Terminated(signum)


def _interrupt(signum, frame):
    _quiet_cluster()
    raise KeyboardInterrupt


def main(argv=None):
    args = parse_args(argv)
    # Only where the signal would otherwise end the process: one ignored at start (nohup, a
    # background job's SIGINT) stays ignored, and a caller's own handler stays.
    for signum in (signal.SIGTERM, signal.SIGHUP):
        if signal.getsignal(signum) is signal.SIG_DFL:
            signal.signal(signum, _terminate)
    if signal.getsignal(signal.SIGINT) is signal.default_int_handler:
        signal.signal(signal.SIGINT, _interrupt)
    try:
        summary = run(args)
    except TilesError as e:
        print("tailor.tiles: error: %s" % e, file=sys.stderr)
        return 1
    except (tailor.Error, tiles_stream.StreamError) as e:
        print("tailor.tiles: error: %s" % e, file=sys.stderr)
        return 1
    except OSError as e:  # a write of the output (a full disk): name the file, or the folder
        where = e.filename if e.filename is not None else args.output
        print("tailor.tiles: error: %s: %s" % (where, e.strerror or e), file=sys.stderr)
        return 1
    except KeyboardInterrupt:
        print("tailor.tiles: interrupted; %s left as it was" % args.output, file=sys.stderr)
        return 130
    except Terminated as e:
        print("tailor.tiles: terminated (%s); %s left as it was" % (signal.Signals(e.signum).name, args.output),
              file=sys.stderr)
        return 128 + e.signum
    if args.json:
        print(json.dumps(summary, indent=1))
    elif not args.quiet:
        print(
            "tailor.tiles: %d tiles (%d written, %d kept), %d faces, %.2f s -> %s/tileset.json"
            % (
                summary["tiles"],
                summary["written"],
                summary["kept"],
                summary["faces"],
                summary["seconds"]["total"],
                args.output,
            )
        )
    return 0


if __name__ == "__main__":
    # Run as the module tailor.tiles, not as __main__: cloudpickle sends a function of __main__ by
    # value, with every function it calls, in each task (milliseconds of this process's time each);
    # one of an importable module goes by name.
    from tailor import tiles as _tiles

    sys.exit(_tiles.main())
