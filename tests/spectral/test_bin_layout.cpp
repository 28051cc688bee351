// BinLayout: construction, validation of every parser input, find, to_string round trips.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <string>

#include "prizma/spectral/bin_layout.h"
#include "prizma/spectral/error.h"

using prizma::spectral::BinLayout;
using prizma::spectral::InputError;

namespace {

// Expects parse(spec) to throw InputError whose message contains `needle` and the input name.
void expect_parse_error(const std::string& spec, const std::string& needle) {
  try {
    (void)BinLayout::parse(spec, "--bins");
    ADD_FAILURE() << "no error for " << spec;
  } catch (const InputError& e) {
    EXPECT_EQ(e.input(), "--bins") << spec;
    EXPECT_NE(std::string(e.what()).find(needle), std::string::npos)
        << "spec " << spec << ": message \"" << e.what() << "\" lacks \"" << needle << "\"";
  }
}

}  // namespace

TEST(BinLayout, DefaultIs16BinsOf25nm) {
  const BinLayout b;
  ASSERT_EQ(b.size(), 16);
  EXPECT_DOUBLE_EQ(b.min_nm(), 380.0);
  EXPECT_DOUBLE_EQ(b.max_nm(), 780.0);
  for (int i = 0; i < b.size(); ++i) EXPECT_DOUBLE_EQ(b.width_nm(i), 25.0) << i;
  EXPECT_DOUBLE_EQ(b.centre_nm(0), 392.5);
}

TEST(BinLayout, LinearEdgesAreExactMultiples) {
  const auto b = BinLayout::linear(400, 700, 12);
  ASSERT_EQ(b.size(), 12);
  for (int i = 0; i <= 12; ++i) EXPECT_DOUBLE_EQ(b.edges_nm()[i], 400.0 + 25.0 * i);
}

TEST(BinLayout, ExponentialFollowsTheVptFormula) {
  const double k = 1.5;
  const auto b = BinLayout::exponential(400, 700, 10, k);
  ASSERT_EQ(b.size(), 10);
  for (int i = 0; i <= 10; ++i) {
    const double t = i / 10.0;
    EXPECT_NEAR(b.edges_nm()[i], 400.0 + 300.0 * (std::exp(k * t) - 1.0) / (std::exp(k) - 1.0), 1e-9) << i;
  }
  // k > 0: narrow bins at the blue end, widths increase monotonically.
  for (int i = 1; i < b.size(); ++i) EXPECT_GT(b.width_nm(i), b.width_nm(i - 1));
  // k < 0 mirrors it: wide at blue.
  const auto m = BinLayout::exponential(400, 700, 10, -1.5);
  for (int i = 1; i < m.size(); ++i) EXPECT_LT(m.width_nm(i), m.width_nm(i - 1));
  // k = 0 is linear.
  EXPECT_EQ(BinLayout::exponential(400, 700, 12, 0.0), BinLayout::linear(400, 700, 12));
}

TEST(BinLayout, ParseAllForms) {
  EXPECT_EQ(BinLayout::parse("linear:400:700:12"), BinLayout::linear(400, 700, 12));
  EXPECT_EQ(BinLayout::parse("exp:400:700:12:1.5"), BinLayout::exponential(400, 700, 12, 1.5));
  EXPECT_EQ(BinLayout::parse("log:400:700:12:1.5"), BinLayout::exponential(400, 700, 12, 1.5));
  EXPECT_EQ(BinLayout::parse("  LINEAR:400:700:12 "), BinLayout::linear(400, 700, 12));
  const auto e = BinLayout::parse("edges:400, 450,500.5,700");
  ASSERT_EQ(e.size(), 3);
  EXPECT_DOUBLE_EQ(e.edges_nm()[2], 500.5);
  EXPECT_EQ(BinLayout::parse("edges:360,830").size(), 1);
  EXPECT_EQ(BinLayout::parse("linear:380:780:1024").size(), BinLayout::kMaxBins);
}

