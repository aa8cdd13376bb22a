#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <functional>
#include <limits>
#include <random>
#include <sstream>

#include <glm/gtc/quaternion.hpp>

#include "core/errors.h"
#include "input/recording.h"
#include "tests/support/test_paths.h"

using namespace lobe;

namespace {

constexpr float kNaN = std::numeric_limits<float>::quiet_NaN();
constexpr float kInf = std::numeric_limits<float>::infinity();

HandState sample_hand(double t, int h)
{
    HandState hand;
    hand.active = true;
    const float side = h == 0 ? -0.2f : 0.2f;
    for (int j = 0; j < kJointCount; ++j) {
        JointState& js = hand.joints[j];
        const float fj = static_cast<float>(j);
        const float ft = static_cast<float>(t);
        js.pose.position = {side + 0.01f * fj, 1.2f + 0.05f * std::sin(ft + fj), -0.4f + 0.03f * std::cos(ft * 2.0f - fj)};
        glm::vec3 axis = glm::normalize(glm::vec3(std::sin(fj), 1.0f, std::cos(ft + fj)));
        js.pose.orientation = glm::angleAxis(0.3f * fj + ft, axis);
        js.radius = 0.005f + 0.0003f * fj;
        js.flags = j % 7 == 3 ? std::uint8_t{kOrientationValid | kPositionValid} : kAllJointFlags;
    }
    hand.joints[5].pose.position.x = 1e-7f; // an awkward float for the text form
    return hand;
}

/// Two hands (the right one drops out for a few frames), head, events, annotations.
Recording sample_recording(int frames = 30)
{
    Recording r;
    r.header.source = "test:recording_test";
    r.header.device = "unit test hands";
    r.header.space = "stage";
    r.header.nominal_rate_hz = 90.0;
    r.header.created = "2024-05-01T10:00:00Z";
    for (int i = 0; i < frames; ++i) {
        HandFrame f;
        f.time = i / 90.0;
        f.head_valid = i % 10 != 4;
        f.head.position = {0.01f * static_cast<float>(i), 1.6f, 0.1f};
        f.head.orientation = glm::angleAxis(0.01f * static_cast<float>(i), glm::vec3(0, 1, 0));
        f.hands[0] = sample_hand(f.time, 0);
        if (i % 12 < 9) f.hands[1] = sample_hand(f.time, 1);
        r.frames.push_back(f);
    }
    auto event = [&](double t, InputEventKind k, int code, int value, float x, float y) {
        InputEvent e;
        e.time = t;
        e.kind = k;
        e.code = code;
        e.value = value;
        e.x = x;
        e.y = y;
        r.events.push_back(e);
    };
    event(0.05, InputEventKind::Key, 65, 1, 0, 0);
    event(0.05, InputEventKind::MouseMove, 0, 0, 312.5f, 200.25f);
    event(0.1, InputEventKind::MouseButton, 0, 1, 0, 0);
    event(0.12, InputEventKind::MouseWheel, 0, 0, 0, -1.5f);
    event(0.2, InputEventKind::Key, 65, 0, 0, 0);
    r.annotations.push_back({0.06, "stroke_begin id=1"});
    r.annotations.push_back({0.3, "two\nlines, a \\ backslash,\ta tab and  spaces "});
    r.annotations.push_back({0.3, ""});
    return r;
}

std::string slurp(const std::string& path)
{
    std::ifstream in(path, std::ios::binary);
    return std::string(std::istreambuf_iterator<char>(in), {});
}

void spit(const std::string& path, const std::string& bytes)
{
    std::ofstream out(path, std::ios::binary);
    out << bytes;
}

/// The FileError message of f(), after checking it is one line starting with the path.
std::string file_error(const std::string& path, const std::function<void()>& f)
{
    try {
        f();
    } catch (const FileError& e) {
        std::string m = e.what();
        EXPECT_EQ(m.find('\n'), std::string::npos) << m;
        EXPECT_EQ(m.rfind(path + ": ", 0), 0u) << m;
        return m;
    }
    ADD_FAILURE() << "expected a FileError for " << path;
    return {};
}

bool has_problem(const ReadReport& r, const std::string& part)
{
    for (const std::string& p : r.problems)
        if (p.find(part) != std::string::npos) return true;
    return false;
}

std::string problems(const ReadReport& r)
{
    std::string s;
    for (const std::string& p : r.problems) s += "  " + p + "\n";
    return s;
}

void expect_same_events_and_notes(const Recording& a, const Recording& b)
{
    ASSERT_EQ(a.events.size(), b.events.size());
    for (std::size_t i = 0; i < a.events.size(); ++i) {
        EXPECT_EQ(a.events[i].time, b.events[i].time);
        EXPECT_EQ(a.events[i].kind, b.events[i].kind);
        EXPECT_EQ(a.events[i].code, b.events[i].code);
        EXPECT_EQ(a.events[i].value, b.events[i].value);
        EXPECT_EQ(a.events[i].x, b.events[i].x);
        EXPECT_EQ(a.events[i].y, b.events[i].y);
    }
    ASSERT_EQ(a.annotations.size(), b.annotations.size());
    for (std::size_t i = 0; i < a.annotations.size(); ++i) {
        EXPECT_EQ(a.annotations[i].time, b.annotations[i].time);
        EXPECT_EQ(a.annotations[i].text, b.annotations[i].text);
    }
}

/// Frames equal up to the binary form's quantisation (exact for quat_tol = radius_tol = 0).
void expect_same_frame(const HandFrame& a, const HandFrame& b, float quat_tol, float radius_tol)
{
    EXPECT_EQ(a.time, b.time);
    ASSERT_EQ(a.head_valid, b.head_valid);
    if (a.head_valid) {
        EXPECT_EQ(a.head.position, b.head.position);
        EXPECT_EQ(a.head.orientation, b.head.orientation);
    }
    for (int h = 0; h < kHandCount; ++h) {
        ASSERT_EQ(a.hands[h].active, b.hands[h].active);
        if (!a.hands[h].active) continue;
        for (int j = 0; j < kJointCount; ++j) {
            const JointState& x = a.hands[h].joints[j];
            const JointState& y = b.hands[h].joints[j];
            EXPECT_EQ(x.pose.position, y.pose.position);
            for (int c = 0; c < 4; ++c) EXPECT_NEAR(x.pose.orientation[c], y.pose.orientation[c], quat_tol);
            EXPECT_NEAR(x.radius, y.radius, radius_tol);
            EXPECT_EQ(x.flags, y.flags);
        }
    }
}

/// Byte offsets where each record of an encoded recording with frames only starts; the last
/// entry is the file size.
std::vector<std::size_t> frame_record_offsets(const Recording& rec)
{
    Recording prefix = rec;
    prefix.events.clear();
    prefix.annotations.clear();
    std::vector<std::size_t> offsets;
    for (std::size_t k = 0; k <= rec.frames.size(); ++k) {
        prefix.frames.assign(rec.frames.begin(), rec.frames.begin() + static_cast<std::ptrdiff_t>(k));
        offsets.push_back(encode_recording_binary(prefix).size());
    }
    return offsets;
}

std::string numbers_for_hand(float x)
{
    std::string s;
    for (int j = 0; j < kJointCount; ++j) {
        s += ' ';
        s += std::to_string(x);
        s += " 1.2 -0.3 1 0 0 0 0.008 15";
    }
    return s;
}

} // namespace

