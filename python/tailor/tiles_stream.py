"""The out-of-core input of `python3 -m tailor.tiles`: a binary little-endian PLY cut into per-tile
files by streaming it, never held whole.

The header is parsed here; the body is read in blocks of faces (BLOCK_FACES), each face's corners
gathered from a memory map of the vertex element. After every block its face records' pages are
released, and the vertex element's too when it is larger than VERTEX_PAGES_KEPT, so that the
driver's resident memory stays bounded by a block and that budget, not by the file. The chunk rule's arithmetic
is the library's own (tailor.chunk_edge_lengths, tailor.chunk_cell_exponent, tailor.chunk_cells: the
functions plan_chunks computes with), so the tiles hold the faces `tailor.plan_chunks` gives them.

Passes over the faces: (1) checks (counts, index range, finite coordinates), the bounding box of the
referenced vertices and a histogram of the edge lengths' float bits (high 16 bits), (2) when the
cell is automatic and the one bin that holds the median spans two cell exponents, the exact median
from the low 16 bits of the lengths in that bin, (3) each face's tile, its three vertex ids and
corner positions appended to the tile's file. Pass (3) runs in ranges of whole blocks, each into a
folder of its own (partition_parts: the driver and a cluster's workers share them); a tile's files
in the ranges' order are its faces in file order.
What tailor.load would change is done the same way: faces that repeat a vertex are dropped here,
faces that repeat another face's vertices (the first kept) by the task that reads the tile.
"""
import math
import mmap
import os
import pathlib
import shutil
import stat
import tempfile

import numpy as np

import tailor

BLOCK_FACES = 1 << 18  # the driver holds about 300 bytes per face of a block
# A vertex element up to this size stays mapped between blocks: every block gathers from all of
# it, and faulting its pages in again after each block took 0.4 s of a 1.1 s survey (6.2 M faces).
# Its pages are clean file pages, which the kernel reclaims under memory pressure.
VERTEX_PAGES_KEPT = 256 << 20

_TYPES = {
    "char": "i1", "int8": "i1", "uchar": "u1", "uint8": "u1",
    "short": "<i2", "int16": "<i2", "ushort": "<u2", "uint16": "<u2",
    "int": "<i4", "int32": "<i4", "uint": "<u4", "uint32": "<u4",
    "float": "<f4", "float32": "<f4", "double": "<f8", "float64": "<f8",
}  # fmt: skip


class StreamError(Exception):
    """A one-line error about the input (tailor.tiles prints it as its own)."""


class PlyLayout:
    """Where a binary little-endian PLY keeps its vertices and triangles."""

    def __init__(self, path, size, vertex_count, vertex_offset, vertex_dtype, face_count, face_offset, face_dtype):
        self.path, self.size = path, size
        self.vertex_count, self.vertex_offset, self.vertex_dtype = vertex_count, vertex_offset, vertex_dtype
        self.face_count, self.face_offset, self.face_dtype = face_count, face_offset, face_dtype
        self.index_dtype = np.dtype("<u4") if vertex_count <= 0xFFFFFFFF else np.dtype("<u8")


