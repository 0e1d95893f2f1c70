"""tailor.map(material=...) and tailor.save(material=...): the material of `tailor map --material`,
bit for bit; material_role and the Blender add-on's copy of the suffix table agree."""
import importlib.util
import os
import shutil
import struct
import subprocess
import sys
import zlib

import numpy as np
import pytest

import tailor
from conftest import GRAVEL, ROOT, SPOT, run_cli


def write_png(path, pixels):
    """An 8-bit PNG of a (H, W) or (H, W, 3) uint8 array (no imaging library needed)."""
    pixels = np.ascontiguousarray(pixels, np.uint8)
    height, width = pixels.shape[:2]
    colour = {2: 0, 3: 2}[pixels.ndim]
    raw = b"".join(b"\0" + pixels[y].tobytes() for y in range(height))

    def chunk(kind, body):
        return struct.pack(">I", len(body)) + kind + body + struct.pack(">I", zlib.crc32(kind + body))

    header = struct.pack(">IIBBBBB", width, height, 8, colour, 0, 0, 0)
    path.write_bytes(b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", header) + chunk(b"IDAT", zlib.compress(raw)) +
                     chunk(b"IEND", b""))


@pytest.fixture
def material_dir(tmp_path):
    """gravel.png as the colour map, with a bumpy normal map, roughness and occlusion of its size."""
    folder = tmp_path / "gravel_material"
    folder.mkdir()
    shutil.copy(GRAVEL, folder / "gravel_Color.png")
    y, x = np.mgrid[0:512, 0:512] / 512.0 * 2 * np.pi
    height = np.sin(4 * x) * np.cos(6 * y)
    dx, dy = np.gradient(height, axis=1), -np.gradient(height, axis=0)
    n = np.stack([-dx * 20, -dy * 20, np.ones_like(dx)], -1)
    n /= np.linalg.norm(n, axis=-1, keepdims=True)
    write_png(folder / "gravel_normal.png", np.round((n * 0.5 + 0.5) * 255))
    write_png(folder / "gravel_roughness.png", np.round(127 + 100 * height))
    write_png(folder / "gravel_ao.png", np.round(200 + 50 * height))
    (folder / "readme.txt").write_text("not a map")
    return folder


def test_material_is_bit_identical_to_the_cli(tmp_path, tailor_binary, material_dir):
    mesh = tailor.load(SPOT)
    result = tailor.map(mesh, material=material_dir)
    assert result.texture_size == (512, 512)
    # The colour map decides 'auto' as --texture does: gravel has no direction.
    assert result.stats["options"]["field_following"] == 0 and result.stats["texture_isotropy"] >= 0.8
    cli_out, py_out = tmp_path / "cli.glb", tmp_path / "py.glb"
    code, _, err = run_cli(tailor_binary, "map", SPOT, "--material", material_dir, "-o", cli_out, "-q")
    assert code == 0, err
    tailor.save(py_out, mesh, result)
    assert py_out.read_bytes() == cli_out.read_bytes()
    assert b"normalTexture" in py_out.read_bytes() and b"TANGENT" in py_out.read_bytes()
    # Given again to save, the same file; an .obj after map(material=) names the colour map.
    tailor.save(tmp_path / "again.glb", mesh, result, material=material_dir)
    assert (tmp_path / "again.glb").read_bytes() == cli_out.read_bytes()
    tailor.save(tmp_path / "colour.obj", mesh, result)
    assert "gravel_Color.png" in (tmp_path / "colour.mtl").read_text()
    # Without the material the .glb has the colour only.
    tailor.save(tmp_path / "plain.glb", mesh, result, texture=material_dir / "gravel_Color.png")
    assert b"normalTexture" not in (tmp_path / "plain.glb").read_bytes()


