// nmbake_cases CASES: runs many nmbake command lines in one process (cli/command.h), for the
// command-line tests that try a long list of inputs (run_cases.sh): one start of the program, whose
// ~0.4 s of loading OpenImageIO's libraries would otherwise be paid per case.
// CASES has one case a line, fields separated by tabs (run_cases.sh writes them): the case's folder
// (absolute), then the arguments, each with \\, \t and \n for a backslash, a tab and a newline. For each case it prints "case K:
// FOLDER" on stdout before running it, runs the command in FOLDER with stdin from /dev/null and stdout and stderr in stdout.txt
// and stderr.txt there, and then writes "STATUS MILLISECONDS" to code.txt there. A case that crashes ends the program: the cases
// after it have no code.txt. A case whose first argument is --nmdiff runs nmdiff's command
// (nmdiff/command.h) with the arguments after it. Exit 0 when every case ran, 2 for a bad CASES file.
#include <chrono>
#include <cstdio>
#include <fstream>
#include <string>
#include <vector>

#include "command.h"
#include "io/output_files.h"
#include "test_support.h"

namespace {

std::string unescape(const std::string& field) {
  std::string s;
  for (std::size_t i = 0; i < field.size(); ++i) {
    if (field[i] != '\\' || i + 1 == field.size()) {
      s += field[i];
      continue;
    }
    const char c = field[++i];
    s += c == 't' ? '\t' : c == 'n' ? '\n' : c;
  }
  return s;
}

}  // namespace

int main(int argc, char** argv) {
  if (argc != 2) {
    std::fprintf(stderr, "usage: nmbake_cases CASES\n");
    return 2;
  }
  std::ifstream in(argv[1]);
  if (!in) {
    std::fprintf(stderr, "error: cannot read %s\n", argv[1]);
    return 2;
  }
  nmbake::protect_standard_streams();
  std::string line;
  for (int k = 0; std::getline(in, line); ++k) {
    std::vector<std::string> fields;
    for (std::size_t start = 0;;) {
      const std::size_t tab = line.find('\t', start);
      fields.push_back(line.substr(start, tab == std::string::npos ? std::string::npos : tab - start));
      if (tab == std::string::npos) break;
      start = tab + 1;
    }
    for (std::string& f : fields) f = unescape(f);
    if (fields.empty() || fields[0].empty() || fields[0][0] != '/') {
      std::fprintf(stderr, "error: %s line %d: expected an absolute folder, then tab-separated arguments\n", argv[1], k + 1);
      return 2;
    }
    std::printf("case %d: %s\n", k, fields[0].c_str());
    std::fflush(stdout);
    const bool nmdiff = fields.size() > 1 && fields[1] == "--nmdiff";
    const std::vector<std::string> args(fields.begin() + (nmdiff ? 2 : 1), fields.end());
    const auto start = std::chrono::steady_clock::now();
    const int code =
        nmdiff ? nmbake::test::run_command_in(nmbake::nmdiff_command, "nmdiff", args, fields[0], "stdout.txt", "stderr.txt")
               : nmbake::test::run_nmbake_in(args, fields[0], "stdout.txt", "stderr.txt");
    const long long ms = std::chrono::duration_cast<std::chrono::milliseconds>(std::chrono::steady_clock::now() - start).count();
    std::ofstream(fields[0] + "/code.txt") << code << ' ' << ms << '\n';
  }
  return 0;
}
