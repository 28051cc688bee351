// The live page's Save (save_folder.h): plain names in one folder, never the served file (nor a hard
// link to it), never through a symbolic link, at most SaveFolder::kMaxCreatedFiles new files.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <string>

#include "prizma/relight/save_folder.h"
#include "prizma/spectral/error.h"
#include "spectral/relight_test_util.h"

namespace prizma::relight {
namespace {

namespace fs = std::filesystem;

class SaveFolderTest : public ::testing::Test {
 protected:
  void SetUp() override {
    dir = spectral::test::scratch_dir(std::string("save-folder-") +
                            ::testing::UnitTest::GetInstance()->current_test_info()->name());
    served = dir / "scene.exr";
    write_text(served, "served");
  }
  void TearDown() override { fs::remove_all(dir); }

  static void write_text(const fs::path& p, const std::string& text) { std::ofstream(p) << text; }
  static std::string read_text(const fs::path& p) {
    std::ifstream in(p);
    return std::string(std::istreambuf_iterator<char>(in), {});
  }
  // A writer standing in for RelightSession::save.
  static std::function<void(const fs::path&)> writes(const std::string& text) {
    return [text](const fs::path& p) { write_text(p, text); };
  }
  std::string refusal(SaveFolder& f, const std::string& name) {
    try {
      f.save(name, writes("new"));
    } catch (const spectral::InputError& e) {
      return e.what();
    }
    return {};
  }

  fs::path dir, served;
};

TEST_F(SaveFolderTest, WritesPlainNamesInsideTheFolder) {
  SaveFolder f(dir, served);
  EXPECT_EQ(f.save("relit.png", writes("png")), dir / "relit.png");
  EXPECT_EQ(read_text(dir / "relit.png"), "png");
  EXPECT_EQ(f.created(), 1);
  f.save("relit.png", writes("again"));  // over its own file: not a new one
  EXPECT_EQ(f.created(), 1);
}

TEST_F(SaveFolderTest, RefusesNamesThatAreNotPlainImageNames) {
  SaveFolder f(dir, served);
  EXPECT_NE(refusal(f, "../escape.png").find("is not a plain file name"), std::string::npos);
  EXPECT_NE(refusal(f, ".hidden.png").find("is not a plain file name"), std::string::npos);
  EXPECT_NE(refusal(f, "x.bmp"), "");
  EXPECT_FALSE(fs::exists(dir.parent_path() / "escape.png"));
}

TEST_F(SaveFolderTest, NeverWritesTheServedFileNorAHardLinkToIt) {
  SaveFolder f(dir, served);
  EXPECT_EQ(refusal(f, "scene.exr"), "file: \"scene.exr\" is the file being served; Save never replaces it");
  fs::create_hard_link(served, dir / "also.exr");
  EXPECT_EQ(refusal(f, "also.exr"), "file: \"also.exr\" is the file being served; Save never replaces it");
  EXPECT_EQ(read_text(served), "served");
}

TEST_F(SaveFolderTest, NeverWritesThroughASymbolicLink) {
  const fs::path outside = dir.string() + "-outside.png";
  write_text(outside, "outside");
  fs::create_symlink(outside, dir / "link.png");
  SaveFolder f(dir, served);
  EXPECT_EQ(refusal(f, "link.png"),
            "file: \"link.png\" is a symbolic link in the save folder; Save does not follow links");
  EXPECT_EQ(read_text(outside), "outside");
  fs::remove(outside);
}

TEST_F(SaveFolderTest, CreatesAtMostTheLimitOfNewFiles) {
  write_text(dir / "before.png", "x");  // files that were there do not count
  SaveFolder f(dir, served);
  for (int i = 0; i < SaveFolder::kMaxCreatedFiles; ++i) f.save("f" + std::to_string(i) + ".png", writes(""));
  EXPECT_EQ(refusal(f, "one_more.png"),
            "file: this server has already created 1000 files; save over one of them, or restart prizma-relight --serve");
  EXPECT_FALSE(fs::exists(dir / "one_more.png"));
  EXPECT_EQ(refusal(f, "f7.png"), "");  // over one of them: still allowed
  EXPECT_EQ(refusal(f, "before.png"), "");
}

TEST_F(SaveFolderTest, RefusesAFolderThatIsMissing) {
  EXPECT_THROW(SaveFolder(dir / "no_such", served), spectral::InputError);
}

}  // namespace
}  // namespace prizma::relight
