// LD_PRELOAD library for the output tests (tests/e2e/outputs.cmake, case io_faults): with
// PRIZMA_IO_FAULT set, one system call fails with EIO the way a dying disk or a full network
// file system makes it fail, so that the paths of write_atomically that no file-size limit reaches
// are exercised through the real executables:
//   fsync    fsync() of Prizma's temporaries (files named .prizma-tmp-*) fails
//   close    close() of a temporary closes it and then reports EIO (as NFS does for a lost write)
//   dirsync  fsync() of a folder fails (the rename is done, its durability is not)
//   rename2  the second rename() of a temporary into place fails (an OutputGroup's commit: the first
//            output, already renamed, must be put back)
// Everything else goes through to the C library unchanged.
#include <dlfcn.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstdio>
#include <cstdlib>
#include <cstring>

namespace {

int fault_is(const char* name) {
  const char* m = std::getenv("PRIZMA_IO_FAULT");
  return m != nullptr && std::strcmp(m, name) == 0;
}

int is_temporary(int fd) {
  char link[64];
  char target[4096];
  std::snprintf(link, sizeof link, "/proc/self/fd/%d", fd);
  const ssize_t n = readlink(link, target, sizeof target - 1);
  if (n <= 0) return 0;
  target[n] = '\0';
  const char* base = std::strrchr(target, '/');
  return base != nullptr && std::strncmp(base + 1, ".prizma-tmp-", 12) == 0;
}

int is_temporary_name(const char* path) {
  const char* base = std::strrchr(path, '/');
  return std::strncmp(base != nullptr ? base + 1 : path, ".prizma-tmp-", 12) == 0;
}

int is_directory(int fd) {
  struct stat st {};
  return fstat(fd, &st) == 0 && S_ISDIR(st.st_mode);
}

using fd_call = int (*)(int);

fd_call next_call(const char* name) {
  void* f = dlsym(RTLD_NEXT, name);
  if (f == nullptr) std::abort();
  fd_call call = nullptr;
  std::memcpy(&call, &f, sizeof call);
  return call;
}

}  // namespace

extern "C" int fsync(int fd) {
  static const fd_call real = next_call("fsync");
  if ((fault_is("fsync") && is_temporary(fd)) || (fault_is("dirsync") && is_directory(fd))) {
    errno = EIO;
    return -1;
  }
  return real(fd);
}

extern "C" int rename(const char* from, const char* to) {
  using rename_call = int (*)(const char*, const char*);
  static rename_call real = [] {
    void* f = dlsym(RTLD_NEXT, "rename");
    if (f == nullptr) std::abort();
    rename_call call = nullptr;
    std::memcpy(&call, &f, sizeof call);
    return call;
  }();
  static int temporaries_renamed = 0;
  if (fault_is("rename2") && is_temporary_name(from) && ++temporaries_renamed == 2) {
    errno = EIO;
    return -1;
  }
  return real(from, to);
}

extern "C" int close(int fd) {
  static const fd_call real = next_call("close");
  const int fail = fault_is("close") && is_temporary(fd);
  const int rc = real(fd);
  if (fail && rc == 0) {
    errno = EIO;
    return -1;
  }
  return rc;
}