def test_material_errors_are_the_cli_messages(tmp_path, material_dir):
    mesh = tailor.load(SPOT)
    with pytest.raises(tailor.Error, match="give --texture or --material, not both"):
        tailor.map(mesh, texture=GRAVEL, material=material_dir)
    with pytest.raises(tailor.Error, match="no map recognised"):
        tailor.map(mesh, material=tmp_path)
    small = tmp_path / "small"
    small.mkdir()
    shutil.copy(GRAVEL, small / "a_color.png")
    write_png(small / "a_normal.png", np.full((8, 8, 3), 128))
    with pytest.raises(tailor.Error, match="all maps of a material must share one size"):
        tailor.map(mesh, material=small)
    result = tailor.map(mesh, material=material_dir)
    with pytest.raises(tailor.Error, match="^material= needs a .glb output"):
        tailor.save(tmp_path / "x.obj", mesh, result, material=material_dir)
    with pytest.raises(tailor.Error, match="^give texture= or material=, not both"):
        tailor.save(tmp_path / "x.glb", mesh, result, texture=GRAVEL, material=material_dir)
    assert not (tmp_path / "x.obj").exists()
    (material_dir / "gravel.height.png").write_bytes((material_dir / "gravel_roughness.png").read_bytes())
    with pytest.warns(UserWarning, match="height map not embedded"):
        tailor.map(mesh, material=material_dir)


def test_a_material_that_is_a_fifo_is_refused_not_waited_on(tmp_path, material_dir):
    # Opening a FIFO for reading would block until a writer came: a material JSON, or a folder's
    # material.json, that is one is an error at once.
    # In a child process with a time limit: a regression fails here instead of hanging the suite.
    fifo = tmp_path / "m.json"
    os.mkfifo(fifo)
    os.mkfifo(material_dir / "material.json")
    script = (
        "import sys, tailor\n"
        "for material in sys.argv[1:]:\n"
        "    try:\n"
        "        tailor.load_material(material)\n"
        "    except tailor.Error as e:\n"
        "        print(e)\n"
    )
    env = dict(os.environ, PYTHONPATH=os.pathsep.join(sys.path))
    done = subprocess.run([sys.executable, "-c", script, str(fifo), str(material_dir)], env=env,
                          capture_output=True, text=True, timeout=60)  # fmt: skip
    lines = done.stdout.splitlines()
    assert len(lines) == 2 and "m.json: not a regular file" in lines[0], done
    assert "material.json: not a regular file" in lines[1], done


