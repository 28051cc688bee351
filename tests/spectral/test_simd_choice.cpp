// How a dispatched kernel's SIMD level is chosen (simd_choice.h): a level forced in the process,
// else PRIZMA_SIMD, else the highest available unless a measured rule caps it for this CPU; a level
// the kernel or CPU lacks falls to the highest available below it.
#include <gtest/gtest.h>

#include <cstdlib>
#include <optional>
#include <string>
#include <vector>

#include "prizma/spectral/error.h"
#include "prizma/spectral/simd_choice.h"

namespace prizma::spectral {
namespace {

// Sets PRIZMA_SIMD (or unsets it, for nullptr) for its lifetime.
class SimdEnv {
 public:
  explicit SimdEnv(const char* value) {
    if (const char* old = std::getenv("PRIZMA_SIMD")) m_old = old;
    if (value != nullptr)
      ::setenv("PRIZMA_SIMD", value, 1);
    else
      ::unsetenv("PRIZMA_SIMD");
  }
  ~SimdEnv() {
    if (m_old)
      ::setenv("PRIZMA_SIMD", m_old->c_str(), 1);
    else
      ::unsetenv("PRIZMA_SIMD");
  }
  SimdEnv(const SimdEnv&) = delete;
  SimdEnv& operator=(const SimdEnv&) = delete;

