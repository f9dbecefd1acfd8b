// The entry of libnmbake-oiio.so (oiio_module.h): the three calls, each turning what it throws into
// a Failure, under the loading process's "all cores" setting.
#include <exception>
#include <new>

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

void write_call(const std::string& path, const Image& image, const WriteOptions& options, int bits, int all_cores,
                Failure* failure) {
  const AllCores cores(all_cores);
  guarded(path, ExitCode::output, failure, [&] { write(path, image, options, bits); });
}

void read_call(const std::string& path, std::uint64_t file_size, int all_cores, Image* image, Failure* failure) {
  const AllCores cores(all_cores);
  guarded(path, ExitCode::input, failure, [&] { *image = read(path, file_size); });
}

void read_metadata_call(const std::string& path, std::map<std::string, std::string>* out, Failure* failure) {
  guarded(path, ExitCode::input, failure, [&] { *out = read_metadata(path); });
}

constexpr Api kApi{kAbi, sizeof(Image), sizeof(WriteOptions), write_call, read_call, read_metadata_call};

}  // namespace
}  // namespace nmbake::oiio_module

extern "C" __attribute__((visibility("default"))) const nmbake::oiio_module::Api* nmbake_oiio_module_api() {
  return &nmbake::oiio_module::kApi;
}
