// Helpers of the load_mesh() tests (test_mesh_io*.cpp): the message of a refused file, and files
// written by a test.
#pragma once

#include <fstream>
#include <initializer_list>
#include <string>

#include <gtest/gtest.h>

#include "core/errors.h"
#include "io/mesh_io.h"
#include "test_support.h"

// Skips the test when ../shared/data is absent.
#define SKIP_WITHOUT_SHARED_DATA()                                         \
  if (!::nmbake::test::exists(::nmbake::test::shared_data_path("meshes"))) \
  GTEST_SKIP() << "../shared/data is absent (" << ::nmbake::test::shared_data_path("meshes") << "); skipping"

namespace nmbake::mesh_io_test {

inline std::string file_name(const std::string& path) { return path.substr(path.find_last_of('/') + 1); }

// The InputError message of loading `path`, or "" (plus a test failure) when it loads.
inline std::string load_error(const std::string& path, const LoadOptions& options = {}) {
  try {
    Mesh m = load_mesh(path, options);
    ADD_FAILURE() << path << " loaded (" << m.triangle_count() << " triangles) but should fail";
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

inline void expect_error(const std::string& path, std::initializer_list<const char*> words, const LoadOptions& options = {}) {
  std::string message = load_error(path, options);
  EXPECT_NE(message.find(file_name(path)), std::string::npos) << message;
  EXPECT_EQ(message.find('\n'), std::string::npos) << "not one line: " << message;
  for (const char* word : words) EXPECT_NE(message.find(word), std::string::npos) << "'" << word << "' not in: " << message;
}

inline void write_file(const std::string& path, const std::string& bytes) { std::ofstream(path, std::ios::binary) << bytes; }

}  // namespace nmbake::mesh_io_test
