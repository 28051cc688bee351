// write_atomically: the destination holds the old file or the complete new one, never a partial one.
#include <gtest/gtest.h>
#include <sys/resource.h>
#include <sys/socket.h>
#include <sys/stat.h>
#include <sys/sysmacros.h>
#include <sys/un.h>
#include <unistd.h>

#include <csignal>
#include <cstring>
#include <functional>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "prizma/spectral/atomic_file.h"
#include "prizma/spectral/error.h"
#include "spectral/scratch_files.h"

namespace fs = std::filesystem;
using prizma::spectral::AtomicOutput;
using prizma::spectral::check_distinct_outputs;
using prizma::spectral::check_output_file;
using prizma::spectral::InputError;
using prizma::spectral::RuntimeError;
using prizma::spectral::write_atomically;

namespace {

using prizma::spectral::test::read_all;
using prizma::spectral::test::write_text;

fs::path scratch_dir(const std::string& name) { return prizma::spectral::test::scratch_dir("atomic", name); }

void write_text(AtomicOutput& out, const std::string& text) {
  if (!out.write(text)) throw std::runtime_error("cannot write " + out.temporary().string());
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
  write_atomically(dest, [&](AtomicOutput& out) {
    seen_tmp = out.temporary();
    write_text(out, "new contents");
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
  write_atomically(dest, [&](AtomicOutput& out) { write_text(out, "new"); });
  EXPECT_EQ(read_all(dest), "new");
  EXPECT_EQ(entries_in(dir), 1);
  fs::remove_all(dir);
}

TEST(AtomicFile, FailingWriterLeavesNoFile) {
  const fs::path dir = scratch_dir("fail-new");
  const fs::path dest = dir / "out.png";
  fs::path seen_tmp;
  EXPECT_THROW(write_atomically(dest,
                                [&](AtomicOutput& out) {
                                  seen_tmp = out.temporary();
                                  write_text(out, "half a fi");
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
    write_atomically(dest, [&](AtomicOutput& out) {
      write_text(out, "garbage");
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
    write_atomically(dest, [&](AtomicOutput&) { called = true; });
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
    write_atomically(dir / "out.exr", [](AtomicOutput& out) { write_text(out, "x"); });
    ADD_FAILURE() << "expected RuntimeError";
  } catch (const RuntimeError& e) {
    EXPECT_NE(std::string(e.what()).find("not writable"), std::string::npos) << e.what();
  }
  fs::permissions(dir, fs::perms::owner_all);
  fs::remove_all(dir);
}

TEST(AtomicFile, WriterThatWritesNothingIsRuntimeError) {
  const fs::path dir = scratch_dir("nothing");
  EXPECT_THROW(write_atomically(dir / "out.txt", [](AtomicOutput&) {}), RuntimeError);
  EXPECT_EQ(entries_in(dir), 0);
  fs::remove_all(dir);
}

TEST(AtomicFile, TemporaryNamesAreUnique) {
  const fs::path dir = scratch_dir("unique");
  fs::path first, second;
  write_atomically(dir / "a.txt", [&](AtomicOutput& out) {
    first = out.temporary();
    write_text(out, "1");
  });
  write_atomically(dir / "a.txt", [&](AtomicOutput& out) {
    second = out.temporary();
    write_text(out, "2");
  });
  EXPECT_NE(first, second);
  EXPECT_EQ(read_all(dir / "a.txt"), "2");
  fs::remove_all(dir);
}

// ---------------------------------------------------------------------------------------------
// Failed writes: every write is checked, the old file survives (docs/errors.md, "Outputs").

namespace {

// A file-size limit for the scope (SIGXFSZ ignored, so a write past it fails with EFBIG), as
// `(trap '' XFSZ; ulimit -f N; …)` does for a tool.
class FileSizeLimit {
 public:
  explicit FileSizeLimit(rlim_t bytes) {
    ::getrlimit(RLIMIT_FSIZE, &m_old);
    m_old_handler = std::signal(SIGXFSZ, SIG_IGN);
    struct rlimit lim = m_old;
    lim.rlim_cur = bytes;
    m_ok = ::setrlimit(RLIMIT_FSIZE, &lim) == 0;
  }
  ~FileSizeLimit() {
    ::setrlimit(RLIMIT_FSIZE, &m_old);
    std::signal(SIGXFSZ, m_old_handler);
  }
  bool ok() const { return m_ok; }

 private:
  struct rlimit m_old {};
  void (*m_old_handler)(int) = nullptr;
  bool m_ok = false;
};

// The message of the exception write_atomically throws, "" when it throws none.
template <typename Error>
std::string error_of(const fs::path& dest, const std::function<void(AtomicOutput&)>& writer) {
  try {
    write_atomically(dest, writer);
  } catch (const Error& e) {
    return e.what();
  }
  return "";
}

template <typename Error>
std::string check_error(const fs::path& path) {
  try {
    check_output_file(path, "-o");
  } catch (const Error& e) {
    return e.what();
  }
  return "";
}

}  // namespace

TEST(AtomicFile, WriteBeyondFileSizeLimitFailsAndKeepsTheOldFile) {
  const fs::path dir = scratch_dir("fsize");
  const fs::path dest = dir / "out.csv";
  write_text(dest, "precious");
  std::string msg;
  {
    FileSizeLimit limit(1024);
    ASSERT_TRUE(limit.ok());
    // Writers that ignore the result (as OpenImageIO's PNG writer does) still fail the file.
    msg = error_of<RuntimeError>(dest, [](AtomicOutput& out) {
      const std::string block(4096, 'x');
      (void)out.write(block);
      (void)out.write(block);
    });
  }
  EXPECT_NE(msg.find("File too large"), std::string::npos) << msg;
  EXPECT_NE(msg.find(dest.string()), std::string::npos) << msg;
  EXPECT_NE(msg.find("existing file is unchanged"), std::string::npos) << msg;
  EXPECT_EQ(read_all(dest), "precious");
  EXPECT_EQ(entries_in(dir), 1);
  fs::remove_all(dir);
}

TEST(AtomicFile, FailedWriteIsStickyAndItsReasonWinsOverTheWritersException) {
  const fs::path dir = scratch_dir("sticky");
  const fs::path dest = dir / "out.exr";
  std::string msg;
  bool later_write_failed = false;
  {
    FileSizeLimit limit(100);
    ASSERT_TRUE(limit.ok());
    msg = error_of<RuntimeError>(dest, [&](AtomicOutput& out) {
      const std::string block(200, 'x');
      EXPECT_FALSE(out.write(block));
      later_write_failed = !out.write("y", 1) && !out.write_at("y", 1, 0);
      throw std::runtime_error("the library's own vague message");
    });
  }
  EXPECT_TRUE(later_write_failed);
  EXPECT_NE(msg.find("File too large"), std::string::npos) << msg;
  EXPECT_EQ(msg.find("vague"), std::string::npos) << msg;
  EXPECT_FALSE(fs::exists(dest));
  EXPECT_EQ(entries_in(dir), 0);
  fs::remove_all(dir);
}

TEST(AtomicFile, WriterReportedFailureFailsTheFile) {
  const fs::path dir = scratch_dir("fail-report");
  const fs::path dest = dir / "out.png";
  const std::string msg = error_of<RuntimeError>(dest, [](AtomicOutput& out) {
    write_text(out, "data");
    out.fail("encoder: out of cheese");
  });
  EXPECT_NE(msg.find("out of cheese"), std::string::npos) << msg;
  EXPECT_EQ(entries_in(dir), 0);
  fs::remove_all(dir);
}

TEST(AtomicFile, SeekAndWriteAtBuildTheFileLikeASeekingWriter) {
  const fs::path dir = scratch_dir("seek");
  const fs::path dest = dir / "out.bin";
  write_atomically(dest, [](AtomicOutput& out) {
    write_text(out, "....body");
    ASSERT_TRUE(out.write_at("HEAD", 4, 0));  // a table patched at the start, as EXR and TIFF do
    EXPECT_EQ(out.tell(), 8);
    ASSERT_TRUE(out.seek(8));
    write_text(out, "!");
    char back[4] = {};
    EXPECT_EQ(out.read_at(back, 4, 0), 4u);
    EXPECT_EQ(std::string(back, 4), "HEAD");
    EXPECT_EQ(out.size(), 9);
  });
  EXPECT_EQ(read_all(dest), "HEADbody!");
  fs::remove_all(dir);
}

TEST(AtomicFile, ReplacedFileKeepsItsPermissions) {
  const fs::path dir = scratch_dir("mode");
  const fs::path dest = dir / "out.csv";
  write_text(dest, "old");
  ::chmod(dest.c_str(), 0640);
  prizma::spectral::write_file_atomically(dest, "new");
  struct stat st {};
  ASSERT_EQ(::stat(dest.c_str(), &st), 0);
  EXPECT_EQ(st.st_mode & 07777, 0640u);
  EXPECT_EQ(read_all(dest), "new");
  fs::remove_all(dir);
}

// ---------------------------------------------------------------------------------------------
// Special files and links as outputs

TEST(AtomicFile, DevicesFifosSocketsAndFoldersAreRefusedAndNeverReplaced) {
  const fs::path dir = scratch_dir("special");
  const fs::path fifo = dir / "pipe.png";
  ASSERT_EQ(::mkfifo(fifo.c_str(), 0600), 0);
  const fs::path sock = dir / "sock.png";
  const int fd = ::socket(AF_UNIX, SOCK_STREAM, 0);
  ASSERT_GE(fd, 0);
  sockaddr_un addr{};
  addr.sun_family = AF_UNIX;
  ASSERT_LT(sock.string().size(), sizeof addr.sun_path);
  std::strcpy(addr.sun_path, sock.c_str());
  ASSERT_EQ(::bind(fd, reinterpret_cast<const sockaddr*>(&addr), sizeof addr), 0);
  fs::create_directory(dir / "folder.png");
  // A device: as root a private copy of /dev/null (root could replace the real one if this broke).
  fs::path device = "/dev/null";
  if (::geteuid() == 0) device = ::mknod((dir / "null").c_str(), S_IFCHR | 0666, makedev(1, 3)) == 0 ? dir / "null" : "";
  EXPECT_NE(check_error<InputError>("/dev/null").find("character device"), std::string::npos);
  std::vector<std::pair<fs::path, std::string>> cases = {
      {fifo, "FIFO"}, {sock, "socket"}, {dir / "folder.png", "folder"}};
  if (!device.empty()) cases.emplace_back(device, "character device");
  for (const auto& [path, kind] : cases) {
    const std::string msg = check_error<InputError>(path);
    EXPECT_NE(msg.find(kind), std::string::npos) << path << ": " << msg;
    EXPECT_EQ(msg.rfind("-o: \"" + path.string() + "\"", 0), 0u) << msg;
    bool called = false;
    const std::string write_msg = error_of<InputError>(path, [&](AtomicOutput& out) {
      called = true;
      write_text(out, "x");
    });
    EXPECT_NE(write_msg.find(kind), std::string::npos) << path << ": " << write_msg;
    EXPECT_FALSE(called) << path;
  }
  struct stat st {};
  if (!device.empty()) {
    ASSERT_EQ(::stat(device.c_str(), &st), 0);
    EXPECT_TRUE(S_ISCHR(st.st_mode));
  }
  ASSERT_EQ(::lstat(fifo.c_str(), &st), 0);
  EXPECT_TRUE(S_ISFIFO(st.st_mode));
  ASSERT_EQ(::lstat(sock.c_str(), &st), 0);
  EXPECT_TRUE(S_ISSOCK(st.st_mode));
  ::close(fd);
  EXPECT_EQ(entries_in(dir), device == dir / "null" ? 4 : 3);  // no temporaries
  fs::remove_all(dir);
}

TEST(AtomicFile, SymlinkToAFileHasItsTargetReplacedAndTheLinkKept) {
  const fs::path dir = scratch_dir("symlink");
  fs::create_directories(dir / "real");
  fs::create_directories(dir / "links");
  const fs::path target = dir / "real" / "image.png";
  write_text(target, "old");
  const fs::path link = dir / "links" / "latest.png";
  fs::create_symlink("../real/image.png", link);
  EXPECT_EQ(check_output_file(link, "-o").file, fs::canonical(target));
  fs::path seen_tmp;
  write_atomically(link, [&](AtomicOutput& out) {
    seen_tmp = out.temporary();
    write_text(out, "new");
  });
  EXPECT_TRUE(fs::is_symlink(link));
  EXPECT_EQ(fs::read_symlink(link), fs::path("../real/image.png"));
  EXPECT_EQ(read_all(target), "new");
  EXPECT_EQ(fs::canonical(seen_tmp.parent_path()), fs::canonical(dir / "real"));  // beside the target
  EXPECT_EQ(entries_in(dir / "real"), 1);
  EXPECT_EQ(entries_in(dir / "links"), 1);
  fs::remove_all(dir);
}

TEST(AtomicFile, DanglingSymlinkAndSymlinkLoopAreRefused) {
  const fs::path dir = scratch_dir("dangling");
  fs::create_symlink("nowhere/missing.png", dir / "dangling.png");
  fs::create_symlink("loop-b.png", dir / "loop-a.png");
  fs::create_symlink("loop-a.png", dir / "loop-b.png");
  std::string msg = check_error<InputError>(dir / "dangling.png");
  EXPECT_NE(msg.find("symbolic link to a file that does not exist"), std::string::npos) << msg;
  EXPECT_NE(msg.find("nowhere/missing.png"), std::string::npos) << msg;
  msg = check_error<InputError>(dir / "loop-a.png");
  EXPECT_NE(msg.find("too many levels of symbolic links"), std::string::npos) << msg;
  EXPECT_FALSE(error_of<InputError>(dir / "dangling.png", [](AtomicOutput& out) { write_text(out, "x"); }).empty());
  EXPECT_TRUE(fs::is_symlink(dir / "dangling.png"));
  EXPECT_FALSE(fs::exists(dir / "nowhere"));
  EXPECT_EQ(entries_in(dir), 3);
  fs::remove_all(dir);
}

TEST(AtomicFile, MissingOrReadOnlyFolderIsInputErrorBeforeTheWork) {
  const fs::path dir = scratch_dir("check-folder");
  std::string msg = check_error<InputError>(dir / "no" / "out.png");
  EXPECT_NE(msg.find("does not exist"), std::string::npos) << msg;
  msg = check_error<InputError>(dir / "out.png" / "");
  EXPECT_NE(msg.find("not a file name"), std::string::npos) << msg;
  write_text(dir / "file", "x");
  msg = check_error<InputError>(dir / "file" / "out.png");
  EXPECT_NE(msg.find("not a folder"), std::string::npos) << msg;
  EXPECT_NO_THROW(check_output_file(dir / "out.png", "-o"));
  fs::remove_all(dir);
}

// The temporary's prefix ".prizma-tmp-<pid>-<n>-" must not make a valid name too long.
TEST(AtomicFile, LongestNamesStillWriteAndLongerOnesAreRefusedBeforeTheWork) {
  const fs::path dir = scratch_dir("long");
  const fs::path longest = dir / (std::string(251, 'n') + ".png");  // 255 bytes: NAME_MAX
  fs::path seen_tmp;
  write_atomically(longest, [&](AtomicOutput& out) {
    seen_tmp = out.temporary();
    write_text(out, "ok");
  });
  EXPECT_EQ(read_all(longest), "ok");
  EXPECT_EQ(seen_tmp.extension(), ".png");
  EXPECT_LE(seen_tmp.filename().string().size(), 255u);
  const std::string msg = check_error<InputError>(dir / (std::string(252, 'n') + ".png"));
  EXPECT_NE(msg.find("256 bytes long"), std::string::npos) << msg;
  EXPECT_EQ(entries_in(dir), 1);
  fs::remove_all(dir);
}

// ---------------------------------------------------------------------------------------------
// Two outputs of one run in one file

TEST(AtomicFile, TwoOutputsResolvingToOneFileAreRefused) {
  const fs::path dir = scratch_dir("distinct");
  fs::create_directories(dir / "sub");
  write_text(dir / "a.png", "a");
  fs::create_symlink("a.png", dir / "link.png");
  fs::create_hard_link(dir / "a.png", dir / "hard.png");
  fs::create_directory_symlink("sub", dir / "alias");
  using Outputs = std::vector<std::pair<fs::path, std::string>>;
  const auto refused = [](const Outputs& outs) {
    try {
      check_distinct_outputs(outs);
    } catch (const InputError& e) {
      return std::string(e.what());
    }
    return std::string();
  };
  const std::string msg = refused({{dir / "a.png", "-o"}, {dir / "." / "a.png", "--preview"}});
  EXPECT_EQ(msg.rfind("--preview: ", 0), 0u) << msg;
  EXPECT_NE(msg.find("is the same file as -o"), std::string::npos) << msg;
  EXPECT_FALSE(refused({{dir / "a.png", "-o"}, {dir / "link.png", "b"}}).empty());
  EXPECT_FALSE(refused({{dir / "hard.png", "-o"}, {dir / "a.png", "b"}}).empty());
  // Not yet existing files: the same folder and name, however spelled.
  EXPECT_FALSE(refused({{dir / "sub" / "new.png", "-o"}, {dir / "alias" / "new.png", "b"}}).empty());
  EXPECT_FALSE(refused({{dir / "sub" / "new.png", "-o"}, {dir / "sub" / ".." / "sub" / "new.png", "b"}}).empty());
  EXPECT_TRUE(refused({{dir / "a.png", "-o"}, {dir / "sub" / "a.png", "b"}, {dir / "new.png", "c"}}).empty());
  fs::remove_all(dir);
}
