// Error messages stay one printable line (issue 23 item 11): the bytes of a bad input that a
// message repeats are escaped and cut.
#include "maps/parse_error.hpp"

#include <gtest/gtest.h>

#include <string>

namespace skylane::maps {
namespace {

TEST(Printable, EscapesControlCharactersAndBytesThatAreNotUtf8) {
  using namespace std::string_literals;
  EXPECT_EQ(printable("a\nb\r\tc"), "a\\nb\\r\\tc");
  EXPECT_EQ(printable("\x1b[31mred\x1b[0m"), "\\x1b[31mred\\x1b[0m");  // a terminal's colour escape
  EXPECT_EQ(printable("before\0after"s), "before\\x00after");            // not cut at NUL
  EXPECT_EQ(printable("\x7f"), "\\x7f");
  EXPECT_EQ(printable("\xff\xfe"), "\\xff\\xfe");                        // not UTF-8
  EXPECT_EQ(printable("\xc0\xaf"), "\\xc0\\xaf");                        // an overlong '/'
  EXPECT_EQ(printable("\xed\xa0\x80"), "\\xed\\xa0\\x80");               // a surrogate
  EXPECT_EQ(printable("\xc2\x9b" "2J"), "\\xc2\\x9b2J");                 // C1 CSI
  EXPECT_EQ(printable("\xe2\x82"), "\\xe2\\x82");                        // a cut sequence
}

TEST(Printable, KeepsPrintableUtf8AsItIsAndIsIdempotent) {
  for (const std::string s : {"plain", "47.3° N, Zürich", "禁飞区", "emoji 🛩", "back\\slash"}) {
    EXPECT_EQ(printable(s), s);
  }
  const std::string once = printable("x\n\x1b\xff");
  EXPECT_EQ(printable(once), once);
}

TEST(Printable, CutsAfterTheLimitWithAMark) {
  EXPECT_EQ(printable(std::string(150, 'a'), 100), std::string(100, 'a') + "…");
  EXPECT_EQ(printable(std::string(100, 'a'), 100), std::string(100, 'a'));
}

TEST(ParseError, QuotesTheValueOnOneLineCutAtTheLimit) {
  const ParseError e("alm.txt", 3, "Health", "00\n\x1b]0;owned\x07" + std::string(300, 'z'), "a number");
  const std::string msg = e.what();
  EXPECT_EQ(msg.find('\n'), std::string::npos) << msg;
  EXPECT_EQ(msg.find('\x1b'), std::string::npos) << msg;
  EXPECT_EQ(msg.rfind("alm.txt:3: field 'Health': got '00\\n\\x1b]0;owned\\x07zzz", 0), 0u) << msg;
  EXPECT_NE(msg.find("z…', expected a number"), std::string::npos) << msg;
  EXPECT_LT(msg.size(), 200u);
}

}  // namespace
}  // namespace skylane::maps
