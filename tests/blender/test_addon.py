"""The Blender add-on, headless, as a user would use it (run by blender_test.sh):
  blender -b --factory-startup --python-exit-code 1 --python tests/blender/test_addon.py -- ZIP MESH IMAGE TAILOR TMP
Installs and enables the add-on from its zip, imports a mesh, marks seams, runs the operator with
the module backend and the command backend, and checks the UV map "tailor": every loop finite, no
flipped triangle, the marked seams handed to tailor, one texel density on objects of two sizes,
the material (an image, or a PBR material folder wired into the Principled BSDF), the automatic
field following on textures without direction, quarter-turn seams under a 4-fold tile, errors as reports, and the UVs after saving and
reloading the .blend."""
import os
import shutil
import sys
import traceback

import bpy
import numpy as np

ZIP, MESH, IMAGE, TAILOR, TMP, BUNDLED = sys.argv[sys.argv.index("--") + 1:]
# Without the Python module in the zip (a build without pybind11) the command backend does it all.
KIND = "module" if BUNDLED == "1" else "cli"
failures = []


def check(condition, what):
    print(("ok: " if condition else "FAIL: ") + what)
    if not condition:
        failures.append(what)


def loop_uvs(obj):
    layer = obj.data.uv_layers["tailor"]
    uv = np.empty(2 * len(obj.data.loops), np.float32)
    layer.data.foreach_get("uv", uv)
    return uv.reshape(-1, 2)


def triangle_arrays(obj):
    mesh = obj.data
    mesh.calc_loop_triangles()
    loops = np.empty(3 * len(mesh.loop_triangles), np.int32)
    mesh.loop_triangles.foreach_get("loops", loops)
    vertices = np.empty(3 * len(mesh.loop_triangles), np.int32)
    mesh.loop_triangles.foreach_get("vertices", vertices)
    co = np.empty(3 * len(mesh.vertices), np.float32)
    mesh.vertices.foreach_get("co", co)
    world = np.array(obj.matrix_world)
    positions = co.reshape(-1, 3) @ world[:3, :3].T + world[:3, 3]
    return loops.reshape(-1, 3), vertices.reshape(-1, 3), positions


def uv_figures(obj):
    """(finite, flipped triangles, UV area / world area in repeats^2 per unit^2)."""
    uv = loop_uvs(obj)
    loops, vertices, positions = triangle_arrays(obj)
    t = uv[loops]
    signed = 0.5 * ((t[:, 1, 0] - t[:, 0, 0]) * (t[:, 2, 1] - t[:, 0, 1]) -
                    (t[:, 2, 0] - t[:, 0, 0]) * (t[:, 1, 1] - t[:, 0, 1]))
    p = positions[vertices]
    area = 0.5 * np.linalg.norm(np.cross(p[:, 1] - p[:, 0], p[:, 2] - p[:, 0]), axis=1)
    real = area > 1e-12
    return bool(np.isfinite(uv).all()), int((signed[real] <= 0).sum()), float(np.abs(signed).sum() / area.sum())


def select_only(*objects):
    bpy.ops.object.select_all(action="DESELECT")
    for o in objects:
        o.select_set(True)
    bpy.context.view_layer.objects.active = objects[0]


def make_material(folder, backend):
    """gravel.png as the colour map, a bumpy DirectX normal map, roughness and occlusion of its size."""
    os.makedirs(folder, exist_ok=True)
    shutil.copy(IMAGE, os.path.join(folder, "gravel_color.png"))
    image = bpy.data.images.load(IMAGE)
    width, height = image.size
    y, x = np.mgrid[0:height, 0:width] / width * 2 * np.pi
    bumps = np.sin(4 * x) * np.cos(6 * y)
    n = np.stack([-np.gradient(bumps, axis=1) * 20, np.gradient(bumps, axis=0) * 20, np.ones_like(bumps)], -1)
    n /= np.linalg.norm(n, axis=-1, keepdims=True)
    backend.write_png(os.path.join(folder, "gravel_normal_dx.png"), np.round((n * 0.5 + 0.5) * 255))
    backend.write_png(os.path.join(folder, "gravel_roughness.png"), np.round(127 + 100 * bumps))
    backend.write_png(os.path.join(folder, "gravel_ao.png"), np.round(200 + 50 * bumps))
    with open(os.path.join(folder, "notes.txt"), "w") as f:
        f.write("not a map")
    return folder


