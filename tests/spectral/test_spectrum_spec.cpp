// Spectrum spec strings, named data, CSV reading and writing.
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>
#include <thread>
#include <unistd.h>

#include "prizma/spectral/data_path.h"
#include "prizma/spectral/error.h"
#include "prizma/spectral/spectrum_spec.h"

using namespace prizma::spectral;
namespace fs = std::filesystem;

namespace {

void expect_spec_error(const std::string& spec, const std::string& needle) {
  SpecContext ctx;
  ctx.input = "--light key";
  try {
    (void)parse_spectrum(spec, ctx);
    ADD_FAILURE() << "no error for " << spec;
  } catch (const InputError& e) {
    EXPECT_EQ(e.input(), "--light key") << spec;
    EXPECT_NE(std::string(e.what()).find(needle), std::string::npos)
        << "spec " << spec << ": message \"" << e.what() << "\" lacks \"" << needle << "\"";
  }
}

bool same(const Spectrum& a, const Spectrum& b) {
  return a.is_constant() == b.is_constant() && a.wavelengths_nm() == b.wavelengths_nm() && a.values() == b.values() &&
         a.eval(0) == b.eval(0);
}

// A scratch folder unique to this process.
class SpecFiles : public ::testing::Test {
 protected:
  void SetUp() override {
    m_dir = fs::temp_directory_path() / ("prizma-spec-test-" + std::to_string(::getpid()) + "-" +
                                         ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::create_directories(m_dir);
  }
  void TearDown() override { fs::remove_all(m_dir); }
  fs::path write(const std::string& name, const std::string& text) {
    const fs::path p = m_dir / name;
    std::ofstream(p) << text;
    return p;
  }
  void expect_csv_error(const std::string& name, const std::string& text, const std::string& needle) {
    const fs::path p = write(name, text);
    try {
      (void)read_spectrum_csv(p);
      ADD_FAILURE() << "no error for " << name;
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find(needle), std::string::npos)
          << name << ": message \"" << e.what() << "\" lacks \"" << needle << "\"";
    }
  }
  fs::path m_dir;
};

}  // namespace

TEST(SpectrumSpec, NamedIlluminants) {
  const auto names = named_illuminants();
  ASSERT_EQ(names.size(), 15u);
  for (const auto& n : names) {
    const Spectrum s = parse_spectrum(n);
    EXPECT_FALSE(s.is_constant()) << n;
    EXPECT_GT(s.integrate(380, 780), 0.0) << n;
  }
  // Values as published (data/spectra): D65 and A are 100 at 560 nm; D65(300) = 0.0341; F2(380) = 1.18.
  EXPECT_DOUBLE_EQ(parse_spectrum("D65").eval(560), 100.0);
  EXPECT_DOUBLE_EQ(parse_spectrum("D65").eval(300), 0.0341);
  EXPECT_DOUBLE_EQ(parse_spectrum("A").eval(560), 100.0);
  EXPECT_DOUBLE_EQ(parse_spectrum("F2").eval(380), 1.18);
  EXPECT_DOUBLE_EQ(parse_spectrum("LED-V1").eval(390), 0.14);
  // Case-insensitive.
  EXPECT_TRUE(same(parse_spectrum("d65"), parse_spectrum("D65")));
  EXPECT_TRUE(same(parse_spectrum("led-b1"), parse_spectrum("LED-B1")));
  EXPECT_TRUE(same(parse_spectrum(" Led-Rgb1 "), parse_spectrum("LED-RGB1")));
  EXPECT_FALSE(same(parse_spectrum("LED-B1"), parse_spectrum("LED-B2")));
}

TEST(SpectrumSpec, UnknownNameListsTheKnownOnes) {
  expect_spec_error("D66", "unknown spectrum \"D66\"");
  expect_spec_error("D66", "D65");
  expect_spec_error("D66", "LED-V2");
  expect_spec_error("D66", "cc:<patch>");
  expect_spec_error("sunlight:5", "unknown spectrum");
  expect_spec_error("", "empty spectrum");
  expect_spec_error("   ", "empty spectrum");
}

