#pragma once
// The FNV-1a 64 hash of the pixel checksums (internal; not installed): one 32-bit word per value,
// the float32 bit pattern of each value as a reader gets it (half and double converted to float
// first). Each checksum part (transport, variance, re-radiation, coefficients, basis) starts from
// its own offset basis, and the parts are summed modulo 2⁶⁴ by the caller, so that their order does
// not matter (the prizma:checksum attribute, docs/spectral-exr.md).
#include <bit>
#include <cstddef>
#include <cstdint>

namespace prizma::spectral::detail {

constexpr std::uint64_t kFnvPrime = 0x100000001b3ULL;

template <class Value>
std::uint64_t hash_float_bits(const Value* v, std::size_t n, std::uint64_t basis) {
  std::uint64_t h = basis;
  for (std::size_t i = 0; i < n; ++i) h = (h ^ std::bit_cast<std::uint32_t>(static_cast<float>(v[i]))) * kFnvPrime;
  return h;
}

}  // namespace prizma::spectral::detail
