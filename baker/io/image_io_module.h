// The interface between the nmbake command and its image-library module (libnmbake_oiio.so), which
// holds image_io.cpp and so OpenImageIO. Errors do not cross the boundary as exceptions: each call
// returns 0 or the ExitCode of the error it caught, with its message.
#pragma once

#include <map>
#include <string>

#include "core/image.h"
#include "io/image_io.h"

namespace nmbake {

struct ImageIoModule {
  int version;  // kImageIoModuleVersion of the module's build
  int (*write)(const std::string& path, const Image& image, const WriteOptions& options, std::string* error);
  int (*read)(const std::string& path, Image* image, std::string* error);
  int (*read_metadata)(const std::string& path, std::map<std::string, std::string>* metadata, std::string* error);
};

constexpr int kImageIoModuleVersion = 3;

}  // namespace nmbake

// The module's one exported symbol.
extern "C" const nmbake::ImageIoModule* nmbake_image_io_module();
