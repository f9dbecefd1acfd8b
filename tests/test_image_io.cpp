// image_io: exact quantisation round trips, atomic writes, and the error kinds.
#include "io/image_io.h"

#include <cmath>
#include <cstdint>
#include <cstring>
#include <utility>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <limits>
#include <string>

#include <unistd.h>

#include <gtest/gtest.h>

#include "core/errors.h"
#include "core/parallel.h"
#include "test_support.h"

namespace fs = std::filesystem;
using nmbake::Image;

namespace {

std::string slurp(const std::string& path) {
  std::ifstream f(path, std::ios::binary);
  return {std::istreambuf_iterator<char>(f), std::istreambuf_iterator<char>()};
}

void spit(const std::string& path, const std::string& bytes) {
  std::ofstream f(path, std::ios::binary);
  f << bytes;
}

// Files in `dir` whose name contains ".tmp-" and that are not folders.
int leftover_temp_files(const std::string& dir) {
  int n = 0;
  for (const auto& e : fs::directory_iterator(dir))
    if (!e.is_directory() && e.path().filename().string().find(".tmp-") != std::string::npos) ++n;
  return n;
}

// A 1-channel ramp holding every code of an n-level integer format, k / (levels - 1).
Image code_ramp(int levels) {
  Image img(levels, 1, 1);
  for (int k = 0; k < levels; ++k) img.pixels[k] = float(double(k) / (levels - 1));
  return img;
}

}  // namespace

// A map of several MiB takes the huge-page hint (image.h) before it is filled: every value is the
// fill and the buffer is whole, whether or not the system grants the hint. Odd sizes put the
// buffer's ends off any 2 MiB boundary.
TEST(ImageIo, LargeImageIsFilledWhole) {
  for (const float fill : {0.0f, 0.25f}) {
    const Image img(1531, 1023, 3, fill);
    ASSERT_EQ(img.pixels.size(), std::size_t(1531) * 1023 * 3);
    std::size_t wrong = 0;
    for (float v : img.pixels) wrong += v != fill;
    EXPECT_EQ(wrong, 0u) << "fill " << fill;
    EXPECT_EQ(img.at(1530, 1022)[2], fill);
  }
}

TEST(ImageIo, DefaultBitsFollowExtension) {
  EXPECT_EQ(nmbake::default_bits_for("a.png"), 8);
  EXPECT_EQ(nmbake::default_bits_for("a.PNG"), 8);
  EXPECT_EQ(nmbake::default_bits_for("a.tif"), 16);
  EXPECT_EQ(nmbake::default_bits_for("dir.x/a.tiff"), 16);
  EXPECT_EQ(nmbake::default_bits_for("a.exr"), 32);
}

TEST(ImageIo, CheckOutputFormatRejectsWhatAFormatCannotHold) {
  EXPECT_NO_THROW(nmbake::check_output_format("a.png", 8));
  EXPECT_NO_THROW(nmbake::check_output_format("a.png", 16));
  EXPECT_NO_THROW(nmbake::check_output_format("a.tif", 32));
  EXPECT_NO_THROW(nmbake::check_output_format("a.exr", 16));
  EXPECT_NO_THROW(nmbake::check_output_format("a.exr", 32));
  EXPECT_THROW(nmbake::check_output_format("a.png", 32), nmbake::UsageError);
  EXPECT_THROW(nmbake::check_output_format("a.exr", 8), nmbake::UsageError);
  EXPECT_THROW(nmbake::check_output_format("a.png", 12), nmbake::UsageError);
  EXPECT_THROW(nmbake::check_output_format("a.xyz", 8), nmbake::UsageError);
  EXPECT_THROW(nmbake::check_output_format("noextension", 8), nmbake::UsageError);
}

TEST(ImageIo, EightBitRoundsHalfAwayFromZeroAndClamps) {
  const std::string path = nmbake::test::scratch_dir() + "/q8.png";
  Image img(6, 1, 1);
  img.pixels = {0.5f, 0.0f, 1.0f, -0.25f, 1.5f, std::numeric_limits<float>::quiet_NaN()};
  nmbake::write_image(path, img, {8, {}});
  Image back = nmbake::read_image(path);
  ASSERT_EQ(back.width, 6);
  ASSERT_EQ(back.channels, 1);
  const int expected[] = {128, 0, 255, 0, 255, 0};
  for (int i = 0; i < 6; ++i) EXPECT_EQ(std::lround(back.pixels[i] * 255.0f), expected[i]) << i;
}

