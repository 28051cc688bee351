// SampleRange: parsing and formatting "A:B" and "A:B,C:D" (sample_range.h).
#include "prizma/render/sample_range.h"

#include <algorithm>
#include <charconv>

#include "prizma/spectral/error.h"

namespace prizma::render {
namespace {

using spectral::InputError;

// A whole decimal int64 (no sign, no spaces, no junk), or false.
bool parse_index(std::string_view text, std::int64_t& out) {
  if (text.empty() || text.front() < '0' || text.front() > '9') return false;
  const auto res = std::from_chars(text.data(), text.data() + text.size(), out);
  return res.ec == std::errc() && res.ptr == text.data() + text.size();
}

}  // namespace

SampleRange SampleRange::parse(std::string_view text, const std::string& input) {
  const auto colon = text.find(':');
  SampleRange r;
  if (colon == std::string_view::npos || !parse_index(text.substr(0, colon), r.begin) ||
      !parse_index(text.substr(colon + 1), r.end) || r.end <= r.begin || r.end > kMaxSampleIndex)
    throw InputError(input, "expected A:B with 0 ≤ A < B ≤ 2^62, got \"" + std::string(text) + "\"");
  return r;
}

SampleRange SampleRange::starting_at(std::int64_t begin, std::int64_t count, const std::string& input) {
  if (count < 1 || count > kMaxSamplesPerPixel)
    throw InputError(input, "must be 1 to 2^40 samples per pixel, got " + std::to_string(count));
  if (begin < 0 || begin > kMaxSampleIndex - count)
    throw InputError(input, std::to_string(count) + " samples from sample " + std::to_string(begin) +
                                " pass the largest sample index 2^62");
  return {begin, begin + count};
}

std::string SampleRange::to_string() const { return std::to_string(begin) + ":" + std::to_string(end); }

std::vector<SampleRange> parse_sample_ranges(std::string_view text, const std::string& input) {
  std::vector<SampleRange> out;
  std::size_t pos = 0;
  while (true) {
    const std::size_t comma = std::min(text.find(',', pos), text.size());
    try {
      out.push_back(SampleRange::parse(text.substr(pos, comma - pos), input));
    } catch (const InputError&) {
      throw InputError(input, "bad sample range \"" + std::string(text) + "\" (expected A:B or A:B,C:D,…)");
    }
    if (comma == text.size()) break;
    pos = comma + 1;
  }
  return out;
}

std::vector<SampleRange> join_sample_ranges(std::vector<SampleRange> ranges) {
  std::sort(ranges.begin(), ranges.end());
  std::vector<SampleRange> joined;
  for (const auto& r : ranges) {
    if (!joined.empty() && joined.back().end == r.begin)
      joined.back().end = r.end;
    else
      joined.push_back(r);
  }
  return joined;
}

std::string format_sample_ranges(std::vector<SampleRange> ranges) {
  std::string s;
  for (const auto& r : join_sample_ranges(std::move(ranges))) {
    if (!s.empty()) s += ",";
    s += r.to_string();
  }
  return s;
}

}  // namespace prizma::render
