// A module with a thread-local buffer. Loaded with dlopen, its TLS is dynamic: glibc mallocs one
// block per thread on the thread's first use (__tls_get_addr), as for OpenImageIO in the image module.
__thread char tls_buffer_storage[13];
extern "C" __attribute__((visibility("default"))) char* tls_buffer() { return tls_buffer_storage; }
