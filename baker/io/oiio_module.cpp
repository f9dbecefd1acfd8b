// The entry of libnmbake-oiio.so (oiio_module.h): the three calls, each turning what it throws into
// a Failure, under the loading process's "all cores" setting.
#include <exception>
#include <mutex>
#include <new>

#include <OpenImageIO/imageio.h>

#include "core/errors.h"
#include "core/parallel.h"
#include "io/oiio_module.h"

namespace nmbake::oiio_module {
namespace {

// Runs `call`; an exception becomes *failure (an nmbake::Error keeps its exit code; running out of
// memory is exit 4; anything else `other`, with the path).
template <typename Call>
void guarded(const std::string& path, ExitCode other, Failure* failure, Call&& call) {
  try {
    call();
  } catch (const Error& e) {
    *failure = {int(e.code()), e.what()};
  } catch (const std::bad_alloc&) {
    *failure = {int(ExitCode::memory), path + ": out of memory"};
  } catch (const std::exception& e) {
    *failure = {int(other), one_line(path + ": " + e.what())};
  }
}

// OpenImageIO's thread pool (where its TIFF writer compresses strips and its readers decode them)
// and OpenEXR's (where each block of an EXR is compressed or decompressed) are the libraries' own,
// by default one thread per core of the machine, whatever --threads says: a `--threads 1` bake to
// EXR compressed on every core. Each call sizes both to the process's "all cores" (core/parallel.h)
// first, unless another call is using them (calls at once are one command's files side by side,
// under one setting; they share the pools).
class LibraryThreads {
 public:
  LibraryThreads() {
    const std::lock_guard<std::mutex> lock(mutex_);
    const int threads = worker_threads(0);
    if (in_use_ == 0 && threads != set_) {
      // OpenImageIO's pool: threads - 1 workers beside the calling thread, which takes tasks too;
      // OpenEXR's: `threads` workers beside the calling thread, which does the file's I/O.
      OIIO::attribute("threads", threads);
      OIIO::attribute("exr_threads", threads);
      set_ = threads;
    }
    ++in_use_;
  }
  ~LibraryThreads() {
    const std::lock_guard<std::mutex> lock(mutex_);
    --in_use_;
  }
  LibraryThreads(const LibraryThreads&) = delete;
  LibraryThreads& operator=(const LibraryThreads&) = delete;

 private:
  static inline std::mutex mutex_;
  static inline int in_use_ = 0, set_ = 0;  // set_ 0: the libraries' defaults
};

void write_call(const std::string& path, const Image& image, const WriteOptions& options, int bits, int all_cores,
                Failure* failure) {
  const AllCores cores(all_cores);
  guarded(path, ExitCode::output, failure, [&] {
    const LibraryThreads pools;
    write(path, image, options, bits);
  });
}

void read_call(const std::string& path, std::uint64_t file_size, int all_cores, Image* image, Failure* failure) {
  const AllCores cores(all_cores);
  guarded(path, ExitCode::input, failure, [&] {
    const LibraryThreads pools;
    *image = read(path, file_size);
  });
}

void read_metadata_call(const std::string& path, std::map<std::string, std::string>* out, Failure* failure) {
  guarded(path, ExitCode::input, failure, [&] { *out = read_metadata(path); });
}

void library_threads_call(int* openimageio, int* openexr) {
  *openimageio = OIIO::get_int_attribute("threads");
  *openexr = OIIO::get_int_attribute("exr_threads");  // applied to OpenEXR as each EXR file opens
}

constexpr Api kApi{kAbi, sizeof(Image), sizeof(WriteOptions), write_call, read_call, read_metadata_call, library_threads_call};

}  // namespace
}  // namespace nmbake::oiio_module

extern "C" __attribute__((visibility("default"))) const nmbake::oiio_module::Api* nmbake_oiio_module_api() {
  return &nmbake::oiio_module::kApi;
}
