#include "prizma/relight/line_reader.h"

#include <histedit.h>
#include <unistd.h>

#include <algorithm>
#include <cstdlib>
#include <system_error>

#include "prizma/relight/command_words.h"

namespace prizma::relight {

namespace fs = std::filesystem;

StreamLineReader::StreamLineReader(std::istream& in, std::ostream* prompt_out, std::string prompt)
    : m_in(in), m_prompt_out(prompt_out), m_prompt(std::move(prompt)) {}

bool StreamLineReader::read_line(std::string& line) {
  if (m_prompt_out) *m_prompt_out << m_prompt << std::flush;
  if (!std::getline(m_in, line)) return false;
  if (!line.empty() && line.back() == '\r') line.pop_back();
  return true;
}

std::vector<std::string> matching_candidates(const std::vector<std::string>& candidates, const std::string& partial) {
  std::vector<std::string> out;
  for (const auto& c : candidates)
    if (c.compare(0, partial.size(), partial) == 0 && std::find(out.begin(), out.end(), c) == out.end())
      out.push_back(c);
  std::sort(out.begin(), out.end());
  return out;
}

std::string common_prefix(const std::vector<std::string>& words) {
  if (words.empty()) return {};
  std::string prefix = words.front();
  for (const auto& w : words) {
    std::size_t n = 0;
    while (n < prefix.size() && n < w.size() && prefix[n] == w[n]) ++n;
    prefix.resize(n);
  }
  return prefix;
}

fs::path default_history_file(const std::string& name) {
  fs::path state;
  if (const char* xdg = std::getenv("XDG_STATE_HOME"); xdg && *xdg && fs::path(xdg).is_absolute()) {
    state = xdg;
  } else if (const char* home = std::getenv("HOME"); home && *home) {
    state = fs::path(home) / ".local" / "state";
  } else {
    return {};
  }
  return state / "prizma" / name;
}

namespace {

// Characters (not bytes) in a UTF-8 string: what el_deletestr counts.
int utf8_length(std::string_view s) {
  int n = 0;
  for (unsigned char c : s) n += (c & 0xC0) != 0x80;
  return n;
}

class EditLineReader final : public LineReader {
 public:
  explicit EditLineReader(TerminalReaderOptions options) : m_opts(std::move(options)) {
    m_history = history_init();
    HistEvent ev;
    history(m_history, &ev, H_SETSIZE, std::max(1, m_opts.history_size));
    history(m_history, &ev, H_SETUNIQUE, 1);
    if (!m_opts.history_file.empty()) {
      std::error_code ec;
      if (fs::exists(m_opts.history_file, ec) && history(m_history, &ev, H_LOAD, m_opts.history_file.c_str()) < 0) {
        // Not ours to overwrite: this session keeps its history to itself.
        m_history_failed = true;
        if (m_opts.warnings) {
          *m_opts.warnings << m_opts.program << ": warning: " << m_opts.history_file.string()
                           << ": history not loaded (not readable or not a libedit history file), and not saved\n";
        }
      }
    }
    m_el = el_init(m_opts.program.c_str(), m_opts.in, m_opts.out, stderr);
    el_set(m_el, EL_CLIENTDATA, this);
    el_set(m_el, EL_EDITOR, "emacs");
    el_set(m_el, EL_SIGNAL, 1);  // restore the terminal on signals and follow window size changes
    el_set(m_el, EL_PROMPT, &EditLineReader::prompt);
    el_set(m_el, EL_HIST, history, m_history);
    // The wide call: libedit keeps these (static) strings as they are, where the narrow el_set copies
    // them and never frees the copies.
    el_wset(m_el, EL_ADDFN, L"prizma-complete", L"complete the word at the cursor", &EditLineReader::complete);
    el_set(m_el, EL_BIND, "^I", "prizma-complete", nullptr);
    // Ctrl-C cancels the line being typed, as in bash, and never ends the session: while a line is
    // edited the terminal sends it as a key (no SIGINT: -isig in libedit's edit mode), bound here.
    el_set(m_el, EL_SETTY, "-d", "-isig", nullptr);
    el_wset(m_el, EL_ADDFN, L"prizma-cancel", L"cancel the line (as Ctrl-C in bash)", &EditLineReader::cancel);
    el_set(m_el, EL_BIND, "^C", "prizma-cancel", nullptr);
    el_source(m_el, nullptr);  // the user's ~/.editrc, as every libedit program reads it
  }

  ~EditLineReader() override {
    el_end(m_el);
    history_end(m_history);
  }
  EditLineReader(const EditLineReader&) = delete;
  EditLineReader& operator=(const EditLineReader&) = delete;

  bool read_line(std::string& line) override {
    int count = 0;
    const char* text = el_gets(m_el, &count);
    while (m_cancelled) {  // Ctrl-C: the line is dropped (not run, not in the history); a new prompt
      m_cancelled = false;
      text = el_gets(m_el, &count);
    }
    if (!text || count <= 0) {
      // End of input (Ctrl-D on an empty line): leave the terminal on a new line.
      std::fputs("\n", m_opts.out);
      std::fflush(m_opts.out);
      return false;
    }
    line.assign(text, static_cast<std::size_t>(count));
    while (!line.empty() && (line.back() == '\n' || line.back() == '\r')) line.pop_back();
    if (line.find_first_not_of(" \t") != std::string::npos) {
      HistEvent ev;
      history(m_history, &ev, H_ENTER, line.c_str());
      save_history();
    }
    return true;
  }

