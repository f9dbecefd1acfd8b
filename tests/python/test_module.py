"""The Python module nmbake (python/, docs/python.md) against the nmbake command (NMBAKE_EXE).

Run by ctest as python.module: PYTHONPATH=build/python, NMBAKE_EXE and NMDIFF_EXE the built
commands, NMBAKE_SAMPLE_DIR data/sample. Small maps (64 px) keep it to a few seconds.
"""

import os
import struct
import subprocess
import threading
import time
import zlib

import numpy as np
import pytest

import nmbake

SAMPLE = os.environ.get("NMBAKE_SAMPLE_DIR", os.path.join(os.path.dirname(__file__), "..", "..", "data", "sample"))
LOW = os.path.join(SAMPLE, "torus_low.obj")
HIGH = os.path.join(SAMPLE, "torus_high.ply")
SIZE = 64


def nmbake_exe():
    exe = os.environ.get("NMBAKE_EXE")
    if not exe:
        pytest.fail("NMBAKE_EXE names the nmbake binary to compare with (ctest sets it)")
    return exe


def run_command(*args):
    return subprocess.run([nmbake_exe(), *args], capture_output=True, text=True)


def decode_png(path):
    """An 8- or 16-bit grey or RGB(A) PNG's stored integers, H x W x C, by the PNG specification."""
    data = open(path, "rb").read()
    assert data[:8] == b"\x89PNG\r\n\x1a\n"
    pos, idat = 8, b""
    while pos < len(data):
        length, kind = struct.unpack(">I4s", data[pos:pos + 8])
        body = data[pos + 8:pos + 8 + length]
        if kind == b"IHDR":
            width, height, depth, color = struct.unpack(">IIBB", body[:10])
        elif kind == b"IDAT":
            idat += body
        pos += 12 + length
    channels = {0: 1, 2: 3, 4: 2, 6: 4}[color]
    step = channels * depth // 8
    stride = width * step
    raw = zlib.decompress(idat)
    rows = np.zeros((height, stride), dtype=np.int32)
    prev = np.zeros(stride, dtype=np.int32)
    for y in range(height):
        line = raw[y * (stride + 1):(y + 1) * (stride + 1)]
        kind, cur = line[0], np.frombuffer(line[1:], dtype=np.uint8).astype(np.int32)
        out = np.zeros(stride, dtype=np.int32)
        for x in range(stride):
            a = out[x - step] if x >= step else 0
            b = prev[x]
            c = prev[x - step] if x >= step else 0
            if kind == 0:
                p = 0
            elif kind == 1:
                p = a
            elif kind == 2:
                p = b
            elif kind == 3:
                p = (a + b) // 2
            else:
                pa, pb, pc = abs(b - c), abs(a - c), abs(a + b - 2 * c)
                p = a if pa <= pb and pa <= pc else b if pb <= pc else c
            out[x] = (cur[x] + p) & 0xFF
        rows[y], prev = out, out
    if depth == 16:
        rows = rows[:, 0::2] * 256 + rows[:, 1::2]
    return rows.reshape(height, width, channels)


@pytest.fixture(scope="module")
def both(tmp_path_factory):
    """One set of maps baked by the module with output= and by the command, same inputs and options."""
    folder = tmp_path_factory.mktemp("both")
    options = ["--size", str(SIZE), "--samples", "2", "--green", "down", "--maps", "normal,ao,height", "--ao-rays", "16"]
    py = str(folder / "py_<MAP>.png")
    cli = str(folder / "cli_<MAP>.png")
    result = nmbake.bake(LOW, HIGH, size=SIZE, samples=2, green="down", maps=["normal", "ao", "height"], ao_rays=16,
                         output=py, report=str(folder / "py.json"))
    done = run_command(LOW, HIGH, "-o", cli, "--quiet", *options)
    assert done.returncode == 0, done.stderr
    return folder, result


def test_bake_from_paths_gives_float_maps_by_name():
    result = nmbake.bake(LOW, HIGH, size=SIZE)
    assert list(result.maps) == ["normal"]
    normal = result.maps["normal"]
    assert normal.shape == (SIZE, SIZE, 3) and normal.dtype == np.float32
    assert 0.0 <= normal.min() and normal.max() <= 1.0
    # Without output=, the bake's float values: not only multiples of 1/255.
    assert np.any(np.abs(normal * 255.0 - np.round(normal * 255.0)) > 1e-3)
    # Tangent-space normals point out of the surface: blue above 0.5 where the torus is covered.
    assert np.median(normal[..., 2]) > 0.7
    report = result.report
    assert report["options"]["size"] == [SIZE, SIZE]
    assert report["options"]["output"] is None
    assert report["options"]["samples"] == 1
    assert report["options"]["green"] == "up"
    assert 0.3 < report["coverage"] <= 1.0
    assert isinstance(report["warnings"], list)
    assert report["command"][0] == "nmbake" and report["command"][-2:] == [LOW, HIGH]
    assert report["maps"] == [{"map": "normal", "file": None}]


