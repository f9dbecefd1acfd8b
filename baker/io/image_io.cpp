#include "io/image_io.h"

#include <algorithm>
#include <atomic>
#include <cassert>
#include <cerrno>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <ctime>
#include <filesystem>
#include <functional>
#include <limits>
#include <map>
#include <memory>
#include <new>
#include <optional>
#include <string>
#include <system_error>

#include <fcntl.h>
#include <sys/mman.h>
#include <sys/stat.h>
#include <unistd.h>

#include <OpenImageIO/filesystem.h>
#include <OpenImageIO/imageio.h>

#include "core/errors.h"

namespace nmbake {
namespace {

namespace fs = std::filesystem;

// OpenImageIO messages may span lines; our errors are printed as one line.
std::string one_line(std::string s) {
  for (char& c : s)
    if (c == '\n' || c == '\r') c = ' ';
  while (!s.empty() && s.back() == ' ') s.pop_back();
  return s.empty() ? std::string("unknown error") : s;
}

// value * scale rounded half away from zero, clamped to [0, scale]; NaN becomes 0.
// For v = value * scale >= 0, round(v) == trunc(v + 0.5) exactly: v is a float times at most
// 65535, so v + 0.5 is exact in double wherever it can reach 1. Negative and NaN values clamp to 0
// either way.
template <typename T, typename Floats>
std::vector<T> quantize(const Floats& values, double scale) {
  std::vector<T> out(values.size());
  for (std::size_t i = 0; i < values.size(); ++i) {
    double v = static_cast<double>(values[i]) * scale + 0.5;
    if (!(v > 0.0)) v = 0.0;
    if (v > scale) v = scale;
    out[i] = static_cast<T>(v);  // truncation of a value in [0, scale]
  }
  return out;
}

// A value in [0, 1) from a 64-bit key (splitmix64's finaliser): the same for a texel and channel
// whatever thread writes it.
double unit_hash(std::uint64_t key) {
  key += 0x9E3779B97F4A7C15ull;
  key = (key ^ (key >> 30)) * 0xBF58476D1CE4E5B9ull;
  key = (key ^ (key >> 27)) * 0x94D049BB133111EBull;
  key ^= key >> 31;
  return double(key >> 11) * (1.0 / 9007199254740992.0);
}

// 8-bit values with triangular noise of one step added before rounding (WriteOptions::dither):
// the sum of two uniform values in [0, 1) minus 1, seeded by the value's index, so that a gradient
// finer than a step shows no bands and the average over many texels keeps the float value.
std::vector<std::uint8_t> quantize_dithered(const Image::Pixels& values) {
  std::vector<std::uint8_t> out(values.size());
  for (std::size_t i = 0; i < values.size(); ++i) {
    const double noise = unit_hash(2 * std::uint64_t(i)) + unit_hash(2 * std::uint64_t(i) + 1) - 1.0;
    double v = static_cast<double>(values[i]) * 255.0 + 0.5 + noise;
    if (!(v > 0.0)) v = 0.0;
    if (v > 255.0) v = 255.0;
    out[i] = static_cast<std::uint8_t>(v);
  }
  return out;
}

// A temporary beside `target` for write_image without WriteOptions::temp_path (nmdiff, the tests).
std::string temp_path_for(const fs::path& target) {
  static std::atomic<unsigned> counter{0};
  std::string name = "." + target.filename().string() + ".tmp-" + std::to_string(::getpid()) + "-" + std::to_string(counter++) +
                     target.extension().string();
  return (target.parent_path() / name).string();
}

// The encoders' bytes go through this proxy straight to a file descriptor, so that the first
// system error (ENOSPC, EIO) is known exactly: through stdio, OpenImageIO's PNG writer only says
// "Write error at position N" once per failed call (a 29 KB message on a full disk). Small writes
// (libpng writes chunk headers of 4-13 bytes) are gathered in a buffer.
class FileProxy final : public OIIO::Filesystem::IOProxy {
 public:
  FileProxy(const std::string& name, int fd) : IOProxy(name, Write), fd_(fd) { buffer_.reserve(kBuffer); }
  const char* proxytype() const override { return "nmbake-file"; }
  void close() override { flush_buffer(); }
  void flush() const override { const_cast<FileProxy*>(this)->flush_buffer(); }
  bool seek(int64_t offset) override {
    if (!flush_buffer() || offset < 0) return false;
    m_pos = offset;
    return true;
  }
  size_t write(const void* data, size_t size) override {
    if (error_) return 0;
    if (buffer_.size() + size > kBuffer && !flush_buffer()) return 0;
    if (size >= kBuffer) {
      const size_t n = put(data, size, m_pos);
      m_pos += int64_t(n);
      return n;
    }
    if (buffer_.empty()) start_ = m_pos;
    buffer_.insert(buffer_.end(), static_cast<const char*>(data), static_cast<const char*>(data) + size);
    m_pos += int64_t(size);
    return size;
  }
  size_t pwrite(const void* data, size_t size, int64_t offset) override { return flush_buffer() ? put(data, size, offset) : 0; }
  size_t read(void* data, size_t size) override {
    const size_t n = pread(data, size, m_pos);
    m_pos += int64_t(n);
    return n;
  }
  size_t pread(void* data, size_t size, int64_t offset) override {
    if (!flush_buffer()) return 0;
    const ssize_t n = ::pread(fd_, data, size, offset);
    return n > 0 ? size_t(n) : 0;
  }
  size_t size() const override {
    const_cast<FileProxy*>(this)->flush_buffer();
    struct stat st {};
    return ::fstat(fd_, &st) == 0 ? size_t(st.st_size) : 0;
  }
  bool flush_buffer() {
    if (buffer_.empty()) return error_ == 0;
    const size_t n = put(buffer_.data(), buffer_.size(), start_);
    const bool ok = n == buffer_.size();
    buffer_.clear();
    return ok;
  }
  int failure() const { return error_; }  // the first errno of a failed write, or 0