TEST(SpectrumSpec, ColorCheckerPatches) {
  const auto patches = colorchecker_patches();
  ASSERT_EQ(patches.size(), 24u);
  EXPECT_EQ(patches.front(), "cc:dark-skin");
  for (const auto& p : patches) EXPECT_NO_THROW((void)parse_spectrum(p)) << p;
  // Ohta data (data/spectra/colorchecker_reflectance.csv): dark skin 0.048 at 380 nm, black 0.032.
  const Spectrum dark_skin = parse_spectrum("cc:dark-skin");
  EXPECT_DOUBLE_EQ(dark_skin.eval(380), 0.048);
  EXPECT_DOUBLE_EQ(parse_spectrum("cc:24").eval(780), 0.032);
  for (const char* alias : {"cc:Dark Skin", "cc:dark_skin", "cc:DARKSKIN", "cc:1", "CC:dark-skin"}) {
    EXPECT_TRUE(same(parse_spectrum(alias), dark_skin)) << alias;
  }
  const Spectrum white = parse_spectrum("cc:19");
  EXPECT_DOUBLE_EQ(white.eval(380), 0.153);
  for (const char* alias : {"cc:white9.5", "cc:white", "cc:White 9.5 (.05 D)", "cc:white-9.5"}) {
    EXPECT_TRUE(same(parse_spectrum(alias), white)) << alias;
  }
  EXPECT_TRUE(same(parse_spectrum("cc:neutral8"), parse_spectrum("cc:20")));
  EXPECT_TRUE(same(parse_spectrum("cc:neutral-3.5"), parse_spectrum("cc:23")));
  EXPECT_TRUE(same(parse_spectrum("cc:black"), parse_spectrum("cc:24")));
  EXPECT_FALSE(same(parse_spectrum("cc:2"), dark_skin));
  expect_spec_error("cc:neutral", "unknown ColorChecker patch");  // ambiguous: four neutrals
  expect_spec_error("cc:0", "1..24");
  expect_spec_error("cc:25", "1..24");
  expect_spec_error("cc:-3", "1..24");
  expect_spec_error("cc:purpleish", "purplish-blue");
  expect_spec_error("cc:", "unknown ColorChecker patch");
}

TEST(SpectrumSpec, Blackbody) {
  const Spectrum bb = parse_spectrum("blackbody:3000K");
  EXPECT_DOUBLE_EQ(bb.domain_lo_nm(), 300.0);
  EXPECT_DOUBLE_EQ(bb.domain_hi_nm(), 900.0);
  EXPECT_EQ(bb.wavelengths_nm().size(), 601u);  // 1 nm steps
  // Planck ratio B(450)/B(650) at 3000 K, c2 = 1.438776877e-2 m·K (CODATA 2018).
  auto planck = [](double l_nm, double t) { return std::pow(l_nm, -5.0) / std::expm1(1.438776877e7 / (l_nm * t)); };
  EXPECT_NEAR(bb.eval(450) / bb.eval(650), planck(450, 3000) / planck(650, 3000), 1e-12);
  // 5000 K peaks at b/T = 579.6 nm, inside the table: the tabulated maximum is 1 (to the 1 nm grid).
  EXPECT_NEAR(parse_spectrum("blackbody:5000K").max_value(), 1.0, 1e-5);
  EXPECT_LE(parse_spectrum("blackbody:5000K").max_value(), 1.0);
  // 3000 K peaks at 966 nm: every tabulated value is below 1, rising to the red.
  EXPECT_LT(bb.max_value(), 1.0);
  EXPECT_GT(bb.eval(800), bb.eval(500));
  EXPECT_TRUE(same(parse_spectrum("blackbody:6500k"), parse_spectrum("BLACKBODY:6500")));
  expect_spec_error("blackbody:-5K", "temperature");
  expect_spec_error("blackbody:0K", "temperature");
  expect_spec_error("blackbody:nanK", "not a finite number");
  expect_spec_error("blackbody:infK", "not a finite number");
  expect_spec_error("blackbody:K", "bad temperature");
  expect_spec_error("blackbody:warm", "bad temperature");
}