// ------------------------------------------------------------------------------------------
// Round trips
// ------------------------------------------------------------------------------------------

TEST(RecordingBinary, RoundTripKeepsEveryValueWithinQuantisation)
{
    const std::string path = test::temp_dir("rec-bin-roundtrip") + "/a.lrec";
    const Recording rec = sample_recording();
    write_recording_binary(path, rec);
    ReadReport report;
    const Recording back = read_recording(path, &report);

    EXPECT_EQ(back.header.version, kRecordingVersion);
    EXPECT_EQ(back.header.source, rec.header.source);
    EXPECT_EQ(back.header.device, rec.header.device);
    EXPECT_EQ(back.header.units, "m");
    EXPECT_EQ(back.header.space, "stage");
    EXPECT_EQ(back.header.nominal_rate_hz, 90.0);
    EXPECT_EQ(back.header.created, rec.header.created);
    ASSERT_EQ(back.frames.size(), rec.frames.size());
    for (std::size_t i = 0; i < rec.frames.size(); ++i) expect_same_frame(rec.frames[i], back.frames[i], 1e-4f, 1e-5f);
    expect_same_events_and_notes(rec, back);
    EXPECT_EQ(report.frames_read, rec.frames.size());
    EXPECT_EQ(report.frames_dropped, 0u);
    EXPECT_EQ(report.events_dropped, 0u);
    EXPECT_TRUE(report.problems.empty()) << problems(report);
}

TEST(RecordingBinary, ReencodingADecodedFileGivesIdenticalBytes)
{
    const std::string bytes = encode_recording_binary(sample_recording());
    const Recording once = parse_recording(bytes, "mem.lrec");
    EXPECT_EQ(encode_recording_binary(once), bytes);
    const Recording twice = parse_recording(encode_recording_binary(once), "mem.lrec");
    EXPECT_EQ(encode_recording_binary(twice), bytes);
}

TEST(RecordingBinary, RecordsCarryAStandardCrc32OfTypeLengthAndPayload)
{
    // Bitwise reference CRC-32 (IEEE), independent of the table-driven one under test.
    auto crc = [](const unsigned char* p, std::size_t n) {
        std::uint32_t c = 0xFFFFFFFFu;
        for (std::size_t i = 0; i < n; ++i) {
            c ^= p[i];
            for (int k = 0; k < 8; ++k) c = (c >> 1) ^ (0xEDB88320u & (0u - (c & 1u)));
        }
        return ~c;
    };
    const unsigned char check[] = "123456789";
    ASSERT_EQ(crc(check, 9), 0xCBF43926u);

    Recording rec = sample_recording(1);
    rec.events.clear();
    rec.annotations.clear();
    const std::string bytes = encode_recording_binary(rec);
    const auto* p = reinterpret_cast<const unsigned char*>(bytes.data());
    ASSERT_EQ(bytes.substr(0, 7), "LOBEREC");
    const std::size_t header = 16 + (p[12] | p[13] << 8) + 4;
    const std::size_t record = bytes.size() - header;
    const std::size_t payload = p[header + 5] | p[header + 6] << 8;
    ASSERT_EQ(record, 13 + payload);
    const std::size_t stored = bytes.size() - 4;
    const std::uint32_t expected = p[stored] | p[stored + 1] << 8 | p[stored + 2] << 16 |
                                   static_cast<std::uint32_t>(p[stored + 3]) << 24;
    EXPECT_EQ(crc(p + header + 4, 5 + payload), expected);
}

TEST(RecordingText, RoundTripIsExactAndReencodesToIdenticalText)
{
    const std::string path = test::temp_dir("rec-text-roundtrip") + "/a.lrec.txt";
    const Recording rec = sample_recording();
    write_recording_text(path, rec);
    const std::string text = slurp(path);
    EXPECT_EQ(text.rfind("lobesketch-recording-text 1\nheader {", 0), 0u);
    ReadReport report;
    const Recording back = read_recording(path, &report);
    EXPECT_TRUE(report.problems.empty()) << problems(report);
    EXPECT_EQ(back.header.source, rec.header.source);
    EXPECT_EQ(back.header.created, rec.header.created);
    ASSERT_EQ(back.frames.size(), rec.frames.size());
    for (std::size_t i = 0; i < rec.frames.size(); ++i) expect_same_frame(rec.frames[i], back.frames[i], 0.0f, 0.0f);
    expect_same_events_and_notes(rec, back);
    EXPECT_EQ(encode_recording_text(back), text);
}

