// Sessions the program writes are read back and written again byte for byte: every shipped
// recording replayed into a document (stroke edits, pinch deforms, moves, rotations and
// scales among them), saved, loaded and saved again.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>

#include "core/document.h"
#include "tests/support/replay_fixture.h"
#include "tests/support/test_paths.h"

using namespace lobe;
namespace fs = std::filesystem;

namespace {

std::string read_all(const std::string& path)
{
    std::ifstream in(path, std::ios::binary);
    return std::string(std::istreambuf_iterator<char>(in), {});
}

} // namespace

TEST(SessionRoundTrip, EveryReplayedRecordingIsWrittenBackByteForByte)
{
    const std::string dir = test::temp_dir("session-roundtrip");
    std::size_t recordings = 0, edits = 0;
    for (const fs::directory_entry& e : fs::directory_iterator(test::source_path("recordings"))) {
        if (e.path().extension() != ".lrec" || e.is_symlink()) continue; // demo.lrec names another one
        const std::string name = e.path().stem().string();
        const Document doc = test::replay_document(name);
        const std::string first = dir + "/" + name + ".json", second = dir + "/" + name + ".again.json";
        save_document(first, doc);
        const Document loaded = load_document(first);
        save_document(second, loaded);
        EXPECT_EQ(read_all(first), read_all(second)) << name;
        EXPECT_EQ(loaded.edits.size(), doc.edits.size()) << name;
        ++recordings;
        edits += doc.edits.size();
    }
    EXPECT_EQ(recordings, 5u);
    EXPECT_GT(edits, 4u); // the edit recordings are among them
}
