// The nmbake program's operator new: blocks of 4 MiB and more on transparent huge pages.
//
// A bake's big arrays (the meshes as read, the prepared positions and normals, the welds' keys,
// the texel lists) are allocated fresh, each one its own mmap in glibc, and first touched by the
// stage that fills them: one page fault per 4 KiB. Where the kernel leaves huge pages to the
// program's asking (transparent_hugepage "madvise", as here and on Ubuntu), those faults were a
// fifth of a 4M-triangle bake's CPU on this VM, and they scale badly with threads (the faults of a
// process share its memory map's locks): load, prepare and the BVH build ran at 2 threads about
// as long as at 1. Asked for huge pages (madvise MADV_HUGEPAGE on the block's whole 2 MiB pages,
// before anything touches them), a 2 MiB page costs one fault. Embree's own blocks are asked for
// through its device ("hugepages=1", raycast/). Measured (docs/bench.md, issue 38 item 1): the 4M
// bake at 2048^2, 2 threads, 3.3 -> 2.0 s; maps unchanged (memory placement changes no value).
// The blocks start on a 2 MiB boundary (posix_memalign; glibc maps them, as the others, and frees
// them with free), so that all of a block but its last partial 2 MiB is advised: from malloc's
// address (16 bytes into a 4 KiB page) a 4 MiB block held one whole huge page, not two, and the
// rest took 4 KiB faults. Measured: the 4M bake's page faults 29.0k -> 20.7k, wall 0.94x (1M 0.93x)
// at the same peak memory (+0.4 MiB at 1M).
//
// Replacing the global operator new is standard C++ ([new.delete.single]); this one allocates with
// malloc as libstdc++'s does, so its operator delete (free) stays right. Only the nmbake program
// links this file (not the libraries, the tests or the Python module), and not under the address
// sanitizer, whose own operator new checks new against delete.
#include <malloc.h>
#include <sys/mman.h>

#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <new>

#if defined(__SANITIZE_ADDRESS__)
#define NMBAKE_LARGE_PAGES 0
#elif defined(__has_feature)
#if __has_feature(address_sanitizer)
#define NMBAKE_LARGE_PAGES 0
#endif
#endif
#ifndef NMBAKE_LARGE_PAGES
#define NMBAKE_LARGE_PAGES 1
#endif

#if NMBAKE_LARGE_PAGES
namespace {

constexpr std::size_t kHugePage = std::size_t(2) << 20;
constexpr std::size_t kLarge = std::size_t(4) << 20;  // blocks this big and up are advised

// Every block from kLarge up is a fresh mapping of its own (glibc's threshold otherwise rises to the
// size of the last block freed, and later blocks come from reused heap memory, advised piecemeal).
[[maybe_unused]] const int kMmapThreshold = ::mallopt(M_MMAP_THRESHOLD, int(kLarge));

// The whole 2 MiB pages inside [p, p + n).
void advise_huge_pages(void* p, std::size_t n) {
  const auto a = reinterpret_cast<std::uintptr_t>(p);
  const std::uintptr_t begin = (a + kHugePage - 1) & ~(kHugePage - 1);
  const std::uintptr_t end = (a + n) & ~(kHugePage - 1);
  if (end > begin) ::madvise(reinterpret_cast<void*>(begin), end - begin, MADV_HUGEPAGE);  // only a hint
}

}  // namespace

void* operator new(std::size_t n) {
  for (;;) {
    void* p = nullptr;
    if (n < kLarge) p = std::malloc(n ? n : 1);
    else if (::posix_memalign(&p, kHugePage, n) == 0) advise_huge_pages(p, n);
    else p = nullptr;
    if (p) return p;
    const std::new_handler handler = std::get_new_handler();
    if (!handler) throw std::bad_alloc();
    handler();
  }
}
#endif
