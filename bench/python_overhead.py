"""Overhead of the Python module's map() over the C++ calls it makes, on a ~1M-face mesh.

Usage: PYTHONPATH=build/python /usr/bin/python3 bench/python_overhead.py [BUILD_DIR] [--runs N]
(scripts/bench.sh runs it after tailor_bench when the module is built).

Three figures per run, same mesh, same options (defaults, crack closing on and off):
  python   wall time of tailor.map(mesh) as a Python caller sees it (options, GIL release,
           progress bridge, the result's arrays and the stats dict included);
  library  Result.library_seconds: the C++ calls inside that map() (topology, map_texture, the
           report), timed in C++ around them;
  cli      the same stages in a separate `tailor map` process (time_ms: topology + orientation +
           mapping + metrics from --stats), an independent C++ baseline.
Overhead = python / library - 1 (the issue's target: below 5%). Best of N runs each.
"""
import json
import os
import subprocess
import sys
import tempfile
import time

import numpy as np

import tailor


def bumpy_grid(n):
    x, y = np.meshgrid(np.linspace(0, 4, n), np.linspace(0, 4, n), indexing="ij")
    z = 0.3 * np.sin(2.5 * x) * np.cos(3.0 * y) + 0.1 * np.sin(7 * x + 3 * y)
    positions = np.stack([x, y, z], axis=-1).reshape(-1, 3).astype(np.float32)
    i = (np.arange(n - 1)[:, None] * n + np.arange(n - 1)[None, :]).ravel()
    a, b, c, d = i, i + n, i + n + 1, i + 1
    faces = np.concatenate([np.stack([a, b, c], -1), np.stack([a, c, d], -1)]).astype(np.uint32)
    return positions, faces


def write_ply(path, positions, faces):
    header = (f"ply\nformat binary_little_endian 1.0\nelement vertex {len(positions)}\n"
              "property float x\nproperty float y\nproperty float z\n"
              f"element face {len(faces)}\nproperty list uchar uint vertex_indices\nend_header\n")
    rows = np.zeros(len(faces), dtype=[("n", "u1"), ("v", "<u4", 3)])
    rows["n"], rows["v"] = 3, faces
    with open(path, "wb") as f:
        f.write(header.encode())
        f.write(positions.astype("<f4").tobytes())
        f.write(rows.tobytes())


def main():
    args = [a for a in sys.argv[1:] if not a.startswith("--")]
    build = args[0] if args else "build"
    runs = int(sys.argv[sys.argv.index("--runs") + 1]) if "--runs" in sys.argv else 3
    positions, faces = bumpy_grid(708)
    start = time.perf_counter()
    mesh = tailor.Mesh(positions, faces)
    mesh_seconds = time.perf_counter() - start
    print(f"python: {mesh.face_count} faces, {mesh.vertex_count} vertices; tailor.Mesh(float32, uint32) "
          f"{1000 * mesh_seconds:.1f} ms (one copy + the readers' validation)")
    with tempfile.TemporaryDirectory() as tmp:
        ply = os.path.join(tmp, "grid.ply")
        write_ply(ply, positions, faces)
        for label, options, flags in (("default", {}, []), ("no crack closing", {"close_cracks": False},
                                                            ["--no-crack-closing"])):
            python_s, library_s, cli_s = [], [], []
            for _ in range(runs):
                start = time.perf_counter()
                result = tailor.map(mesh, **options)
                python_s.append(time.perf_counter() - start)
                library_s.append(result.library_seconds)
                stats = os.path.join(tmp, "stats.json")
                subprocess.run([os.path.join(build, "tailor"), "map", ply, "-o", os.path.join(tmp, "out.ply"),
                                "-q", "--stats", stats, *flags], check=True)
                t = json.load(open(stats))["time_ms"]
                cli_s.append((t["topology"] + t["orientation"] + t["mapping"] + t["metrics"]) / 1000)
            p, lib, cli = min(python_s), min(library_s), min(cli_s)
            print(f"python: map {label:17s} python {p:.3f} s  library {lib:.3f} s  cli stages {cli:.3f} s  "
                  f"overhead {100 * (p / lib - 1):+.2f}% (vs the CLI's stages {100 * (p / cli - 1):+.2f}%)")


if __name__ == "__main__":
    main()