def check_material_nodes(material):
    """The maps are wired as glTF means them: colour x occlusion, roughness, metallic, the normal map
    in tangent space of the UV map "tailor" (green flipped for the DirectX map)."""
    check(material.name == "tailor gravel_material", f"material named after the folder: {material.name}")
    nodes = material.node_tree.nodes
    shader = next(n for n in nodes if n.type == "BSDF_PRINCIPLED")
    textures = {n.label: n for n in nodes if n.type == "TEX_IMAGE"}
    check(sorted(textures) == ["color", "normal", "occlusion", "roughness"], f"four maps: {sorted(textures)}")
    check(all(t.image.colorspace_settings.name == "Non-Color" for r, t in textures.items() if r != "color"),
          "data maps are Non-Color")

    def source(socket):
        return socket.links[0].from_node if socket.is_linked else None

    check(source(shader.inputs["Roughness"]) == textures["roughness"], "roughness map -> Roughness")
    base = source(shader.inputs["Base Color"])
    check(base is not None and base.type == "MIX_RGB" and base.blend_type == "MULTIPLY" and
          source(base.inputs["Color2"]) == textures["occlusion"], "base colour x occlusion -> Base Color")
    normal = source(shader.inputs["Normal"])
    check(normal is not None and normal.type == "NORMAL_MAP" and normal.space == "TANGENT" and normal.uv_map == "tailor",
          "normal map node (tangent space, UV map tailor) -> Normal")
    check(normal is not None and source(normal.inputs["Color"]).type == "COMBINE_COLOR",
          "the DirectX normal map's green is flipped")
    check(all(source(t.inputs["Vector"]).type == "UVMAP" and source(t.inputs["Vector"]).uv_map == "tailor"
              for t in textures.values()), "every map reads the UV map tailor")


