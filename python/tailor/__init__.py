"""tailor: texture mapping of triangle meshes by homogeneous patch discovery, and self-tileable
textures.

    import tailor
    mesh = tailor.load("bunny.ply")                  # or tailor.Mesh(positions, faces) from numpy
    result = tailor.map(mesh, texture="gravel_tile.png")
    result.corner_uvs                                # (F, 3, 2) float32, texture repeats
    tailor.save("bunny.glb", mesh, result)

Every call releases the GIL while the C++ library works; errors raise tailor.Error (a ValueError)
with the message the tailor command prints. See docs/python.md; `python3 -m tailor.tiles` maps a
large mesh as 3D Tiles on a Dask cluster (docs/scale.md).
"""
from ._tailor import (
    MAP_DEFAULTS,
    MAP_LIMITS,
    ChunkedMapper,
    Error,
    Mesh,
    Result,
    __version__,
    auto_field_following,
    canonical_tile,
    chunk_cell_exponent,
    chunk_cells,
    chunk_edge_lengths,
    evaluate,
    image_size,
    load,
    load_material,
    map,
    material_role,
    orient_faces,
    plan_chunks,
    save,
    save_uvs,
    simplify_uvs,
    tile,
    tile_set,
)

__all__ = [
    "MAP_DEFAULTS",
    "MAP_LIMITS",
    "ChunkedMapper",
    "Error",
    "Mesh",
    "Result",
    "auto_field_following",
    "canonical_tile",
    "chunk_cell_exponent",
    "chunk_cells",
    "chunk_edge_lengths",
    "evaluate",
    "image_size",
    "load",
    "load_material",
    "map",
    "material_role",
    "orient_faces",
    "plan_chunks",
    "save",
    "save_uvs",
    "simplify_uvs",
    "tile",
    "tile_set",
    "__version__",
]
