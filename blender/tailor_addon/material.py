"""The material the operator assigns on request: Principled BSDF <- Image Texture (repeat) <- UV
Map "tailor"; and the Blender image of a tile made by tailor."""
import bpy
import numpy as np


def image_from_pixels(name, pixels):
    """A packed Blender image from a uint8 (H, W, C) array, rows top first (Blender's are bottom first)."""
    height, width, channels = pixels.shape
    rgba = np.ones((height, width, 4), np.float32)
    grey = pixels[..., 0:1].astype(np.float32) / 255.0
    if channels >= 3:
        rgba[..., :3] = pixels[..., :3] / 255.0
    else:
        rgba[..., :3] = grey
    if channels in (2, 4):
        rgba[..., 3] = pixels[..., channels - 1] / 255.0
    image = bpy.data.images.new(name, width, height, alpha=channels in (2, 4))
    image.pixels.foreach_set(rgba[::-1].ravel())
    image.pack()
    return image


def assign(obj, image, uv_map="tailor"):
    """Adds (or reuses) the material "tailor <image>" and gives it every face of obj."""
    name = f"tailor {image.name}"
    material = bpy.data.materials.get(name)
    if material is None:
        material = bpy.data.materials.new(name)
        material.use_nodes = True
        nodes, links = material.node_tree.nodes, material.node_tree.links
        shader = next(n for n in nodes if n.type == "BSDF_PRINCIPLED")
        texture = nodes.new("ShaderNodeTexImage")
        texture.image = image
        texture.extension = "REPEAT"
        texture.location = (shader.location.x - 320, shader.location.y)
        coordinates = nodes.new("ShaderNodeUVMap")
        coordinates.uv_map = uv_map
        coordinates.location = (texture.location.x - 220, texture.location.y - 120)
        links.new(coordinates.outputs["UV"], texture.inputs["Vector"])
        links.new(texture.outputs["Color"], shader.inputs["Base Color"])
    mesh = obj.data
    if material.name not in mesh.materials:
        mesh.materials.append(material)
    index = list(mesh.materials).index(material)
    mesh.polygons.foreach_set("material_index", np.full(len(mesh.polygons), index, np.int32))
    mesh.update()
    return material