 private:
  static constexpr size_t kBuffer = 1 << 16;
  size_t put(const void* data, size_t size, int64_t offset) {
    size_t done = 0;
    while (done < size && !error_) {
      const ssize_t n = ::pwrite(fd_, static_cast<const char*>(data) + done, size - done, offset + int64_t(done));
      if (n < 0 && errno == EINTR) continue;
      if (n <= 0) error_ = n < 0 ? errno : EIO;
      else done += size_t(n);
    }
    return done;
  }
  int fd_;
  int error_ = 0;
  int64_t start_ = 0;  // the file position of buffer_[0]
  std::vector<char> buffer_;
};

// The first message of an OpenImageIO error (it repeats one per failed call), on one line.
std::string first_message(const std::string& text) {
  const std::size_t start = text.find_first_not_of("\r\n");
  std::string s = one_line(start == std::string::npos ? text : text.substr(start, text.find_first_of("\r\n", start) - start));
  const std::size_t repeat = s.find("  ");
  if (repeat != std::string::npos) s.resize(repeat);
  if (s.size() > 240) s = s.substr(0, 240) + "...";
  return s;
}

// The EXR and TIFF writers stamp the current time into "DateTime", so two identical bakes differ
// in a few bytes. With SOURCE_DATE_EPOCH set (seconds since 1970, the reproducible-builds
// convention) that time is used instead and identical bakes give identical files.
std::string reproducible_date_time() {
  const char* epoch = std::getenv("SOURCE_DATE_EPOCH");
  if (!epoch || !*epoch) return "";
  char* end = nullptr;
  const long long seconds = std::strtoll(epoch, &end, 10);
  if (*end != '\0' || seconds < 0) return "";
  const std::time_t t = static_cast<std::time_t>(seconds);
  std::tm utc{};
  if (!gmtime_r(&t, &utc)) return "";
  char text[32];
  std::strftime(text, sizeof text, "%Y:%m:%d %H:%M:%S", &utc);
  return text;
}

// A reason that is memory running out (libpng's "insufficient memory", ENOMEM): exit 4, not 3.
bool memory_reason(const std::string& reason) {
  return reason.find("insufficient memory") != std::string::npos || reason.find("out of memory") != std::string::npos ||
         reason.find("Out of memory") != std::string::npos || reason == std::strerror(ENOMEM);
}

[[noreturn]] void fail_write(const std::string& path, const std::string& reason) {
  if (memory_reason(reason)) throw ResourceError(path + ": cannot write: out of memory (" + reason + ")");
  throw OutputError(path + ": cannot write: " + reason);
}

// libpng prints its errors on stderr itself ("libpng error: insufficient memory", "libpng error:
// No IDATs written into file") besides the message OpenImageIO returns, which makes one error
// three lines. While an encoder runs, stderr goes to a memory file; afterwards its lines go on to
// stderr, libpng's left out. Without a memory file or a spare descriptor, nothing is redirected.
class EncoderStderr {
 public:
  EncoderStderr() {
    std::fflush(stderr);
    memory_ = ::memfd_create("nmbake-encoder-stderr", MFD_CLOEXEC);
    if (memory_ < 0) return;
    saved_ = ::fcntl(2, F_DUPFD_CLOEXEC, 3);
    if (saved_ < 0 || ::dup2(memory_, 2) < 0) restore();
  }
  ~EncoderStderr() { restore(); }
  EncoderStderr(const EncoderStderr&) = delete;
  EncoderStderr& operator=(const EncoderStderr&) = delete;

