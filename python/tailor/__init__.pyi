# Type stubs of the tailor module (the C++ extension tailor._tailor); docstrings: help(tailor.map).
import os
from typing import Any, Callable, Dict, List, Literal, Optional, Sequence, Tuple, Union, overload

import numpy as np
import numpy.typing as npt

__version__: str
# map()'s defaults of texture_size, scale, max_stretch and crack_rings (the library's, by name).
MAP_DEFAULTS: Dict[str, Union[int, float]]
# The ranges map() accepts of scale, max_stretch, hop_age, crack_rings and relax_iterations: (lowest, highest).
MAP_LIMITS: Dict[str, Tuple[Union[int, float], Union[int, float]]]

_Path = Union[str, os.PathLike[str]]
_Progress = Callable[[float], Optional[bool]]

class Error(ValueError):
    """Bad input, bad options or failed I/O; str() is the tailor command's one-line message."""

    code: str

class Mesh:
    """A triangle mesh: positions (V, 3) float32, faces (F, 3) uint32."""

    def __init__(self, positions: npt.ArrayLike, faces: npt.ArrayLike) -> None: ...
    @property
    def positions(self) -> npt.NDArray[np.float32]: ...
    @property
    def faces(self) -> npt.NDArray[np.uint32]: ...
    @property
    def corner_uvs(self) -> Optional[npt.NDArray[np.float32]]: ...
    @property
    def seam_faces(self) -> Optional[npt.NDArray[np.uint8]]: ...
    @property
    def vertex_count(self) -> int: ...
    @property
    def face_count(self) -> int: ...
    @property
    def source(self) -> str: ...
    @property
    def load_report(self) -> Dict[str, Any]:
        """LoadReport's fields by name: format, file_bytes, source_faces, polygons_triangulated,
        concave_polygons, degenerate_faces, duplicate_faces, zero_area_faces, unreferenced_vertices,
        welded_vertices, faces_collapsed_by_weld, faces_without_uv, primitive_without_uv, faces_turned,
        mesh_instances, skipped_primitives, not_kept, not_read, texture_width, texture_height, texture_file,
        texture_path, texture_named, texture_problem, texture_transform, texture_symmetry, load_seconds."""

class Result:
    """What map() returns."""

    @property
    def corner_uvs(self) -> npt.NDArray[np.float32]: ...
    @property
    def patch(self) -> npt.NDArray[np.uint32]: ...
    @property
    def patch_count(self) -> int: ...
    @property
    def texture_size(self) -> Tuple[int, int]: ...
    @property
    def stats(self) -> dict: ...
    @property
    def metrics(self) -> dict: ...
    @property
    def library_seconds(self) -> float: ...

class ChunkedMapper:
    def __init__(
        self,
        cell_exponent: int,
        texels_per_unit: float,
        *,
        threads: int = 0,
        field_following: float = 1.0,
        max_stretch: float = 0.25,
        texture_size: Optional[Tuple[int, int]] = None,
        crack_rings: Optional[int] = None,
        chunk_split: Optional[int] = None,
    ) -> None: ...
    def set_chunk(self, cell: Sequence[int], faces: Mesh) -> None: ...
    def set_mesh(self, mesh: Mesh) -> List[Tuple[int, int, int]]: ...
    def remove_chunk(self, cell: Sequence[int]) -> bool: ...
    def chunk(self, cell: Sequence[int]) -> Optional[Dict[str, Any]]: ...
    def cells(self) -> List[Tuple[int, int, int]]: ...
    @property
    def cell_size(self) -> float: ...
    @property
    def texels_per_unit(self) -> float: ...

