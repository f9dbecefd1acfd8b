// Section 10 of the bake bench: the whole nmbake command side by side with Blender's Cycles bake
// of the same pair (blender_bake.py), measured in the same run and alternated nmbake, Blender,
// nmbake, ... over the rounds, so a change in the host's load falls on both: median wall time and
// max RSS of each, their ratio, and Blender's own load / bake / save split.
//
// Both commands are measured the same way, wall time and ru_maxrss from wait4 on the process (not
// nmbake's report). Linux starts a child's ru_maxrss from the resident size of the process it was
// forked from, as of the child's exec (that process's whole peak with vfork / posix_spawn), and the
// bench holds gigabytes after its earlier sections; so each command is started by a fresh `bench_bake
// --measure-child` process, which forks, times it and appends the figures to the command's log. Its
// anonymous pages (about 45 MiB) are still a floor under the max RSS; the section prints it.
#include <fcntl.h>
#include <spawn.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <system_error>
#include <vector>

#include "bench_bake.h"
#include "bench_support.h"
#include "tests/build_paths.h"

extern char** environ;

namespace nmbake::bench {

namespace {

namespace fs = std::filesystem;

constexpr const char* kMeasured = "bench-measured:";

// The helper is this very program, so it needs no path of its own.
std::string self_exe() {
  std::error_code ec;
  const fs::path p = fs::read_symlink("/proc/self/exe", ec);
  return ec ? std::string("/proc/self/exe") : p.string();
}

std::string describe_status(int status) {
  if (WIFEXITED(status)) return "exit " + std::to_string(WEXITSTATUS(status));
  if (WIFSIGNALED(status)) return "signal " + std::to_string(WTERMSIG(status));
  return "status " + std::to_string(status);
}

std::vector<char*> c_argv(const std::vector<std::string>& args) {
  std::vector<char*> v;
  for (const std::string& a : args) v.push_back(const_cast<char*>(a.c_str()));
  v.push_back(nullptr);
  return v;
}

// Both sides of one scene, and Blender's own split per round (seconds).
struct Pair {
  std::string scene;
  Side nm, bl;
  std::vector<double> load, bake, save;
};

// Blender's "blender-bake: load L bake B save S" line from its log.
void read_split(const std::string& log, Pair& p) {
  std::ifstream in(log);
  for (std::string line; std::getline(in, line);) {
    double load = 0, bake = 0, save = 0;
    if (std::sscanf(line.c_str(), "blender-bake: load %lf bake %lf save %lf", &load, &bake, &save) == 3) {
      p.load.push_back(load);
      p.bake.push_back(bake);
      p.save.push_back(save);
    }
  }
}

// Alternated rounds: nmbake, Blender, nmbake, Blender, ... (Blender left out when `blender` is empty).
Pair measure_pair(const BenchRun& run, const Scenes& scenes, const std::string& blender, const std::string& scene,
                  const std::string& high, const std::string& tag) {
  Pair p;
  p.scene = scene;
  const std::string low = scenes.s4 + "/low.obj", dir = run.run_dir + "/";
  const std::vector<std::string> nm = {run.args.exe, low, high, "-o", dir + tag + "_nmbake.png", "--size", "2048", "--quiet"};
  std::vector<std::string> bl = {blender, "-b",       "--factory-startup", "--python-exit-code",
                                 "1",     "--python", blender_script(),    "--"};
  bl.insert(bl.end(), {low, high, dir + tag + "_blender.png", "2048", "1", kBlenderExtrusion});
  const std::string nm_log = dir + tag + "_nmbake.log", bl_log = dir + tag + "_blender.log";
  for (int round = 0; round < run.args.rounds; ++round) {
    if (p.nm.failed.empty()) run_side(run, p.nm, nm, nm_log);
    if (!blender.empty() && p.bl.failed.empty() && run_side(run, p.bl, bl, bl_log)) read_split(bl_log, p);
  }
  return p;
}

std::string per_round(const std::vector<double>& v) {
  std::string s;
  for (std::size_t i = 0; i < v.size(); ++i) s += fmt(i ? ", %.2f" : "%.2f", v[i]);
  return s;
}

void print_side(const std::string& scene, const std::string& name, const Side& s) {
  if (!s.ok()) {
    std::printf("| %s | %s | failed: %s | | |\n", scene.c_str(), name.c_str(), s.failed.c_str());
  } else {
    std::printf("| %s | %s | %.2f | %.0f | %s |\n", scene.c_str(), name.c_str(), median(s.wall), median(s.rss),
                per_round(s.wall).c_str());
  }
}

// The scene's rows: nmbake, Blender (when measured or failed) and the ratio.
void print_pair(const Pair& p, const std::string& blender_name, bool blender) {
  print_side(p.scene, "nmbake", p.nm);
  if (blender) print_side(p.scene, blender_name, p.bl);
  if (p.nm.ok() && p.bl.ok())
    std::printf("| %s | Blender / nmbake | %.1fx | %.1fx | |\n", p.scene.c_str(), median(p.bl.wall) / median(p.nm.wall),
                median(p.bl.rss) / median(p.nm.rss));
  flush();
}

// Blender's load / bake / save seconds, when its log had them; returns whether it printed.
bool print_split(const Pair& p) {
  if (p.bake.empty()) return false;
  const double rest = median(p.bl.wall) - median(p.load) - median(p.bake) - median(p.save);
  std::printf(
      "- %s, Blender's own split (blender_bake.py, medians): load %.2f s, bake %.2f s, save %.2f s; the rest of its wall "
      "(start-up, the output check, exit) %.2f s.\n",
      p.scene.c_str(), median(p.load), median(p.bake), median(p.save), rest);
  return true;
}

// The targets on one scene: on the 1M one nmbake's wall time, the ratio, nmbake's memory; on the 4M one the ratio.
void judge(BenchRun& run, const Pair& p, bool m1, const std::string& no_blender) {
  const std::string rounds = std::to_string(p.nm.wall.size()) + " alternated round" + (p.nm.wall.size() == 1 ? "" : "s");
  const std::string of = ", median of " + rounds;
  const std::string wall = "whole command 1M tris 2048^2 1 sample", memory = "peak memory 1M tris 2048^2";
  if (m1 && p.nm.ok()) {
    run.add_target(wall, "<= 0.7 s", fmt("%.2f s", median(p.nm.wall)) + of, median(p.nm.wall) <= 0.7);
  } else if (m1) {
    run.skip_target(wall, "<= 0.7 s", "nmbake failed");
  }
  const std::string what = std::string("nmbake vs Blender, ") + (m1 ? "1M" : "4M") + " tris 2048^2";
  if (p.nm.ok() && p.bl.ok()) {
    const double ratio = median(p.bl.wall) / median(p.nm.wall);
    run.add_target(what, ">= 15x",
                   fmt("%.1fx", ratio) + fmt(" (Blender %.2f s", median(p.bl.wall)) + fmt(" / nmbake %.2f s", median(p.nm.wall)) +
                       ", medians of " + rounds + ")",
                   ratio >= 15.0);
  } else {
    run.skip_target(what, ">= 15x", !p.nm.ok() ? "nmbake failed" : !no_blender.empty() ? no_blender : "Blender failed");
  }
  if (m1 && p.nm.ok()) {
    run.add_target(memory, "<= 320 MiB", fmt("%.0f MiB max RSS", median(p.nm.rss)) + of, median(p.nm.rss) <= 320.0);
  } else if (m1) {
    run.skip_target(memory, "<= 320 MiB", "nmbake failed");
  }
}

}  // namespace

std::string blender_script() { return std::string(nmbake::build::source_dir()) + "/bench/blender_bake.py"; }

bool run_side(const BenchRun& run, Side& side, const std::vector<std::string>& command, const std::string& log) {
  if (!side.failed.empty()) return false;
  const Measured m = measure(command, log);
  if (m.ok) {
    side.wall.push_back(m.wall);
    side.rss.push_back(m.rss_mib);
    return true;
  }
  const std::string kept = run.args.scratch + "/" + fs::path(log).filename().string();
  std::error_code ec;
  fs::copy_file(log, kept, fs::copy_options::overwrite_existing, ec);
  side.failed = m.why + "; log: " + (ec ? log : kept);
  return false;
}

std::string find_blender(std::string& why) {
  const char* env = std::getenv("NMBAKE_BLENDER");
  const std::string name = env && *env ? env : "blender";
  auto executable = [](const std::string& p) { return fs::is_regular_file(p) && ::access(p.c_str(), X_OK) == 0; };
  if (name.find('/') != std::string::npos) {
    if (executable(name)) return name;
    why = "NMBAKE_BLENDER=" + name + " is not an executable";
    return "";
  }
  const char* path = std::getenv("PATH");
  std::stringstream dirs(path ? path : "");
  for (std::string dir; std::getline(dirs, dir, ':');)
    if (!dir.empty() && executable(dir + "/" + name)) return dir + "/" + name;
  why = env && *env ? "NMBAKE_BLENDER=" + name + " is not on PATH" : "no `blender` on PATH and NMBAKE_BLENDER not set";
  return "";
}

Measured measure(const std::vector<std::string>& command, const std::string& log) {
  Measured m;
  std::vector<std::string> args = {self_exe(), kMeasureChild};
  args.insert(args.end(), command.begin(), command.end());
  posix_spawn_file_actions_t actions;
  posix_spawn_file_actions_init(&actions);
  posix_spawn_file_actions_addopen(&actions, 0, "/dev/null", O_RDONLY, 0);
  posix_spawn_file_actions_addopen(&actions, 1, log.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_APPEND, 0644);
  posix_spawn_file_actions_adddup2(&actions, 1, 2);
  pid_t pid = 0;
  std::vector<char*> argv = c_argv(args);
  const int e = posix_spawn(&pid, argv[0], &actions, nullptr, argv.data(), environ);
  posix_spawn_file_actions_destroy(&actions);
  if (e != 0) {
    m.why = std::string("cannot start the measuring helper: ") + std::strerror(e);
    return m;
  }
  int helper_status = 0;
  while (waitpid(pid, &helper_status, 0) < 0 && errno == EINTR) {
  }
  std::ifstream in(log);
  int status = -1;
  long rss_kib = 0;
  for (std::string line; std::getline(in, line);)
    if (line.rfind(kMeasured, 0) == 0)
      std::sscanf(line.c_str() + std::strlen(kMeasured), " status %d wall %lf maxrss_kib %ld", &status, &m.wall, &rss_kib);
  if (status == -1) {
    m.why = "no figures from the measuring helper (" + describe_status(helper_status) + ")";
    return m;
  }
  m.rss_mib = double(rss_kib) / 1024.0;
  m.ok = WIFEXITED(status) && WEXITSTATUS(status) == 0;
  if (!m.ok) m.why = describe_status(status);
  return m;
}

int measure_child(char** argv) {
  if (!argv[0]) return 2;
  const auto t0 = Clock::now();
  // fork, not posix_spawn: a vfork child's ru_maxrss starts from this process's peak (its shared
  // libraries, about 130 MiB), a forked child's only from the anonymous pages it copies.
  const pid_t pid = ::fork();
  if (pid == 0) {
    ::execvp(argv[0], argv);
    std::fprintf(stderr, "bench: cannot start %s: %s\n", argv[0], std::strerror(errno));
    ::_exit(127);
  }
  if (pid < 0) {
    std::fprintf(stderr, "bench: cannot fork: %s\n", std::strerror(errno));
    return 127;
  }
  int status = 0;
  rusage ru{};
  while (wait4(pid, &status, 0, &ru) < 0 && errno == EINTR) {
  }
  const double wall = since(t0);
  // ru_maxrss: KiB on Linux; a line of its own even when the command's output ends without one.
  std::printf("\n%s status %d wall %.6f maxrss_kib %ld\n", kMeasured, status, wall, static_cast<long>(ru.ru_maxrss));
  return WIFEXITED(status) ? WEXITSTATUS(status) : 1;
}

// 10. Blender side by side.
void run_blender(BenchRun& run, const Scenes& scenes) {
  const Args& args = run.args;
  std::printf("## 10. Blender side by side (the whole nmbake command against Blender's Cycles bake of the same pair)\n\n");
  std::string no_blender;
  std::string blender = find_blender(no_blender);
  if (!blender.empty() && !fs::exists(blender_script())) {
    no_blender = blender_script() + " not found";
    blender.clear();
  }
  std::string name = "Blender";
  if (blender.empty()) {
    std::printf("Blender is not installed (%s): nmbake's figures alone.\n\n", no_blender.c_str());
  } else {
    const std::string version = command_output("'" + blender + "' -b --factory-startup --version 2>/dev/null | head -1");
    name = (version.empty() ? "Blender" : version) + " Cycles";
    std::printf(
        "suz_L4 low.obj onto each high-poly, 2048^2 8-bit .png, 1 sample, every core. nmbake: `nmbake LOW HIGH -o OUT.png --size "
        "2048 --quiet` (automatic cage). Blender (%s): `blender -b --factory-startup --python bench/blender_bake.py -- LOW HIGH "
        "OUT.png 2048 1 %s` (selected-to-active NORMAL bake, tangent space, fixed cage extrusion %s, margin 16).\n\n",
        blender.c_str(), kBlenderExtrusion, kBlenderExtrusion);
  }
  const Measured floor = measure({"true"}, run.run_dir + "/floor.log");
  std::printf(
      "Each command is one process, wall time and max RSS from wait4 (not nmbake's report); %d round%s%s; the figures "
      "are medians. Max RSS floor of the measurement (`true` measured the same way): %s. Load "
      "average %s.\n\n",
      args.rounds, args.rounds == 1 ? "" : "s", blender.empty() ? "" : ", alternated nmbake, Blender, nmbake, ...",
      floor.ok ? fmt("%.0f MiB", floor.rss_mib).c_str() : floor.why.c_str(), load_average().c_str());
  std::printf("| scene | command | median wall s | median max RSS MiB | per round wall s |\n|---|---|---|---|---|\n");
  flush();
  std::vector<Pair> pairs;
  pairs.push_back(measure_pair(run, scenes, blender, "suz_L4_x4 (1M)", scenes.m1_ply, "m1"));
  print_pair(pairs.back(), name, !blender.empty());
  judge(run, pairs.back(), true, no_blender);
  if (!args.quick) {
    pairs.push_back(measure_pair(run, scenes, blender, "suz_L4_x16 (4M)", scenes.m4_ply, "m4"));
    print_pair(pairs.back(), name, !blender.empty());
    judge(run, pairs.back(), false, no_blender);
  } else {
    run.skip_target("nmbake vs Blender, 4M tris 2048^2", ">= 15x", "--quick");
  }
  std::printf("\n");
  bool split = false;
  for (const Pair& p : pairs) split |= print_split(p);
  if (split) std::printf("\n");
  flush();
}

}  // namespace nmbake::bench
