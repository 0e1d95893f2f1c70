"""tailor.load and tailor.Mesh: round trips, dtypes, views, and bad arrays as errors."""
import base64
import json
import os
import pickle
import shutil
import struct

import numpy as np
import pytest

import tailor
from conftest import DATA, SPOT, bumpy_grid, run_cli


def test_load_counts_match_the_manifest():
    mesh = tailor.load(SPOT)
    assert (mesh.vertex_count, mesh.face_count) == (2930, 5856)
    assert mesh.positions.shape == (2930, 3) and mesh.positions.dtype == np.float32
    assert mesh.faces.shape == (5856, 3) and mesh.faces.dtype == np.uint32
    assert mesh.source == str(SPOT)
    assert mesh.load_report["format"] == "OBJ"
    assert mesh.corner_uvs is not None and mesh.corner_uvs.shape == (5856, 3, 2)  # spot.obj has vt


def write_scene_gltf(path):
    """A .gltf with a data: URI buffer: a triangle placed by a parent and a child node, a point
    primitive beside it, and a TANGENT attribute (what a mapping does not keep)."""
    data = struct.pack("<9f", 0, 0, 0, 1, 0, 0, 0, 1, 0) + struct.pack("<12f", *[1, 0, 0, 1] * 3)
    uri = "data:application/octet-stream;base64," + base64.b64encode(data).decode()
    gltf = {"asset": {"version": "2.0"}, "scene": 0, "scenes": [{"nodes": [0]}],
            "nodes": [{"children": [1], "translation": [5, 0, 0]}, {"mesh": 0, "scale": [1, 2, 1]}],
            "meshes": [{"primitives": [{"attributes": {"POSITION": 0, "TANGENT": 1}},
                                       {"attributes": {"POSITION": 0}, "mode": 0}]}],
            "buffers": [{"byteLength": len(data), "uri": uri}],
            "bufferViews": [{"buffer": 0, "byteLength": 36}, {"buffer": 0, "byteOffset": 36, "byteLength": 48}],
            "accessors": [{"bufferView": 0, "componentType": 5126, "count": 3, "type": "VEC3"},
                          {"bufferView": 1, "componentType": 5126, "count": 3, "type": "VEC4"}]}
    path.write_text(json.dumps(gltf))


def test_load_report_has_what_the_command_warns_about(tmp_path, tailor_binary):
    path = tmp_path / "scene.gltf"
    write_scene_gltf(path)
    report = tailor.load(path).load_report
    assert report["mesh_instances"] == 1 and report["skipped_primitives"] == 1
    assert "TANGENT" in report["not_kept"] and "node transforms" in report["not_kept"]
    assert report["texture_transform"] is False and report["primitive_without_uv"] == ""
    # The command's warning line quotes the same text.
    code, _, err = run_cli(tailor_binary, "map", path, "-o", tmp_path / "out.glb")
    assert code == 0, err
    assert f"tailor: warning: {path}: not kept in the output: {report['not_kept']}\n" in err
    # tailor info says the same of the file, before any map.
    code, out, err = run_cli(tailor_binary, "info", path, "--json")
    assert code == 0, err
    info = json.loads(out)
    assert (info["mesh_instances"], info["skipped_primitives"], info["not_kept"]) == (1, 1, report["not_kept"])
    code, out, _ = run_cli(tailor_binary, "info", path)
    assert "  skipped primitives     1 (points and lines, not read)\n" in out
    assert "  not kept in outputs    %s\n" % report["not_kept"] in out


def test_load_report_names_what_the_reader_read_past(tmp_path, tailor_binary):
    # An OFF header that counts one face of two: load_report, the map's warning and info agree.
    path = tmp_path / "short.off"
    path.write_text("OFF\n4 1 0\n0 0 0\n1 0 0\n0 1 0\n1 1 0\n3 0 1 2\n3 1 3 2\n")
    mesh = tailor.load(path)
    assert mesh.face_count == 1
    said = "1 line after the 1 face the OFF header declares (from line 8)"
    assert mesh.load_report["not_read"] == said
    code, _, err = run_cli(tailor_binary, "map", path, "-o", tmp_path / "out.glb")
    assert code == 0, err
    assert f"tailor: warning: {path}: not read: {said}\n" in err
    code, out, err = run_cli(tailor_binary, "info", path, "--json")
    assert code == 0, err
    assert json.loads(out)["not_read"] == said
    assert tailor.load(SPOT).load_report["not_read"] == ""


def test_arrays_round_trip_and_views_are_read_only():
    loaded = tailor.load(DATA / "meshes" / "fandisk.off")
    mesh = tailor.Mesh(loaded.positions, loaded.faces)
    assert np.array_equal(mesh.positions, loaded.positions)
    assert np.array_equal(mesh.faces, loaded.faces)
    assert mesh.corner_uvs is None and mesh.seam_faces is None
    view = mesh.positions
    assert np.shares_memory(view, mesh.positions)  # views of the mesh's own array, no copy
    assert not view.flags.writeable
    with pytest.raises(ValueError):
        view[0, 0] = 1.0


