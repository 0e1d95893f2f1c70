"""Progress, cancelling, Ctrl-C and the GIL: a long map leaves other Python threads running."""
import _thread
import json
import os
import shutil
import struct
import threading
import time

import numpy as np
import pytest

import tailor
from conftest import GRAVEL, bumpy_grid


@pytest.fixture(scope="module")
def big_mesh():
    """About one million faces (a 708 x 708 grid over a wavy height field)."""
    mesh = tailor.Mesh(*bumpy_grid(708))
    assert mesh.face_count == 2 * 707 * 707
    return mesh


def test_million_faces_map_releases_the_gil(big_mesh):
    counts = []
    done = threading.Event()

    def count():  # pure Python: it can only run while map() has released the GIL
        n = 0
        while not done.is_set():
            n += 1
            if n % 1000 == 0:
                counts.append((time.monotonic(), n))

    worker = threading.Thread(target=count)
    worker.start()
    try:
        start = time.monotonic()
        result = tailor.map(big_mesh, close_cracks=False)
        end = time.monotonic()
    finally:
        done.set()
        worker.join()
    during = [n for t, n in counts if start < t < end]
    assert len(during) >= 10, "the other thread made no progress while map() ran"
    assert during[-1] - during[0] >= 10000
    uvs = result.corner_uvs
    assert uvs.shape == (big_mesh.face_count, 3, 2) and np.isfinite(uvs).all()
    assert result.metrics["flipped"] == 0 and result.stats["mesh"]["faces"] == big_mesh.face_count


def test_progress_is_called_and_can_stop(big_mesh):
    seen = []
    tailor.map(big_mesh, close_cracks=False, progress=seen.append)
    assert seen and seen[-1] == 1.0 and seen == sorted(seen) and all(0 <= f <= 1 for f in seen)
    assert seen.count(1.0) == 1, seen  # the end once, though the last stages each report it
    # With the axis chosen first, the choice and the mapping share the range: it never goes back.
    seen = []
    tailor.map(big_mesh, close_cracks=False, axis="auto", progress=seen.append)
    assert seen and seen[-1] == 1.0 and seen == sorted(seen) and seen.count(1.0) == 1, seen
    assert any(0.5 < f < 1 for f in seen), seen  # the mapping is heard, not only the choice
    calls = []

    def stop(fraction):
        calls.append(fraction)
        return False

    with pytest.raises(tailor.Error, match="cancelled") as caught:
        tailor.map(big_mesh, progress=stop)
    assert caught.value.code == "cancelled" and len(calls) == 1

    # numpy's False (a comparison) stops too; None goes on.
    with pytest.raises(tailor.Error, match="cancelled"):
        tailor.map(big_mesh, progress=lambda fraction: np.float32(fraction) < 0)

    class Stop(Exception):
        pass

    def fail(fraction):
        raise Stop("from the callback")

    with pytest.raises(Stop, match="from the callback"):
        tailor.map(big_mesh, progress=fail)


def test_ctrl_c_stops_a_long_map(big_mesh):
    # interrupt_main() is what a SIGINT does: the map notices it at its next progress report.
    timer = threading.Timer(0.3, _thread.interrupt_main)
    timer.start()
    start = time.monotonic()
    try:
        with pytest.raises(KeyboardInterrupt):
            tailor.map(big_mesh)  # with crack closing: several seconds if not stopped
    finally:
        timer.cancel()
    assert time.monotonic() - start < 2.0


def test_tile_from_array_and_file(tmp_path, tailor_binary):
    import json

    from conftest import run_cli

    tile, report = tailor.tile(GRAVEL, report=True)
    assert tile.dtype == np.uint8 and tile.ndim == 3
    code, _, err = run_cli(tailor_binary, "tile", GRAVEL, "-o", tmp_path / "t.png", "--json", tmp_path / "t.json")
    assert code == 0, err
    cli = json.loads((tmp_path / "t.json").read_text())
    for key in cli:
        if key not in ("seconds", "time_ms", "output", "tiles"):
            assert report[key] == cli[key], key
    again = tailor.tile(GRAVEL)
    assert again.tobytes() == tile.tobytes()
    assert tailor.tile(GRAVEL, seed=2).tobytes() != tile.tobytes()
    grey = np.ascontiguousarray(tile[:, :, 0])
    assert tailor.tile(grey).shape == grey.shape + (1,)
    with pytest.raises(tailor.Error, match="uint8"):
        tailor.tile(grey.astype(np.float32))
    with pytest.raises(tailor.Error):
        tailor.tile(np.zeros((8, 8, 3), np.uint8))  # too small to tile
    # A quarter-turn tile is twice the input's side, or its side with same_size.
    small = np.ascontiguousarray(tile[:128, :128])
    turned = tailor.tile(small, symmetry=4)
    assert turned.shape == (256, 256, small.shape[2])
    assert np.array_equal(np.rot90(turned), turned)
    assert tailor.tile(small, symmetry=4, same_size=True).shape == small.shape
    with pytest.raises(tailor.Error, match="same-size"):
        tailor.tile(small, same_size=True)