TEST(BinLayout, RejectsMalformedAndEmpty) {
  expect_parse_error("", "empty");
  expect_parse_error("   ", "empty");
  expect_parse_error("400:700:12", "unknown bin layout kind");
  expect_parse_error("linear", "expected");
  expect_parse_error("cubic:400:700:12", "unknown bin layout kind \"cubic\"");
  expect_parse_error("linear:400:700", "expected linear:LO:HI:N");
  expect_parse_error("linear:400:700:12:3", "expected linear:LO:HI:N");
  expect_parse_error("exp:400:700:12", "expected exp:LO:HI:N:K");
  expect_parse_error("linear:400:abc:12", "\"abc\"");
  expect_parse_error("linear:400:700:12.5", "bad bin count \"12.5\"");
  expect_parse_error("linear:400:700:", "bad bin count");
  expect_parse_error("edges:", "bad bin edge");
  expect_parse_error("edges:400,,500", "bad bin edge");
  expect_parse_error("edges:400;500", "bad bin edge");
}

TEST(BinLayout, RejectsNonFiniteNegativeAndOutOfRange) {
  expect_parse_error("linear:nan:700:12", "not a finite number");
  expect_parse_error("linear:400:inf:12", "not a finite number");
  expect_parse_error("edges:400,nan,500", "not a finite number");
  expect_parse_error("edges:-400,500", "must be positive");
  expect_parse_error("edges:0,500", "must be positive");
  expect_parse_error("linear:300:700:12", "300 nm is outside [360, 830]");
  expect_parse_error("linear:400:900:12", "900 nm is outside");
  expect_parse_error("linear:700:400:12", "must increase");
  expect_parse_error("linear:400:400:12", "must increase");
  expect_parse_error("linear:400:700:0", "at least 1 bin");
  expect_parse_error("linear:400:700:-3", "at least 1 bin");
  expect_parse_error("linear:400:700:1025", "too many bins: 1025");
  expect_parse_error("exp:400:700:12:11", "[-10, 10]");
  expect_parse_error("exp:400:700:12:nan", "not a finite number");
  expect_parse_error("edges:400", "at least 1 bin");
}

TEST(BinLayout, RejectsUnsortedAndDuplicateEdges) {
  expect_parse_error("edges:400,500,450", "not sorted: 450 nm follows 500 nm");
  expect_parse_error("edges:400,500,500,600", "duplicate bin edge 500");
  EXPECT_THROW((void)BinLayout::from_edges({500, 400}), InputError);
  EXPECT_THROW((void)BinLayout::from_edges({}), InputError);
  EXPECT_THROW((void)BinLayout::from_edges({400, std::numeric_limits<double>::quiet_NaN()}), InputError);
  EXPECT_THROW((void)BinLayout::linear(400, 700, 0), InputError);
  EXPECT_THROW((void)BinLayout::exponential(400, 700, 4, -10.5), InputError);
  std::vector<double> many(1026);
  for (std::size_t i = 0; i < many.size(); ++i) many[i] = 400.0 + 0.25 * static_cast<double>(i);
  EXPECT_THROW((void)BinLayout::from_edges(many), InputError);
}

TEST(BinLayout, FindIsHalfOpenWithLastBinClosed) {
  const auto b = BinLayout::linear(400, 700, 3);  // 400 500 600 700
  EXPECT_EQ(b.find(400.0), 0);
  EXPECT_EQ(b.find(499.999), 0);
  EXPECT_EQ(b.find(500.0), 1);
  EXPECT_EQ(b.find(650.0), 2);
  EXPECT_EQ(b.find(700.0), 2);
  EXPECT_EQ(b.find(700.0001), -1);
  EXPECT_EQ(b.find(399.9999), -1);
  EXPECT_EQ(b.find(std::numeric_limits<double>::quiet_NaN()), -1);
}

TEST(BinLayout, ToStringRoundTrips) {
  const BinLayout layouts[] = {
      BinLayout(),
      BinLayout::linear(400, 700, 12),
      BinLayout::linear(380.1, 779.3, 7),
      BinLayout::exponential(400, 700, 12, 1.5),
      BinLayout::exponential(360, 830, 1000, -7.25),
      BinLayout::from_edges({400, 401.5, 555.123456789, 700}),
  };
  for (const auto& b : layouts) {
    const std::string s = b.to_string();
    EXPECT_EQ(BinLayout::parse(s), b) << s;
  }
  EXPECT_EQ(BinLayout::linear(400, 700, 12).to_string(), "linear:400:700:12");
  EXPECT_EQ(BinLayout::from_edges({400, 450, 700}).to_string(), "edges:400,450,700");
}
