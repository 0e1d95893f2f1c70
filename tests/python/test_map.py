"""tailor.map, save and evaluate: identity with the tailor command, options, errors."""
import json
import re
import warnings

import numpy as np
import pytest

import tailor
from conftest import DATA, GRAVEL, SPOT, bumpy_grid, run_cli


def without_times(stats):
    kept = {k: v for k, v in stats.items() if k not in ("time_ms", "output", "input", "previews", "peak_resident_mib")}
    if "mapping" in kept:  # each stage's time (mapping.stage_ms) differs from run to run
        kept["mapping"] = {k: v for k, v in kept["mapping"].items() if k != "stage_ms"}
    return kept


@pytest.mark.parametrize(
    "mesh_path, options, cli_options",
    [
        (SPOT, dict(texture=GRAVEL), ["--texture", GRAVEL]),
        (SPOT, dict(texture=GRAVEL, field_following=1, crack_rings=8), ["--texture", GRAVEL, "--field-following", "1",
                                                                         "--crack-rings", "8"]),
        (DATA / "meshes" / "fandisk.off", dict(axis="auto", texture_size=256), ["--axis", "auto", "--texture-size", "256"]),
        (DATA / "meshes" / "horse.ply", dict(axis=(0, 1, 0), scale=400, threads=2, close_cracks=False, smooth=2),
         ["--axis", "0,1,0", "--scale", "400", "--threads", "2", "--no-crack-closing", "--smooth", "2"]),
        (DATA / "meshes" / "horse.ply", dict(chunks="on", chunk_cell=-4, threads=2),
         ["--chunks", "on", "--chunk-cell", "-4", "--threads", "2"]),
        (DATA / "meshes" / "horse.ply", dict(chunks="on", chunk_cell=-3, chunk_split=4096),
         ["--chunks", "on", "--chunk-cell", "-3", "--chunk-split", "4096"]),
    ],
)
def test_map_is_bit_identical_to_the_cli(tmp_path, tailor_binary, mesh_path, options, cli_options):
    mesh = tailor.load(mesh_path)
    result = tailor.map(mesh, **options)
    for ext in (".glb", ".ply"):
        cli_out, py_out = tmp_path / ("cli" + ext), tmp_path / ("py" + ext)
        code, _, err = run_cli(tailor_binary, "map", mesh_path, "-o", cli_out, "-q", "--stats", tmp_path / "s.json",
                               *cli_options)
        assert code == 0, err
        tailor.save(py_out, mesh, result)
        assert py_out.read_bytes() == cli_out.read_bytes()
    cli_stats = json.loads((tmp_path / "s.json").read_text())
    assert without_times(result.stats) == without_times(cli_stats)
    assert result.metrics == cli_stats["metrics"]
    # The UVs as arrays are the file's UVs: reading the .ply back gives the same per-corner bits.
    back = tailor.load(tmp_path / "py.ply")
    assert back.corner_uvs.tobytes() == result.corner_uvs.tobytes()


def test_field_following_auto_follows_the_texture():
    mesh = tailor.load(SPOT)
    gravel = tailor.map(mesh, texture=GRAVEL)  # no direction: rigid unfolding, 32 crack rings
    assert gravel.stats["options"]["field_following"] == 0 and gravel.stats["options"]["crack_rings"] == 32
    assert gravel.stats["options"]["field_following_auto"] and gravel.stats["texture_isotropy"] >= 0.8
    plain = tailor.map(mesh)  # no texture: the orientation field, as the thesis
    assert plain.stats["options"]["field_following"] == 1 and "texture_isotropy" not in plain.stats
    assert tailor.map(mesh, texture=GRAVEL, crack_rings=12).stats["options"]["crack_rings"] == 12
    for bad in (1.5, -0.1, "sometimes", None):
        with pytest.raises(tailor.Error, match="--field-following must be auto or a number in"):
            tailor.map(mesh, field_following=bad)


def test_result_arrays(tmp_path):
    mesh = tailor.load(SPOT)
    result = tailor.map(mesh, texture_size=1024)
    assert result.corner_uvs.shape == (mesh.face_count, 3, 2) and result.corner_uvs.dtype == np.float32
    assert np.isfinite(result.corner_uvs).all()
    assert result.patch.shape == (mesh.face_count,) and result.patch.max() + 1 == result.patch_count
    assert result.texture_size == (1024, 1024)
    assert result.metrics["flipped"] == 0 and result.stats["texture_size"] == [1024, 1024]
    assert 0 < result.library_seconds
    # Seams: faces listed as seam faces move the cuts there (the counter reports them).
    seams = np.arange(0, mesh.face_count, 7)
    flagged = tailor.map(mesh, seam_faces=seams)
    mask = np.zeros(mesh.face_count, bool)
    mask[seams] = True
    assert flagged.stats["mapping"]["faces_seam"] == len(seams)
    assert tailor.map(mesh, seam_faces=mask).corner_uvs.tobytes() == flagged.corner_uvs.tobytes()