TEST(RecordingText, BinaryAndTextFormsDecodeToTheSameRecording)
{
    const Recording from_binary = parse_recording(encode_recording_binary(sample_recording()), "a.lrec");
    const Recording from_text = parse_recording(encode_recording_text(from_binary), "a.txt");
    EXPECT_EQ(encode_recording_binary(from_text), encode_recording_binary(from_binary));
}

TEST(RecordingText, HandWrittenFixtureWithCommentsAndInactiveHandsParses)
{
    const std::string fixture =
        "lobesketch-recording-text 1\n"
        "# a hand-written fixture: only the right hand, no head\n"
        "header {\"source\": \"hand-written\", \"device\": \"none\"}\n"
        "\n"
        "frame 0 head - left - right" + numbers_for_hand(0.1f) + "\n"
        "   # indented comment\n"
        "frame 0.5 head 0 1.6 0 1 0 0 0 left - right" + numbers_for_hand(0.2f) + "\r\n"
        "event 0.25 key 32 1\n"
        "event 0.3 mouse_move 10 20.5\n"
        "event 0.3 wheel -1\n"
        "event 0.4 mouse_button 0 0\n"
        "note 0.5 pinch_start hand=right\n";
    ReadReport report;
    const Recording rec = parse_recording(fixture, "fixture.txt", &report);
    EXPECT_EQ(rec.header.source, "hand-written");
    EXPECT_EQ(rec.header.units, "m");
    ASSERT_EQ(rec.frames.size(), 2u);
    EXPECT_FALSE(rec.frames[0].head_valid);
    EXPECT_TRUE(rec.frames[1].head_valid);
    EXPECT_FALSE(rec.frames[0].hands[0].active);
    EXPECT_TRUE(rec.frames[1].hands[1].active);
    EXPECT_FLOAT_EQ(rec.frames[1].hands[1].joints[25].pose.position.x, 0.2f);
    EXPECT_EQ(rec.frames[1].hands[1].joints[25].flags, kAllJointFlags);
    ASSERT_EQ(rec.events.size(), 4u);
    EXPECT_EQ(rec.events[0].kind, InputEventKind::Key);
    EXPECT_EQ(rec.events[0].code, 32);
    EXPECT_EQ(rec.events[1].kind, InputEventKind::MouseMove);
    EXPECT_EQ(rec.events[1].y, 20.5f);
    EXPECT_EQ(rec.events[2].kind, InputEventKind::MouseWheel);
    EXPECT_EQ(rec.events[2].y, -1.0f);
    ASSERT_EQ(rec.annotations.size(), 1u);
    EXPECT_EQ(rec.annotations[0].text, "pinch_start hand=right");
    EXPECT_TRUE(has_problem(report, "left hand never tracked")) << problems(report);
}

// ------------------------------------------------------------------------------------------
// Recovery from truncation and corruption
// ------------------------------------------------------------------------------------------

TEST(RecordingBinary, TruncationAtEveryByteOfTheLastRecordsRecoversEveryCompleteFrame)
{
    Recording rec = sample_recording(24);
    rec.events.clear();
    rec.annotations.clear();
    const std::vector<std::size_t> ends = frame_record_offsets(rec);
    const std::string bytes = encode_recording_binary(rec);
    ASSERT_EQ(ends.back(), bytes.size());
    const std::size_t from = ends[ends.size() - 5];
    for (std::size_t cut = from; cut <= bytes.size(); ++cut) {
        std::size_t complete = 0;
        while (complete + 1 < ends.size() && ends[complete + 1] <= cut) ++complete;
        ReadReport report;
        const Recording back = parse_recording(bytes.substr(0, cut), "cut.lrec", &report);
        ASSERT_EQ(back.frames.size(), complete) << "cut at " << cut;
        const bool at_boundary = ends[complete] == cut;
        EXPECT_EQ(report.frames_dropped, at_boundary ? 0u : 1u) << "cut at " << cut;
        if (!at_boundary) {
            EXPECT_TRUE(has_problem(report, "record at byte " + std::to_string(ends[complete]) +
                                                ": truncated final record"))
                << "cut at " << cut << "\n" << problems(report);
        }
        for (std::size_t i = 0; i < complete; ++i) EXPECT_EQ(back.frames[i].time, rec.frames[i].time);
    }
}

TEST(RecordingBinary, FlippingAnyByteOfAMiddleRecordLosesOnlyThatFrameAndNamesItsOffset)
{
    Recording rec = sample_recording(20);
    rec.events.clear();
    rec.annotations.clear();
    const std::vector<std::size_t> ends = frame_record_offsets(rec);
    const std::string bytes = encode_recording_binary(rec);
    const std::size_t k = 10;
    for (std::size_t at = ends[k]; at < ends[k + 1]; ++at) {
        std::string damaged = bytes;
        damaged[at] = static_cast<char>(damaged[at] ^ 0xFF);
        ReadReport report;
        const Recording back = parse_recording(damaged, "flip.lrec", &report);
        ASSERT_EQ(back.frames.size(), rec.frames.size() - 1) << "flip at " << at << "\n" << problems(report);
        for (std::size_t i = 0, j = 0; i < rec.frames.size(); ++i) {
            if (i == k) continue;
            EXPECT_EQ(back.frames[j++].time, rec.frames[i].time);
        }
        EXPECT_GE(report.frames_dropped, 1u);
        EXPECT_TRUE(has_problem(report, "record at byte " + std::to_string(ends[k]) + ": "))
            << "flip at " << at << "\n" << problems(report);
    }
    // A payload flip is a checksum failure.
    std::string damaged = bytes;
    damaged[ends[k] + 40] = static_cast<char>(damaged[ends[k] + 40] ^ 0x10);
    ReadReport report;
    parse_recording(damaged, "flip.lrec", &report);
    EXPECT_TRUE(has_problem(report, "record at byte " + std::to_string(ends[k]) + ": bad checksum"))
        << problems(report);
}

