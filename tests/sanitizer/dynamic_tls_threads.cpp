// The LeakSanitizer tracer crash of docs/errors.md ("Sanitizer builds"), made certain: loads
// dynamic_tls_module.so with dlopen, starts N threads that each use its thread-local buffer (one
// dynamic TLS block per thread, malloc'd) and keep running, and exits, so that LeakSanitizer stops
// and scans them. With the runtime's __tls_get_addr guess on (intercept_tls_get_addr=1) a block
// 16 bytes past a page boundary gets a garbage range and the tracer dies (exit 1, "Tracer caught
// signal 11"); with the sanitizer trees' default (cmake/sanitizer_options.cpp) it exits 0.
//   prizma_test_dynamic_tls_threads MODULE [N]
#include <dlfcn.h>
#include <pthread.h>
#include <unistd.h>

#include <cstdio>
#include <cstdlib>

namespace {

using TlsBuffer = char* (*)();
TlsBuffer g_tls_buffer = nullptr;
pthread_barrier_t g_ready;

void* hold_a_block(void*) {
  g_tls_buffer()[0] = 1;  // glibc allocates this thread's block of the module's TLS here
  pthread_barrier_wait(&g_ready);
  for (;;) pause();  // alive at exit: LeakSanitizer suspends and scans it
  return nullptr;
}

}  // namespace

int main(int argc, char** argv) {
  if (argc < 2) {
    std::fprintf(stderr, "usage: prizma_test_dynamic_tls_threads MODULE [N]\n");
    return 2;
  }
  void* module = dlopen(argv[1], RTLD_NOW | RTLD_LOCAL);
  if (module == nullptr) {
    std::fprintf(stderr, "%s\n", dlerror());
    return 2;
  }
  g_tls_buffer = reinterpret_cast<TlsBuffer>(dlsym(module, "tls_buffer"));
  const int n = argc > 2 ? std::atoi(argv[2]) : 64;
  if (g_tls_buffer == nullptr || n < 1 || n > 1024) {
    std::fprintf(stderr, "no tls_buffer in %s, or N not in [1, 1024]\n", argv[1]);
    return 2;
  }
  pthread_barrier_init(&g_ready, nullptr, static_cast<unsigned>(n) + 1);
  for (int i = 0; i < n; ++i) {
    pthread_attr_t attr;
    pthread_attr_init(&attr);
    pthread_attr_setstacksize(&attr, 64 * 1024);
    pthread_t thread;
    if (pthread_create(&thread, &attr, hold_a_block, nullptr) != 0) {
      std::fprintf(stderr, "cannot start thread %d\n", i);
      return 2;
    }
    pthread_attr_destroy(&attr);
  }
  pthread_barrier_wait(&g_ready);
  std::printf("%d threads hold a dynamic TLS block\n", n);
  return 0;
}
