// Run-time defaults of the sanitizer trees (PRIZMA_SANITIZE, PRIZMA_FUZZ), compiled into every
// executable there by prizma_set_warnings (cmake/PrizmaWarnings.cmake). ASAN_OPTIONS set at run
// time are read after these and override them key by key.
//
// intercept_tls_get_addr=0: the runtimes of clang 14 and g++ 12 (Debian 12) guess the extent of a
// dynamic TLS block from the address __tls_get_addr returns: one 16 bytes past a page boundary is
// taken for glibc 2.19–2.24's block with a header, and the two words before it are recorded as its
// start and size. Since glibc 2.25 there is no such header: a block that malloc placed there by
// chance gets two words of the allocator's own chunk header as its range, and LeakSanitizer's
// stop-the-world tracer dies scanning it at exit ("Tracer caught signal 11", "LeakSanitizer has
// encountered a fatal error"). Only the libraries loaded with dlopen have dynamic TLS here
// (OpenImageIO in the image module, OpenVDB in the VDB module), so the crash came at random after
// runs that wrote pictures (docs/errors.md, "Sanitizer builds"). Without the interception the leak
// check loses nothing: LeakSanitizer takes every block the dynamic linker allocated (DTVs, dynamic
// TLS blocks) as a root (use_ld_allocations, on by default), so what they point to is reachable.
extern "C" __attribute__((used)) const char* __asan_default_options() { return "intercept_tls_get_addr=0"; }
