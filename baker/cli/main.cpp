// nmbake: the command (cli/command.h).
#include "cli/command.h"
#include "io/output_files.h"

int main(int argc, char** argv) {
  // A closed or full stdout or stderr loses messages, never changes the outputs or the exit status;
  // a file past ulimit -f is a failed write (exit 3), not a SIGXFSZ death.
  nmbake::protect_standard_streams();
  return nmbake::nmbake_command(argc, argv);
}