TEST(SpectrumSpec, Gaussian) {
  const Spectrum g = parse_spectrum("gaussian:550:20");
  const double sigma = 20.0 / (2.0 * std::sqrt(2.0 * std::log(2.0)));
  EXPECT_DOUBLE_EQ(g.eval(550), 1.0);
  EXPECT_DOUBLE_EQ(g.max_value(), 1.0);
  EXPECT_NEAR(g.eval(540), 0.5, 1e-3);  // half maximum at centre ± FWHM/2 (interpolated)
  EXPECT_NEAR(g.eval(560), 0.5, 1e-3);
  EXPECT_NEAR(g.domain_lo_nm(), 550 - 6 * sigma, 1e-9);
  EXPECT_NEAR(g.domain_hi_nm(), 550 + 6 * sigma, 1e-9);
  const auto& lam = g.wavelengths_nm();
  for (std::size_t i = 1; i < lam.size(); ++i) EXPECT_LE(lam[i] - lam[i - 1], 20.0 / 40.0 + 1e-12);
  // Area σ√(2π); the piecewise-linear error at step FWHM/40 is ≈ 1e-4 relative.
  EXPECT_NEAR(g.integrate(0, 1000), sigma * std::sqrt(2 * std::numbers::pi), 2e-4 * sigma * std::sqrt(2 * std::numbers::pi));
  expect_spec_error("gaussian:550", "expected gaussian:<centre>:<fwhm>");
  expect_spec_error("gaussian:550:20:3", "expected gaussian:<centre>:<fwhm>");
  expect_spec_error("gaussian:550:0", "FWHM");
  expect_spec_error("gaussian:550:-20", "FWHM");
  expect_spec_error("gaussian:nan:20", "not a finite number");
  expect_spec_error("gaussian:-550:20", "centre");
  expect_spec_error("gaussian:green:20", "bad gaussian centre \"green\"");
}

TEST(SpectrumSpec, BoxConstantsAndFactors) {
  const Spectrum b = parse_spectrum("box:500:560");
  EXPECT_DOUBLE_EQ(b.integrate(0, 1000), 60.0);
  EXPECT_DOUBLE_EQ(b.eval(530), 1.0);
  EXPECT_DOUBLE_EQ(b.eval(499), 0.0);
  EXPECT_DOUBLE_EQ(b.eval(561), 0.0);
  expect_spec_error("box:560:500", "must increase");
  expect_spec_error("box:500:500", "must increase");
  expect_spec_error("box:-1:5", "negative");
  expect_spec_error("box:500", "expected box:<lo>:<hi>");
  expect_spec_error("box:500:inf", "not a finite number");

  const Spectrum c = parse_spectrum("0.5");
  EXPECT_TRUE(c.is_constant());
  EXPECT_DOUBLE_EQ(c.eval(123), 0.5);
  EXPECT_DOUBLE_EQ(parse_spectrum("0").eval(500), 0.0);
  expect_spec_error("-1", "must not be negative");
  expect_spec_error("nan", "not a finite number");
  expect_spec_error("inf", "not a finite number");
  expect_spec_error("1e999", "not a finite number");

  const Spectrum d65 = parse_spectrum("D65");
  const Spectrum half = parse_spectrum("D65*0.5");
  ASSERT_EQ(half.values().size(), d65.values().size());
  for (std::size_t i = 0; i < d65.values().size(); ++i) EXPECT_DOUBLE_EQ(half.values()[i], 0.5 * d65.values()[i]);
  EXPECT_TRUE(same(parse_spectrum("cc:1 * 2 * 0.5"), parse_spectrum("cc:1")));
  EXPECT_DOUBLE_EQ(parse_spectrum("0.5*4").eval(0), 2.0);
  // A negative factor is accepted (difference spectra); consumers needing light check themselves.
  EXPECT_DOUBLE_EQ(parse_spectrum("gaussian:550:20*-1").eval(550), -1.0);
  expect_spec_error("D65*abc", "bad scale factor \"abc\"");
  expect_spec_error("D65*", "bad scale factor");
  expect_spec_error("*2", "nothing to scale");
  expect_spec_error("D65*nan", "not a finite number");
  expect_spec_error("D65*1e307", "overflows");
  expect_spec_error("D66*2", "unknown spectrum \"D66\"");
}

