// OutputGroup (output_group.h): complete temporaries first, then all the renames, undone when one fails.
#include "prizma/spectral/output_group.h"

#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <set>
#include <string>
#include <system_error>

#include "atomic_file_detail.h"
#include "prizma/spectral/error.h"

namespace prizma::spectral {
namespace {

namespace fs = std::filesystem;

void remove_quietly(const fs::path& p) {
  std::error_code ec;
  if (!p.empty()) fs::remove(p, ec);
}

// "a.exr", "a.exr and b.png", "a.exr, b.png and c.tif".
std::string listed(const std::vector<std::string>& names) {
  std::string out;
  for (std::size_t i = 0; i < names.size(); ++i)
    out += (i == 0 ? "" : i + 1 == names.size() ? " and " : ", ") + names[i];
  return out;
}

}  // namespace

struct OutputGroup::File {
  detail::CompleteTemporary temporary;
  fs::path backup;            // a link to the file replaced, while the group commits
  std::string backup_error;   // why none could be made
  bool placed = false;        // renamed into place
};

OutputGroup::OutputGroup() = default;

OutputGroup::~OutputGroup() { discard(); }

std::size_t OutputGroup::size() const { return m_files.size(); }

void OutputGroup::discard() noexcept {
  for (const File& f : m_files)
    if (!f.placed) remove_quietly(f.temporary.temporary);
  m_files.clear();
}

void OutputGroup::write(const fs::path& path, const std::function<void(AtomicOutput& out)>& writer) {
  std::vector<std::string> earlier;
  for (const File& f : m_files) earlier.push_back(f.temporary.destination.string());
  const std::string also =
      earlier.empty() ? "" : listed(earlier) + (earlier.size() == 1 ? " was" : " were") + " not written either";
  try {
    m_files.push_back(File{detail::write_temporary(path, writer, also), {}, {}, false});
  } catch (...) {
    discard();
    throw;
  }
}

std::string OutputGroup::put_back(std::size_t count) {
  std::vector<std::string> undone, kept;
  for (std::size_t j = count; j-- > 0;) {  // last first
    File& p = m_files[j];
    const std::string name = p.temporary.destination.string();
    if (!p.temporary.existed) {
      if (::unlink(p.temporary.target.c_str()) == 0) {
        undone.push_back(name + " was removed again");
      } else {
        kept.push_back(name + " could not be removed again (" + std::strerror(errno) + ")");
      }
    } else if (p.backup.empty()) {
      kept.push_back(name + " could not be put back (no link to the old file could be made: " + p.backup_error + ")");
    } else if (::rename(p.backup.c_str(), p.temporary.target.c_str()) == 0) {
      undone.push_back(name + " was put back as it was");
    } else {
      kept.push_back(name + " could not be put back (" + std::strerror(errno) + "); the old file is " +
                     detail::quoted_path(p.backup));
      p.backup.clear();  // kept: it holds the old file
    }
    p.placed = false;
  }
  std::string note = listed(undone);
  if (!kept.empty()) note += (note.empty() ? "" : "; ") + listed(kept) + ": it holds this run's output";
  return note;
}

void OutputGroup::commit() {
  for (std::size_t i = 0; i < m_files.size(); ++i) {
    File& f = m_files[i];
    const detail::CompleteTemporary& t = f.temporary;
    if (t.existed) {  // kept until every output is in place, to put it back if a later rename fails
      const fs::path backup = t.folder / detail::backup_name(t);
      if (::link(t.target.c_str(), backup.c_str()) == 0) {
        f.backup = backup;
      } else {
        f.backup_error = std::strerror(errno);
      }
    }
    if (::rename(t.temporary.c_str(), t.target.c_str()) == 0) {
      f.placed = true;
      continue;
    }
    const std::string reason = std::strerror(errno);
    remove_quietly(f.backup);
    std::string note = t.existed ? "the existing file is unchanged" : "";
    if (const std::string undone = put_back(i); !undone.empty()) note += (note.empty() ? "" : "; ") + undone;
    RuntimeError error = detail::write_failure(
        t.destination, "cannot rename " + detail::quoted_path(t.temporary) + " into place (" + reason + ")", note);
    for (std::size_t j = i; j < m_files.size(); ++j) remove_quietly(m_files[j].temporary.temporary);
    m_files.clear();
    throw error;
  }

  // Every output in place: the links go, and the renames are made durable.
  std::set<fs::path> folders;
  std::string unflushed;
  for (const File& f : m_files) {
    remove_quietly(f.backup);
    if (!folders.insert(f.temporary.folder).second) continue;
    if (const std::string err = detail::flush_folder(f.temporary.folder); !err.empty() && unflushed.empty()) {
      unflushed = f.temporary.destination.string() + ": written, but its folder " +
                  detail::quoted_path(f.temporary.folder) + " could not be flushed to disk (" + err + ")";
    }
  }
  m_files.clear();
  if (!unflushed.empty()) throw RuntimeError(unflushed);
}

void write_atomically(const fs::path& path, const std::function<void(AtomicOutput& out)>& writer, OutputGroup* group) {
  if (group != nullptr) {
    group->write(path, writer);
  } else {
    write_atomically(path, writer);
  }
}

}  // namespace prizma::spectral
