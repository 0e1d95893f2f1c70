"""The figures of docs/scale.md: python3 -m tailor.tiles against the single-process chunked map.

    PYTHONPATH=build/python /usr/bin/python3 bench/tiles_scale.py mesh  /tmp/horse_x64.ply
    PYTHONPATH=build/python /usr/bin/python3 bench/tiles_scale.py time  /tmp/horse_x64.ply build/tailor
    PYTHONPATH=build/python /usr/bin/python3 bench/tiles_scale.py borders /tmp/horse_x64.ply

mesh: tests/data/meshes/horse.ply (96,966 faces) refined three times by 1-to-4 midpoint subdivision
(6,205,824 faces), written as binary PLY. time: wall seconds of `tailor map --chunks on -o x.glb`,
then of `python3 -m tailor.tiles --no-lod` with --workers 0 (no Dask), 1 and 2, each run into a
fresh folder, then with levels of detail at 2 workers, and of its re-run (every tile kept), with
each run's peak memory (the driver's, and the largest of a worker process that ran a task), then
the 2-worker speed-up again as the median of three alternated 1- and 2-worker runs.
borders: the share of visible edges between tiles and inside them (an edge is visible when its two
sides are not whole texture repeats apart: a gap of 1 px or more at either end).
"""
import json
import os
import pathlib
import shutil
import subprocess
import sys
import tempfile
import time

import numpy as np

import tailor

ROOT = pathlib.Path(__file__).resolve().parents[1]
PAIRS = 3  # alternated 1- and 2-worker runs for the scaling ratio


def subdivide(positions, faces):
    """1-to-4 midpoint subdivision; new vertices numbered in order of first use."""
    f = faces.astype(np.int64)
    edges = np.concatenate([f[:, [0, 1]], f[:, [1, 2]], f[:, [2, 0]]])
    key = np.sort(edges, axis=1)
    unique, inverse = np.unique(key[:, 0] * positions.shape[0] + key[:, 1], return_inverse=True)
    a, b = unique // positions.shape[0], unique % positions.shape[0]
    mids = (positions[a].astype(np.float64) + positions[b]) / 2
    n = positions.shape[0]
    m = inverse.reshape(3, -1).T + n  # midpoint of edge 01, 12, 20 per face
    v0, v1, v2 = f[:, 0], f[:, 1], f[:, 2]
    m01, m12, m20 = m[:, 0], m[:, 1], m[:, 2]
    out = np.concatenate(
        [
            np.stack([v0, m01, m20], 1),
            np.stack([m01, v1, m12], 1),
            np.stack([m20, m12, v2], 1),
            np.stack([m01, m12, m20], 1),
        ]
    )
    return np.concatenate([positions, mids.astype(np.float32)]), out.astype(np.uint32)


def write_ply(path, positions, faces):
    header = (
        "ply\nformat binary_little_endian 1.0\nelement vertex %d\nproperty float x\nproperty float y\n"
        "property float z\nelement face %d\nproperty list uchar int vertex_indices\nend_header\n"
        % (positions.shape[0], faces.shape[0])
    )
    rows = np.zeros(faces.shape[0], dtype=[("n", "u1"), ("v", "<i4", 3)])
    rows["n"] = 3
    rows["v"] = faces
    tmp = str(path) + ".part"
    with open(tmp, "wb") as f:
        f.write(header.encode())
        f.write(positions.astype("<f4").tobytes())
        f.write(rows.tobytes())
    os.replace(tmp, path)


def make_mesh(path):
    mesh = tailor.load(ROOT / "tests" / "data" / "meshes" / "horse.ply")
    p, f = np.array(mesh.positions), np.array(mesh.faces)
    for _ in range(3):
        p, f = subdivide(p, f)
    write_ply(path, p, f)
    print("%s: %d vertices, %d faces" % (path, p.shape[0], f.shape[0]))


