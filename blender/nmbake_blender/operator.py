"""bpy.ops.object.nmbake_bake: the active mesh object is the low-poly, the other selected mesh
objects are the high-poly (Blender's selected-to-active). Checks the selection, exports the meshes
(export_ply.py) into a temporary folder, runs nmbake (runner.py) and loads its maps (images.py).

From the UI (invoke) it runs modal: the status bar shows nmbake's progress, Esc stops it (nmbake
then writes nothing). From a script or in the background (execute) it waits, printing the progress.
Every refusal or nmbake error is one ERROR report (a script calling the operator gets it as
RuntimeError) and writes nothing.
"""

import json
import os
import re
import shlex
import shutil
import tempfile

import bpy

from . import export_ply, images, runner, settings


class _Refused(Exception):
    pass


def _file_stem(name, used):
    """A file name from an object's name: nmbake names an object of a file without names after the
    file (object-id map), so the stem is the object's name where the file system allows it."""
    stem = re.sub(r"[^A-Za-z0-9._-]", "_", name).strip(".") or "object"
    candidate, n = stem, 1
    while candidate.lower() in used:
        n += 1
        candidate = "%s_%d" % (stem, n)
    used.add(candidate.lower())
    return candidate


class _Job:
    """What one bake needs after nmbake exits."""

    def __init__(self):
        self.folder = None
        self.run = None
        self.report_path = None
        self.low_name = None
        self.uv_map = None
        self.maps = []
        self.output = None
        self.wire = False
        self.keep = False
        self.stopped = False  # Esc


def _check(context, s):
    """(low, highs, cage, uv_map, maps, output) for the bake, or _Refused naming the object."""
    low = context.active_object
    selected = list(context.selected_objects)
    if low is None or low.type != "MESH" or low not in selected:
        what = "no active object" if low is None else "the active object '%s' is %s" % (
            low.name, "not a mesh" if low.type != "MESH" else "not selected")
        raise _Refused("no low-poly selected (%s): select the high-poly objects, then the low-poly last so it is active" % what)
    cage = s.cage_object if s.cage_mode == "OBJECT" else None
    highs = [o for o in selected if o is not low and o is not cage and o.type == "MESH"]
    if not highs:
        raise _Refused("no high-poly selected for the low-poly '%s': select the high-poly mesh objects too, then the low-poly last" % low.name)
    depsgraph = context.evaluated_depsgraph_get()
    low_mesh = low.evaluated_get(depsgraph).data
    if len(low_mesh.uv_layers) == 0:
        raise _Refused("the low-poly '%s' has no UV map: unwrap it before baking" % low.name)
    uv_map = s.uv_map or low_mesh.uv_layers.active.name
    if low_mesh.uv_layers.get(uv_map) is None:
        raise _Refused("the low-poly '%s' has no UV map '%s'" % (low.name, uv_map))
    if len(low_mesh.polygons) == 0:
        raise _Refused("the low-poly '%s' has no faces" % low.name)
    for high in highs:
        if len(high.evaluated_get(depsgraph).data.polygons) == 0:
            raise _Refused("the high-poly '%s' has no faces" % high.name)
    if s.cage_mode == "OBJECT":
        if cage is None:
            raise _Refused("no cage object: choose one in the nmbake panel, or another cage option")
        if cage is low:
            raise _Refused("the cage object '%s' is the low-poly itself" % cage.name)
        cage_mesh = cage.evaluated_get(depsgraph).data
        if len(cage_mesh.vertices) != len(low_mesh.vertices) or len(cage_mesh.loops) != len(low_mesh.loops):
            raise _Refused("the cage object '%s' does not have the low-poly '%s''s topology (%d vertices, %d corners against %d, %d)" % (
                cage.name, low.name, len(cage_mesh.vertices), len(cage_mesh.loops), len(low_mesh.vertices), len(low_mesh.loops)))
    maps = [m for m in runner.MAP_NAMES if m in s.maps]
    if not maps:
        raise _Refused("no map chosen: tick at least one of the nmbake panel's maps")
    if not s.output.strip():
        raise _Refused("no output file: give one in the nmbake panel")
    if s.output.startswith("//") and not bpy.data.filepath:
        raise _Refused("the output '%s' is relative to the .blend file, which is not saved: save it or give an absolute path" % s.output)
    output = os.path.abspath(bpy.path.abspath(s.output))  # a plain relative path: from Blender's working folder
    return low, highs, cage, uv_map, maps, output


def _export(context, s, low, highs, cage, uv_map, maps, folder):
    """Writes the meshes into `folder`: (low file, high files, cage file or None)."""
    depsgraph = context.evaluated_depsgraph_get()
    scale = context.scene.unit_settings.scale_length or 1.0
    used = set()
    low_wm = export_ply.WorldMesh(low, depsgraph, scale)
    try:
        low_path = os.path.join(folder, _file_stem(low.name, used) + ".ply")
        layout = export_ply.write_mesh(low_path, low_wm, uv_layer=uv_map, comment="low-poly " + low.name)
        cage_path = None
        if cage is not None:
            cage_wm = export_ply.WorldMesh(cage, depsgraph, scale)
            try:
                cage_path = os.path.join(folder, _file_stem(cage.name, used) + ".ply")
                export_ply.write_cage(cage_path, cage_wm, layout, low_wm, uv_map, comment="cage " + cage.name)
            finally:
                cage_wm.free()
    finally:
        low_wm.free()
    high_paths = []
    for high in highs:
        wm = export_ply.WorldMesh(high, depsgraph, scale)
        try:
            path = os.path.join(folder, _file_stem(high.name, used) + ".ply")
            export_ply.write_mesh(path, wm, colors="vertex-color" in maps, comment="high-poly " + high.name)
            high_paths.append(path)
        finally:
            wm.free()
    return low_path, high_paths, cage_path


