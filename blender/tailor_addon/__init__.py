"""tailor for Blender: "UV > tailor: Texture Map" writes a UV map named "tailor" on the selected
mesh objects with tailor's patch discovery, at one world-space texel density (a tile size in scene
units), honouring marked seams, and optionally assigns a material with an image (made tileable by
tailor on request). It calls the Python module `tailor` (bundled in the add-on's zip for the Python
it was built for) and falls back to the `tailor` command. See docs/blender.md.
"""

bl_info = {
    "name": "tailor: Texture Map",
    "author": "tailor",
    "version": (0, 1, 0),
    "blender": (3, 4, 0),
    "location": "3D Viewport > UV > tailor: Texture Map (Edit Mode); Object > tailor: Texture Map",
    "description": "Texture-map meshes by homogeneous patch discovery, with self-tileable textures",
    "doc_url": "https://github.com/tailor/tailor/blob/main/docs/blender.md",
    "category": "UV",
}

if "bpy" in locals():  # reloading the add-on (F3 > Reload Scripts)
    import importlib

    from . import backend, mesh_data, material, operator, preferences

    for module in (backend, mesh_data, material, preferences, operator):
        importlib.reload(module)
else:
    from . import backend, mesh_data, material, operator, preferences  # noqa: F401

import bpy


def menu_entry(self, context):
    self.layout.separator()
    self.layout.operator(operator.TAILOR_OT_texture_map.bl_idname, text="tailor: Texture Map")


classes = (preferences.TailorPreferences, operator.TAILOR_OT_texture_map)


def register():
    for cls in classes:
        bpy.utils.register_class(cls)
    bpy.types.VIEW3D_MT_uv_map.append(menu_entry)
    bpy.types.VIEW3D_MT_object.append(menu_entry)


def unregister():
    bpy.types.VIEW3D_MT_object.remove(menu_entry)
    bpy.types.VIEW3D_MT_uv_map.remove(menu_entry)
    for cls in reversed(classes):
        bpy.utils.unregister_class(cls)