def test_save_uvs_writes_a_material_read_once(tmp_path, material_dir):
    # Per-corner UVs in pixels, as ChunkedMapper gives them, with the material of `tailor map
    # --material`: read from the folder, or once by load_material for many files.
    mesh = tailor.load(SPOT)
    with pytest.warns(UserWarning, match="does not wrap"):  # the example photo is not a tile: fine here
        uv = tailor.map(mesh, material=material_dir).corner_uvs * np.float32(512)
    loaded = tailor.load_material(material_dir)
    assert (loaded["width"], loaded["height"]) == (512, 512) and loaded["color"].endswith("gravel_Color.png")
    assert loaded["normal_png"][:8] == b"\x89PNG\r\n\x1a\n" and loaded["orm_png"][:8] == b"\x89PNG\r\n\x1a\n"
    assert loaded["orm_roughness_metallic"] and loaded["orm_occlusion"] and len(loaded["files"]) == 4
    tailor.save_uvs(tmp_path / "folder.glb", mesh, uv, (512, 512), material=material_dir)
    tailor.save_uvs(tmp_path / "loaded.glb", mesh, uv, (512, 512), material=loaded)
    data = (tmp_path / "folder.glb").read_bytes()
    assert data == (tmp_path / "loaded.glb").read_bytes()
    assert b"normalTexture" in data and b"TANGENT" in data and b"occlusionTexture" in data
    assert loaded["normal_png"] in data and loaded["orm_png"] in data and GRAVEL.read_bytes() in data
    # up='z': the node turns Z-up coordinates Y up, as `tailor map --up z`.
    tailor.save_uvs(tmp_path / "z.glb", mesh, uv, (512, 512), up="z")
    assert b'"rotation":[-0.7071067811865476,0.0,0.0,0.7071067811865476]' in (tmp_path / "z.glb").read_bytes()
    with pytest.raises(tailor.Error, match="^give texture= or material=, not both"):
        tailor.save_uvs(tmp_path / "x.glb", mesh, uv, (512, 512), texture=GRAVEL, material=loaded)
    with pytest.raises(tailor.Error, match="^the material is 512x512 but texture_size is 256x256"):
        tailor.save_uvs(tmp_path / "x.glb", mesh, uv, (256, 256), material=loaded)
    with pytest.raises(tailor.Error, match="^--up must be y or z, got 'x'"):
        tailor.save_uvs(tmp_path / "x.glb", mesh, uv, (512, 512), up="x")
    # An edited dict is checked as it is read: sizes, maps, flags, symmetry.
    for key, value, message in [
        ("width", 10**12, r"material\['width'\] must be a whole number in 1..16384"),
        ("normal_png", b"notapng", r"material\['normal_png'\] must be a PNG of the material's 512x512 px"),
        ("orm_png", "text", r"material\['orm_png'\] must be bytes or None"),
        ("orm_occlusion", "yes", r"material\['orm_occlusion'\] must be True or False"),
        ("symmetry", 3, r"material\['symmetry'\] must be 0, 1 or 4"),
    ]:
        with pytest.raises(tailor.Error, match=message):
            tailor.save_uvs(tmp_path / "x.glb", mesh, uv, (512, 512), material=dict(loaded, **{key: value}))
    assert not (tmp_path / "x.glb").exists()
    with pytest.raises(tailor.Error, match="no map recognised"):
        tailor.load_material(tmp_path)
    # image_uris: the maps named instead of embedded; a bad role, URI or output is one error, no file.
    uris = {"color": "../c.png", "normal": "../n.png", "orm": "../o.png"}
    tailor.save_uvs(tmp_path / "named.glb", mesh, uv, (512, 512), material=loaded, image_uris=uris)
    named = (tmp_path / "named.glb").read_bytes()
    assert all(('"uri":"%s"' % u).encode() in named for u in uris.values())
    assert loaded["normal_png"] not in named and len(named) < len(data) - len(loaded["orm_png"])
    for bad, message in (
        ({"colour": "c.png"}, "^image_uris: a role is color, normal or orm, got 'colour'"),
        ({"color": None}, "^image_uris: the URI of color must be a str"),
        ({"color": ""}, "^image_uris: the URI of color is empty"),
        ({"orm": "o.png"}, "an image URI is given for the ORM map but it serves as neither"),
    ):
        with pytest.raises(tailor.Error, match=message):
            tailor.save_uvs(tmp_path / "x.glb", mesh, uv, (512, 512), texture=GRAVEL, image_uris=bad)
    with pytest.raises(tailor.Error, match="images named by URI need a .glb output"):
        tailor.save_uvs(tmp_path / "x.obj", mesh, uv, (512, 512), texture=GRAVEL, image_uris={"color": "c.png"})
    assert not (tmp_path / "x.glb").exists() and not (tmp_path / "x.obj").exists()


def load_addon_table():
    path = ROOT / "blender" / "tailor_addon" / "material_files.py"
    spec = importlib.util.spec_from_file_location("tailor_material_files", path)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def test_material_role_and_the_blender_addon_agree(tmp_path, material_dir):
    files = load_addon_table()
    words = [w for w, _, _ in files._WORDS] + ["normals", "colorful", "mao", "rock", "ao_map", "x"]
    names = []
    for word in words:
        for stem in (word, f"rock_{word}", f"Rock-{word.upper()}", f"rock {word}", f"rock.{word}", f"rock{word}"):
            names.append(stem + ".png")
    names += ["bark_normal-GL.png", "bark_Normal_DX.jpg", "bark metalness.png", "bark.height.png", "notes.txt"]
    for name in names:
        assert files.role(name) == tailor.material_role(name), name
    assert tailor.material_role("wall_normal_dx.png") == ("normal", True)
    assert tailor.material_role("wall.png") == (None, False)
    maps = files.find_maps(str(material_dir))
    assert {k: v[0].rsplit("/", 1)[1] for k, v in maps.items()} == {
        "color": "gravel_Color.png", "normal": "gravel_normal.png", "roughness": "gravel_roughness.png",
        "occlusion": "gravel_ao.png"}
    shutil.copy(GRAVEL, material_dir / "gravel_albedo.png")
    with pytest.raises(RuntimeError, match="two files claim the color map"):
        files.find_maps(str(material_dir))
