"""Mapping and tiling through the Python module `tailor` when it imports in Blender's Python (the
copy bundled in the add-on's zip first sits in _bundled/), else through the `tailor` command."""
import os
import shutil
import struct
import subprocess
import sys
import tempfile
import warnings
import zlib

import numpy as np

_BUNDLED = os.path.join(os.path.dirname(os.path.abspath(__file__)), "_bundled")


def import_module():
    """The tailor module, or None when neither an installed nor the bundled one imports."""
    try:
        import tailor

        return tailor
    except ImportError:
        pass
    if os.path.isdir(_BUNDLED) and _BUNDLED not in sys.path:
        sys.path.append(_BUNDLED)
        try:
            import tailor

            return tailor
        except ImportError:  # built for another Python version
            sys.path.remove(_BUNDLED)
    return None


def command_path(configured):
    path = configured or shutil.which("tailor")
    if not path or not os.path.isfile(path):
        raise RuntimeError("the tailor command was not found: set its path in the add-on's preferences, "
                           "or install tailor (make install)")
    return path


def choose(preferences):
    """('module', tailor) or ('cli', path), as the preferences ask."""
    if preferences.backend in ("AUTO", "MODULE"):
        module = import_module()
        if module is not None:
            return "module", module
        if preferences.backend == "MODULE":
            raise RuntimeError("the tailor Python module does not import in Blender's Python "
                               f"{sys.version.split()[0]} (the add-on bundles the one it was built for)")
    return "cli", command_path(preferences.tailor_path)


class MapRequest:
    """What the operator asks for one object: world-space triangles and the options."""

    def __init__(self, positions, faces, seam_faces, texture_size, tile_size, axis, options):
        self.positions, self.faces, self.seam_faces = positions, faces, seam_faces
        self.texture_size, self.tile_size, self.axis, self.options = texture_size, tile_size, axis, options

    @property
    def scale(self):
        """Texture pixels per scene unit: one texture repeat per tile size."""
        return self.texture_size / self.tile_size


def map_with_module(tailor, request, progress):
    """Corner UVs (F, 3, 2), the stats dict and the warnings (sentences) of tailor.map, by the module
    (GIL released; progress(fraction))."""
    mesh = tailor.Mesh(request.positions, request.faces)
    if mesh.face_count != len(request.faces):
        raise RuntimeError(f"{len(request.faces) - mesh.face_count} degenerate faces")
    seams = request.seam_faces if request.seam_faces is not None and request.seam_faces.any() else None
    options = dict(request.options)
    if options.get("texture") is None:
        options.pop("texture", None)
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        result = tailor.map(mesh, texture_size=request.texture_size, scale=request.scale, axis=request.axis,
                            seam_faces=seams, progress=progress, unit_scale=1.0, **options)
    return np.array(result.corner_uvs), result.stats, [str(w.message) for w in caught]


def write_ply(path, positions, faces):
    header = (f"ply\nformat binary_little_endian 1.0\nelement vertex {len(positions)}\n"
              "property float x\nproperty float y\nproperty float z\n"
              f"element face {len(faces)}\nproperty list uchar uint vertex_indices\nend_header\n")
    rows = np.zeros(len(faces), dtype=[("n", "u1"), ("v", "<u4", 3)])
    rows["n"], rows["v"] = 3, faces
    with open(path, "wb") as f:
        f.write(header.encode())
        f.write(np.ascontiguousarray(positions, "<f4").tobytes())
        f.write(rows.tobytes())


def read_split_ply(path):
    """The corner UVs of a .ply tailor wrote (x y z s t per split vertex, triangles)."""
    with open(path, "rb") as f:
        data = f.read()
    end = data.index(b"end_header\n") + len(b"end_header\n")
    header = data[:end].decode("ascii", "replace").split("\n")
    counts = {line.split()[1]: int(line.split()[2]) for line in header if line.startswith("element")}
    vertices = np.frombuffer(data, "<f4", counts["vertex"] * 5, end).reshape(-1, 5)
    rows = np.frombuffer(data, [("n", "u1"), ("v", "<u4", 3)], counts["face"], end + vertices.nbytes)
    return vertices[rows["v"]][:, :, 3:5]


def _run(command):
    """Runs the tool; its warnings (the sentences after 'tailor: warning: '), or the error it ends on."""
    done = subprocess.run(command, capture_output=True, text=True)
    if done.returncode != 0:
        lines = done.stderr.strip().splitlines() or [f"exit code {done.returncode}"]
        raise RuntimeError(lines[-1].removeprefix("tailor: error: "))
    prefix = "tailor: warning: "
    return [line[len(prefix):] for line in done.stderr.splitlines() if line.startswith(prefix)]


