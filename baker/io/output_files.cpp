#include "io/output_files.h"

#include <dirent.h>
#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <atomic>
#include <cerrno>
#include <climits>
#include <csignal>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <system_error>

#include "core/errors.h"

namespace nmbake {
namespace {

namespace fs = std::filesystem;

const char* const kTempTag = ".nmbake-tmp.";
const char* const kOldTag = ".nmbake-old.";  // as long as kTempTag
constexpr std::size_t kPidDigits = 7;        // Linux pids stay below 2^22 (4194304)

std::string folder_of(const std::string& path) {
  const fs::path dir = fs::path(path).parent_path();
  return dir.empty() ? std::string(".") : dir.string();
}

// The file an output replaces: the path itself, or the file a symbolic link to a regular file
// names (written through, like cp).
std::string target_of(const std::string& path) {
  struct stat st {};
  if (::lstat(path.c_str(), &st) != 0 || !S_ISLNK(st.st_mode)) return path;
  std::error_code ec;
  const fs::path real = fs::canonical(path, ec);
  return ec ? path : real.string();
}

std::string sibling(const std::string& target, const char* tag) {
  const fs::path p(target);
  return (p.parent_path() / ("." + p.filename().string() + tag + std::to_string(::getpid()))).string();
}

const char* kind_of(mode_t mode) {
  if (S_ISCHR(mode)) return "a character device";
  if (S_ISBLK(mode)) return "a block device";
  if (S_ISFIFO(mode)) return "a FIFO (named pipe)";
  if (S_ISSOCK(mode)) return "a socket";
  return "not a regular file";
}

// The temporaries a signal handler removes (remove_temporaries_on_signals): fixed storage, as a
// handler may only read memory and call unlink. A slot is free when its first byte is 0, which is
// written last when a name is stored and first when it is forgotten.
constexpr int kSignalSlots = 32;
char g_signal_temps[kSignalSlots][PATH_MAX];
volatile std::sig_atomic_t g_committing = 0;  // the renames have begun: the set is finished

void remember_temp(const std::string& temp) {
  if (temp.empty() || temp.size() >= PATH_MAX) return;
  for (char* slot : g_signal_temps) {
    if (slot[0] != 0) continue;
    std::memcpy(slot + 1, temp.c_str() + 1, temp.size());
    std::atomic_signal_fence(std::memory_order_release);
    slot[0] = temp[0];
    return;
  }
}

void forget_temp(const std::string& temp) {
  for (char* slot : g_signal_temps)
    if (slot[0] != 0 && temp == slot) slot[0] = 0;
}

extern "C" void remove_temporaries_and_die(int sig) {
  if (g_committing) return;  // the renames take microseconds: the run completes
  for (char* slot : g_signal_temps)
    if (slot[0] != 0) ::unlink(slot);
  ::signal(sig, SIG_DFL);
  ::raise(sig);
}

// Marks the renames of a commit, also when it throws.
struct Committing {
  Committing() { g_committing = 1; }
  ~Committing() { g_committing = 0; }
};

// Identity of a path: device and inode where it exists, else its canonical absolute name.
struct FileKey {
  bool exists = false;
  dev_t dev = 0;
  ino_t ino = 0;
  std::string name;
};

FileKey key_of(const std::string& path) {
  FileKey k;
  struct stat st {};
  if (::stat(path.c_str(), &st) == 0) {
    k.exists = true;
    k.dev = st.st_dev;
    k.ino = st.st_ino;
    return k;
  }
  std::error_code ec;
  k.name = fs::weakly_canonical(fs::absolute(path, ec), ec).string();
  if (ec) k.name = fs::absolute(path, ec).lexically_normal().string();
  return k;
}

bool same_key(const FileKey& a, const FileKey& b) {
  if (a.exists != b.exists) return false;
  return a.exists ? a.dev == b.dev && a.ino == b.ino : a.name == b.name;
}

// What is at the output path, followed through symbolic links: refused unless nothing or a
// regular file.
void check_kind(const NamedFile& out) {
  const std::string head = out.path + ": cannot write " + out.what + ": ";
  struct stat link {};
  if (::lstat(out.path.c_str(), &link) != 0) return;  // nothing there yet
  struct stat st {};
  const bool is_link = S_ISLNK(link.st_mode);
  if (::stat(out.path.c_str(), &st) != 0) {
    if (is_link) throw OutputError(head + "it is a symbolic link to a missing file");
    return;
  }
  if (S_ISDIR(st.st_mode)) throw OutputError(head + "it is a directory");
  if (S_ISREG(st.st_mode)) return;
  std::string what = kind_of(st.st_mode);
  if (is_link) {
    std::error_code ec;
    what = std::string("a symbolic link to ") + what + " (" + fs::canonical(out.path, ec).string() + ")";
  }
  throw OutputError(head + "it is " + what + "; " + program_invocation_short_name + " writes only regular files");
}

// The folder of the file replaced must exist and be writable, and its name leave room for the
// temporary's.
void check_place(const NamedFile& out) {
  const std::string head = out.path + ": cannot write " + out.what + ": ";
  const std::string target = target_of(out.path);
  const std::string dir = folder_of(target);
  std::error_code ec;
  if (!fs::is_directory(dir, ec)) throw OutputError(head + "folder " + dir + " does not exist");
  if (::access(dir.c_str(), W_OK) != 0) throw OutputError(head + "folder " + dir + " is not writable");
  long name_max = ::pathconf(dir.c_str(), _PC_NAME_MAX);
  if (name_max <= 0) name_max = 255;
  const std::size_t name = fs::path(target).filename().string().size();
  const std::size_t room =
      std::size_t(name_max) - std::min<std::size_t>(std::size_t(name_max), 1 + std::strlen(kTempTag) + kPidDigits);
  if (name > std::size_t(name_max))
    throw OutputError(head + "its name is " + std::to_string(name) + " bytes long, more than the folder allows (" +
                      std::to_string(name_max) + ")");
  if (name > room)
    throw OutputError(head + "its name is " + std::to_string(name) + " bytes long, more than the " + std::to_string(room) +
                      " that leave room for its temporary file (the folder allows " + std::to_string(name_max) + ")");
}

// Removes ".<name>.nmbake-tmp.<pid>" beside `target` whose process no longer exists, and its
// ".<name>.nmbake-old.<pid>" where that is only a second name of `target` (a run killed during
// commit). An old copy that differs from `target` is kept: it is the only copy of an old output,
// left by a commit whose renames failed and could not be undone, and that run's error named it.
void remove_stale(const std::string& target) {
  const std::string dir = folder_of(target);
  const std::string name = "." + fs::path(target).filename().string();
  DIR* d = ::opendir(dir.c_str());
  if (!d) return;
  while (const dirent* e = ::readdir(d)) {
    const std::string entry = e->d_name;
    if (entry.compare(0, name.size(), name) != 0) continue;
    const std::string rest = entry.substr(name.size());
    if (rest.compare(0, std::strlen(kTempTag), kTempTag) != 0 && rest.compare(0, std::strlen(kOldTag), kOldTag) != 0) continue;
    const std::string number = rest.substr(std::strlen(kTempTag));
    if (number.empty() || number.size() > 9 || number.find_first_not_of("0123456789") != std::string::npos) continue;
    const long pid = std::stol(number);
    if (pid == long(::getpid()) || pid <= 0) continue;
    if (::kill(pid_t(pid), 0) == 0 || errno != ESRCH) continue;  // alive (or not ours to ask)
    const std::string path = dir + "/" + entry;
    if (rest.compare(0, std::strlen(kOldTag), kOldTag) == 0) {
      struct stat old {
      }, now{};
      if (::stat(path.c_str(), &old) != 0 || ::stat(target.c_str(), &now) != 0 || old.st_dev != now.st_dev ||
          old.st_ino != now.st_ino)
        continue;
    }
    ::unlink(path.c_str());
  }
  ::closedir(d);
}

}  // namespace

bool same_file(const std::string& a, const std::string& b) { return same_key(key_of(a), key_of(b)); }

void check_output_files(const std::vector<NamedFile>& inputs, const std::vector<NamedFile>& outputs) {
  std::vector<std::pair<const NamedFile*, FileKey>> seen;
  for (const NamedFile& in : inputs)
    if (!in.path.empty()) seen.emplace_back(&in, key_of(in.path));
  for (const NamedFile& out : outputs) {
    if (out.path.empty()) continue;
    FileKey key = key_of(out.path);
    for (const auto& [other, other_key] : seen)
      if (same_key(key, other_key))
        throw UsageError(out.option + " " + out.path + " is the same file as " + other->path + "; nothing written");
    seen.emplace_back(&out, std::move(key));
  }
  for (const NamedFile& out : outputs) {
    if (out.path.empty()) continue;
    check_kind(out);
    check_place(out);
  }
}

OutputFiles::~OutputFiles() { discard(); }

std::string OutputFiles::add(const std::string& path) {
  File f;
  f.path = path;
  f.target = target_of(path);
  f.temp = sibling(f.target, kTempTag);
  remove_stale(f.target);
  files_.push_back(f);
  remember_temp(f.temp);
  return f.temp;
}

void OutputFiles::discard() {
  if (committed_) return;
  for (const File& f : files_) {
    forget_temp(f.temp);
    ::unlink(f.temp.c_str());
    if (!f.backup.empty()) ::unlink(f.backup.c_str());
  }
  files_.clear();
}

void OutputFiles::commit() {
  const Committing committing;
  // The old files stay reachable under a second name (a hard link) until every rename is done,
  // so a failed rename can put them back. The new file keeps the old one's permissions.
  for (File& f : files_) {
    struct stat st {};
    if (::stat(f.target.c_str(), &st) != 0 || !S_ISREG(st.st_mode)) continue;
    ::chmod(f.temp.c_str(), st.st_mode & 07777);
    const std::string backup = sibling(f.target, kOldTag);
    ::unlink(backup.c_str());
    if (::link(f.target.c_str(), backup.c_str()) == 0) f.backup = backup;
  }
  for (std::size_t i = 0; i < files_.size(); ++i) {
    if (std::rename(files_[i].temp.c_str(), files_[i].target.c_str()) == 0) continue;
    std::string message = files_[i].path + ": cannot write: " + std::strerror(errno);
    for (std::size_t j = 0; j < i; ++j) {
      File& done = files_[j];
      if (done.backup.empty()) {
        ::unlink(done.target.c_str());
      } else if (std::rename(done.backup.c_str(), done.target.c_str()) == 0) {
        done.backup.clear();
      } else {
        message += "; the old " + done.path + " is kept as " + done.backup;
        done.backup.clear();  // not removed: the only copy
      }
    }
    discard();
    throw OutputError(message);
  }
  for (const File& f : files_) {
    forget_temp(f.temp);
    if (!f.backup.empty()) ::unlink(f.backup.c_str());
  }
  committed_ = true;
  files_.clear();
}

void protect_standard_streams() {
  std::signal(SIGPIPE, SIG_IGN);
  std::signal(SIGXFSZ, SIG_IGN);
  for (int fd = 0; fd <= 2; ++fd) {
    if (::fcntl(fd, F_GETFD) != -1 || errno != EBADF) continue;
    // The lowest free number: `fd` itself, the ones below it being open by now.
    const int null = ::open("/dev/null", fd == 0 ? O_RDONLY : O_WRONLY);
    if (null >= 0 && null != fd) {
      ::dup2(null, fd);
      ::close(null);
    }
  }
}

void remove_temporaries_on_signals() {
  struct sigaction action {};
  action.sa_handler = remove_temporaries_and_die;
  sigemptyset(&action.sa_mask);
  for (int sig : {SIGINT, SIGTERM, SIGHUP}) {
    struct sigaction old {};
    // Ignored on entry (nohup; SIGINT of a background job) stays ignored.
    if (::sigaction(sig, nullptr, &old) == 0 && old.sa_handler == SIG_IGN) continue;
    ::sigaction(sig, &action, nullptr);
  }
}

}  // namespace nmbake