def test_evaluate_matches_the_map_and_the_cli(tmp_path, tailor_binary):
    mesh = tailor.load(SPOT)
    result = tailor.map(mesh)
    report = tailor.evaluate(mesh, result.corner_uvs, 512)
    for key in ("flipped", "seam_edges", "stretch", "l2_stretch", "seam_gap_px"):  # patches: derived
        assert report[key] == result.metrics[key], key
    tailor.save(tmp_path / "out.obj", mesh, result)
    code, out, err = run_cli(tailor_binary, "eval", tmp_path / "out.obj", "--json", "--texture-size", "512")
    assert code == 0, err
    cli = json.loads(out)
    back = tailor.load(tmp_path / "out.obj")
    ours = tailor.evaluate(back, back.corner_uvs, 512)
    for key in ("flipped", "seam_edges", "stretch", "l2_stretch", "linf_stretch", "distortion_deg"):
        assert ours[key] == cli[key], key
    with pytest.raises(tailor.Error, match=r"corner_uvs must be a float \(F, 3, 2\) array"):
        tailor.evaluate(mesh, result.corner_uvs[:10], 512)
    bad = np.array(result.corner_uvs)
    bad[3, 1, 0] = np.inf
    with pytest.raises(tailor.Error):
        tailor.evaluate(mesh, bad, 512)
    # Errors name the keywords, not the command's flags.
    with pytest.raises(tailor.Error, match=r"^texture_size must be between 1 and 65536, got 0x512$"):
        tailor.evaluate(mesh, result.corner_uvs, (0, 512))
    # numpy's integers are whole numbers as map takes them; a float or a triple is not a size.
    figures = {k: v for k, v in report.items() if k != "seconds"}
    for size in (np.int64(512), (np.int32(512), np.uint16(512))):
        assert {k: v for k, v in tailor.evaluate(mesh, result.corner_uvs, size).items() if k != "seconds"} == figures
    for not_a_size in (512.0, (512, 512, 1), "512"):
        with pytest.raises(tailor.Error, match=r"^texture_size must be an int or \(width, height\)$"):
            tailor.evaluate(mesh, result.corner_uvs, not_a_size)
    with pytest.raises(tailor.Error, match=r"^texture_size must be between 1 and 65536, got 1099511627776x"):
        tailor.evaluate(mesh, result.corner_uvs, 2**40)
    with pytest.raises(tailor.Error, match=r"^symmetry must be 1 or 4, got 2$"):
        tailor.evaluate(mesh, result.corner_uvs, 512, symmetry=2)
    with pytest.raises(tailor.Error, match=r"^symmetry=4 needs a square texture_size, got 512x256$"):
        tailor.evaluate(mesh, result.corner_uvs, (512, 256), symmetry=4)


@pytest.mark.parametrize(
    "options, cli_options",
    [
        (dict(scale=0), ["--scale", "0"]),
        (dict(hop_age=2.0), ["--hop-age", "2"]),
        (dict(max_stretch=5.0), ["--max-stretch", "5"]),
        (dict(crack_rings=1), ["--crack-rings", "1"]),
        (dict(relax_iterations=1001), ["--relax-iterations", "1001"]),
        (dict(smooth=1001), ["--smooth", "1001"]),
        (dict(axis="w"), ["--axis", "w"]),
        (dict(mode="thesis", symmetry=4), ["--mode", "thesis", "--symmetry", "4"]),
        (dict(mode="thesis", max_stretch=3.0), ["--mode", "thesis", "--max-stretch", "3"]),
        (dict(mode="thesis", close_cracks=False), ["--mode", "thesis", "--no-crack-closing"]),
        (dict(threshold=5.0), ["--threshold", "5"]),
        (dict(texture_size=0), ["--texture-size", "0"]),
        (dict(seed_point=(0, 1)), ["--seed-point", "0,1"]),
        (dict(texture=SPOT), ["--texture", SPOT]),
    ],
)
def test_bad_options_raise_the_cli_message(tmp_path, tailor_binary, options, cli_options):
    mesh = tailor.load(SPOT)
    with pytest.raises(tailor.Error) as caught:
        tailor.map(mesh, **options)
    code, _, err = run_cli(tailor_binary, "map", SPOT, "-o", tmp_path / "x.glb", *cli_options)
    assert code != 0 and err.strip() == "tailor: error: " + str(caught.value)


