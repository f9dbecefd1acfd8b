// nmview: the low-poly with its baked normal map beside the high-poly, one camera, one light.
//
//   nmview LOW.obj normal.png HIGH.ply                 window: left low + map, right high
//   nmview LOW.obj HIGH.ply -m normal.png              the same in nmbake's order (also --map)
//   nmview LOW.obj normal.png HIGH.ply --screenshot cmp.png --size 1600x800 --view 30,20
//   nmview LOW.obj normal.png HIGH.ply --screenshot ear.png --view 30,20,0.25,0.6,1.2,0.1   zoomed on a point
//   nmview LOW.obj normal.png HIGH.ply --compare       appearance and normal-angle difference, a verdict
//   nmview LOW.obj 'crate_<MAP>.png' HIGH.ply          the texture set: AO lit, A and M keys, --show MAP
//   nmview LOW.obj normal.png HIGH.ply --report r.json --show masks,cage   nmbake's masks and cage (K, C keys)
//   nmview LOW.obj 'suz.<UDIM>.png' HIGH.ply           UDIM tiles (udim_tiles.h): each face samples its tile
//   nmview LOW.obj normal.png HIGH.ply --show uv --uv-cursor 0.3,0.6 --frame-selection --screenshot at.png
//                                                      the texel at UV 0.3,0.6 marked on the model, framed
//
// main only parses arguments and wires the stages together; errors print "error: <what>" and
// exit with the baker's codes (errors.h).
#include <cerrno>
#include <cmath>
#include <csignal>
#include <cstdint>
#include <cstring>
#include <iostream>
#include <optional>
#include <sstream>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>

#include "cli/numbers.h"
#include "cli/shell.h"
#include "cli/spellings.h"
#include "compare.h"
#include "core/errors.h"
#include "io/image_io.h"
#include "io/mesh_io.h"
#include "io/output_files.h"
#include "gl_context.h"
#include "inputs.h"
#include "interactive.h"
#include "overlays.h"
#include "renderer.h"
#include "scene.h"
#include "udim_textures.h"
#include "uv_cursor.h"

