"""Blender mesh <-> flat arrays: the triangles in world space, the seam faces from marked seams,
and the UV map written back per loop. numpy and foreach_get/set only (no per-element Python)."""
import numpy as np


def edge_keys(a, b, vertex_count):
    lo, hi = np.minimum(a, b).astype(np.int64), np.maximum(a, b).astype(np.int64)
    return lo * vertex_count + hi


class Triangles:
    """The loop triangles of an object's mesh, in world space, with exact duplicates left out (the
    readers of tailor drop them; `dropped` get the UVs of the triangle they repeat)."""

    def __init__(self, obj, use_seams):
        mesh = obj.data
        mesh.calc_loop_triangles()
        count = len(mesh.loop_triangles)
        self.loops = np.empty(3 * count, np.int32)
        mesh.loop_triangles.foreach_get("loops", self.loops)
        self.loops = self.loops.reshape(-1, 3)
        vertices = np.empty(3 * count, np.int32)
        mesh.loop_triangles.foreach_get("vertices", vertices)
        vertices = vertices.reshape(-1, 3)
        co = np.empty(3 * len(mesh.vertices), np.float32)
        mesh.vertices.foreach_get("co", co)
        matrix = np.array(obj.matrix_world, dtype=np.float64)
        self.positions = (co.reshape(-1, 3) @ matrix[:3, :3].T + matrix[:3, 3]).astype(np.float32)
        # A mirroring transform turns counter-clockwise faces clockwise: map them reversed.
        self.mirrored = np.linalg.det(matrix[:3, :3]) < 0
        order = [0, 2, 1] if self.mirrored else [0, 1, 2]
        self.vertices = vertices[:, order]
        self.loops = self.loops[:, order]
        # Exact duplicates (same vertex set): keep the first.
        ordered = np.sort(vertices, axis=1).astype(np.int64)
        if len(mesh.vertices) < 1 << 21:  # one int64 key per triangle: a 1-D unique, ~10x faster
            ordered = (ordered[:, 0] << 42) | (ordered[:, 1] << 21) | ordered[:, 2]
            _, first, inverse = np.unique(ordered, return_index=True, return_inverse=True)
        else:
            _, first, inverse = np.unique(ordered, axis=0, return_index=True, return_inverse=True)
        inverse = inverse.ravel()
        self.kept = np.zeros(count, bool)
        self.kept[first] = True
        self.original = first[inverse]  # the kept triangle each triangle repeats (itself when kept)
        self.seam_faces = None
        if use_seams and len(mesh.edges):
            seam = np.empty(len(mesh.edges), bool)
            mesh.edges.foreach_get("use_seam", seam)
            if seam.any():
                ends = np.empty(2 * len(mesh.edges), np.int32)
                mesh.edges.foreach_get("vertices", ends)
                ends = ends.reshape(-1, 2)[seam]
                marked = edge_keys(ends[:, 0], ends[:, 1], len(mesh.vertices))
                tri = self.vertices[self.kept]
                keys = edge_keys(tri, np.roll(tri, -1, axis=1), len(mesh.vertices))
                self.seam_faces = np.isin(keys, marked).any(axis=1)

    @property
    def faces(self):
        return self.vertices[self.kept]

    def loop_uvs(self, corner_uvs, loop_count):
        """Per-loop UVs (L, 2) from the kept triangles' corner UVs (K, 3, 2)."""
        full = np.empty((len(self.kept), 3, 2), np.float32)
        full[self.kept] = corner_uvs
        dropped = np.flatnonzero(~self.kept)
        for t in dropped:  # rare: duplicate faces; match corners by vertex
            source = self.original[t]
            for k in range(3):
                full[t, k] = full[source, int(np.argmax(self.vertices[source] == self.vertices[t, k]))]
        uvs = np.zeros((loop_count, 2), np.float32)
        uvs[self.loops.ravel()] = full.reshape(-1, 2)
        return uvs


def write_uv_map(obj, loop_uvs, name="tailor"):
    """Writes the UV map `name` (created when missing) and makes it the active one."""
    mesh = obj.data
    layer = mesh.uv_layers.get(name) or mesh.uv_layers.new(name=name)
    if layer is None:
        raise RuntimeError(f"{obj.name}: cannot add a UV map (Blender allows 8 per mesh)")
    layer.data.foreach_set("uv", loop_uvs.ravel())
    mesh.uv_layers.active = layer
    mesh.update()
    return layer
