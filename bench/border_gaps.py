"""How far apart, modulo whole texture repeats, the two sides of each chunk border land.

    PYTHONPATH=build/python /usr/bin/python3 bench/border_gaps.py MESH [--axis pca|x|y|z|X,Y,Z]
        [--chunk-cell E] [--scale S] [--texture-size N] [--max-stretch X]
    PYTHONPATH=build/python /usr/bin/python3 bench/border_gaps.py plane [--noise F] [--height Z] [--axis ...]

MESH "plane" is a scanned floor: a 400 x 400-vertex grid at z = Z (0 by default; 79.2 x 79.1 units, its corner at
(-37.3, -12.1): the grid's planes fall inside it), heights with Gaussian noise of F times the edge
length (seed 1; F = 0.05 by default, 0 for a flat floor).

Maps MESH in chunks (`--chunks on`, the default for an isotropic tile: field following 0, 32 crack
rings), prints the whole map's patches and seams (visible: the share of the edge length on seams
whose gap is 1 px or more; invisible: the share of the seam length whose gap is under 1 px), and,
for every edge whose two faces lie in different chunks, measures the lattice gap: the
larger, over its two end vertices, of the distance between the two sides' UVs after removing whole
repeats (0 = the texture continues across the border). A zip of a border band within max_stretch
can only absorb a gap of about max_stretch times the band's width, so the table says which share of
the border length a band of 1, 2, 4... rings could close, and the band width the median gap needs.
"""
import argparse
import sys

import numpy as np

import tailor


def border_gaps(mesh, result, chunk_of_face, period):
    faces = np.asarray(mesh.faces, dtype=np.int64)
    positions = np.asarray(mesh.positions, dtype=np.float64)
    uv = np.asarray(result.corner_uvs, dtype=np.float64) * period  # pixels
    start = faces.reshape(-1)
    end = faces[:, [1, 2, 0]].reshape(-1)
    face_of = np.repeat(np.arange(len(faces)), 3)
    key = np.minimum(start, end) * (len(positions) + 1) + np.maximum(start, end)
    order = np.argsort(key, kind="stable")
    pair = key[order][1:] == key[order][:-1]
    h0, h1 = order[:-1][pair], order[1:][pair]
    across = chunk_of_face[face_of[h0]] != chunk_of_face[face_of[h1]]
    h0, h1 = h0[across], h1[across]

    def corner_uv(h, vertex):
        f = face_of[h]
        corner = np.argmax(faces[f] == vertex[:, None], axis=1)
        return uv[f, corner]

    gap = np.zeros(len(h0))
    for vertex in (start[h0], end[h0]):
        d = corner_uv(h0, vertex) - corner_uv(h1, vertex)
        d -= period * np.round(d / period)
        gap = np.maximum(gap, np.hypot(d[:, 0], d[:, 1]))
    length = np.linalg.norm(positions[start[h0]] - positions[end[h0]], axis=1)
    f = face_of[h0]
    k = h0 - 3 * f
    edge_px = np.median(np.hypot(*(uv[f, (k + 1) % 3] - uv[f, k]).T))
    return gap, length, edge_px


def noisy_plane(noise, height):
    n, step = 400, 0.1985
    x, y = np.meshgrid(-37.3 + step * np.arange(n), -12.1 + step * np.arange(n), indexing="xy")
    z = height + np.random.default_rng(1).normal(0.0, noise * step, x.shape)
    positions = np.stack([x, y, z], axis=-1).reshape(-1, 3).astype(np.float32)
    i = np.arange(n - 1)
    a = (i[:, None] * n + i[None, :]).reshape(-1)  # lower-left vertex of each square
    faces = np.concatenate([np.stack([a, a + 1, a + n + 1], 1), np.stack([a, a + n + 1, a + n], 1)])
    return tailor.Mesh(positions, faces.astype(np.uint32))


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("mesh")
    parser.add_argument("--axis", default="pca")
    parser.add_argument("--noise", type=float, default=0.05, help="plane: height noise over the edge length")
    parser.add_argument("--height", type=float, default=0.0, help="plane: its z")
    parser.add_argument("--chunk-cell", type=int, default=None)
    parser.add_argument("--scale", type=float, default=800.0)
    parser.add_argument("--texture-size", type=int, default=512)
    parser.add_argument("--max-stretch", type=float, default=0.25)
    args = parser.parse_args()
    if not args.noise >= 0:
        parser.error("--noise must be 0 or more")
    axis = args.axis if "," not in args.axis else [float(c) for c in args.axis.split(",")]
    mesh = noisy_plane(args.noise, args.height) if args.mesh == "plane" else tailor.load(args.mesh)
    plan = tailor.plan_chunks(mesh, chunk_cell=args.chunk_cell)
    chunk_of_face = np.empty(mesh.face_count, np.int64)
    for c in range(len(plan["cells"])):
        chunk_of_face[plan["faces"][plan["chunk_start"][c] : plan["chunk_start"][c + 1]]] = c
    result = tailor.map(mesh, texture_size=args.texture_size, scale=args.scale, axis=axis,
                        field_following=0, crack_rings=32, max_stretch=args.max_stretch, chunks="on",
                        chunk_cell=args.chunk_cell)
    m = result.metrics
    print(f"{args.mesh}: {m['patches']} patches, visible seams {100 * m['visible_seam_ratio']:.2f} % of the edge "
          f"length, invisible {100 * m['seam_invisible_ratio']:.1f} % of the seam length")
    gap, length, edge_px = border_gaps(mesh, result, chunk_of_face, float(args.texture_size))
    if len(gap) == 0:
        print(f"{args.mesh}: one chunk, no border")
        return 0
    total = length.sum()
    print(f"{args.mesh}: {mesh.face_count} faces, {len(plan['cells'])} chunks, {len(gap)} border edges, "
          f"median edge {edge_px:.2f} px, repeat {args.texture_size} px")
    print(f"  gap < 1 px (invisible): {100 * length[gap < 1].sum() / total:.1f} % of the border length")
    for rings in (1, 2, 4, 8, 32):
        closable = gap < args.max_stretch * rings * edge_px
        print(f"  closable by a band {rings:>2} rings wide (gap < {args.max_stretch} x {rings} edges): "
              f"{100 * length[closable].sum() / total:.1f} %")
    median = float(np.median(gap))
    print(f"  median gap {median:.0f} px = {median / edge_px:.0f} edges: it needs a band "
          f"{median / (args.max_stretch * edge_px):.0f} rings wide")
    return 0


if __name__ == "__main__":
    sys.exit(main())