TEST(ImageIo, SixteenBitRoundsHalfAwayFromZero) {
  const std::string path = nmbake::test::scratch_dir() + "/q16.png";
  Image img(3, 1, 1);
  img.pixels = {0.5f, 0.0f, 1.0f};
  nmbake::write_image(path, img, {16, {}});
  Image back = nmbake::read_image(path);
  EXPECT_EQ(std::lround(back.pixels[0] * 65535.0f), 32768);
  EXPECT_EQ(std::lround(back.pixels[1] * 65535.0f), 0);
  EXPECT_EQ(std::lround(back.pixels[2] * 65535.0f), 65535);
}

TEST(ImageIo, EveryIntegerCodeRoundTripsExactly) {
  const std::string dir = nmbake::test::scratch_dir();
  struct Case {
    std::string name;
    int bits, levels;
  };
  for (const Case& c : {Case{"c8.png", 8, 256}, Case{"c16.png", 16, 65536}, Case{"c8.tif", 8, 256}, Case{"c16.tif", 16, 65536}}) {
    Image img = code_ramp(c.levels);
    nmbake::write_image(dir + "/" + c.name, img, {c.bits, {}});
    Image back = nmbake::read_image(dir + "/" + c.name);
    ASSERT_EQ(back.pixels.size(), img.pixels.size()) << c.name;
    int wrong = 0;
    for (int k = 0; k < c.levels; ++k)
      if (std::lround(double(back.pixels[k]) * (c.levels - 1)) != k) ++wrong;
    EXPECT_EQ(wrong, 0) << c.name;
  }
}

TEST(ImageIo, FloatFormatsKeepValuesBitExact) {
  const std::string dir = nmbake::test::scratch_dir();
  Image img(4, 2, 3);
  for (std::size_t i = 0; i < img.pixels.size(); ++i) img.pixels[i] = float(i) * 0.1234567f - 0.3f;
  for (const std::string name : {"f.exr", "f.tif"}) {
    nmbake::write_image(dir + "/" + name, img, {32, {}});
    Image back = nmbake::read_image(dir + "/" + name);
    ASSERT_EQ(back.width, 4);
    ASSERT_EQ(back.height, 2);
    ASSERT_EQ(back.channels, 3);
    for (std::size_t i = 0; i < img.pixels.size(); ++i) EXPECT_EQ(back.pixels[i], img.pixels[i]) << name << i;
  }
}

TEST(ImageIo, HalfExrIsWithinHalfPrecision) {
  const std::string path = nmbake::test::scratch_dir() + "/h.exr";
  Image img(16, 1, 1);
  for (int i = 0; i < 16; ++i) img.pixels[i] = float(i) / 15.0f;
  nmbake::write_image(path, img, {16, {}});
  Image back = nmbake::read_image(path);
  for (int i = 0; i < 16; ++i) EXPECT_NEAR(back.pixels[i], img.pixels[i], 1.0 / 2048) << i;
}

TEST(ImageIo, RowZeroIsTheTopAndAlphaIsNotPremultiplied) {
  const std::string path = nmbake::test::scratch_dir() + "/rgba.png";
  Image img(2, 2, 4, 0.0f);
  // Top-left opaque red; bottom-right transparent but with a colour that must survive.
  float* tl = img.at(0, 0);
  tl[0] = 1, tl[3] = 1;
  float* br = img.at(1, 1);
  br[0] = 0.5f, br[1] = 0.5f, br[2] = 1.0f, br[3] = 0.0f;
  nmbake::write_image(path, img);
  Image back = nmbake::read_image(path);
  ASSERT_EQ(back.channels, 4);
  EXPECT_EQ(back.at(0, 0)[0], 1.0f);
  EXPECT_EQ(back.at(1, 0)[0], 0.0f);
  EXPECT_EQ(std::lround(back.at(1, 1)[0] * 255), 128);
  EXPECT_EQ(std::lround(back.at(1, 1)[1] * 255), 128);
  EXPECT_EQ(std::lround(back.at(1, 1)[2] * 255), 255);
  EXPECT_EQ(back.at(1, 1)[3], 0.0f);
}

