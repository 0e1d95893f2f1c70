"""The maps of a material folder by their names' suffixes, as `tailor map --material FOLDER` finds
them (material_role_from_name in src/export/material_maps.cpp; tests/python/test_material.py checks
that both agree). No bpy here, so that the test can import it outside Blender."""
import os

# (suffix word, role, DirectX normal map), in the order the library tries them.
_WORDS = [
    ("base_color", "color", False), ("basecolor", "color", False), ("base_colour", "color", False),
    ("albedo", "color", False), ("diffuse", "color", False), ("colour", "color", False),
    ("color", "color", False), ("col", "color", False),
    ("normal_gl", "normal", False), ("normalgl", "normal", False), ("normal_dx", "normal", True),
    ("normaldx", "normal", True), ("normal_directx", "normal", True), ("normal_opengl", "normal", False),
    ("normal", "normal", False), ("nor_gl", "normal", False), ("nor_dx", "normal", True), ("nor", "normal", False),
    ("nrm", "normal", False),
    ("roughness", "roughness", False), ("rough", "roughness", False),
    ("metallic", "metallic", False), ("metalness", "metallic", False), ("metal", "metallic", False),
    ("ambientocclusion", "occlusion", False), ("ambient_occlusion", "occlusion", False),
    ("occlusion", "occlusion", False), ("ao", "occlusion", False),
    ("displacement", "height", False), ("disp", "height", False), ("height", "height", False),
    ("bump", "height", False),
]
_IMAGE_EXTENSIONS = (".png", ".jpg", ".jpeg")


def role(file_name):
    """(role or None, directx) of a file name: its stem (lower case, - . and spaces as _) ends with a
    known word after an underscore, or is that word."""
    stem = os.path.splitext(os.path.basename(file_name))[0].lower()
    for c in "-. ":
        stem = stem.replace(c, "_")
    for word, name, directx in _WORDS:
        if stem.endswith(word) and (len(stem) == len(word) or stem[-len(word) - 1] == "_"):
            return name, directx
    return None, False


def find_maps(folder):
    """{role: (path, directx)} of the folder's images (sorted by name); a RuntimeError when two
    files claim one role or none is recognised, with the library's wording."""
    if not os.path.isdir(folder):
        raise RuntimeError(f"{folder}: the material folder does not exist")
    maps = {}
    for name in sorted(os.listdir(folder)):
        path = os.path.join(folder, name)
        if not name.lower().endswith(_IMAGE_EXTENSIONS) or not os.path.isfile(path):
            continue
        found, directx = role(name)
        if found is None:
            continue
        if found in maps:
            raise RuntimeError(f"{folder}: two files claim the {found} map: {maps[found][0]} and {path}")
        maps[found] = (path, directx)
    if not maps:
        raise RuntimeError(f"{folder}: no map recognised (name them NAME_color.png, NAME_normal.png, "
                           "NAME_roughness.png, NAME_metallic.png, NAME_ao.png, NAME_height.png)")
    return maps
