// nmbake's command line as a function: parses arguments and wires the stages together; nothing else.
#include "cli/command.h"

#include <unistd.h>

#include <atomic>
#include <chrono>
#include <csignal>
#include <cstdio>
#include <optional>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>

#include "pipeline/bake.h"
#include "io/output_files.h"
#include "cli/args.h"
#include "cli/batch.h"
#include "cli/job.h"
#include "cli/progress.h"
#include "cli/shell.h"

namespace nmbake {
namespace {

using Clock = std::chrono::steady_clock;

// The first of SIGINT, SIGTERM and SIGHUP received, or 0. The handler only records it: the bake
// stops at its next progress call, the writes between two files, and the temporaries are removed
// on the way out; once the renames of the finished outputs have begun, the run completes.
std::atomic<int> g_signal{0};
extern "C" void on_signal(int sig) {
  int none = 0;
  g_signal.compare_exchange_strong(none, sig);
}
bool interrupted() { return g_signal.load() != 0; }

void install_signal_handlers() {
  struct sigaction action {};
  action.sa_handler = on_signal;
  sigemptyset(&action.sa_mask);
  action.sa_flags = SA_RESTART;
  for (int sig : {SIGINT, SIGTERM, SIGHUP}) {
    struct sigaction old {};
    // A SIGHUP ignored on entry (nohup) stays ignored.
    if (sig == SIGHUP && ::sigaction(sig, nullptr, &old) == 0 && old.sa_handler == SIG_IGN) continue;
    ::sigaction(sig, &action, nullptr);
  }
}

const char* signal_name(int sig) { return sig == SIGTERM ? "SIGTERM" : sig == SIGHUP ? "SIGHUP" : "SIGINT"; }

// What the command does, for an out-of-memory message ("error: out of memory while writing the
// outputs"); the bake names its own stages.
const char* g_doing = nullptr;

int run(int argc, char** argv) {
  if (wants_batch(argc, argv)) {
    BatchArgs b;
    if (const int code = parse_batch_args(argc, argv, b); code >= 0) return code;
    const auto start = Clock::now();
    install_signal_handlers();
    return run_batch(b, interrupted, &g_doing, start);
  }
  Args a;
  if (const std::optional<int> status = parse_bake_command_line(argc, argv, a)) return *status;
  const auto start = Clock::now();
  install_signal_handlers();
  // One line for the whole command, on a terminal or with --progress; never with --quiet.
  Progress progress(!a.quiet && (a.progress || ::isatty(STDERR_FILENO)), start, interrupted);
  const JobEnv env{std::vector<std::string>(argv, argv + argc), interrupted, &g_doing, progress, start, nullptr};
  bake_job(a, env);
  return 0;
}

// A bake stopped by SIGINT, SIGTERM or SIGHUP: exit 128 + the signal's number.
int run_interruptible(int argc, char** argv) {
  try {
    return run(argc, argv);
  } catch (const Cancelled&) {
    const int sig = g_signal.load() ? g_signal.load() : SIGINT;
    std::fprintf(stderr, "error: interrupted by %s; no output written\n", signal_name(sig));
    return 128 + sig;
  }
}

}  // namespace

std::optional<int> parse_bake_command_line(int argc, char** argv, Args& a) {
  CLI::App app{"nmbake: bake a tangent-space normal map from a high-poly mesh onto a low-poly mesh with UVs.", "nmbake"};
  add_options(app, a);
  if (const std::optional<int> status = parse_command_line(app, argc, argv, "nmbake")) return status;
  finish_args(a, app);
  return std::nullopt;
}

int nmbake_command(int argc, char** argv) {
  g_signal.store(0);
  g_doing = nullptr;
  return run_command([&] { return run_interruptible(argc, argv); }, {}, &g_doing);
}

}  // namespace nmbake