TEST(SpectrumSpec, CachedTablesAreThreadSafe) {
  std::vector<Spectrum> results(8);
  std::vector<std::thread> threads;
  for (int t = 0; t < 8; ++t) {
    threads.emplace_back([t, &results] { results[t] = parse_spectrum(t % 2 ? "cc:5" : "LED-B3"); });
  }
  for (auto& th : threads) th.join();
  for (int t = 2; t < 8; ++t) EXPECT_TRUE(same(results[t], results[t % 2])) << t;
  EXPECT_FALSE(same(results[0], results[1]));
}

TEST_F(SpecFiles, CsvRelativeToBaseDir) {
  write("light.csv", "# my light\nwavelength_nm,power\n400,1\n\n500, 3   # peak\n600,1\n");
  SpecContext ctx;
  ctx.base_dir = m_dir;
  const Spectrum s = parse_spectrum("csv:light.csv*2", ctx);
  EXPECT_EQ(s.wavelengths_nm(), (std::vector<double>{400, 500, 600}));
  EXPECT_EQ(s.values(), (std::vector<double>{2, 6, 2}));
  // No header, whitespace separated, absolute path.
  const fs::path p = write("ws.csv", "400 0.1\n700 0.2\n");
  EXPECT_EQ(parse_spectrum("csv:" + p.string()).values(), (std::vector<double>{0.1, 0.2}));
  expect_spec_error("csv:", "needs a file path");
  SpecContext missing;
  missing.base_dir = m_dir;
  EXPECT_THROW((void)parse_spectrum("csv:nope.csv", missing), InputError);
}

// The quantity decides the sign (SpecContext::values): a signed one (the anisotropy g) takes negative
// constants and csv: rows, every other quantity refuses them, named by file and line as before.
TEST_F(SpecFiles, SignedQuantitiesTakeNegativeValuesOthersRefuseThem) {
  const fs::path p = write("g.csv", "wavelength_nm,g\n400,-0.6\n700,0.2\n");
  SpecContext signed_ctx;
  signed_ctx.values = SpectrumValues::Signed;
  const Spectrum g = parse_spectrum("csv:" + p.string(), signed_ctx);
  EXPECT_EQ(g.values(), (std::vector<double>{-0.6, 0.2}));
  EXPECT_EQ(read_spectrum_csv(p, SpectrumValues::Signed).values(), g.values());
  EXPECT_DOUBLE_EQ(parse_spectrum("-0.3", signed_ctx).eval(500), -0.3);
  EXPECT_DOUBLE_EQ(parse_spectrum("csv:" + p.string() + "*0.5", signed_ctx).eval(400), -0.3);
  SpecContext albedo;
  albedo.input = "scene.json: materials[0].albedo";
  try {
    (void)parse_spectrum("csv:" + p.string(), albedo);
    ADD_FAILURE() << "a negative csv: value of a non-negative quantity parsed";
  } catch (const InputError& e) {
    EXPECT_EQ(std::string(e.what()), p.string() + ":2: value must not be negative, got -0.6");
  }
  expect_spec_error("-0.3", "constant spectrum must not be negative, got \"-0.3\"");
  expect_csv_error("neg.csv", "400,0.5\n700,-0.1\n", "neg.csv:2: value must not be negative, got -0.1");
}

