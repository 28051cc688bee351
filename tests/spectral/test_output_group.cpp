// OutputGroup: the outputs of one run appear together or not at all; and InputRecording: no output
// replaces a file the run reads (docs/errors.md, "Outputs").
#include <gtest/gtest.h>

#include <filesystem>
#include <functional>
#include <stdexcept>
#include <string>
#include <vector>

#include "prizma/spectral/atomic_file.h"
#include "prizma/spectral/error.h"
#include "prizma/spectral/input_file.h"
#include "prizma/spectral/output_group.h"
#include "spectral/scratch_files.h"

namespace fs = std::filesystem;
using prizma::spectral::AtomicOutput;
using prizma::spectral::check_distinct_outputs;
using prizma::spectral::check_output_file;
using prizma::spectral::InputError;
using prizma::spectral::InputRecording;
using prizma::spectral::OutputGroup;
using prizma::spectral::RuntimeError;

namespace {

using prizma::spectral::test::read_all;

fs::path scratch_dir(const std::string& name) { return prizma::spectral::test::scratch_dir("group", name); }

void put(const fs::path& p, const std::string& text) { prizma::spectral::test::write_text(p, text); }

std::function<void(AtomicOutput&)> text(const std::string& t) {
  return [t](AtomicOutput& out) {
    if (!out.write(t)) throw std::runtime_error("write failed");
  };
}

// The names in `dir` that start with a prefix Prizma gives its own files (temporaries, kept links).
std::vector<std::string> leftovers(const fs::path& dir) {
  std::vector<std::string> out;
  for (const auto& e : fs::directory_iterator(dir)) {
    const std::string n = e.path().filename().string();
    if (n.rfind(".prizma-", 0) == 0) out.push_back(n);
  }
  return out;
}

std::string message_of(const std::function<void()>& f) {
  try {
    f();
  } catch (const std::exception& e) {
    return e.what();
  }
  return {};
}

}  // namespace

TEST(OutputGroup, NothingAppearsBeforeCommitThenEverything) {
  const fs::path dir = scratch_dir("commit");
  put(dir / "a.exr", "old a");
  OutputGroup group;
  group.write(dir / "a.exr", text("new a"));
  group.write(dir / "b.png", text("new b"));
  EXPECT_EQ(group.size(), 2u);
  EXPECT_EQ(read_all(dir / "a.exr"), "old a");
  EXPECT_FALSE(fs::exists(dir / "b.png"));
  group.commit();
  EXPECT_EQ(read_all(dir / "a.exr"), "new a");
  EXPECT_EQ(read_all(dir / "b.png"), "new b");
  EXPECT_TRUE(leftovers(dir).empty());
}

TEST(OutputGroup, ALaterFailedWriteLeavesNoOutput) {
  const fs::path dir = scratch_dir("later");
  put(dir / "a.exr", "old a");
  put(dir / "b.png", "old b");
  OutputGroup group;
  group.write(dir / "a.exr", text("new a"));
  const std::string msg = message_of([&] {
    group.write(dir / "b.png", [](AtomicOutput& out) { out.fail("No space left on device"); });
  });
  EXPECT_NE(msg.find("b.png: cannot write: No space left on device (the existing file is unchanged; "), std::string::npos)
      << msg;
  EXPECT_NE(msg.find("a.exr was not written either)"), std::string::npos) << msg;
  group.commit();  // nothing left to commit
  EXPECT_EQ(read_all(dir / "a.exr"), "old a");
  EXPECT_EQ(read_all(dir / "b.png"), "old b");
  EXPECT_TRUE(leftovers(dir).empty());
}

TEST(OutputGroup, DestroyedWithoutCommitLeavesNothing) {
  const fs::path dir = scratch_dir("abandon");
  put(dir / "a.exr", "old a");
  {
    OutputGroup group;
    group.write(dir / "a.exr", text("new a"));
    group.write(dir / "b.png", text("new b"));
  }
  EXPECT_EQ(read_all(dir / "a.exr"), "old a");
  EXPECT_FALSE(fs::exists(dir / "b.png"));
  EXPECT_TRUE(leftovers(dir).empty());
}

// The second rename fails (its destination became a folder after the temporaries were written): the
// first output, already in place, is put back: the old file from its link, a new one removed.
TEST(OutputGroup, AFailedRenameUndoesTheOnesBefore) {
  const fs::path dir = scratch_dir("rename");
  put(dir / "a.exr", "old a");
  OutputGroup group;
  group.write(dir / "a.exr", text("new a"));
  group.write(dir / "new.txt", text("new file"));
  group.write(dir / "c.png", text("new c"));
  fs::create_directories(dir / "c.png" / "inside");  // rename(file, non-empty folder) fails
  const std::string msg = message_of([&] { group.commit(); });
  EXPECT_NE(msg.find("c.png: cannot write: cannot rename"), std::string::npos) << msg;
  EXPECT_NE(msg.find("(" + (dir / "new.txt").string() + " was removed again and " + (dir / "a.exr").string() +
                     " was put back as it was)"),
            std::string::npos)
      << msg;
  EXPECT_EQ(read_all(dir / "a.exr"), "old a");
  EXPECT_FALSE(fs::exists(dir / "new.txt"));
  EXPECT_TRUE(fs::is_directory(dir / "c.png"));
  EXPECT_TRUE(leftovers(dir).empty());
}

// Outputs that are inputs of the run: refused by identity (./in, a hard link, a symbolic link), naming
// the option and the input; an in-place update only by the options allowed; nothing without recording.
TEST(InputRecording, OutputsThatAreInputsAreRefused) {
  const fs::path dir = scratch_dir("inputs");
  put(dir / "in.exr", "input");
  fs::create_hard_link(dir / "in.exr", dir / "hard.exr");
  fs::create_symlink("in.exr", dir / "link.exr");
  EXPECT_NO_THROW(check_output_file(dir / "in.exr", "-o"));  // not recorded: nothing refused
  const InputRecording recording;
  prizma::spectral::require_regular_file(dir / "in.exr", "an OpenEXR file");
  for (const fs::path& out : {dir / "in.exr", dir / "." / "in.exr", dir / "hard.exr", dir / "link.exr"}) {
    const std::string msg = message_of([&] { check_output_file(out, "-o"); });
    EXPECT_EQ(msg, "-o: \"" + out.string() + "\" would replace \"" + (dir / "in.exr").string() +
                       "\", the OpenEXR file this run reads (an output never replaces an input)");
  }
  EXPECT_THROW(check_distinct_outputs({{dir / "new.png", "--preview"}, {dir / "hard.exr", "-o"}}), InputError);
  EXPECT_THROW(prizma::spectral::write_file_atomically(dir / "link.exr", "x"), InputError);
  EXPECT_EQ(read_all(dir / "in.exr"), "input");

  prizma::spectral::allow_in_place_update(dir / "in.exr", {"--resume"});
  EXPECT_NO_THROW(check_output_file(dir / "hard.exr", "--resume"));
  EXPECT_THROW(check_output_file(dir / "in.exr", "--preview"), InputError);
  prizma::spectral::write_file_atomically(dir / "in.exr", "updated");  // allowed in place for some output
  EXPECT_EQ(read_all(dir / "hard.exr"), "input");  // the link keeps the old inode: replaced, not rewritten
  EXPECT_EQ(read_all(dir / "in.exr"), "updated");
}