def test_files_are_byte_identical_to_the_command(both):
    folder, _ = both
    for name in ("normal", "ao", "height"):
        py = (folder / f"py_{name}.png").read_bytes()
        cli = (folder / f"cli_{name}.png").read_bytes()
        assert py == cli, name


def test_arrays_are_what_the_files_decode_to(both):
    folder, result = both
    assert sorted(result.maps) == ["ao", "height", "normal"]
    assert result.maps["normal"].shape == (SIZE, SIZE, 3)
    assert result.maps["ao"].shape == (SIZE, SIZE, 1)
    assert result.maps["height"].shape == (SIZE, SIZE, 1)
    for name, array in result.maps.items():
        stored = decode_png(folder / f"py_{name}.png")
        assert stored.shape == array.shape, name
        assert np.array_equal(np.round(array.astype(np.float64) * 255.0).astype(np.int32), stored), name
        assert np.array_equal(array, (stored / 255.0).astype(np.float32)), name
        assert np.allclose(nmbake.read_image(folder / f"py_{name}.png"), array, rtol=0, atol=1e-6), name


def test_id_map_arrays_are_their_colours(tmp_path):
    # The ID maps are held as palette indices inside the bake; the module hands back the RGB
    # colours the file stores (the report's colour per name), as for every other map.
    out = str(tmp_path / "id_<MAP>.png")
    result = nmbake.bake(LOW, HIGH, size=SIZE, maps=["normal", "object-id", "material-id"], output=out)
    for name in ("object-id", "material-id"):
        array = result.maps[name]
        assert array.shape == (SIZE, SIZE, 3) and array.dtype == np.float32, name
        assert np.allclose(nmbake.read_image(tmp_path / f"id_{name}.png"), array, rtol=0, atol=1e-6), name
        entry = next(m for m in result.report["maps"] if m["map"] == name)
        colours = {tuple(c) for c in entry["colors"].values()} | {(0, 0, 0)}
        used = {tuple(int(v) for v in px) for px in np.round(array.reshape(-1, 3) * 255.0)}
        assert used <= colours and len(used - {(0, 0, 0)}) >= 1, (name, used, colours)


def test_report_dict_is_the_report_file(both):
    import json
    folder, result = both
    written = json.loads((folder / "py.json").read_text())
    assert written == result.report
    assert result.report["options"]["green"] == "down"
    assert result.report["options"]["samples"] == 2
    assert [m["map"] for m in result.report["maps"]] == ["normal", "ao", "height"]
    assert result.report["maps"][1]["rays_per_texel"] == 16
    assert result.report["maps"][0]["file"].endswith("py_normal.png")


def plane(z, n, uvs):
    """A square [0,1]^2 at height z as an n x n grid of quads, UVs = (x, y)."""
    xs = np.linspace(0.0, 1.0, n + 1)
    x, y = np.meshgrid(xs, xs)
    positions = np.stack([x.ravel(), y.ravel(), np.full(x.size, z)], axis=1)
    tris = []
    for j in range(n):
        for i in range(n):
            a = j * (n + 1) + i
            tris += [[a, a + 1, a + n + 2], [a, a + n + 2, a + n + 1]]
    mesh = {"positions": positions, "triangles": np.array(tris, dtype=np.int64)}
    if uvs:
        mesh["uvs"] = positions[:, :2].copy()
    return mesh


def write_obj(path, mesh):
    with open(path, "w") as f:
        for p in mesh["positions"]:
            f.write("v %r %r %r\n" % tuple(float(v) for v in p))
        for t in mesh.get("uvs", []):
            f.write("vt %r %r\n" % tuple(float(v) for v in t))
        for a, b, c in mesh["triangles"] + 1:
            f.write(f"f {a}/{a} {b}/{b} {c}/{c}\n" if "uvs" in mesh else f"f {a} {b} {c}\n")


