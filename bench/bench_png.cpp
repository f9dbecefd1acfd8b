// The PNG encoder's settings measured on a real map (the 1M-triangle sculpt's 2048^2 8-bit map of
// section 3): zlib level, libpng's row filters and zlib's strategy against file size and encode
// time (libpng's own encoder, png_libpng.h), which is how PngSettings' defaults (baker/io/png_write.h)
// were chosen; and the default settings in bands on several threads, as nmbake writes PNG.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <system_error>
#include <string>
#include <vector>

#include "bench_bake.h"
#include "bench_support.h"
#include "io/image_io.h"
#include "io/png_write.h"
#include "png_libpng.h"

namespace nmbake::bench {

namespace {

bool fs_exists(const std::string& path) {
  std::error_code ec;
  return std::filesystem::exists(path, ec);
}

struct Setting {
  const char* name;
  PngSettings s;
  int threads = -1;  // -1: libpng's one stream (encode_png_libpng); else nmbake's bands on this many (0: all cores)
};

}  // namespace

void run_png_settings(BenchRun& run, const Scenes& scenes) {
  const std::string map = run.run_dir + "/m1_2k.png";
  if (!fs_exists(map))
    run_nmbake(run.args.exe, scenes.s4 + "/low.obj " + scenes.m1_ply + " -o " + map + " --size 2048", run.report, 1);
  std::printf("## 9. PNG settings (the 1M sculpt's 2048^2 8-bit map from section 3, encoded in memory)\n\n");
  Image image;
  try {
    image = read_image(map);
  } catch (const std::exception& e) {
    std::printf("No map to encode (%s).\n\n", e.what());
    return;
  }
  std::vector<std::uint8_t> rows(image.pixels.size());
  for (std::size_t i = 0; i < rows.size(); ++i) rows[i] = std::uint8_t(std::lround(image.pixels[i] * 255.0f));
  const std::vector<Setting> settings = {
      {"RLE strategy, paeth (the default), libpng, one thread", PngSettings{}},
      {"the default in 8 bands, every core (what nmbake writes)", PngSettings{}, 0},
      {"the default in 8 bands, one thread", PngSettings{}, 1},
      {"level 1, up (the settings before)", {1, 0x20, 0}},
      {"level 1, no filter", {1, 0x08, 0}},
      {"level 1, sub", {1, 0x10, 0}},
      {"level 1, paeth", {1, 0x80, 0}},
      {"level 1, adaptive (all filters)", {1, 0xF8, 0}},
      {"level 1, up, RLE strategy", {1, 0x20, 3}},
      {"level 1, up, filtered strategy", {1, 0x20, 1}},
      {"RLE strategy, sub", {1, 0x10, 3}},
      {"RLE strategy, adaptive", {1, 0xF8, 3}},
      {"Huffman only, up", {1, 0x20, 2}},
      {"Huffman only, paeth", {1, 0x80, 2}},
      {"level 2, up", {2, 0x20, 0}},
      {"level 3, up", {3, 0x20, 0}},
      {"level 6 (zlib's default), up", {6, 0x20, 0}},
      {"level 6, adaptive (libpng's default)", {6, 0xF8, 0}},
      {"level 9, up", {9, 0x20, 0}},
      {"level 0 (stored), no filter", {0, 0x08, 0}},
  };
  const int reps = run.args.quick ? 1 : 3;
  std::printf("Best of %d encodes each; load average %s.\n\n| settings | MB | vs default | encode s |\n|---|---|---|---|\n", reps,
              load_average().c_str());
  double default_size = 0.0;
  for (const Setting& st : settings) {
    double best = 1e30;
    std::size_t size = 0;
    for (int r = 0; r < reps; ++r) {
      const auto t0 = Clock::now();
      std::string error;
      const std::vector<unsigned char> bytes =
          st.threads < 0 ? encode_png_libpng(rows.data(), image.width, image.height, image.channels, 8, {}, st.s, &error)
                         : encode_png(rows.data(), image.width, image.height, image.channels, 8, {}, st.s, st.threads, &error);
      best = std::min(best, since(t0));
      size = bytes.size();
    }
    if (default_size == 0.0) default_size = double(size);
    std::printf("| %s | %.2f | %+.1f%% | %.3f |\n", st.name, double(size) / 1e6, 100.0 * (double(size) / default_size - 1.0),
                best);
  }
  std::printf("\n");
  flush();
}

}  // namespace nmbake::bench
