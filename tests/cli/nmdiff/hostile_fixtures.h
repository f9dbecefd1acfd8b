// Hostile and convention-carrying inputs of the nmdiff command-line tests (hostile_fixtures.cpp).
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>

// A PNG header for width x height RGB 8-bit whose pixel data is `idat_bytes` zero bytes (not a
// valid stream: a reader must refuse the file before it reads any of it).
void write_png_header(const std::string& path, std::uint32_t width, std::uint32_t height, std::size_t idat_bytes);

// Writes them into `dir`; throws std::runtime_error when one cannot be made.
void write_hostile_fixtures(const std::string& dir);
