// libnmbake_oiio.so: image_io.cpp (OpenImageIO) behind the C entry point of image_io_module.h.
#include "io/image_io_module.h"

#include <exception>
#include <new>
#include <string>

#include "core/errors.h"

namespace nmbake {
namespace {

// Errors of image_io.cpp name the file themselves; others get "<path>: cannot <doing>: ".
template <typename Fn>
int guarded(std::string* error, const std::string& path, const char* doing, Fn&& fn) {
  try {
    fn();
    return 0;
  } catch (const Error& e) {
    *error = e.what();
    return int(e.code());
  } catch (const std::bad_alloc&) {
    *error = path + ": cannot " + doing + ": out of memory";
    return int(ExitCode::memory);
  } catch (const std::exception& e) {
    *error = path + ": cannot " + doing + ": " + e.what();
    return int(ExitCode::output);
  }
}

const ImageIoModule kModule = {
    kImageIoModuleVersion,
    [](const std::string& path, const Image& image, const WriteOptions& options, std::string* error) {
      return guarded(error, path, "write", [&] { write_image(path, image, options); });
    },
    [](const std::string& path, Image* image, std::string* error) {
      return guarded(error, path, "read image", [&] { *image = read_image(path); });
    },
    [](const std::string& path, std::map<std::string, std::string>* metadata, std::string* error) {
      return guarded(error, path, "read image", [&] { *metadata = read_image_metadata(path); });
    },
};

}  // namespace
}  // namespace nmbake

extern "C" __attribute__((visibility("default"))) const nmbake::ImageIoModule* nmbake_image_io_module() {
  return &nmbake::kModule;
}