TEST(RecordingBinary, AGarbageRunInTheMiddleLosesOnlyTheFramesItOverwrites)
{
    Recording rec = sample_recording(40);
    const std::vector<std::size_t> ends = frame_record_offsets(rec);
    rec.events.clear();
    rec.annotations.clear();
    std::string bytes = encode_recording_binary(rec);
    std::mt19937 rng(7);
    const std::size_t begin = ends[15] + 100, end = ends[18] + 50; // frames 15..18 damaged
    for (std::size_t i = begin; i < end; ++i) bytes[i] = static_cast<char>(rng());
    ReadReport report;
    const Recording back = parse_recording(bytes, "garbage.lrec", &report);
    ASSERT_EQ(back.frames.size(), rec.frames.size() - 4) << problems(report);
    EXPECT_EQ(back.frames[14].time, rec.frames[14].time);
    EXPECT_EQ(back.frames[15].time, rec.frames[19].time);
    EXPECT_TRUE(has_problem(report, "record at byte " + std::to_string(ends[15]))) << problems(report);
}

TEST(RecordingBinary, ABadHeaderChecksumFallsBackToADefaultHeaderAndKeepsTheFrames)
{
    std::string bytes = encode_recording_binary(sample_recording(5));
    bytes[20] = static_cast<char>(bytes[20] ^ 0x01); // inside the JSON header
    ReadReport report;
    const Recording back = parse_recording(bytes, "header.lrec", &report);
    EXPECT_EQ(back.frames.size(), 5u);
    EXPECT_EQ(back.header.source, "unknown");
    EXPECT_TRUE(has_problem(report, "header: bad checksum")) << problems(report);
}

TEST(RecordingText, BadLinesAreDroppedWithTheirLineNumberAndTheRestIsRead)
{
    const Recording rec = sample_recording(10);
    Recording frames_only = rec;
    frames_only.events.clear();
    frames_only.annotations.clear();
    std::vector<std::string> lines;
    std::istringstream in(encode_recording_text(frames_only));
    for (std::string l; std::getline(in, l);) lines.push_back(l);
    ASSERT_EQ(lines.size(), 12u); // version, header, 10 frames
    // Line 4 (frame 1): the last number of the left hand removed.
    std::string& l4 = lines[3];
    const std::size_t right = l4.find(" right ");
    const std::size_t last = l4.rfind(' ', right - 1);
    l4.erase(last, right - last);
    lines[5] = "frame 0.05 head - left - right 1 2 x";                 // line 6: bad number
    lines.insert(lines.begin() + 7, "wibble 3 4");                      // line 8: unknown kind
    lines.insert(lines.begin() + 8, "event 0.1 key 65");                // line 9: missing value
    std::string text;
    for (const std::string& l : lines) text += l + "\n";

    ReadReport report;
    const Recording back = parse_recording(text, "bad.txt", &report);
    EXPECT_EQ(back.frames.size(), 8u);
    EXPECT_EQ(report.frames_dropped, 2u);
    EXPECT_EQ(report.events_dropped, 1u);
    EXPECT_TRUE(has_problem(report, "line 4: expected 234 numbers for the left hand")) << problems(report);
    EXPECT_TRUE(has_problem(report, "line 6: bad number 'x' in the right hand")) << problems(report);
    EXPECT_TRUE(has_problem(report, "line 8: unknown line kind 'wibble'")) << problems(report);
    EXPECT_TRUE(has_problem(report, "line 9: missing value")) << problems(report);
    EXPECT_EQ(back.frames.back().time, rec.frames.back().time);
}

TEST(RecordingText, ATruncatedFinalLineIsDroppedWithAReason)
{
    Recording rec = sample_recording(5);
    rec.events.clear();
    rec.annotations.clear();
    const std::string text = encode_recording_text(rec);
    const std::string cut = text.substr(0, text.rfind(' ')); // the last frame line loses its last number
    ReadReport report;
    const Recording back = parse_recording(cut, "cut.txt", &report);
    EXPECT_EQ(back.frames.size(), 4u);
    EXPECT_EQ(report.frames_dropped, 1u);
    EXPECT_TRUE(has_problem(report, "line 7: expected 234 numbers for the right hand, found 233")) << problems(report);
    EXPECT_TRUE(has_problem(report, "(truncated final line)")) << problems(report);
}

// ------------------------------------------------------------------------------------------
// Errors and validation: each a one-line message naming the file
// ------------------------------------------------------------------------------------------

TEST(RecordingErrors, WrongMagicIsAOneLineFileErrorNamingTheFile)
{
    const std::string path = test::temp_dir("rec-magic") + "/notes.lrec";
    spit(path, "PK\x03\x04 this is a zip file, not a recording\n");
    EXPECT_NE(file_error(path, [&] { read_recording(path); }).find("wrong magic"), std::string::npos);
    spit(path, "");
    EXPECT_NE(file_error(path, [&] { read_recording(path); }).find("empty file"), std::string::npos);
    spit(path, "LOBE");
    EXPECT_NE(file_error(path, [&] { read_recording(path); }).find("truncated file header"), std::string::npos);
}

TEST(RecordingErrors, MissingFileIsAOneLineFileErrorNamingTheFile)
{
    const std::string path = test::temp_dir("rec-missing") + "/nothing.lrec";
    EXPECT_NE(file_error(path, [&] { read_recording(path); }).find("no such file"), std::string::npos);
}

