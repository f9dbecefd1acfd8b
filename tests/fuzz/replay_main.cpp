// Runs the fuzz target once on every file named on the command line (or in the folders named),
// without libFuzzer: the corpus and the minimised crashers become a regression test of the
// ordinary build (and of the ASan build). Prints the count; a crash or abort fails the test, after
// a line naming the input that caused it.
#include <unistd.h>

#include <csignal>
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>
#include <vector>

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size);

namespace {

// The input being run, for the signal handler (async-signal-safe: write(2) of a prepared string).
std::string g_current_line;

extern "C" void name_the_input(int signal_number) {
  const ssize_t written = write(STDERR_FILENO, g_current_line.data(), g_current_line.size());
  (void)written;
  std::signal(signal_number, SIG_DFL);
  std::raise(signal_number);
}

}  // namespace

int main(int argc, char** argv) {
  namespace fs = std::filesystem;
  std::vector<fs::path> files;
  for (int i = 1; i < argc; ++i) {
    if (fs::is_directory(argv[i])) {
      for (const auto& entry : fs::directory_iterator(argv[i]))
        if (entry.is_regular_file()) files.push_back(entry.path());
    } else {
      files.emplace_back(argv[i]);
    }
  }
  if (files.empty()) {
    std::fprintf(stderr, "error: fuzz_mesh_load_replay: no input files\n");
    return 1;
  }
  for (int signal_number : {SIGABRT, SIGSEGV, SIGBUS, SIGFPE, SIGILL}) std::signal(signal_number, name_the_input);
  for (const fs::path& file : files) {
    g_current_line = "fuzz_mesh_load_replay: crashed on " + file.string() + "\n";
    std::ifstream in(file, std::ios::binary);
    if (!in) {
      std::fprintf(stderr, "error: %s: cannot open\n", file.c_str());
      return 1;
    }
    std::vector<char> bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    LLVMFuzzerTestOneInput(reinterpret_cast<const std::uint8_t*>(bytes.data()), bytes.size());
  }
  std::printf("fuzz_mesh_load_replay: %zu inputs ran without a crash\n", files.size());
  return 0;
}
