// nmdiff's own code, compiled once more here: nmdiff/main.cpp keeps its command line, its reading
// of the files and its JSON in one file, not in the nmdiff_core library, and the module must give
// the same figures under the same keys with the same checks and messages. Its headers are
// included first, so that the renaming of its main() and run() (which the module never calls)
// touches nothing else. Moving CommandLine, compare_files and to_json into nmdiff_core would make
// this file a plain user of the library.
#include "nmdiff_json.h"

#include <cerrno>
#include <cmath>
#include <csignal>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <iostream>
#include <limits>
#include <map>
#include <optional>
#include <string>

#include <CLI/CLI.hpp>
#include <nlohmann/json.hpp>

#include "cli/numbers.h"
#include "cli/shell.h"
#include "conventions.h"
#include "core/errors.h"
#include "io/image_io.h"
#include "io/mesh_io.h"
#include "io/output_files.h"
#include "io/text_file.h"
#include "map_diff.h"
#include "nmdiff.h"

#define main nmdiff_command_main
#define run nmdiff_command_run
#include "../../nmdiff/main.cpp"
#undef run
#undef main

namespace nmbake::python {

std::string nmdiff_json(const std::vector<std::string>& words) {
  std::vector<std::string> storage = words;
  std::vector<char*> argv;
  for (std::string& w : storage) argv.push_back(w.data());
  argv.push_back(nullptr);
  CommandLine cl;
  if (::parse_command_line(int(storage.size()), argv.data(), cl)) throw UsageError("--help is not a comparison");
  ::check_outputs(cl);
  const Comparison c = ::compare_files(cl);
  // What report() writes, without its lines on stdout.
  const nlohmann::json json = ::is_normal_like(c)
                                  ? ::to_json(cl.path_a, cl.path_b, c.stats, cl.options, cl.mask_path, cl.resample, c.seen)
                                  : ::map_to_json(cl.path_a, cl.path_b, c.map_stats, c.map_options, cl.mask_path, cl.resample);
  OutputFiles outputs;
  if (!cl.heatmap_path.empty()) {
    if (::is_normal_like(c)) ::write_heatmap(cl, c, outputs);
    else ::write_map_heatmap(cl, c, outputs);
  }
  const std::string text = json.dump(2) + "\n";
  if (!cl.json_path.empty()) write_text_file(cl.json_path, outputs.add(cl.json_path), text);
  outputs.commit();
  return text;
}

}  // namespace nmbake::python
