#include "prizma/relight/command_words.h"

#include "prizma/spectral/error.h"

namespace prizma::relight {

namespace {

bool is_blank(char c) { return c == ' ' || c == '\t' || c == '\n' || c == '\r'; }

}  // namespace

CommandWords split_words_partial(std::string_view line) {
  CommandWords out;
  std::string word;
  bool in_word = false;
  char quote = 0;
  for (std::size_t i = 0; i < line.size(); ++i) {
    const char c = line[i];
    if (!in_word) {
      if (is_blank(c)) continue;
      if (c == '#') break;  // a comment runs to the end of the line
      in_word = true;
      out.last_word_start = i;
      word.clear();
    }
    if (quote == '\'') {
      if (c == '\'') {
        quote = 0;
      } else {
        word += c;
      }
    } else if (quote == '"') {
      if (c == '"') {
        quote = 0;
      } else if (c == '\\' && i + 1 < line.size() && (line[i + 1] == '"' || line[i + 1] == '\\')) {
        word += line[++i];
      } else if (c == '\\' && i + 1 == line.size()) {
        out.trailing_backslash = true;
      } else {
        word += c;
      }
    } else if (c == '"' || c == '\'') {
      quote = c;
    } else if (c == '\\') {
      if (i + 1 < line.size()) {
        word += line[++i];
      } else {
        out.trailing_backslash = true;
      }
    } else if (is_blank(c)) {
      out.words.push_back(word);
      in_word = false;
    } else {
      word += c;
    }
  }
  if (in_word) {
    out.words.push_back(word);
    out.ends_in_blank = false;
  } else {
    out.last_word_start = line.size();
  }
  out.open_quote = quote;
  return out;
}

std::vector<std::string> split_words(std::string_view line) {
  CommandWords w = split_words_partial(line);
  if (w.open_quote) {
    throw spectral::InputError("line", std::string("unterminated ") + (w.open_quote == '"' ? "\"" : "'") + " quote");
  }
  if (w.trailing_backslash) throw spectral::InputError("line", "a backslash at the end of the line escapes nothing");
  return std::move(w.words);
}

std::string quote_word(std::string_view word, bool close) {
  bool plain = !word.empty() && word.front() != '#';
  for (char c : word) plain = plain && !is_blank(c) && c != '"' && c != '\'' && c != '\\';
  if (plain) return std::string(word);
  std::string out = "\"";
  for (char c : word) {
    if (c == '"' || c == '\\') out += '\\';
    out += c;
  }
  if (close) out += '"';
  return out;
}

}  // namespace prizma::relight