def timed(cmd, env=None):
    start = time.monotonic()
    done = subprocess.run(cmd, capture_output=True, text=True, env=env)
    seconds = time.monotonic() - start
    if done.returncode != 0:
        sys.exit("failed: %s\n%s" % (" ".join(cmd), done.stderr))
    return seconds, done.stdout


def time_runs(path, binary):
    texture = str(ROOT / "examples" / "gravel.png")
    env = dict(os.environ)
    work = pathlib.Path(tempfile.mkdtemp(prefix="tiles_scale_"))
    rows = []
    mesh = tailor.load(path)
    cell = tailor.plan_chunks(mesh)["cell_exponent"]
    del mesh
    # The single-process chunked map, as the CLI runs it: the same options as the tiles.
    s, _ = timed(
        [binary, "map", str(path), "-o", str(work / "whole.glb"), "--texture", texture, "--chunks", "on",
         "--chunk-cell", str(cell), "--threads", "2"], env)
    rows.append(("tailor map --chunks on (2 threads, one .glb)", s, None))
    s, _ = timed(
        [binary, "map", str(path), "-o", str(work / "whole1.glb"), "--texture", texture, "--chunks", "on",
         "--chunk-cell", str(cell), "--threads", "1"], env)
    rows.append(("tailor map --chunks on (1 thread, one .glb)", s, None))
    for workers, threads, lod in ((0, 1, False), (0, 2, False), (1, 1, False), (2, 1, False), (2, 1, True)):
        out = work / ("w%d_t%d%s" % (workers, threads, "_lod" if lod else ""))
        cmd = [sys.executable, "-m", "tailor.tiles", str(path), "-o", str(out), "--texture", texture,
               "--chunk-cell", str(cell), "--workers", str(workers), "--threads", str(threads), "--json"]
        if not lod:
            cmd.append("--no-lod")
        s, stdout = timed(cmd, env)
        summary = json.loads(stdout)
        name = "tailor.tiles --workers %d --threads %d%s" % (workers, threads, "" if lod else " --no-lod")
        rows.append((name, s, summary))
        if lod:
            s, stdout = timed(cmd, env)
            rows.append((name + ", re-run (all kept)", s, json.loads(stdout)))
    outputs = [work / "w0_t1", work / "w0_t2", work / "w1_t1", work / "w2_t1"]
    same = subprocess.run(["diff", "-r", "-q", str(outputs[0]), str(outputs[1])]).returncode == 0
    same &= all(subprocess.run(["diff", "-r", "-q", str(outputs[0]), str(o)]).returncode == 0 for o in outputs[2:])
    for name, s, summary in rows:
        extra = ""
        if summary:
            t = summary["seconds"]
            extra = " (%d tiles, %d written; load+plan %.1f s, cut %.1f s, map+write %.1f s; peak MiB: driver %d" % (
                summary["tiles"], summary["written"], t["load_plan"], t["cut"], t["map_write"],
                summary["driver_peak_rss"] >> 20)
            if summary.get("worker_peak_rss"):
                extra += ", largest worker %d" % (summary["worker_peak_rss"] >> 20)
            extra += ")"
        print("%-48s %7.1f s%s" % (name, s, extra))
    wall = {name: s for name, s, _ in rows}
    w0 = wall["tailor.tiles --workers 0 --threads 1 --no-lod"]
    w1 = wall["tailor.tiles --workers 1 --threads 1 --no-lod"]
    w2 = wall["tailor.tiles --workers 2 --threads 1 --no-lod"]
    print("2 workers over 1: %.2fx; 1 worker over the same tiles without Dask (--workers 0): %+.0f %%" % (
        w1 / w2, 100 * (w1 / w0 - 1)))
    # The ratio again from alternated pairs: a virtual machine's speed drifts by more than a tenth
    # between minutes, which single runs minutes apart take for the ratio.
    ratios = []
    for _ in range(PAIRS):
        pair = []
        for workers in (1, 2):
            out = work / ("pair_w%d" % workers)
            shutil.rmtree(out, ignore_errors=True)
            pair.append(timed([sys.executable, "-m", "tailor.tiles", str(path), "-o", str(out), "--texture", texture,
                               "--chunk-cell", str(cell), "--workers", str(workers), "--no-lod", "--quiet"], env)[0])
        ratios.append(pair[0] / pair[1])
    print("2 workers over 1, %d alternated pairs: median %.2fx (%s)" % (
        PAIRS, float(np.median(ratios)), ", ".join("%.2f" % r for r in ratios)))
    print("tile folders identical for workers 0/1/2 and threads 1/2: %s" % same)
    print("load average: %s" % " ".join("%.2f" % x for x in os.getloadavg()))
    shutil.rmtree(work)


