"""nmbake from Python: the nmbake command's bakes and nmdiff's comparisons (docs/python.md).

    import nmbake
    result = nmbake.bake("low.obj", "high.ply", size=1024, samples=4, maps=["normal", "ao"])
    result.maps["normal"]      # numpy float32, H x W x 3, the values the file would decode to
    result.report["trace"]     # the report --report writes, as a dict
    nmbake.diff("a.png", "b.png", max_mean=0.5)["mean_deg"]

Keyword arguments are the command's long options with '-' as '_' (nmbake --help): they become a
command line that goes through the command's own parsing, so every check and message is the
command's. Errors raise Error's subclasses by the command's exit status (README's table).
"""

import collections
import json
import numbers
import os
import tempfile
from collections.abc import Mapping

import numpy as np

from . import _nmbake

__all__ = ["bake", "diff", "read_image", "Bake", "Error", "UsageError", "InputError", "OutputError", "ResourceError",
           "StrictError"]


class Error(Exception):
    """An error of nmbake or nmdiff: its one-line message, without "error: "."""
    exit_code = None  # the command's exit status for it


class UsageError(Error, ValueError):
    """A bad option or combination of options (exit status 1)."""
    exit_code = 1


class InputError(Error):
    """An unreadable or invalid input: a mesh, a map, a pair that cannot be baked (exit status 2)."""
    exit_code = 2


class OutputError(Error):
    """An output that could not be written (exit status 3)."""
    exit_code = 3


class ResourceError(Error):
    """Out of memory, or a size refused (exit status 4)."""
    exit_code = 4


class StrictError(Error):
    """A warning under strict=True: nothing written (exit status 5)."""
    exit_code = 5


_ERRORS = {e.exit_code: e for e in (UsageError, InputError, OutputError, ResourceError, StrictError)}

Bake = collections.namedtuple("Bake", "maps report")
Bake.__doc__ = """A bake's result: maps {name: array} ({name: {tile: array}} with <UDIM>), report (a dict)."""

# The command's long options, with '_' for '-': name -> (option, takes a value).
_BAKE_OPTIONS = {name.replace("-", "_"): (name, value) for name, value in _nmbake.option_names().items()}
# nmdiff's long options (nmdiff --help); --json and --heatmap write files as nmdiff does.
_DIFF_OPTIONS = {name: (name.replace("_", "-"), value) for name, value in {
    "max_mean": True, "max_p99": True, "max_deg": True, "max_abs": True, "max_share": True, "map": True, "mask": True,
    "include_padding": False, "ignore_alpha": False, "green_a": True, "green_b": True, "same_convention": False,
    "resample": True, "heatmap": True, "heatmap_scale": True, "json": True}.items()}
_MESH_KEYS = ("positions", "triangles", "normals", "uvs")


def _raise(failure):
    status, message = failure.args
    raise _ERRORS.get(status, Error)(message) from None


def _words(function, options, table):
    """The command-line words of keyword arguments: --name=value, a flag --name (n times for n)."""
    words = []
    for key, value in options.items():
        if key not in table:
            raise TypeError(f"{function}() got an unexpected keyword argument '{key}'")
        name, takes_value = table[key]
        if value is None:
            continue
        if not takes_value:
            if isinstance(value, bool) or (isinstance(value, numbers.Integral) and value >= 0):
                words += [f"--{name}"] * int(value)
                continue
            raise TypeError(f"{function}() argument '{key}' is a flag: True or False, got {value!r}")
        if isinstance(value, (list, tuple)):
            value = ",".join(str(v) for v in value)
        elif isinstance(value, float):
            value = repr(value)
        elif isinstance(value, os.PathLike):
            value = os.fspath(value)
        words.append(f"--{name}={value}")
    return words


def _array(mesh, key, arg, columns, integer):
    a = np.asarray(mesh[key])
    kind = "integers" if integer else "numbers"
    if a.ndim != 2 or a.shape[1] != columns:
        raise ValueError(f"{arg}: {key} must be an N x {columns} array, got shape {a.shape}")
    if integer and a.dtype.kind not in "iu":
        raise ValueError(f"{arg}: {key} must hold integers (vertex numbers from 0), got {a.dtype}")
    if not integer and a.dtype.kind not in "iuf":
        raise ValueError(f"{arg}: {key} must hold {kind}, got {a.dtype}")
    return a


def _mesh_bytes(mesh, arg):
    """A mesh given as arrays as a binary PLY file's bytes: it is read by the command's PLY reader,
    so its checks and messages are a file's (a non-finite coordinate, an index out of range)."""
    unknown = [k for k in mesh if k not in _MESH_KEYS]
    if unknown:
        raise ValueError(f"{arg}: unknown key {unknown[0]!r} (a mesh holds {', '.join(_MESH_KEYS)})")
    for key in ("positions", "triangles"):
        if key not in mesh:
            raise ValueError(f"{arg}: no {key} (a mesh holds positions N x 3, triangles M x 3, normals N x 3, uvs N x 2)")
    positions = _array(mesh, "positions", arg, 3, False)
    triangles = _array(mesh, "triangles", arg, 3, True)
    if triangles.size and (triangles.min() < -2**31 or triangles.max() >= 2**31):
        raise ValueError(f"{arg}: triangles hold a vertex number beyond 32 bits")
    fields = [("x", positions[:, 0]), ("y", positions[:, 1]), ("z", positions[:, 2])]
    for key, names, columns in (("normals", ("nx", "ny", "nz"), 3), ("uvs", ("s", "t"), 2)):
        if mesh.get(key) is None:
            continue
        a = _array(mesh, key, arg, columns, False)
        if a.shape[0] != positions.shape[0]:
            raise ValueError(f"{arg}: {key} must have one row per position ({positions.shape[0]}), got {a.shape[0]}")
        fields += [(n, a[:, i]) for i, n in enumerate(names)]
    vertices = np.empty(positions.shape[0], dtype=[(n, "<f8") for n, _ in fields])
    for n, column in fields:
        vertices[n] = column
    faces = np.empty(triangles.shape[0], dtype=[("n", "u1"), ("v", "<i4", (3,))])
    faces["n"] = 3
    faces["v"] = triangles
    header = ["ply", "format binary_little_endian 1.0", "comment nmbake.bake arrays",
              f"element vertex {positions.shape[0]}"]
    header += [f"property double {n}" for n, _ in fields]
    header += [f"element face {triangles.shape[0]}", "property list uchar int vertex_indices", "end_header"]
    return ("\n".join(header) + "\n").encode("ascii") + vertices.tobytes() + faces.tobytes()


