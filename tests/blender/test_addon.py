"""blender.addon: the Blender add-on as users get it, driven headless by Blender (one process).

Run by run_addon_test.sh: blender -b --factory-startup --python-exit-code 1 --python test_addon.py --
--zip ADDON.zip --nmbake NMBAKE --nmdiff NMDIFF --work DIR, with BLENDER_USER_SCRIPTS and TMPDIR in
DIR. Installs the zip (Preferences > Add-ons > Install), enables it, and checks: it registers and
its panel draws; a generated pair (a 16x8 UV sphere under a displaced, subdivided icosphere,
modifiers unapplied) bakes at 128^2 to the same map as the command line on the exported files
(nmdiff mean <= 0.01 degrees, and the same bytes), loaded and wired into the material; the modal
bake (stand-ins for the window) and Esc; moving, rotating, scaling and mirroring the objects and
changing the unit scale leaves the map the same; a cage object is passed as --cage and bakes as the
command does with it; a texture set with <UDIM>; the map's UVs are Blender's (v up); a missing
executable, no low-poly, no high-poly, a low-poly without UVs and an nmbake error are one-line
reports (RuntimeError for a script), naming the object, with nothing written.
"""

import argparse
import glob
import json
import math
import os
import subprocess
import sys
import tempfile
import traceback

import bpy

argv = sys.argv[sys.argv.index("--") + 1 :] if "--" in sys.argv else []
parser = argparse.ArgumentParser()
for name in ("--zip", "--nmbake", "--nmdiff", "--work"):
    parser.add_argument(name, required=True)
ARGS = parser.parse_args(argv)
WORK = ARGS.work
SIZE = 128
failures = []


def check(condition, what):
    print(("ok: " if condition else "FAILED: ") + what)
    if not condition:
        failures.append(what)


def prefs():
    return bpy.context.preferences.addons["nmbake_blender"].preferences


def nmdiff(a, b, name):
    out = os.path.join(WORK, name + ".diff.json")
    subprocess.run([ARGS.nmdiff, a, b, "--json", out, "--max-mean", "0.01"], check=False, stdout=subprocess.DEVNULL)
    with open(out, encoding="utf-8") as f:
        return json.load(f)


def select(low, highs):
    for o in bpy.context.view_layer.objects:
        o.select_set(False)
    for o in highs:
        o.select_set(True)
    if low is not None:
        low.select_set(True)
    bpy.context.view_layer.objects.active = low


def smooth(obj):
    for p in obj.data.polygons:
        p.use_smooth = True


def bake(output, **options):
    s = bpy.context.scene.nmbake
    s.output, s.size, s.samples, s.maps, s.cage_mode = output, SIZE, 1, {"normal"}, "AUTO"
    s.extra_args, s.wire_material = "", True
    for key, value in options.items():
        setattr(s, key, value)
    bpy.ops.object.nmbake_bake()
    return bpy.context.window_manager.nmbake_last_export


def refused(output_dir, what, *needles):
    """The operator raises one report naming `needles`, writes nothing and leaves nothing behind."""
    images_before = len(bpy.data.images)
    temps_before = set(glob.glob(os.path.join(tempfile.gettempdir(), "nmbake-blender-*")))
    message = None
    try:
        bake(os.path.join(output_dir, "map_<MAP>.png"))
    except RuntimeError as e:
        message = str(e).strip()
    print("  report:", message)
    check(message is not None, what + ": refused")
    if message is not None:
        check(all(n in message for n in needles), what + ": the report names %s" % (needles,))
        check("Traceback" not in message and message.count("\n") == 0, what + ": one line, no trace")
    check(not os.path.exists(output_dir), what + ": nothing written")
    check(len(bpy.data.images) == images_before, what + ": no image loaded")
    check(set(glob.glob(os.path.join(tempfile.gettempdir(), "nmbake-blender-*"))) == temps_before, what + ": no temporary folder left")
    return message


def ply_faces(path):
    with open(path, "rb") as f:
        for line in f:
            if line.startswith(b"element face"):
                return int(line.split()[2])
    return -1


