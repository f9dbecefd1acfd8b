// The extension nmbake._nmbake: the nmbake command's bake and nmdiff's comparison for the Python
// package (python/nmbake/__init__.py turns keyword arguments into their command lines and the
// results into numpy arrays and dicts; docs/python.md).
//
// A bake is the command's: its command line parsed by parse_bake_command_line (cli/command.h), then
// bake_job (cli/job.h) with the Python hooks of JobEnv: meshes given as arrays (PLY bytes made by
// __init__.py) loaded by load_mesh_from_memory, the images handed over before they are encoded,
// the maps not written when there is no output, the stages to the progress callback. The GIL is
// released while it runs and taken again for the callback only.
//
// Errors leave as _nmbake.Failure(status, message): the command's exit status (README's table)
// and its one-line message (cli/shell.h, failure_of); __init__.py raises nmbake.Error's subclass.
#include <pybind11/functional.h>
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <unistd.h>

#include <atomic>
#include <chrono>
#include <cstring>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>
#include <CLI/CLI.hpp>

#include "cli/args.h"
#include "cli/command.h"
#include "cli/job.h"
#include "cli/progress.h"
#include "cli/shell.h"
#include "io/image_io.h"
#include "io/image_write.h"
#include "io/mesh_io.h"
#include "command.h"
#include "pipeline/bake.h"

namespace py = pybind11;

namespace nmbake::python {
namespace {

// _nmbake.Failure, raised with (status, message); never freed (the interpreter may outlive the
// module's statics at exit).
py::object* g_failure = nullptr;

[[noreturn]] void raise_failure(const Failure& f) {
  PyErr_SetObject(g_failure->ptr(), py::make_tuple(f.status, f.message).ptr());
  throw py::error_already_set();
}

// argv for the parsers: argv[0] first; the strings outlive the call.
struct Argv {
  explicit Argv(const std::vector<std::string>& words) : words_(words) {
    for (std::string& w : words_) pointers_.push_back(w.data());
    pointers_.push_back(nullptr);
  }
  int argc() const { return int(words_.size()); }
  char** argv() { return pointers_.data(); }

