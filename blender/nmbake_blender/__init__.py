"""nmbake for Blender: bakes the selected high-poly objects onto the active low-poly with the nmbake
program (normal map and the texture set's other maps), from the Properties editor's Render tab.
docs/blender.md in nmbake's source tells how to install and use it."""

bl_info = {
    "name": "nmbake",
    "author": "nmbake",
    "version": (0, 1, 0),
    "blender": (3, 4, 0),
    "location": "Properties > Render > nmbake",
    "description": "Bake normal maps and texture sets from high-poly to low-poly objects with the nmbake program",
    "doc_url": "",
    "category": "Render",
}

if "bpy" in locals():
    import importlib

    for _module in (runner, export_ply, images, settings, operator, panel):  # noqa: F821 (reload)
        importlib.reload(_module)
else:
    from . import runner, export_ply, images, settings, operator, panel

import bpy  # noqa: E402,F401

_modules = (settings, operator, panel)


def register():
    for module in _modules:
        module.register()


def unregister():
    for module in reversed(_modules):
        module.unregister()
