"""The nmbake panel in the Properties editor's Render tab."""

import bpy


class RENDER_PT_nmbake(bpy.types.Panel):
    bl_label = "nmbake"
    bl_space_type = "PROPERTIES"
    bl_region_type = "WINDOW"
    bl_context = "render"
    bl_options = {"DEFAULT_CLOSED"}

    def draw(self, context):
        layout = self.layout
        layout.use_property_split = True
        layout.use_property_decorate = False
        s = context.scene.nmbake
        low = context.active_object
        highs = [o for o in context.selected_objects if o is not low and o.type == "MESH" and o is not s.cage_object]
        box = layout.box()
        box.label(text="Low-poly: %s" % (low.name if low is not None and low.type == "MESH" else "(none active)"), icon="MESH_DATA")
        box.label(text="High-poly: %s" % (", ".join(o.name for o in highs[:3]) + (" ..." if len(highs) > 3 else "") if highs else "(none selected)"),
                  icon="SCULPTMODE_HLT")
        layout.prop(s, "output")
        layout.prop(s, "size")
        row = layout.row(heading="Samples")
        row.prop(s, "samples_auto", text="Adaptive")
        sub = row.row()
        sub.enabled = not s.samples_auto
        sub.prop(s, "samples", text="")
        layout.prop(s, "green")
        layout.prop(s, "uv_map")
        layout.prop(s, "cage_mode")
        if s.cage_mode == "DISTANCE":
            layout.prop(s, "front")
            layout.prop(s, "rear")
        elif s.cage_mode == "OBJECT":
            layout.prop(s, "cage_object")
        layout.label(text="Maps:")
        layout.use_property_split = False
        grid = layout.grid_flow(columns=2, even_columns=True)
        grid.prop(s, "maps")
        layout.use_property_split = True
        layout.prop(s, "wire_material")
        layout.prop(s, "extra_args")
        layout.operator("object.nmbake_bake", icon="RENDER_STILL")


classes = (RENDER_PT_nmbake,)
register, unregister = bpy.utils.register_classes_factory(classes)
