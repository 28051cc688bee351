#pragma once
// Splitting one interactive command line into words, as a POSIX shell does for the cases that matter
// here: blanks separate words, "double" and 'single' quotes group them, a backslash escapes the next
// character (inside double quotes only \" and \\), and '#' at the start of a word begins a comment.
// `display "Display P3"` is two words: display, Display P3.
#include <cstddef>
#include <string>
#include <string_view>
#include <vector>

namespace prizma::relight {

struct CommandWords {
  std::vector<std::string> words;  // unquoted
  // Where the last word starts in the line (bytes, its opening quote included); line.size() when the
  // line ends in a blank (the word being typed is then empty). Completion replaces from here.
  std::size_t last_word_start = 0;
  bool ends_in_blank = true;  // no word is being typed at the end of the line
  char open_quote = 0;        // '"' or '\'' when the line ends inside quotes, else 0
  bool trailing_backslash = false;
};

// Never throws: an unterminated quote or a trailing backslash is reported in the result (completion
// needs the partial word).
CommandWords split_words_partial(std::string_view line);
// Throws InputError (input "line") for an unterminated quote or a trailing backslash.
std::vector<std::string> split_words(std::string_view line);
// The word as it must be typed to read back as itself: unchanged when it holds no blank, quote,
// backslash or leading '#', else in double quotes with \" and \\ escaped. With `close` false the
// closing quote is left off (a completion that is still a prefix).
std::string quote_word(std::string_view word, bool close = true);

}  // namespace prizma::relight
