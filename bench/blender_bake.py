# Blender's Cycles bake of a tangent-space normal map: the peer that section 10 of the bake bench
# (bench_blender.cpp) runs, as a whole command, alternately with nmbake on the same pair.
#
#   blender -b --factory-startup --python-exit-code 1 --python blender_bake.py -- \
#       LOW HIGH OUT.png SIZE SAMPLES EXTRUSION [ao DISTANCE]
#
# LOW (.obj with UVs) is the active object and HIGH (.ply or .obj) the selected one; the bake is
# selected-to-active, type NORMAL, tangent space, on the CPU, SAMPLES samples per texel, a 16-texel
# margin, into a SIZE x SIZE 8-bit non-colour image saved as PNG. EXTRUSION is Blender's cage
# extrusion, one fixed distance in scene units for the whole mesh, where nmbake measures an
# automatic cage per vertex. With `ao DISTANCE` the bake is type AO instead (ambient occlusion of
# the high-poly seen from the low-poly's texels through the same cage, SAMPLES samples per texel,
# the world's AO distance set to DISTANCE scene units, as nmbake's --ao-distance), into a byte
# image saved as PNG; check_ao then only checks the bake wrote something. The bench passes 0.05 for its suz_L4 scenes (a Suzanne about 2 units
# wide): nmbake's automatic cage on the 1M-triangle pair has a scene-wide front distance of 0.042
# (per vertex: mean 0.038, max 0.10).
# Prints "blender-bake: load L bake B save S" (seconds), which the bench parses. Any failure raises,
# and --python-exit-code turns that into a non-zero exit status.
import array
import sys
import time

import bpy


def parse_args():
    argv = sys.argv[sys.argv.index("--") + 1:] if "--" in sys.argv else []
    if len(argv) not in (6, 8) or (len(argv) == 8 and argv[6] != "ao"):
        raise SystemExit("usage: blender -b --python blender_bake.py -- LOW HIGH OUT SIZE SAMPLES EXTRUSION [ao DISTANCE]")
    ao = float(argv[7]) if len(argv) == 8 else None
    return argv[0], argv[1], argv[2], int(argv[3]), int(argv[4]), float(argv[5]), ao


def import_mesh(path):
    """Imports one mesh file and returns the object it made."""
    before = set(bpy.data.objects)
    if path.lower().endswith(".ply"):
        bpy.ops.import_mesh.ply(filepath=path)
    else:
        # The file's axes as they are (the default turns Y-up into Z-up with a rotation the PLY
        # importer does not apply, and the pair would no longer overlap).
        bpy.ops.wm.obj_import(filepath=path, forward_axis="Y", up_axis="Z")
    made = [o for o in bpy.data.objects if o not in before]
    if len(made) != 1:
        raise RuntimeError("%s: expected one object, the import made %d" % (path, len(made)))
    return made[0]


def bake_target(low, size):
    """A SIZE x SIZE byte image on the low-poly's only material, as the active image node (where Cycles bakes)."""
    image = bpy.data.images.new("normal_map", size, size, alpha=False, float_buffer=False)
    image.colorspace_settings.name = "Non-Color"
    material = bpy.data.materials.new("bake")
    material.use_nodes = True
    node = material.node_tree.nodes.new("ShaderNodeTexImage")
    node.image = image
    material.node_tree.nodes.active = node
    low.data.materials.clear()
    low.data.materials.append(material)
    return image


def check_normals(image):
    """Raises when most sampled texels hold a zero normal (0.5 grey): Cycles wrote nothing. Runs after the timing."""
    pixels = array.array("f", [0.0]) * len(image.pixels)
    image.pixels.foreach_get(pixels)
    sampled = zero = 0
    for i in range(0, len(pixels), 4 * 97):
        sampled += 1
        zero += all(abs(v - 0.5) < 1.5 / 255.0 for v in pixels[i:i + 3])
    if zero > sampled // 2:
        raise RuntimeError("%d of %d sampled texels hold a zero normal: the bake wrote nothing" % (zero, sampled))


def check_ao(image):
    """Raises when every sampled texel holds one value: Cycles wrote nothing. Runs after the timing."""
    pixels = array.array("f", [0.0]) * len(image.pixels)
    image.pixels.foreach_get(pixels)
    values = set(round(pixels[i], 3) for i in range(0, len(pixels), 4 * 97))
    if len(values) < 3:
        raise RuntimeError("the AO bake holds %d distinct values: it wrote nothing" % len(values))


def main():
    low_path, high_path, out_path, size, samples, extrusion, ao_distance = parse_args()
    t0 = time.time()
    # --factory-startup's cube, camera and light.
    for obj in list(bpy.data.objects):
        bpy.data.objects.remove(obj, do_unlink=True)
    low = import_mesh(low_path)
    high = import_mesh(high_path)
    if not low.data.uv_layers:
        raise RuntimeError("%s: the low-poly has no UVs" % low_path)
    # Blender 3.4's PLY importer drops the file's normals and shades flat: shade the high-poly smooth,
    # so the bake interpolates the vertex normals Blender computes, as nmbake interpolates the file's.
    high.data.polygons.foreach_set("use_smooth", [True] * len(high.data.polygons))
    high.data.update()
    t1 = time.time()

    image = bake_target(low, size)
    scene = bpy.context.scene
    scene.render.engine = "CYCLES"
    scene.cycles.device = "CPU"
    scene.cycles.samples = samples
    # Debian's Blender is built without OpenImageDenoise; with denoising on (the default) Cycles
    # stops and the bake "finishes" with every texel (0.5, 0.5, 0.5), a zero normal.
    scene.cycles.use_denoising = False
    bake = scene.render.bake
    bake.use_selected_to_active = True
    bake.cage_extrusion = extrusion
    bake.margin = 16
    bake.normal_space = "TANGENT"
    if ao_distance is not None:
        # Cycles' AO bake reads the world's AO distance (WorldLighting.distance).
        if scene.world is None:
            scene.world = bpy.data.worlds.new("World")
        scene.world.light_settings.distance = ao_distance
    bpy.ops.object.select_all(action="DESELECT")
    high.select_set(True)
    low.select_set(True)
    bpy.context.view_layer.objects.active = low
    if "FINISHED" not in bpy.ops.object.bake(type="NORMAL" if ao_distance is None else "AO"):
        raise RuntimeError("the bake did not finish")
    t2 = time.time()

    image.filepath_raw = out_path
    image.file_format = "PNG"
    image.save()
    t3 = time.time()
    print("blender-bake: load %.2f bake %.2f save %.2f" % (t1 - t0, t2 - t1, t3 - t2), flush=True)
    if ao_distance is None:
        check_normals(image)
    else:
        check_ao(image)


main()
