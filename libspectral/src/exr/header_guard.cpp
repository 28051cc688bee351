// The OpenEXR 3.1 header guard (header_guard.h).
#include "exr/header_guard.h"

#include <cstdint>
#include <fstream>
#include <map>

#include "prizma/spectral/error.h"
#include "text_util.h"

namespace prizma::spectral::exr {
namespace {

// OpenEXR 3.1's Imf::Header trusts the sizes a header declares and allocates them before it finds
// the bytes missing: an 865-byte file whose string attribute declares 1.9 GB, found by
// fuzz_spectral_exr. It reads a value of a fixed-size type (box2i, int, ...) by its type, a channel
// list up to its empty name, a preview by its width × height, a string vector string by string, and
// anything else (strings, float vectors, unknown types as opaque bytes) by the declared size; when
// these disagree it reads the rest of the header out of step (a second fuzz find: a channel list
// ending early, after which a pixel-data byte pair was read as a 1.9 GB string size). The walk below
// reads the header(s) the same way (name, type name, int32 size, value; an empty name ends a header;
// a multi-part file ends its list of headers with an empty one) and refuses a value whose content
// disagrees with its declared size (no valid writer makes one) and any size larger than the bytes
// that hold it. Anything else malformed is left for OpenEXR to report.
std::int64_t le_u32(const char* b) {
  const auto* u = reinterpret_cast<const unsigned char*>(b);
  return std::int64_t{u[0]} | std::int64_t{u[1]} << 8 | std::int64_t{u[2]} << 16 | std::int64_t{u[3]} << 24;
}
std::int64_t le_i32(const char* b) { return static_cast<std::int32_t>(static_cast<std::uint32_t>(le_u32(b))); }

// The value size of OpenEXR 3.1's fixed-size attribute types; -1 for the others.
int fixed_value_size(const std::string& type) {
  static const std::map<std::string, int> sizes = {
      {"box2f", 16},   {"box2i", 16},   {"chromaticities", 32}, {"compression", 1}, {"deepImageState", 1},
      {"double", 8},   {"envmap", 1},   {"float", 4},           {"int", 4},         {"keycode", 28},
      {"lineOrder", 1}, {"m33d", 72},   {"m33f", 36},           {"m44d", 128},      {"m44f", 64},
      {"rational", 8}, {"tiledesc", 9}, {"timecode", 8},        {"v2d", 16},        {"v2f", 8},
      {"v2i", 8},      {"v3d", 24},     {"v3f", 12},            {"v3i", 12}};
  const auto it = sizes.find(type);
  return it == sizes.end() ? -1 : it->second;
}

// For the types OpenEXR reads by their content: empty when the content fills the value exactly.
std::string content_problem(const std::string& type, const std::string& v) {
  const auto n = static_cast<std::int64_t>(v.size());
  if (type == "chlist") {  // (name, 16 bytes)*, empty name
    for (std::size_t at = 0; at < v.size();) {
      const auto end = v.find('\0', at);
      if (end == std::string::npos) break;
      if (end == at) return end + 1 == v.size() ? "" : "is a channel list that ends before its size";
      at = end + 1 + 16;
    }
    return "is a channel list that runs past its size";
  }
  if (type == "stringvector") {  // (int32 length, bytes)*
    std::int64_t at = 0;
    for (; at + 4 <= n;) {
      const std::int64_t len = le_i32(v.data() + at);
      if (len < 0 || len > n - at - 4) return "holds a string of " + std::to_string(len) + " bytes";
      at += 4 + len;
    }
    return at == n ? "" : "is a string vector that runs past its size";
  }
  if (type == "preview") {  // uint32 width, uint32 height, 4 bytes per pixel
    if (n < 8) return "is a preview image without its size";
    const std::int64_t w = le_u32(v.data()), h = le_u32(v.data() + 4), bytes = n - 8;
    if ((w > 0 && h > 0 && w > bytes / 4 / h) || w * h * 4 != bytes) {
      return "holds a " + std::to_string(w) + "x" + std::to_string(h) + " preview image";
    }
  }
  return {};
}

}  // namespace

void check_header_sizes(const std::string& p) {
  std::ifstream in(p, std::ios::binary);
  in.seekg(0, std::ios::end);
  const std::int64_t file_size = static_cast<std::int64_t>(in.tellg());
  in.seekg(0);
  char magic_version[8];
  if (!in.read(magic_version, sizeof magic_version)) return;
  const bool multipart = (le_u32(magic_version + 4) & 0x1000) != 0;
  // Reads a null-terminated name; false at end of file or when it is too long to be a name.
  const auto read_name = [&in](std::string& out) {
    out.clear();
    for (char c; in.get(c);) {
      if (c == '\0') return true;
      if (out.size() == 255) return false;
      out.push_back(c);
    }
    return false;
  };
  std::string name, type, value;
  while (true) {
    int attributes = 0;
    while (read_name(name) && !name.empty()) {
      ++attributes;
      char size_bytes[4];
      if (!read_name(type) || !in.read(size_bytes, sizeof size_bytes)) return;
      const std::int64_t size = le_i32(size_bytes);
      const std::int64_t left = file_size - static_cast<std::int64_t>(in.tellg());
      const auto refuse = [&](const std::string& what) {
        throw InputError(p, "header attribute \"" + detail::printable(name) + "\" (" + detail::printable(type) + ", " +
                                std::to_string(size) + " bytes) " + what + " (damaged file?)");
      };
      if (size < 0 || size > left) refuse("is larger than the " + std::to_string(left) + " bytes left in the file");
      const int fixed = fixed_value_size(type);
      if (fixed >= 0 && size != fixed) refuse("should have " + std::to_string(fixed) + " bytes");
      if (type == "floatvector" && size % 4 != 0) refuse("is not a whole number of floats");
      if (type == "chlist" || type == "stringvector" || type == "preview") {
        value.resize(static_cast<std::size_t>(size));
        if (!in.read(value.data(), size)) return;
        if (const std::string problem = content_problem(type, value); !problem.empty()) refuse(problem);
      } else {
        in.seekg(size, std::ios::cur);
      }
    }
    if (!in || !multipart || attributes == 0) return;
  }
}

}  // namespace prizma::spectral::exr
