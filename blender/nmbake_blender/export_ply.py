"""Blender mesh objects written as binary PLY files for nmbake.

Space and units: positions are world space (the object's matrix_world applied, modifiers applied:
the evaluated mesh of the depsgraph) times the scene's unit scale (scene.unit_settings.scale_length),
so one file unit is one metre with metric units, one Blender unit otherwise; Blender's Z-up axes are
kept (no axis conversion: nmbake reads the file's coordinates as they are, so object-space maps
(object-normal, position) are in Blender's world axes). Normals are the mesh's own (split/corner
normals where a face is flat, an edge sharp or normals custom), transformed with the positions
(Mesh.transform); a mirroring (negative-determinant) transform's windings and normals are turned
back, as Blender draws them.

Vertices: one PLY vertex per distinct (vertex, normal, UV, colour) of the triangles' corners, so
nmbake's MikkTSpace frames and per-vertex cage see the mesh as Blender does. UVs are written as
Blender stores them (v up, origin bottom-left: what nmbake reads from PLY and OBJ). Colours (only
when asked) are 8-bit sRGB. Uses only the standard library (Debian's Blender has no numpy).
"""

import array
import sys

import bpy

_LITTLE = sys.byteorder == "little"


def _floats(n):
    return array.array("f", bytes(4 * n))


def _ints(n):
    # "I": the type of Blender's index properties, which foreach_get copies at once (with "i" it
    # goes item by item, 7 to 15 times slower).
    return array.array("I", bytes(4 * n))


class WorldMesh:
    """The evaluated mesh of `obj` in world space times `scale`, triangulated; a temporary datablock
    removed by free()."""

    def __init__(self, obj, depsgraph, scale):
        import mathutils

        obj_eval = obj.evaluated_get(depsgraph)
        self.mesh = bpy.data.meshes.new_from_object(obj_eval, preserve_all_data_layers=True, depsgraph=depsgraph)
        matrix = mathutils.Matrix.Scale(scale, 4) @ obj.matrix_world
        self.mesh.transform(matrix)
        # A mirroring transform turns the faces inside out (Mesh.transform keeps the windings and
        # the normals follow them; Blender draws such an object turned back): the writer reverses
        # the windings and the normals.
        self.mirrored = matrix.is_negative
        self.mesh.calc_loop_triangles()

    def free(self):
        if self.mesh is not None:
            bpy.data.meshes.remove(self.mesh)
            self.mesh = None


def _normals_per_corner(me):
    """True where some corner's normal differs from its vertex's (flat faces, sharp edges, custom)."""
    domain = getattr(me, "normals_domain", None)  # Blender 4.1 and later
    if domain is not None:
        return domain != "POINT"
    if me.has_custom_normals or getattr(me, "use_auto_smooth", False):
        return True
    smooth = [False] * len(me.polygons)
    me.polygons.foreach_get("use_smooth", smooth)
    return not all(smooth)


def _corner_normals(me):
    n = _floats(3 * len(me.loops))
    if hasattr(me, "corner_normals"):  # Blender 4.1 and later
        me.corner_normals.foreach_get("vector", n)
    else:
        me.calc_normals_split()
        me.loops.foreach_get("normal", n)
    return n


def _srgb_byte(c):
    c = min(max(c, 0.0), 1.0)
    s = c * 12.92 if c <= 0.0031308 else 1.055 * c ** (1.0 / 2.4) - 0.055
    return int(s * 255.0 + 0.5)


def _active_colors(me):
    """(domain, RGBA floats, scene-linear) of the active colour attribute, or (None, None)."""
    attrs = getattr(me, "color_attributes", None)
    layer = attrs.active_color if attrs is not None else None
    legacy = getattr(me, "vertex_colors", None)  # per-corner byte colours, gone in Blender 4
    if layer is None and legacy is not None and legacy.active is not None:
        layer = legacy.active
        data = _floats(4 * len(me.loops))
        layer.data.foreach_get("color", data)
        return "CORNER", data
    if layer is None:
        return None, None
    count = len(me.vertices) if layer.domain == "POINT" else len(me.loops)
    data = _floats(4 * count)
    layer.data.foreach_get("color", data)
    return layer.domain, data


class Layout:
    """Which source vertex and corner each written vertex comes from, and the triangles over the
    written vertices: what a cage with the same topology is written with."""

    def __init__(self, vertex_of, corner_of, triangles):
        self.vertex_of = vertex_of  # written vertex -> mesh vertex index
        self.corner_of = corner_of  # written vertex -> one mesh corner (loop) index, or None
        self.triangles = triangles  # array('i'), 3 per triangle