def test_bake_from_arrays_equals_the_same_meshes_from_files(tmp_path):
    low = plane(0.0, 2, True)
    high = plane(0.0625, 8, False)
    # A bump: the high-poly's middle vertices raised, so the map is not flat everywhere.
    high["positions"][40, 2] = 0.25
    # Flat boxes of different heights: --allow-mismatch.
    from_arrays = nmbake.bake(low, [high], size=32, front=0.5, rear=0.5, allow_mismatch=True)
    write_obj(tmp_path / "low.obj", low)
    write_obj(tmp_path / "high.obj", high)
    from_files = nmbake.bake(str(tmp_path / "low.obj"), tmp_path / "high.obj", size=32, front=0.5, rear=0.5,
                             allow_mismatch=True)
    a, b = from_arrays.maps["normal"], from_files.maps["normal"]
    assert np.array_equal(a, b)
    # Known answer: parallel planes give the flat normal (0.5, 0.5, 1) away from the bump.
    assert np.allclose(a[0, 0], [0.5, 0.5, 1.0], atol=1e-6)
    assert np.abs(a - [0.5, 0.5, 1.0]).max() > 0.05
    assert from_arrays.report["options"]["low"] == "array:low.ply"
    assert from_arrays.report["highs"] == ["array:highs[0].ply"]


def test_arrays_with_normals_and_a_cage_bake():
    low = plane(0.0, 2, True)
    low["normals"] = np.tile([0.0, 0.0, 1.0], (low["positions"].shape[0], 1))
    cage = plane(0.5, 2, True)
    del cage["uvs"]
    result = nmbake.bake(low, plane(0.125, 4, False), size=16, cage=cage, rear=0.5,
                         allow_mismatch=True)
    assert np.allclose(result.maps["normal"][8, 8], [0.5, 0.5, 1.0], atol=1e-6)
    assert result.report["options"]["cage"] == "array:cage.ply"


def test_arrays_of_the_wrong_shape_raise_value_error_naming_the_argument():
    low, high = plane(0.0, 2, True), plane(0.1, 2, False)
    bad = dict(low, positions=low["positions"][:, :2])
    with pytest.raises(ValueError, match=r"^low: positions must be an N x 3 array, got shape \(9, 2\)"):
        nmbake.bake(bad, high)
    with pytest.raises(ValueError, match=r"^highs\[1\]: triangles must hold integers"):
        nmbake.bake(low, [high, dict(high, triangles=high["triangles"].astype(float))])
    with pytest.raises(ValueError, match=r"^low: uvs must have one row per position \(9\), got 4"):
        nmbake.bake(dict(low, uvs=low["uvs"][:4]), high)
    with pytest.raises(ValueError, match=r"^highs: unknown key 'uv'"):
        nmbake.bake(low, dict(high, uv=low["uvs"]))


def test_array_errors_found_by_the_reader_are_input_errors():
    low, high = plane(0.0, 2, True), plane(0.1, 2, False)
    high["triangles"][0, 0] = 99
    with pytest.raises(nmbake.InputError, match=r"^array:highs\.ply: .*99"):
        nmbake.bake(low, high)


def test_wrong_keyword_raises_type_error_naming_it():
    with pytest.raises(TypeError, match="unexpected keyword argument 'sampels'"):
        nmbake.bake(LOW, HIGH, sampels=4)
    with pytest.raises(TypeError, match="unexpected keyword argument 'max_means'"):
        nmbake.diff(LOW, HIGH, max_means=1)
    with pytest.raises(TypeError, match="'dither' is a flag"):
        nmbake.bake(LOW, HIGH, dither="yes")


def test_missing_file_raises_the_input_error_naming_it(tmp_path):
    missing = str(tmp_path / "no_such_high.ply")
    with pytest.raises(nmbake.InputError) as caught:
        nmbake.bake(LOW, missing, size=SIZE, output=str(tmp_path / "map.png"))
    message = str(caught.value)
    assert missing in message and not message.startswith("error:")
    assert isinstance(caught.value, nmbake.Error) and caught.value.exit_code == 2
    assert not (tmp_path / "map.png").exists()
    # The command's own line, less "error: ".
    done = run_command(LOW, missing, "-o", str(tmp_path / "map.png"), "--size", str(SIZE))
    assert done.returncode == 2
    assert done.stderr.strip().splitlines()[-1] == "error: " + message


def test_bad_option_values_raise_the_commands_usage_error():
    # Caught by the parser (CLI11) and by the options' checks; the command's line for each.
    for options, args in (({"samples": 0}, ["--samples", "0"]), ({"green": "sideways"}, ["--green", "sideways"])):
        with pytest.raises(nmbake.UsageError) as caught:
            nmbake.bake(LOW, HIGH, **options)
        assert caught.value.exit_code == 1 and isinstance(caught.value, ValueError)
        done = run_command(LOW, HIGH, "-o", "unused.png", *args)
        assert done.returncode == 1
        assert done.stderr.strip().splitlines()[-1] == "error: " + str(caught.value), options
    with pytest.raises(nmbake.UsageError, match=r"^--maps: unknown map 'glow'"):
        nmbake.bake(LOW, HIGH, maps=["normal", "glow"])