TEST(RecordingErrors, NewerVersionIsRefusedInBothForms)
{
    const std::string dir = test::temp_dir("rec-version");
    std::string bytes = encode_recording_binary(sample_recording(3));
    bytes[8] = 2; // major version, little-endian u16
    spit(dir + "/v2.lrec", bytes);
    std::string m = file_error(dir + "/v2.lrec", [&] { read_recording(dir + "/v2.lrec"); });
    EXPECT_NE(m.find("unsupported recording version 2"), std::string::npos) << m;

    std::string text = encode_recording_text(sample_recording(3));
    text[26] = '2';
    ASSERT_EQ(text.rfind("lobesketch-recording-text 2\n", 0), 0u);
    spit(dir + "/v2.txt", text);
    m = file_error(dir + "/v2.txt", [&] { read_recording(dir + "/v2.txt"); });
    EXPECT_NE(m.find("unsupported recording version 2"), std::string::npos) << m;
}

TEST(RecordingErrors, ZeroUsableFramesIsRefused)
{
    const std::string dir = test::temp_dir("rec-zero");
    Recording empty;
    write_recording_binary(dir + "/empty.lrec", empty);
    std::string m = file_error(dir + "/empty.lrec", [&] { read_recording(dir + "/empty.lrec"); });
    EXPECT_NE(m.find("no usable frames"), std::string::npos) << m;

    Recording all_bad = sample_recording(3);
    all_bad.events.clear();
    for (HandFrame& f : all_bad.frames) f.hands[0].joints[2].pose.position.y = kNaN;
    write_recording_text(dir + "/bad.txt", all_bad);
    m = file_error(dir + "/bad.txt", [&] { read_recording(dir + "/bad.txt"); });
    EXPECT_NE(m.find("no usable frames (3 frames and 0 events dropped; first problem: line 3: NaN/Inf"),
              std::string::npos)
        << m;
}

TEST(RecordingErrors, EventsWithoutFramesAreAUsableDesktopRecording)
{
    Recording desktop = sample_recording(0);
    const Recording back = parse_recording(encode_recording_binary(desktop), "desktop.lrec");
    EXPECT_TRUE(back.frames.empty());
    EXPECT_EQ(back.events.size(), desktop.events.size());
}

TEST(RecordingValidation, NaNAndInfAnywhereDropTheFrameInBothForms)
{
    Recording rec = sample_recording(8);
    rec.frames[1].hands[0].joints[idx(Joint::IndexTip)].pose.position.x = kNaN;
    rec.frames[2].hands[1].joints[3].pose.orientation.y = kInf;
    rec.frames[3].hands[0].joints[4].radius = kNaN;
    rec.frames[5].head.position.z = -kInf;
    rec.frames[6].time = std::numeric_limits<double>::quiet_NaN();
    for (bool binary : {true, false}) {
        const std::string bytes = binary ? encode_recording_binary(rec) : encode_recording_text(rec);
        ReadReport report;
        const Recording back = parse_recording(bytes, "nan", &report);
        EXPECT_EQ(back.frames.size(), 3u) << problems(report);
        EXPECT_EQ(report.frames_dropped, 5u);
        EXPECT_TRUE(has_problem(report, "NaN/Inf in left index_tip position in frame 1")) << problems(report);
        EXPECT_TRUE(has_problem(report, "NaN/Inf in right thumb_proximal orientation in frame 2")) << problems(report);
        EXPECT_TRUE(has_problem(report, "NaN/Inf in left thumb_distal radius in frame 3")) << problems(report);
        EXPECT_TRUE(has_problem(report, "NaN/Inf in head position in frame 5")) << problems(report);
        EXPECT_TRUE(has_problem(report, "NaN/Inf time in frame 6")) << problems(report);
    }
}

TEST(RecordingValidation, TimeGoingBackwardsDropsTheFrameOrEvent)
{
    Recording rec = sample_recording(8);
    rec.frames[4].time = rec.frames[2].time;
    rec.frames[6].time = rec.frames[5].time; // not strictly increasing
    rec.events[3].time = 0.01;
    for (bool binary : {true, false}) {
        const std::string bytes = binary ? encode_recording_binary(rec) : encode_recording_text(rec);
        ReadReport report;
        const Recording back = parse_recording(bytes, "time", &report);
        EXPECT_EQ(back.frames.size(), 6u);
        EXPECT_EQ(back.events.size(), rec.events.size() - 1);
        EXPECT_TRUE(has_problem(report, "time going backwards at frame 4")) << problems(report);
        EXPECT_TRUE(has_problem(report, "time going backwards at frame 6")) << problems(report);
        EXPECT_TRUE(has_problem(report, "time going backwards at event")) << problems(report);
        for (std::size_t i = 1; i < back.frames.size(); ++i) EXPECT_GT(back.frames[i].time, back.frames[i - 1].time);
    }
}

TEST(RecordingValidation, UnknownEventKindIsSkippedWithAWarning)
{
    Recording rec = sample_recording(4);
    rec.events[2].kind = static_cast<InputEventKind>(9);
    ReadReport report;
    Recording back = parse_recording(encode_recording_binary(rec), "kind.lrec", &report);
    EXPECT_EQ(back.events.size(), rec.events.size() - 1);
    EXPECT_TRUE(has_problem(report, "unknown event kind 9 skipped")) << problems(report);

    std::string text = encode_recording_text(sample_recording(4));
    text += "event 1 gamepad_axis 3 0.5\n";
    back = parse_recording(text, "kind.txt", &report);
    EXPECT_EQ(back.events.size(), rec.events.size());
    EXPECT_EQ(report.events_dropped, 1u);
    EXPECT_TRUE(has_problem(report, "unknown event kind 'gamepad_axis' skipped")) << problems(report);
}