def read_layout(path):
    """The layout of a binary little-endian PLY of triangles that can be streamed, else None (another
    format, ASCII or big-endian PLY, tristrips, a list before the faces other than their indices, a
    first face that is not a triangle: tailor.load reads those, whole). StreamError when the header's
    counts need more bytes than the file has."""
    path = str(path)
    try:
        # Opening a FIFO would wait for a writer: anything but a regular file is tailor.load's to
        # refuse (it names what it is).
        if not stat.S_ISREG(os.stat(path).st_mode):
            return None
        with open(path, "rb") as f:
            head = f.read(1 << 20)
            size = os.fstat(f.fileno()).st_size
    except OSError:
        return None
    if not head.startswith(b"ply\n") and not head.startswith(b"ply\r\n"):
        return None
    # The header's lines up to the one whose first word is end_header, as tailor.load reads it (a
    # comment may hold the word too).
    lines, pos = [], head.index(b"\n") + 1
    while True:
        eol = head.find(b"\n", pos)
        if eol < 0:
            return None
        words = head[pos:eol].split()
        if words and words[0] == b"end_header":
            break
        lines.append(head[pos:eol])
        pos = eol + 1
    body = eol + 1
    elements, fmt = [], None
    for raw in lines:
        w = raw.decode("latin-1").split()
        if not w or w[0] in ("comment", "obj_info"):
            continue
        if w[0] == "format":
            fmt = w[1] if len(w) > 1 else None
        elif w[0] == "element" and len(w) == 3 and w[2].isdigit():
            elements.append({"name": w[1], "count": int(w[2]), "props": []})
        elif w[0] == "property" and elements and len(w) == 5 and w[1] == "list":
            if w[2] not in _TYPES or w[3] not in _TYPES:
                return None
            elements[-1]["props"].append(("list", w[4], _TYPES[w[2]], _TYPES[w[3]]))
        elif w[0] == "property" and elements and len(w) == 3 and w[1] in _TYPES:
            elements[-1]["props"].append(("scalar", w[2], _TYPES[w[1]], None))
        else:
            return None  # tailor.load says what is wrong
    if fmt != "binary_little_endian":
        return None
    names = [e["name"] for e in elements]
    if "vertex" not in names or "face" not in names or "tristrips" in names or len(set(names)) != len(names):
        return None
    offset = body
    vertex = face = None
    for e in elements:
        lists = [p for p in e["props"] if p[0] == "list"]
        if e["name"] == "face":
            index = [p for p in lists if p[1] in ("vertex_indices", "vertex_index")][:1]
            if len(lists) != 1 or not index or np.dtype(index[0][3]).kind == "f":
                return None
            fields, formats = [], []
            for kind, name, t, item in e["props"]:
                if kind == "list":
                    fields += ["n", "i"]
                    formats += [t, (item, 3)]
                else:
                    fields.append("_%d" % len(fields))
                    formats.append(t)
            dtype = np.dtype({"names": fields, "formats": formats})
            face = (e["count"], offset, dtype)
        else:
            if lists:
                if face is not None and vertex is not None:
                    break  # after both: never read
                return None
            dtype = np.dtype({"names": ["_%d" % k for k in range(len(e["props"]))], "formats": [p[2] for p in e["props"]]})
            if e["name"] == "vertex":
                props = [p[1] for p in e["props"]]
                if not all(axis in props for axis in "xyz"):
                    return None
                fields = {axis: props.index(axis) for axis in "xyz"}
                xyz = np.dtype(
                    {
                        "names": list("xyz"),
                        "formats": [dtype.fields["_%d" % fields[a]][0] for a in "xyz"],
                        "offsets": [dtype.fields["_%d" % fields[a]][1] for a in "xyz"],
                        "itemsize": dtype.itemsize,
                    }
                )
                vertex = (e["count"], offset, xyz)
        offset += e["count"] * dtype.itemsize
        if face is not None and vertex is not None:
            break
    need = max(vertex[1] + vertex[0] * vertex[2].itemsize, face[1] + face[0] * face[2].itemsize)
    if need > size:
        polygon = _first_polygon(path, face, size)
        if polygon is not None:  # a face of fewer corners shortened the file: that face is the error
            raise StreamError(_NOT_TRIANGLE % ((path,) + polygon))
        raise StreamError(
            "%s: truncated: the header's counts (%d vertices, %d triangles) need %d bytes, the file has %d"
            % (path, vertex[0], face[0], need, size)
        )
    layout = PlyLayout(path, size, vertex[0], vertex[1], vertex[2], face[0], face[1], face[2])
    if layout.face_count == 0 or layout.vertex_count == 0:
        return None
    first = np.frombuffer(_read(path, face[1], face[2].itemsize), dtype=face[2])
    if int(first["n"][0]) != 3:
        return None  # polygons: tailor.load triangulates them
    return layout