def write_mesh(path, wm, uv_layer=None, colors=False, comment=""):
    """Writes WorldMesh `wm` to `path`; `uv_layer` the name of the UV map to write (None: none);
    `colors` writes the active colour attribute (if any). Returns the Layout."""
    me = wm.mesh
    nv, nt = len(me.vertices), len(me.loop_triangles)
    co = _floats(3 * nv)
    me.vertices.foreach_get("co", co)
    col_domain, col = _active_colors(me) if colors else (None, None)

    if uv_layer is None and not _normals_per_corner(me) and col_domain != "CORNER":
        # Every corner of a vertex has the vertex's normal: the mesh's own vertices.
        normals = _floats(3 * nv)
        me.vertices.foreach_get("normal", normals)
        tris = _ints(3 * nt)
        me.loop_triangles.foreach_get("vertices", tris)
        rgb = None
        if col is not None:
            rgb = bytes(_srgb_byte(col[4 * i + k]) for i in range(nv) for k in range(3))
        if wm.mirrored:
            _turn_back(normals, tris)
        _write_ply(path, co, normals, None, rgb, tris, comment)
        return Layout(list(range(nv)), [None] * nv, tris)

    tri_loops = _ints(3 * nt)
    me.loop_triangles.foreach_get("loops", tri_loops)
    loop_vert = _ints(len(me.loops))
    me.loops.foreach_get("vertex_index", loop_vert)
    normals = _corner_normals(me)
    uvs = None
    if uv_layer is not None:
        uvs = _floats(2 * len(me.loops))
        me.uv_layers[uv_layer].data.foreach_get("uv", uvs)
    index = {}
    vertex_of, corner_of = [], []
    tris = _ints(3 * nt)
    for i, c in enumerate(tri_loops):
        v = loop_vert[c]
        key = (v, normals[3 * c], normals[3 * c + 1], normals[3 * c + 2])
        if uvs is not None:
            key += (uvs[2 * c], uvs[2 * c + 1])
        if col is not None:
            j = v if col_domain == "POINT" else c
            key += (col[4 * j], col[4 * j + 1], col[4 * j + 2])
        k = index.get(key)
        if k is None:
            k = index[key] = len(vertex_of)
            vertex_of.append(v)
            corner_of.append(c)
        tris[i] = k
    out_co, out_n = _floats(3 * len(vertex_of)), _floats(3 * len(vertex_of))
    out_uv = _floats(2 * len(vertex_of)) if uvs is not None else None
    for k, (v, c) in enumerate(zip(vertex_of, corner_of)):
        out_co[3 * k : 3 * k + 3] = co[3 * v : 3 * v + 3]
        out_n[3 * k : 3 * k + 3] = normals[3 * c : 3 * c + 3]
        if out_uv is not None:
            out_uv[2 * k : 2 * k + 2] = uvs[2 * c : 2 * c + 2]
    rgb = None
    if col is not None:
        rgb = bytes(
            _srgb_byte(col[4 * (v if col_domain == "POINT" else c) + k]) for v, c in zip(vertex_of, corner_of) for k in range(3)
        )
    if wm.mirrored:
        _turn_back(out_n, tris)
    _write_ply(path, out_co, out_n, out_uv, rgb, tris, comment)
    return Layout(vertex_of, corner_of, tris)


def write_cage(path, wm_cage, layout, low_wm, uv_layer, comment=""):
    """Writes the cage WorldMesh `wm_cage` with the low-poly's Layout (its written vertices, their
    normals and UVs, its triangles), positions from the cage's vertices of the same index: the file
    has the low-poly file's topology, as nmbake's --cage needs. The caller checks the counts."""
    me, low = wm_cage.mesh, low_wm.mesh
    co = _floats(3 * len(me.vertices))
    me.vertices.foreach_get("co", co)
    normals = _corner_normals(low)
    uvs = _floats(2 * len(low.loops))
    low.uv_layers[uv_layer].data.foreach_get("uv", uvs)
    n = len(layout.vertex_of)
    out_co, out_n, out_uv = _floats(3 * n), _floats(3 * n), _floats(2 * n)
    for k, (v, c) in enumerate(zip(layout.vertex_of, layout.corner_of)):
        out_co[3 * k : 3 * k + 3] = co[3 * v : 3 * v + 3]
        out_n[3 * k : 3 * k + 3] = normals[3 * c : 3 * c + 3]
        out_uv[2 * k : 2 * k + 2] = uvs[2 * c : 2 * c + 2]
    if low_wm.mirrored:  # the layout's triangles are turned back already
        out_n = array.array("f", (-x for x in out_n))
    _write_ply(path, out_co, out_n, out_uv, None, layout.triangles, comment)


def _turn_back(normals, tris):
    """Reverses each triangle's winding and every normal (a mirrored object's mesh)."""
    for i in range(len(normals)):
        normals[i] = -normals[i]
    tris[1::3], tris[2::3] = tris[2::3], tris[1::3]


def _interleave(dest, record, offset, data, size):
    """Copies `data`'s consecutive `size`-byte fields into `dest`'s records at `offset`."""
    for j in range(size):
        dest[offset + j :: record] = data[j::size]


def _le(a):
    if not _LITTLE:
        a = array.array(a.typecode, a)
        a.byteswap()
    return a.tobytes()


def _write_ply(path, co, normals, uvs, rgb, tris, comment):
    n, t = len(co) // 3, len(tris) // 3
    head = ["ply", "format binary_little_endian 1.0"]
    if comment:
        head.append("comment " + comment.replace("\n", " "))
    head += ["element vertex %d" % n] + ["property float " + p for p in ("x", "y", "z", "nx", "ny", "nz")]
    record = 24
    if uvs is not None:
        head += ["property float s", "property float t"]
        record += 8
    if rgb is not None:
        head += ["property uchar red", "property uchar green", "property uchar blue"]
        record += 3
    head += ["element face %d" % t, "property list uchar int vertex_indices", "end_header"]
    vertices = bytearray(record * n)
    _interleave(vertices, record, 0, _le(co), 12)
    _interleave(vertices, record, 12, _le(normals), 12)
    offset = 24
    if uvs is not None:
        _interleave(vertices, record, offset, _le(uvs), 8)
        offset += 8
    if rgb is not None:
        _interleave(vertices, record, offset, rgb, 3)
    faces = bytearray(13 * t)
    faces[0::13] = b"\x03" * t
    _interleave(faces, 13, 1, _le(tris), 12)
    with open(path, "wb") as f:
        f.write(("\n".join(head) + "\n").encode("ascii", "replace"))
        f.write(vertices)
        f.write(faces)