def load(path: _Path) -> Mesh: ...
def orient_faces(mesh: Mesh) -> Mesh: ...
def plan_chunks(mesh: Mesh, chunk_cell: Optional[int] = None) -> Dict[str, Any]: ...
def chunk_edge_lengths(corners: np.ndarray) -> np.ndarray: ...
def chunk_cell_exponent(median_edge: float, chunk_cell: Optional[int] = None) -> int: ...
def chunk_cells(corners: np.ndarray, cell_exponent: int) -> np.ndarray: ...
def save_uvs(
    path: _Path,
    mesh: Mesh,
    corner_uvs: npt.ArrayLike,
    texture_size: Tuple[int, int],
    texture: Optional[_Path] = None,
    material: Union[_Path, Dict[str, Any], None] = None,
    up: Literal["y", "z"] = "y",
    image_uris: Dict[str, str] = ...,
) -> None: ...
def load_material(path: _Path) -> Dict[str, Any]: ...
def simplify_uvs(mesh: Mesh, corner_uvs: npt.ArrayLike, target_faces: int, lock_border: bool = True) -> Dict[str, Any]: ...
def canonical_tile(positions: npt.ArrayLike, faces: npt.ArrayLike) -> Tuple[np.ndarray, np.ndarray]: ...
def map(
    mesh: Mesh,
    texture_size: int = 512,
    scale: float = 800.0,
    axis: Union[Literal["pca", "skeleton", "x", "y", "z", "auto"], Sequence[float]] = "pca",
    seam_faces: Optional[npt.ArrayLike] = None,
    threads: int = 0,
    progress: Optional[_Progress] = None,
    *,
    texture: Optional[_Path] = None,
    mode: Literal["patches", "thesis"] = "patches",
    max_stretch: float = 0.25,
    field_following: Union[float, Literal["auto"]] = "auto",
    min_patch_faces: int = 16,
    hop_age: float = 0.02,
    shorten_seams: bool = True,
    close_cracks: bool = True,
    crack_rings: Optional[int] = None,
    relax_iterations: int = 10,
    threshold: float = 25.0,
    seed_point: Optional[Sequence[float]] = None,
    symmetry: Optional[Literal[1, 4]] = None,
    unit_scale: float = 0.0,
    smooth: int = 0,
    material: Optional[_Path] = None,
    chunks: Literal["auto", "on", "off"] = "auto",
    chunk_cell: Optional[int] = None,
    chunk_split: Optional[int] = None,
) -> Result: ...
@overload
def tile(
    image: Union[npt.NDArray[np.uint8], _Path],
    block: int = 32,
    overlap: int = 0,
    seed: int = 1,
    fit_period: bool = False,
    symmetry: Literal[1, 4] = 1,
    same_size: bool = False,
    report: Literal[False] = False,
    progress: Optional[_Progress] = None,
) -> npt.NDArray[np.uint8]: ...
@overload
def tile(
    image: Union[npt.NDArray[np.uint8], _Path],
    block: int = 32,
    overlap: int = 0,
    seed: int = 1,
    fit_period: bool = False,
    symmetry: Literal[1, 4] = 1,
    same_size: bool = False,
    *,
    report: Literal[True],
    progress: Optional[_Progress] = None,
) -> Tuple[npt.NDArray[np.uint8], dict]: ...
def tile_set(
    maps: Sequence[_Path],
    output: _Path,
    normal_maps: Sequence[_Path] = (),
    block: int = 32,
    overlap: int = 0,
    seed: int = 1,
    symmetry: Literal[1, 4] = 1,
    same_size: bool = False,
    progress: Optional[_Progress] = None,
) -> List[str]: ...
def auto_field_following(texture: _Path) -> Tuple[float, int]: ...
def image_size(texture: _Path) -> Tuple[int, int]: ...
def evaluate(
    mesh: Mesh,
    corner_uvs: npt.ArrayLike,
    texture_size: Union[int, Tuple[int, int]] = 512,
    symmetry: Literal[1, 4] = 1,
) -> dict: ...
def save(
    path: _Path, mesh: Mesh, result: Result, texture: Optional[_Path] = None, material: Optional[_Path] = None
) -> None: ...
def material_role(
    file_name: str,
) -> Tuple[Optional[Literal["color", "normal", "roughness", "metallic", "occlusion", "height"]], bool]: ...
