#pragma once
/// \file recording_format.h
/// What the recording readers and writers of input/ share (not included outside input/):
/// the constants that define both forms on disk, the CRC, the header JSON and the Collector
/// that validates what either reader decodes and keeps the bounded problem list. Byte-by-byte
/// and line-by-line description of both forms, and the limits: docs/recording-format.md.
///
/// recording.cpp detects the form and dispatches; recording_binary.cpp and recording_text.cpp
/// read one form each; recording_writer.cpp writes both and holds RecordingWriter.

#include <algorithm>
#include <array>
#include <charconv>
#include <cmath>
#include <cstdint>
#include <limits>
#include <string>
#include <string_view>

#include <glm/gtc/quaternion.hpp>
#include <glm/vec3.hpp>

#include "core/hand_frame.h"
#include "input/recording.h"

namespace lobe::recording_format {

// ---------------------------------------------------------------------------------------
// Format constants
// ---------------------------------------------------------------------------------------

inline constexpr std::array<unsigned char, 8> kMagic = {'L', 'O', 'B', 'E', 'R', 'E', 'C', 0x1A};
inline constexpr std::uint16_t kMinorVersion = 0;
inline constexpr std::size_t kFileHeaderBytes = 16; // magic 8, major u16, minor u16, header length u32
inline constexpr std::uint32_t kSyncMarker = 0x1E524CFEu; // bytes FE 4C 52 1E on disk
inline constexpr unsigned char kSyncFirstByte = 0xFE;
inline constexpr std::size_t kRecordPrefixBytes = 9;  // sync 4, type 1, length 4
inline constexpr std::size_t kRecordOverhead = 13;    // prefix + CRC 4
inline constexpr std::size_t kMaxPayloadBytes = 65536;
inline constexpr std::size_t kMaxHeaderBytes = 65536;
inline constexpr std::size_t kMaxHeaderNesting = 16;
inline constexpr std::size_t kMaxAnnotationBytes = 1000;
inline constexpr std::size_t kMaxFileBytes = std::size_t{2} << 30;
inline constexpr std::size_t kMaxLineBytes = 131072;
inline constexpr std::size_t kMaxProblems = 20;
inline constexpr double kAbsurdMetres = 1000.0;

inline constexpr std::string_view kTextMagic = "lobesketch-recording-text";
inline constexpr std::string_view kUtf8Bom = "\xEF\xBB\xBF";

enum class RecordType : std::uint8_t { Frame = 1, Event = 2, Annotation = 3 };

inline constexpr std::size_t kJointBytes = 12 + 8 + 2 + 1; // position, quaternion, radius, flags
inline constexpr std::size_t kHeadBytes = 28;              // position + float quaternion
inline constexpr std::size_t kMaxFramePayload =
    8 + 1 + kHeadBytes + kHandCount * (1 + kJointCount * kJointBytes);
inline constexpr std::size_t kEventPayload = 8 + 1 + 4 + 4 + 4 + 4;
inline constexpr std::size_t kMaxAnnotationPayload = 8 + 2 + kMaxAnnotationBytes;
inline constexpr std::size_t kMaxRecordBytes =
    kRecordOverhead + std::max({kMaxFramePayload, kEventPayload, kMaxAnnotationPayload});

// Quantisation: orientation components × 32767 as int16, radius in 0.01 mm as u16. Values
// that cannot be represented (NaN/Inf) get a sentinel so the reader drops the frame exactly
// as it would drop the float.
inline constexpr double kQuatScale = 32767.0;
inline constexpr std::int16_t kNonFiniteQuat = -32768;
inline constexpr double kRadiusPerUnit = 1e-5;
inline constexpr std::uint16_t kNonFiniteRadius = 0xFFFF;
inline constexpr double kMaxRadiusUnits = 65534.0;

inline constexpr int kTextHeadNumbers = 7;
inline constexpr int kTextJointNumbers = 9;
inline constexpr int kTextHandNumbers = kJointCount * kTextJointNumbers; // 234

/// Hand names in both forms and in messages, indexed by Hand.
inline constexpr const char* kHandNames[kHandCount] = {"left", "right"};

// ---------------------------------------------------------------------------------------
// Checksums, numbers and text
// ---------------------------------------------------------------------------------------

/// CRC-32 (IEEE 802.3, reflected polynomial 0xEDB88320) of `size` bytes.
std::uint32_t crc32(const unsigned char* data, std::size_t size);

inline bool finite(const glm::vec3& v) { return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z); }
inline bool finite(const glm::quat& q)
{
    return std::isfinite(q.w) && std::isfinite(q.x) && std::isfinite(q.y) && std::isfinite(q.z);
}
/// |q|², summed in double.
inline double norm2(const glm::quat& q)
{
    return double(q.w) * q.w + double(q.x) * q.x + double(q.y) * q.y + double(q.z) * q.z;
}