def _mesh_word(mesh, arg, meshes):
    """The command-line word of a mesh: its path, or the name of its arrays' PLY bytes."""
    if isinstance(mesh, (str, os.PathLike)):
        return os.fspath(mesh)
    if isinstance(mesh, Mapping):
        name = f"array:{arg}.ply"
        meshes[name] = _mesh_bytes(mesh, arg)
        return name
    raise TypeError(f"{arg} must be a path or a dict of arrays (positions, triangles, normals, uvs), "
                    f"got {type(mesh).__name__}")


def bake(low, highs, **options):
    """Bakes as `nmbake LOW HIGH... --option value ...` does; returns Bake(maps, report).

    low, highs: paths, or dicts of numpy arrays {positions: N x 3, triangles: M x 3 (int),
    normals: N x 3 (optional), uvs: N x 2 (the low-poly's)}; highs may be a list of them (baked as
    one). The keyword arguments are the command's long options with '_' for '-' (samples=16,
    green="down", maps=["normal", "ao"], cage=..., report="r.json"); a flag takes True.
    output="crate_<MAP>.png" writes the files exactly as the command does; without it nothing is
    written but the files other options name, and the maps are the bake's float values (bits=8 or
    16: as such a file would hold them). quiet defaults to True (no summary line on stdout);
    warnings still print on stderr and are in report["warnings"]. progress=callable(stage, share)
    is called at each stage (share 0) and each percent done; an exception in it stops the bake and
    is raised. maps: {name: float32 array H x W x C} (the masks as "miss-mask", "suspect-mask"),
    {name: {tile: array}} with <UDIM> in output.
    """
    callback = options.pop("progress", None)
    if callback is not None and not callable(callback):
        options["progress"] = callback  # the command's --progress flag: its line on stderr
        callback = None
    options.setdefault("quiet", True)
    meshes = {}
    if isinstance(highs, (list, tuple)):
        if not highs:
            raise ValueError("highs: at least one high-poly mesh")
        high_words = [_mesh_word(h, f"highs[{i}]", meshes) for i, h in enumerate(highs)]
    else:
        high_words = [_mesh_word(highs, "highs", meshes)]
    low_word = _mesh_word(low, "low", meshes)
    if options.get("cage") is not None and not isinstance(options["cage"], (str, os.PathLike)):
        options["cage"] = _mesh_word(options["cage"], "cage", meshes)
    words = _words("bake", options, _BAKE_OPTIONS)
    command = ["nmbake"] + words + ["--", low_word] + high_words
    written = options.get("output") is not None
    argv = command
    if not written:
        # An output the command's checks accept, never written: its extension sets the bit depth.
        bits = options.get("bits")
        ext = ".png" if bits == 8 else ".tif" if bits == 16 else ".exr"
        argv = ["nmbake", "--output=" + os.path.join(tempfile.gettempdir(), "nmbake-in-memory_<MAP>" + ext)] + command[1:]
    try:
        images, report_text = _nmbake.bake(argv, command, meshes, written, callback)
    except _nmbake.Failure as failure:
        _raise(failure)
    maps = {}
    for name, tile, array, half in images:
        if half:  # an EXR in 16 bits holds half floats
            array = array.astype(np.float16).astype(np.float32)
        if tile:
            maps.setdefault(name, {})[tile] = array
        else:
            maps[name] = array
    report = json.loads(report_text)
    if not written:
        report["options"]["output"] = None
        if options.get("compression") is None:
            report["options"]["compression"] = None
        for m in report.get("maps", []):
            m["file"] = None
    return Bake(maps, report)


def diff(a, b, **options):
    """Compares map files as `nmdiff A B --option value ...` does; returns the figures its --json
    writes, as a dict (normal maps: mean_deg, p99_deg, max_deg, within, ...; the other maps in
    their units: mean, p99, max, within, ...). Outside the tolerances is not an error: "within" is
    False. Keyword arguments: nmdiff's long options with '_' for '-' (max_mean=0.5, mask="low.obj",
    green_b="down", heatmap="diff.png")."""
    words = _words("diff", options, _DIFF_OPTIONS)
    try:
        return json.loads(_nmbake.diff(["nmdiff"] + words + ["--", os.fspath(a), os.fspath(b)]))
    except _nmbake.Failure as failure:
        _raise(failure)


def read_image(path):
    """A map file as nmdiff reads it: float32 H x W x C, integer formats scaled to [0, 1]."""
    try:
        return _nmbake.read_image(os.fspath(path))
    except _nmbake.Failure as failure:
        _raise(failure)