TEST(RecordingSettings, SettingEventsRoundTripExactlyInBothForms)
{
    Recording rec = sample_recording(4);
    auto setting = [&](double t, SettingId id, int lobe, float x) {
        InputEvent e;
        e.time = t;
        e.kind = InputEventKind::Setting;
        e.code = static_cast<std::int32_t>(id);
        e.value = lobe;
        e.x = x;
        rec.events.push_back(e);
    };
    setting(0.2, SettingId::SplitAngle, 0, 22.5f);
    setting(0.21, SettingId::AttractorSpacing, 0, 0.03f);
    setting(0.22, SettingId::Species, 3, 2.0f);
    setting(0.23, SettingId::Seed, 0, 16777215.0f);
    setting(0.24, SettingId::LeafLength, 0, 1e-7f); // out of range, but the reader keeps raw input
    for (bool binary : {true, false}) {
        ReadReport report;
        const std::string bytes = binary ? encode_recording_binary(rec) : encode_recording_text(rec);
        const Recording back = parse_recording(bytes, "settings", &report);
        EXPECT_EQ(report.events_dropped, 0u) << problems(report);
        expect_same_events_and_notes(rec, back);
        // Text: the same bytes again after reading.
        if (!binary) {
            EXPECT_EQ(encode_recording_text(back), bytes);
        }
    }
    EXPECT_NE(encode_recording_text(rec).find("event 0.2 setting 1 0 22.5\n"), std::string::npos);
    EXPECT_STREQ(event_kind_name(InputEventKind::Setting), "setting");
    EXPECT_STREQ(setting_name(SettingId::LeavesPerNode), "leaves-per-node");
    EXPECT_STREQ(setting_name(SettingId::Grower), "grower");
    EXPECT_STREQ(setting_name(SettingId::GrowthSteps), "growth-steps");
    EXPECT_EQ(setting_name(static_cast<SettingId>(9)), nullptr);
}

TEST(RecordingSettings, UnknownSettingIdIsSkippedWithAWarningNotACrash)
{
    std::string text = encode_recording_text(sample_recording(4));
    text += "event 1 setting 9 0 0.5\n";
    text += "event 1.1 setting 1 0 25\n";
    text += "event 1.2 setting -2147483648 7 nan\n";
    text += "event 1.3 setting 1 0\n";
    ReadReport report;
    Recording back = parse_recording(text, "ids.txt", &report);
    ASSERT_EQ(back.events.size(), sample_recording(4).events.size() + 1);
    EXPECT_EQ(back.events.back().kind, InputEventKind::Setting);
    EXPECT_EQ(back.events.back().x, 25.0f);
    EXPECT_EQ(report.events_dropped, 3u);
    EXPECT_TRUE(has_problem(report, "unknown setting id 9 skipped")) << problems(report);
    EXPECT_TRUE(has_problem(report, "unknown setting id -2147483648 skipped")) << problems(report);
    EXPECT_TRUE(has_problem(report, "missing value in setting event")) << problems(report);

    // Binary: the same rule for a newer writer's id.
    Recording rec = sample_recording(4);
    InputEvent e;
    e.time = 0.2;
    e.kind = InputEventKind::Setting;
    e.code = 42;
    rec.events.push_back(e);
    ReadReport binary_report;
    back = parse_recording(encode_recording_binary(rec), "ids.lrec", &binary_report);
    EXPECT_EQ(back.events.size(), rec.events.size() - 1);
    EXPECT_TRUE(has_problem(binary_report, "unknown setting id 42 skipped")) << problems(binary_report);
}

TEST(RecordingValidation, AbsurdCoordinatesDropTheFrame)
{
    Recording rec = sample_recording(4);
    rec.frames[2].hands[0].joints[idx(Joint::Wrist)].pose.position.y = 2000.0f;
    for (bool binary : {true, false}) {
        const std::string bytes = binary ? encode_recording_binary(rec) : encode_recording_text(rec);
        ReadReport report;
        const Recording back = parse_recording(bytes, "far", &report);
        EXPECT_EQ(back.frames.size(), 3u);
        EXPECT_TRUE(has_problem(report, "absurd coordinate 2000 m (limit 1000 m) in left wrist position in frame 2"))
            << problems(report);
    }
}

TEST(RecordingValidation, AHandMissingForTheWholeFileIsOnlyNoted)
{
    Recording rec = sample_recording(6);
    for (HandFrame& f : rec.frames) f.hands[1].active = false;
    ReadReport report;
    const Recording back = parse_recording(encode_recording_binary(rec), "onehand.lrec", &report);
    EXPECT_EQ(back.frames.size(), 6u);
    EXPECT_EQ(report.frames_dropped, 0u);
    EXPECT_TRUE(has_problem(report, "right hand never tracked")) << problems(report);
    EXPECT_FALSE(has_problem(report, "left hand never tracked")) << problems(report);
}

TEST(RecordingValidation, AllZeroQuaternionsAreRepairedNotDropped)
{
    Recording rec = sample_recording(4);
    rec.frames[1].hands[0].joints[7].pose.orientation = glm::quat(0, 0, 0, 0);
    rec.frames[2].hands[1].joints[0].pose.orientation = glm::quat(0, 0, 0, 0);
    for (bool binary : {true, false}) {
        const std::string bytes = binary ? encode_recording_binary(rec) : encode_recording_text(rec);
        ReadReport report;
        const Recording back = parse_recording(bytes, "zero", &report);
        ASSERT_EQ(back.frames.size(), 4u);
        const JointState& j = back.frames[1].hands[0].joints[7];
        EXPECT_EQ(j.pose.orientation, glm::quat(1, 0, 0, 0));
        EXPECT_EQ(j.flags & kOrientationValid, 0);
        EXPECT_EQ(j.flags & kPositionValid, kPositionValid);
        EXPECT_TRUE(has_problem(report, "2 all-zero joint orientations set to identity")) << problems(report);
    }
}