@pytest.mark.parametrize("position_type", [np.float32, np.float64, ">f4", ">f8"])
@pytest.mark.parametrize("face_type", [np.int32, np.int64, np.uint32, np.uint64, ">u4", ">i8"])
def test_every_accepted_dtype_gives_the_same_map(position_type, face_type):
    positions, faces = bumpy_grid(24)
    reference = tailor.map(tailor.Mesh(positions, faces))
    mesh = tailor.Mesh(positions.astype(position_type), faces.astype(face_type))
    assert np.array_equal(mesh.positions, positions)
    assert reference.corner_uvs.tobytes() == tailor.map(mesh).corner_uvs.tobytes()


def test_non_contiguous_arrays_are_read_correctly():
    positions, faces = bumpy_grid(16)
    mesh = tailor.Mesh(np.asfortranarray(positions), faces[::-1][::-1].T.copy().T)
    assert np.array_equal(mesh.positions, positions) and np.array_equal(mesh.faces, faces)
    strided = np.zeros((positions.shape[0], 6), np.float64)
    strided[:, ::2] = positions
    assert np.array_equal(tailor.Mesh(strided[:, ::2], faces).positions, positions)


def test_unpickled_arrays_are_accepted():
    # numpy gives an unpickled array (multiprocessing, Dask) its own, equal dtype object.
    positions, faces = bumpy_grid(8)
    copied = pickle.loads(pickle.dumps(positions))
    assert copied.dtype is not positions.dtype and copied.dtype == positions.dtype
    assert np.array_equal(tailor.Mesh(copied, pickle.loads(pickle.dumps(faces))).positions, positions)
    image = pickle.loads(pickle.dumps(np.zeros((32, 32, 3), np.uint8)))
    assert tailor.tile(image, block=8).dtype == np.uint8


def test_degenerate_and_duplicate_faces_are_dropped_and_counted():
    positions = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0], [1, 1, 0]], np.float32)
    faces = np.array([[0, 1, 2], [1, 3, 2], [0, 0, 1], [2, 0, 1]])
    mesh = tailor.Mesh(positions, faces)
    assert mesh.face_count == 2
    assert mesh.load_report["degenerate_faces"] == 1 and mesh.load_report["duplicate_faces"] == 1


def test_orient_faces_turns_back_faces_wound_against_their_neighbours():
    clean = tailor.load(SPOT)
    faces = np.array(clean.faces)
    faces[::97] = faces[::97][:, [0, 2, 1]]
    mesh = tailor.Mesh(np.array(clean.positions), faces)
    turned = tailor.orient_faces(mesh)
    assert turned.load_report["faces_turned"] == len(faces[::97])
    assert np.array_equal(turned.faces, clean.faces)
    assert np.array_equal(mesh.faces, faces)  # the argument is left as it was
    again = tailor.orient_faces(turned)
    assert again.load_report["faces_turned"] == 0 and np.array_equal(again.faces, clean.faces)


def test_file_names_that_are_not_utf8(tmp_path):
    # Python names such files with surrogate escapes (os.fsdecode); they must reach the same file.
    name = os.fsdecode(bytes(tmp_path) + b"/spot\xff.obj")
    shutil.copy(SPOT, name)
    mesh = tailor.load(name)
    assert mesh.source == name and mesh.face_count == tailor.load(SPOT).face_count
    assert "spot\\xff.obj" in repr(mesh)
    with pytest.raises(tailor.Error, match="missing\ufffd.ply: cannot open file"):
        tailor.load(os.fsdecode(bytes(tmp_path) + b"/missing\xff.ply"))
    image = os.fsdecode(bytes(tmp_path) + b"/sand\xfe_color.png")
    shutil.copy(DATA / "textures" / "vistex-sand05-128.png", image)
    folder = os.fsdecode(bytes(tmp_path) + b"/set\xfd")
    written = tailor.tile_set([image], folder)
    assert written == [os.path.join(folder, os.path.basename(image))] and os.path.exists(written[0])
    # A folder of maps recognised by name (material.json, being JSON, holds such names with U+FFFD).
    os.remove(os.path.join(folder, "material.json"))
    assert tailor.load_material(folder)["color"] == written[0]
    # A warning naming such a file (the photo does not wrap) is a warning, not a UnicodeDecodeError.
    with pytest.warns(UserWarning, match="sand\ufffd_color.png does not wrap"):
        tailor.map(mesh, texture=image)


GOOD_POSITIONS = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0]], np.float32)
GOOD_FACES = np.array([[0, 1, 2]], np.int32)


