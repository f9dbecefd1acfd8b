// image_io.h for the commands (nmbake, nmdiff, nmview): OpenImageIO lives in the module
// libnmbake_oiio.so (in the build tree's baker/ folder, in lib/nmbake/ when installed), loaded on a
// background thread that preload_image_io() starts first thing in main(), while the meshes load and
// the bake runs. Under ulimit -v it loads first thing, checked against the address space left: linked
// directly, its libraries' static constructors met the limit before main() and crashed (nmdiff and
// nmview below ~440 MB: exit 127, 134 or 139). Loading
// it costs ~0.15-0.3 s of symbol relocation in its ~260 libraries (measured: `nmbake --version`
// linked directly took 0.35 s, an empty program linked to OpenImageIO 0.27 s); done beside the
// single-threaded mesh loading, the user no longer waits.
#include <dlfcn.h>
#include <unistd.h>

#include <cerrno>
#include <chrono>
#include <climits>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <future>
#include <mutex>
#include <string>
#include <system_error>
#include <thread>
#include <vector>

#include "core/errors.h"
#include "core/memory_budget.h"
#include "io/image_io.h"
#include "io/image_io_module.h"
#include "io/png_write.h"

namespace nmbake {
namespace {

struct Loaded {
  const ImageIoModule* module = nullptr;
  std::string error;    // why it could not be loaded
  bool memory = false;  // for want of memory (ulimit -v): exit 4, not the caller's code
};

// Where the module may be, in the order looked at: next to the executable (nmbake in the build
// tree), the installed layout's module folder relative to the executable's (NMBAKE_IMAGE_MODULE_DIR,
// set by cmake/Install.cmake, e.g. "../lib/nmbake"), then the build tree's baker/ folder seen from its nmdiff/ and viewer/
// folders. Relative to the executable only, so that a command copied elsewhere without its module says so
// (cli.nmbake.image_module_missing).
std::vector<std::string> module_candidates() {
  char exe[PATH_MAX];
  const ssize_t n = ::readlink("/proc/self/exe", exe, sizeof exe - 1);
  std::string dir = ".";
  if (n > 0) {
    dir.assign(exe, std::size_t(n));
    dir = dir.substr(0, dir.find_last_of('/'));
  }
  std::vector<std::string> paths{dir + "/" NMBAKE_IMAGE_MODULE};
#ifdef NMBAKE_IMAGE_MODULE_DIR
  paths.push_back(dir + "/" NMBAKE_IMAGE_MODULE_DIR "/" NMBAKE_IMAGE_MODULE);
#endif
  paths.push_back(dir + "/../baker/" NMBAKE_IMAGE_MODULE);  // the build tree's nmdiff/ and viewer/ folders
  return paths;
}

// The first candidate that exists; empty, with *error saying where it looked, when none does.
std::string module_path(std::string* error) {
  const std::vector<std::string> paths = module_candidates();
  for (const std::string& p : paths)
    if (::access(p.c_str(), F_OK) == 0) return p;
  const int missing = errno;
  *error = "cannot load the image library module " + paths.front() + ": " + std::strerror(missing);
  for (std::size_t i = 1; i < paths.size(); ++i) *error += " (nor " + paths[i] + ")";
  return {};
}

// Address space loading the module takes: 431 MB measured (VmSize before and after dlopen, its
// ~260 libraries and the threads some of them start), with a margin for what the bake allocates
// meanwhile.
constexpr std::uint64_t kModuleAddressSpace = 560ull << 20;

Loaded load() {
  Loaded l;
  const std::string path = module_path(&l.error);
  if (path.empty()) return l;
  // Short of address space, one of the libraries' constructors (log4cplus's thread pool) does not
  // fail but waits forever: a run under ulimit -v 510 MB hung. Refused before dlopen instead.
  if (const std::uint64_t left = address_space_headroom(); left < kModuleAddressSpace) {
    l.error = "out of memory: loading the image library needs about " + std::to_string(kModuleAddressSpace >> 20) +
              " MiB of address space and the limit (ulimit -v) leaves " + std::to_string(left >> 20) + " MiB";
    l.memory = true;
    return l;
  }
  void* handle = ::dlopen(path.c_str(), RTLD_NOW | RTLD_LOCAL);
  if (!handle) {
    const char* why = ::dlerror();
    l.error = "cannot load the image library module " + path + ": " + (why ? why : "unknown error");
    l.memory = why && (std::strstr(why, "Cannot allocate memory") || std::strstr(why, "failed to map segment"));
    if (l.memory) l.error = "out of memory: " + l.error;
    return l;
  }
  using Entry = const ImageIoModule* (*)();
  auto entry = reinterpret_cast<Entry>(::dlsym(handle, "nmbake_image_io_module"));
  const ImageIoModule* m = entry ? entry() : nullptr;
  if (!m || m->version != kImageIoModuleVersion) {
    l.error = path + ": not the image library module of this nmbake build";
    return l;
  }
  l.module = m;  // never unloaded: it lives as long as the process
  return l;
}

std::once_flag g_started;
std::shared_future<Loaded> g_loaded;
// Joined, not detached: the result is ready before the thread has ended, and a thread still ending
// (its thread-local destructors, some of them in the libraries it loaded) while exit() destroys
// those libraries' statics crashed an early error exit now and then (exit 139 after the error line,
// about once in a few hundred runs under load). main() joins it (wait_for_image_io).
std::thread g_loader;

std::packaged_task<Loaded()> g_task;

// Never throws: it runs before main()'s error handling. Without memory for the task, g_loaded stays
// empty (module() reports it); without a thread (EAGAIN under ulimit), the load runs here.
void start() {
  std::call_once(g_started, [] {
    try {
      g_task = std::packaged_task<Loaded()>(load);
      g_loaded = g_task.get_future().share();
      // Under ulimit -v the load runs here, before anything else allocates: a library constructor
      // (log4cplus's thread pool) that meets the limit while the meshes load beside it aborts or
      // waits forever, and the headroom load() checks holds only if nothing competes for it.
      if (address_space_headroom() != UINT64_MAX) {
        g_task();
        return;
      }
      try {
        g_loader = std::thread([] { g_task(); });
      } catch (const std::system_error&) {
        g_task();
      }
    } catch (const std::exception&) {
      g_loaded = {};
    }
  });
}

const ImageIoModule& module(const std::string& path, ExitCode failure) {
  start();
  if (!g_loaded.valid()) throw ResourceError(path + ": out of memory: the image library could not be loaded");
  const Loaded& l = g_loaded.get();
  if (!l.module) throw Error(l.memory ? ExitCode::memory : failure, path + ": " + l.error);
  return *l.module;
}

[[noreturn]] void rethrow(int code, const std::string& message) {
  switch (ExitCode(code)) {
    case ExitCode::usage: throw UsageError(message);
    case ExitCode::input: throw InputError(message);
    case ExitCode::memory: throw ResourceError(message);
    default: throw OutputError(message);
  }
}

}  // namespace

void preload_image_io() { start(); }

void wait_for_image_io() {
  if (g_loader.joinable()) g_loader.join();
}

std::string image_io_problem() {
  start();
  if (!g_loaded.valid()) return "out of memory: the image library could not be loaded";
  if (g_loaded.wait_for(std::chrono::seconds(0)) == std::future_status::ready && !g_loaded.get().module)
    return g_loaded.get().error;
  std::string error;
  const std::string path = module_path(&error);
  if (path.empty()) return error;
  if (::access(path.c_str(), R_OK) != 0) return "cannot load the image library module " + path + ": " + std::strerror(errno);
  return {};
}

void write_image(const std::string& path, const Image& image, const WriteOptions& options) {
  if (image_io_detail::lower_extension(path) == ".png") return write_png_image(path, image, options);  // no module needed
  std::string error;
  if (const int code = module(path, ExitCode::output).write(path, image, options, &error)) rethrow(code, error);
}

Image read_image(const std::string& path) {
  Image image;
  std::string error;
  if (const int code = module(path, ExitCode::input).read(path, &image, &error)) rethrow(code, error);
  return image;
}

std::map<std::string, std::string> read_image_metadata(const std::string& path) {
  std::map<std::string, std::string> metadata;
  std::string error;
  if (const int code = module(path, ExitCode::input).read_metadata(path, &metadata, &error)) rethrow(code, error);
  return metadata;
}

}  // namespace nmbake
