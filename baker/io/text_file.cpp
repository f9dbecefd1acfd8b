#include "io/text_file.h"

#include <fcntl.h>
#include <sys/uio.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstdio>
#include <cstring>
#include <filesystem>

#include "core/errors.h"

namespace nmbake {

void write_text_file(const std::string& path, const std::string& temp, const std::string& text) {
  write_bytes_file(path, temp, text.data(), text.size());
}

void write_bytes_file(const std::string& path, const std::string& temp, const void* data, std::size_t size) {
  write_spans_file(path, temp, {ByteSpan{data, size}});
}

void write_spans_file(const std::string& path, const std::string& temp, const std::vector<ByteSpan>& spans) {
  auto fail = [&](int err) {
    ::unlink(temp.c_str());
    throw OutputError(path + ": cannot write: " + std::strerror(err));
  };
  const int fd = ::open(temp.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_NOFOLLOW | O_CLOEXEC, 0666);
  if (fd < 0) throw OutputError(path + ": cannot write: " + std::strerror(errno));
  // From span `next`, `skip` bytes in: the rest, up to kMaxSpans spans a call (writev's limit is at
  // least 1024), until every byte is written.
  constexpr std::size_t kMaxSpans = 1024;
  std::size_t next = 0, skip = 0;
  iovec io[kMaxSpans];
  while (true) {
    while (next < spans.size() && skip == spans[next].size) ++next, skip = 0;
    if (next == spans.size()) break;
    int count = 0;
    for (std::size_t i = next; i < spans.size() && std::size_t(count) < kMaxSpans; ++i) {
      const std::size_t from = i == next ? skip : 0;
      if (from == spans[i].size) continue;
      io[count].iov_base = const_cast<char*>(static_cast<const char*>(spans[i].data) + from);
      io[count].iov_len = spans[i].size - from;
      ++count;
    }
    const ssize_t n = ::writev(fd, io, count);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) {
      const int err = n < 0 ? errno : EIO;
      ::close(fd);
      fail(err);
    }
    for (std::size_t left = std::size_t(n); left > 0;) {  // past what was written
      const std::size_t step = std::min(left, spans[next].size - skip);
      skip += step;
      left -= step;
      if (skip == spans[next].size) ++next, skip = 0;
    }
  }
  // A full disk or a failing device may only show here, on some filesystems (NFS) only at close.
  if (::fsync(fd) != 0) {
    const int err = errno;
    ::close(fd);
    fail(err);
  }
  if (::close(fd) != 0) fail(errno);
}

void write_text_atomically(const std::string& path, const std::string& text) {
  const std::filesystem::path target(path);
  const std::string temp =
      (target.parent_path() / ("." + target.filename().string() + ".nmbake-tmp." + std::to_string(::getpid()))).string();
  write_text_file(path, temp, text);
  if (std::rename(temp.c_str(), path.c_str()) != 0) {
    const int err = errno;
    ::unlink(temp.c_str());
    throw OutputError(path + ": cannot write: " + std::strerror(err));
  }
}

std::string read_text_file(const std::string& path) {
  std::FILE* f = std::fopen(path.c_str(), "rb");
  if (!f) throw InputError(path + ": cannot read: " + std::strerror(errno));
  std::string text;
  char buf[65536];
  for (std::size_t n; (n = std::fread(buf, 1, sizeof buf, f)) > 0;) text.append(buf, n);
  const bool failed = std::ferror(f) != 0;
  std::fclose(f);
  if (failed) throw InputError(path + ": cannot read");
  return text;
}

}  // namespace nmbake
