// Every error message is one line (core/errors.h): the CLI prints it as it is, and a file's
// names and keys quoted in it must not break it up or flood the terminal.
#include <gtest/gtest.h>

#include <string>

#include "core/errors.h"

using namespace lobe;

TEST(ErrorMessages, ControlCharactersAFileQuotedAreEscapedSoTheMessageStaysOneLine)
{
    const InvalidInput e(std::string("settings.growth: unknown key 'split_\ngle\r\t\x01\x7f'"));
    EXPECT_STREQ(e.what(), "settings.growth: unknown key 'split_\\ngle\\r\\t\\x01\\x7f'");
    const FileError f("a\nb.json", "bad");
    EXPECT_STREQ(f.what(), "a\\nb.json: bad");
}

TEST(ErrorMessages, PrintableTextAndUtf8AreKeptAsTheyAre)
{
    const std::string text = "mesh 'Bäume – 木' has no POSITION";
    EXPECT_EQ(InvalidInput(text).what(), text);
}

TEST(ErrorMessages, AHugeMessageIsCutAtACharacterBoundaryAndSaysSo)
{
    std::string key;
    for (int i = 0; i < 2000; ++i) key += "\xc3\xa4"; // ä, two bytes each
    const std::string msg = InvalidInput("unknown key '" + key + "'").what();
    EXPECT_LE(msg.size(), 1000u + 3u); // the cut text and the mark
    EXPECT_EQ(msg.substr(msg.size() - 3), "\u2026");
    EXPECT_EQ(msg.substr(0, 13), "unknown key '");
    // Every ä before the mark is whole.
    const std::string body = msg.substr(13, msg.size() - 16);
    ASSERT_EQ(body.size() % 2, 0u);
    for (std::size_t i = 0; i < body.size(); i += 2) EXPECT_EQ(body.substr(i, 2), "\xc3\xa4");
}