def map_with_cli(path, request):
    """The same through `tailor map` (no live progress; without -q for its warnings, which it prints
    only when asked to talk: its progress bars need a terminal). The CLI normalises the mesh into the unit
    cube, so its --scale is the module's times the longest side of the bounding box: the same
    density (the texture's offset differs)."""
    used = request.positions[np.unique(request.faces)]
    side = float((used.max(axis=0) - used.min(axis=0)).max())
    o = request.options
    with tempfile.TemporaryDirectory(prefix="tailor-blender-") as tmp:
        mesh_in, mesh_out = os.path.join(tmp, "in.ply"), os.path.join(tmp, "out.ply")
        write_ply(mesh_in, request.positions, request.faces)
        command = [path, "map", mesh_in, "-o", mesh_out, "--texture-size", str(request.texture_size),
                   "--scale", repr(request.scale * side), "--axis", request.axis,
                   "--max-stretch", repr(o["max_stretch"]), "--field-following", str(o["field_following"]),
                   "--relax-iterations", str(o["relax_iterations"]), "--threads", str(o["threads"]),
                   "--symmetry", str(o.get("symmetry", 1)), "--stats", os.path.join(tmp, "stats.json")]
        if not o["close_cracks"]:
            command.append("--no-crack-closing")
        if o.get("texture"):  # its size is the texture size; 'auto' measures it
            command += ["--texture", o["texture"]]
        if request.seam_faces is not None and request.seam_faces.any():
            seam_file = os.path.join(tmp, "seams.txt")
            np.savetxt(seam_file, np.flatnonzero(request.seam_faces), fmt="%d")
            command += ["--seam-faces", seam_file]
        warned = _run(command)
        import json

        with open(os.path.join(tmp, "stats.json")) as f:
            stats = json.load(f)
        uvs = read_split_ply(mesh_out)
    if len(uvs) != len(request.faces):
        raise RuntimeError(f"{len(request.faces) - len(uvs)} degenerate faces")
    return np.array(uvs, np.float32), stats, warned


def make_tileable(kind, tool, image_path, out_png, symmetry=1):
    """Writes a self-tileable version of image_path to out_png (PNG); symmetry 4: also unchanged by a
    quarter turn (twice the image's side)."""
    if kind == "cli":
        # --allow-misses: the add-on keeps the tile as the Python module's tile() does (no verdict).
        _run([tool, "tile", image_path, "-o", out_png, "-q", "--allow-misses", "--symmetry", str(symmetry)])
        return None
    return tool.tile(image_path, symmetry=symmetry)  # (H, W, C) uint8: the caller makes a Blender image of it


def make_tileable_set(kind, tool, map_paths, normal_paths, out_folder, symmetry=1):
    """Writes the maps of one material, made self-tileable with one cut for all, into out_folder
    under their own names (.png), as `tailor tile --set`; symmetry 4: one quarter-turn tile for all
    (twice the maps' side, normal maps turned with their content)."""
    if kind == "cli":
        command = [tool, "tile", "--set", *map_paths, "-o", out_folder + os.sep, "-q", "--allow-misses",
                   "--symmetry", str(symmetry)]
        for path in normal_paths:
            command += ["--normal-map", path]
        _run(command)
    else:
        tool.tile_set(list(map_paths), out_folder, normal_maps=list(normal_paths), symmetry=symmetry)


def write_png(path, pixels):
    """An 8-bit PNG of a uint8 (H, W[, C]) array, rows top first (the tile the module made, so that
    the mapping can measure it as the command does)."""
    pixels = np.ascontiguousarray(pixels, np.uint8)
    if pixels.ndim == 2:
        pixels = pixels[:, :, None]
    height, width, channels = pixels.shape
    raw = b"".join(b"\0" + pixels[y].tobytes() for y in range(height))

    def chunk(kind, body):
        return struct.pack(">I", len(body)) + kind + body + struct.pack(">I", zlib.crc32(kind + body))

    header = struct.pack(">IIBBBBB", width, height, 8, {1: 0, 2: 4, 3: 2, 4: 6}[channels], 0, 0, 0)
    with open(path, "wb") as f:
        f.write(b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", header) + chunk(b"IDAT", zlib.compress(raw)) + chunk(b"IEND", b""))