def run_cli(folder, low, high, output, *extra):
    command = [ARGS.nmbake, os.path.join(folder, low), os.path.join(folder, high), "-o", output, "--size", str(SIZE)]
    command += ["--samples", "1", "--green", "up", "--maps", "normal", "--quiet"] + list(extra)
    subprocess.run(command, check=True)


def same_bytes(a, b):
    with open(a, "rb") as fa, open(b, "rb") as fb:
        return fa.read() == fb.read()


# Install from the zip into BLENDER_USER_SCRIPTS, as a user does ----------------------------------
def case_registers():
    user_scripts = os.environ["BLENDER_USER_SCRIPTS"]
    bpy.ops.preferences.addon_install(filepath=ARGS.zip, overwrite=True)
    bpy.ops.preferences.addon_enable(module="nmbake_blender")
    import nmbake_blender

    check(os.path.realpath(nmbake_blender.__file__).startswith(os.path.realpath(user_scripts)), "the add-on runs from the installed zip")
    check(tuple(nmbake_blender.bl_info["blender"]) == (3, 4, 0), "bl_info: Blender 3.4 at least")
    check(hasattr(bpy.types, "RENDER_PT_nmbake") and bpy.types.RENDER_PT_nmbake.bl_context == "render", "the panel is in the Render tab")
    check("nmbake_bake" in dir(bpy.ops.object), "bpy.ops.object.nmbake_bake exists")
    s = bpy.context.scene.nmbake
    check(s.size == 2048 and s.maps == {"normal"} and s.green == "up" and s.cage_mode == "AUTO", "the defaults are nmbake's")
    prefs().executable = ARGS.nmbake
    prefs().keep_exported = True
    from nmbake_blender import runner

    check(runner.parse_progress("nmbake: tracing  42% [############......] 3.1 s, about 4.2 s left") == ("tracing", 42)
          and runner.parse_progress("nmbake: building the BVH, 1.2 s") == ("building the BVH", None)
          and runner.parse_progress("nmbake: wrote a.png (64x64): samples 1") is None, "nmbake's progress line is read")


class _FakeLayout:
    """Stands in for the panel's UILayout: checks that each prop names a property of its data and
    each operator exists."""

    def __init__(self, seen):
        self.seen = seen

    def __getattr__(self, _name):
        return lambda *args, **kwargs: self

    def prop(self, data, name, **_kwargs):
        if not hasattr(data, name):
            raise AttributeError("the panel draws %r, which %s lacks" % (name, data))
        self.seen.append(name)
        return self

    def operator(self, idname, **_kwargs):
        category, name = idname.split(".")
        if name not in dir(getattr(bpy.ops, category)):
            raise AttributeError("the panel's operator %s does not exist" % idname)
        self.seen.append(idname)
        return self


def case_panel_draws():
    seen = []
    panel = type("PanelStandIn", (), {"layout": _FakeLayout(seen)})()
    s = bpy.context.scene.nmbake
    for mode in ("AUTO", "DISTANCE", "OBJECT"):
        s.cage_mode = mode
        bpy.types.RENDER_PT_nmbake.draw(panel, bpy.context)
    s.cage_mode = "AUTO"
    wanted = {"size", "samples", "maps", "output", "green", "cage_mode", "front", "rear", "cage_object", "wire_material", "object.nmbake_bake"}
    check(wanted <= set(seen), "the panel draws the bake's properties and its button (missing: %s)" % sorted(wanted - set(seen)))


def make_pair():
    for o in list(bpy.data.objects):
        bpy.data.objects.remove(o)
    bpy.ops.mesh.primitive_uv_sphere_add(segments=16, ring_count=8, radius=1.0)
    low = bpy.context.active_object
    low.name = "Low"
    smooth(low)
    bpy.ops.mesh.primitive_ico_sphere_add(subdivisions=3, radius=1.0)
    high = bpy.context.active_object
    high.name = "High"
    smooth(high)
    high.modifiers.new("Subdivision", "SUBSURF").levels = 1
    texture = bpy.data.textures.new("bumps", "CLOUDS")
    texture.noise_scale = 0.4
    displace = high.modifiers.new("Displace", "DISPLACE")
    displace.texture, displace.strength = texture, 0.1
    select(low, [high])
    return low, high


