// The line input cuts a byte stream into lines wherever the reads happen to end: a file read in
// 64 kB blocks, a FIFO written in chunks of random size. Whatever the chunking, the lines handed
// out are those an independent split of the whole text gives (at '\n', a trailing '\r' taken
// off, the last line without its newline kept), and a line over kMaxLineBytes is said once as
// too long and skipped to its end.
#include "planner/tracking/line_input.hpp"
#include "tests/test_util.hpp"

#include <gtest/gtest.h>

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <fstream>
#include <random>
#include <string>
#include <thread>
#include <vector>

namespace skylane::planner {
namespace {

/// What next() should hand out for one line of the text.
struct Expected {
  LineInput::Status status;
  std::string line;
};

/// A text of `n` lines: most short, some tens of kB (across the reader's blocks), some ending in
/// CR LF, some empty, and (when `too_long`) one of 3 MiB in the middle.
std::string randomText(std::mt19937& rng, int n, bool too_long, bool final_newline) {
  std::string text;
  for (int i = 0; i < n; ++i) {
    const unsigned kind = rng() % 20;
    std::size_t length = kind == 0 ? 20000 + rng() % 90000 : kind == 1 ? 0 : rng() % 300;
    if (too_long && i == n / 2) length = 3 * kMaxLineBytes;
    for (std::size_t k = 0; k < length; ++k) text.push_back(static_cast<char>('a' + rng() % 26));
    if (rng() % 4 == 0) text.push_back('\r');
    if (i + 1 < n || final_newline) text.push_back('\n');
  }
  return text;
}

/// The independent split.
std::vector<Expected> splitLines(const std::string& text) {
  std::vector<Expected> out;
  std::size_t at = 0;
  while (at < text.size()) {
    std::size_t end = text.find('\n', at);
    const bool last = end == std::string::npos;
    if (last) end = text.size();
    std::string line = text.substr(at, end - at);
    if (!line.empty() && line.back() == '\r') line.pop_back();
    if (line.size() > kMaxLineBytes) {
      out.push_back({LineInput::Status::kTooLong, ""});
    } else {
      out.push_back({LineInput::Status::kLine, line});
    }
    at = last ? text.size() : end + 1;
  }
  return out;
}

/// Everything the input hands out until its end (quiet spells skipped).
std::vector<Expected> readAll(LineInput& in) {
  std::vector<Expected> out;
  std::string line;
  for (;;) {
    const LineInput::Status s = in.next(line, 1000);
    if (s == LineInput::Status::kEnd) return out;
    if (s == LineInput::Status::kTimeout) continue;
    out.push_back({s, s == LineInput::Status::kLine ? line : ""});
  }
}

void expectSame(const std::vector<Expected>& got, const std::vector<Expected>& want, const std::string& what) {
  ASSERT_EQ(got.size(), want.size()) << what;
  for (std::size_t i = 0; i < got.size(); ++i) {
    EXPECT_EQ(got[i].status, want[i].status) << what << ", line " << i + 1;
    EXPECT_EQ(got[i].line, want[i].line) << what << ", line " << i + 1;
  }
}

TEST(LineInput, AFileGivesTheLinesOfAnIndependentSplitWhateverTheBlocks) {
  std::mt19937 rng(20261204);
  for (int round = 0; round < 6; ++round) {
    const std::string text = randomText(rng, 400, round % 2 == 1, round % 3 != 0);
    const std::string path = test::scratchPath("lines-" + std::to_string(round) + ".txt");
    std::ofstream(path, std::ios::binary) << text;
    const auto in = openLineInput(path);
    expectSame(readAll(*in), splitLines(text), "round " + std::to_string(round));
  }
}

TEST(LineInput, AFifoWrittenInChunksOfRandomSizeGivesTheSameLines) {
  std::mt19937 rng(7);
  for (int round = 0; round < 4; ++round) {
    const std::string text = randomText(rng, 300, round == 1, round != 2);
    const std::string path = test::scratchPath("fifo-" + std::to_string(round));
    ASSERT_EQ(mkfifo(path.c_str(), 0600), 0);
    std::thread writer([&text, &path, seed = rng()] {
      std::mt19937 chunks(seed);
      const int fd = open(path.c_str(), O_WRONLY);
      for (std::size_t at = 0; at < text.size();) {
        const std::size_t n = std::min<std::size_t>(text.size() - at, 1 + chunks() % (chunks() % 2 ? 40 : 100000));
        const ssize_t w = write(fd, text.data() + at, n);
        if (w <= 0) break;
        at += static_cast<std::size_t>(w);
      }
      close(fd);
    });
    const auto in = openLineInput(path);
    EXPECT_TRUE(in->live());
    const std::vector<Expected> got = readAll(*in);
    writer.join();
    expectSame(got, splitLines(text), "round " + std::to_string(round));
  }
}

}  // namespace
}  // namespace skylane::planner