def test_tile_set_writes_the_maps_as_the_cli_does(tmp_path, tailor_binary):
    from conftest import run_cli

    textures = str(GRAVEL.parent.parent / "tests" / "data" / "textures") + os.sep
    sand, bark = textures + "vistex-sand05-128.png", textures + "vistex-bark11-128.png"
    written = tailor.tile_set([sand, bark], tmp_path / "py", normal_maps=[bark])
    assert [os.path.basename(p) for p in written] == ["vistex-sand05-128.png", "vistex-bark11-128.png"]
    # --allow-misses: bark read as a normal map is renormalised, so its tile misses the histogram target.
    code, _, err = run_cli(tailor_binary, "tile", "--set", sand, bark, "--normal-map", bark, "-o", tmp_path / "cli", "-q",
                           "--allow-misses")
    assert code == 0, err
    for name in ("vistex-sand05-128.png", "vistex-bark11-128.png", "material.json"):
        assert (tmp_path / "py" / name).read_bytes() == (tmp_path / "cli" / name).read_bytes(), name
    with pytest.raises(tailor.Error, match="water-caustics-300.jpg: every map of a set must have the same size"):
        tailor.tile_set([sand, textures + "water-caustics-300.jpg"], tmp_path / "bad")
    assert not (tmp_path / "bad").exists()
    # The maps' own folder: the tiles would replace them, which is refused before any work.
    own = tmp_path / "own"
    own.mkdir()
    shutil.copy(sand, own / "vistex-sand05-128.png")
    before = (own / "vistex-sand05-128.png").read_bytes()
    with pytest.raises(tailor.Error, match="would overwrite an input"):
        tailor.tile_set([own / "vistex-sand05-128.png"], own)
    assert (own / "vistex-sand05-128.png").read_bytes() == before
    (tmp_path / "a_file").write_text("")
    with pytest.raises(tailor.Error, match="not a folder"):
        tailor.tile_set([sand], tmp_path / "a_file")
    with pytest.raises(tailor.Error, match="normal_maps"):
        tailor.tile_set([sand], tmp_path / "bad", normal_maps=[bark])
    # With symmetry 4: one quarter-turn tile for both, the command's bytes; the tiles twice the side.
    tailor.tile_set([sand, bark], tmp_path / "py4", normal_maps=[bark], symmetry=4)
    code, _, err = run_cli(tailor_binary, "tile", "--set", sand, bark, "--normal-map", bark, "-o", tmp_path / "cli4",
                           "-q", "--allow-misses", "--symmetry", "4")
    assert code == 0, err
    for name in ("vistex-sand05-128.png", "vistex-bark11-128.png", "material.json"):
        assert (tmp_path / "py4" / name).read_bytes() == (tmp_path / "cli4" / name).read_bytes(), name
    assert json.loads((tmp_path / "py4" / "material.json").read_text())["symmetry"] == 4
    header = (tmp_path / "py4" / "vistex-sand05-128.png").read_bytes()[16:24]  # the PNG's IHDR width, height
    assert struct.unpack(">II", header) == (256, 256)


def test_maps_in_parallel_threads_give_the_sequential_bits():
    from concurrent.futures import ThreadPoolExecutor

    from conftest import DATA, SPOT

    meshes = [tailor.load(SPOT), tailor.load(DATA / "meshes" / "fandisk.off")] * 2
    sequential = [tailor.map(m).corner_uvs.tobytes() for m in meshes]
    with ThreadPoolExecutor(4) as pool:
        parallel = [r.corner_uvs.tobytes() for r in pool.map(tailor.map, meshes)]
    assert parallel == sequential