def case_pair(low, high):
    folder = bake(os.path.join(WORK, "pair", "addon_<MAP>.png"))
    addon = os.path.join(WORK, "pair", "addon_normal.png")
    check(os.path.isfile(addon), "the add-on wrote addon_normal.png")
    check(folder != "" and os.path.isfile(os.path.join(folder, "Low.ply")) and os.path.isfile(os.path.join(folder, "High.ply")),
          "the meshes are exported as Low.ply and High.ply")
    depsgraph = bpy.context.evaluated_depsgraph_get()
    high_mesh = high.evaluated_get(depsgraph).data
    high_mesh.calc_loop_triangles()
    check(ply_faces(os.path.join(folder, "High.ply")) == len(high_mesh.loop_triangles) > 320,
          "High.ply has the modifiers applied (%d triangles)" % ply_faces(os.path.join(folder, "High.ply")))
    cli = os.path.join(WORK, "pair", "cli_normal.png")
    run_cli(folder, "Low.ply", "High.ply", cli)
    d = nmdiff(addon, cli, "pair")
    print("  add-on vs command line: mean %.5f p99 %.5f max %.5f deg" % (d["mean_deg"], d["p99_deg"], d["max_deg"]))
    check(d["mean_deg"] <= 0.01, "the add-on's map is the command line's on the same files (nmdiff mean <= 0.01 deg)")
    check(same_bytes(addon, cli), "... byte for byte")
    with open(os.path.join(folder, "report.json"), encoding="utf-8") as f:
        report = json.load(f)
    check(report["coverage"] > 0.8 and report["misses"] <= report["rays"] * 0.01,
          "the bake hits (coverage %.3f, %d misses of %d rays)" % (report["coverage"], report["misses"], report["rays"]))
    case_cancel(folder)
    image = bpy.data.images.get("addon_normal.png")
    check(image is not None and image.colorspace_settings.name == "Non-Color" and tuple(image.size) == (SIZE, SIZE),
          "the map is loaded as a Non-Color image")
    material = low.active_material
    nodes = material.node_tree.nodes if material is not None else {}
    normal_map = nodes.get("nmbake normal map")
    uv_name = low.data.uv_layers.active.name
    check(normal_map is not None and normal_map.space == "TANGENT" and normal_map.uv_map == uv_name, "a tangent-space Normal Map node on the UV map")
    bsdf = next((n for n in nodes if n.bl_idname == "ShaderNodeBsdfPrincipled"), None)
    check(bsdf is not None and any(l.from_node == normal_map for l in bsdf.inputs["Normal"].links), "... wired into the material's Normal")
    texture = nodes.get("nmbake normal")
    check(texture is not None and texture.image == image, "... from the map's Image Texture")
    return addon


def case_cancel(folder):
    """What Esc does in the modal bake: the running nmbake is stopped (SIGTERM) and writes nothing."""
    import time

    from nmbake_blender import runner

    out = os.path.join(WORK, "cancelled.png")
    run = runner.Run([ARGS.nmbake, os.path.join(folder, "Low.ply"), os.path.join(folder, "High.ply"), "-o", out, "--size", "4096",
                      "--samples", "64", "--progress"])
    deadline = time.time() + 20.0
    while run.stage == "starting" and not run.done and time.time() < deadline:
        time.sleep(0.02)
    stage = run.status_text()
    run.cancel()
    run.wait(30.0)
    print("  cancelled at '%s': exit %s, %s" % (stage, run.returncode, run.error))
    check(stage.startswith("nmbake: ") and stage != "nmbake: starting", "the progress is read while nmbake runs (%s)" % stage)
    check(run.returncode == 143 and not os.path.exists(out), "a stopped bake exits 143 and writes nothing")


class _FakeWindowManager:
    def __init__(self, calls):
        self.calls = calls
        self.nmbake_last_export = ""

    def event_timer_remove(self, _timer):
        self.calls.append("timer removed")

    def progress_update(self, value):
        self.calls.append(("progress", value))

    def progress_end(self):
        self.calls.append("progress end")


