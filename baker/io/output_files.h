// The output contract of the three commands (nmbake, nmdiff, nmview): output files checked
// before any work, each written to a temporary file beside it, and renamed into place together
// only when every one is complete.
//
// A failed write (a full disk, EFBIG under ulimit -f), an interruption or an error leaves every
// old file as it was and no temporary behind. Temporaries are named ".<name>.nmbake-tmp.<pid>"
// (and, while the set is renamed into place, the old file is kept as ".<name>.nmbake-old.<pid>"),
// so that those of a killed run can be recognised: the next run removes its own outputs' ones
// whose process no longer exists.
#pragma once

#include <string>
#include <vector>

namespace nmbake {

// A file named on the command line: its option ("--report"; "" for positional inputs), the path
// as given, and what it holds ("the report"; used in messages).
struct NamedFile {
  std::string option, path, what;
};

// Refuses outputs that would destroy data or could not be written, before any work (empty paths
// are skipped):
// - UsageError (nmbake and nmview exit 1, nmdiff 2) when an output is the same file as an input or as another output, by
//   identity (device and inode where the file exists, so links and "./" do not slip through; the
//   canonical folder and name where it does not yet): "--report low.obj is the same file as
//   low.obj; nothing written";
// - OutputError (exit 3) when an output is a folder, a special file (device, FIFO, socket, or a
//   symbolic link to one), a symbolic link to nothing, in a missing or read-only folder, or has a
//   name too long for its temporary file (NAME_MAX).
// A symbolic link to a regular file is written through, as cp does: the link stays, its target
// gets the new contents (the temporary is made beside the target).
void check_output_files(const std::vector<NamedFile>& inputs, const std::vector<NamedFile>& outputs);

// Whether two paths name one file (see check_output_files).
bool same_file(const std::string& a, const std::string& b);

class OutputFiles {
 public:
  OutputFiles() = default;
  OutputFiles(const OutputFiles&) = delete;
  OutputFiles& operator=(const OutputFiles&) = delete;
  ~OutputFiles();  // removes the temporaries of a set not committed

  // The temporary file to write `path` to. Removes stale temporaries of `path` left by killed runs.
  std::string add(const std::string& path);

  // Renames every temporary over its output (the renames take microseconds: a signal after the
  // first leaves the set finished). When a rename fails, the outputs already renamed get their old
  // files back and OutputError names the file.
  void commit();

  // Removes every temporary (also done by the destructor). Safe to call more than once.
  void discard();

 private:
  struct File {
    std::string path;    // as given (messages)
    std::string target;  // the file replaced: path, or the regular file a symbolic link names
    std::string temp, backup;
  };
  std::vector<File> files_;
  bool committed_ = false;
};

// What every command does first, so that its streams cannot break the contract:
// - SIGPIPE and SIGXFSZ ignored: a closed pipe is a failed write (EPIPE), a file past ulimit -f
//   a failed write (EFBIG) that the writers turn into OutputError, its temporary removed;
// - a closed stdin, stdout or stderr (>&-) reopened on /dev/null, so that no output file gets its
//   number and receives the messages.
// A message that cannot be written to stdout or stderr (closed, full, a pipe closed by its reader)
// is lost and changes nothing else: the exit status and the files are those of the work done.
void protect_standard_streams();

// For a command without its own handlers (nmdiff, nmview; nmbake records the signal and stops at
// its next check): SIGINT, SIGTERM and SIGHUP remove the temporaries of every set not committed,
// then end the process as the signal would; during a commit's renames they are ignored, the set is
// finished. A signal ignored on entry (nohup) stays ignored.
void remove_temporaries_on_signals();

}  // namespace nmbake