 private:
  std::vector<std::string> words_;
  std::vector<char*> pointers_;
};

// The command's long options: name (without "--") -> whether it takes a value (false: a flag).
std::map<std::string, bool> option_names() {
  Args a;
  CLI::App app;
  add_options(app, a);
  std::map<std::string, bool> names;
  for (const CLI::Option* opt : app.get_options()) {
    if (opt->get_positional() || opt->get_lnames().empty()) continue;
    const std::string& name = opt->get_lnames().front();
    if (name == "help" || name == "version") continue;
    names[name] = opt->get_expected_min() > 0;
  }
  return names;
}

// One image as the file holds it once decoded: the 8- and 16-bit writers' quantization
// (io/image_write.h) divided back, the float values as they are. EXR in 16 bits (half float) is
// converted by the caller (`half`).
struct DecodedImage {
  std::string name;
  int tile = 0;
  int width = 0, height = 0, channels = 0;
  std::vector<float> values;
  bool half = false;
};

DecodedImage decode_as_written(const JobImage& j) {
  const Image expanded = j.options->palette.empty() ? Image() : expand_palette(*j.image, j.options->palette);
  const Image& image = j.options->palette.empty() ? *j.image : expanded;  // an ID map: its colours
  DecodedImage d{j.name, j.tile, image.width, image.height, image.channels, {}, false};
  const int bits = j.options->bits ? j.options->bits : default_bits_for(j.path);
  const Image::Pixels& p = image.pixels;
  const bool exr = image_io_detail::lower_extension(j.path) == ".exr";
  d.values.resize(p.size());
  if (bits == 8) {
    const auto q = image_write::quantize8(p, j.options->dither, j.options->threads);
    for (std::size_t i = 0; i < q.size(); ++i) d.values[i] = float(q[i]) / 255.0f;
  } else if (bits == 16 && !exr) {
    const auto q = image_write::quantize16(p, j.options->threads);
    for (std::size_t i = 0; i < q.size(); ++i) d.values[i] = float(q[i]) / 65535.0f;
  } else {
    std::memcpy(d.values.data(), p.data(), p.size() * sizeof(float));
    d.half = bits == 16;
  }
  return d;
}

py::array_t<float> to_array(DecodedImage& d) {
  auto* values = new std::vector<float>(std::move(d.values));
  py::capsule owner(values, [](void* v) { delete static_cast<std::vector<float>*>(v); });
  const py::ssize_t c = d.channels, w = d.width;
  return py::array_t<float>({py::ssize_t(d.height), w, c},
                            {w * c * py::ssize_t(sizeof(float)), c * py::ssize_t(sizeof(float)), py::ssize_t(sizeof(float))},
                            values->data(), owner);
}

// A bake: argv the command line (argv[0] "nmbake"), `command` what the report's "command" says,
// `meshes` the PLY bytes of the meshes given as arrays by their names in argv. Returns the images
// (name, tile, array, half) and the report's JSON text.
py::tuple bake(const std::vector<std::string>& words, const std::vector<std::string>& command,
               const std::map<std::string, py::bytes>& meshes, bool write_maps, const py::object& progress) {
  Args a;
  const char* doing = nullptr;
  std::map<std::string, std::string> mesh_bytes;
  for (const auto& [name, bytes] : meshes) mesh_bytes[name] = std::string(bytes);
  // The callback's exception (or KeyboardInterrupt) stops the bake through `interrupted` and is
  // raised again once the bake has stopped.
  std::atomic<bool> cancel{false};
  std::optional<py::error_already_set> raised;
  std::vector<DecodedImage> images;
  nlohmann::json report;
  int last_percent = -1;
  const char* last_stage = nullptr;
  auto last_call = std::chrono::steady_clock::now();
  const auto call_back = [&](const char* stage, double share) {
    // Python is called at each stage and, with a callback, at each whole percent; without one (only
    // to see Ctrl-C) at most ten times a second: the GIL may have to be waited for.
    const int percent = int(share * 100.0);
    const auto now = std::chrono::steady_clock::now();
    if (stage == last_stage &&
        (percent == last_percent || (progress.is_none() && now - last_call < std::chrono::milliseconds(100))))
      return;
    last_stage = stage, last_percent = percent, last_call = now;
    py::gil_scoped_acquire gil;
    if (cancel) return;
    try {
      if (PyErr_CheckSignals() != 0) throw py::error_already_set();  // Ctrl-C, on the main thread
      if (!progress.is_none()) progress(stage, share);
    } catch (py::error_already_set& e) {
      raised.emplace(e);
      cancel = true;
    }
  };
  std::optional<Failure> failed;
  {
    py::gil_scoped_release release;
    try {
      Argv argv(words);
      if (parse_bake_command_line(argv.argc(), argv.argv(), a)) throw UsageError("--help and --version are not bakes");
      const auto start = std::chrono::steady_clock::now();
      const auto interrupted = [&cancel] { return cancel.load(); };
      // The command's progress line where it would draw one (quiet=False on a terminal, or progress=True).
      Progress line(!a.quiet && (a.progress || ::isatty(STDERR_FILENO)), start, interrupted);
      JobEnv env{command, interrupted, &doing, line, start, nullptr};
      env.report = &report;
      env.write_maps = write_maps;
      env.load_mesh = [&](const std::string& path, const LoadOptions& options, MeshLoadInfo* info) {
        const auto it = mesh_bytes.find(path);
        return it == mesh_bytes.end() ? load_mesh(path, options, info) : load_mesh_from_memory(path, it->second, options, info);
      };
      env.on_image = [&](const JobImage& j) { images.push_back(decode_as_written(j)); };
      env.on_progress = call_back;
      bake_job(a, env);
      call_back("done", 1.0);
    } catch (const Cancelled&) {
      if (!raised) failed = Failure{int(ExitCode::usage), "cancelled"};
    } catch (...) {
      failed = failure_of(std::current_exception(), {}, &doing);
    }
  }
  if (raised) throw *raised;
  if (cancel && !failed) failed = Failure{int(ExitCode::usage), "cancelled"};
  if (failed) raise_failure(*failed);
  py::list out;
  for (DecodedImage& d : images) out.append(py::make_tuple(d.name, d.tile, to_array(d), d.half));
  // Invalid UTF-8 in a path given is replaced, where --report's file would fail to be written.
  return py::make_tuple(out, report.dump(-1, ' ', false, nlohmann::json::error_handler_t::replace));
}

// nmdiff's figures (--json's) for its command line (argv[0] "nmdiff").
std::string diff(const std::vector<std::string>& words) {
  std::optional<Failure> failed;
  std::string json;
  {
    py::gil_scoped_release release;
    try {
      json = nmdiff_json_text(words);
    } catch (...) {
      failed = failure_of(std::current_exception());
    }
  }
  if (failed) raise_failure(*failed);
  return json;
}

// A map file decoded to float (integer formats scaled to [0,1]), as nmdiff reads it.
py::array_t<float> read_map(const std::string& path) {
  std::optional<Failure> failed;
  DecodedImage d;
  {
    py::gil_scoped_release release;
    try {
      const Image image = read_image(path);
      d = {"", 0, image.width, image.height, image.channels, std::vector<float>(image.pixels.begin(), image.pixels.end()), false};
    } catch (...) {
      failed = failure_of(std::current_exception());
    }
  }
  if (failed) raise_failure(*failed);
  return to_array(d);
}

}  // namespace
}  // namespace nmbake::python

PYBIND11_MODULE(_nmbake, m) {
  using namespace nmbake::python;
  m.doc() = "The nmbake command's bake and nmdiff's comparison (use the package nmbake, not this module).";
  g_failure = new py::object(py::exception<std::runtime_error>(m, "Failure"));
  m.def("option_names", &option_names, "The command's long options: name -> takes a value (False: a flag).");
  m.def("bake", &bake, py::arg("argv"), py::arg("command"), py::arg("meshes"), py::arg("write_maps"), py::arg("progress"));
  m.def("diff", &diff, py::arg("argv"));
  m.def("read_image", &read_map, py::arg("path"));
}
