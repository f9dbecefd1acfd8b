// image_io.h's calls: PNG written here (png_write.h), everything else handed to OpenImageIO's
// module, loaded on first use (oiio_module.h).
#include "io/image_io.h"

#include <dlfcn.h>
#include <link.h>
#include <unistd.h>

#include <cstdint>
#include <filesystem>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

#include "core/errors.h"
#include "core/parallel.h"
#include "io/image_read_guard.h"
#include "io/image_write.h"
#include "io/oiio_module.h"
#include "io/png_write.h"
#include "io/tiff_write.h"

namespace nmbake {
namespace {

namespace fs = std::filesystem;

// The file of the program or shared library that holds this code: the Python module's own path
// when it is the Python module, /proc/self/exe's target for the program (whose name in the
// loader's list is empty).
std::string own_file() {
  struct Find {
    std::uintptr_t address = 0;
    bool found = false;
    std::string name;
  } find;
  find.address = reinterpret_cast<std::uintptr_t>(&own_file);
  dl_iterate_phdr(
      [](dl_phdr_info* info, std::size_t, void* data) {
        auto* f = static_cast<Find*>(data);
        for (int i = 0; i < info->dlpi_phnum; ++i) {
          const ElfW(Phdr)& ph = info->dlpi_phdr[i];
          const std::uintptr_t begin = info->dlpi_addr + ph.p_vaddr;
          if (ph.p_type == PT_LOAD && f->address >= begin && f->address < begin + ph.p_memsz) {
            f->found = true;
            f->name = info->dlpi_name ? info->dlpi_name : "";
            return 1;
          }
        }
        return 0;
      },
      &find);
  std::error_code ec;
  const fs::path file = find.found && !find.name.empty() ? fs::path(find.name) : fs::path("/proc/self/exe");
  const fs::path real = fs::canonical(file, ec);
  return ec ? std::string() : real.string();
}

// Where the module may be, in the order tried (oiio_module.h).
std::vector<std::string> module_candidates() {
  std::vector<std::string> paths;
  const std::string own = own_file();
  if (!own.empty()) {
    const fs::path dir = fs::path(own).parent_path();
    paths.push_back((dir / oiio_module::kFileName).string());
#ifdef NMBAKE_OIIO_MODULE_DIR
    paths.push_back((dir / NMBAKE_OIIO_MODULE_DIR / oiio_module::kFileName).lexically_normal().string());
#endif
  }
#if defined(NMBAKE_OIIO_MODULE_BUILD) && defined(NMBAKE_BUILD_ROOT)
  // Only for a program of the build tree: an installed one never loads a build's module.
  if (own.rfind(NMBAKE_BUILD_ROOT, 0) == 0) paths.push_back(NMBAKE_OIIO_MODULE_BUILD);
#endif
  return paths;
}

// The module's table, or an empty pointer and why not.
struct Loaded {
  const oiio_module::Api* api = nullptr;
  std::string error;
  bool memory = false;  // the loader ran out of memory or address space (ulimit -v): exit 4
};

// The first of module_candidates() that exists, or "" and the list looked through in *looked.
std::string find_module(std::string* looked) {
  for (const std::string& path : module_candidates()) {
    if (::access(path.c_str(), F_OK) == 0) return path;
    *looked += (looked->empty() ? "" : ", ") + path;
  }
  return "";
}

std::string not_found(const std::string& looked) {
  return std::string(oiio_module::kFileName) + " not found (looked for " + looked + ")";
}

Loaded load_module() {
  Loaded loaded;
  std::string looked;
  const std::string path = find_module(&looked);
  if (path.empty()) {
    loaded.error = not_found(looked);
    return loaded;
  }
  // Kept until exit: OpenImageIO's threads and static objects live as long as the process.
  void* handle = ::dlopen(path.c_str(), RTLD_NOW | RTLD_LOCAL);
  if (!handle) {
    const char* why = ::dlerror();
    const std::string reason = why ? why : "unknown error";
    // The loader's words when mmap fails (ENOMEM: a ulimit -v, or memory running out).
    loaded.memory =
        reason.find("failed to map segment") != std::string::npos || reason.find("annot allocate memory") != std::string::npos;
    loaded.error = (loaded.memory ? "out of memory loading " : "cannot load ") + path + ": " + reason;
    return loaded;
  }
  using Entry = const oiio_module::Api* (*)();
  const auto entry = reinterpret_cast<Entry>(::dlsym(handle, "nmbake_oiio_module_api"));
  const oiio_module::Api* api = entry ? entry() : nullptr;
  if (!api || api->abi != oiio_module::kAbi || api->image_size != sizeof(Image) || api->options_size != sizeof(WriteOptions)) {
    loaded.error = path + " is of another build of nmbake (rebuild or reinstall it)";
    return loaded;
  }
  loaded.api = api;
  return loaded;
}

// The process's one load: by the first api() call, or by preload()'s thread, which api() joins.
struct ModuleState {
  std::mutex mutex;
  std::thread loader;
  bool done = false;
  Loaded loaded;
  ~ModuleState() {
    if (loader.joinable()) loader.join();
  }
};
ModuleState& module_state() {
  static ModuleState state;
  return state;
}

// Turns a Failure back into the Error it stands for.
void rethrow(const oiio_module::Failure& failure) {
  switch (ExitCode(failure.code)) {
    case ExitCode::ok: return;
    case ExitCode::usage: throw UsageError(failure.message);
    case ExitCode::input: throw InputError(failure.message);
    case ExitCode::output: throw OutputError(failure.message);
    case ExitCode::memory: throw ResourceError(failure.message);
    default: throw Error(ExitCode(failure.code), failure.message);
  }
}

}  // namespace

const oiio_module::Api& oiio_module::api(const std::string& path, ExitCode kind) {
  ModuleState& state = module_state();
  std::unique_lock<std::mutex> lock(state.mutex);
  if (state.loader.joinable()) state.loader.join();
  if (!state.done) {
    state.loaded = load_module();
    state.done = true;
  }
  if (!state.loaded.api) {
    if (state.loaded.memory) throw ResourceError(path + ": " + state.loaded.error);
    const std::string what =
        path + (kind == ExitCode::output ? ": cannot write: " : ": cannot read image: ") + state.loaded.error;
    if (kind == ExitCode::output) throw OutputError(what);
    throw InputError(what);
  }
  return *state.loaded.api;
}

void oiio_module::preload() {
  ModuleState& state = module_state();
  std::lock_guard<std::mutex> lock(state.mutex);
  if (state.loader.joinable() || state.done) return;  // a running loader's writes are not read here
  try {
    state.loader = std::thread([&state] {
      Loaded loaded = load_module();
      state.loaded = std::move(loaded);
      state.done = true;
    });
  } catch (const std::system_error&) {
    // No thread to be had (ulimit): api() loads it when it is needed.
  }
}

void prepare_write(const std::string& path) {
  const std::string ext = image_io_detail::lower_extension(path);
  if (ext == ".png") return;
  // A missing module is known before the bake, not after it.
  std::string looked;
  if (find_module(&looked).empty()) throw OutputError(path + ": cannot write: " + not_found(looked));
  // TIFF is written here (tiff_write.h); the module only for a file past 4 GiB.
  if (!image_io_detail::is_tiff(ext) && worker_threads(0) > 1) oiio_module::preload();
}

void write_image(const std::string& path, const Image& image, const WriteOptions& options) {
  const std::string ext = image_io_detail::lower_extension(path);
  if (ext == ".png") return write_png_image(path, image, options);
  if (!options.palette.empty()) {
    WriteOptions rgb = options;
    rgb.palette.clear();
    return write_image(path, expand_palette(image, options.palette), rgb);
  }
  const int bits = image_write::check_write(path, image, options);
  if (image_io_detail::is_tiff(ext) && write_tiff_image(path, image, options, bits)) return;
  oiio_module::Failure failure;
  oiio_module::api(path, ExitCode::output).write(path, image, options, bits, all_cores_setting().load(), &failure);
  rethrow(failure);
}

Image read_image(const std::string& path) {
  // Only a regular file (a FIFO or a device would block or never end), and "no such file" without
  // loading the module.
  const std::uint64_t file_size = regular_file_size(path);
  Image image;
  oiio_module::Failure failure;
  oiio_module::api(path, ExitCode::input).read(path, file_size, all_cores_setting().load(), &image, &failure);
  rethrow(failure);
  return image;
}

std::map<std::string, std::string> read_image_metadata(const std::string& path) {
  regular_file_size(path);
  std::map<std::string, std::string> metadata;
  oiio_module::Failure failure;
  oiio_module::api(path, ExitCode::input).read_metadata(path, &metadata, &failure);
  rethrow(failure);
  return metadata;
}

std::pair<int, int> image_library_threads() {
  std::pair<int, int> n{0, 0};
  oiio_module::api("libnmbake-oiio.so", ExitCode::input).library_threads(&n.first, &n.second);
  return n;
}

}  // namespace nmbake
