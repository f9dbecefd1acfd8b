// A float image in memory: row 0 is the top of the picture, channels interleaved.
// Normal maps hold encoded values c = n * 0.5 + 0.5 in [0, 1].
#pragma once

#include <cstddef>
#include <algorithm>
#include <cstdint>
#include <memory>
#include <new>
#include <utility>
#include <vector>

#include <glm/vec3.hpp>

#if defined(__linux__)
#include <sys/mman.h>
#endif

namespace nmbake {

// std::allocator, except that a vector's new elements are default-initialized (for float: left
// as they are) where std::allocator value-initializes them (zeroes them).
template <typename T>
struct DefaultInitAllocator : std::allocator<T> {
  template <typename U>
  struct rebind {
    using other = DefaultInitAllocator<U>;
  };
  DefaultInitAllocator() = default;
  template <typename U>
  DefaultInitAllocator(const DefaultInitAllocator<U>&) noexcept {}
  template <typename U>
  void construct(U* p) noexcept {
    ::new (static_cast<void*>(p)) U;
  }
  template <typename U, typename... Args>
  void construct(U* p, Args&&... args) {
    ::new (static_cast<void*>(p)) U(std::forward<Args>(args)...);
  }
};

struct Image {
  int width = 0;
  int height = 0;
  int channels = 0;
  using Pixels = std::vector<float, DefaultInitAllocator<float>>;
  Pixels pixels;  // width * height * channels, row-major from the top row

  Image() = default;
  Image(int w, int h, int c, float fill = 0.0f) : Image(w, h, c, Unset{}) { std::fill(pixels.begin(), pixels.end(), fill); }
  // Pixels left unset, for a caller that writes every one before reading any: a large map is not
  // written twice (the memory comes from the system zeroed anyway).
  struct Unset {};
  Image(int w, int h, int c, Unset) : width(w), height(h), channels(c) {
    const std::size_t n = static_cast<std::size_t>(w) * h * c;
    pixels.reserve(n);
    advise_huge_pages(pixels.data(), n * sizeof(float));
    pixels.resize(n);
  }

  float* at(int x, int y) { return &pixels[(static_cast<std::size_t>(y) * width + x) * channels]; }
  const float* at(int x, int y) const { return &pixels[(static_cast<std::size_t>(y) * width + x) * channels]; }

 private:
  // A map of a few MiB or more is written once, texel by texel: backed by 2 MiB pages where the
  // system allows it (transparent huge pages in "madvise" mode), it takes one page fault per 2 MiB
  // instead of per 4 KiB. Only a hint: nothing changes where it is not granted.
  static void advise_huge_pages(void* data, std::size_t bytes) {
#if defined(__linux__) && defined(MADV_HUGEPAGE)
    constexpr std::uintptr_t kHuge = std::uintptr_t(2) << 20;
    const std::uintptr_t lo = (reinterpret_cast<std::uintptr_t>(data) + kHuge - 1) & ~(kHuge - 1);
    const std::uintptr_t hi = (reinterpret_cast<std::uintptr_t>(data) + bytes) & ~(kHuge - 1);
    if (hi > lo) madvise(reinterpret_cast<void*>(lo), hi - lo, MADV_HUGEPAGE);
#else
    (void)data;
    (void)bytes;
#endif
  }
};

// The entry a value of an image of palette indices names among `size` colours: k (1 .. size) for
// the colour palette[k - 1], 0 for black (0, a value out of range, NaN). Values are rounded to the
// nearest entry.
inline std::size_t palette_entry(float value, std::size_t size) {
  const double v = double(value);
  return v >= 0.5 && v < double(size) + 0.5 ? std::size_t(v + 0.5) : 0;
}

// An image of palette indices (1 channel, palette_entry) as the RGB image it stands for: how the
// ID maps are held until written (BakedMap::image, WriteOptions::palette).
inline Image expand_palette(const Image& index, const std::vector<glm::vec3>& palette) {
  Image out(index.width, index.height, 3, Image::Unset{});
  const std::size_t n = std::size_t(index.width) * std::size_t(index.height);
  for (std::size_t i = 0; i < n; ++i) {
    const std::size_t k = palette_entry(index.pixels[i], palette.size());
    const glm::vec3 c = k ? palette[k - 1] : glm::vec3(0.0f);
    for (int ch = 0; ch < 3; ++ch) out.pixels[3 * i + std::size_t(ch)] = c[ch];
  }
  return out;
}

}  // namespace nmbake