namespace {

struct Options {
  std::vector<std::string> files;  // LOW MAP HIGH, or LOW HIGH with -m (inputs.h)
  std::string map_option;          // -m, --map
  std::string low, map, high;      // resolved
  std::string screenshot;
  std::string size = "1600x800";
  std::string view = "30,20";
  std::string light = "-30,30";
  std::string show;
  nmview::OverlayFiles overlays;  // --miss-mask, --suspect-mask, --cage, --report
  bool no_map = false;
  bool no_ao = false;
  bool compare = false;
  std::string uv_cursor;                          // --uv-cursor U,V ("" none)
  bool frame_selection = false;                   // --frame-selection: the view frames the UV cursor's point
  double diff_scale = nmview::kDefaultDiffScale;  // degrees at the top of the difference pane's colour scale
  unsigned uv_set = 0;                            // the low-poly's UV set the map was baked into (nmbake --uv-set)
  nmview::DecodingOverrides decoding;
};

// "A,B" of two finite numbers (--light).
void parse_pair(const std::string& flag, const std::string& text, float& a, float& b) {
  std::istringstream in(text);
  char comma = 0;
  double x = 0, y = 0;
  if (!(in >> x >> comma >> y) || comma != ',' || !(in >> std::ws).eof() || !std::isfinite(x) || !std::isfinite(y))
    throw nmbake::UsageError(flag + ": expected AZ,EL in degrees (e.g. 30,20), got '" + text + "'");
  a = float(x);
  b = float(y);
}

void parse_size(const std::string& text, int& width, int& height) {
  std::istringstream in(text);
  char x = 0;
  long w = 0, h = 0;
  if (!(in >> w >> x >> h) || (x != 'x' && x != 'X') || !(in >> std::ws).eof() || w < 16 || h < 16 || w > 16384 || h > 16384)
    throw nmbake::UsageError("--size: expected WxH with 16..16384 pixels each (e.g. 1600x800), got '" + text + "'");
  width = int(w);
  height = int(h);
}

// Toggles, and at most one display: "lit" or a map name of the set (core/maps.h).
void parse_show(const std::string& text, nmview::Toggles& toggles) {
  std::istringstream in(text);
  std::string item, display;
  while (std::getline(in, item, ',')) {
    nmbake::MapKind kind;
    if (item == "lit" || nmbake::parse_map_name(item, kind)) {
      if (!display.empty())
        throw nmbake::UsageError("--show: " + display + " and " + item + ": the left pane shows one of lit and the set's maps");
      display = item;
      toggles.show_map = item != "lit";
      if (toggles.show_map) toggles.shown = kind;
    } else if (item == "wire") toggles.wireframe = true;
    else if (item == "diff") toggles.difference = true;
    else if (item == "tangent") toggles.tangent_colours = true;
    else if (item == "specular") toggles.specular = 0.3f;
    else if (item == "nolabels") toggles.labels = false;
    else if (item == "masks") toggles.masks = true;
    else if (item == "cage") toggles.cage = true;
    else if (item == "uv") toggles.uv_layout = true;
    else if (!item.empty())
      throw nmbake::UsageError(
          "--show: unknown item '" + nmbake::printable(item) +
          "' (wire, diff, tangent, specular, nolabels, masks, cage, uv; lit or one map: " + nmbake::map_name_list() + ")");
  }
}

// The overlay files of the options and the report, checked against --show's masks and cage.
nmview::OverlayFiles resolve_overlays(const Options& o, const nmview::Toggles& toggles) {
  nmview::OverlayFiles report;
  if (!o.overlays.report.empty()) report = nmview::read_report_overlays(o.overlays.report);
  const nmview::OverlayFiles files = nmview::merge_overlay_files(o.overlays, report);
  const std::string in_report = o.overlays.report.empty() ? "" : " (" + o.overlays.report + " names none)";
  if (toggles.masks && !files.any_mask())
    throw nmbake::UsageError("--show masks: no mask given" + in_report +
                             "; give --miss-mask FILE or --suspect-mask FILE (written by nmbake --miss-mask, "
                             "--suspect-mask), or --report FILE of a bake that wrote them");
  if (toggles.cage && files.cage.empty())
    throw nmbake::UsageError("--show cage: no cage given" +
                             (o.overlays.report.empty() ? std::string()
                                                        : " (" + o.overlays.report +
                                                              " names none: that bake made its own cage; nmbake --save-cage "
                                                              "FILE writes it)") +
                             "; give --cage FILE (a cage nmbake took with --cage or wrote with --save-cage), or --report "
                             "FILE of a bake with --cage or --save-cage");
  return files;
}

int run(const Options& o) {
  nmview::InteractiveOptions io;
  parse_size(o.size, io.width, io.height);
  const nmview::ViewOption view = nmview::parse_view_option(o.view);
  parse_pair("--light", o.light, io.light.azimuth, io.light.elevation);
  parse_show(o.show, io.toggles);
  io.toggles.map = !o.no_map;
  if (!(o.diff_scale >= 0.001 && o.diff_scale <= double(nmview::kMaxDiffScale)))  // NaN included
    throw nmbake::UsageError("--diff-scale: expected degrees above 0 up to 180 (e.g. 30), got " + std::to_string(o.diff_scale));
  io.toggles.diff_scale = float(o.diff_scale);
  // The texture set's files (a map path with <MAP>); none is read yet.
  const nmview::TextureSetFiles maps = nmview::find_texture_set(o.map);
  if (io.toggles.show_map && !maps.find(io.toggles.shown)) {
    const std::string name = nmbake::map_name(io.toggles.shown);
    throw nmbake::UsageError("--show " + name + ": " + o.map + " has no " + name + " map" +
                             (maps.has_token ? " (" + nmview::describe_set(maps) + ")"
                                             : "; give the set's path with <MAP> (crate_<MAP>.png) to load its maps"));
  }
  io.toggles.ao = !o.no_ao && maps.find(nmbake::MapKind::ao);
  // The screenshot may not be an input (exit 1) nor a file that cannot be written (exit 3): checked
  // before anything is loaded or rendered.
  const nmview::OverlayFiles overlay_files = resolve_overlays(o, io.toggles);
  nmview::check_screenshot(o.screenshot, o.low, maps, o.high);
  nmbake::check_output_files(nmview::overlay_inputs(overlay_files), {{"--screenshot", o.screenshot, "the screenshot"}});

  const std::optional<glm::vec2> uv_cursor =
      o.uv_cursor.empty() ? std::nullopt : std::optional<glm::vec2>(nmview::parse_uv_cursor(o.uv_cursor));
  if (o.frame_selection && !uv_cursor)
    throw nmbake::UsageError(
        "--frame-selection: nothing selected; give --uv-cursor U,V (the point of the low-poly at that UV is "
        "framed)");
  if (o.compare && uv_cursor)
    throw nmbake::UsageError(
        "--uv-cursor: --compare keeps its fixed views and marks nothing; use it with --screenshot or the "
        "window");

  const nmview::Scene scene = nmview::load_scene(o.low, maps, o.high, std::cerr, o.decoding, o.uv_set);
  // The target is given in the meshes' object space; the renderer's scene is re-centred.
  io.view = nmview::resolve_view(view, scene.bounds.centre());
  const nmview::OverlayData overlays = nmview::load_overlays(overlay_files, scene, std::cerr);

  // The UV cursor: its texel's point on the low-poly is marked and selected (F frames it).
  nmview::Marks marks;
  if (uv_cursor) {
    const std::optional<nmview::UvPoint> point = nmview::find_uv_point(scene.low, *uv_cursor);
    marks.uv = uv_cursor;
    marks.label = nmview::describe_uv_point(*uv_cursor, point);
    if (point) {
      marks.points.push_back(point->position);
      const glm::vec3 p = point->position + scene.bounds.centre();
      std::cerr << "nmview: --uv-cursor " << o.uv_cursor << ": triangle " << point->triangle
                << (point->tile > 0 ? " (tile " + std::to_string(point->tile) + ")" : std::string()) << " of the low-poly, at "
                << p.x << "," << p.y << "," << p.z << ": marked\n";
      if (o.frame_selection) io.view = nmview::frame_point(io.view, point->position);
    } else {
      std::cerr << "nmview: --uv-cursor " << o.uv_cursor << ": in no triangle of the low-poly's UV layout: no marker"
                << (o.frame_selection ? ", nothing to frame (the view as given)" : "") << "\n";
    }
  }
  io.uv_cursor = uv_cursor;

  if (!o.compare && o.screenshot.empty()) {
    nmview::run_interactive(scene, io, overlays);
    return 0;
  }

  nmview::HeadlessContext context;
  std::cerr << "nmview: " << context.description() << "\n";
  nmview::Renderer renderer(scene.low, scene.high, scene.map, scene.radius, scene.decoding);
  for (const nmview::SetMap& m : scene.set_maps) renderer.add_set_map(m.kind, m.image);
  renderer.set_overlays(overlays);
  nmview::upload_udim_tiles(renderer, scene);

  if (o.compare) {
    // Each view is measured at the size of one pane of the --size window, lit and without AO: the
    // high-poly has no occlusion to compare it with.
    const int pane_width = io.width / 2, pane_height = io.height;
    nmview::Toggles measure;
    measure.map = io.toggles.map;
    const nmview::CompareResult result = nmview::run_compare(renderer, pane_width, pane_height, io.light, measure);

    // The worst view as low | high | difference, at the same pane size, only where asked: nothing
    // is left in the current folder.
    if (!o.screenshot.empty()) {
      nmview::Toggles show = measure;
      show.difference = true;
      show.diff_scale = io.toggles.diff_scale;
      nmview::Framebuffer target(3 * pane_width, pane_height);
      renderer.render(target.id(), 3 * pane_width, pane_height, result.views[result.worst].view, io.light, show);
      nmview::write_screenshot(o.screenshot, nmview::Renderer::read_framebuffer(target.id(), 3 * pane_width, pane_height), scene);
      std::cerr << "nmview: worst view written to " << o.screenshot << "\n";
    }
    nmview::print_compare(result, scene.decoding, std::cout);
    return 0;
  }

  nmview::Framebuffer target(io.width, io.height);
  renderer.set_marks(marks);
  renderer.render(target.id(), io.width, io.height, io.view, io.light, io.toggles);
  nmview::write_screenshot(o.screenshot, nmview::Renderer::read_framebuffer(target.id(), io.width, io.height), scene);
  std::cerr << "nmview: wrote " << o.screenshot << " (" << io.width << "x" << io.height << ")\n";
  return 0;
}

}  // namespace