_NOT_TRIANGLE = "%s: face %d has %d vertices: a binary PLY is streamed as triangles only"


def _first_polygon(path, face, size):
    """(face, vertex count) of the first face record, read as triangles, whose count is not 3 among
    those the file's size holds; None when all are triangles. Blocks of BLOCK_FACES records."""
    count, offset, dtype = face
    fit = min(count, max(0, size - offset) // dtype.itemsize)
    with open(path, "rb") as f, mmap.mmap(f.fileno(), 0, access=mmap.ACCESS_READ) as m:
        for first in range(0, fit, BLOCK_FACES):
            records = np.frombuffer(m, dtype=dtype, count=min(BLOCK_FACES, fit - first), offset=offset + first * dtype.itemsize)
            n = records["n"].copy()  # a copy: no view of the map outlives it
            del records
            bad = np.flatnonzero(n != 3)
            if bad.size:
                return first + int(bad[0]), int(n[bad[0]])
    return None


def _read(path, offset, count):
    with open(path, "rb") as f:
        f.seek(offset)
        return f.read(count)


class _Body:
    """The vertex element memory-mapped (read-only), and the faces read block by block."""

    def __init__(self, layout):
        self.layout = layout
        self.file = open(layout.path, "rb")
        self.map = mmap.mmap(self.file.fileno(), 0, access=mmap.ACCESS_READ)
        self.vertices = np.ndarray(
            (layout.vertex_count,), dtype=layout.vertex_dtype, buffer=self.map, offset=layout.vertex_offset
        )
        # x, y, z as three consecutive float32 (the usual vertex): one gather of 12 bytes per corner
        # (tailor._gather_corners) instead of one per axis. The header's length leaves the floats
        # unaligned as often as not, which numpy would copy whole before it gathers.
        fields = layout.vertex_dtype.fields
        x = fields["x"][1]
        self.xyz_at = None
        if all(fields[a][0] == np.dtype("<f4") and fields[a][1] == x + 4 * k for k, a in enumerate("xyz")):
            self.xyz_at = layout.vertex_offset + x

    def close(self):
        del self.vertices
        try:
            self.map.close()
        except BufferError:  # a block still viewed by a frame an error left: closed when collected
            pass
        self.file.close()

    def keeps_vertices(self):
        """Whether the vertex element's pages stay mapped between blocks (VERTEX_PAGES_KEPT)."""
        return self.layout.vertex_count * self.layout.vertex_dtype.itemsize <= VERTEX_PAGES_KEPT

    def release(self, offset, length):
        """Drops the mapped pages of bytes [offset, offset + length) from this process's resident
        memory; they stay in the page cache."""
        if hasattr(self.map, "madvise") and hasattr(mmap, "MADV_DONTNEED"):
            start = offset - offset % mmap.PAGESIZE
            self.map.madvise(mmap.MADV_DONTNEED, start, min(len(self.map), offset + length) - start)

    def positions(self, first, count):
        v = self.vertices[first : first + count]
        out = np.empty((v.shape[0], 3), dtype=np.float32)
        # A double beyond float32 becomes inf here, which the checks that follow name in one line;
        # numpy's own overflow warning would come first.
        with np.errstate(over="ignore", invalid="ignore"):
            for k, axis in enumerate("xyz"):
                out[:, k] = v[axis]
        return out

    def blocks(self, block_faces, begin=0, end=None):
        """(first face, (n, 3) int64 vertex ids, (n, 3, 3) float32 corners, kept: not repeating a vertex)
        per block of faces [begin, end), checked."""
        layout = self.layout
        dtype = layout.face_dtype
        nv = layout.vertex_count
        end = layout.face_count if end is None else end
        for first in range(begin, end, block_faces):
            n = min(block_faces, end - first)
            records = np.frombuffer(self.map, dtype=dtype, count=n, offset=layout.face_offset + first * dtype.itemsize)
            bad = np.flatnonzero(records["n"] != 3)
            if bad.size:
                f = first + int(bad[0])
                raise StreamError(_NOT_TRIANGLE % (layout.path, f, int(records["n"][bad[0]])))
            ids = records["i"].astype(np.int64)
            del records
            out = (ids < 0) | (ids >= nv)
            if out.any():
                c = int(np.flatnonzero(out.ravel())[0])
                raise StreamError(
                    "%s: face index %d out of range (mesh has %d vertices) at face %d"
                    % (layout.path, int(ids.ravel()[c]), nv, first + c // 3)
                )
            del out
            kept = (ids[:, 0] != ids[:, 1]) & (ids[:, 1] != ids[:, 2]) & (ids[:, 0] != ids[:, 2])
            if kept.all():
                kept = slice(None)
            if self.xyz_at is None:
                corners = np.empty((n, 3, 3), dtype=np.float32)
                for k, axis in enumerate("xyz"):
                    corners[:, :, k] = self.vertices[axis][ids]
            else:
                corners = tailor._tailor._gather_corners(self.map, self.xyz_at, layout.vertex_dtype.itemsize, nv, ids)
            # Every face record read so far, not only this block's: faulting a page in maps the
            # cached pages around it too (the kernel's fault-around), earlier blocks' among them.
            self.release(layout.face_offset, (first + n) * dtype.itemsize)
            if not self.keeps_vertices():
                self.release(layout.vertex_offset, nv * layout.vertex_dtype.itemsize)
            yield first, ids, corners, kept


def _check_finite(body, block):
    for first in range(0, body.layout.vertex_count, block):
        p = body.positions(first, block)
        bad = ~np.isfinite(p).all(axis=1)
        if bad.any():
            raise StreamError(
                "%s: vertex coordinate not finite or beyond the range of 32-bit floats (3.4e38) at vertex %d"
                % (body.layout.path, first + int(np.flatnonzero(bad)[0]))
            )
        if not body.keeps_vertices():  # every vertex read so far (see blocks)
            body.release(body.layout.vertex_offset, (first + p.shape[0]) * body.layout.vertex_dtype.itemsize)


def survey(layout, chunk_cell, block_faces=BLOCK_FACES):
    """The streaming passes before the partition: checks, the bounding box of the referenced vertices
    and the chunk rule's cell exponent from the median edge length (exact: plan_chunks takes element
    n // 2 of the 3F lengths). The second pass, for the median's low 16 bits, runs only when the bin
    of the coarse histogram that holds the median spans two exponents. Returns {faces, lo, hi,
    median_edge (None when the bin decided, or with chunk_cell), about_median (the median, or the
    low end of its bin of the coarse histogram), cell_exponent}."""
    body = _Body(layout)
    try:
        _check_finite(body, block_faces)
        lo = np.full(3, np.inf, dtype=np.float32)
        hi = np.full(3, -np.inf, dtype=np.float32)
        coarse = np.zeros(1 << 16, dtype=np.int64)
        faces = 0
        for _, _, corners, kept in body.blocks(block_faces):
            corners = corners[kept]
            if corners.shape[0] == 0:
                continue
            faces += corners.shape[0]
            tailor._tailor._survey_block(corners, lo, hi, coarse)
        if faces == 0:
            raise StreamError("%s: mesh has no faces" % layout.path)
        median = None
        # The median's bin of the coarse histogram (top 16 bits of the lengths' float bits): its
        # low end is the median to 2^-7, enough for the far-from-origin warning.
        rank = (3 * faces) // 2
        cumulative = np.cumsum(coarse)
        top = int(np.searchsorted(cumulative, rank, side="right"))
        below = int(cumulative[top - 1]) if top else 0
        bin_ends = np.array([top << 16, (top << 16) | 0xFFFF], dtype=np.uint32).view(np.float32)
        decided = float(bin_ends[0])
        # The automatic cell needs the exact median only when the bin spans two of its exponents
        # (otherwise every length of the bin gives the median's exponent): a second pass.
        if chunk_cell is None and not _same_exponent(float(bin_ends[0]), float(bin_ends[1])):
            fine = np.zeros(1 << 16, dtype=np.int64)
            for _, _, corners, kept in body.blocks(block_faces):
                bits = tailor.chunk_edge_lengths(corners[kept]).view(np.uint32).ravel()
                bits = bits[(bits >> 16) == top]
                fine += np.bincount(bits & 0xFFFF, minlength=1 << 16)
            low = int(np.searchsorted(np.cumsum(fine), rank - below, side="right"))
            median = float(np.array([(top << 16) | low], dtype=np.uint32).view(np.float32)[0])
            decided = median
        try:
            exponent = tailor.chunk_cell_exponent(decided if chunk_cell is None else 0.0, chunk_cell)
        except tailor.Error as e:
            raise StreamError("%s: %s" % (layout.path, e)) from None
        return {"faces": faces, "lo": lo, "hi": hi, "median_edge": median, "about_median": decided,
                "cell_exponent": exponent}
    finally:
        body.close()


def _same_exponent(a, b):
    """Whether the automatic cell exponent is the same for every median edge length in [a, b] (it
    grows with the length): then the bin of the coarse histogram that holds the median decides it."""
    if not (0.0 < a <= b < math.inf):
        return False
    try:
        return tailor.chunk_cell_exponent(a) == tailor.chunk_cell_exponent(b)
    except tailor.Error:
        return False


def record_dtype(layout):
    return np.dtype([("i", layout.index_dtype, 3), ("p", "<f4", (3, 3))])


def _pack(cells):
    """(n, 3) int64 cells (or tiles) as one int64 each, in the order of (z, y, x)."""
    return ((cells[:, 2] + (1 << 20)) << 42) | ((cells[:, 1] + (1 << 20)) << 21) | (cells[:, 0] + (1 << 20))


def _unpack(key):
    mask = (1 << 21) - 1
    return ((key & mask) - (1 << 20), ((key >> 21) & mask) - (1 << 20), (key >> 42) - (1 << 20))


def tile_file(folder, tile):
    return pathlib.Path(folder) / ("%d_%d_%d.faces" % tuple(tile))


def part_ranges(face_count, parts, block_faces=BLOCK_FACES):
    """[begin, end) face ranges that cut the file into `parts` pieces of whole blocks, in file order."""
    blocks = -(-face_count // block_faces)
    parts = max(1, min(parts, blocks))
    bounds = [min(face_count, (blocks * k // parts) * block_faces) for k in range(parts + 1)]
    return list(zip(bounds[:-1], bounds[1:]))


def part_folder(scratch, part):
    return pathlib.Path(scratch) / ("part-%04d" % part)


def partition(layout, cell_exponent, tile_level, folder, begin=0, end=None, block_faces=BLOCK_FACES):
    """Appends every kept face of the faces [begin, end) (its vertex ids and corners, file order) to
    its tile's file in folder. Returns ({tile: face count}, the distinct chunk cells as a sorted int64
    array of packed keys).

    The files are written into a folder of this call's own and renamed into place when complete:
    a range run twice at once (a task Dask retried while its first worker, declared lost, still
    runs) or again (a retry) never mixes two runs' appends, and a folder in place is always whole.
    When another run put the folder in place first, this one's is dropped (it holds the same bytes)."""
    folder = pathlib.Path(folder)
    folder.parent.mkdir(parents=True, exist_ok=True)
    own = pathlib.Path(tempfile.mkdtemp(prefix=folder.name + ".run-", dir=folder.parent))
    try:
        result = _partition_into(layout, cell_exponent, tile_level, own, begin, end, block_faces)
        if not folder.exists():
            try:
                os.rename(own, folder)
            except OSError:  # another run's folder came first (not empty): it holds the same bytes
                pass
        return result
    finally:
        shutil.rmtree(own, ignore_errors=True)


def _partition_into(layout, cell_exponent, tile_level, folder, begin, end, block_faces):
    index_bytes = layout.index_dtype.itemsize
    counts, cells_seen = {}, []
    body = _Body(layout)
    try:
        for _, ids, corners, kept in body.blocks(block_faces, begin, end):
            ids, corners = ids[kept], corners[kept]
            if ids.shape[0] == 0:
                continue
            # The block's records (record_dtype) grouped by tile, file order within a tile.
            try:
                records, tiles, starts, cells = tailor._tailor._partition_block(
                    ids, corners, cell_exponent, tile_level, index_bytes
                )
            except tailor.Error as e:
                raise StreamError("%s: %s" % (layout.path, e)) from None
            del ids, corners
            cells_seen.append(cells)
            starts = starts.tolist()
            for k, key in enumerate(tiles.tolist()):
                tile = _unpack(key)
                with open(tile_file(folder, tile), "ab") as f:
                    f.write(records[starts[k] : starts[k + 1]])
                counts[tile] = counts.get(tile, 0) + (starts[k + 1] - starts[k])
    finally:
        body.close()
    return counts, np.unique(np.concatenate(cells_seen)) if cells_seen else np.empty(0, np.int64)


def partition_parts(layout, cell_exponent, tile_level, scratch, parts, run=None, block_faces=BLOCK_FACES):
    """The partition cut into `parts` ranges of the file, each into its own folder of the scratch
    folder; run(function, *args) -> results in order runs the parts (elsewhere: Dask), or here one
    after the other. A tile's faces in file order are its files in the parts' order. Returns
    ({tile: face count}, {tile: [its files, in order]}, number of distinct chunk cells)."""
    ranges = part_ranges(layout.face_count, parts, block_faces)
    args = [
        (layout, cell_exponent, tile_level, str(part_folder(scratch, k)), b, e, block_faces)
        for k, (b, e) in enumerate(ranges)
    ]
    results = run(partition, args) if run else [partition(*a) for a in args]
    counts, files = {}, {}
    for k, (part_counts, _) in enumerate(results):
        for tile, n in part_counts.items():
            counts[tile] = counts.get(tile, 0) + n
            files.setdefault(tile, []).append(str(tile_file(part_folder(scratch, k), tile)))
    cells = np.unique(np.concatenate([cells for _, cells in results]))
    return counts, files, int(cells.shape[0])


def read_tile(paths, index_dtype, cell_exponent, tile_level):
    """A tile's files, one after the other, as tailor.load and plan_chunks would give the tile: faces
    that repeat another face's vertices dropped (the first kept), faces grouped by chunk in cell
    order (file order within a chunk), the tile's vertices in the order of their ids. Returns
    (positions (V, 3) float32, faces (F, 3) uint32)."""
    dtype = np.dtype([("i", index_dtype, 3), ("p", "<f4", (3, 3))])
    sizes = [os.path.getsize(p) for p in paths]
    records = np.empty(sum(sizes) // dtype.itemsize, dtype=dtype)
    at = 0
    for path, size in zip(paths, sizes):
        with open(path, "rb") as f:
            at += f.readinto(memoryview(records.view(np.uint8))[at : at + size])
    ids = records["i"].astype(np.int64)
    corners = records["p"]
    del records
    # The vertices numbered in the order of their ids, the repeated faces dropped (the first kept).
    positions, faces, kept = tailor._tailor._compact_tile(ids, corners)
    del ids
    if tile_level > 0:
        cells = tailor.chunk_cells(corners[kept], cell_exponent).astype(np.int64)
        faces = faces[np.argsort(_pack(cells), kind="stable")]
    return positions, faces


def texels_per_unit(lo, hi, scale):
    """tailor.tiles.texels_per_unit_for from a streamed bounding box."""
    longest = float((hi.astype(np.float64) - lo.astype(np.float64)).max())
    if not (longest > 0) or not math.isfinite(longest):
        return None
    x = math.log2(float(np.float32(scale)) / longest)
    return math.ldexp(1.0, int(math.copysign(math.floor(abs(x) + 0.5), x)))