@pytest.mark.parametrize(
    "positions, faces, message",
    [
        (GOOD_POSITIONS[:, :2], GOOD_FACES, r"positions must be a \(V, 3\) array, got float32 \(3, 2\)"),
        (GOOD_POSITIONS, np.array([[0, 1, 2, 0]]), r"faces must be an \(F, 3\) array"),
        (GOOD_POSITIONS.astype(np.int32), GOOD_FACES, "positions must be float32 or float64"),
        (GOOD_POSITIONS, GOOD_FACES.astype(np.float32), "faces must be int32, int64, uint32 or uint64"),
        (np.array([[0, 0, 0], [1, 0, 0], [0, np.nan, 0]]), GOOD_FACES,
         r"^tailor.Mesh: vertex coordinate not finite or beyond the range of 32-bit floats \(3.4e38\) \(vertex 2\)$"),
        (np.array([[0, 0, 0], [1e39, 0, 0], [0, 1, 0]]), GOOD_FACES,
         r"^tailor.Mesh: vertex coordinate 1e\+39 beyond the range of 32-bit floats \(vertex 1\)$"),
        (GOOD_POSITIONS, np.array([[0, 1, 3]]),
         r"^tailor.Mesh: face index 3 out of range \(mesh has 3 vertices\) \(face 0\)$"),
        (GOOD_POSITIONS, np.array([[0, 1, 2], [0, -1, 2]]), r"face index -1 out of range .*\(face 1\)"),
        (GOOD_POSITIONS, np.array([[0, 1, 2 ** 40]], np.int64), "face index 1099511627776 out of range"),
        (GOOD_POSITIONS, np.zeros((0, 3), np.int32), "mesh has no faces"),
        (object(), GOOD_FACES, r"positions must be a \(V, 3\) array, got object \(\)"),
        ([[0, 0, 0], [1, 0], [0, 1, 0]], GOOD_FACES, "positions must be an array of numbers, got a list numpy cannot read as one"),
        (GOOD_POSITIONS, "abc", r"faces must be an \(F, 3\) array"),
    ],
)
def test_bad_arrays_raise_tailor_error(positions, faces, message):
    with pytest.raises(tailor.Error, match=message) as caught:
        tailor.Mesh(positions, faces)
    assert isinstance(caught.value, ValueError) and caught.value.code in ("invalid_argument", "invalid_mesh", "limit")
    assert tailor.Error("made by hand").code == "error"  # the class's, until one is given


def test_nested_lists_are_arrays():
    mesh = tailor.Mesh([[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]], [[0, 1, 2]])
    assert mesh.face_count == 1 and np.array_equal(mesh.positions, GOOD_POSITIONS.astype(np.float32))


def test_interrupts_inside_array_conversion_pass_through():
    # An __array__ that raises Ctrl-C or runs out of memory stops the call with that exception;
    # one that fails otherwise is an array numpy cannot read (tailor.Error).
    class Raising:
        def __init__(self, error):
            self.error = error

        def __array__(self, *args, **kwargs):
            raise self.error

    for error in (KeyboardInterrupt, MemoryError):
        with pytest.raises(error):
            tailor.Mesh(Raising(error), GOOD_FACES)
        with pytest.raises(error):
            tailor.map(tailor.Mesh(GOOD_POSITIONS, GOOD_FACES), seam_faces=Raising(error))
    with pytest.raises(tailor.Error, match="positions must be an array of numbers"):
        tailor.Mesh(Raising(RuntimeError("no")), GOOD_FACES)


def test_objects_made_without_init_are_refused():
    # cls.__new__(cls) without __init__ holds no C++ object: every use raises instead of reading
    # unconstructed memory (pybind11 allocates the value lazily and would hand it over).
    mesh = tailor.Mesh.__new__(tailor.Mesh)
    for use in (lambda: mesh.face_count, lambda: mesh.positions, lambda: repr(mesh),
                lambda: tailor.map(mesh), lambda: tailor.evaluate(mesh, np.zeros((0, 3, 2), np.float32))):
        with pytest.raises(tailor.Error, match=r"tailor.Mesh was made by __new__ without __init__"):
            use()
    result = tailor.Result.__new__(tailor.Result)
    with pytest.raises(tailor.Error, match="tailor.map returns one"):
        result.corner_uvs
    mapper = tailor.ChunkedMapper.__new__(tailor.ChunkedMapper)
    with pytest.raises(tailor.Error, match=r"tailor.ChunkedMapper\(cell_exponent, texels_per_unit\)"):
        mapper.set_chunk((0, 0, 0), tailor.Mesh(GOOD_POSITIONS, GOOD_FACES))
    # A subclass that initialises its base is a Mesh like any other.
    class Named(tailor.Mesh):
        def __init__(self, positions, faces):
            super().__init__(positions, faces)
    assert Named(GOOD_POSITIONS, GOOD_FACES).face_count == 1


def test_bad_files_raise_the_cli_message(tmp_path, tailor_binary):
    from conftest import run_cli

    bad = tmp_path / "bad.off"
    bad.write_text("OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 7\n")
    for path in (bad, tmp_path / "missing.ply", DATA / "meshes"):
        with pytest.raises(tailor.Error) as caught:
            tailor.load(path)
        code, _, err = run_cli(tailor_binary, "map", path, "-o", tmp_path / "out.glb")
        assert code == 1 and err.strip() == "tailor: error: " + str(caught.value)
    assert not (tmp_path / "out.glb").exists()
