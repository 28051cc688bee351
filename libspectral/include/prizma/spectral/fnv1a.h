#pragma once
// 64-bit FNV-1a (Fowler–Noll–Vo), Prizma's one hash: the scene hash (prizma:sceneHash, over bytes:
// renderer/src/scene/scene_hash.cpp) and the pixel checksum (prizma:checksum, over one 32-bit word
// per value: docs/spectral-exr.md). Both values are stored in files and compared across versions
// (--resume, merge, the reader's check), so what goes in and in which order must not change.
#include <bit>
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <string>

namespace prizma::spectral {

inline constexpr std::uint64_t kFnv1aOffsetBasis = 0xcbf29ce484222325ULL;
inline constexpr std::uint64_t kFnv1aPrime = 0x100000001b3ULL;

class Fnv1a {
 public:
  constexpr Fnv1a() = default;
  // Another offset basis: the checksum's layer kinds each start from their own (exr_common.h).
  explicit constexpr Fnv1a(std::uint64_t basis) : m_h(basis) {}

  // One step per byte.
  void add_bytes(const void* data, std::size_t n) {
    const auto* p = static_cast<const unsigned char*>(data);
    std::uint64_t h = m_h;  // a local: the bytes may alias the member
    for (std::size_t i = 0; i < n; ++i) h = (h ^ p[i]) * kFnv1aPrime;
    m_h = h;
  }
  // One step per value: its float32 bit pattern as one 32-bit word (half and double converted to
  // float first, as a reader of the file gets them).
  template <class Value>
  void add_float_words(const Value* v, std::size_t n) {
    std::uint64_t h = m_h;
    for (std::size_t i = 0; i < n; ++i) h = (h ^ std::bit_cast<std::uint32_t>(static_cast<float>(v[i]))) * kFnv1aPrime;
    m_h = h;
  }

  constexpr std::uint64_t value() const { return m_h; }
  // 16 lower-case hex digits, as the files store it.
  std::string hex() const {
    char buf[17];
    std::snprintf(buf, sizeof buf, "%016llx", static_cast<unsigned long long>(m_h));
    return buf;
  }

 private:
  std::uint64_t m_h = kFnv1aOffsetBasis;
};

}  // namespace prizma::spectral