def main():
    bpy.ops.preferences.addon_install(filepath=ZIP, overwrite=True)
    bpy.ops.preferences.addon_enable(module="tailor_addon")
    preferences = bpy.context.preferences.addons["tailor_addon"].preferences
    from tailor_addon import backend

    if KIND == "module":
        check(backend.import_module() is not None, "the bundled module imports in Blender's Python")
    else:
        print("note: the zip has no Python module: testing the command backend only")
    for o in list(bpy.data.objects):
        bpy.data.objects.remove(o)
    bpy.ops.wm.obj_import(filepath=MESH)
    small = bpy.context.selected_objects[0]
    small.name = "small"
    # Seams: every edge crossing the plane x = 0 of the object (a closed loop around the mesh).
    mesh = small.data
    co = np.empty(3 * len(mesh.vertices), np.float32)
    mesh.vertices.foreach_get("co", co)
    x = co.reshape(-1, 3)[:, 0]
    ends = np.empty(2 * len(mesh.edges), np.int32)
    mesh.edges.foreach_get("vertices", ends)
    ends = ends.reshape(-1, 2)
    seam = (x[ends[:, 0]] < 0) != (x[ends[:, 1]] < 0)
    mesh.edges.foreach_set("use_seam", seam)
    _, vertices, _ = triangle_arrays(small)
    marked = {(min(a, b), max(a, b)) for a, b in ends[seam]}
    expected_seam_faces = sum(any((min(t[k], t[(k + 1) % 3]), max(t[k], t[(k + 1) % 3])) in marked for k in range(3))
                              for t in vertices)
    large = small.copy()
    large.data = small.data.copy()
    large.name = "large"
    large.scale = (2.5, 2.5, 2.5)
    large.location = (3, 0, 0)
    bpy.context.collection.objects.link(large)
    bpy.context.view_layer.update()

    # --- the module backend (or the command) on both objects, with the material and a tileable image ---
    select_only(small, large)
    preferences.backend = "MODULE" if KIND == "module" else "CLI"
    preferences.tailor_path = TAILOR
    result = bpy.ops.uv.tailor_texture_map(tile_size=0.25, assign_material=True, image_path=IMAGE,
                                           make_tileable=True)
    check(result == {"FINISHED"}, f"operator ({KIND}) finished: {result}")
    densities = []
    for obj in (small, large):
        finite, flipped, density = uv_figures(obj)
        check(finite, f"{obj.name}: every loop has a finite UV")
        check(flipped == 0, f"{obj.name}: 0 flipped triangles (got {flipped})")
        densities.append(density)
        check(obj["tailor"]["backend"] == KIND, f"{obj.name}: mapped by the {KIND} backend")
        check(obj["tailor"]["faces_seam"] == expected_seam_faces,
              f"{obj.name}: the {expected_seam_faces} faces along marked seams went to tailor "
              f"(got {obj['tailor']['faces_seam']})")
        material = obj.data.materials[-1]
        nodes = material.node_tree.nodes
        check(any(n.type == "UVMAP" and n.uv_map == "tailor" for n in nodes), f"{obj.name}: material uses UV map tailor")
        images = [n.image for n in nodes if n.type == "TEX_IMAGE"]
        check(len(images) == 1 and images[0].packed_file is not None, f"{obj.name}: the tileable image is packed")
    # One repeat per 0.25 units: 16 repeats^2 per unit^2 on both objects (the mapping stretches a bit).
    check(all(abs(d / 16.0 - 1) < 0.1 for d in densities), f"texel density 16/unit^2 on both sizes: {densities}")
    check(abs(densities[0] / densities[1] - 1) < 0.02, f"same density on both objects: {densities}")
    without_marks = None
    # Marked seams are honoured: faces along them are mapped last, so the cuts move there.
    seam_share = {}
    for use in (True, False):
        select_only(small)
        bpy.ops.uv.tailor_texture_map(tile_size=0.25, use_seams=use)
        uv = loop_uvs(small)
        loops, tri_vertices, _ = triangle_arrays(small)
        corner = {}
        cut_edges = set()
        for t in range(len(tri_vertices)):
            for k in range(3):
                a, b = tri_vertices[t, k], tri_vertices[t, (k + 1) % 3]
                key = (min(a, b), max(a, b))
                ua, ub = uv[loops[t, k]].tobytes(), uv[loops[t, (k + 1) % 3]].tobytes()
                side = (ua, ub) if a < b else (ub, ua)
                if key in corner and corner[key] != side:
                    cut_edges.add(key)
                corner.setdefault(key, side)
        on_marked = sum(1 for e in cut_edges if e in marked)
        seam_share[use] = on_marked / max(1, len(marked))
    check(seam_share[True] > seam_share[False],
          f"more marked edges become UV cuts with the marks honoured ({seam_share[True]:.2f}) than without "
          f"({seam_share[False]:.2f})")

    # --- automatic field following: rigid unfolding under gravel (no direction), the number otherwise ---
    check(large["tailor"]["field_following"] == 0, "auto field following: gravel's tile unfolds rigidly (0)")
    select_only(small)
    bpy.ops.uv.tailor_texture_map(tile_size=0.25, assign_material=True, image_path=IMAGE, auto_field_following=False)
    check(small["tailor"]["field_following"] == 1, "auto off: the Field following number (1)")
    bpy.ops.uv.tailor_texture_map(tile_size=0.25)
    check(small["tailor"]["field_following"] == 1, "no image: the Field following number (1)")

    # --- a material folder (gravel with a DirectX normal map, roughness, occlusion) ---
    folder = make_material(os.path.join(TMP, "gravel_material"), backend)
    for kind in ([KIND, "cli"] if KIND == "module" else ["cli"]):
        preferences.backend = "MODULE" if kind == "module" else "CLI"
        select_only(small)
        result = bpy.ops.uv.tailor_texture_map(tile_size=0.25, assign_material=True, material_path=folder)
        check(result == {"FINISHED"} and small["tailor"]["backend"] == kind, f"material folder ({kind}) finished")
        check(small["tailor"]["field_following"] == 0, f"material ({kind}): auto on its colour map (0)")
        finite, flipped, density = uv_figures(small)
        check(finite and flipped == 0 and abs(density / 16.0 - 1) < 0.1,
              f"material ({kind}): finite, 0 flipped, 16 repeats^2/unit^2 from the colour map's size ({density})")
    check_material_nodes(small.data.materials[-1])
    # Make tileable on a material folder: its maps tiled with one cut (tailor tile --set), packed.
    for kind in ([KIND, "cli"] if KIND == "module" else ["cli"]):
        preferences.backend = "MODULE" if kind == "module" else "CLI"
        select_only(small)
        result = bpy.ops.uv.tailor_texture_map(tile_size=0.25, assign_material=True, material_path=folder,
                                               make_tileable=True)
        check(result == {"FINISHED"} and small["tailor"]["backend"] == kind, f"tileable material ({kind}) finished")
        tiled = small.data.materials[-1]
        check(tiled.name == "tailor gravel_material_tile", f"tileable material ({kind}): named so ({tiled.name})")
        textures = {n.label: n.image for n in tiled.node_tree.nodes if n.type == "TEX_IMAGE"}
        check(sorted(textures) == ["color", "normal", "occlusion", "roughness"] and
              all(i.packed_file is not None for i in textures.values()),
              f"tileable material ({kind}): four maps, all packed: {sorted(textures)}")
        # The colour map now continues across its wrap (the source does not): mean difference across
        # the wrap over the mean difference between neighbouring columns.
        colour = np.empty(4 * 512 * 512, np.float32)
        textures["color"].pixels.foreach_get(colour)
        colour = colour.reshape(512, 512, 4)[:, :, 0]
        source = bpy.data.images.load(IMAGE)
        original = np.empty(4 * 512 * 512, np.float32)
        source.pixels.foreach_get(original)
        original = original.reshape(512, 512, 4)[:, :, 0]
        wrap = np.abs(colour[:, 0] - colour[:, -1]).mean() / np.abs(np.diff(colour, axis=1)).mean()
        raw = np.abs(original[:, 0] - original[:, -1]).mean() / np.abs(np.diff(original, axis=1)).mean()
        check(wrap < 1.3 < raw, f"tileable material ({kind}): the colour map wraps (ratio {wrap:.2f}, source {raw:.2f})")
    # A material folder made tileable with quarter turns: one 4-fold tile for all its maps.
    for kind in ([KIND, "cli"] if KIND == "module" else ["cli"]):
        preferences.backend = "MODULE" if kind == "module" else "CLI"
        select_only(small)
        result = bpy.ops.uv.tailor_texture_map(tile_size=0.25, assign_material=True, material_path=folder,
                                               make_tileable=True, quarter_turns=True)
        check(result == {"FINISHED"} and small["tailor"]["symmetry"] == 4, f"4-fold material ({kind}) finished")
        tiled = small.data.materials[-1]
        check(tiled.name == "tailor gravel_material_tile4", f"4-fold material ({kind}): named so ({tiled.name})")
        textures = {n.label: n.image for n in tiled.node_tree.nodes if n.type == "TEX_IMAGE"}
        check(sorted(textures) == ["color", "normal", "occlusion", "roughness"] and
              all(i.packed_file is not None and tuple(i.size) == (1024, 1024) for i in textures.values()),
              f"4-fold material ({kind}): four maps of 1024 px, all packed "
              f"({ {k: (tuple(i.size), i.packed_file is not None) for k, i in textures.items()} })")
        colour = np.empty(4 * 1024 * 1024, np.float32)
        textures["color"].pixels.foreach_get(colour)
        colour = colour.reshape(1024, 1024, 4)
        check(np.array_equal(np.rot90(colour), colour), f"4-fold material ({kind}): the colour map is unchanged by a quarter turn")
    preferences.backend = "MODULE" if KIND == "module" else "CLI"

    # --- quarter-turn seams (tailor map --symmetry 4) under a 4-fold tile made here, both backends ---
    for kind in ([KIND, "cli"] if KIND == "module" else ["cli"]):
        preferences.backend = "MODULE" if kind == "module" else "CLI"
        select_only(small)
        result = bpy.ops.uv.tailor_texture_map(tile_size=0.25, assign_material=True, image_path=IMAGE,
                                               make_tileable=True, quarter_turns=True)
        check(result == {"FINISHED"} and small["tailor"]["backend"] == kind, f"quarter turns ({kind}) finished")
        check(small["tailor"]["symmetry"] == 4, f"quarter turns ({kind}): mapped with symmetry 4")
        finite, flipped, density = uv_figures(small)
        check(finite and flipped == 0 and abs(density / 16.0 - 1) < 0.1,
              f"quarter turns ({kind}): finite, 0 flipped, 16 repeats^2/unit^2 ({density})")
        image = [n.image for n in small.data.materials[-1].node_tree.nodes if n.type == "TEX_IMAGE"][0]
        check(tuple(image.size) == (1024, 1024), f"quarter turns ({kind}): the tile is twice gravel's side ({image.size[:]})")
        pixels = np.empty(4 * image.size[0] * image.size[1], np.float32)
        image.pixels.foreach_get(pixels)
        pixels = pixels.reshape(image.size[1], image.size[0], 4)
        check(np.array_equal(np.rot90(pixels), pixels), f"quarter turns ({kind}): the tile is unchanged by a quarter turn")
        check(small["tailor"]["warnings"] == "", f"quarter turns ({kind}): no warning ({small['tailor']['warnings']})")
        # A tile larger than the object: the warning of tailor map, as a report and on the object.
        result = bpy.ops.uv.tailor_texture_map(tile_size=50.0, assign_material=True, image_path=IMAGE,
                                               make_tileable=True, quarter_turns=True)
        check(result == {"FINISHED"} and "times across the mesh; quarter-turn seams" in small["tailor"]["warnings"],
              f"quarter turns ({kind}), one repeat for many objects: warned ({small['tailor']['warnings']})")
    preferences.backend = "MODULE" if KIND == "module" else "CLI"

    # --- errors are reports, never a crash ---
    try:
        bpy.ops.uv.tailor_texture_map(assign_material=True, image_path=os.path.join(TMP, "missing.png"))
        check(False, "a missing image is an error")
    except RuntimeError as error:
        check("missing.png: the image file does not exist" in str(error), f"error report: {error}")

    # --- the command backend ---
    preferences.backend = "CLI"
    preferences.tailor_path = TAILOR
    select_only(large)
    result = bpy.ops.uv.tailor_texture_map(tile_size=0.25)
    check(result == {"FINISHED"} and large["tailor"]["backend"] == "cli", "operator (command) finished")
    finite, flipped, density = uv_figures(large)
    check(finite and flipped == 0, f"command: finite UVs, 0 flipped (got {flipped})")
    check(abs(density / densities[1] - 1) < 0.02, f"command: the module's density ({density} vs {densities[1]})")
    preferences.tailor_path = os.path.join(TMP, "no-such-tailor")
    try:
        bpy.ops.uv.tailor_texture_map(tile_size=0.25)
        check(False, "a missing command is an error")
    except RuntimeError as error:
        check("tailor command was not found" in str(error), f"error report: {error}")

    # --- save and reload ---
    before = {o.name: loop_uvs(o).copy() for o in (small, large)}
    path = os.path.join(TMP, "mapped.blend")
    bpy.ops.wm.save_as_mainfile(filepath=path)
    bpy.ops.wm.open_mainfile(filepath=path)
    for name, uv in before.items():
        obj = bpy.data.objects[name]
        check(np.array_equal(loop_uvs(obj), uv), f"{name}: UV map tailor unchanged after save and reload")


try:
    main()
except Exception:
    traceback.print_exc()
    failures.append("exception")
print(f"blender add-on test: {len(failures)} failed")
sys.exit(1 if failures else 0)
