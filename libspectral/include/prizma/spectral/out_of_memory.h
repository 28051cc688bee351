#pragma once
// Running out of memory, in every form it takes (std::bad_alloc, a thread that cannot start, a
// library's message), recognised in one place, and allocating(): what a library call was doing when
// memory ran out, as a RuntimeError that says so.
#include <exception>
#include <new>
#include <string>
#include <string_view>
#include <system_error>
#include <utility>

#include "prizma/spectral/error.h"

namespace prizma::spectral {

// True for a std::system_error that means the system ran out of memory or threads (a thread that
// cannot be started: EAGAIN, ENOMEM).
bool is_out_of_resources(const std::system_error& e);
// True for every way running out of memory shows: std::bad_alloc, the system_errors above, and
// TBB's "pthread_create has failed" (a std::runtime_error when it cannot start a worker).
bool is_out_of_memory(const std::exception& e);
// True when a library's error message (OpenEXR's Iex, OCIO) says that memory or threads ran out:
// "Out of memory", "std::bad_alloc", "Cannot allocate memory", "Resource temporarily unavailable".
// Text from the first to the last double quote is ignored: the messages quote file and channel names,
// which come from the input and may hold these words and quotes (channels "Out of memory", a"bad_alloc).
bool message_says_out_of_memory(std::string_view what);

// Runs f(); running out of memory inside it (std::bad_alloc, or a thread that cannot be started)
// becomes RuntimeError("out of memory <what>"), e.g. what = "reading the scene's volume".
template <typename F>
decltype(auto) allocating(std::string_view what, F&& f) {
  try {
    return std::forward<F>(f)();
  } catch (const InputError&) {
    throw;
  } catch (const std::bad_alloc&) {
    throw RuntimeError("out of memory " + std::string(what));
  } catch (const std::exception& e) {
    if (is_out_of_memory(e)) throw RuntimeError("out of memory " + std::string(what) + " (" + e.what() + ")");
    throw;
  }
}

}  // namespace prizma::spectral