def _command(executable, s, scale, low_path, high_paths, cage_path, maps, output, report_path):
    command = [executable, low_path] + high_paths + ["-o", output, "--size", str(s.size)]
    command += ["--samples", "auto" if s.samples_auto else str(s.samples), "--green", s.green, "--maps", ",".join(maps)]
    if s.cage_mode == "OBJECT":
        command += ["--cage", cage_path]
    elif s.cage_mode == "DISTANCE":
        command += ["--front", repr(s.front * scale), "--rear", repr(s.rear * scale)]
    command += shlex.split(s.extra_args)
    command += ["--report", report_path, "--progress"]
    return command


class OBJECT_OT_nmbake_bake(bpy.types.Operator):
    """Bake the selected high-poly objects onto the active low-poly with nmbake"""

    bl_idname = "object.nmbake_bake"
    bl_label = "Bake with nmbake"
    bl_options = {"REGISTER"}

    @classmethod
    def poll(cls, context):
        return context.scene is not None

    def _start(self, context):
        s = context.scene.nmbake
        prefs = settings.preferences(context)
        job = _Job()
        try:
            executable = runner.find_executable(prefs.executable)
            low, highs, cage, job.uv_map, job.maps, job.output = _check(context, s)
            shlex.split(s.extra_args)  # a bad quote: refused before anything is written
        except (runner.NotFound, _Refused, ValueError) as e:
            self.report({"ERROR"}, str(e))
            return None
        job.low_name, job.wire, job.keep = low.name, s.wire_material, prefs.keep_exported
        job.folder = tempfile.mkdtemp(prefix="nmbake-blender-")
        try:
            low_path, high_paths, cage_path = _export(context, s, low, highs, cage, job.uv_map, job.maps, job.folder)
            os.makedirs(os.path.dirname(job.output) or ".", exist_ok=True)
            job.report_path = os.path.join(job.folder, "report.json")
            scale = context.scene.unit_settings.scale_length or 1.0
            command = _command(executable, s, scale, low_path, high_paths, cage_path, job.maps, job.output, job.report_path)
            print("nmbake-blender: " + " ".join(shlex.quote(c) for c in command))
            job.run = runner.Run(command)
        except OSError as e:  # a full disk, a folder not writable, an executable that will not run
            self._cleanup(context, job)
            self.report({"ERROR"}, "nmbake could not start: %s" % e)
            return None
        except BaseException:
            self._cleanup(context, job)
            raise
        return job

    def _cleanup(self, context, job):
        context.window_manager.nmbake_last_export = job.folder if job.keep else ""
        if job.folder and not job.keep:
            shutil.rmtree(job.folder, ignore_errors=True)

    def _finish(self, context, job):
        try:
            if job.run.returncode != 0 and job.stopped:
                self.report({"WARNING"}, "nmbake: stopped (Esc); nothing written")
                return {"CANCELLED"}
            if job.run.returncode != 0:
                self.report({"ERROR"}, job.run.error)
                return {"CANCELLED"}
            with open(job.report_path, encoding="utf-8") as f:
                report = json.load(f)
            for warning in report.get("warnings", []):
                self.report({"WARNING"}, warning)
            loaded = []
            for name, (pattern, files) in images.map_files(report).items():
                if not files:
                    continue
                image = images.load_map(name, pattern, files)
                loaded.append(image.name)
                low = bpy.data.objects.get(job.low_name)
                if name == "normal" and job.wire and low is not None:
                    images.wire_normal_map(low, image, job.uv_map)
            kept = " (meshes kept in %s)" % job.folder if job.keep else ""
            self.report({"INFO"}, "nmbake: baked %s for '%s': %s%s" % (", ".join(job.maps), job.low_name, ", ".join(loaded), kept))
            return {"FINISHED"}
        finally:
            self._cleanup(context, job)

    def execute(self, context):
        job = self._start(context)
        if job is None:
            return {"CANCELLED"}
        shown = None
        while not job.run.wait(0.25):
            text = job.run.status_text()
            if text != shown:
                print(text)
                shown = text
        return self._finish(context, job)

    def invoke(self, context, _event):
        if bpy.app.background or context.window is None:
            return self.execute(context)
        job = self._start(context)
        if job is None:
            return {"CANCELLED"}
        self._job = job
        wm = context.window_manager
        self._timer = wm.event_timer_add(0.1, window=context.window)
        wm.progress_begin(0, 100)
        wm.modal_handler_add(self)
        return {"RUNNING_MODAL"}

    def modal(self, context, event):
        job = self._job
        if event.type == "ESC" and event.value == "PRESS":
            job.stopped = True
            job.run.cancel()
        if event.type != "TIMER":
            return {"PASS_THROUGH"}
        wm = context.window_manager
        if not job.run.done:
            context.workspace.status_text_set(job.run.status_text() + "  (Esc: stop)")
            if job.run.percent is not None:
                wm.progress_update(job.run.percent)
            return {"PASS_THROUGH"}
        wm.event_timer_remove(self._timer)
        wm.progress_end()
        context.workspace.status_text_set(None)
        return self._finish(context, job)


classes = (OBJECT_OT_nmbake_bake,)
register, unregister = bpy.utils.register_classes_factory(classes)
