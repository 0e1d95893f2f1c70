"""What the chunk borders cost in visible seams: every mesh of a folder mapped whole, in chunks of the
automatic cell, and in chunks of a cell a third of its longest side, in both texture modes; prints
the medians over the meshes of the visible seams (% of edge length) and the worst flipped count, L2
and Linf stretch of each column (docs/performance.md, "Quality of the borders").

    python3 bench/chunk_quality.py build/tailor ../shared/data/meshes
"""
import json
import math
import pathlib
import statistics
import subprocess
import sys
import tempfile

MODES = {
    "patches": ["--field-following", "1"],
    "undirected": ["--field-following", "0", "--crack-rings", "32"],
}
MESH_SUFFIXES = {".ply", ".obj", ".off", ".stl"}


def longest_side(tailor, mesh):
    """The longest side of the mesh's bounding box, from `tailor info`."""
    out = subprocess.run([tailor, "info", str(mesh)], capture_output=True, text=True, check=True).stdout
    line = next(l for l in out.splitlines() if l.strip().startswith("bounding box"))
    lo, hi = (json.loads(part.strip()) for part in line.split("box", 1)[1].split(" - "))
    return max(h - l for l, h in zip(lo, hi))


def mapped(tailor, mesh, mode, chunks, folder):
    """The stats JSON's metrics of one map, with its chunk count."""
    stats = folder / "stats.json"
    subprocess.run(
        [tailor, "map", str(mesh), "-o", str(folder / "out.glb"), "--quiet", "--stats", str(stats)]
        + MODES[mode]
        + chunks,
        check=True,
    )
    report = json.loads(stats.read_text())
    return dict(report["metrics"], chunks=report["mapping"].get("chunks", 0))


def main(argv):
    if len(argv) != 3:
        sys.exit(__doc__)
    tailor, meshes = argv[1], sorted(p for p in pathlib.Path(argv[2]).iterdir() if p.suffix in MESH_SUFFIXES)
    if not meshes:
        sys.exit("no mesh in %s" % argv[2])
    columns = {
        "whole": lambda mesh: ["--chunks", "off"],
        "automatic cell": lambda mesh: ["--chunks", "on"],
        "cell of 1/3 of the longest side": lambda mesh: [
            "--chunks",
            "on",
            "--chunk-cell",
            str(math.floor(math.log2(longest_side(tailor, mesh) / 3))),
        ],
    }
    with tempfile.TemporaryDirectory() as tmp:
        folder = pathlib.Path(tmp)
        for mode in MODES:
            row = []
            for name, chunks in columns.items():
                runs = [mapped(tailor, mesh, mode, chunks(mesh), folder) for mesh in meshes]
                row.append(
                    "%s (%d to %d chunks): visible %.2f %%, flipped <= %d, L2 <= %.3f, Linf <= %.2f"
                    % (
                        name,
                        min(m["chunks"] for m in runs),
                        max(m["chunks"] for m in runs),
                        100 * statistics.median(m["visible_seam_ratio"] for m in runs),
                        max(m["flipped"] for m in runs),
                        max(m["l2_stretch"] for m in runs),
                        max(m["linf_stretch"] for m in runs),
                    )
                )
            print("%s (%d meshes)\n  %s" % (mode, len(meshes), "\n  ".join(row)))


if __name__ == "__main__":
    main(sys.argv)
