// libFuzzer target: spectrum spec strings (parse_spectrum) and bin layout specs (BinLayout::parse).
// Input: the first line is the spec, tried with both parsers; the rest of the input is the text of
// "f.csv" in the spec's base folder, so "csv:f.csv" reaches the CSV reader. Specs with a '/' are
// skipped to keep file access inside the scratch folder. InputError is the expected answer to bad
// input; any other exception, a crash, undefined behaviour or a broken invariant is a bug.
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <string>
#include <string_view>

#include "fuzz/fuzz_support.h"
#include "prizma/spectral/bin_layout.h"
#include "prizma/spectral/spectrum.h"
#include "prizma/spectral/spectrum_spec.h"

namespace {

constexpr std::size_t kMaxInputBytes = 16 * 1024;

void check_spectrum(const prizma::spectral::Spectrum& s) {
  const auto& lambda = s.wavelengths_nm();
  const auto& values = s.values();
  if (!s.is_constant()) {
    PRIZMA_FUZZ_CHECK(lambda.size() == values.size() && lambda.size() >= 2, "%zu wavelengths, %zu values",
                      lambda.size(), values.size());
  }
  for (std::size_t i = 0; i < lambda.size(); ++i) {
    PRIZMA_FUZZ_CHECK(std::isfinite(lambda[i]), "wavelength %zu is %g", i, lambda[i]);
    if (i > 0) PRIZMA_FUZZ_CHECK(lambda[i] > lambda[i - 1], "wavelengths not increasing at %zu", i);
  }
  for (std::size_t i = 0; i < values.size(); ++i) {
    PRIZMA_FUZZ_CHECK(std::isfinite(values[i]), "value %zu is %g", i, values[i]);
  }
  const double v = s.eval(550.0);
  PRIZMA_FUZZ_CHECK(std::isfinite(v), "eval(550) = %g", v);
}

void check_bins(const prizma::spectral::BinLayout& b) {
  using prizma::spectral::BinLayout;
  PRIZMA_FUZZ_CHECK(b.size() >= 1 && b.size() <= BinLayout::kMaxBins, "%d bins", b.size());
  const auto& e = b.edges_nm();
  for (std::size_t i = 0; i < e.size(); ++i) {
    PRIZMA_FUZZ_CHECK(std::isfinite(e[i]) && e[i] >= BinLayout::kMinNm && e[i] <= BinLayout::kMaxNm,
                      "edge %zu = %.17g", i, e[i]);
    if (i > 0) PRIZMA_FUZZ_CHECK(e[i] > e[i - 1], "edges not increasing at %zu", i);
  }
  // to_string() promises a spec that parse() turns back into the same layout.
  const std::string text = b.to_string();
  bool same = false;
  const bool reparsed = prizma::fuzz::accepts("BinLayout::parse(to_string())", [&] {
    same = BinLayout::parse(text, "round trip") == b;
  });
  PRIZMA_FUZZ_CHECK(reparsed && same, "to_string() = \"%s\" does not parse back to the same layout", text.c_str());
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size > kMaxInputBytes) return 0;
  const std::string_view input(reinterpret_cast<const char*>(data), size);
  const std::size_t newline = input.find('\n');
  const std::string_view spec = input.substr(0, newline);
  const std::string_view csv = newline == std::string_view::npos ? std::string_view{} : input.substr(newline + 1);
  if (spec.find('/') != std::string_view::npos) return 0;

  static const prizma::fuzz::ScratchDir dir("spectrum_spec");
  prizma::fuzz::write_file(dir.path() / "f.csv", csv);

  prizma::spectral::SpecContext ctx;
  ctx.input = "fuzz";
  ctx.base_dir = dir.path();
  prizma::fuzz::accepts("parse_spectrum", [&] { check_spectrum(prizma::spectral::parse_spectrum(spec, ctx)); });
  prizma::fuzz::accepts("BinLayout::parse", [&] { check_bins(prizma::spectral::BinLayout::parse(spec, "fuzz")); });
  return 0;
}