TEST_F(SpecFiles, CsvBadLinesNameFileAndLine) {
  expect_csv_error("a.csv", "wavelength_nm,value\n400,1\n450,abc\n", "a.csv:3: not a number: \"abc\"");
  expect_csv_error("b.csv", "400,1\n500,2\n450,3\n", "b.csv:3: wavelengths must be strictly increasing: 450 nm follows 500");
  expect_csv_error("c.csv", "400,1\n400,2\n", "c.csv:2: wavelengths must be strictly increasing");
  expect_csv_error("d.csv", "400,1\n500,nan\n", "d.csv:2: not a finite number");
  expect_csv_error("e.csv", "400,1\n500,inf\n", "e.csv:2: not a finite number");
  expect_csv_error("f.csv", "400,1\n500,-0.5\n", "f.csv:2: value must not be negative");
  expect_csv_error("g.csv", "400,1,2\n500,2,3\n", "g.csv:1: expected 2 columns, got 3");
  expect_csv_error("h.csv", "400,1\n500\n", "h.csv:2: expected 2 columns");
  expect_csv_error("i.csv", "wavelength_nm,value\n400,1\n", "at least 2 lines");
  expect_csv_error("j.csv", "", "no data lines");
  expect_csv_error("k.csv", "# only a comment\nwavelength,value\n", "no data lines");
  expect_csv_error("l.csv", "-400,1\n500,1\n", "l.csv:1: wavelength must be positive");
  EXPECT_THROW((void)read_spectrum_csv(m_dir / "missing.csv"), InputError);
  EXPECT_THROW((void)read_spectrum_csv(m_dir), InputError);
}

TEST_F(SpecFiles, WriteThenReadRoundTrips) {
  const Spectrum g = parse_spectrum("gaussian:512.3:17.1");
  const fs::path p = m_dir / "g.csv";
  write_spectrum_csv(p, g, "albedo");
  std::ifstream in(p);
  std::string header;
  std::getline(in, header);
  EXPECT_EQ(header, "wavelength_nm,albedo");
  const Spectrum back = read_spectrum_csv(p);
  EXPECT_EQ(back.wavelengths_nm(), g.wavelengths_nm());  // shortest round-trip formatting: bit-exact
  EXPECT_EQ(back.values(), g.values());
  // A constant is written over 360–830 nm.
  write_spectrum_csv(p, Spectrum::constant(0.25));
  const Spectrum c = read_spectrum_csv(p);
  EXPECT_DOUBLE_EQ(c.eval(360), 0.25);
  EXPECT_DOUBLE_EQ(c.eval(830), 0.25);
  // No temporary left behind.
  int files = 0;
  for ([[maybe_unused]] const auto& e : fs::directory_iterator(m_dir)) ++files;
  EXPECT_EQ(files, 1);
}

TEST(DataPath, EnvironmentOverrideAndMissingFiles) {
  // ctest sets PRIZMA_DATA_DIR to the source tree's data/ folder; data_dir() must follow it.
  const char* old = std::getenv("PRIZMA_DATA_DIR");
  const std::string saved = old ? old : "";
  ::setenv("PRIZMA_DATA_DIR", "/nonexistent/prizma-data", 1);
  EXPECT_EQ(data_dir(), fs::path("/nonexistent/prizma-data"));
  EXPECT_THROW((void)data_file("spectra/cie1931_xyz2deg_1nm.csv"), RuntimeError);
  ::setenv("PRIZMA_DATA_DIR", PRIZMA_TEST_DATA_DIR, 1);
  EXPECT_TRUE(fs::exists(data_file("spectra/cie1931_xyz2deg_1nm.csv")));
  try {
    (void)data_file("spectra/no-such-table.csv");
    FAIL() << "expected RuntimeError";
  } catch (const RuntimeError& e) {
    EXPECT_NE(std::string(e.what()).find("no-such-table.csv"), std::string::npos) << e.what();
  }
  // Unset: falls back to the build-time source data folder, which exists in the build tree.
  ::unsetenv("PRIZMA_DATA_DIR");
  EXPECT_TRUE(fs::exists(data_dir() / "spectra" / "illuminant_D65_5nm.csv")) << data_dir();
  if (old) {
    ::setenv("PRIZMA_DATA_DIR", saved.c_str(), 1);
  }
}