 private:
  void restore() {
    std::fflush(stderr);
    if (saved_ >= 0) {
      ::dup2(saved_, 2);
      ::close(saved_);
      saved_ = -1;
      pass_on();
    }
    if (memory_ >= 0) ::close(memory_);
    memory_ = -1;
  }
  void pass_on() const {
    std::string text;
    char buf[4096];
    for (ssize_t n; (n = ::pread(memory_, buf, sizeof buf, off_t(text.size()))) > 0;) text.append(buf, std::size_t(n));
    for (std::size_t start = 0; start < text.size();) {
      std::size_t end = text.find('\n', start);
      end = end == std::string::npos ? text.size() : end + 1;
      if (text.compare(start, 7, "libpng ") != 0)
        if (::write(2, text.data() + start, end - start) < 0) return;
      start = end;
    }
  }
  int memory_ = -1;
  int saved_ = -1;
};

// The header written: size, stored type, metadata, and the encoder's settings for `ext`.
OIIO::ImageSpec output_spec(const Image& image, OIIO::TypeDesc stored, const std::string& ext, const WriteOptions& options) {
  OIIO::ImageSpec spec(image.width, image.height, image.channels, stored);
  // Alpha is coverage, not premultiplication: keep colour values exactly as given.
  spec.attribute("oiio:UnassociatedAlpha", 1);
  for (const auto& [key, value] : options.metadata) spec.attribute(key, value);
  if (const std::string date = reproducible_date_time(); !date.empty() && spec.get_string_attribute("DateTime").empty())
    spec.attribute("DateTime", date);
  // Measured on a 2048^2 map: PNG at zlib level 6 took 3.3 s, level 1 0.6 s (file ~10% larger);
  // EXR zip shrank float normals by 1% in 2.3 s, uncompressed takes 0.1 s. With level 1, libpng's
  // adaptive filter choice costs about a third of the write: the "up" filter alone (0x20) wrote
  // the torus_s3 map in 0.18-0.27 s instead of 0.31-0.37 s, and 2% smaller (4.97 MB, not 5.08).
  if (ext == ".png") {
    spec.attribute("png:compressionLevel", 1);
    spec.attribute("png:filter", 0x20);
  }
  // EXR: ZIP (lossless) unless WriteOptions::compression says otherwise.
  if (ext == ".exr") spec.attribute("compression", options.compression.empty() ? "zip" : options.compression);
  // The TIFF writer drops attributes it does not know; keep them readable (and parsable by
  // read_image_metadata) as "key=value" items after any given description in the description tag.
  if (ext == ".tif" || ext == ".tiff") {
    std::string description = spec.get_string_attribute("ImageDescription");
    for (const auto& [key, value] : options.metadata)
      if (key != "ImageDescription") description += (description.empty() ? "" : "; ") + key + "=" + value;
    if (!description.empty()) spec.attribute("ImageDescription", description);
  }
  return spec;
}

}  // namespace

void write_image(const std::string& path, const Image& image, const WriteOptions& options) {
  const int bits = options.bits ? options.bits : default_bits_for(path);
  check_output_format(path, bits);
  assert(image.pixels.size() == static_cast<std::size_t>(image.width) * image.height * image.channels);
  if (image.width <= 0 || image.height <= 0 || image.channels <= 0)
    fail_write(path, "empty image (" + std::to_string(image.width) + "x" + std::to_string(image.height) + "x" +
                         std::to_string(image.channels) + ")");

  // Check the folder first: OpenImageIO would only name the temporary file.
  const fs::path target(path);
  const fs::path folder = target.parent_path().empty() ? fs::path(".") : target.parent_path();
  std::error_code ec;
  if (!fs::is_directory(folder, ec)) fail_write(path, "folder '" + folder.string() + "' does not exist");
  if (::access(folder.c_str(), W_OK) != 0)
    fail_write(path, "folder '" + folder.string() + "' is not writable (" + std::strerror(errno) + ")");

  // Pixels in the stored type: integer formats are quantized here, float goes through as is
  // (OpenImageIO converts float to half for EXR 16).
  const std::string ext = image_io_detail::lower_extension(path);
  OIIO::TypeDesc stored = OIIO::TypeDesc::FLOAT;
  OIIO::TypeDesc given = OIIO::TypeDesc::FLOAT;
  std::vector<std::uint8_t> data8;
  std::vector<std::uint16_t> data16;
  const void* data = image.pixels.data();
  if (bits == 8) {
    data8 = options.dither ? quantize_dithered(image.pixels) : quantize<std::uint8_t>(image.pixels, 255.0);
    stored = given = OIIO::TypeDesc::UINT8;
    data = data8.data();
  } else if (bits == 16 && ext != ".exr") {
    data16 = quantize<std::uint16_t>(image.pixels, 65535.0);
    stored = given = OIIO::TypeDesc::UINT16;
    data = data16.data();
  } else if (bits == 16) {
    stored = OIIO::TypeDesc::HALF;
  }

  const OIIO::ImageSpec spec = output_spec(image, stored, ext, options);

  // Create with the real path so the writer is chosen by its extension.
  auto out = OIIO::ImageOutput::create(path);
  if (!out) fail_write(path, first_message(OIIO::geterror()));

  const std::string temp = options.temp_path.empty() ? temp_path_for(target) : options.temp_path;
  const int fd = ::open(temp.c_str(), O_RDWR | O_CREAT | O_TRUNC | O_NOFOLLOW | O_CLOEXEC, 0666);
  if (fd < 0) fail_write(path, std::strerror(errno));
  // Whatever ends the write early (an error, std::bad_alloc from the encoder or the proxy's buffer)
  // closes the encoder before the proxy it writes to, and removes the temporary. The proxy is
  // declared before the guard, so it is destroyed after it.
  std::optional<FileProxy> made;
  bool open = true, kept = false;
  auto abandon = [&] {
    out.reset();
    if (open) ::close(fd);
    open = false;
    if (!kept) ::unlink(temp.c_str());
    kept = true;
  };
  struct OnExit {
    const std::function<void()> run;
    ~OnExit() { run(); }
  } on_exit{abandon};
  made.emplace(temp, fd);  // its buffer allocated here, not while libpng's C code calls it
  FileProxy& proxy = *made;
  // The first failure's reason: the system's for a failed write, else OpenImageIO's.
  auto discard = [&](const std::string& message, int err) {
    if (!err) err = proxy.failure();
    abandon();
    fail_write(path, err ? std::string(std::strerror(err)) : first_message(message));
  };
  out->set_ioproxy(&proxy);
  std::optional<EncoderStderr> quiet(std::in_place);
  if (!out->open(temp, spec)) discard(out->geterror(), 0);
  if (!out->write_image(given, data) || out->has_error() || proxy.failure()) {
    std::string reason = out->geterror();
    out->close();
    discard(reason, 0);
  }
  // Only close()'s result counts: with Debian 12's libtiff every TIFF close records a harmless
  // "failed TIFFWriteCustomDirectory() of the Exif data" and still writes a good file.
  if (!out->close() || !proxy.flush_buffer()) discard(out->geterror(), 0);
  out->geterror();  // drop that message
  out.reset();
  quiet.reset();
  // A full disk or a failing device may only show here (delayed allocation, NFS).
  if (::fsync(fd) != 0) discard("", errno);
  open = false;
  if (::close(fd) != 0) discard("", errno);
  if (!options.temp_path.empty()) {
    kept = true;  // the caller renames it
    return;
  }
  if (std::rename(temp.c_str(), path.c_str()) != 0) {
    std::string reason = std::strerror(errno);
    if (fs::is_directory(target, ec)) reason = "a folder of that name exists";
    abandon();
    fail_write(path, reason);
  }
  kept = true;
}

// read_image and read_image_metadata: image_read.cpp.

void preload_image_io() {}  // linked directly: nothing to load
void wait_for_image_io() {}
std::string image_io_problem() { return {}; }

}  // namespace nmbake