 private:
  std::optional<std::string> m_old;
};

const std::vector<SimdLevel> kAll = {SimdLevel::Baseline, SimdLevel::Sse4, SimdLevel::Avx2, SimdLevel::Avx512};
const CpuModel kZen5{"AuthenticAMD", 0x1A, 0x02, "AMD EPYC"};
const CpuModel kXeon{"GenuineIntel", 6, 0x8F, "Intel Xeon"};

TEST(SimdChoice, NamesRoundTripAndAnUnknownOneNamesItsInput) {
  for (SimdLevel l : kAll) EXPECT_EQ(parse_simd_level(simd_level_name(l), "test"), l);
  try {
    (void)parse_simd_level("avx1024", "PRIZMA_SIMD");
    FAIL() << "no throw";
  } catch (const InputError& e) {
    EXPECT_EQ(e.input(), "PRIZMA_SIMD");
    EXPECT_NE(std::string(e.what()).find("\"avx1024\""), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("baseline, sse4, avx2, avx512"), std::string::npos) << e.what();
  }
  for (SimdKernel k : kSimdKernels) EXPECT_FALSE(simd_kernel_name(k).empty());
}

TEST(SimdChoice, WithoutRulesTheHighestAvailable) {
  const SimdEnv env(nullptr);
  const std::vector<SimdRule> none;
  EXPECT_EQ(choose_simd_level(SimdKernel::Relight, kAll, kZen5, none), SimdLevel::Avx512);
  const std::vector<SimdLevel> tracer = {SimdLevel::Baseline, SimdLevel::Avx2};
  EXPECT_EQ(choose_simd_level(SimdKernel::Tracer, tracer, kZen5, none), SimdLevel::Avx2);
}

TEST(SimdChoice, ARuleCapsItsKernelOnItsCpusOnly) {
  const SimdEnv env(nullptr);
  const std::vector<SimdRule> rules = {{SimdKernel::Relight, "AuthenticAMD", 0x1A, 0x00, 0x0F, SimdLevel::Avx2, "test"}};
  EXPECT_EQ(choose_simd_level(SimdKernel::Relight, kAll, kZen5, rules), SimdLevel::Avx2);
  EXPECT_EQ(ruled_simd_level(SimdKernel::Relight, kAll, kZen5, rules), SimdLevel::Avx2);
  // Another kernel, vendor, family or model: not capped.
  EXPECT_EQ(choose_simd_level(SimdKernel::CompressedFrame, kAll, kZen5, rules), SimdLevel::Avx512);
  EXPECT_EQ(choose_simd_level(SimdKernel::Relight, kAll, kXeon, rules), SimdLevel::Avx512);
  EXPECT_EQ(choose_simd_level(SimdKernel::Relight, kAll, CpuModel{"AuthenticAMD", 0x19, 0x02, ""}, rules), SimdLevel::Avx512);
  EXPECT_EQ(choose_simd_level(SimdKernel::Relight, kAll, CpuModel{"AuthenticAMD", 0x1A, 0x44, ""}, rules), SimdLevel::Avx512);
  // A cap below every available level: the lowest available.
  const std::vector<SimdLevel> wide = {SimdLevel::Avx2, SimdLevel::Avx512};
  const std::vector<SimdRule> low = {{SimdKernel::Relight, "AuthenticAMD", 0x1A, 0x00, 0xFF, SimdLevel::Sse4, "test"}};
  EXPECT_EQ(choose_simd_level(SimdKernel::Relight, wide, kZen5, low), SimdLevel::Avx2);
}

TEST(SimdChoice, PrizmaSimdOverridesTheRulesAndFallsToWhatIsAvailable) {
  const std::vector<SimdRule> rules = {{SimdKernel::Relight, "AuthenticAMD", 0x1A, 0x00, 0xFF, SimdLevel::Avx2, "test"}};
  {
    const SimdEnv env("avx512");
    EXPECT_EQ(choose_simd_level(SimdKernel::Relight, kAll, kZen5, rules), SimdLevel::Avx512);
    EXPECT_EQ(ruled_simd_level(SimdKernel::Relight, kAll, kZen5, rules), SimdLevel::Avx2) << "the rules alone";
  }
  {
    const SimdEnv env("sse4");
    EXPECT_EQ(choose_simd_level(SimdKernel::Relight, kAll, kZen5, rules), SimdLevel::Sse4);
    // The tracer has no SSE4 level: the highest below it.
    const std::vector<SimdLevel> tracer = {SimdLevel::Baseline, SimdLevel::Avx2, SimdLevel::Avx512};
    EXPECT_EQ(choose_simd_level(SimdKernel::Tracer, tracer, kZen5, rules), SimdLevel::Baseline);
  }
  {
    const SimdEnv env("avx512");
    const std::vector<SimdLevel> no_avx512 = {SimdLevel::Baseline, SimdLevel::Sse4, SimdLevel::Avx2};
    EXPECT_EQ(choose_simd_level(SimdKernel::Relight, no_avx512, kZen5, rules), SimdLevel::Avx2);
  }
  {
    const SimdEnv env("");  // empty: as if unset
    EXPECT_EQ(choose_simd_level(SimdKernel::Relight, kAll, kZen5, rules), SimdLevel::Avx2);
  }
  {
    const SimdEnv env("fast");
    EXPECT_THROW((void)choose_simd_level(SimdKernel::Relight, kAll, kZen5, rules), InputError);
  }
}

TEST(SimdChoice, AForcedLevelWinsAndIsPutBack) {
  const SimdEnv env("avx2");
  const std::vector<SimdRule> none;
  {
    const ForcedSimdLevel outer(SimdKernel::Relight, SimdLevel::Sse4);
    EXPECT_EQ(choose_simd_level(SimdKernel::Relight, kAll, kZen5, none), SimdLevel::Sse4);
    EXPECT_EQ(choose_simd_level(SimdKernel::CompressedFrame, kAll, kZen5, none), SimdLevel::Avx2) << "per kernel";
    {
      const ForcedSimdLevel inner(SimdKernel::Relight, SimdLevel::Baseline);
      EXPECT_EQ(choose_simd_level(SimdKernel::Relight, kAll, kZen5, none), SimdLevel::Baseline);
    }
    EXPECT_EQ(choose_simd_level(SimdKernel::Relight, kAll, kZen5, none), SimdLevel::Sse4);
  }
  EXPECT_EQ(choose_simd_level(SimdKernel::Relight, kAll, kZen5, none), SimdLevel::Avx2) << "PRIZMA_SIMD again";
}

TEST(SimdChoice, ThisCpuIsIdentified) {
  const CpuModel& cpu = this_cpu();
#if defined(__x86_64__)
  EXPECT_EQ(cpu.vendor.size(), 12u) << cpu.vendor;  // CPUID's 12 characters: "AuthenticAMD", "GenuineIntel"
  EXPECT_GT(cpu.family, 0);
#else
  EXPECT_TRUE(cpu.vendor.empty());
#endif
}

}  // namespace
}  // namespace prizma::spectral
