#pragma once
// The build's absolute paths, for the tests and bench programs that run binaries or read data.
// Each target defines the ones it uses through nmbake_build_paths() (cmake/NmbakeRelocatable.cmake),
// in a generated file: -D definitions would put the checkout's path in every compile command of
// the target and defeat the compiler cache in a fresh clone.
namespace nmbake::build {

const char* data_dir();         // the checkout's data/
const char* shared_data_dir();  // the shared meshes (NMBAKE_SHARED_DATA_DIR, NMBAKE_SHARED_DATA)
const char* binary_dir();       // the top of the build folder
const char* source_dir();       // the checkout
const char* nmbake_exe();
const char* nmview_exe();  // "" when the viewer is not built

}  // namespace nmbake::build
