"""The add-on's preferences: which backend maps (the Python module or the tailor command) and
where the command is."""
import bpy


class TailorPreferences(bpy.types.AddonPreferences):
    bl_idname = __package__

    backend: bpy.props.EnumProperty(
        name="Backend",
        items=[
            ("AUTO", "Automatic", "The Python module when it imports in Blender's Python, else the tailor command"),
            ("MODULE", "Python module", "The tailor module (bundled in the add-on's zip, or installed)"),
            ("CLI", "Command", "The tailor command (a subprocess per object)"),
        ],
        default="AUTO",
    )
    tailor_path: bpy.props.StringProperty(
        name="tailor command",
        description="The tailor executable for the command backend (empty: 'tailor' on PATH)",
        subtype="FILE_PATH",
        default="",
    )

    def draw(self, context):
        from . import backend

        self.layout.prop(self, "backend")
        self.layout.prop(self, "tailor_path")
        module = backend.import_module()
        self.layout.label(text="Python module: " + (f"tailor {module.__version__}" if module else "not importable"))
