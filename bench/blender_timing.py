"""The add-on's operator against Blender's Smart UV Project, headless:
  blender -b --factory-startup --python bench/blender_timing.py -- ZIP MESH.obj [MESH.obj ...]
(after `make blender-addon`: ZIP = out/tailor_addon.zip). Prints, per mesh, the faces and the
seconds of each (tailor: the operator with its defaults, module backend; Smart UV Project: its
defaults, in Edit Mode on every face), and a 999,698-face height field built with foreach_set."""
import sys
import time

import bpy
import numpy as np

ZIP, *MESHES = sys.argv[sys.argv.index("--") + 1:]
bpy.ops.preferences.addon_install(filepath=ZIP, overwrite=True)
bpy.ops.preferences.addon_enable(module="tailor_addon")


def grid_object(n=708):
    x, y = np.meshgrid(np.linspace(0, 4, n), np.linspace(0, 4, n), indexing="ij")
    z = 0.3 * np.sin(2.5 * x) * np.cos(3.0 * y) + 0.1 * np.sin(7 * x + 3 * y)
    positions = np.stack([x, y, z], axis=-1).reshape(-1, 3).astype(np.float32)
    i = (np.arange(n - 1)[:, None] * n + np.arange(n - 1)[None, :]).ravel()
    faces = np.concatenate([np.stack([i, i + n, i + n + 1], -1), np.stack([i, i + n + 1, i + 1], -1)])
    mesh = bpy.data.meshes.new("grid")
    mesh.vertices.add(len(positions))
    mesh.vertices.foreach_set("co", positions.ravel())
    mesh.loops.add(faces.size)
    mesh.loops.foreach_set("vertex_index", faces.ravel().astype(np.int32))
    mesh.polygons.add(len(faces))
    mesh.polygons.foreach_set("loop_start", np.arange(0, faces.size, 3, dtype=np.int32))
    mesh.polygons.foreach_set("loop_total", np.full(len(faces), 3, np.int32))
    mesh.update(calc_edges=True)
    obj = bpy.data.objects.new("grid", mesh)
    bpy.context.collection.objects.link(obj)
    return obj


def only(obj):
    bpy.ops.object.select_all(action="DESELECT")
    obj.select_set(True)
    bpy.context.view_layer.objects.active = obj


def measure(obj, label):
    only(obj)
    start = time.perf_counter()
    bpy.ops.uv.tailor_texture_map()
    tailor_s = time.perf_counter() - start
    bpy.ops.object.mode_set(mode="EDIT")
    bpy.ops.mesh.select_all(action="SELECT")
    start = time.perf_counter()
    bpy.ops.uv.smart_project()
    smart_s = time.perf_counter() - start
    bpy.ops.object.mode_set(mode="OBJECT")
    print(f"blender-timing: {label}: {len(obj.data.polygons)} faces  tailor {tailor_s:.2f} s  "
          f"Smart UV Project {smart_s:.2f} s")


for o in list(bpy.data.objects):
    bpy.data.objects.remove(o)
for path in MESHES:
    bpy.ops.wm.obj_import(filepath=path)
    measure(bpy.context.selected_objects[0], path.rsplit("/", 1)[-1])
measure(grid_object(), "height field")