namespace {

int run_command_line(int argc, char** argv) {
  CLI::App app{
      "nmview: the low-poly with its baked tangent-space normal map beside the high-poly, "
      "lit alike from one camera.\n  nmview LOW MAP HIGH [OPTIONS]\n  nmview LOW HIGH -m MAP [OPTIONS]   (nmbake's order)"};
  Options o;
  app.add_option("files", o.files,
                 "LOW MAP HIGH, or LOW HIGH with -m MAP (nmbake's order); the map may stand anywhere among three files: "
                 "meshes and images are told apart by their content. LOW: the low-poly mesh with UVs (OBJ, PLY, OFF, STL, "
                 "glTF, FBX, DAE...), as given to nmbake. MAP: the normal map baked for it (any size; its nmbake:* "
                 "metadata says how it was baked), or the texture set as nmbake -o wrote it, with <MAP> for each map's "
                 "name (crate_<MAP>.png: every map found is loaded, the normal map is required), and/or <UDIM> for each UDIM "
                 "tile's number (suz.<UDIM>.png: every tile 1001-2000 found is loaded, each face samples the tile of its "
                 "UV centroid; a face whose tile has no file is drawn magenta and one warning lists those tiles). HIGH: the "
                 "high-poly "
                 "mesh (its normals, else computed ones)")
      ->expected(2, 3)
      ->required()
      ->option_text("FILE x 2-3 REQUIRED");
  app.add_option("-m,--map", o.map_option, "The map (as MAP above), with LOW HIGH in nmbake's order");
  app.add_option("--screenshot", o.screenshot,
                 "Render without a display to FILE and exit (with --compare: write the worst view's difference "
                 "image to FILE; without it --compare writes no image)");
  app.add_option("--size", o.size, "Window or image size WxH in pixels (both panes together)")->capture_default_str();
  app.add_option("--view", o.view,
                 "Camera AZ,EL[,DIST[,TX,TY,TZ]]: azimuth and elevation in degrees (Y up; 0,0 looks from +Z); DIST "
                 "the distance from the target as a factor of the distance that frames both models (1, the default, "
                 "frames them; 0.5 is twice as close; 0.001..1000); TX,TY,TZ the point looked at and orbited, in the "
                 "meshes' own coordinates (default: the centre of both models' bounding box). --compare keeps its "
                 "fixed views. The window's V key prints its current view in this form")
      ->capture_default_str();
  app.add_option("--light", o.light, "Light azimuth,elevation in degrees relative to the view direction (0,0 = from the eye)")
      ->capture_default_str();
  app.add_flag("--no-map", o.no_map, "Left pane without the normal map (the low-poly's bare shading)");
  app.add_flag("--no-ao", o.no_ao, "Lit render without the set's ao map (by default multiplied in when the set has one)");
  app.add_flag("--compare", o.compare,
               "Render both models from 10 fixed views (8 around at 20 deg elevation, top, bottom) with one light "
               "and print the appearance difference. psnr/rmse/within2 are over the INTERIOR: pixels fully covered "
               "by both models whose neighbours within 1 pixel are too (silhouettes and their anti-aliasing left "
               "out); rmse of the 8-bit RGB values scaled to 0..1, psnr = 20 log10(1/rmse), within2 = share of "
               "pixels with every channel within 2/255. silhouette_mismatch = share of the object's pixels "
               "(covered by either model) covered by one model only; union_psnr/union_rmse = the same over all "
               "the object's pixels (one-model pixels against black). Then the angle in degrees between the "
               "low-poly's shading normal and the high-poly's over the interior, with the map as decoded, with no map, "
               "green flipped and red/green swapped (mean, p95), the share of the no-map angle the map removes, and a "
               "verdict: good, likely green flipped, likely swapped channels, the map barely helps. Last stdout line: "
               "psnr=<dB> rmse=<0..1> within2=<fraction> silhouette_mismatch=<fraction> union_psnr=<dB> "
               "union_rmse=<0..1> interior_share=<fraction> angle_mean=<deg> angle_p95=<deg> no_map_angle_mean=<deg> "
               "no_map_angle_p95=<deg> flipped_angle_mean=<deg> swapped_angle_mean=<deg> map_removes=<share> "
               "verdict=<good|green_flipped|swapped_channels|barely_helps>");
  app.add_option("--uv-cursor", o.uv_cursor,
                 "U,V: the UV cursor at the low-poly's UV (U,V), as the mouse puts it over the UV view (U key, --show uv): "
                 "a cyan cross there, and the texel's point on the model (the first triangle holding that UV; any UDIM tile, "
                 "1.5,0.5 is in 1002) marked with a cyan cross in the 3D panes, drawn over the models (not depth-tested); "
                 "that point is the selection (F frames it). Outside every UV triangle: no marker, and a line says so");
  app.add_flag("--frame-selection", o.frame_selection,
               "With --uv-cursor: the view frames the selected point (the target at it, a tenth of the models' radius "
               "around it shown: the F key), keeping --view's angles");
  app.add_option("--diff-scale", o.diff_scale,
                 "Difference pane (D, --show diff): the angle in degrees between the low-poly's shading normal and the "
                 "high-poly's normal at the top of its colour scale (black 0, red, yellow, white at DEG; keys [ and ] "
                 "step it), above 0 up to 180")
      ->capture_default_str();
  app.add_option("--space", o.decoding.space,
                 "How the map was baked: tangent or object space (default: the map's nmbake:space metadata, "
                 "else tangent)");
  app.add_option("--green", o.decoding.green,
                 "Tangent-space map's green: up = OpenGL, down = DirectX, also gl/opengl and dx/directx, any case "
                 "(default: nmbake:green metadata, else up)")
      ->transform([](const std::string& value) { return nmbake::canonical_green(value); });
  app.add_option("--bitangent", o.decoding.bitangent,
                 "Tangent-space map's bitangent: pixel = sign*cross(N,T) per pixel (MikkTSpace), vertex = "
                 "interpolated per-corner B (default: nmbake:bitangent metadata, else pixel)");
  app.add_option("--uv-set", o.uv_set,
                 "The low-poly's UV set the map was baked into, from 0, as given to nmbake --uv-set (glTF, FBX, DAE "
                 "may have several)")
      ->check(CLI::Range(0u, nmbake::kMaxUvSets - 1))
      ->capture_default_str();
  app.add_option("--miss-mask", o.overlays.miss_mask,
                 "nmbake --miss-mask's image (the share of each texel's rays that missed): painted magenta on the low-poly "
                 "with --show masks or the K key");
  app.add_option("--suspect-mask", o.overlays.suspect_mask,
                 "nmbake --suspect-mask's image: suspect texels painted orange on the low-poly with --show masks or K");
  app.add_option("--cage", o.overlays.cage,
                 "A cage with the low-poly's topology (as given to nmbake --cage, or written by --save-cage): its edges drawn "
                 "green over the low-poly with --show cage or the C key");
  app.add_option("--report", o.overlays.report,
                 "nmbake --report's JSON: the miss mask, suspect mask and cage (--cage, else --save-cage) it names (relative "
                 "paths from the current "
                 "folder, else the report's) are loaded where --miss-mask, --suspect-mask, --cage are not given");
  app.add_option("--show", o.show,
                 "Start with toggles on: wire,diff (the normal-angle difference pane),tangent,specular,nolabels,masks (K),cage "
                 "(C),uv (U: the left pane shows the map flat with the UV edges); and what "
                 "the left pane shows: lit (the "
                 "default) or one map of the set unlit in its own colours (normal, ao, curvature, object-id, ...)");
  nmbake::require_numbers(app);

  if (const std::optional<int> status = nmbake::parse_command_line(app, argc, argv, "nmview")) return *status;
  const nmview::InputFiles inputs = nmview::resolve_inputs(o.files, o.map_option);
  o.low = inputs.low;
  o.map = inputs.map;
  o.high = inputs.high;
  return run(o);
}

}  // namespace

int main(int argc, char** argv) {
  // A closed or full stdout or stderr loses messages, never changes the screenshot or the exit
  // status; a file past ulimit -f is a failed write (exit 3).
  nmbake::protect_standard_streams();
  nmbake::remove_temporaries_on_signals();
  return nmbake::run_command([&] { return run_command_line(argc, argv); });
}
