"""The baked maps in Blender: loaded as images (Non-Color where the data is not colour; UDIM maps as
tiled images) and the normal map wired into the low-poly's material."""

import os

import bpy

from . import runner


def map_files(report):
    """{map name: (path or <UDIM> pattern, [(tile or None, file)])} from nmbake's --report JSON."""
    tiles = [t["tile"] for t in (report.get("udim") or {}).get("tiles", [])]
    files = {}
    for entry in report.get("maps", []):
        path = entry["file"]
        if "<UDIM>" in path:
            found = [(t, path.replace("<UDIM>", str(t))) for t in tiles]
        else:
            found = [(None, path)]
        files[entry["map"]] = (path, [(t, f) for t, f in found if os.path.isfile(f)])
    return files


def _same_file(image, path):
    return os.path.normpath(bpy.path.abspath(image.filepath, library=image.library)) == os.path.normpath(path)


def load_map(name, pattern, files):
    """The image of one map (reloaded when already loaded), its colour space set."""
    image = next((i for i in bpy.data.images if _same_file(i, pattern)), None)
    if image is None:
        image = bpy.data.images.load(files[0][1], check_existing=False)
        if files[0][0] is not None:
            image.source = "TILED"
            image.filepath = pattern
            for tile, _path in files[1:]:
                if image.tiles.get(tile) is None:
                    image.tiles.new(tile_number=tile)
    image.reload()
    image.colorspace_settings.name = "sRGB" if name in runner.COLOR_MAPS else "Non-Color"
    return image


def _node(nodes, name, kind, location):
    node = nodes.get(name)
    if node is None or node.bl_idname != kind:
        node = nodes.new(kind)
        node.name = name
        node.location = location
    node.label = name
    return node


def wire_normal_map(obj, image, uv_map):
    """Image Texture (reading `uv_map`) -> Normal Map (tangent space, `uv_map`) -> the Normal of each
    Principled BSDF in the materials of `obj` (a new material when it has none). Returns the
    materials wired."""
    materials = [slot.material for slot in obj.material_slots if slot.material is not None]
    if not materials:
        material = bpy.data.materials.new(obj.name + "_nmbake")
        material.use_nodes = True
        obj.data.materials.append(material)
        materials = [material]
    wired = []
    for material in dict.fromkeys(materials):
        if not material.use_nodes:
            material.use_nodes = True
        nodes, links = material.node_tree.nodes, material.node_tree.links
        bsdfs = [n for n in nodes if n.bl_idname == "ShaderNodeBsdfPrincipled"]
        x, y = (bsdfs[0].location.x, bsdfs[0].location.y) if bsdfs else (0.0, 0.0)
        uv = _node(nodes, "nmbake UV", "ShaderNodeUVMap", (x - 900, y - 500))
        uv.uv_map = uv_map
        texture = _node(nodes, "nmbake normal", "ShaderNodeTexImage", (x - 700, y - 500))
        texture.image = image
        normal_map = _node(nodes, "nmbake normal map", "ShaderNodeNormalMap", (x - 300, y - 500))
        normal_map.space = "TANGENT"
        normal_map.uv_map = uv_map
        links.new(uv.outputs["UV"], texture.inputs["Vector"])
        links.new(texture.outputs["Color"], normal_map.inputs["Color"])
        for bsdf in bsdfs:
            links.new(normal_map.outputs["Normal"], bsdf.inputs["Normal"])
        wired.append(material)
    return wired