TEST(RecordingValidation, UnitsOtherThanMetresAreRefused)
{
    std::string text = "lobesketch-recording-text 1\nheader {\"units\": \"mm\"}\nframe 0 head - left - right -\n";
    const std::string m = file_error("mm.txt", [&] { parse_recording(text, "mm.txt"); });
    EXPECT_NE(m.find("units 'mm' are not supported"), std::string::npos) << m;
}

TEST(RecordingValidation, HeaderWithInvalidUtf8OrDeepNestingNeverThrowsButTheUnitsCheck)
{
    Recording rec = sample_recording(2);
    rec.header.device = "bad \xff\xfe utf-8";
    const Recording back = parse_recording(encode_recording_binary(rec), "utf8.lrec");
    EXPECT_EQ(back.header.device, "bad \xef\xbf\xbd\xef\xbf\xbd utf-8"); // U+FFFD twice

    const std::string text = "lobesketch-recording-text 1\nheader {\"a\":" + std::string(5000, '[') +
                             "\nframe 0 head - left - right -\n";
    ReadReport report;
    const Recording deep = parse_recording(text, "deep.txt", &report);
    EXPECT_EQ(deep.frames.size(), 1u);
    EXPECT_EQ(deep.header.source, "unknown");
    EXPECT_TRUE(has_problem(report, "line 2: header nested too deeply, using a default header")) << problems(report);
}

TEST(RecordingLimits, AnnotationTextIsCappedAt1000Bytes)
{
    Recording rec = sample_recording(2);
    rec.annotations = {{0.0, std::string(5000, 'a')}};
    for (bool binary : {true, false}) {
        const std::string bytes = binary ? encode_recording_binary(rec) : encode_recording_text(rec);
        const Recording back = parse_recording(bytes, "note");
        ASSERT_EQ(back.annotations.size(), 1u);
        EXPECT_EQ(back.annotations[0].text.size(), 1000u);
    }
    const std::string text = "lobesketch-recording-text 1\nheader {}\nframe 0 head - left - right -\nnote 0 " +
                             std::string(1500, 'b') + "\n";
    ReadReport report;
    const Recording back = parse_recording(text, "long.txt", &report);
    EXPECT_EQ(back.annotations.at(0).text.size(), 1000u);
    EXPECT_TRUE(has_problem(report, "line 4: annotation longer than 1000 bytes, truncated")) << problems(report);
}

TEST(RecordingLimits, EventCountIsCappedAndReadingStopsWithAReason)
{
    Recording rec;
    rec.events.resize(kMaxRecordingEvents + 5);
    for (std::size_t i = 0; i < rec.events.size(); ++i) rec.events[i].time = static_cast<double>(i) * 1e-3;
    ReadReport report;
    const Recording back = parse_recording(encode_recording_binary(rec), "many.lrec", &report);
    EXPECT_EQ(back.events.size(), kMaxRecordingEvents);
    EXPECT_TRUE(has_problem(report, "event limit reached (1000000 events), stopped reading")) << problems(report);
}

TEST(RecordingLimits, FilesOverTheSizeLimitAreRefusedBeforeReading)
{
    const std::string path = test::temp_dir("rec-huge") + "/huge.lrec";
    spit(path, encode_recording_binary(sample_recording(2)));
    std::filesystem::resize_file(path, std::uintmax_t{3} << 30); // sparse: costs no disk
    const std::string m = file_error(path, [&] { read_recording(path); });
    EXPECT_NE(m.find("file too large"), std::string::npos) << m;
    std::filesystem::remove(path);
}

TEST(RecordingLimits, TheProblemListStaysBounded)
{
    std::string text = "lobesketch-recording-text 1\nheader {}\nframe 0 head - left - right -\n";
    for (int i = 0; i < 5000; ++i) text += "frame " + std::to_string(i + 1) + " head - left 1 2 3 right -\n";
    ReadReport report;
    parse_recording(text, "many-bad.txt", &report);
    EXPECT_EQ(report.frames_dropped, 5000u);
    EXPECT_LE(report.problems.size(), 25u);
    EXPECT_TRUE(has_problem(report, "... and 4980 more problems")) << problems(report);
}

TEST(RecordingGarbage, RandomGarbageIsRejectedQuicklyWithABoundedReport)
{
    std::mt19937 rng(1234);
    std::string garbage(4 << 20, '\0');
    for (char& c : garbage) c = static_cast<char>(rng());
    const std::string dir = test::temp_dir("rec-garbage");
    spit(dir + "/noise.lrec", garbage);
    std::string m = file_error(dir + "/noise.lrec", [&] { read_recording(dir + "/noise.lrec"); });
    EXPECT_NE(m.find("wrong magic"), std::string::npos) << m;

    // The same noise behind a valid binary header, and behind a valid text header.
    Recording empty;
    ReadReport report;
    const std::string binary = encode_recording_binary(empty) + garbage;
    m = file_error("noise.lrec", [&] { parse_recording(binary, "noise.lrec", &report); });
    EXPECT_NE(m.find("no usable frames"), std::string::npos) << m;
    EXPECT_LE(report.problems.size(), 25u);

    std::string text = encode_recording_text(empty) + garbage;
    m = file_error("noise.txt", [&] { parse_recording(text, "noise.txt", &report); });
    EXPECT_NE(m.find("no usable frames"), std::string::npos) << m;
    EXPECT_LE(report.problems.size(), 25u);
    for (const std::string& p : report.problems) EXPECT_EQ(p.find('\n'), std::string::npos);
}

