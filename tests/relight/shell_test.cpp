// The interactive shell's parts: command words and quoting, completion, terminal images (sixel,
// kitty, half blocks), terminal detection, and whole sessions driven through a stream.
#include <gtest/gtest.h>

#include <poll.h>
#include <pty.h>
#include <termios.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <regex>
#include <sstream>
#include <thread>

#include "prizma/relight/command_words.h"
#include "prizma/relight/interactive_shell.h"
#include "prizma/relight/line_reader.h"
#include "prizma/relight/terminal_image.h"
#include "prizma/relight/terminal_preview.h"
#include "prizma/spectral/error.h"
#include "spectral/relight_test_util.h"

namespace prizma::relight {
namespace {

using spectral::BinLayout;
using Words = std::vector<std::string>;

// 6×4, lights "key" (left half grey) and "back" (right half ramp), as in relight_session_test.
RelightSession make_session() {
  const BinLayout bins = BinLayout::linear(400.0, 700.0, 12);
  auto img = spectral::test::make_image(6, 4, bins, {"key", "back"}, [](int l, int p, int i) {
    const int x = p % 6;
    if (l == 0) return x < 3 ? 0.5f : 0.0f;
    return x >= 3 ? static_cast<float>(i) / 11.0f : 0.0f;
  });
  return RelightSession(std::move(img), "mem.exr");
}

std::string run(RelightSession& session, const std::string& script, int* failures = nullptr,
                InteractiveOptions opts = {}) {
  std::istringstream in(script);
  std::ostringstream out;
  const int f = run_interactive(session, in, out, opts);
  if (failures) *failures = f;
  return out.str();
}

std::size_t count(const std::string& text, const std::string& what) {
  std::size_t n = 0;
  for (std::size_t pos = text.find(what); pos != std::string::npos; pos = text.find(what, pos + what.size())) ++n;
  return n;
}

TEST(CommandWords, QuotesEscapesAndComments) {
  EXPECT_EQ(split_words("display \"Display P3\""), (Words{"display", "Display P3"}));
  EXPECT_EQ(split_words("  light   key\tA  "), (Words{"light", "key", "A"}));
  EXPECT_EQ(split_words("save 'a b.png'"), (Words{"save", "a b.png"}));
  EXPECT_EQ(split_words(R"(save a\ b.png)"), (Words{"save", "a b.png"}));
  EXPECT_EQ(split_words(R"(save "say \"hi\" \\ \n")"), (Words{"save", R"(say "hi" \ \n)"}));
  EXPECT_EQ(split_words(R"(save 'it\'s)"), (Words{"save", R"(it\s)"}));  // no escapes inside '…'
  EXPECT_EQ(split_words("save x\"y z\"w"), (Words{"save", "xy zw"}));  // quotes join with the word
  EXPECT_EQ(split_words("save \"\""), (Words{"save", ""}));
  EXPECT_EQ(split_words("light key A # a comment"), (Words{"light", "key", "A"}));
  EXPECT_EQ(split_words("save \"#1.png\""), (Words{"save", "#1.png"}));
  EXPECT_EQ(split_words("save a#1.png"), (Words{"save", "a#1.png"}));
  EXPECT_TRUE(split_words("# only a comment").empty());
  EXPECT_THROW(split_words("display \"Display P3"), spectral::InputError);
  EXPECT_THROW(split_words("display 'sRGB"), spectral::InputError);
  EXPECT_THROW(split_words("display sRGB\\"), spectral::InputError);
}

TEST(CommandWords, PartialLinesForCompletion) {
  CommandWords w = split_words_partial("display \"Display P");
  EXPECT_EQ(w.words, (Words{"display", "Display P"}));
  EXPECT_EQ(w.open_quote, '"');
  EXPECT_EQ(w.last_word_start, 8u);
  EXPECT_FALSE(w.ends_in_blank);
  w = split_words_partial("light key ");
  EXPECT_EQ(w.words, (Words{"light", "key"}));
  EXPECT_TRUE(w.ends_in_blank);
  EXPECT_EQ(w.last_word_start, 10u);
}

TEST(CommandWords, QuoteWordReadsBackAsItself) {
  EXPECT_EQ(quote_word("sRGB"), "sRGB");
  EXPECT_EQ(quote_word("Display P3"), "\"Display P3\"");
  EXPECT_EQ(quote_word("Display P3", false), "\"Display P3");
  for (const std::string s : {"a b", "say \"hi\"", "back\\slash", "it's", "#x", "", "tab\there"}) {
    EXPECT_EQ(split_words("save " + quote_word(s)), (Words{"save", s})) << s;
  }
}

TEST(Completion, CommandsLightsSpectraDisplaysObservers) {
  RelightSession session = make_session();
  auto complete = [&](const Words& before, const std::string& partial) {
    return matching_candidates(complete_command(session, before, partial), partial);
  };
  EXPECT_EQ(complete({}, "li"), (Words{"light", "lights"}));
  EXPECT_EQ(complete({}, "st"), (Words{"status"}));
  EXPECT_EQ(complete({"light"}, "k"), (Words{"key"}));
  EXPECT_EQ(complete({"light"}, "b"), (Words{"back", "blackbody:", "box:"}));
  EXPECT_EQ(complete({"light", "key"}, "F1"), (Words{"F11"}));
  EXPECT_EQ(complete({"light", "key"}, "LED-B"), (Words{"LED-B1", "LED-B2", "LED-B3", "LED-B4", "LED-B5", "LED-BH1"}));
  EXPECT_EQ(complete({"light", "key"}, "o"), (Words{"off"}));
  EXPECT_TRUE(complete({"light", "key", "A"}, "").empty());
  EXPECT_EQ(complete({"display"}, "Di"), (Words{"Display P3"}));
  EXPECT_EQ(complete({"display"}, ""), (Words{"Display P3", "Rec.2020", "sRGB"}));
  EXPECT_EQ(complete({"cmf"}, "2012"), (Words{"2012-10", "2012-2"}));
  EXPECT_EQ(complete({"adapt"}, ""), (Words{"off", "on"}));
  EXPECT_EQ(common_prefix({"LED-B1", "LED-B2", "LED-BH1"}), "LED-B");
  EXPECT_EQ(common_prefix({}), "");
}

TEST(Completion, SaveCompletesFileNames) {
  const auto dir = spectral::test::scratch_dir("complete_files");
  std::filesystem::create_directories(dir / "out folder");
  std::ofstream(dir / "lamp.csv") << "400,1\n700,1\n";
  RelightSession session = make_session();
  const std::string base = dir.string() + "/";
  EXPECT_EQ(matching_candidates(complete_command(session, {"save"}, base + "ou"), base + "ou"),
            (Words{base + "out folder/"}));
  EXPECT_EQ(matching_candidates(complete_command(session, {"light", "key"}, "csv:" + base + "la"), "csv:" + base + "la"),
            (Words{"csv:" + base + "lamp.csv"}));
}

TEST(TerminalImage, ProtocolFromEnvironment) {
  TerminalEnvironment env;
  EXPECT_EQ(image_protocol_from_environment(env), std::nullopt);  // only asking can tell
  env.term = "xterm-kitty";
  EXPECT_EQ(image_protocol_from_environment(env), ImageProtocol::Kitty);
  env.tmux = "/tmp/tmux-0/default,1,0";  // inside tmux the outer terminal does not draw
  EXPECT_EQ(image_protocol_from_environment(env), std::nullopt);
  env = {};
  env.term = "foot";
  EXPECT_EQ(image_protocol_from_environment(env), ImageProtocol::Sixel);
  env = {};
  env.term_program = "WezTerm";
  EXPECT_EQ(image_protocol_from_environment(env), ImageProtocol::Sixel);
  env = {};
  env.kitty_window_id = "1";
  EXPECT_EQ(image_protocol_from_environment(env), ImageProtocol::Kitty);
  env.prizma_images = "blocks";  // the override wins
  EXPECT_EQ(image_protocol_from_environment(env), ImageProtocol::Blocks);
  env = {};
  env.term = "dumb";
  EXPECT_EQ(image_protocol_from_environment(env), ImageProtocol::Blocks);
}

TEST(TerminalImage, ProtocolFromReplies) {
  EXPECT_EQ(image_protocol_from_replies("\x1b[?62;4;6;22c\x1b[0n"), ImageProtocol::Sixel);  // xterm -ti vt340
  EXPECT_EQ(image_protocol_from_replies("\x1b[?1;2c\x1b[0n"), ImageProtocol::Blocks);     // tmux, plain xterm
  EXPECT_EQ(image_protocol_from_replies("\x1b[?64;1;2;6;9;15;18;21;22c"), ImageProtocol::Blocks);  // 14 ≠ 4
  EXPECT_EQ(image_protocol_from_replies("\x1b_Gi=31;OK\x1b\\\x1b[?62;c\x1b[0n"), ImageProtocol::Kitty);
  EXPECT_EQ(image_protocol_from_replies(""), ImageProtocol::Blocks);
  EXPECT_EQ(image_protocol_from_replies("\x1b[?62;4"), ImageProtocol::Blocks);  // cut short
}

// The terminal's side of the query on the pseudo-terminal `master`: reads up to the status report
// request (DSR), waits `delay`, then writes `reply`.
void answer_query(int master, const std::string& reply, std::chrono::milliseconds delay = {}) {
  std::string seen;
  char buf[256];
  while (seen.find("\x1b[5n") == std::string::npos) {
    pollfd p{master, POLLIN, 0};
    if (::poll(&p, 1, 5000) <= 0) return;
    const ssize_t n = ::read(master, buf, sizeof buf);
    if (n <= 0) return;
    seen.append(buf, static_cast<std::size_t>(n));
  }
  std::this_thread::sleep_for(delay);
  EXPECT_EQ(::write(master, reply.data(), reply.size()), static_cast<ssize_t>(reply.size()));
}

// The query on a real pseudo-terminal: with nobody answering it gives up (Blocks) instead of hanging;
// with a terminal answering DA1 with attribute 4 it finds sixel.
TEST(TerminalImage, QueryOnAPseudoTerminal) {
  int master = -1, slave = -1;
  ASSERT_EQ(::openpty(&master, &slave, nullptr, nullptr, nullptr), 0);
  EXPECT_EQ(query_image_protocol(slave, slave, 100), ImageProtocol::Blocks);
  // Read the query, then answer as a sixel terminal would.
  std::thread terminal([master] { answer_query(master, "\x1b[?62;4;22c\x1b[0n"); });
  EXPECT_EQ(query_image_protocol(slave, slave, 5000), ImageProtocol::Sixel);
  terminal.join();
  // Not a terminal at all: no query.
  int pipefd[2];
  ASSERT_EQ(::pipe(pipefd), 0);
  EXPECT_EQ(query_image_protocol(pipefd[0], pipefd[1], 5000), ImageProtocol::Blocks);
  for (int fd : {master, slave, pipefd[0], pipefd[1]}) ::close(fd);
}

// issue 21: a terminal that answered after 300 ms (tmux on a loaded machine) had its reply read by
// the line editor as typed keys ("1;2cquit: unknown command"), so relight.e2e.shell_terminal failed
// under load. The query waits for the reply itself: one that comes 800 ms late is read by the query,
// and nothing is left on the terminal's input.
TEST(TerminalImage, ALateReplyIsReadByTheQueryNotLeftAsTypedKeys) {
  int master = -1, slave = -1;
  ASSERT_EQ(::openpty(&master, &slave, nullptr, nullptr, nullptr), 0);
  // tmux's reply, from a busy terminal.
  std::thread terminal([master] { answer_query(master, "\x1b[?1;2c\x1b[0n", std::chrono::milliseconds(800)); });
  EXPECT_EQ(query_image_protocol(slave, slave), ImageProtocol::Blocks);
  terminal.join();
  // As the line editor reads it (raw: a reply has no newline for canonical mode to deliver).
  termios raw{};
  ASSERT_EQ(::tcgetattr(slave, &raw), 0);
  raw.c_lflag &= ~static_cast<tcflag_t>(ICANON | ECHO);
  ASSERT_EQ(::tcsetattr(slave, TCSANOW, &raw), 0);
  pollfd left{slave, POLLIN, 0};
  EXPECT_EQ(::poll(&left, 1, 0), 0) << "the reply was left on the terminal's input";
  for (int fd : {master, slave}) ::close(fd);
}

std::vector<float> solid(int w, int h, float r, float g, float b) {
  std::vector<float> px;
  for (int i = 0; i < w * h; ++i) px.insert(px.end(), {r, g, b});
  return px;
}

TEST(TerminalImage, KittyChunksDecodeToThePixels) {
  const Rgb8Image img = resample_rgb8(solid(40, 30, 1.0f, 0.5f, 0.0f), 40, 30, 40, 30);
  const std::string k = encode_kitty(img);
  ASSERT_EQ(k.rfind("\x1b_Ga=T,f=24,q=2,s=40,v=30,m=1;", 0), 0u) << k.substr(0, 40);
  // 40·30·3 = 3600 bytes → 4800 base64 characters: two chunks, the last with m=0.
  EXPECT_EQ(count(k, "\x1b_G"), 2u);
  EXPECT_NE(k.find("\x1b_Gm=0;"), std::string::npos);
  // Decode the payload back.
  std::string b64;
  for (std::size_t pos = 0; (pos = k.find(';', pos)) != std::string::npos;) {
    const std::size_t end = k.find("\x1b\\", pos);
    b64 += k.substr(pos + 1, end - pos - 1);
    pos = end;
  }
  auto digit = [](char c) -> int {
    const std::string digits = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
    return static_cast<int>(digits.find(c));
  };
  std::vector<std::uint8_t> bytes;
  for (std::size_t i = 0; i + 3 < b64.size(); i += 4) {
    const int v = (digit(b64[i]) << 18) | (digit(b64[i + 1]) << 12) | ((b64[i + 2] == '=' ? 0 : digit(b64[i + 2])) << 6) |
                  (b64[i + 3] == '=' ? 0 : digit(b64[i + 3]));
    bytes.push_back(static_cast<std::uint8_t>(v >> 16));
    if (b64[i + 2] != '=') bytes.push_back(static_cast<std::uint8_t>(v >> 8));
    if (b64[i + 3] != '=') bytes.push_back(static_cast<std::uint8_t>(v));
  }
  EXPECT_EQ(bytes, img.pixels);
  EXPECT_EQ(img.pixels[0], 255);
  EXPECT_EQ(img.pixels[1], 128);
  EXPECT_EQ(img.pixels[2], 0);
}

TEST(TerminalImage, SixelIsOneDeviceControlStringWithThePalette) {
  const Rgb8Image img = resample_rgb8(solid(16, 12, 1.0f, 0.0f, 0.0f), 16, 12, 16, 12);
  const std::string s = encode_sixel(img);
  ASSERT_GT(s.size(), 10u);
  EXPECT_EQ(s.substr(0, 2), "\x1bP");          // DCS
  EXPECT_EQ(s.substr(s.size() - 2), "\x1b\\");  // ST
  // The palette entry "#n;2;r;g;b" (RGB in percent; libsixel's quantiser gives 97 for 255).
  std::smatch m;
  ASSERT_TRUE(std::regex_search(s, m, std::regex(R"(#\d+;2;(\d+);(\d+);(\d+))"))) << s;
  EXPECT_GE(std::stoi(m[1]), 90);
  EXPECT_LE(std::stoi(m[2]), 5);
  EXPECT_LE(std::stoi(m[3]), 5);
  EXPECT_NE(s.find("\"1;1;16;12"), std::string::npos) << "raster attributes: 16×12";
}

TEST(TerminalImage, SizedToTheTerminal) {
  int w = 0, h = 0;
  TerminalSize term;  // 80×24 cells of unknown size: 10×20 pixels each
  fit_to_terminal(1600, 1000, term, 4, w, h);  // fits 800×400
  EXPECT_EQ(w, 640);
  EXPECT_EQ(h, 400);
  fit_to_terminal(60, 40, term, 4, w, h);  // small: enlarged by a whole factor, at most 8
  EXPECT_EQ(w, 480);
  EXPECT_EQ(h, 320);
  fit_to_terminal(100, 50, term, 4, w, h);  // 800 / 100 = 8, 400 / 50 = 8
  EXPECT_EQ(w, 800);
  EXPECT_EQ(h, 400);
  fit_to_terminal(300, 50, term, 4, w, h);  // 800 / 300 = 2.67: twice
  EXPECT_EQ(w, 600);
  EXPECT_EQ(h, 100);
  term.width_px = 1600;  // 20×40-pixel cells
  term.height_px = 960;
  fit_to_terminal(1600, 1000, term, 4, w, h);  // 1600×800 available
  EXPECT_EQ(w, 1280);
  EXPECT_EQ(h, 800);
  // Half blocks: 172×116 in 80 columns and 10 lines → 20 pixel rows → 30 columns wide.
  std::ostringstream out;
  print_terminal_thumbnail(out, solid(172, 116, 0.5f, 0.5f, 0.5f), 172, 116, 80, 10);
  const std::string text = out.str();
  EXPECT_EQ(count(text, "\n"), 10u);
  EXPECT_EQ(count(text, "\u2580"), 300u);
  EXPECT_NE(text.find("\x1b[38;2;128;128;128m"), std::string::npos);
}

TEST(InteractiveShell, QuotedDisplayStatusAdaptUndo) {
  RelightSession session = make_session();
  int failures = 0;
  const std::string text = run(session,
                               "status\n"
                               "display \"Display P3\"\n"
                               "light key A\n"
                               "adapt on\n"
                               "exposure 1\n"
                               "status\n"
                               "undo\n"
                               "undo\n"
                               "status\n"
                               "undo\n"
                               "undo\n"
                               "undo\n"
                               "display Display P3\n"
                               "display 'Rec.2020\n"
                               "adapt maybe\n"
                               "status\n",
                               &failures);
  EXPECT_EQ(failures, 4) << text;  // the last undo, the unquoted and unterminated displays, "maybe"
  // Every setting shows in status.
  EXPECT_NE(text.find("light       key = D65 (default D65)"), std::string::npos) << text;
  EXPECT_NE(text.find("light       back = D65"), std::string::npos) << text;
  EXPECT_NE(text.find("exposure    0 EV"), std::string::npos) << text;
  EXPECT_NE(text.find("cmf         cie1931-2"), std::string::npos) << text;
  EXPECT_NE(text.find("display     sRGB"), std::string::npos) << text;
  EXPECT_NE(text.find("adaptation  off"), std::string::npos) << text;
  EXPECT_NE(text.find("preview     none"), std::string::npos) << text;
  // After the four changes.
  EXPECT_NE(text.find("display     Display P3"), std::string::npos) << text;
  EXPECT_NE(text.find("light       key = A"), std::string::npos) << text;
  EXPECT_NE(text.find("adaptation  on"), std::string::npos) << text;
  EXPECT_NE(text.find("exposure    1 EV"), std::string::npos) << text;
  EXPECT_NE(text.find("undo        4 levels"), std::string::npos) << text;
  // Two undos: exposure and adaptation back, A and P3 kept.
  const std::size_t third = text.rfind("file        ", text.rfind("file        ") - 1);
  const std::string after_two = text.substr(third, text.find("last relight", third) - third);
  EXPECT_NE(after_two.find("exposure    0 EV"), std::string::npos) << after_two;
  EXPECT_NE(after_two.find("adaptation  off"), std::string::npos) << after_two;
  EXPECT_NE(after_two.find("light       key = A"), std::string::npos) << after_two;
  EXPECT_NE(after_two.find("display     Display P3"), std::string::npos) << after_two;
  EXPECT_NE(text.find("error: undo: nothing to undo"), std::string::npos) << text;
  EXPECT_NE(text.find("error: display: usage: display NAME (quoted"), std::string::npos) << text;
  EXPECT_NE(text.find("error: line: unterminated ' quote"), std::string::npos) << text;
  EXPECT_NE(text.find("error: adapt: on or off"), std::string::npos) << text;
  // The first status and the last are the same settings (everything undone).
  EXPECT_EQ(session.settings().output.display.display, "sRGB");
  EXPECT_EQ(session.settings().lights[0].text, "D65");
  // Every change printed its relight time: the start, 4 changes, 4 undos.
  EXPECT_EQ(count(text, "relit in "), 9u) << text;
}

// The adaptation the shell turns on is the one the library computes (--adapt).
TEST(InteractiveShell, AdaptOnEqualsTheAdaptedImage) {
  RelightSession session = make_session();
  run(session, "light A\nadapt on\n");
  const std::vector<float> shell = session.xyz().xyz;
  RelightSession direct = make_session();
  RelightSettings s = direct.settings();
  s.lights = {parse_light_spec("A"), parse_light_spec("A")};
  s.relight.adapt_to_d65 = true;
  direct.apply(s);
  EXPECT_EQ(direct.xyz().xyz, shell);
}

// Issue 11: compare with a huge pixel index printed NaN. Every index is checked: whole numbers inside
// the image, with the image size in the message; the radius too.
TEST(InteractiveShell, PixelIndicesAreCheckedWithAClearError) {
  RelightSession session = make_session();
  int failures = 0;
  const std::string text = run(session,
                               "compare 0 0 99999999999 0\n"
                               "compare 0 0 1 1 99999999999\n"
                               "compare 0 0 1 1 2147483647\n"
                               "compare 0 0 6 0\n"
                               "compare -1 0 1 1\n"
                               "compare 0 0 1.5 1\n"
                               "compare 0 0 nan 1\n"
                               "compare 0 0 inf 1\n"
                               "compare 0 0 1e3 1\n"
                               "probe 0 4\n"
                               "probe 99999999999999999999 0\n"
                               "probe 0x1 0\n"
                               "compare 0 0 5 3 6\n"
                               "probe 5 3\n",
                               &failures);
  EXPECT_EQ(failures, 12) << text;
  EXPECT_EQ(text.find("dE2000 nan"), std::string::npos) << text;
  EXPECT_EQ(text.find("dE2000 -nan"), std::string::npos) << text;
  EXPECT_NE(text.find("error: compare X2: 99999999999 is outside the 6×4 image (0 to 5)"), std::string::npos) << text;
  EXPECT_NE(text.find("error: compare R: 99999999999 is outside the radius range of the 6×4 image (0 to 6)"),
            std::string::npos) << text;
  EXPECT_NE(text.find("error: compare R: 2147483647 is outside"), std::string::npos) << text;
  EXPECT_NE(text.find("error: compare X2: 6 is outside the 6×4 image (0 to 5)"), std::string::npos) << text;
  EXPECT_NE(text.find("error: compare X1: -1 is outside"), std::string::npos) << text;
  EXPECT_NE(text.find("error: compare X2: not a whole number: \"1.5\""), std::string::npos) << text;
  EXPECT_NE(text.find("error: compare X2: not a whole number: \"nan\""), std::string::npos) << text;
  EXPECT_NE(text.find("error: compare X2: not a whole number: \"inf\""), std::string::npos) << text;
  EXPECT_NE(text.find("error: compare X2: not a whole number: \"1e3\""), std::string::npos) << text;
  EXPECT_NE(text.find("error: probe Y: 4 is outside the 6×4 image (0 to 3)"), std::string::npos) << text;
  EXPECT_NE(text.find("error: probe X: 99999999999999999999 is outside"), std::string::npos) << text;
  EXPECT_NE(text.find("error: probe X: not a whole number: \"0x1\""), std::string::npos) << text;
  // The largest radius and the last pixel work.
  EXPECT_NE(text.find("dE2000 "), std::string::npos) << text;
  EXPECT_NE(text.find("probe 5 3\n"), std::string::npos) << text;
  // The library refuses a radius that would overflow too.
  EXPECT_THROW(session.compare(0, 0, 1, 1, 2147483647), spectral::InputError);
  EXPECT_THROW(session.compare(0, 0, 1, 1, -1), spectral::InputError);
}

TEST(InteractiveShell, ProbeShowsTheExcitationEmissionMapOfAFluorescentPixel) {
  // relight_test_util.h's fluorescent image: 6 bins over 400–700 nm (centres 425 … 675), pairs from
  // the two blue bins into the three red ones, values 0.02·(1 + (k·7 + 3l) % 11) (k = pixel·6 + pair).
  RelightSession session(spectral::test::fluorescent_image(), "fluor.exr");
  int failures = 0;
  const std::string text = run(session, "probe 0 0\nprobe 0 0 sky\nprobe 0 0 nope\n", &failures);
  EXPECT_EQ(failures, 1) << text;
  // Pixel 0, light uv: (0,3) 1, (0,4) 8, (0,5) 4, (1,3) 11, (1,4) 7, (1,5) 3 times 0.02: digits
  // round(9·v/0.22) = 1, 7, 3, 9, 6, 2; rows out 675, 625, 575 from the top, columns in 425, 475.
  const std::string uv = "  excitation–emission uv: M[out][in] as 0–9 of its largest, 0.22 (475 → 575 nm); . zero, \\ diagonal\n"
                         "    out\\in 425 475\n"
                         "       675   3   2\n"
                         "       625   7   6\n"
                         "       575   1   9\n";
  EXPECT_NE(text.find(uv), std::string::npos) << text;
  // Light sky (l = 1): (k·7 + 3) % 11 for k = 0…5 → 3, 10, 6, 2, 9, 5: values 4, 11, 7, 3, 10, 6.
  const std::string sky = "       675   6   5\n"
                          "       625   9   8\n"
                          "       575   3   2\n";
  EXPECT_EQ(count(text, "excitation–emission uv"), 1u) << text;  // "probe 0 0 sky": sky's map only
  EXPECT_EQ(count(text, "excitation–emission sky"), 2u) << text;
  EXPECT_NE(text.find(sky), std::string::npos) << text;
  EXPECT_NE(text.find("error: probe LIGHT: "), std::string::npos) << text;
  // A diagonal file prints no map.
  RelightSession plain = make_session();
  EXPECT_EQ(run(plain, "probe 0 0\n").find("excitation"), std::string::npos);
}

TEST(InteractiveShell, ShowDrawsWithTheChosenProtocolAndShowEveryAfterChanges) {
  RelightSession session = make_session();
  InteractiveOptions opts;
  opts.terminal.columns = 40;
  opts.terminal.rows = 12;
  std::string text = run(session, "show\nshow sixel\nshow kitty\nshow png\nexposure 1\n", nullptr, opts);
  EXPECT_EQ(count(text, "\u2580"), 6u * 4u / 2u) << "one 6×4 half-block image (never enlarged)";
  EXPECT_NE(text.find("\x1bP"), std::string::npos);
  EXPECT_NE(text.find("\x1b_Ga=T"), std::string::npos);
  EXPECT_NE(text.find("error: show: blocks, sixel or kitty, not \"png\""), std::string::npos);
  // --show-every: at the start and after each change; the protocol is detected once, when first needed.
  int detections = 0;
  opts.show_every = true;
  opts.detect_protocol = [&] {
    ++detections;
    return ImageProtocol::Kitty;
  };
  text = run(session, "exposure 1\nlight key off\nlights\n", nullptr, opts);
  EXPECT_EQ(count(text, "\x1b_Ga=T"), 3u) << text;
  EXPECT_EQ(detections, 1);
  EXPECT_EQ(text.find("\u2580"), std::string::npos);
}

// Issue 25 item 17: inside tmux a sixel or kitty image that tmux would not pass on is refused with
// what to do; kitty goes through tmux's passthrough once it is allowed.
TEST(TerminalImage, RouteInsideTmux) {
  for (ImageProtocol p : {ImageProtocol::Blocks, ImageProtocol::Sixel, ImageProtocol::Kitty}) {
    const ImageRoute outside = image_route(p, TmuxFacts{});
    EXPECT_TRUE(outside.shown && !outside.tmux_passthrough && outside.why.empty()) << image_protocol_name(p);
  }
  const TmuxFacts plain_tmux{.inside = true};
  EXPECT_TRUE(image_route(ImageProtocol::Blocks, plain_tmux).shown);
  const ImageRoute sixel = image_route(ImageProtocol::Sixel, plain_tmux);
  EXPECT_FALSE(sixel.shown);
  EXPECT_NE(sixel.why.find("--enable-sixel"), std::string::npos) << sixel.why;
  EXPECT_TRUE(image_route(ImageProtocol::Sixel, TmuxFacts{.inside = true, .sixel = true}).shown);
  const ImageRoute kitty = image_route(ImageProtocol::Kitty, plain_tmux);
  EXPECT_FALSE(kitty.shown);
  EXPECT_NE(kitty.why.find("tmux set -g allow-passthrough on"), std::string::npos) << kitty.why;
  const ImageRoute through = image_route(ImageProtocol::Kitty, TmuxFacts{.inside = true, .passthrough = true});
  EXPECT_TRUE(through.shown && through.tmux_passthrough);
}

TEST(TerminalImage, TmuxPassthroughWrapsEachSequenceWithItsEscapesDoubled) {
  EXPECT_EQ(tmux_passthrough("\x1b_Ga=T,m=1;AAAA\x1b\\\x1b_Gm=0;BB\x1b\\"),
            "\x1bPtmux;\x1b\x1b_Ga=T,m=1;AAAA\x1b\x1b\\\x1b\\\x1bPtmux;\x1b\x1b_Gm=0;BB\x1b\x1b\\\x1b\\");
  EXPECT_EQ(tmux_passthrough(""), "");
}

TEST(InteractiveShell, ShowRefusesWhatWouldNotReachTheScreenAndClearClearsATerminal) {
  RelightSession session = make_session();
  InteractiveOptions opts;
  opts.image_route = [](ImageProtocol p) { return image_route(p, TmuxFacts{.inside = true}); };
  int failures = 0;
  std::string text = run(session, "show kitty\nshow sixel\nshow blocks\nclear\n", &failures, opts);
  EXPECT_EQ(failures, 2);
  EXPECT_NE(text.find("error: show kitty: inside tmux"), std::string::npos) << text;
  EXPECT_NE(text.find("error: show sixel: this tmux draws no sixel images"), std::string::npos) << text;
  EXPECT_EQ(count(text, "drawn in "), 1u) << "only the half blocks are drawn: " << text;
  EXPECT_EQ(text.find("\x1b_G"), std::string::npos);
  EXPECT_EQ(text.find("\x1b[2J"), std::string::npos) << "clear writes nothing into a pipe";
  opts.image_route = [](ImageProtocol p) { return image_route(p, TmuxFacts{.inside = true, .passthrough = true}); };
  opts.terminal_output = true;
  text = run(session, "show kitty\nclear\n", &failures, opts);
  EXPECT_EQ(failures, 0) << text;
  EXPECT_NE(text.find("\x1bPtmux;\x1b\x1b_Ga=T"), std::string::npos);
  EXPECT_NE(text.find("through tmux's passthrough"), std::string::npos);
  EXPECT_NE(text.find("\x1b[H\x1b[2J"), std::string::npos);
}

TEST(LineReader, StreamReaderStripsCarriageReturnsAndPrompts) {
  std::istringstream in("status\r\nquit\n");
  std::ostringstream prompts;
  StreamLineReader reader(in, &prompts, "relight> ");
  std::string line;
  ASSERT_TRUE(reader.read_line(line));
  EXPECT_EQ(line, "status");
  ASSERT_TRUE(reader.read_line(line));
  EXPECT_EQ(line, "quit");
  EXPECT_FALSE(reader.read_line(line));
  EXPECT_EQ(prompts.str(), "relight> relight> relight> ");
}

TEST(LineReader, HistoryFileFollowsXdgStateHome) {
  const char* saved_xdg = std::getenv("XDG_STATE_HOME");
  const char* saved_home = std::getenv("HOME");
  const std::string xdg = saved_xdg ? saved_xdg : "", home = saved_home ? saved_home : "";
  ::setenv("XDG_STATE_HOME", "/tmp/state-x", 1);
  EXPECT_EQ(default_history_file(), "/tmp/state-x/prizma/relight_history");
  ::setenv("XDG_STATE_HOME", "relative/ignored", 1);
  ::setenv("HOME", "/home/someone", 1);
  EXPECT_EQ(default_history_file(), "/home/someone/.local/state/prizma/relight_history");
  ::unsetenv("XDG_STATE_HOME");
  ::unsetenv("HOME");
  EXPECT_EQ(default_history_file(), "");
  saved_xdg ? ::setenv("XDG_STATE_HOME", xdg.c_str(), 1) : ::unsetenv("XDG_STATE_HOME");
  saved_home ? ::setenv("HOME", home.c_str(), 1) : ::unsetenv("HOME");
}

}  // namespace
}  // namespace prizma::relight