TEST(ImageIo, MetadataIsStoredInTheFile) {
  const std::string dir = nmbake::test::scratch_dir();
  nmbake::WriteOptions options;
  options.metadata = {{"nmbake:green", "up"}, {"nmbake:source", "low-poly-marker.obj"}};
  for (const std::string name : {"meta.png", "meta.tif", "meta.exr"}) {
    nmbake::write_image(dir + "/" + name, Image(2, 2, 3, 0.5f), options);
    const std::string bytes = slurp(dir + "/" + name);
    EXPECT_NE(bytes.find("nmbake:green"), std::string::npos) << name;
    EXPECT_NE(bytes.find("low-poly-marker.obj"), std::string::npos) << name;
  }
}

TEST(ImageIo, MetadataReadsBackFromEveryFormat) {
  const std::string dir = nmbake::test::scratch_dir();
  nmbake::WriteOptions options;
  options.metadata = {{"nmbake:green", "down"}, {"nmbake:space", "tangent"}, {"ImageDescription", "a map, baked"}};
  for (const std::string name : {"meta.png", "meta.tif", "meta.exr"}) {
    nmbake::write_image(dir + "/" + name, Image(2, 2, 3, 0.5f), options);
    const auto metadata = nmbake::read_image_metadata(dir + "/" + name);
    EXPECT_EQ(metadata.count("nmbake:green") ? metadata.at("nmbake:green") : "", "down") << name;
    EXPECT_EQ(metadata.count("nmbake:space") ? metadata.at("nmbake:space") : "", "tangent") << name;
    ASSERT_TRUE(metadata.count("ImageDescription")) << name;
    EXPECT_EQ(metadata.at("ImageDescription").rfind("a map, baked", 0), 0u) << name;
  }
  nmbake::write_image(dir + "/plain.png", Image(2, 2, 3, 0.5f));
  EXPECT_EQ(nmbake::read_image_metadata(dir + "/plain.png").count("nmbake:green"), 0u);
  EXPECT_THROW(nmbake::read_image_metadata(dir + "/none.png"), nmbake::InputError);
}

TEST(ImageIo, SuccessfulWriteReplacesTheFileAndLeavesNoTemporary) {
  const std::string dir = nmbake::test::scratch_dir();
  const std::string path = dir + "/out.png";
  nmbake::write_image(path, Image(3, 3, 3, 0.0f));
  nmbake::write_image(path, Image(5, 4, 3, 1.0f));
  Image back = nmbake::read_image(path);
  EXPECT_EQ(back.width, 5);
  EXPECT_EQ(back.height, 4);
  EXPECT_EQ(back.pixels[0], 1.0f);
  EXPECT_EQ(leftover_temp_files(dir), 0);
  EXPECT_EQ(std::distance(fs::directory_iterator(dir), fs::directory_iterator()), 1);
}

// PNG and TIFF, each written by nmbake's own encoders (png_write.h, tiff_write.h).
TEST(ImageIo, MissingFolderIsAnOutputError) {
  for (const std::string name : {"out.png", "out.tif"}) {
    const std::string path = nmbake::test::scratch_dir() + "/no/such/folder/" + name;
    try {
      nmbake::write_image(path, Image(2, 2, 3, 0.5f));
      FAIL() << "no exception, " << name;
    } catch (const nmbake::OutputError& e) {
      EXPECT_EQ(std::string(e.what()).rfind(path + ": cannot write: ", 0), 0u) << e.what();
      EXPECT_EQ(e.code(), nmbake::ExitCode::output);
    }
  }
}

