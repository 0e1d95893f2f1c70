"""The operator "tailor: Texture Map" (UV menu in Edit Mode, Object menu): maps every selected mesh
object into the UV map "tailor" at one world-space texel density, then optionally assigns a
material with an image or a PBR material folder. Errors become Blender reports; Blender itself
never sees an exception."""
import os
import tempfile

import bpy
import numpy as np

from . import backend, material, material_files, mesh_data


class TAILOR_OT_texture_map(bpy.types.Operator):
    """Texture-map the selected meshes with tailor: UV map "tailor", the same texel density on every object"""

    bl_idname = "uv.tailor_texture_map"
    bl_label = "tailor: Texture Map"
    bl_options = {"REGISTER", "UNDO"}

    # The defaults are those of tailor's library (tailor map --help).
    tile_size: bpy.props.FloatProperty(
        name="Tile size", description="Scene units one repeat of the texture covers, on every object",
        default=1.0, min=1e-6, soft_min=0.01, soft_max=100.0, unit="LENGTH")
    texture_size: bpy.props.IntProperty(
        name="Texture size",
        description="Pixels of one repeat when no image is given (the image's or the material's width otherwise)",
        default=512, min=8, max=16384)
    axis: bpy.props.EnumProperty(
        name="Axis", description="Direction the texture follows (projected on each face)",
        items=[("pca", "Principal axis", "The mesh's first principal axis (the thesis)"),
               ("auto", "Automatic", "Of PCA, X, Y, Z, the one leaving the least seam (4 trial maps)"),
               ("x", "X", "World X"), ("y", "Y", "World Y"), ("z", "Z", "World Z")],
        default="pca")
    use_seams: bpy.props.BoolProperty(
        name="Use marked seams", description="Faces along edges marked as seams are mapped last, so the cuts move there",
        default=True)
    max_stretch: bpy.props.FloatProperty(
        name="Max stretch", description="Per-face bound on the stretch: singular values within [1/(1+x), 1+x]",
        default=0.25, min=0.01, max=4.0)
    auto_field_following: bpy.props.BoolProperty(
        name="Automatic field following",
        description="As tailor map's default (auto): rigid unfolding (fewer seams) for an image or material "
                    "without direction (gravel, grass), the field otherwise; without an image, Field following",
        default=True)
    field_following: bpy.props.FloatProperty(
        name="Field following", description="1: the texture direction follows the field; 0: rigid unfolding (fewer seams)",
        default=1.0, min=0.0, max=1.0)
    close_cracks: bpy.props.BoolProperty(
        name="Close cracks", description="Zip cuts inside a patch shut (about half the seam length, 3-10x the time)",
        default=True)
    relax_iterations: bpy.props.IntProperty(
        name="Relaxation", description="Iterations of the final ARAP relaxation (0: off)", default=10, min=0, max=1000)
    quarter_turns: bpy.props.BoolProperty(
        name="Quarter-turn seams",
        description="Experimental (tailor map --symmetry 4): an integer-grid map whose seams are quarter turns plus "
                    "whole repeats, invisible under a square tile that a quarter turn leaves unchanged; with Make "
                    "tileable the tile is made so (twice the image's side). Best with many repeats per object",
        default=False)
    threads: bpy.props.IntProperty(
        name="Threads", description="0: automatic; the result is the same for any count", default=0, min=0, max=64)
    assign_material: bpy.props.BoolProperty(
        name="Assign material", description="Give the objects a material showing the image through the UV map",
        default=False)
    image_path: bpy.props.StringProperty(
        name="Image", description="Texture image (PNG, JPEG...)", subtype="FILE_PATH", default="")
    material_path: bpy.props.StringProperty(
        name="Material folder",
        description="A PBR material instead of the image: a folder of maps named *_color, *_normal, *_roughness, "
                    "*_metallic, *_ao (as tailor map --material)",
        subtype="DIR_PATH", default="")
    make_tileable: bpy.props.BoolProperty(
        name="Make tileable",
        description="Make the image, or the material folder's maps with one cut for all, self-tileable with tailor "
                    "first (packed into the .blend)",
        default=False)

    @classmethod
    def poll(cls, context):
        return any(o.type == "MESH" for o in context.selected_objects)

    def draw(self, context):
        layout = self.layout
        layout.use_property_split = True
        box = layout.box()
        box.label(text="Density")
        box.prop(self, "tile_size")
        box.prop(self, "texture_size")
        box = layout.box()
        box.label(text="Mapping")
        for name in ("axis", "use_seams", "max_stretch", "auto_field_following", "field_following", "close_cracks",
                     "relax_iterations", "quarter_turns", "threads"):
            box.prop(self, name)
        box = layout.box()
        box.label(text="Material")
        box.prop(self, "assign_material")
        row = box.column()
        row.enabled = self.assign_material
        row.prop(self, "image_path")
        row.prop(self, "material_path")
        row.prop(self, "make_tileable")

    def invoke(self, context, event):
        return context.window_manager.invoke_props_dialog(self, width=380)

    def execute(self, context):
        objects = [o for o in context.selected_objects if o.type == "MESH"]
        edit_mode = context.mode == "EDIT_MESH"
        if edit_mode:
            bpy.ops.object.mode_set(mode="OBJECT")
        wm = context.window_manager
        wm.progress_begin(0, 1000)
        try:
            return self.run(context, objects)
        except Exception as error:  # never let Blender see an exception: one report
            self.report({"ERROR"}, f"tailor: {error}")
            return {"CANCELLED"}
        finally:
            wm.progress_end()
            self.status(context, None)
            if edit_mode:
                bpy.ops.object.mode_set(mode="EDIT")

    def status(self, context, text):
        if context.workspace is not None:
            context.workspace.status_text_set(text)

    def run(self, context, objects):
        with tempfile.TemporaryDirectory(prefix="tailor-blender-") as tmp:
            return self.run_in(context, objects, tmp)

    def run_in(self, context, objects, tmp):
        preferences = context.preferences.addons[__package__].preferences
        kind, tool = backend.choose(preferences)
        image = maps = texture_file = None
        texture_width = texture_height = self.texture_size
        if self.assign_material and self.material_path:
            maps = material_files.find_maps(bpy.path.abspath(self.material_path))
            if self.make_tileable:
                maps = self.tile_maps(kind, tool, maps, tmp)
            images = material.load_maps(maps)
            if self.make_tileable:  # the tiles live in tmp: into the .blend with them
                for tile in images.values():
                    tile.pack()
            texture_width, texture_height = images[next(iter(images))].size
            texture_file = maps["color"][0] if "color" in maps else None  # decides 'auto', as --material does
        elif self.assign_material:
            image, texture_file = self.load_image(kind, tool, tmp)
            texture_width, texture_height = image.size
        # 'auto' measures the image the mapping is for (tailor map's default); without one, the number.
        automatic = self.auto_field_following and texture_file is not None
        options = {"max_stretch": self.max_stretch, "field_following": "auto" if automatic else self.field_following,
                   "close_cracks": self.close_cracks, "relax_iterations": self.relax_iterations,
                   "threads": self.threads, "texture": texture_file, "symmetry": 4 if self.quarter_turns else 1}
        wm = context.window_manager
        mapped, failed = 0, []
        for i, obj in enumerate(objects):
            self.status(context, f"tailor: mapping {obj.name} ({i + 1}/{len(objects)})")
            wm.progress_update(int(1000 * i / len(objects)))

            def progress(fraction, i=i, name=obj.name):
                wm.progress_update(int(1000 * (i + fraction) / len(objects)))
                self.status(context, f"tailor: mapping {name} ({i + 1}/{len(objects)}) {100 * fraction:.0f}%")
                if not bpy.app.background:  # the window redraws only between operators otherwise
                    bpy.ops.wm.redraw_timer(type="DRAW_WIN_SWAP", iterations=1)

            try:
                triangles = mesh_data.Triangles(obj, self.use_seams)
                if not len(triangles.faces):
                    raise RuntimeError("the mesh has no faces")
                request = backend.MapRequest(triangles.positions, triangles.faces, triangles.seam_faces,
                                             texture_width, self.tile_size, self.axis, options)
                if kind == "module":
                    uvs, stats, warned = backend.map_with_module(tool, request, progress)
                else:
                    uvs, stats, warned = backend.map_with_cli(tool, request)
            except KeyboardInterrupt:
                self.report({"WARNING"}, "tailor: cancelled")
                return {"CANCELLED"}
            except Exception as error:  # tailor.Error (a ValueError), RuntimeError, OSError...
                failed.append(obj.name)
                self.report({"ERROR"}, f"tailor: {obj.name}: {error}")
                continue
            if texture_height != texture_width:  # repeats along v in the image's own height
                uvs[..., 1] *= texture_width / texture_height
            mesh_data.write_uv_map(obj, triangles.loop_uvs(uvs, len(obj.data.loops)))
            metrics = stats["metrics"]
            obj["tailor"] = {"backend": kind, "faces_seam": stats["mapping"]["faces_seam"],
                             "patches": metrics["patches"], "flipped": metrics["flipped"],
                             "seam_length_ratio": metrics["seam_length_ratio"], "tile_size": self.tile_size,
                             "field_following": stats["options"]["field_following"],
                             "symmetry": options["symmetry"], "visible_seam_ratio": metrics["visible_seam_ratio"],
                             "warnings": "\n".join(warned)}
            for line in warned:  # what tailor map would print: a 4-fold map under too few repeats...
                self.report({"WARNING"}, f"tailor: {obj.name}: {line}")
            if image is not None:
                material.assign(obj, image)
            elif maps is not None:
                material.assign_maps(obj, maps, images)
            mapped += 1
        wm.progress_update(1000)
        if mapped == 0:
            return {"CANCELLED"}
        self.report({"INFO"}, f"tailor: mapped {mapped} object(s) with the {kind} backend" +
                    (f"; failed: {', '.join(failed)}" if failed else ""))
        return {"FINISHED"}

    def tile_maps(self, kind, tool, maps, tmp):
        """The material folder's maps made self-tileable together (tailor tile --set), in tmp under
        their own names, so that the roles (and a DirectX normal map) are found as before; with
        Quarter-turn seams one 4-fold tile for all (normal maps turned with their content)."""
        folder = os.path.basename(os.path.normpath(bpy.path.abspath(self.material_path)))
        out = os.path.join(tmp, folder + ("_tile4" if self.quarter_turns else "_tile"))
        paths = [path for path, _ in maps.values()]
        normals = [path for role, (path, _) in maps.items() if role == "normal"]
        backend.make_tileable_set(kind, tool, paths, normals, out, 4 if self.quarter_turns else 1)
        return material_files.find_maps(out)

    def load_image(self, kind, tool, tmp):
        """The Blender image and the file the mapping measures (the tile, when made here, in tmp)."""
        path = bpy.path.abspath(self.image_path)
        if not path or not os.path.isfile(path):
            raise RuntimeError(f"{path or 'no image'}: the image file does not exist")
        name = os.path.basename(path)
        if not self.make_tileable:
            return bpy.data.images.load(path, check_existing=True), path
        out = os.path.join(tmp, os.path.splitext(name)[0] + "_tile.png")
        pixels = backend.make_tileable(kind, tool, path, out, 4 if self.quarter_turns else 1)
        if pixels is not None:
            backend.write_png(out, pixels)
            return material.image_from_pixels(os.path.splitext(name)[0] + "_tile", pixels), out
        image = bpy.data.images.load(out)
        image.pack()
        return image, out
