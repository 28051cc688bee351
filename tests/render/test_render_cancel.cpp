// issue 11: one Ctrl-C must stop a render whose current pass would run for a long time: the
// cancel flag is polled at every sample, the cut pass is abandoned and the completed passes kept.
#include <gtest/gtest.h>

#include <atomic>
#include <chrono>
#include <cstring>
#include <thread>

#include "prizma/render/render.h"
#include "prizma/spectral/error.h"
#include "render_test_scenes.h"

namespace prizma::render {
namespace {

using spectral::Spectrum;

Scene dense_scene(std::int64_t spp) {
  Scene s = testing::box_scene(testing::make_material(Spectrum::constant(0.9), Spectrum::constant(20.0),
                                                      Spectrum::constant(0.3)),
                               8, 4, spp);
  s.lights.push_back(testing::directional_light("sun", {0.5, 1, 0.2}));
  return s;
}

// Raises `cancel` from another thread after `delay` once start() is called.
class Raiser {
 public:
  explicit Raiser(std::atomic<bool>& cancel) : m_cancel(cancel) {}
  ~Raiser() {
    if (m_thread.joinable()) m_thread.join();
  }
  void start(std::chrono::milliseconds delay) {
    if (m_thread.joinable()) return;
    m_thread = std::thread([this, delay] {
      std::this_thread::sleep_for(delay);
      m_cancel = true;
    });
  }

 private:
  std::atomic<bool>& m_cancel;
  std::thread m_thread;
};

TEST(RenderCancel, StopsInsideTheFirstPass) {
  // One pass of 2^26 samples of one pixel (about a minute): before the fix the flag was read
  // only between passes, so the render ran it to the end and returned it.
  Scene s = dense_scene(std::int64_t{1} << 26);
  s.camera.width = s.camera.height = 1;
  std::atomic<bool> cancel{false};
  RenderCallbacks cb;
  cb.cancel = &cancel;
  cb.samples_per_pass = s.settings.sample_end;
  Raiser raiser(cancel);
  raiser.start(std::chrono::milliseconds(50));
  EXPECT_THROW(render(s, cb), spectral::RuntimeError);
}

TEST(RenderCancel, ACutPassIsAbandonedAndTheCompletedPassesKept) {
  // Passes of 2^16 samples of 2×2 pixels; the cancel is raised as soon as pass 1 is reported, so
  // it lands before or inside pass 2: either way the result is exactly pass 1.
  constexpr std::int64_t kPass = std::int64_t{1} << 16;
  Scene s = dense_scene(64 * kPass);
  s.camera.width = s.camera.height = 2;
  std::atomic<bool> cancel{false};
  Raiser raiser(cancel);
  RenderCallbacks cb;
  cb.samples_per_pass = kPass;
  cb.cancel = &cancel;
  cb.progress = [&](const RenderProgress&) { raiser.start(std::chrono::milliseconds(0)); };
  RenderStats stats;
  const auto partial = render(s, cb, &stats);
  EXPECT_TRUE(stats.interrupted);
  EXPECT_EQ(partial.info.samples, kPass);
  EXPECT_EQ(partial.info.sample_range, "0:65536");
  // The kept pass is bit for bit the uninterrupted render of the same samples.
  Scene ref = s;
  ref.settings.sample_end = kPass;
  const auto full = render(ref);
  ASSERT_EQ(full.lights.size(), partial.lights.size());
  for (std::size_t l = 0; l < full.lights.size(); ++l) {
    ASSERT_EQ(full.lights[l].data.size(), partial.lights[l].data.size());
    EXPECT_EQ(std::memcmp(full.lights[l].data.data(), partial.lights[l].data.data(),
                          full.lights[l].data.size() * sizeof(float)),
              0);
  }
}

}  // namespace
}  // namespace prizma::render
