"""The add-on's settings: the scene's bake properties (scene.nmbake) and the preferences (where the
nmbake executable is). Lengths are Blender units, as the UI shows them (the scene's unit scale
applies, as it does to the exported meshes)."""

import bpy

from . import runner

_MAP_ITEMS = [(name, name, "nmbake --maps " + name) for name in runner.MAP_NAMES]


def _is_mesh(_self, obj):
    return obj.type == "MESH"


class NmbakeSettings(bpy.types.PropertyGroup):
    size: bpy.props.IntProperty(name="Size", description="Map size in texels (square): nmbake --size", default=2048, min=8, max=16384)
    samples: bpy.props.IntProperty(name="Samples", description="Sample points per texel: nmbake --samples", default=1, min=1, max=1024)
    samples_auto: bpy.props.BoolProperty(
        name="Adaptive Samples", description="--samples auto: 4 per texel, 16 or 64 where those disagree", default=False
    )
    maps: bpy.props.EnumProperty(
        name="Maps", description="Maps to bake from the same hits: nmbake --maps", items=_MAP_ITEMS, options={"ENUM_FLAG"}, default={"normal"}
    )
    output: bpy.props.StringProperty(
        name="Output",
        description="Output file; <MAP> is replaced by each map's name (needed for several maps), <UDIM> by each UDIM tile's number; "
        ".png/.tga 8-bit, .tif 16-bit, .exr float; // is the .blend file's folder",
        default="//nmbake_<MAP>.png",
        subtype="FILE_PATH",
    )
    green: bpy.props.EnumProperty(
        name="Green",
        description="Green channel convention: nmbake --green",
        items=[("up", "OpenGL (Y+)", "Blender, glTF, Unity, Maya"), ("down", "DirectX (Y-)", "Unreal, 3ds Max")],
        default="up",
    )
    cage_mode: bpy.props.EnumProperty(
        name="Cage",
        description="Where rays start",
        items=[
            ("AUTO", "Automatic", "nmbake's automatic cage: ray start and reach measured per vertex"),
            ("DISTANCE", "Distances", "One ray start distance outside and one reach inside for the whole scene (--front, --rear)"),
            ("OBJECT", "Cage Object", "A cage object with the low-poly's topology (--cage)"),
        ],
        default="AUTO",
    )
    front: bpy.props.FloatProperty(name="Front", description="Ray start outside the low-poly (--front)", default=0.05, min=0.0, subtype="DISTANCE")
    rear: bpy.props.FloatProperty(name="Rear", description="Ray reach inside the low-poly (--rear)", default=0.05, min=0.0, subtype="DISTANCE")
    cage_object: bpy.props.PointerProperty(
        name="Cage Object", description="The low-poly's cage: the same mesh with its vertices moved outwards", type=bpy.types.Object, poll=_is_mesh
    )
    uv_map: bpy.props.StringProperty(name="UV Map", description="The low-poly's UV map to bake into (empty: the active one)", default="")
    wire_material: bpy.props.BoolProperty(
        name="Wire into Material",
        description="Connect the normal map to the low-poly's material (Image Texture, Normal Map node in tangent space)",
        default=True,
    )
    extra_args: bpy.props.StringProperty(name="Extra Options", description="More nmbake options, as on its command line", default="")


class NmbakePreferences(bpy.types.AddonPreferences):
    bl_idname = __package__

    executable: bpy.props.StringProperty(
        name="nmbake Executable", description="Path of the nmbake program, or a name found on PATH", default="nmbake", subtype="FILE_PATH"
    )
    keep_exported: bpy.props.BoolProperty(
        name="Keep Exported Meshes",
        description="Keep the temporary folder of the exported PLY files (its path is printed and in the Info report)",
        default=False,
    )

    def draw(self, _context):
        self.layout.prop(self, "executable")
        self.layout.prop(self, "keep_exported")


def preferences(context):
    return context.preferences.addons[__package__].preferences


classes = (NmbakeSettings, NmbakePreferences)


def register():
    for cls in classes:
        bpy.utils.register_class(cls)
    bpy.types.Scene.nmbake = bpy.props.PointerProperty(type=NmbakeSettings)
    bpy.types.WindowManager.nmbake_last_export = bpy.props.StringProperty(
        name="Last Export", description="The folder the last bake's meshes were kept in (Keep Exported Meshes)", default=""
    )


def unregister():
    del bpy.types.WindowManager.nmbake_last_export
    del bpy.types.Scene.nmbake
    for cls in reversed(classes):
        bpy.utils.unregister_class(cls)
