// nmdiff's program: the command (command.h) with its streams protected and its temporary files
// removed on a signal.
#include "command.h"
#include "io/output_files.h"

int main(int argc, char** argv) {
  nmbake::protect_standard_streams();
  nmbake::remove_temporaries_on_signals();
  return nmbake::nmdiff_command(argc, argv);
}