TEST(ImageIo, FolderAtThePathIsAnOutputErrorAndTheTemporaryIsRemoved) {
  for (const std::string name : {"taken.png", "taken.tif"}) {
    const std::string dir = nmbake::test::scratch_dir();
    const std::string path = dir + "/" + name;
    fs::create_directory(path);
    EXPECT_THROW(nmbake::write_image(path, Image(2, 2, 3, 0.5f)), nmbake::OutputError) << name;
    EXPECT_TRUE(fs::is_directory(path));
    EXPECT_EQ(leftover_temp_files(dir), 0) << name;
    EXPECT_EQ(std::distance(fs::directory_iterator(dir), fs::directory_iterator()), 1) << name;
  }
}

// White box: the temporary file is ".<name>.tmp-<pid>-<n><ext>"; folders of those names make the
// write fail after the old file exists, which must then be untouched.
TEST(ImageIo, FailedWriteKeepsTheExistingFileIntact) {
  const std::string dir = nmbake::test::scratch_dir();
  const std::string path = dir + "/keep.png";
  nmbake::write_image(path, Image(2, 2, 3, 0.25f));
  const std::string before = slurp(path);
  for (int n = 0; n < 512; ++n)
    fs::create_directory(dir + "/.keep.png.tmp-" + std::to_string(::getpid()) + "-" + std::to_string(n) + ".png");
  EXPECT_THROW(nmbake::write_image(path, Image(8, 8, 3, 0.75f)), nmbake::OutputError);
  EXPECT_EQ(slurp(path), before);
  EXPECT_EQ(leftover_temp_files(dir), 0);
}

TEST(ImageIo, ReadOnlyFolderIsAnOutputError) {
  const std::string dir = nmbake::test::scratch_dir() + "/ro";
  fs::create_directory(dir);
  spit(dir + "/old.png", "");
  nmbake::write_image(dir + "/old.png", Image(2, 2, 3, 0.25f));
  const std::string before = slurp(dir + "/old.png");
  fs::permissions(dir, fs::perms::owner_read | fs::perms::owner_exec);
  if (::access(dir.c_str(), W_OK) == 0) {
    fs::permissions(dir, fs::perms::owner_all);
    GTEST_SKIP() << "running with privileges that ignore folder permissions";
  }
  EXPECT_THROW(nmbake::write_image(dir + "/old.png", Image(4, 4, 3, 0.5f)), nmbake::OutputError);
  fs::permissions(dir, fs::perms::owner_all);
  EXPECT_EQ(slurp(dir + "/old.png"), before);
  EXPECT_EQ(leftover_temp_files(dir), 0);
}

TEST(ImageIo, UnreadableFilesAreInputErrors) {
  const std::string dir = nmbake::test::scratch_dir();
  // Missing file, a folder, text pretending to be a PNG, truncated files, an empty file.
  // (OpenImageIO 2.4 leaks 31 bytes reading the truncated PNG: LeakSanitizer needs a suppression
  // "leak:PNGInput::PngReadCallback" with ASAN_OPTIONS=fast_unwind_on_malloc=0.)
  for (const std::string ext : {".png", ".tif", ".exr"}) {
    Image noise(64, 64, 3);
    for (std::size_t i = 0; i < noise.pixels.size(); ++i) noise.pixels[i] = float((i * 7919) % 256) / 255.0f;
    nmbake::write_image(dir + "/good" + ext, noise);
    const std::string good = slurp(dir + "/good" + ext);
    spit(dir + "/truncated" + ext, good.substr(0, good.size() / 2));
  }
  spit(dir + "/text.png", "this is not a picture\n");
  spit(dir + "/empty.png", "");
  fs::create_directory(dir + "/folder.png");
  for (const std::string name :
       {"missing.png", "folder.png", "text.png", "empty.png", "truncated.png", "truncated.tif", "truncated.exr"}) {
    const std::string path = dir + "/" + name;
    try {
      nmbake::read_image(path);
      ADD_FAILURE() << name << ": no exception";
    } catch (const nmbake::InputError& e) {
      const std::string what = e.what();
      EXPECT_EQ(what.rfind(path + ": cannot read image: ", 0), 0u) << what;
      EXPECT_EQ(what.find('\n'), std::string::npos) << what;
    }
  }
}

