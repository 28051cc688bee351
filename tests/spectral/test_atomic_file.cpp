// write_atomically: the destination holds the old file or the complete new one, never a partial one.
#include <gtest/gtest.h>
#include <sys/stat.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <sstream>
#include <stdexcept>
#include <string>

#include "prizma/spectral/atomic_file.h"
#include "prizma/spectral/error.h"

namespace fs = std::filesystem;
using prizma::spectral::RuntimeError;
using prizma::spectral::write_atomically;

namespace {

fs::path scratch_dir(const std::string& name) {
  const fs::path dir = fs::temp_directory_path() /
                       ("prizma-test-atomic-" + std::to_string(::getpid()) + "-" + name);
  fs::remove_all(dir);
  fs::create_directories(dir);
  return dir;
}

std::string read_all(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

void write_text(const fs::path& p, const std::string& text) {
  std::ofstream out(p, std::ios::binary);
  out << text;
  if (!out) throw std::runtime_error("cannot write " + p.string());
}

int entries_in(const fs::path& dir) {
  int n = 0;
  for ([[maybe_unused]] const auto& e : fs::directory_iterator(dir)) ++n;
  return n;
}

}  // namespace

TEST(AtomicFile, SuccessCreatesFileAndTemporaryKeepsExtension) {
  const fs::path dir = scratch_dir("create");
  const fs::path dest = dir / "image.exr";
  fs::path seen_tmp;
  write_atomically(dest, [&](const fs::path& tmp) {
    seen_tmp = tmp;
    write_text(tmp, "new contents");
  });
  EXPECT_EQ(read_all(dest), "new contents");
  EXPECT_EQ(seen_tmp.parent_path(), dir);
  EXPECT_EQ(seen_tmp.extension(), ".exr");
  EXPECT_EQ(seen_tmp.filename().string().rfind(".prizma-tmp-" + std::to_string(::getpid()) + "-", 0), 0u)
      << seen_tmp;
  EXPECT_FALSE(fs::exists(seen_tmp));
  EXPECT_EQ(entries_in(dir), 1);
  fs::remove_all(dir);
}

TEST(AtomicFile, SuccessReplacesExistingFile) {
  const fs::path dir = scratch_dir("replace");
  const fs::path dest = dir / "out.csv";
  write_text(dest, "old contents that are longer than the new ones");
  write_atomically(dest, [&](const fs::path& tmp) { write_text(tmp, "new"); });
  EXPECT_EQ(read_all(dest), "new");
  EXPECT_EQ(entries_in(dir), 1);
  fs::remove_all(dir);
}

TEST(AtomicFile, FailingWriterLeavesNoFile) {
  const fs::path dir = scratch_dir("fail-new");
  const fs::path dest = dir / "out.png";
  fs::path seen_tmp;
  EXPECT_THROW(write_atomically(dest,
                                [&](const fs::path& tmp) {
                                  seen_tmp = tmp;
                                  write_text(tmp, "half a fi");
                                  throw std::runtime_error("writer failed");
                                }),
               std::runtime_error);
  EXPECT_FALSE(fs::exists(dest));
  EXPECT_FALSE(seen_tmp.empty());
  EXPECT_FALSE(fs::exists(seen_tmp));
  EXPECT_EQ(entries_in(dir), 0);
  fs::remove_all(dir);
}

TEST(AtomicFile, FailingWriterKeepsExistingFile) {
  const fs::path dir = scratch_dir("fail-keep");
  const fs::path dest = dir / "out.exr";
  write_text(dest, "precious");
  try {
    write_atomically(dest, [&](const fs::path& tmp) {
      write_text(tmp, "garbage");
      throw std::logic_error("boom");
    });
    FAIL() << "the writer's exception must propagate";
  } catch (const std::logic_error& e) {
    EXPECT_STREQ(e.what(), "boom");
  }
  EXPECT_EQ(read_all(dest), "precious");
  EXPECT_EQ(entries_in(dir), 1);
  fs::remove_all(dir);
}

TEST(AtomicFile, MissingFolderIsRuntimeErrorNamingIt) {
  const fs::path dir = scratch_dir("missing");
  const fs::path dest = dir / "no" / "such" / "folder" / "out.exr";
  bool called = false;
  try {
    write_atomically(dest, [&](const fs::path&) { called = true; });
    FAIL() << "expected RuntimeError";
  } catch (const RuntimeError& e) {
    const std::string msg = e.what();
    EXPECT_NE(msg.find((dir / "no" / "such" / "folder").string()), std::string::npos) << msg;
    EXPECT_NE(msg.find("does not exist"), std::string::npos) << msg;
  }
  EXPECT_FALSE(called);
  fs::remove_all(dir);
}

TEST(AtomicFile, ReadOnlyFolderIsRuntimeError) {
  if (::geteuid() == 0) GTEST_SKIP() << "root can write into read-only folders";
  const fs::path dir = scratch_dir("readonly");
  fs::permissions(dir, fs::perms::owner_read | fs::perms::owner_exec);
  try {
    write_atomically(dir / "out.exr", [](const fs::path& tmp) { write_text(tmp, "x"); });
    ADD_FAILURE() << "expected RuntimeError";
  } catch (const RuntimeError& e) {
    EXPECT_NE(std::string(e.what()).find("not writable"), std::string::npos) << e.what();
  }
  fs::permissions(dir, fs::perms::owner_all);
  fs::remove_all(dir);
}

TEST(AtomicFile, WriterThatCreatesNothingIsRuntimeError) {
  const fs::path dir = scratch_dir("nothing");
  EXPECT_THROW(write_atomically(dir / "out.txt", [](const fs::path&) {}), RuntimeError);
  EXPECT_EQ(entries_in(dir), 0);
  fs::remove_all(dir);
}

TEST(AtomicFile, TemporaryNamesAreUnique) {
  const fs::path dir = scratch_dir("unique");
  fs::path first, second;
  write_atomically(dir / "a.txt", [&](const fs::path& tmp) {
    first = tmp;
    write_text(tmp, "1");
  });
  write_atomically(dir / "a.txt", [&](const fs::path& tmp) {
    second = tmp;
    write_text(tmp, "2");
  });
  EXPECT_NE(first, second);
  EXPECT_EQ(read_all(dir / "a.txt"), "2");
  fs::remove_all(dir);
}