TEST(RecordingGarbage, RandomDamageToEitherFormNeverThrowsAnythingButAOneLineFileError)
{
    const Recording rec = sample_recording(12);
    const std::string forms[2] = {encode_recording_binary(rec), encode_recording_text(rec)};
    std::mt19937 rng(99);
    for (int round = 0; round < 400; ++round) {
        std::string bytes = forms[round % 2];
        const int flips = 1 + static_cast<int>(rng() % 40);
        for (int i = 0; i < flips; ++i) bytes[rng() % bytes.size()] = static_cast<char>(rng());
        if (rng() % 3 == 0) bytes.resize(rng() % bytes.size());
        try {
            ReadReport report;
            const Recording back = parse_recording(bytes, "damaged", &report);
            EXPECT_LE(back.frames.size(), rec.frames.size());
            EXPECT_LE(report.problems.size(), 26u);
        } catch (const FileError& e) {
            EXPECT_EQ(std::string(e.what()).find('\n'), std::string::npos) << e.what();
            EXPECT_EQ(std::string(e.what()).rfind("damaged: ", 0), 0u) << e.what();
        }
    }
}

// ------------------------------------------------------------------------------------------
// Streaming writer
// ------------------------------------------------------------------------------------------

TEST(RecordingWriter, FlushesSoASecondReaderSeesFramesWhileTheWriterIsOpen)
{
    const std::string path = test::temp_dir("rec-writer") + "/live.lrec";
    const Recording rec = sample_recording(6);
    RecordingWriter writer(path, rec.header, 1);
    EXPECT_EQ(writer.path(), path);
    EXPECT_NE(file_error(path, [&] { read_recording(path); }).find("no usable frames"), std::string::npos);
    for (std::size_t i = 0; i < 3; ++i) {
        writer.append(rec.frames[i]);
        const Recording seen = read_recording(path);
        EXPECT_EQ(seen.frames.size(), i + 1);
        EXPECT_EQ(seen.header.source, rec.header.source);
    }
    writer.append(rec.events[0]);
    writer.append(rec.annotations[0]);
    const Recording seen = read_recording(path);
    EXPECT_EQ(seen.events.size(), 1u);
    EXPECT_EQ(seen.annotations.size(), 1u);
    writer.close();
    writer.close(); // closing twice is harmless
    EXPECT_THROW(writer.append(rec.frames[3]), FileError);
}

TEST(RecordingWriter, FlushEveryNFramesBatchesAndEventsFlushAtOnce)
{
    const std::string path = test::temp_dir("rec-writer-batch") + "/live.lrec";
    const Recording rec = sample_recording(8);
    RecordingWriter writer(path, rec.header, 4);
    for (std::size_t i = 0; i < 3; ++i) writer.append(rec.frames[i]);
    EXPECT_NE(file_error(path, [&] { read_recording(path); }).find("no usable frames"), std::string::npos);
    writer.append(rec.frames[3]);
    EXPECT_EQ(read_recording(path).frames.size(), 4u);
    writer.append(rec.frames[4]);
    writer.append(rec.events[0]); // flushes the pending frame too
    const Recording seen = read_recording(path);
    EXPECT_EQ(seen.frames.size(), 5u);
    EXPECT_EQ(seen.events.size(), 1u);
}

TEST(RecordingWriter, StreamedFileHasTheSameBytesAsTheWholeFileEncoder)
{
    const std::string path = test::temp_dir("rec-writer-same") + "/live.lrec";
    Recording rec = sample_recording(5);
    rec.events.clear();
    rec.annotations = {{1.0, "end"}};
    {
        RecordingWriter writer(path, rec.header, 2);
        for (const HandFrame& f : rec.frames) writer.append(f);
        writer.append(rec.annotations[0]);
    } // the destructor closes
    EXPECT_EQ(slurp(path), encode_recording_binary(rec));
}

TEST(RecordingWriter, UnwritablePathIsAOneLineFileError)
{
    const std::string path = test::temp_dir("rec-writer-bad") + "/no/such/dir/live.lrec";
    std::string m = file_error(path, [&] { RecordingWriter w(path, RecordingHeader{}); });
    EXPECT_NE(m.find("cannot create"), std::string::npos) << m;
}

TEST(RecordingEvents, SceneEventsRoundTripInBothFormsAndOutOfRangeOnesAreDroppedWithAWarning)
{
    Recording rec = sample_recording();
    rec.events.push_back({1.0, InputEventKind::Scene, int(SceneComponent::Scale), 0, 0.5f, 0.0f});
    rec.events.push_back({1.0, InputEventKind::Scene, int(SceneComponent::Yaw), 0, -0.25f, 0.0f});
    rec.events.push_back({1.0, InputEventKind::Scene, int(SceneComponent::TranslationZ), 0, -1.5f, 0.0f});
    const Recording from_binary = parse_recording(encode_recording_binary(rec), "a.lrec");
    const std::string text = encode_recording_text(from_binary);
    EXPECT_NE(text.find("event 1 scene 0 0.5\n"), std::string::npos) << text;
    const Recording from_text = parse_recording(text, "a.txt");
    EXPECT_EQ(encode_recording_binary(from_text), encode_recording_binary(from_binary));
    int scene = 0;
    for (const InputEvent& e : from_text.events) scene += e.kind == InputEventKind::Scene;
    EXPECT_EQ(scene, 3);

    for (const auto& [component, value] : std::vector<std::pair<int, float>>{
             {0, 0.0f}, {0, 1000.0f}, {1, 20.0f}, {2, 1e6f}, {5, 1.0f}, {0, std::nanf("")}}) {
        Recording bad = sample_recording();
        bad.events.push_back({1.0, InputEventKind::Scene, component, 0, value, 0.0f});
        for (const std::string& bytes : {encode_recording_binary(bad), encode_recording_text(bad)}) {
            ReadReport report;
            const Recording back = parse_recording(bytes, "bad.lrec", &report);
            for (const InputEvent& e : back.events) EXPECT_NE(e.kind, InputEventKind::Scene) << component << " " << value;
            ASSERT_FALSE(report.problems.empty());
            EXPECT_EQ(report.problems.front().find('\n'), std::string::npos);
        }
    }
}