 private:
  static char* prompt(EditLine* el) {
    EditLineReader* self = nullptr;
    el_get(el, EL_CLIENTDATA, &self);
    return self->m_opts.prompt.data();
  }

  // Ctrl-C: "^C" where the cursor is (as the terminal echoes it for bash), a new line, and el_gets
  // returns (read_line drops the line).
  static unsigned char cancel(EditLine* el, int) {
    EditLineReader* self = nullptr;
    el_get(el, EL_CLIENTDATA, &self);
    self->m_cancelled = true;
    std::fputs("^C\n", self->m_opts.out);
    std::fflush(self->m_opts.out);
    return CC_NEWLINE;
  }

  static unsigned char complete(EditLine* el, int) {
    EditLineReader* self = nullptr;
    el_get(el, EL_CLIENTDATA, &self);
    return self->complete_here();
  }

  unsigned char complete_here() {
    if (!m_opts.completer) return CC_ERROR;
    const LineInfo* info = el_line(m_el);
    const std::string before(info->buffer, info->cursor);
    CommandWords w = split_words_partial(before);
    std::string partial;
    if (!w.ends_in_blank) {
      partial = w.words.back();
      w.words.pop_back();
    }
    std::vector<std::string> matches;
    try {
      matches = matching_candidates(m_opts.completer(w.words, partial), partial);
    } catch (const std::exception&) {
      return CC_ERROR;  // a completer failing (an unreadable folder, say) completes nothing
    }
    if (matches.empty()) return CC_ERROR;
    std::string replacement;
    if (matches.size() == 1) {
      const std::string& m = matches.front();
      const bool prefix_only = !m.empty() && (m.back() == ':' || m.back() == '/');
      replacement = quote_word(m, !prefix_only);
      if (!prefix_only) replacement += ' ';
    } else {
      const std::string prefix = common_prefix(matches);
      if (prefix.size() > partial.size()) {
        replacement = quote_word(prefix, false);
      } else {
        list(matches);
        return CC_REDISPLAY;
      }
    }
    el_deletestr(m_el, utf8_length(std::string_view(before).substr(w.last_word_start)));
    if (el_insertstr(m_el, replacement.c_str()) != 0) return CC_ERROR;
    return CC_REFRESH;
  }

  // The candidates below the line, in columns as wide as the terminal (libedit then redraws the line).
  void list(const std::vector<std::string>& matches) {
    int columns = 80;
    el_get(m_el, EL_GETTC, "co", &columns, nullptr);
    std::size_t width = 0;
    for (const auto& m : matches) width = std::max(width, m.size());
    width += 2;
    const std::size_t per_row = std::max<std::size_t>(1, static_cast<std::size_t>(std::max(columns, 1)) / width);
    std::string text = "\n";
    for (std::size_t i = 0; i < matches.size(); ++i) {
      std::string cell = matches[i];
      if ((i + 1) % per_row != 0 && i + 1 != matches.size()) cell.resize(width, ' ');
      text += cell;
      if ((i + 1) % per_row == 0 || i + 1 == matches.size()) text += '\n';
    }
    std::fputs(text.c_str(), m_opts.out);
    std::fflush(m_opts.out);
  }

  // The whole history, written to a temporary next to the file and renamed over it, so two sessions
  // ending at once never leave a half-written file. A failure warns once and the session goes on.
  void save_history() {
    if (m_opts.history_file.empty() || m_history_failed) return;
    std::error_code ec;
    const fs::path dir = m_opts.history_file.parent_path();
    if (!dir.empty()) fs::create_directories(dir, ec);
    const fs::path tmp = m_opts.history_file.string() + ".tmp" + std::to_string(::getpid());
    HistEvent ev;
    std::string why;
    if (ec) {
      why = "cannot create " + dir.string() + ": " + ec.message();
    } else if (history(m_history, &ev, H_SAVE, tmp.c_str()) < 0) {
      why = "cannot write " + tmp.string();
    } else {
      fs::rename(tmp, m_opts.history_file, ec);
      if (ec) why = "cannot replace it: " + ec.message();
    }
    if (why.empty()) return;
    fs::remove(tmp, ec);
    m_history_failed = true;
    if (m_opts.warnings) {
      *m_opts.warnings << m_opts.program << ": warning: " << m_opts.history_file.string() << ": history not saved ("
                       << why << ")\n";
    }
  }

  TerminalReaderOptions m_opts;
  EditLine* m_el = nullptr;
  History* m_history = nullptr;
  bool m_history_failed = false;
  bool m_cancelled = false;  // the line ended with Ctrl-C
};

}  // namespace

std::unique_ptr<LineReader> make_terminal_line_reader(TerminalReaderOptions options) {
  return std::make_unique<EditLineReader>(std::move(options));
}

}  // namespace prizma::relight
