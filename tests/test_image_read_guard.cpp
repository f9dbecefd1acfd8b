// Known answers of the checks read_image makes before allocating (io/image_read_guard.h): the
// compression bounds, the message for a header larger than its file, the memory budget, and which
// paths count as regular files.
#include <sys/stat.h>
#include <unistd.h>

#include <cstdint>
#include <fstream>
#include <limits>
#include <string>

#include <gtest/gtest.h>

#include "core/errors.h"
#include "core/memory_budget.h"
#include "io/image_io.h"
#include "io/image_read_guard.h"
#include "test_support.h"

namespace nmbake {
namespace {

constexpr std::uint64_t kNoBudget = std::numeric_limits<std::uint64_t>::max();

ImageHeader header(std::int64_t w, std::int64_t h, const std::string& format, const std::string& compression = "",
                   int channels = 3, int bits = 8) {
  ImageHeader hd;
  hd.width = w;
  hd.height = h;
  hd.channels = channels;
  hd.bits_per_sample = bits;
  hd.format = format;
  hd.compression = compression;
  hd.palette = format == "png" || format == "tiff";
  return hd;
}

std::string message_of(const std::string& path, const ImageHeader& h, std::uint64_t file_size, std::uint64_t budget) {
  try {
    check_image_header(path, h, file_size, budget);
  } catch (const ResourceError& e) {
    return e.what();
  }
  return "";
}

TEST(ImageReadGuard, CompressionBounds) {
  EXPECT_EQ(max_pixel_bytes_per_file_byte(header(1, 1, "png")), 1032.0);
  EXPECT_EQ(max_pixel_bytes_per_file_byte(header(1, 1, "openexr", "none")), 1.0);
  EXPECT_EQ(max_pixel_bytes_per_file_byte(header(1, 1, "openexr", "rle")), 64.0);
  EXPECT_EQ(max_pixel_bytes_per_file_byte(header(1, 1, "openexr", "zip")), 1032.0);
  EXPECT_EQ(max_pixel_bytes_per_file_byte(header(1, 1, "openexr", "piz")), 1032.0);
  EXPECT_EQ(max_pixel_bytes_per_file_byte(header(1, 1, "openexr", "dwab")), 64.0 * 1032.0);
  EXPECT_EQ(max_pixel_bytes_per_file_byte(header(1, 1, "tiff", "none")), 1.0);
  EXPECT_NEAR(max_pixel_bytes_per_file_byte(header(1, 1, "tiff", "lzw")), 4096.0 * 8 / 9, 1e-9);
  EXPECT_EQ(max_pixel_bytes_per_file_byte(header(1, 1, "tiff", "zstd")), 0.0);  // no sound bound
  EXPECT_EQ(max_pixel_bytes_per_file_byte(header(1, 1, "jpeg")), 0.0);
}

TEST(ImageReadGuard, HeaderLargerThanItsFile) {
  EXPECT_EQ(message_of("big.png", header(20000, 20000, "png"), 812, kNoBudget),
            "big.png: header says 20000x20000 pixels (4.8 GB) but the file has 812 bytes");
  // An uncompressed EXR must hold every byte: 2048^2 RGB half is 25.2 MB.
  EXPECT_NE(message_of("a.exr", header(2048, 2048, "openexr", "none", 3, 16), 10000000, kNoBudget), "");
  EXPECT_EQ(message_of("a.exr", header(2048, 2048, "openexr", "none", 3, 16), 25200000, kNoBudget), "");
}

TEST(ImageReadGuard, CompressibleImagesPass) {
  // A flat 16384^2 8-bit PNG deflates to a few hundred kB; 1-bit and palette images pack 8x and 3x
  // tighter than RGB and must pass too.
  EXPECT_EQ(message_of("flat.png", header(16384, 16384, "png"), 300000, kNoBudget), "");
  EXPECT_EQ(message_of("bits.png", header(16384, 16384, "png", "", 1, 1), 40000, kNoBudget), "");
  // Unknown bounds (JPEG) leave only the budget.
  EXPECT_EQ(message_of("a.jpg", header(20000, 20000, "jpeg"), 812, kNoBudget), "");
}

TEST(ImageReadGuard, MemoryBudget) {
  const ImageHeader h = header(16384, 16384, "png");
  EXPECT_EQ(image_read_bytes(h), std::uint64_t(16384) * 16384 * 3 * 5);  // floats and 8-bit samples
  EXPECT_EQ(message_of("m.png", h, 1000000, 1000000000),
            "m.png: header says 16384x16384 pixels (3.2 GB; 4.0 GB to read), which exceeds the memory budget of 1.0 GB "
            "(available memory, ulimit -v)");
  EXPECT_EQ(message_of("m.png", h, 1000000, image_read_bytes(h)), "");
  EXPECT_GT(memory_budget_bytes(), 0u);
}

std::string input_error(const std::string& path) {
  try {
    regular_file_size(path);
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

TEST(ImageReadGuard, OnlyRegularFiles) {
  const std::string dir = test::scratch_dir();
  ASSERT_EQ(::mkfifo((dir + "/fifo.png").c_str(), 0600), 0);
  EXPECT_EQ(input_error(dir + "/fifo.png"), dir + "/fifo.png: not a regular file (a FIFO)");
  EXPECT_EQ(input_error("/dev/zero"), "/dev/zero: not a regular file (a character device)");
  EXPECT_EQ(input_error(dir), dir + ": cannot read image: it is a folder");
  EXPECT_EQ(input_error(dir + "/none.png"), dir + "/none.png: cannot read image: no such file");
  std::ofstream(dir + "/real.png") << "12345";
  ASSERT_EQ(::symlink("real.png", (dir + "/link.png").c_str()), 0);
  EXPECT_EQ(regular_file_size(dir + "/link.png"), 5u);
  ASSERT_EQ(::symlink("fifo.png", (dir + "/fifo_link.png").c_str()), 0);
  EXPECT_EQ(input_error(dir + "/fifo_link.png"), dir + "/fifo_link.png: not a regular file (a FIFO)");
  // read_image and read_image_metadata check first: neither blocks on the FIFO.
  EXPECT_THROW(read_image(dir + "/fifo.png"), InputError);
  EXPECT_THROW(read_image_metadata(dir + "/fifo.png"), InputError);
}

}  // namespace
}  // namespace nmbake