def test_bad_seam_faces_and_mismatched_save(tmp_path):
    mesh = tailor.load(SPOT)
    with pytest.raises(tailor.Error, match=r"seam face index 5856 out of range \(mesh has 5856 faces\)"):
        tailor.map(mesh, seam_faces=[1, 5856])
    with pytest.raises(tailor.Error, match="one entry per face"):
        tailor.map(mesh, seam_faces=np.zeros(3, bool))
    other = tailor.Mesh(*bumpy_grid(8))
    with pytest.raises(tailor.Error, match="save the mesh that was mapped"):
        tailor.save(tmp_path / "x.glb", mesh, tailor.map(other))
    with pytest.raises(tailor.Error, match="directory"):
        tailor.save(tmp_path / "missing" / "x.glb", mesh, tailor.map(mesh))
    # The C library ends a name at a NUL: "x\0.glb" would write "x", "SPOT\0.xyz" read SPOT.
    with pytest.raises(tailor.Error, match="path contains a NUL character"):
        tailor.save(str(tmp_path / "x\0.glb"), mesh, tailor.map(mesh))
    with pytest.raises(tailor.Error, match="path contains a NUL character"):
        tailor.load(str(SPOT) + "\0.xyz")
    # An empty path (texture=os.environ.get("TEX", "") with TEX unset) is refused, not taken for no
    # texture.
    for call in (lambda: tailor.map(mesh, texture=""), lambda: tailor.map(mesh, material=""),
                 lambda: tailor.load(""), lambda: tailor.save("", mesh, tailor.map(mesh))):
        with pytest.raises(tailor.Error, match="expected a path, got an empty one"):
            call()
    assert list(tmp_path.iterdir()) == []
    # No index is no seam face, whatever dtype numpy gives an empty list.
    assert np.array_equal(tailor.map(mesh, seam_faces=[]).corner_uvs, tailor.map(mesh).corner_uvs)


def test_unit_scale_gives_one_texel_density_whatever_the_size():
    positions, faces = bumpy_grid(40)
    densities = []
    for factor in (1.0, 3.0):
        mesh = tailor.Mesh(positions * factor, faces)
        densities.append(tailor.map(mesh, scale=100, unit_scale=1.0).metrics["uv_scale"])  # px^2 per unit^2
        normalised = tailor.map(mesh, scale=100).metrics["uv_scale"]
        assert normalised == pytest.approx(100**2 / (4 * factor) ** 2, rel=0.05)  # the longest side is 4 * factor
    assert densities[0] == pytest.approx(100**2, rel=0.05) and densities[1] == pytest.approx(100**2, rel=0.05)
    with pytest.raises(tailor.Error, match="unit_scale"):
        tailor.map(tailor.Mesh(positions, faces), unit_scale=-1)


def test_numbers_beyond_their_range_and_non_finite_uvs_are_errors(tmp_path):
    mesh = tailor.load(SPOT)
    with pytest.raises(tailor.Error, match=r"chunk_split must be a whole number in 0..4294967295, got 1180591620717411303424"):
        tailor.map(mesh, chunk_split=2**70)
    uvs = tailor.map(mesh).corner_uvs
    with pytest.raises(tailor.Error, match=r"texture_size's width must be a whole number in 1..2147483647, got 1099511627776"):
        tailor.save_uvs(tmp_path / "x.glb", mesh, uvs, (2**40, 512))
    with pytest.raises(tailor.Error, match=r"UV is not finite \(corner 3\)"):
        bad = uvs.copy()
        bad[1, 0, 0] = np.nan
        tailor.simplify_uvs(mesh, bad, 100)
    assert list(tmp_path.iterdir()) == []


