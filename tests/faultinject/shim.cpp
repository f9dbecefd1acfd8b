// A fault-injection shim for the output tests, loaded with LD_PRELOAD: the Nth call of one kind of
// file operation or allocation fails with a chosen errno.
//
//   NMBAKE_FAULT=KIND:N:ERRNO     the Nth call of KIND fails (counted from 1), the others run
//   NMBAKE_FAULT=KIND:N+:ERRNO    the Nth call and every later one fail (a disk that stays full)
//   NMBAKE_FAULT_COUNT=FILE       at exit, writes "KIND COUNT" lines: the calls of each kind made
//
// KIND is one of
//   write   write, writev, pwrite, pwrite64, fwrite on a regular file
//   close   close, fclose of a regular file
//   fsync   fsync, fdatasync
//   rename  rename, renameat, renameat2
//   create  open, open64, openat, openat64 with O_CREAT, creat, fopen/fopen64 for writing
//   alloc   malloc, calloc, realloc, posix_memalign, aligned_alloc, memalign, valloc, pvalloc and
//           anonymous mmap/mmap64 (Embree's and TBB's own pools) of at least NMBAKE_FAULT_MIN_BYTES
//           (default 65536): the buffers a bake sizes by its input, where memory really runs out
//           (operator new and std containers allocate through malloc). Smaller ones are not
//           counted: failing one inside a library's static constructor or the dynamic loader tests
//           those libraries, not nmbake. Nor is any allocation made inside dlopen (a loaded
//           library's constructors): an exception from one (libcharls throws std::bad_alloc)
//           cannot cross the loader and ends in std::terminate, whatever the program does.
// ERRNO is ENOSPC, EIO, EDQUOT, EROFS, EACCES or ENOMEM. Reads, and writes to terminals and pipes
// (stdout, stderr), are never counted: the tests need the command's messages.
// glibc's stdio writes through internal calls that no shim sees, so fwrite and fclose are covered
// here themselves.
#ifndef _GNU_SOURCE
#define _GNU_SOURCE
#endif
#include <dlfcn.h>
#include <fcntl.h>
#include <malloc.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/mman.h>
#include <sys/stat.h>
#include <sys/types.h>
#include <sys/uio.h>
#include <unistd.h>

#include <atomic>
#include <cerrno>

namespace {

enum Kind { kWrite, kClose, kFsync, kRename, kCreate, kAlloc, kKinds };
const char* const kNames[kKinds] = {"write", "close", "fsync", "rename", "create", "alloc"};

std::atomic<long> g_calls[kKinds];
int g_kind = -1;        // the kind that fails, -1 for none
long g_nth = 0;         // its call that fails
bool g_onward = false;  // and every later one
int g_errno = 0;
size_t g_min_bytes = 65536;  // allocations counted: this size and larger

template <typename F>
F real(const char* name) {
  return reinterpret_cast<F>(dlsym(RTLD_NEXT, name));
}

int parse_errno(const char* s) {
  if (!strcmp(s, "ENOSPC")) return ENOSPC;
  if (!strcmp(s, "EIO")) return EIO;
  if (!strcmp(s, "EDQUOT")) return EDQUOT;
  if (!strcmp(s, "EROFS")) return EROFS;
  if (!strcmp(s, "EACCES")) return EACCES;
  if (!strcmp(s, "ENOMEM")) return ENOMEM;
  return 0;
}

__attribute__((constructor)) void configure() {
  if (const char* min = getenv("NMBAKE_FAULT_MIN_BYTES"); min && *min) g_min_bytes = size_t(atoll(min));
  const char* spec = getenv("NMBAKE_FAULT");
  if (!spec || !*spec) return;
  char kind[16] = {0}, nth[24] = {0}, err[16] = {0};
  if (sscanf(spec, "%15[^:]:%23[^:]:%15s", kind, nth, err) != 3) return;
  for (int k = 0; k < kKinds; ++k)
    if (!strcmp(kind, kNames[k])) g_kind = k;
  g_onward = strchr(nth, '+') != nullptr;
  g_nth = atol(nth);
  g_errno = parse_errno(err);
  if (g_nth <= 0 || g_errno == 0) g_kind = -1;
}

__attribute__((destructor)) void report_counts() {
  const char* path = getenv("NMBAKE_FAULT_COUNT");
  if (!path || !*path) return;
  // The real calls: the shim's own output is not counted.
  static auto open_ = real<int (*)(const char*, int, ...)>("open");
  static auto write_ = real<ssize_t (*)(int, const void*, size_t)>("write");
  static auto close_ = real<int (*)(int)>("close");
  const int fd = open_(path, O_WRONLY | O_CREAT | O_TRUNC, 0644);
  if (fd < 0) return;
  char line[64];
  for (int k = 0; k < kKinds; ++k) {
    const int n = snprintf(line, sizeof line, "%s %ld\n", kNames[k], g_calls[k].load());
    if (write_(fd, line, size_t(n)) != n) break;
  }
  close_(fd);
}

bool regular_fd(int fd) {
  struct stat st;
  return fd >= 0 && fstat(fd, &st) == 0 && S_ISREG(st.st_mode);
}

// Counts a call of `kind`; true when it must fail (errno then set).
bool fault(Kind kind) {
  const long n = ++g_calls[kind];
  if (g_kind != int(kind) || !(n == g_nth || (g_onward && n > g_nth))) return false;
  errno = g_errno;
  return true;
}

thread_local int t_in_dlopen = 0;  // this thread is inside dlopen: its allocations are not counted

// An allocation of `bytes` is counted, and fails, only from g_min_bytes on, outside dlopen.
bool alloc_fault(size_t bytes) { return bytes >= g_min_bytes && !t_in_dlopen && fault(kAlloc); }

bool writing_mode(const char* mode) { return mode && (strchr(mode, 'w') || strchr(mode, 'a') || strchr(mode, '+')); }

}  // namespace

