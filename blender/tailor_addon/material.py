"""The material the operator assigns on request: Principled BSDF <- Image Texture (repeat) <- UV
Map "tailor", or for a material folder every map in its place (base colour times occlusion,
roughness, metallic, the normal map in tangent space of the UV map "tailor"); and the Blender image
of a tile made by tailor."""
import os

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


def _new_node_material(name):
    """A new node material: (material, its nodes, its links, its Principled BSDF)."""
    material = bpy.data.materials.new(name)
    material.use_nodes = True
    nodes, links = material.node_tree.nodes, material.node_tree.links
    return material, nodes, links, next(n for n in nodes if n.type == "BSDF_PRINCIPLED")


def _uv_node(nodes, uv_map, location):
    """A UV Map node reading uv_map."""
    coordinates = nodes.new("ShaderNodeUVMap")
    coordinates.uv_map = uv_map
    coordinates.location = location
    return coordinates


def _image_node(nodes, links, image, coordinates, location):
    """An Image Texture node of image, repeating, sampled at the UV Map node coordinates."""
    texture = nodes.new("ShaderNodeTexImage")
    texture.image = image
    texture.extension = "REPEAT"
    texture.location = location
    links.new(coordinates.outputs["UV"], texture.inputs["Vector"])
    return texture


def _give_every_face(obj, material):
    """Adds material to obj's slots (once) and gives it every face; returns it."""
    mesh = obj.data
    if material.name not in mesh.materials:
        mesh.materials.append(material)
    index = list(mesh.materials).index(material)
    mesh.polygons.foreach_set("material_index", np.full(len(mesh.polygons), index, np.int32))
    mesh.update()
    return material


def assign(obj, image, uv_map="tailor"):
    """Adds (or reuses) the material "tailor <image>" and gives it every face of obj."""
    name = f"tailor {image.name}"
    material = bpy.data.materials.get(name)
    if material is None:
        material, nodes, links, shader = _new_node_material(name)
        x, y = shader.location.x, shader.location.y
        coordinates = _uv_node(nodes, uv_map, (x - 540, y - 120))
        texture = _image_node(nodes, links, image, coordinates, (x - 320, y))
        links.new(texture.outputs["Color"], shader.inputs["Base Color"])
    return _give_every_face(obj, material)


# The order the maps are loaded in: the colour map first (its size is the texture size).
_ROLES = ("color", "normal", "roughness", "metallic", "occlusion")


def load_maps(maps):
    """{role: Blender image} of material_files.find_maps' result (height is not used, as in the
    .glb of tailor map --material); every map must have the first one's size."""
    images = {}
    for role in _ROLES:
        if role not in maps:
            continue
        path = maps[role][0]
        image = bpy.data.images.load(path, check_existing=True)
        if role != "color":
            image.colorspace_settings.name = "Non-Color"  # data, not colour
        first = next(iter(images.values()), None)
        if first is not None and tuple(image.size) != tuple(first.size):
            raise RuntimeError(f"{path}: map is {image.size[0]}x{image.size[1]} but {first.filepath} is "
                               f"{first.size[0]}x{first.size[1]} (all maps of a material must share one size)")
        images[role] = image
    if not images:
        raise RuntimeError("the material has only a height map: nothing to show")
    return images


def assign_maps(obj, maps, images, uv_map="tailor"):
    """Adds (or reuses) the material "tailor <folder>" wired from the maps and gives it every face
    of obj. A DirectX normal map (*_normal_dx) has its green flipped (Blender wants OpenGL's). A
    reused material shows these images (the maps of a folder made tileable again are new images)."""
    folder = os.path.basename(os.path.dirname(next(iter(maps.values()))[0]))
    name = f"tailor {folder}"
    material = bpy.data.materials.get(name)
    if material is not None:
        for node in material.node_tree.nodes:
            if node.type == "TEX_IMAGE" and node.label in images:
                node.image = images[node.label]
    else:
        material, nodes, links, shader = _new_node_material(name)
        coordinates = _uv_node(nodes, uv_map, (shader.location.x - 900, shader.location.y))
        textures = {}
        for row, (role, image) in enumerate(images.items()):
            location = (shader.location.x - 620, shader.location.y - 280 * row)
            textures[role] = _image_node(nodes, links, image, coordinates, location)
            textures[role].label = role
        colour = textures["color"].outputs["Color"] if "color" in textures else None
        if "occlusion" in textures and colour is not None:  # the Principled BSDF has no occlusion input
            multiply = nodes.new("ShaderNodeMixRGB")
            multiply.blend_type = "MULTIPLY"
            multiply.inputs["Fac"].default_value = 1.0
            multiply.location = (shader.location.x - 300, shader.location.y)
            links.new(colour, multiply.inputs["Color1"])
            links.new(textures["occlusion"].outputs["Color"], multiply.inputs["Color2"])
            colour = multiply.outputs["Color"]
        if colour is not None:
            links.new(colour, shader.inputs["Base Color"])
        for role, socket in (("roughness", "Roughness"), ("metallic", "Metallic")):
            if role in textures:
                links.new(textures[role].outputs["Color"], shader.inputs[socket])
        if "normal" in textures:
            normal_map = nodes.new("ShaderNodeNormalMap")
            normal_map.space = "TANGENT"
            normal_map.uv_map = uv_map
            normal_map.location = (shader.location.x - 220, shader.location.y - 500)
            source = textures["normal"].outputs["Color"]
            if maps["normal"][1]:  # DirectX: green points down
                split = nodes.new("ShaderNodeSeparateColor")
                flip = nodes.new("ShaderNodeMath")
                flip.operation = "SUBTRACT"
                flip.inputs[0].default_value = 1.0
                join = nodes.new("ShaderNodeCombineColor")
                links.new(source, split.inputs["Color"])
                links.new(split.outputs["Red"], join.inputs["Red"])
                links.new(split.outputs["Green"], flip.inputs[1])
                links.new(flip.outputs["Value"], join.inputs["Green"])
                links.new(split.outputs["Blue"], join.inputs["Blue"])
                source = join.outputs["Color"]
            links.new(source, normal_map.inputs["Color"])
            links.new(normal_map.outputs["Normal"], shader.inputs["Normal"])
    return _give_every_face(obj, material)