class _FakeWorkspace:
    def __init__(self, calls):
        self.calls = calls

    def status_text_set(self, text):
        self.calls.append(("status", text))


def case_modal(reference):
    """The panel's bake (invoke: modal, needs a window) driven by hand: the operator's own _start,
    modal and _finish with stand-ins for the window manager, the workspace and the timer events.
    A bake shows nmbake's stage in the status bar and ends with the status cleared and the map
    loaded; Esc stops nmbake: a warning, nothing written."""
    import nmbake_blender.operator as op_module

    op_class = op_module.OBJECT_OT_nmbake_bake
    fake_op_type = type("ModalStandIn", (), {name: getattr(op_class, name) for name in ("_start", "_finish", "_cleanup", "modal")})

    def drive(output, events):
        calls, reports = [], []
        op = fake_op_type()
        op.report = lambda kind, text: reports.append((set(kind), text))
        context = type("ContextStandIn", (), {})()
        context.window_manager, context.workspace = _FakeWindowManager(calls), _FakeWorkspace(calls)
        s = bpy.context.scene.nmbake
        s.output = output
        op._job, op._timer = op._start(bpy.context), None
        result = None
        for kind in events:
            event = type("EventStandIn", (), {"type": kind, "value": "PRESS"})()
            result = op.modal(context, event)
            if result != {"PASS_THROUGH"}:
                break
        for _ in range(3000):
            if result != {"PASS_THROUGH"}:
                break
            op._job.run.wait(0.01)
            result = op.modal(context, type("EventStandIn", (), {"type": "TIMER", "value": "NOTHING"})())
        return result, calls, reports

    bake_settings = bpy.context.scene.nmbake
    bake_settings.size, bake_settings.samples, bake_settings.maps, bake_settings.extra_args = SIZE, 1, {"normal"}, ""
    result, calls, reports = drive(os.path.join(WORK, "modal", "modal_<MAP>.png"), ["TIMER", "MOUSEMOVE", "TIMER"])
    statuses = [c[1] for c in calls if isinstance(c, tuple) and c[0] == "status"]
    print("  modal: %s, statuses %s, reports %s" % (result, statuses[:3] + ["..."] + statuses[-2:], reports))
    check(result == {"FINISHED"} and any(t and t.startswith("nmbake: ") for t in statuses) and statuses[-1] is None,
          "the modal bake shows nmbake's stage in the status bar, then clears it")
    check("progress end" in calls and "timer removed" in calls, "... and ends the progress and its timer")
    modal_map = os.path.join(WORK, "modal", "modal_normal.png")
    check(os.path.isfile(modal_map) and same_bytes(modal_map, reference) and bpy.data.images.get("modal_normal.png") is not None,
          "... and gives the map of the script's bake, loaded")
    bake_settings.size, bake_settings.samples = 4096, 64
    result, calls, reports = drive(os.path.join(WORK, "modal", "stopped_<MAP>.png"), ["TIMER", "ESC"])
    bake_settings.size, bake_settings.samples = SIZE, 1
    print("  Esc: %s, reports %s" % (result, reports))
    check(result == {"CANCELLED"} and any("stopped" in text for kind, text in reports if kind == {"WARNING"}),
          "Esc stops the modal bake with a warning")
    check(not os.path.exists(os.path.join(WORK, "modal", "stopped_normal.png")) and bpy.data.images.get("stopped_normal.png") is None,
          "... and nothing is written or loaded")