def test_unwritable_output_raises_output_error(tmp_path):
    folder = tmp_path / "a_folder.png"
    folder.mkdir()
    with pytest.raises(nmbake.OutputError, match="a_folder.png"):
        nmbake.bake(LOW, HIGH, size=SIZE, output=str(folder))


def test_diff_gives_nmdiffs_figures(both, tmp_path):
    folder, _ = both
    same = nmbake.diff(folder / "py_normal.png", folder / "cli_normal.png")
    assert same["mean_deg"] == 0.0 and same["max_deg"] == 0.0 and same["within"] is True
    assert same["texels_compared"] == SIZE * SIZE
    other = nmbake.bake(LOW, HIGH, size=SIZE, output=str(tmp_path / "up.png"))
    # A map in the other green convention differs (nmdiff's verdict) unless asked to compare in one.
    differs = nmbake.diff(folder / "py_normal.png", tmp_path / "up.png")
    assert differs["convention_differs"] is True and differs["within"] is False
    one = nmbake.diff(folder / "py_normal.png", tmp_path / "up.png", same_convention=True, max_mean=30, max_p99=90,
                      max_deg=180)
    assert one["convention_differs"] is False and one["green_flipped"] is True
    assert 0.0 < one["mean_deg"] < 30.0 and one["within"] is True  # 2 samples against 1
    # The command's --json, key for key.
    nmdiff = os.environ.get("NMDIFF_EXE")
    if nmdiff:
        import json
        done = subprocess.run([nmdiff, "--json", str(tmp_path / "d.json"), "--same-convention", "--max-mean", "30",
                               "--max-p99", "90", "--max-deg", "180",
                               str(folder / "py_normal.png"), str(tmp_path / "up.png")], capture_output=True, text=True)
        assert done.returncode == 0, done.stderr
        assert json.loads((tmp_path / "d.json").read_text()) == one
    ao = nmbake.diff(folder / "py_ao.png", folder / "cli_ao.png")
    assert ao["map"] == "ao" and ao["max"] == 0.0 and ao["within"] is True
    with pytest.raises(nmbake.InputError, match="nothing.png"):
        nmbake.diff(folder / "py_normal.png", tmp_path / "nothing.png")
    assert other.maps["normal"].shape == (SIZE, SIZE, 3)


def test_progress_is_called_with_stages_and_shares():
    calls = []
    nmbake.bake(LOW, HIGH, size=SIZE, progress=lambda stage, share: calls.append((stage, share)))
    stages = [s for s, _ in calls]
    for stage in ("loading", "building the BVH", "tracing", "writing"):
        assert stage in stages
    assert calls[-1] == ("done", 1.0)
    assert all(0.0 <= share <= 1.0 for _, share in calls)


def test_an_exception_in_progress_cancels_the_bake(tmp_path):
    class Stop(Exception):
        pass

    def stop(stage, share):
        if stage == "tracing":
            raise Stop(stage)

    with pytest.raises(Stop):
        nmbake.bake(LOW, HIGH, size=SIZE, progress=stop, output=str(tmp_path / "map.png"))
    assert not (tmp_path / "map.png").exists()
    assert os.listdir(tmp_path) == []


def test_the_gil_is_released_while_baking():
    count = [0]
    stop = threading.Event()

    def spin():
        while not stop.is_set():
            count[0] += 1

    thread = threading.Thread(target=spin)
    thread.start()
    try:
        before = count[0]
        time.sleep(0.05)  # the spinning thread alone
        rate = (count[0] - before) / 0.05
        before = count[0]
        result = nmbake.bake(LOW, HIGH, size=128, samples=4, threads=1)
        during = count[0] - before
    finally:
        stop.set()
        thread.join()
    seconds = result.report["seconds"]["total"]
    assert seconds > 0.05
    # Held through the bake, the GIL would let the thread count only outside it (a few ms).
    assert during > 0.2 * rate * seconds, (during, rate, seconds)


def test_udim_maps_come_by_tile(tmp_path):
    result = nmbake.bake(LOW, HIGH, size=32, output=str(tmp_path / "n.<UDIM>.png"), bits=8)
    assert list(result.maps) == ["normal"] and list(result.maps["normal"]) == [1001]
    stored = decode_png(tmp_path / "n.1001.png")
    assert np.array_equal(np.round(result.maps["normal"][1001].astype(np.float64) * 255.0).astype(np.int32), stored)