def borders(path, tile_level=0):
    """Visible edges between tiles and inside tiles, from the chunked map of the whole mesh."""
    mesh = tailor.load(path)
    plan = tailor.plan_chunks(mesh)
    texture = 512
    sys.path.insert(0, str(ROOT / "python"))
    from tailor.tiles import texels_per_unit_for

    tpu = texels_per_unit_for(mesh, 800.0)
    mapper = tailor.ChunkedMapper(plan["cell_exponent"], tpu, texture_size=(texture, texture))
    uv = np.empty((mesh.face_count, 3, 2), np.float64)
    tile_of = np.empty(mesh.face_count, np.int64)
    cells = plan["cells"] >> tile_level
    start, faces = plan["chunk_start"], plan["faces"]
    keys = {}
    for k in range(cells.shape[0]):
        tile_of[faces[start[k] : start[k + 1]]] = keys.setdefault(tuple(cells[k]), len(keys))
    for cell in mapper.set_mesh(mesh):
        chunk = mapper.chunk(cell)
        uv[chunk["faces"]] = chunk["corner_uvs"]
        mapper.remove_chunk(cell)
    f = np.array(mesh.faces, np.int64)
    n = mesh.vertex_count
    # Half-edges (face, corner k -> k+1); an interior edge is two of them with swapped ends.
    a = f.ravel()
    b = f[:, [1, 2, 0]].ravel()
    face = np.repeat(np.arange(f.shape[0]), 3)
    corner = np.tile(np.arange(3), f.shape[0])
    key = np.minimum(a, b) * n + np.maximum(a, b)
    order = np.argsort(key, kind="stable")
    k_sorted = key[order]
    pair = np.nonzero(k_sorted[1:] == k_sorted[:-1])[0]
    h1, h2 = order[pair], order[pair + 1]
    # UVs at both ends in both faces: h1 runs a->b, h2 runs b->a.
    u1a = uv[face[h1], corner[h1]]
    u1b = uv[face[h1], (corner[h1] + 1) % 3]
    u2a = uv[face[h2], (corner[h2] + 1) % 3]
    u2b = uv[face[h2], corner[h2]]
    da, db = u1a - u2a, u1b - u2b
    shift = np.round(da / texture)
    visible = (np.abs(da - shift * texture).max(1) >= 1) | (np.abs(db - shift * texture).max(1) >= 1)
    seam = (np.abs(da).max(1) > 0) | (np.abs(db).max(1) > 0)
    across = tile_of[face[h1]] != tile_of[face[h2]]
    print("%s: %d faces, %d tiles (cell %g, tile level %d)" % (path, mesh.face_count, len(keys), plan["cell_size"], tile_level))
    print("edges between tiles: %d, visible %.1f %%" % (across.sum(), 100 * visible[across].mean()))
    inside = ~across
    print(
        "edges inside tiles: %d, seams %.2f %%, visible %.2f %%"
        % (inside.sum(), 100 * seam[inside].mean(), 100 * visible[inside].mean())
    )


if __name__ == "__main__":
    what = sys.argv[1]
    if what == "mesh":
        make_mesh(sys.argv[2])
    elif what == "time":
        time_runs(sys.argv[2], sys.argv[3])
    elif what == "borders":
        borders(sys.argv[2], int(sys.argv[3]) if len(sys.argv) > 3 else 0)