def case_transforms(low, high, reference):
    """Both objects moved, rotated and scaled together, the unit scale changed, and the low-poly
    (a copy) given a mirroring, stretching transform with its mesh moved the opposite way (its
    faces turned to stay outwards: its world shape is the same): a map made without the objects'
    transforms, or with a mirrored object inside out, would differ."""
    import bmesh
    import mathutils

    inner = mathutils.Matrix.LocRotScale((0.4, -0.3, 0.2), mathutils.Euler((0.2, 0.9, -0.4)), (1.0, 2.0, -0.5))
    moved = low.copy()
    moved.data = low.data.copy()
    bpy.context.collection.objects.link(moved)
    moved.data.transform(inner.inverted())
    bm = bmesh.new()
    bm.from_mesh(moved.data)
    bmesh.ops.reverse_faces(bm, faces=list(bm.faces))
    bm.to_mesh(moved.data)
    bm.free()
    outer = mathutils.Matrix.LocRotScale((3.0, -2.0, 1.5), mathutils.Euler((0.3, -0.5, 0.7)), (2.5, 2.5, 2.5))
    moved.matrix_world = outer @ inner
    high.matrix_world = outer
    bpy.context.scene.unit_settings.scale_length = 0.01
    select(moved, [high])
    bake(os.path.join(WORK, "moved", "moved_<MAP>.png"))
    bpy.data.objects.remove(moved)
    high.matrix_world = mathutils.Matrix.Identity(4)
    bpy.context.scene.unit_settings.scale_length = 1.0
    select(low, [high])
    d = nmdiff(os.path.join(WORK, "moved", "moved_normal.png"), reference, "moved")
    print("  moved vs in place: mean %.5f p99 %.5f max %.5f deg" % (d["mean_deg"], d["p99_deg"], d["max_deg"]))
    check(d["mean_deg"] <= 0.05 and d["p99_deg"] <= 1.0, "moving, rotating, scaling and mirroring the objects (and the unit scale) keeps the map")


def case_cage(low, high):
    cage = low.copy()
    cage.data = low.data.copy()
    cage.name = "LowCage"
    bpy.context.collection.objects.link(cage)
    for v in cage.data.vertices:
        v.co += v.normal * 0.15
    select(low, [high])
    folder = bake(os.path.join(WORK, "cage", "cage_<MAP>.png"), cage_mode="OBJECT", cage_object=cage)
    with open(os.path.join(folder, "report.json"), encoding="utf-8") as f:
        report = json.load(f)
    command = report["command"]
    check("--cage" in command and command[command.index("--cage") + 1].endswith("LowCage.ply"), "the cage object is passed as --cage")
    check(report["cage"]["source"] == "file", "nmbake baked from the cage file (report: cage source %s)" % report["cage"]["source"])
    cli = os.path.join(WORK, "cage", "cli_normal.png")
    run_cli(folder, "Low.ply", "High.ply", cli, "--cage", os.path.join(folder, "LowCage.ply"))
    addon = os.path.join(WORK, "cage", "cage_normal.png")
    d = nmdiff(addon, cli, "cage")
    check(d["mean_deg"] <= 0.01 and same_bytes(addon, cli), "the cage bake is the command line's with --cage (mean %.5f deg)" % d["mean_deg"])
    bpy.data.objects.remove(cage)


def case_texture_set(low, high):
    """normal, ao, object-id and vertex-color (the high-poly's colour attribute, red) as UDIM
    images: colour spaces, the tile, the colour."""
    colors = high.data.color_attributes.new("Col", "FLOAT_COLOR", "POINT")
    for c in colors.data:
        c.color = (1.0, 0.0, 0.0, 1.0)
    high.data.color_attributes.active_color = colors
    select(low, [high])
    bake(os.path.join(WORK, "set", "set_<MAP>.<UDIM>.png"), size=32, maps={"normal", "ao", "object-id", "vertex-color"},
         extra_args="--ao-rays 4")
    high.data.color_attributes.remove(colors)
    for name in ("normal", "ao", "object-id", "vertex-color"):
        check(os.path.isfile(os.path.join(WORK, "set", "set_%s.1001.png" % name)), "the texture set wrote set_%s.1001.png" % name)
    space = {i.name: (i.source, i.colorspace_settings.name) for i in bpy.data.images if i.name.startswith("set_")}
    print("  images:", space)
    check(space.get("set_normal.1001.png") == ("TILED", "Non-Color") and space.get("set_ao.1001.png") == ("TILED", "Non-Color"),
          "normal and ao are Non-Color UDIM images")
    check(space.get("set_vertex-color.1001.png") == ("TILED", "sRGB"), "vertex-color is an sRGB UDIM image")
    image = bpy.data.images.get("set_vertex-color.1001.png")
    pixels = list(image.pixels) if image is not None else []
    centre = pixels[4 * (16 * 32 + 16) : 4 * (16 * 32 + 16) + 3]
    check(len(centre) == 3 and centre[0] > 0.9 and centre[1] < 0.1 and centre[2] < 0.1, "the high-poly's colour is baked (%s)" % centre)


