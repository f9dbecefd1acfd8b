// OpenImageIO in a module of its own, loaded the first time a process needs it. Internal to io/.
//
// OpenImageIO brings ~260 shared libraries (OpenVDB, GDAL, DCMTK, FFmpeg, ...): linked into a
// program, the dynamic loader maps and relocates all of them before main(), 0.3-0.4 s of one core
// on every start, serial work that no thread count shortens (issue 38). nmbake writes PNG without
// it (png_write.h) and reads no image, so the programs do not link it: image_io.h's reading, and
// its writing of every other format, live in libnmbake-oiio.so (image_io_oiio.cpp,
// image_read.cpp, oiio_module.cpp), which image_io.cpp loads with dlopen on first use and keeps
// until exit. A bake to PNG never loads it; one to EXR, TIFF or TGA loads it once, when it first
// writes one (or earlier, beside the bake, when the command calls preload()).
//
// The module is built from this tree with the same compiler and headers as the program that
// loads it, so the calls pass C++ objects by reference. It links its own static copy of the code
// it uses (errors, quantization, the read guard), hidden: an error crosses as a Failure (exit code
// and message), never as an exception, and the process's "all cores" setting (core/parallel.h)
// is handed over with each call.
#pragma once

#include <cstddef>
#include <cstdint>
#include <map>
#include <string>

#include "core/errors.h"
#include "core/image.h"
#include "io/image_io.h"

namespace nmbake::oiio_module {

// The module's file name.
inline constexpr const char* kFileName = "libnmbake-oiio.so";

// Raised when the calls below change their signature or meaning, so that a module of another
// build is refused rather than called.
inline constexpr int kAbi = 3;

// An error a call ended with: the ExitCode of the nmbake::Error it stands for (0: none) and its
// message (one line, naming the file).
struct Failure {
  int code = 0;
  std::string message;
};

// What the module hands the loader (nmbake_oiio_module_api below).
struct Api {
  int abi;
  std::size_t image_size, options_size;  // sizeof(Image), sizeof(WriteOptions) in the module's build
  // write_image for a format other than PNG and TIFF (and a TIFF past 4 GiB): `image` has no palette and passed check_write,
  // which gave `bits`. `all_cores` is the loader's all_cores_setting().
  void (*write)(const std::string& path, const Image& image, const WriteOptions& options, int bits, int all_cores,
                Failure* failure);
  void (*read)(const std::string& path, std::uint64_t file_size, int all_cores, Image* image, Failure* failure);  // read_image
  void (*read_metadata)(const std::string& path, std::map<std::string, std::string>* out,
                        Failure* failure);  // read_image_metadata
  // The thread counts OpenImageIO's pool and OpenEXR's are set to now (image_library_threads).
  void (*library_threads)(int* openimageio, int* openexr);
};

// The three calls as the module implements them (image_io_oiio.cpp, image_read.cpp); they throw
// nmbake::Error as image_io.h documents.
void write(const std::string& path, const Image& image, const WriteOptions& options, int bits);
// The reads take a path the loader found a regular file (regular_file_size, image_read_guard.h), of
// `file_size` bytes.
Image read(const std::string& path, std::uint64_t file_size);
std::map<std::string, std::string> read_metadata(const std::string& path);

// The loader's side (image_io.cpp). The module is looked for beside the program or library that
// holds this code, then in NMBAKE_OIIO_MODULE_DIR relative to it (an installed bin/nmbake finds
// lib/.../nmbake/), then where the build tree made it. Throws an Error of `kind` naming `path`
// ("out.exr: cannot write: libnmbake-oiio.so not found (looked in ...)") when it cannot be loaded.
const Api& api(const std::string& path, ExitCode kind);

// Starts loading the module on a thread of its own and returns at once; api() waits for it. For a
// command that knows it will write a format other than PNG: the 0.3 s of loading then runs beside
// the bake. A failure is kept for api() to report.
void preload();

}  // namespace nmbake::oiio_module

extern "C" const nmbake::oiio_module::Api* nmbake_oiio_module_api();
