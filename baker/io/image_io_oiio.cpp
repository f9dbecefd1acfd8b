// write_image (image_io.h) for every format but PNG and TIFF (tiff_write.h), through OpenImageIO: the writing half of
// libnmbake-oiio.so (oiio_module.h).
#include "io/oiio_module.h"

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
#include <sys/stat.h>
#include <unistd.h>

#include <OpenImageIO/filesystem.h>
#include <OpenImageIO/imageio.h>

#include "core/errors.h"
#include "io/image_write.h"

namespace nmbake {
namespace {

using image_write::fail_write;

namespace fs = std::filesystem;

// The encoders' bytes go through this proxy straight to a file descriptor, so that the first
// system error (ENOSPC, EIO) is known exactly, not as OpenImageIO's "Write error at position N"
// once per failed call. Small writes are gathered in a buffer.
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
  std::string s = start == std::string::npos ? "" : text.substr(start, text.find_first_of("\r\n", start) - start);
  s.resize(std::min(s.size(), s.find("  ")));  // where the message starts again
  s = one_line(s, 243);
  return s.empty() ? "unknown error" : s;
}

// The header written: size, stored type, metadata, and the encoder's settings for `ext`.
OIIO::ImageSpec output_spec(const Image& image, OIIO::TypeDesc stored, const std::string& ext, const WriteOptions& options) {
  OIIO::ImageSpec spec(image.width, image.height, image.channels, stored);
  // Alpha is coverage, not premultiplication: keep colour values exactly as given.
  spec.attribute("oiio:UnassociatedAlpha", 1);
  for (const auto& [key, value] : options.metadata) spec.attribute(key, value);
  if (const std::string date = image_write::reproducible_date_time();
      !date.empty() && spec.get_string_attribute("DateTime").empty())
    spec.attribute("DateTime", date);
  // EXR: ZIP (lossless) unless WriteOptions::compression says otherwise.
  if (ext == ".exr") spec.attribute("compression", options.compression.empty() ? "zip" : options.compression);
  // The TIFF writer drops attributes it does not know; keep them readable (and parsable by
  // read_image_metadata) as "key=value" items after any given description in the description tag.
  if (image_io_detail::is_tiff(ext)) {
    const std::string description = image_write::tiff_description(options.metadata);
    if (!description.empty()) spec.attribute("ImageDescription", description);
  }
  return spec;
}

}  // namespace

void oiio_module::write(const std::string& path, const Image& image, const WriteOptions& options, int bits) {
  const std::string ext = image_io_detail::lower_extension(path);
  const fs::path target(path);
  std::error_code ec;

  // Pixels in the stored type: integer formats are quantized here, float goes through as is
  // (OpenImageIO converts float to half for EXR 16).
  OIIO::TypeDesc stored = OIIO::TypeDesc::FLOAT;
  OIIO::TypeDesc given = OIIO::TypeDesc::FLOAT;
  image_write::Samples<std::uint8_t> data8;
  image_write::Samples<std::uint16_t> data16;
  const void* data = image.pixels.data();
  if (bits == 8) {
    data8 = image_write::quantize8(image.pixels, options.dither, options.threads);
    stored = given = OIIO::TypeDesc::UINT8;
    data = data8.data();
  } else if (bits == 16 && ext != ".exr") {
    data16 = image_write::quantize16(image.pixels, options.threads);
    stored = given = OIIO::TypeDesc::UINT16;
    data = data16.data();
  } else if (bits == 16) {
    stored = OIIO::TypeDesc::HALF;
  }

  const OIIO::ImageSpec spec = output_spec(image, stored, ext, options);

  // Create with the real path so the writer is chosen by its extension.
  auto out = OIIO::ImageOutput::create(path);
  if (!out) fail_write(path, first_message(OIIO::geterror()));

  const std::string temp = options.temp_path.empty() ? image_write::temp_path_for(path) : options.temp_path;
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
  made.emplace(temp, fd);  // its buffer allocated here, not while an encoder's C code calls it
  FileProxy& proxy = *made;
  // The first failure's reason: the system's for a failed write, else OpenImageIO's.
  auto discard = [&](const std::string& message, int err) {
    if (!err) err = proxy.failure();
    abandon();
    fail_write(path, err ? std::string(std::strerror(err)) : first_message(message));
  };
  out->set_ioproxy(&proxy);
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

}  // namespace nmbake
