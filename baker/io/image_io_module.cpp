// libnmbake_oiio.so: image_io.cpp (OpenImageIO) behind the C entry point of image_io_module.h.
#include "io/image_io_module.h"

#include <exception>
#include <new>

#include "core/errors.h"

namespace nmbake {
namespace {

template <typename Fn>
int guarded(std::string* error, Fn&& fn) {
  try {
    fn();
    return 0;
  } catch (const Error& e) {
    *error = e.what();
    return int(e.code());
  } catch (const std::bad_alloc&) {
    *error = "out of memory";
    return int(ExitCode::memory);
  } catch (const std::exception& e) {
    *error = e.what();
    return int(ExitCode::output);
  }
}

const ImageIoModule kModule = {
    kImageIoModuleVersion,
    [](const std::string& path, const Image& image, const WriteOptions& options, std::string* error) {
      return guarded(error, [&] { write_image(path, image, options); });
    },
    [](const std::string& path, Image* image, std::string* error) { return guarded(error, [&] { *image = read_image(path); }); },
    [](const std::string& path, std::map<std::string, std::string>* metadata, std::string* error) {
      return guarded(error, [&] { *metadata = read_image_metadata(path); });
    },
};

}  // namespace
}  // namespace nmbake

extern "C" __attribute__((visibility("default"))) const nmbake::ImageIoModule* nmbake_image_io_module() {
  return &nmbake::kModule;
}