def test_the_limits_are_those_map_and_the_cli_check(tailor_binary, tmp_path):
    # One table (MappingLimits, OrientationLimits): map() takes each end and refuses a step beyond
    # it, as the CLI does; the CLI's help shows the range, takes its ends as the help writes them
    # and refuses a step beyond before it reads the mesh, naming the flag.
    mesh = tailor.Mesh(*bumpy_grid(6))
    flags = {"scale": "--scale", "max_stretch": "--max-stretch", "hop_age": "--hop-age", "crack_rings": "--crack-rings",
             "relax_iterations": "--relax-iterations", "smooth": "--smooth"}
    path = tmp_path / "grid.glb"
    tailor.save(path, mesh, tailor.map(mesh))
    assert sorted(tailor.MAP_LIMITS) == sorted(flags)
    _, help_text, _ = run_cli(tailor_binary, "map", "--help")
    for name, flag in flags.items():
        entry = help_text[help_text.index("  " + flag + " "):]
        entry = entry[: entry.index("\n    --")]
        low_text, high_text = re.findall(r"\((\S+) to (\S+?)[ )]", entry)[-1]
        assert (float(low_text), float(high_text)) == pytest.approx(tailor.MAP_LIMITS[name], rel=1e-6), (flag, entry)
        assert name in tailor.map.__doc__ and f"({low_text} to {high_text}" in tailor.map.__doc__, name
        for text in (low_text, high_text):
            code, _, stderr = run_cli(tailor_binary, "map", path, "-o", tmp_path / "x.glb", flag, text)
            assert code == 0, (flag, text, stderr)
    for name, (low, high) in tailor.MAP_LIMITS.items():
        whole = isinstance(low, int)
        with warnings.catch_warnings():  # the scale's ends repeat the texture far too little or often
            warnings.simplefilter("ignore")
            for value in (low, high):
                tailor.map(mesh, **{name: value})
        beyond = [high + 1] + ([low - 1] if low > 0 else []) if whole else [float(np.nextafter(np.float32(high), np.float32(np.inf)))]
        for value in beyond:
            with pytest.raises(tailor.Error) as caught:
                tailor.map(mesh, **{name: value})
            code, _, stderr = run_cli(tailor_binary, "map", tmp_path / "missing.glb", "-o", tmp_path / "x.glb",
                                      flags[name], repr(value))
            assert str(caught.value).startswith(f"{flags[name]} must be between"), (name, value, caught.value)
            assert code == 2 and stderr == f"tailor: error: {caught.value}\n", (name, value, stderr)
        if not whole and low > 0:
            with pytest.raises(tailor.Error):
                tailor.map(mesh, **{name: float(np.nextafter(np.float32(low), np.float32(0)))})


def test_seam_faces_that_are_no_array():
    mesh = tailor.load(SPOT)
    for bad in ("abc", [[1, 2], [3, 4]], [0.5, 2.0], object()):
        with pytest.raises(tailor.Error, match="seam_faces"):
            tailor.map(mesh, seam_faces=bad)


def test_map_docstring_carries_the_cli_help(tailor_binary):
    _, help_text, _ = run_cli(tailor_binary, "map", "--help")
    for flag in ("--max-stretch", "--hop-age", "--crack-rings", "--relax-iterations", "--symmetry", "--smooth"):
        assert flag in help_text and flag in tailor.map.__doc__, flag


def test_symmetry_4_warns_as_the_cli(tmp_path, tailor_binary):
    mesh = tailor.load(SPOT)
    # A 1024 px texture at 800 px per mesh size repeats 0.78 times: the command's warning, as UserWarning.
    with pytest.warns(UserWarning, match="the 1024 px texture repeats 0.78 times across the mesh") as caught:
        tailor.map(mesh, symmetry=4, texture_size=1024, relax_iterations=0)
    code, _, err = run_cli(tailor_binary, "map", SPOT, "-o", tmp_path / "x.glb", "--symmetry", "4", "--texture-size",
                           "1024", "--relax-iterations", "0")
    assert code == 0 and f"tailor: warning: {caught[0].message}" in err
    # The gravel photo's tile is not unchanged by a quarter turn.
    with pytest.warns(UserWarning, match="gravel.png: --symmetry 4 but the texture is not unchanged by a quarter turn"):
        tailor.map(mesh, symmetry=4, texture=GRAVEL, relax_iterations=0)
    # A warnings filter that makes them errors stops the map with the warning.
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        with pytest.raises(UserWarning, match="repeats 0.78 times"):
            tailor.map(mesh, symmetry=4, texture_size=1024)
        tailor.map(mesh, symmetry=4, relax_iterations=0)  # 512 px, 1.56 repeats, no texture: nothing to say
        # Below one repeat in any mode: part of the texture is never seen.
        with pytest.raises(UserWarning, match="the 1024 px texture repeats 0.78 times across the mesh: part of it"):
            tailor.map(mesh, texture_size=1024, relax_iterations=0)