def case_uv_orientation():
    """A plane whose UVs fill the lower-left quarter, under a tilted plane: Blender's image
    (pixels from the bottom-left) has the tilted normal there and the flat one far from it."""
    for o in list(bpy.data.objects):
        bpy.data.objects.remove(o)
    bpy.ops.mesh.primitive_plane_add(size=2.0)
    low = bpy.context.active_object
    low.name = "Quad"
    for loop_uv in low.data.uv_layers.active.data:
        loop_uv.uv = (loop_uv.uv[0] * 0.5, loop_uv.uv[1] * 0.5)
    bpy.ops.mesh.primitive_plane_add(size=2.6, location=(0, 0, 0.02), rotation=(0.0, math.radians(20.0), 0.0))
    high = bpy.context.active_object
    high.name = "Tilted"
    select(low, [high])
    bake(os.path.join(WORK, "uv", "quad_<MAP>.png"), size=64, wire_material=False, extra_args="--padding 2 --allow-mismatch")
    image = bpy.data.images["quad_normal.png"]
    pixels = list(image.pixels)

    def red(x, y):
        return pixels[4 * (y * 64 + x)]

    print("  red at (8, 8) %.3f, at (56, 56) %.3f" % (red(8, 8), red(56, 56)))
    check(abs(red(8, 8) - 0.5) > 0.1 and abs(red(56, 56) - 0.5) < 0.02, "the map lies where Blender's UVs are (v up)")


def case_refusals():
    for o in list(bpy.data.objects):
        bpy.data.objects.remove(o)
    low, high = make_pair()
    out = os.path.join(WORK, "refused")
    prefs().executable = os.path.join(WORK, "no-such-folder", "nmbake")
    refused(out, "missing executable (a path)", "nmbake executable not found", "no-such-folder")
    prefs().executable = "nmbake-not-installed"
    refused(out, "missing executable (on PATH)", "nmbake executable not found", "nmbake-not-installed")
    prefs().executable = ARGS.nmbake
    select(None, [high])
    refused(out, "no low-poly", "no low-poly")
    empty = bpy.data.objects.new("AnEmpty", None)
    bpy.context.collection.objects.link(empty)
    select(empty, [high])
    refused(out, "an empty active", "no low-poly", "AnEmpty")
    select(low, [])
    refused(out, "no high-poly", "no high-poly", "'Low'")
    bare = low.copy()
    bare.data = low.data.copy()
    bare.name = "LowNoUV"
    bpy.context.collection.objects.link(bare)
    while bare.data.uv_layers:
        bare.data.uv_layers.remove(bare.data.uv_layers[0])
    select(bare, [high])
    refused(out, "a low-poly without UVs", "'LowNoUV'", "no UV map")
    select(low, [high])
    images_before = len(bpy.data.images)
    message = None
    try:
        bake(os.path.join(out, "both.png"), maps={"normal", "ao"})
    except RuntimeError as e:
        message = str(e).strip()
    print("  report:", message)
    check(message is not None and "nmbake: --output" in message and "<MAP>" in message and "\n" not in message and "Traceback" not in message,
          "an nmbake error is its one line")
    check(not os.path.exists(os.path.join(out, "both.png")) and len(bpy.data.images) == images_before, "... and nothing is written")


def main():
    cases = []
    try:
        case_registers()
        low, high = make_pair()
        case_panel_draws()
        reference = case_pair(low, high)
        case_modal(reference)
        case_transforms(low, high, reference)
        case_cage(low, high)
        case_texture_set(low, high)
        case_uv_orientation()
        case_refusals()
    except Exception:
        traceback.print_exc()
        failures.append("an exception")
    print("Blender %s: %d failure(s)" % (bpy.app.version_string, len(failures)))
    if failures:
        for f in failures:
            print("FAILED:", f)
        raise SystemExit(1)


main()