// OpenImageIO's and OpenEXR's own thread pools follow the process's "all cores" (--threads), for
// reads and writes alike: by default both take every core of the machine, so a `--threads 1` bake
// to EXR compressed on all of them. The bytes do not depend on it.
TEST(ImageIo, TheLibrariesThreadPoolsFollowTheThreadsSetting) {
  const std::string dir = nmbake::test::scratch_dir();
  Image img(64, 40, 3);
  for (std::size_t i = 0; i < img.pixels.size(); ++i) img.pixels[i] = float(i % 97) / 97.0f;
  std::string first;
  for (const int threads : {1, 5, 2}) {
    const nmbake::AllCores cores(threads);
    const std::string path = dir + "/pools" + std::to_string(threads) + ".exr";
    nmbake::write_image(path, img, {32, {}});
    EXPECT_EQ(nmbake::image_library_threads(), std::make_pair(threads, threads)) << "write, " << threads << " threads";
    const std::string bytes = slurp(path);
    if (first.empty()) first = bytes;
    EXPECT_EQ(bytes, first) << threads << " threads";
  }
  const nmbake::AllCores three(3);
  EXPECT_EQ(nmbake::read_image(dir + "/pools5.exr").pixels, img.pixels);
  EXPECT_EQ(nmbake::image_library_threads(), std::make_pair(3, 3)) << "read";
}

// TIFF is written by tiff_write.cpp (strips compressed on every thread), read back by OpenImageIO
// (libtiff): for 1 to 4 channels (grey, grey + alpha, RGB, RGBA), 8 and 16 bits (against the PNG
// writer's values, dither included) and 32-bit float (bit for bit, NaN, infinities and -0 too), an
// image whose last strip is short and one of a single row; the same bytes on 1 and 3 threads.
TEST(ImageIo, TiffReadsBackAsWrittenForEveryLayout) {
  const std::string dir = nmbake::test::scratch_dir();
  for (const auto& [width, height] : {std::pair<int, int>{37, 70}, std::pair<int, int>{5, 1}}) {
    for (int channels = 1; channels <= 4; ++channels) {
      Image img(width, height, channels);
      for (std::size_t i = 0; i < img.pixels.size(); ++i) img.pixels[i] = float((i * 7919) % 1009) / 1008.0f;
      for (const int bits : {8, 16, 32}) {
        for (const bool dither : {false, true}) {
          if (dither && bits != 8) continue;
          const std::string what = std::to_string(width) + "x" + std::to_string(height) + "x" + std::to_string(channels) + " " +
                                   std::to_string(bits) + " bits" + (dither ? " dithered" : "");
          Image in = img;
          if (bits == 32 && in.pixels.size() >= 4) {
            in.pixels[0] = std::numeric_limits<float>::quiet_NaN();
            in.pixels[1] = std::numeric_limits<float>::infinity();
            in.pixels[2] = -0.0f;
            in.pixels[3] = -1e-40f;  // subnormal
          }
          nmbake::WriteOptions options;
          options.bits = bits;
          options.dither = dither;
          std::string bytes[2];
          for (const int threads : {1, 3}) {
            options.threads = threads;
            nmbake::write_image(dir + "/t.tif", in, options);
            bytes[threads == 3] = slurp(dir + "/t.tif");
          }
          EXPECT_EQ(bytes[0], bytes[1]) << what;
          const Image back = nmbake::read_image(dir + "/t.tif");
          ASSERT_EQ(back.width, width) << what;
          ASSERT_EQ(back.height, height) << what;
          ASSERT_EQ(back.channels, channels) << what;
          if (bits == 32) {
            for (std::size_t i = 0; i < in.pixels.size(); ++i) {
              std::uint32_t a, b;
              std::memcpy(&a, &in.pixels[i], 4);
              std::memcpy(&b, &back.pixels[i], 4);
              ASSERT_EQ(a, b) << what << ", value " << i;
            }
            continue;
          }
          nmbake::write_image(dir + "/t.png", in, options);
          EXPECT_EQ(back.pixels, nmbake::read_image(dir + "/t.png").pixels) << what;
        }
      }
    }
  }
}