def test_a_texture_that_does_not_wrap_warns_as_the_cli(tmp_path, tailor_binary):
    mesh = tailor.load(SPOT)
    # The gravel photo's wrap is a cut (eval-tile's wrap ratio 2.89 / 3.63): the warning names the figure and the fix.
    with pytest.warns(UserWarning, match=r"gravel.png does not wrap \(wrap ratio 2.89 in x, 3.63 in y; .*with: tailor tile "):
        tailor.map(mesh, texture=GRAVEL, relax_iterations=0)
    tile = tmp_path / "gravel_tile.png"
    code, _, err = run_cli(tailor_binary, "tile", GRAVEL, "-o", tile, "-q")
    assert code == 0, err
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        tailor.map(mesh, texture=tile, relax_iterations=0)  # a tile from tailor tile wraps: nothing to say


def test_a_set_of_quarter_turn_tiles_is_mapped_with_symmetry_4(tmp_path, tailor_binary):
    import shutil

    textures = DATA / "textures"
    (tmp_path / "in").mkdir()
    shutil.copy(textures / "vistex-sand05-128.png", tmp_path / "in" / "sand_color.png")
    shutil.copy(textures / "vistex-bark11-128.png", tmp_path / "in" / "sand_normal.png")
    code, _, err = run_cli(tailor_binary, "tile", "--set", tmp_path / "in" / "sand_color.png",
                           tmp_path / "in" / "sand_normal.png", "--normal-map", tmp_path / "in" / "sand_normal.png",
                           "--symmetry", "4", "--same-size", "-o", str(tmp_path / "set4") + "/", "-q", "--allow-misses")
    assert code == 0, err
    mesh = tailor.load(SPOT)
    # The record (material.json) decides unless symmetry= is given, as `tailor map --material`.
    assert tailor.map(mesh, material=tmp_path / "set4", relax_iterations=0).stats["options"]["symmetry"] == 4
    assert tailor.map(mesh, material=tmp_path / "set4", symmetry=1, relax_iterations=0).stats["options"]["symmetry"] == 1
    # ... also a set tiled by tailor.tile_set (it writes the same material.json).
    tailor.tile_set([tmp_path / "in" / "sand_color.png", tmp_path / "in" / "sand_normal.png"], tmp_path / "py4",
                    normal_maps=[tmp_path / "in" / "sand_normal.png"], symmetry=4, same_size=True)
    assert tailor.map(mesh, material=tmp_path / "py4", relax_iterations=0).stats["options"]["symmetry"] == 4
    with pytest.raises(tailor.Error, match="--symmetry: 3 not in"):
        tailor.map(mesh, symmetry=3)


def test_auto_field_following_is_what_map_picks_for_a_texture():
    brick = DATA / "textures" / "brick-gray-512.png"
    assert tailor.auto_field_following(GRAVEL) == (0.0, 32)  # no direction: rigid unfolding, 32 rings
    assert tailor.auto_field_following(brick) == (1.0, 16)  # courses of bricks: follow the field
    mesh = tailor.load(SPOT)
    for texture in (GRAVEL, brick):
        field_following, crack_rings = tailor.auto_field_following(texture)
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            auto = tailor.map(mesh, texture=texture)
            given = tailor.map(mesh, texture=texture, field_following=field_following, crack_rings=crack_rings)
        assert np.array_equal(auto.corner_uvs, given.corner_uvs)
    with pytest.raises(tailor.Error, match="cannot open"):
        tailor.auto_field_following(DATA / "textures" / "missing.png")


def test_map_defaults_are_the_signature_and_the_tiles_flags():
    # tailor.MAP_DEFAULTS: the library's defaults by name, as map() shows them and tailor.tiles takes them.
    signature = tailor.map.__doc__.splitlines()[0]
    for name in ("texture_size", "scale", "max_stretch"):
        assert "%s: " % name in signature
        shown = signature.split("%s: " % name, 1)[1].split(",", 1)[0].split(" = ", 1)[1]
        assert float(shown) == pytest.approx(tailor.MAP_DEFAULTS[name], rel=1e-6), name
    assert tailor.MAP_DEFAULTS["crack_rings"] == 16  # map(crack_rings=None)'s documented value
    from tailor import tiles

    args = tiles.parse_args(["in.ply", "-o", "out"])
    assert args.texture_size == tailor.MAP_DEFAULTS["texture_size"]
    assert args.scale == tailor.MAP_DEFAULTS["scale"]
    assert args.max_stretch == tailor.MAP_DEFAULTS["max_stretch"]
