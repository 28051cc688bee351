// Out-of-memory classification of library error messages (out_of_memory.h): a file's own text never
// turns a corrupt-file error into "out of memory".
#include <gtest/gtest.h>

#include "prizma/spectral/out_of_memory.h"

namespace prizma::spectral {
namespace {

TEST(ToolMain, LibraryMessagesThatMeanOutOfMemory) {
  EXPECT_TRUE(message_says_out_of_memory("std::bad_alloc"));
  EXPECT_TRUE(message_says_out_of_memory("Out of memory"));
  EXPECT_TRUE(message_says_out_of_memory("Cannot read image file \"a.exr\". Cannot allocate memory"));
  EXPECT_TRUE(message_says_out_of_memory("Cannot create thread: Resource temporarily unavailable"));
}

TEST(ToolMain, QuotedFileTextIsNotOutOfMemory) {
  // The fuzzer's input: a channel named "aCannot allocate memory" with an invalid pixel type.
  EXPECT_FALSE(message_says_out_of_memory(
      "Cannot read image file \"/tmp/input.exr\". Pixel type of \"aCannot allocate memory\" image channel is invalid."));
  EXPECT_FALSE(message_says_out_of_memory("Cannot read image file \"/data/bad_alloc/x.exr\". Unexpected end of file."));
  EXPECT_FALSE(message_says_out_of_memory("Unexpected end of file."));
  // An unbalanced quote hides the rest: the message is then not taken as out of memory.
  EXPECT_FALSE(message_says_out_of_memory("channel \"std::bad_alloc"));
  // The fuzzer's input (tests/fuzz/corpus/spectral_exr/regression-quote-in-channel-name): a quote
  // inside a channel's name, pairing quotes one by one would leave "ut of memory" outside them.
  EXPECT_FALSE(message_says_out_of_memory(
      "Cannot read image file \"/tmp/input.exr\". Number of pixels per row in the image's data window is not a "
      "multiple of the x subsampling factor of the \"a[{\"fut of memoryEEEE\" channel."));
  // Text after the last quote still counts.
  EXPECT_TRUE(message_says_out_of_memory("Cannot read \"a\"b\" channel: std::bad_alloc"));
}

}  // namespace
}  // namespace prizma::spectral
