"""tailor.ChunkedMapper: chunks mapped one by one are the bits of the whole mesh's chunked map."""
import numpy as np
import pytest

import tailor
from conftest import DATA


def test_a_chunk_set_alone_matches_the_mesh_and_the_cli_density():
    mesh = tailor.load(DATA / "meshes" / "horse.ply")
    mapper = tailor.ChunkedMapper(-4, 4096.0, threads=2)
    cells = mapper.set_mesh(mesh)
    assert len(cells) > 4 and mapper.cells() == cells
    assert mapper.cell_size == 2.0 ** -4 and mapper.texels_per_unit == 4096.0
    assert sum(len(mapper.chunk(c)["faces"]) for c in cells) == mesh.face_count
    # One chunk's faces as a mesh of their own, mapped alone: the same bits.
    cell = max(cells, key=lambda c: len(mapper.chunk(c)["faces"]))
    inside = mapper.chunk(cell)
    faces = mesh.faces[inside["faces"]]
    used, compact = np.unique(faces, return_inverse=True)
    part = tailor.Mesh(mesh.positions[used], compact.reshape(-1, 3).astype(np.uint32))
    alone = tailor.ChunkedMapper(-4, 4096.0)
    alone.set_chunk(cell, part)
    assert np.array_equal(alone.chunk(cell)["corner_uvs"], inside["corner_uvs"])
    assert alone.chunk(cell)["patch_count"] == inside["patch_count"]
    # Faces of another cell are refused; removing a chunk leaves the others.
    other = next(c for c in cells if c != cell)
    with pytest.raises(tailor.Error, match="outside the chunk's cell"):
        alone.set_chunk(other, part)
    before = mapper.chunk(other)["corner_uvs"].copy()
    assert mapper.remove_chunk(cell) and not mapper.remove_chunk(cell)
    assert mapper.chunk(cell) is None
    assert np.array_equal(mapper.chunk(other)["corner_uvs"], before)
    with pytest.raises(tailor.Error, match="texels per unit"):
        tailor.ChunkedMapper(-4, 0.0)
    with pytest.raises(tailor.Error, match="threads: value 1000000 not in range"):
        tailor.ChunkedMapper(-4, 4096.0, threads=10**6)


def test_cells_cut_into_parts_match_the_map_with_the_same_split():
    mesh = tailor.load(DATA / "meshes" / "horse.ply")
    whole = tailor.map(mesh, chunks="on", chunk_cell=-3, chunk_split=4096, texture_size=512)
    mapper = tailor.ChunkedMapper(-3, whole.stats["mapping"]["texels_per_unit"], chunk_split=4096)
    cells = mapper.set_mesh(mesh)
    assert len(cells) < whole.stats["mapping"]["chunks"]  # some cells hold more than 4096 faces: parts
    for cell in cells:
        chunk = mapper.chunk(cell)
        # The map's UVs are repeats of the 512-pixel texture, scaled as the writers scale them.
        repeats = (chunk["corner_uvs"].astype(np.float64) * (1.0 / 512)).astype(np.float32)
        assert np.array_equal(repeats, whole.corner_uvs[chunk["faces"]])
    with pytest.raises(tailor.Error, match="--chunk-split must be 0"):
        tailor.ChunkedMapper(-3, 4096.0, chunk_split=10)
    with pytest.raises(tailor.Error, match="chunk_split must be a whole number in 0..4294967295, got -1"):
        tailor.map(mesh, chunk_split=-1)


def test_bad_arguments_are_tailor_errors_naming_them():
    mesh = tailor.load(DATA / "meshes" / "horse.ply")
    for call, message in (
        (lambda: tailor.ChunkedMapper(-4, 4096.0).chunk((2**31, 0, 0)), r"^cell must be a whole number in"),
        (lambda: tailor.ChunkedMapper(-4, 4096.0).chunk((0.5, 0, 0)), r"^cell must be a whole number in .*got 0\.5$"),
        # A mapper has chunks or nothing: no advice to map without them.
        (lambda: tailor.ChunkedMapper(40, 4096.0), r"^the texel density gives .* chunk cell \(2\^-60 to 2\^60\) or texel density$"),
        (lambda: tailor.ChunkedMapper(-4, 4096.0).chunk("abc"), r"^cell must be three whole numbers \(x, y, z\), got 'abc'$"),
        (lambda: tailor.ChunkedMapper(-4, 4096.0, texture_size=(1.5, 2)), r"^texture_size's width must be a whole"),
        (lambda: tailor.ChunkedMapper(-4, 4096.0, crack_rings=10**12), r"^--crack-rings must be between 2 and 64 rings, got 1000000000000$"),
        (lambda: tailor.plan_chunks(mesh, 2**40), r"^chunk_cell must be a whole number in -60\.\.60"),
        (lambda: tailor.chunk_cell_exponent(0.01, 2**40), r"^chunk_cell must be a whole number in -60\.\.60"),
        (lambda: tailor.map(mesh, chunks="on", chunk_cell=61), r"^chunk_cell must be a whole number in -60\.\.60"),
    ):
        with pytest.raises(tailor.Error, match=message):
            call()
    # The mapping's options are checked when the mapper is made, not at its first chunk.
    with pytest.raises(tailor.Error, match=r"^field following must be in \[0, 1\]$"):
        tailor.ChunkedMapper(-4, 4096.0, field_following=5)
    # numpy's integers are whole numbers too.
    assert tailor.ChunkedMapper(-4, 4096.0, texture_size=(np.int64(256), 256)).chunk((np.int32(1), 0, 0)) is None


def test_a_cell_beyond_the_grid_is_no_other_cell():
    # Cells are kept by 21 bits a coordinate: one 2^21 away must not find (or remove) this one.
    mapper = tailor.ChunkedMapper(-2, 100.0)
    cell = mapper.set_mesh(tailor.load(DATA / "meshes" / "horse.ply"))[0]
    far = (cell[0] + 2**21, cell[1], cell[2])
    assert mapper.chunk(far) is None and not mapper.remove_chunk(far)
    assert mapper.chunk(cell) is not None
