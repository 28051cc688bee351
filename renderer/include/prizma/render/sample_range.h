#pragma once
// Sample ranges: which samples of every pixel a render or a file holds. "A:B" is samples A … B−1;
// a file's prizma:sampleRange may list several disjoint ranges, "0:8,16:24" (a merge with a gap).
// One parser for the command line (--samples), render() and merge (docs/distributed.md).
#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

namespace prizma::render {

// Limits: sample indices below 2^62 (so that no sum of them overflows), at most 2^40 samples per
// pixel in one range (the scene's "samples" range, docs/scene-format.md).
inline constexpr std::int64_t kMaxSampleIndex = std::int64_t{1} << 62;
inline constexpr std::int64_t kMaxSamplesPerPixel = std::int64_t{1} << 40;

struct SampleRange {
  std::int64_t begin = 0;
  std::int64_t end = 0;  // exclusive; begin < end for a valid range

  std::int64_t size() const { return end - begin; }
  // "A:B" (decimal, 0 ≤ A < B ≤ kMaxSampleIndex); throws InputError(input, …) for anything else.
  static SampleRange parse(std::string_view text, const std::string& input);
  // [begin, begin + count); throws InputError(input, …) for a count outside 1 … kMaxSamplesPerPixel
  // or an end beyond kMaxSampleIndex.
  static SampleRange starting_at(std::int64_t begin, std::int64_t count, const std::string& input);
  std::string to_string() const;
  friend bool operator==(const SampleRange&, const SampleRange&) = default;
  friend auto operator<=>(const SampleRange&, const SampleRange&) = default;
};

// "0:8" or "0:8,16:24" → the ranges as written; throws InputError(input, …) for anything else.
std::vector<SampleRange> parse_sample_ranges(std::string_view text, const std::string& input);
// Sorted, touching ranges joined: {16:24, 0:8, 8:16} → "0:24"; {0:8, 16:24} → "0:8,16:24".
std::string format_sample_ranges(std::vector<SampleRange> ranges);
// The same, as ranges (sorted, touching ones joined). Overlaps are kept apart (the caller refuses them).
std::vector<SampleRange> join_sample_ranges(std::vector<SampleRange> ranges);

}  // namespace prizma::render
