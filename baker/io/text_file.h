// Text inputs read whole (jobs files, batch reports), and text outputs (reports, JSON, cages) written like the maps: to a
// temporary file, renamed into place only when complete, so a failed write never leaves a partial file or loses the old one.
#pragma once

#include <cstddef>
#include <string>
#include <vector>

namespace nmbake {

// Writes `text` to the file `temp` (created, or emptied; never through a symbolic link) and flushes
// it to disk (fsync); the caller renames it to `path` when every output is complete. Errors name
// `path`: OutputError "<path>: cannot write: <reason>", the temporary removed.
void write_text_file(const std::string& path, const std::string& temp, const std::string& text);

// The same for `size` bytes at `data` (the image writers' encoded files).
void write_bytes_file(const std::string& path, const std::string& temp, const void* data, std::size_t size);

// Bytes in several places, written in order as one file.
struct ByteSpan {
  const void* data;
  std::size_t size;
};

// The same for the spans' bytes one after another (a file encoded in parts, written without
// joining them into one buffer first).
void write_spans_file(const std::string& path, const std::string& temp, const std::vector<ByteSpan>& spans);

// write_text_file to a temporary file beside `path`, then renamed over it. Throws OutputError
// "<path>: cannot write: <reason>" (the temporary removed).
void write_text_atomically(const std::string& path, const std::string& text);

// The whole file at `path`, as bytes. Throws InputError "<path>: cannot read[: <reason>]".
std::string read_text_file(const std::string& path);

}  // namespace nmbake
