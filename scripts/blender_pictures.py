"""The pictures of docs/blender.md, rendered headless by Blender (Cycles on the CPU):
  bash scripts/blender_pictures.sh    (makes the add-on's zip, runs this in blender -b)
1. blender_texture_map.png: spot at two sizes, mapped in one click with a tile size of 0.4 units:
   the tileable gravel repeats at the same size on both;
2. blender_uv_grid.png: the same with Blender's UV grid image, which shows the patches' directions
   and the seams (where the grid breaks); the scene is saved to SCENE for the dialog's picture
   (scripts/blender_dialog_picture.py)."""
import math
import os
import sys

import bpy

ZIP, MESH, IMAGE, OUT, SCENE = sys.argv[sys.argv.index("--") + 1:]

bpy.ops.preferences.addon_install(filepath=ZIP, overwrite=True)
bpy.ops.preferences.addon_enable(module="tailor_addon")
for o in list(bpy.data.objects):
    bpy.data.objects.remove(o)
bpy.ops.wm.obj_import(filepath=MESH, forward_axis="NEGATIVE_Y", up_axis="Z")
small = bpy.context.selected_objects[0]
small.name = "small"
large = small.copy()
large.data = small.data.copy()
large.name = "large"
bpy.context.collection.objects.link(large)
small.rotation_euler = (math.radians(90), 0, math.radians(150))
large.rotation_euler = (math.radians(90), 0, math.radians(150))
large.scale = (1.8, 1.8, 1.8)
bpy.context.view_layer.update()
# Both standing on z = 0, side by side.
small.location = (-1.1, -0.4, 0)
large.location = (0.8, 0.6, 0)
bpy.context.view_layer.update()
for obj in (small, large):
    lowest = min((obj.matrix_world @ v.co).z for v in obj.data.vertices)
    obj.location.z -= lowest
bpy.context.view_layer.update()
bpy.ops.object.select_all(action="SELECT")
bpy.context.view_layer.objects.active = small
bpy.ops.uv.tailor_texture_map(tile_size=0.4, assign_material=True, image_path=IMAGE, make_tileable=True)

scene = bpy.context.scene
scene.render.engine = "CYCLES"
scene.cycles.device = "CPU"
scene.cycles.samples = 64
scene.cycles.use_denoising = False  # Debian's Blender has no OpenImageDenoise
scene.render.resolution_x, scene.render.resolution_y = 480, 270
scene.render.image_settings.compression = 100
scene.render.film_transparent = False
world = bpy.data.worlds.new("sky")
world.use_nodes = True
world.node_tree.nodes["Background"].inputs["Color"].default_value = (0.8, 0.83, 0.88, 1)
world.node_tree.nodes["Background"].inputs["Strength"].default_value = 0.6
scene.world = world
bpy.ops.object.light_add(type="SUN", rotation=(math.radians(40), math.radians(10), math.radians(30)))
bpy.context.object.data.energy = 3.5
bpy.ops.object.camera_add(location=(0.1, -7.0, 2.7), rotation=(math.radians(76), 0, 0))
scene.camera = bpy.context.object
scene.camera.data.lens = 40


def render(name):
    scene.render.filepath = os.path.join(OUT, name)
    bpy.ops.render.render(write_still=True)


render("blender_texture_map.png")
bpy.ops.object.select_all(action="DESELECT")
for obj in (small, large):
    obj.select_set(True)
bpy.ops.uv.tailor_texture_map(tile_size=2.0)  # one grid image per 2 units, so its squares show
grid = bpy.data.images.new("uv grid", 1024, 1024)
grid.generated_type = "UV_GRID"
for obj in (small, large):
    for node in obj.data.materials[-1].node_tree.nodes:
        if node.type == "TEX_IMAGE":
            node.image = grid
render("blender_uv_grid.png")
bpy.ops.wm.save_as_mainfile(filepath=SCENE)