extern "C" {

ssize_t write(int fd, const void* buf, size_t n) {
  static auto f = real<ssize_t (*)(int, const void*, size_t)>("write");
  if (regular_fd(fd) && fault(kWrite)) return -1;
  return f(fd, buf, n);
}

ssize_t writev(int fd, const struct iovec* iov, int count) {
  static auto f = real<ssize_t (*)(int, const struct iovec*, int)>("writev");
  if (regular_fd(fd) && fault(kWrite)) return -1;
  return f(fd, iov, count);
}

ssize_t pwrite(int fd, const void* buf, size_t n, off_t offset) {
  static auto f = real<ssize_t (*)(int, const void*, size_t, off_t)>("pwrite");
  if (regular_fd(fd) && fault(kWrite)) return -1;
  return f(fd, buf, n, offset);
}

ssize_t pwrite64(int fd, const void* buf, size_t n, off64_t offset) {
  static auto f = real<ssize_t (*)(int, const void*, size_t, off64_t)>("pwrite64");
  if (regular_fd(fd) && fault(kWrite)) return -1;
  return f(fd, buf, n, offset);
}

size_t fwrite(const void* buf, size_t size, size_t count, FILE* stream) {
  static auto f = real<size_t (*)(const void*, size_t, size_t, FILE*)>("fwrite");
  if (stream && regular_fd(fileno(stream)) && fault(kWrite)) return 0;
  return f(buf, size, count, stream);
}

int close(int fd) {
  static auto f = real<int (*)(int)>("close");
  if (regular_fd(fd) && fault(kClose)) {
    const int saved = errno;
    f(fd);  // the descriptor is gone either way, as with a real failing close
    errno = saved;
    return -1;
  }
  return f(fd);
}

int fclose(FILE* stream) {
  static auto f = real<int (*)(FILE*)>("fclose");
  if (stream && regular_fd(fileno(stream)) && fault(kClose)) {
    const int saved = errno;
    f(stream);
    errno = saved;
    return EOF;
  }
  return f(stream);
}

int fsync(int fd) {
  static auto f = real<int (*)(int)>("fsync");
  if (fault(kFsync)) return -1;
  return f(fd);
}

int fdatasync(int fd) {
  static auto f = real<int (*)(int)>("fdatasync");
  if (fault(kFsync)) return -1;
  return f(fd);
}

int rename(const char* from, const char* to) {
  static auto f = real<int (*)(const char*, const char*)>("rename");
  if (fault(kRename)) return -1;
  return f(from, to);
}

int renameat(int from_dir, const char* from, int to_dir, const char* to) {
  static auto f = real<int (*)(int, const char*, int, const char*)>("renameat");
  if (fault(kRename)) return -1;
  return f(from_dir, from, to_dir, to);
}

int renameat2(int from_dir, const char* from, int to_dir, const char* to, unsigned flags) {
  static auto f = real<int (*)(int, const char*, int, const char*, unsigned)>("renameat2");
  if (fault(kRename)) return -1;
  return f(from_dir, from, to_dir, to, flags);
}

#define NMBAKE_SHIM_OPEN(name, ...)                              \
  int name(__VA_ARGS__, int flags, ...) {                        \
    static auto f = real<int (*)(__VA_ARGS__, int, ...)>(#name); \
    mode_t mode = 0;                                             \
    if (flags & (O_CREAT | __O_TMPFILE)) {                       \
      va_list ap;                                                \
      va_start(ap, flags);                                       \
      mode = mode_t(va_arg(ap, int));                            \
      va_end(ap);                                                \
      if (fault(kCreate)) return -1;                             \
    }                                                            \
    return NMBAKE_SHIM_CALL;                                     \
  }

#define NMBAKE_SHIM_CALL f(path, flags, mode)
NMBAKE_SHIM_OPEN(open, const char* path)
NMBAKE_SHIM_OPEN(open64, const char* path)
#undef NMBAKE_SHIM_CALL
#define NMBAKE_SHIM_CALL f(dir, path, flags, mode)
NMBAKE_SHIM_OPEN(openat, int dir, const char* path)
NMBAKE_SHIM_OPEN(openat64, int dir, const char* path)
#undef NMBAKE_SHIM_CALL

int creat(const char* path, mode_t mode) {
  static auto f = real<int (*)(const char*, mode_t)>("creat");
  if (fault(kCreate)) return -1;
  return f(path, mode);
}

FILE* fopen(const char* path, const char* mode) {
  static auto f = real<FILE* (*)(const char*, const char*)>("fopen");
  if (writing_mode(mode) && fault(kCreate)) return nullptr;
  return f(path, mode);
}

FILE* fopen64(const char* path, const char* mode) {
  static auto f = real<FILE* (*)(const char*, const char*)>("fopen64");
  if (writing_mode(mode) && fault(kCreate)) return nullptr;
  return f(path, mode);
}

void* dlopen(const char* file, int mode) {
  static auto f = real<void* (*)(const char*, int)>("dlopen");
  ++t_in_dlopen;
  void* handle = f(file, mode);
  --t_in_dlopen;
  return handle;
}

// The allocator: glibc's own entry points (__libc_*), not dlsym, which itself allocates.
void* __libc_malloc(size_t);
void* __libc_calloc(size_t, size_t);
void* __libc_realloc(void*, size_t);
void* __libc_memalign(size_t, size_t);

void* malloc(size_t n) {
  if (alloc_fault(n)) return nullptr;
  return __libc_malloc(n);
}

void* calloc(size_t count, size_t n) {
  if (n && count <= SIZE_MAX / n && alloc_fault(count * n)) return nullptr;
  return __libc_calloc(count, n);
}

void* realloc(void* p, size_t n) {
  if (alloc_fault(n)) return nullptr;  // p stays valid, as with a real failing realloc
  return __libc_realloc(p, n);
}

void* memalign(size_t alignment, size_t n) {
  if (alloc_fault(n)) return nullptr;
  return __libc_memalign(alignment, n);
}

void* aligned_alloc(size_t alignment, size_t n) { return memalign(alignment, n); }

void* valloc(size_t n) { return memalign(size_t(sysconf(_SC_PAGESIZE)), n); }

void* pvalloc(size_t n) {
  const size_t page = size_t(sysconf(_SC_PAGESIZE));
  return memalign(page, (n + page - 1) / page * page);
}

int posix_memalign(void** out, size_t alignment, size_t n) {
  if (alignment % sizeof(void*) != 0 || (alignment & (alignment - 1)) != 0) return EINVAL;
  if (alloc_fault(n)) return ENOMEM;
  void* p = __libc_memalign(alignment, n);
  if (!p) return ENOMEM;
  *out = p;
  return 0;
}

void* mmap(void* addr, size_t n, int prot, int flags, int fd, off_t offset) {
  static auto f = real<void* (*)(void*, size_t, int, int, int, off_t)>("mmap");
  if ((flags & MAP_ANONYMOUS) && alloc_fault(n)) return MAP_FAILED;
  return f(addr, n, prot, flags, fd, offset);
}

void* mmap64(void* addr, size_t n, int prot, int flags, int fd, off64_t offset) {
  static auto f = real<void* (*)(void*, size_t, int, int, int, off64_t)>("mmap64");
  if ((flags & MAP_ANONYMOUS) && alloc_fault(n)) return MAP_FAILED;
  return f(addr, n, prot, flags, fd, offset);
}

}  // extern "C"