/// Appends the shortest decimal text that reads back to `v` (std::to_chars).
template <typename T>
void append_number(std::string& out, T v)
{
    char buf[40];
    auto r = std::to_chars(buf, buf + sizeof buf, v);
    out.append(buf, r.ptr);
}

template <typename T>
std::string number_text(T v)
{
    std::string s;
    append_number(s, v);
    return s;
}

/// A token from a file, made safe to quote in a one-line message.
std::string quote_token(std::string_view t);

/// Control characters and DEL become '?'.
void make_one_line(std::string& s);

/// Cuts a string to at most max bytes without splitting a UTF-8 sequence.
std::string_view clip_utf8(std::string_view s, std::size_t max);

/// Space, tab, CR, VT or FF (not the newline, which ends a line of the text form).
inline bool is_space(char c) { return c == ' ' || c == '\t' || c == '\r' || c == '\v' || c == '\f'; }

inline bool starts_with(std::string_view s, std::string_view prefix) { return s.substr(0, prefix.size()) == prefix; }

// ---------------------------------------------------------------------------------------
// Collector: validation and bounded report shared by both readers
// ---------------------------------------------------------------------------------------

/// Where a record came from, formatted only when a message needs it.
struct Where {
    bool text = false;
    std::size_t n = 0; ///< line number (text) or byte offset of the record (binary)
    std::string str() const { return (text ? "line " : "record at byte ") + std::to_string(n); }
};

/// Collects what a reader decodes into `rec`: drops frames with NaN/Inf, absurd coordinates
/// (beyond kAbsurdMetres) or time not increasing, and events with time going backwards;
/// repairs all-zero and far-from-unit quaternions; stops at the frame, event and annotation
/// limits of recording.h. Every drop, repair and stop becomes one line in the report (at
/// most kMaxProblems, duplicates once, then a count).
class Collector {
public:
    Collector(const std::string& name, ReadReport& report) : name_(name), report_(report) {}

    Recording rec;

    const std::string& name() const { return name_; }
    /// A limit was reached: the reader reads no further.
    bool stopped() const { return stopped_; }

    void problem(std::string msg);
    void drop_frame(Where w, const std::string& why);
    void drop_event(Where w, const std::string& why);
    /// The number of the next frame record in the file (dropped ones included), for messages.
    std::size_t next_frame_number() { return frame_number_++; }

    /// Validates, repairs the known device quirks, and keeps or drops one frame.
    void add_frame(HandFrame& f, Where w, std::size_t number);
    void add_event(const InputEvent& e, Where w);
    void skip_unknown_event(Where w, const std::string& kind);
    void skip_unknown_setting(Where w, std::int32_t id);
    /// Keeps an annotation, its text clipped to kMaxAnnotationBytes.
    void add_annotation(Annotation a, Where w);

    /// Adds the summaries, fills the report, and refuses a file with nothing usable.
    /// \throw FileError naming the file when no frame and no event was kept.
    Recording finish();

private:
    void stop(Where w, const std::string& why);
    static bool position_ok(const glm::vec3& p);
    static std::string position_problem(const glm::vec3& p, const std::string& what);
    /// Why the frame must be dropped, or empty. Checks everything before repairing anything.
    static std::string unusable(const HandFrame& f);
    /// All-zero quaternions (a device quirk) become identity; far-from-unit ones are normalised.
    /// Returns false for an all-zero quaternion.
    bool repair_quat(glm::quat& q, std::size_t number);
    void repair(HandFrame& f, std::size_t number);

    std::string name_;
    ReadReport& report_;
    bool stopped_ = false;
    std::size_t more_problems_ = 0;
    std::size_t frame_number_ = 0;
    std::size_t event_number_ = 0;
    double last_frame_time_ = -std::numeric_limits<double>::infinity();
    double last_event_time_ = -std::numeric_limits<double>::infinity();
    std::array<bool, kHandCount> hand_seen_{};
    std::size_t zero_joint_quats_ = 0, first_zero_joint_ = 0;
    std::size_t zero_head_quats_ = 0, first_zero_head_ = 0;
    std::size_t normalised_quats_ = 0, first_normalised_ = 0;
};

/// Reads the header JSON of either form into h; problems are reported, never fatal, except
/// units other than metres (every coordinate would be wrong).
/// \throw FileError when the units are not "m".
void read_header_json(std::string_view text, RecordingHeader& h, Collector& c, const std::string& where);

// ---------------------------------------------------------------------------------------
// The two readers
// ---------------------------------------------------------------------------------------

/// The binary form. \pre `data` starts with kMagic.
/// \throw FileError for a truncated file header, an unsupported version, a header that cannot
///        be skipped, or when nothing usable remains.
Recording parse_binary(std::string_view data, const std::string& name, ReadReport& report);

/// The text form. \pre `data` (after an optional UTF-8 BOM) starts with kTextMagic.
/// \throw FileError for a bad version line, an unsupported version, or when nothing usable
///        remains.
Recording parse_text(std::string_view data, const std::string& name, ReadReport& report);

} // namespace lobe::recording_format
