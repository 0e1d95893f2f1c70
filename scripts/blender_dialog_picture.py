"""docs/images/blender_dialog.png: Blender's window with the operator's dialog open over the scene
of blender_pictures.py, taken under a virtual X server (xvfb-run, Mesa's software OpenGL):
  xvfb-run blender SCENE.blend --factory-startup --python scripts/blender_dialog_picture.py -- ZIP OUT.png
Timers wait for the window: frame the objects in Material Preview, invoke the operator as the UV
menu does, take the screenshot, quit."""
import sys

import bpy

ZIP, OUT = sys.argv[sys.argv.index("--") + 1:]
bpy.ops.preferences.addon_install(filepath=ZIP, overwrite=True)
bpy.ops.preferences.addon_enable(module="tailor_addon")


def view3d():
    window = bpy.context.window_manager.windows[0]
    area = next(a for a in window.screen.areas if a.type == "VIEW_3D")
    return window, area, next(r for r in area.regions if r.type == "WINDOW")


def open_dialog():
    window, area, region = view3d()
    area.spaces[0].shading.type = "MATERIAL"
    area.spaces[0].overlay.show_floor = False
    with bpy.context.temp_override(window=window, area=area, region=region):
        for obj in bpy.context.view_layer.objects:
            obj.select_set(obj.type == "MESH")
        bpy.context.view_layer.objects.active = bpy.data.objects["large"]
        bpy.ops.view3d.view_selected()
        for _ in range(4):  # the objects to the left of the dialog
            bpy.ops.view3d.view_pan(type="PANRIGHT")
        bpy.ops.uv.tailor_texture_map("INVOKE_DEFAULT", tile_size=2.0)


def screenshot():
    window, _, _ = view3d()
    with bpy.context.temp_override(window=window):
        bpy.ops.screen.screenshot(filepath=OUT)


bpy.app.timers.register(open_dialog, first_interval=2.0)
bpy.app.timers.register(screenshot, first_interval=14.0)  # after Eevee compiled its shaders
bpy.app.timers.register(lambda: bpy.ops.wm.quit_blender(), first_interval=16.0)
