#include "input/recording.h"

#include <algorithm>
#include <array>
#include <bit>
#include <cerrno>
#include <charconv>
#include <cmath>
#include <cstring>
#include <limits>
#include <string_view>
#include <utility>

#include <unistd.h>

#include <nlohmann/json.hpp>

#include "core/atomic_file.h"
#include "core/errors.h"

// Byte-by-byte and line-by-line description of both forms: docs/recording-format.md.

namespace lobe {

namespace {

using nlohmann::json;

// ---------------------------------------------------------------------------------------
// Format constants
// ---------------------------------------------------------------------------------------

constexpr std::array<unsigned char, 8> kMagic = {'L', 'O', 'B', 'E', 'R', 'E', 'C', 0x1A};
constexpr std::uint16_t kMinorVersion = 0;
constexpr std::size_t kFileHeaderBytes = 16; // magic 8, major u16, minor u16, header length u32
constexpr std::uint32_t kSyncMarker = 0x1E524CFEu; // bytes FE 4C 52 1E on disk
constexpr unsigned char kSyncFirstByte = 0xFE;
constexpr std::size_t kRecordPrefixBytes = 9;  // sync 4, type 1, length 4
constexpr std::size_t kRecordOverhead = 13;    // prefix + CRC 4
constexpr std::size_t kMaxPayloadBytes = 65536;
constexpr std::size_t kMaxHeaderBytes = 65536;
constexpr std::size_t kMaxHeaderNesting = 16;
constexpr std::size_t kMaxAnnotationBytes = 1000;
constexpr std::size_t kMaxFileBytes = std::size_t{2} << 30;
constexpr std::size_t kMaxLineBytes = 131072;
constexpr std::size_t kMaxProblems = 20;
constexpr double kAbsurdMetres = 1000.0;

constexpr std::string_view kTextMagic = "lobesketch-recording-text";
constexpr std::string_view kUtf8Bom = "\xEF\xBB\xBF";

enum class RecordType : std::uint8_t { Frame = 1, Event = 2, Annotation = 3 };

constexpr std::size_t kJointBytes = 12 + 8 + 2 + 1; // position, quaternion, radius, flags
constexpr std::size_t kHeadBytes = 28;              // position + float quaternion
constexpr std::size_t kMaxFramePayload = 8 + 1 + kHeadBytes + kHandCount * (1 + kJointCount * kJointBytes);
constexpr std::size_t kEventPayload = 8 + 1 + 4 + 4 + 4 + 4;
constexpr std::size_t kMaxAnnotationPayload = 8 + 2 + kMaxAnnotationBytes;
constexpr std::size_t kMaxRecordBytes =
    kRecordOverhead + std::max({kMaxFramePayload, kEventPayload, kMaxAnnotationPayload});

// Quantisation: orientation components × 32767 as int16, radius in 0.01 mm as u16. Values
// that cannot be represented (NaN/Inf) get a sentinel so the reader drops the frame exactly
// as it would drop the float.
constexpr double kQuatScale = 32767.0;
constexpr std::int16_t kNonFiniteQuat = -32768;
constexpr double kRadiusPerUnit = 1e-5;
constexpr std::uint16_t kNonFiniteRadius = 0xFFFF;
constexpr double kMaxRadiusUnits = 65534.0;

constexpr int kTextHeadNumbers = 7;
constexpr int kTextJointNumbers = 9;
constexpr int kTextHandNumbers = kJointCount * kTextJointNumbers; // 234

// ---------------------------------------------------------------------------------------
// CRC-32 (IEEE 802.3, reflected polynomial 0xEDB88320), table driven
// ---------------------------------------------------------------------------------------

constexpr std::array<std::uint32_t, 256> make_crc_table()
{
    std::array<std::uint32_t, 256> table{};
    for (std::uint32_t i = 0; i < 256; ++i) {
        std::uint32_t c = i;
        for (int k = 0; k < 8; ++k) c = (c & 1u) ? (0xEDB88320u ^ (c >> 1)) : (c >> 1);
        table[i] = c;
    }
    return table;
}
constexpr std::array<std::uint32_t, 256> kCrcTable = make_crc_table();

std::uint32_t crc32(const unsigned char* data, std::size_t size)
{
    std::uint32_t crc = 0xFFFFFFFFu;
    for (std::size_t i = 0; i < size; ++i) crc = kCrcTable[(crc ^ data[i]) & 0xFFu] ^ (crc >> 8);
    return ~crc;
}

// ---------------------------------------------------------------------------------------
// Little-endian packing
// ---------------------------------------------------------------------------------------

/// Writes little-endian values into a caller-sized buffer.
class ByteWriter {
public:
    explicit ByteWriter(unsigned char* p) : begin_(p), p_(p) {}
    void u8(std::uint8_t v) { *p_++ = v; }
    void u16(std::uint16_t v)
    {
        u8(static_cast<std::uint8_t>(v));
        u8(static_cast<std::uint8_t>(v >> 8));
    }
    void u32(std::uint32_t v)
    {
        for (int i = 0; i < 4; ++i) u8(static_cast<std::uint8_t>(v >> (8 * i)));
    }
    void u64(std::uint64_t v)
    {
        for (int i = 0; i < 8; ++i) u8(static_cast<std::uint8_t>(v >> (8 * i)));
    }
    void i16(std::int16_t v) { u16(static_cast<std::uint16_t>(v)); }
    void i32(std::int32_t v) { u32(static_cast<std::uint32_t>(v)); }
    void f32(float v) { u32(std::bit_cast<std::uint32_t>(v)); }
    void f64(double v) { u64(std::bit_cast<std::uint64_t>(v)); }
    void vec3(const glm::vec3& v)
    {
        f32(v.x);
        f32(v.y);
        f32(v.z);
    }
    void bytes(const void* data, std::size_t size)
    {
        if (size == 0) return;
        std::memcpy(p_, data, size);
        p_ += size;
    }
    std::size_t size() const { return static_cast<std::size_t>(p_ - begin_); }

private:
    unsigned char* begin_;
    unsigned char* p_;
};

std::uint16_t get_u16(const unsigned char* p)
{
    return static_cast<std::uint16_t>(p[0] | (p[1] << 8));
}
std::uint32_t get_u32(const unsigned char* p)
{
    return std::uint32_t{p[0]} | (std::uint32_t{p[1]} << 8) | (std::uint32_t{p[2]} << 16) |
           (std::uint32_t{p[3]} << 24);
}
std::uint64_t get_u64(const unsigned char* p)
{
    return std::uint64_t{get_u32(p)} | (std::uint64_t{get_u32(p + 4)} << 32);
}

/// Reads little-endian values from a payload; the caller checks has() before each group.
class ByteReader {
public:
    ByteReader(const unsigned char* p, std::size_t size) : p_(p), left_(size) {}
    bool has(std::size_t n) const { return left_ >= n; }
    std::size_t left() const { return left_; }
    std::uint8_t u8()
    {
        std::uint8_t v = *p_;
        skip(1);
        return v;
    }
    std::uint16_t u16()
    {
        std::uint16_t v = get_u16(p_);
        skip(2);
        return v;
    }
    std::uint32_t u32()
    {
        std::uint32_t v = get_u32(p_);
        skip(4);
        return v;
    }
    std::int16_t i16() { return static_cast<std::int16_t>(u16()); }
    std::int32_t i32() { return static_cast<std::int32_t>(u32()); }
    float f32() { return std::bit_cast<float>(u32()); }
    double f64()
    {
        double v = std::bit_cast<double>(get_u64(p_));
        skip(8);
        return v;
    }
    glm::vec3 vec3()
    {
        float x = f32();
        float y = f32();
        float z = f32();
        return {x, y, z};
    }
    const unsigned char* data() const { return p_; }
    void skip(std::size_t n)
    {
        p_ += n;
        left_ -= n;
    }

private:
    const unsigned char* p_;
    std::size_t left_;
};

// ---------------------------------------------------------------------------------------
// Quantisation
// ---------------------------------------------------------------------------------------

bool finite(const glm::vec3& v) { return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z); }
bool finite(const glm::quat& q)
{
    return std::isfinite(q.w) && std::isfinite(q.x) && std::isfinite(q.y) && std::isfinite(q.z);
}
double norm2(const glm::quat& q)
{
    return double(q.w) * q.w + double(q.x) * q.x + double(q.y) * q.y + double(q.z) * q.z;
}

// A quaternion already unit length within 1e-4 (in |q|²) is quantised as is: a decoded
// quaternion is within 6.2e-5 of unit length, so decode → encode returns the same integers.
std::array<std::int16_t, 4> quantise_quat(const glm::quat& q)
{
    if (!finite(q)) return {kNonFiniteQuat, kNonFiniteQuat, kNonFiniteQuat, kNonFiniteQuat};
    double n2 = norm2(q);
    if (n2 < 1e-12) return {0, 0, 0, 0}; // the all-zero device quirk, kept for the reader
    double s = std::abs(n2 - 1.0) > 1e-4 ? 1.0 / std::sqrt(n2) : 1.0;
    auto one = [s](float c) {
        double v = std::clamp(std::round(double(c) * s * kQuatScale), -kQuatScale, kQuatScale);
        return static_cast<std::int16_t>(v);
    };
    return {one(q.w), one(q.x), one(q.y), one(q.z)};
}

glm::quat dequantise_quat(const std::array<std::int16_t, 4>& c)
{
    for (std::int16_t v : c)
        if (v == kNonFiniteQuat) {
            float nan = std::numeric_limits<float>::quiet_NaN();
            return glm::quat(nan, nan, nan, nan);
        }
    auto one = [](std::int16_t v) { return static_cast<float>(v) / 32767.0f; };
    return glm::quat(one(c[0]), one(c[1]), one(c[2]), one(c[3]));
}

std::uint16_t quantise_radius(float r)
{
    if (!std::isfinite(r)) return kNonFiniteRadius;
    return static_cast<std::uint16_t>(std::clamp(std::round(double(r) / kRadiusPerUnit), 0.0, kMaxRadiusUnits));
}

float dequantise_radius(std::uint16_t u)
{
    if (u == kNonFiniteRadius) return std::numeric_limits<float>::quiet_NaN();
    return static_cast<float>(double(u) * kRadiusPerUnit);
}

// ---------------------------------------------------------------------------------------
// Small text helpers
// ---------------------------------------------------------------------------------------

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

template <typename T>
bool parse_number(std::string_view t, T& v)
{
    if (t.empty()) return false;
    auto r = std::from_chars(t.data(), t.data() + t.size(), v);
    return r.ec == std::errc() && r.ptr == t.data() + t.size();
}

/// A token from a file, made safe to quote in a one-line message.
std::string quote_token(std::string_view t)
{
    constexpr std::size_t kMax = 32;
    std::string s = "'";
    for (std::size_t i = 0; i < t.size() && i < kMax; ++i) {
        auto c = static_cast<unsigned char>(t[i]);
        s += (c < 0x20 || c == 0x7F) ? '?' : static_cast<char>(c);
    }
    if (t.size() > kMax) s += "...";
    return s + "'";
}

void make_one_line(std::string& s)
{
    for (char& c : s) {
        auto u = static_cast<unsigned char>(c);
        if (u < 0x20 || u == 0x7F) c = '?';
    }
}

/// Cuts a string to at most max bytes without splitting a UTF-8 sequence.
std::string_view clip_utf8(std::string_view s, std::size_t max)
{
    if (s.size() <= max) return s;
    std::size_t n = max;
    while (n > 0 && (static_cast<unsigned char>(s[n]) & 0xC0u) == 0x80u) --n;
    return s.substr(0, n);
}

bool is_space(char c) { return c == ' ' || c == '\t' || c == '\r' || c == '\v' || c == '\f'; }

/// Whitespace-separated tokens of one line, without allocating.
class Tokens {
public:
    explicit Tokens(std::string_view s) : s_(s) {}
    std::string_view next()
    {
        while (pos_ < s_.size() && is_space(s_[pos_])) ++pos_;
        std::size_t b = pos_;
        while (pos_ < s_.size() && !is_space(s_[pos_])) ++pos_;
        return s_.substr(b, pos_ - b);
    }
    std::string_view peek() const
    {
        Tokens copy = *this;
        return copy.next();
    }
    /// The rest of the line after one separator character (free text).
    std::string_view rest() const { return pos_ < s_.size() ? s_.substr(pos_ + 1) : std::string_view(); }

private:
    std::string_view s_;
    std::size_t pos_ = 0;
};

// ---------------------------------------------------------------------------------------
// Header JSON
// ---------------------------------------------------------------------------------------

std::string header_json(const RecordingHeader& h)
{
    json j = {{"source", h.source},   {"device", h.device},
              {"units", h.units},     {"space", h.space},
              {"nominal_rate_hz", h.nominal_rate_hz}, {"created", h.created}};
    // Keys sorted, one line: the same header always gives the same bytes. Invalid UTF-8 from
    // a runtime's device name becomes U+FFFD instead of an exception.
    return j.dump(-1, ' ', false, json::error_handler_t::replace);
}

/// Deepest [ / { nesting outside strings; refuses absurd nesting before parsing.
std::size_t json_nesting(std::string_view s)
{
    std::size_t depth = 0, deepest = 0;
    bool in_string = false, escaped = false;
    for (char c : s) {
        if (in_string) {
            if (escaped) escaped = false;
            else if (c == '\\') escaped = true;
            else if (c == '"') in_string = false;
        } else if (c == '"') {
            in_string = true;
        } else if (c == '[' || c == '{') {
            deepest = std::max(deepest, ++depth);
        } else if ((c == ']' || c == '}') && depth > 0) {
            --depth;
        }
    }
    return deepest;
}


bool known_event_kind(std::uint8_t k) { return k >= 1 && k <= 7; }

// ---------------------------------------------------------------------------------------
// Collector: validation and bounded report shared by both readers
// ---------------------------------------------------------------------------------------

/// Where a record came from, formatted only when a message needs it.
struct Where {
    bool text = false;
    std::size_t n = 0;
    std::string str() const { return (text ? "line " : "record at byte ") + std::to_string(n); }
};

constexpr const char* kHandNames[kHandCount] = {"left", "right"};

class Collector {
public:
    Collector(const std::string& name, ReadReport& report) : name_(name), report_(report) {}

    Recording rec;

    const std::string& name() const { return name_; }
    bool stopped() const { return stopped_; }

    void problem(std::string msg)
    {
        make_one_line(msg);
        auto& list = report_.problems;
        if (std::find(list.begin(), list.end(), msg) != list.end()) return;
        if (list.size() < kMaxProblems) list.push_back(std::move(msg));
        else ++more_problems_;
    }

    void drop_frame(Where w, const std::string& why)
    {
        ++report_.frames_dropped;
        problem(w.str() + ": " + why);
    }
    void drop_event(Where w, const std::string& why)
    {
        ++report_.events_dropped;
        problem(w.str() + ": " + why);
    }
    std::size_t next_frame_number() { return frame_number_++; }

    /// Validates, repairs the known device quirks, and keeps or drops one frame.
    void add_frame(HandFrame& f, Where w, std::size_t number)
    {
        if (rec.frames.size() >= kMaxRecordingFrames) {
            stop(w, "frame limit reached (" + std::to_string(kMaxRecordingFrames) + " frames), stopped reading");
            return;
        }
        std::string why = unusable(f);
        if (!why.empty()) {
            drop_frame(w, why + " in frame " + std::to_string(number));
            return;
        }
        if (!(f.time > last_frame_time_)) {
            drop_frame(w, "time going backwards at frame " + std::to_string(number) + " (t = " +
                              number_text(f.time) + " after " + number_text(last_frame_time_) + ")");
            return;
        }
        repair(f, number);
        last_frame_time_ = f.time;
        for (int h = 0; h < kHandCount; ++h) hand_seen_[h] = hand_seen_[h] || f.hands[h].active;
        rec.frames.push_back(f);
    }

    void add_event(const InputEvent& e, Where w)
    {
        std::size_t number = event_number_++;
        if (rec.events.size() >= kMaxRecordingEvents) {
            stop(w, "event limit reached (" + std::to_string(kMaxRecordingEvents) + " events), stopped reading");
            return;
        }
        if (!std::isfinite(e.time) || !std::isfinite(e.x) || !std::isfinite(e.y)) {
            drop_event(w, "NaN/Inf in event " + std::to_string(number));
            return;
        }
        if (e.time < last_event_time_) {
            drop_event(w, "time going backwards at event " + std::to_string(number) + " (t = " +
                              number_text(e.time) + " after " + number_text(last_event_time_) + ")");
            return;
        }
        last_event_time_ = e.time;
        rec.events.push_back(e);
    }

    void skip_unknown_event(Where w, const std::string& kind)
    {
        ++event_number_;
        drop_event(w, "unknown event kind " + kind + " skipped");
    }

    void skip_unknown_setting(Where w, std::int32_t id)
    {
        ++event_number_;
        drop_event(w, "unknown setting id " + std::to_string(id) + " skipped");
    }

    void add_annotation(Annotation a, Where w)
    {
        if (rec.annotations.size() >= kMaxRecordingAnnotations) {
            stop(w, "annotation limit reached (" + std::to_string(kMaxRecordingAnnotations) +
                        " annotations), stopped reading");
            return;
        }
        if (!std::isfinite(a.time)) {
            problem(w.str() + ": NaN/Inf annotation time, annotation dropped");
            return;
        }
        if (a.text.size() > kMaxAnnotationBytes) {
            a.text.resize(clip_utf8(a.text, kMaxAnnotationBytes).size());
            problem(w.str() + ": annotation longer than " + std::to_string(kMaxAnnotationBytes) +
                    " bytes, truncated");
        }
        rec.annotations.push_back(std::move(a));
    }

    /// Adds the summaries, fills the report, and refuses a file with nothing usable.
    Recording finish()
    {
        auto& list = report_.problems;
        if (more_problems_ > 0) list.push_back("... and " + std::to_string(more_problems_) + " more problems");
        if (zero_joint_quats_ > 0)
            list.push_back(std::to_string(zero_joint_quats_) +
                           " all-zero joint orientations set to identity and marked invalid (first in frame " +
                           std::to_string(first_zero_joint_) + ")");
        if (zero_head_quats_ > 0)
            list.push_back(std::to_string(zero_head_quats_) +
                           " all-zero head orientations set to identity (first in frame " +
                           std::to_string(first_zero_head_) + ")");
        if (normalised_quats_ > 0)
            list.push_back(std::to_string(normalised_quats_) +
                           " orientations were not unit length and were normalised (first in frame " +
                           std::to_string(first_normalised_) + ")");
        if (!rec.frames.empty())
            for (int h = 0; h < kHandCount; ++h)
                if (!hand_seen_[h]) list.push_back(std::string(kHandNames[h]) + " hand never tracked");
        report_.frames_read = rec.frames.size();

        if (rec.frames.empty() && rec.events.empty()) {
            std::string why;
            if (report_.frames_dropped == 0 && report_.events_dropped == 0 && list.empty())
                why = "the file holds no frame or event records";
            else
                why = std::to_string(report_.frames_dropped) + " frames and " +
                      std::to_string(report_.events_dropped) + " events dropped" +
                      (list.empty() ? std::string() : "; first problem: " + list.front());
            throw FileError(name_, "no usable frames (" + why + ")");
        }
        return std::move(rec);
    }

private:
    void stop(Where w, const std::string& why)
    {
        stopped_ = true;
        problem(w.str() + ": " + why);
    }

    static bool position_ok(const glm::vec3& p)
    {
        // NaN fails every comparison, so this also refuses NaN.
        auto ok = [](float v) { return double(std::abs(v)) <= kAbsurdMetres; };
        return ok(p.x) && ok(p.y) && ok(p.z);
    }

    static std::string position_problem(const glm::vec3& p, const std::string& what)
    {
        if (!finite(p)) return "NaN/Inf in " + what + " position";
        float m = std::max({std::abs(p.x), std::abs(p.y), std::abs(p.z)});
        return "absurd coordinate " + number_text(m) + " m (limit " + number_text(kAbsurdMetres) + " m) in " +
               what + " position";
    }

    /// Why the frame must be dropped, or empty. Checks everything before repairing anything.
    static std::string unusable(const HandFrame& f)
    {
        if (!std::isfinite(f.time)) return "NaN/Inf time";
        if (f.head_valid) {
            if (!position_ok(f.head.position)) return position_problem(f.head.position, "head");
            if (!finite(f.head.orientation)) return "NaN/Inf in head orientation";
        }
        for (int h = 0; h < kHandCount; ++h) {
            const HandState& hand = f.hands[h];
            if (!hand.active) continue;
            for (int j = 0; j < kJointCount; ++j) {
                const JointState& js = hand.joints[j];
                auto what = [&] { return std::string(kHandNames[h]) + " " + joint_name(static_cast<Joint>(j)); };
                if (!position_ok(js.pose.position)) return position_problem(js.pose.position, what());
                if (!finite(js.pose.orientation)) return "NaN/Inf in " + what() + " orientation";
                if (!std::isfinite(js.radius)) return "NaN/Inf in " + what() + " radius";
            }
        }
        return {};
    }

    /// All-zero quaternions (a device quirk) become identity; far-from-unit ones are normalised.
    /// Returns false for an all-zero quaternion.
    bool repair_quat(glm::quat& q, std::size_t number)
    {
        double n2 = norm2(q);
        if (n2 < 1e-12) {
            q = glm::quat(1.0f, 0.0f, 0.0f, 0.0f);
            return false;
        }
        if (n2 < 0.998001 || n2 > 1.002001) { // | |q| - 1 | > 1e-3
            float s = static_cast<float>(1.0 / std::sqrt(n2));
            q = glm::quat(q.w * s, q.x * s, q.y * s, q.z * s);
            if (normalised_quats_++ == 0) first_normalised_ = number;
        }
        return true;
    }

    void repair(HandFrame& f, std::size_t number)
    {
        if (f.head_valid && !repair_quat(f.head.orientation, number))
            if (zero_head_quats_++ == 0) first_zero_head_ = number;
        for (HandState& hand : f.hands) {
            if (!hand.active) continue;
            for (JointState& js : hand.joints) {
                if (repair_quat(js.pose.orientation, number)) continue;
                js.flags = static_cast<std::uint8_t>(js.flags & ~(kOrientationValid | kOrientationTracked));
                if (zero_joint_quats_++ == 0) first_zero_joint_ = number;
            }
        }
    }

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
void read_header_json(std::string_view text, RecordingHeader& h, Collector& c, const std::string& where)
{
    if (text.size() > kMaxHeaderBytes) {
        c.problem(where + ": header longer than " + std::to_string(kMaxHeaderBytes) + " bytes, using a default header");
        return;
    }
    if (json_nesting(text) > kMaxHeaderNesting) {
        c.problem(where + ": header nested too deeply, using a default header");
        return;
    }
    json j = json::parse(text.begin(), text.end(), nullptr, false);
    if (j.is_discarded() || !j.is_object()) {
        c.problem(where + ": header is not a JSON object, using a default header");
        return;
    }
    auto read_string = [&](const char* key, std::string& out) {
        auto it = j.find(key);
        if (it == j.end()) return;
        if (it->is_string()) out = it->get<std::string>();
        else c.problem(where + ": header field '" + key + "' is not a string, using '" + out + "'");
    };
    read_string("source", h.source);
    read_string("device", h.device);
    read_string("units", h.units);
    read_string("space", h.space);
    read_string("created", h.created);
    if (auto it = j.find("nominal_rate_hz"); it != j.end()) {
        double v = it->is_number() ? it->get<double>() : std::numeric_limits<double>::quiet_NaN();
        if (std::isfinite(v) && v > 0.0 && v <= 100000.0) h.nominal_rate_hz = v;
        else c.problem(where + ": header field 'nominal_rate_hz' is not a positive rate, using " +
                       number_text(h.nominal_rate_hz));
    }
    if (h.units != "m") {
        std::string units = quote_token(h.units);
        throw FileError(c.name(), where + ": units " + units + " are not supported (recordings are in metres, 'm')");
    }
}

// ---------------------------------------------------------------------------------------
// Binary form: encoding
// ---------------------------------------------------------------------------------------

template <typename WritePayload>
void append_record(std::string& out, RecordType type, WritePayload&& write_payload)
{
    std::array<unsigned char, kMaxRecordBytes> buf;
    ByteWriter w(buf.data());
    w.u32(kSyncMarker);
    w.u8(static_cast<std::uint8_t>(type));
    w.u32(0); // payload length, patched below
    write_payload(w);
    const std::size_t payload = w.size() - kRecordPrefixBytes;
    ByteWriter(buf.data() + 5).u32(static_cast<std::uint32_t>(payload));
    w.u32(crc32(buf.data() + 4, 5 + payload));
    out.append(reinterpret_cast<const char*>(buf.data()), w.size());
}

void append_frame_record(std::string& out, const HandFrame& f)
{
    append_record(out, RecordType::Frame, [&f](ByteWriter& w) {
        w.f64(f.time);
        w.u8(f.head_valid ? 1 : 0);
        if (f.head_valid) {
            w.vec3(f.head.position);
            w.f32(f.head.orientation.w);
            w.f32(f.head.orientation.x);
            w.f32(f.head.orientation.y);
            w.f32(f.head.orientation.z);
        }
        for (const HandState& hand : f.hands) {
            w.u8(hand.active ? 1 : 0);
            if (!hand.active) continue;
            for (const JointState& js : hand.joints) {
                w.vec3(js.pose.position);
                for (std::int16_t c : quantise_quat(js.pose.orientation)) w.i16(c);
                w.u16(quantise_radius(js.radius));
                w.u8(js.flags);
            }
        }
    });
}

void append_event_record(std::string& out, const InputEvent& e)
{
    append_record(out, RecordType::Event, [&e](ByteWriter& w) {
        w.f64(e.time);
        w.u8(static_cast<std::uint8_t>(e.kind));
        w.i32(e.code);
        w.i32(e.value);
        w.f32(e.x);
        w.f32(e.y);
    });
}

void append_annotation_record(std::string& out, const Annotation& a)
{
    std::string_view text = clip_utf8(a.text, kMaxAnnotationBytes);
    append_record(out, RecordType::Annotation, [&](ByteWriter& w) {
        w.f64(a.time);
        w.u16(static_cast<std::uint16_t>(text.size()));
        w.bytes(text.data(), text.size());
    });
}

std::string binary_file_header(const RecordingHeader& header)
{
    std::string js = header_json(header);
    if (js.size() > kMaxHeaderBytes)
        throw InvalidInput("recording header longer than " + std::to_string(kMaxHeaderBytes) + " bytes");
    std::string out(kFileHeaderBytes + js.size() + 4, '\0');
    auto* p = reinterpret_cast<unsigned char*>(out.data());
    ByteWriter w(p);
    w.bytes(kMagic.data(), kMagic.size());
    w.u16(static_cast<std::uint16_t>(kRecordingVersion));
    w.u16(kMinorVersion);
    w.u32(static_cast<std::uint32_t>(js.size()));
    w.bytes(js.data(), js.size());
    w.u32(crc32(reinterpret_cast<const unsigned char*>(js.data()), js.size()));
    return out;
}

/// Visits frames, events and annotations merged by time (ties: frame, event, annotation);
/// each kind keeps its own order, so decoding and re-encoding gives the same sequence.
template <typename OnFrame, typename OnEvent, typename OnAnnotation>
void visit_in_time_order(const Recording& rec, OnFrame&& on_frame, OnEvent&& on_event, OnAnnotation&& on_annotation)
{
    std::size_t f = 0, e = 0, a = 0;
    const auto& fr = rec.frames;
    const auto& ev = rec.events;
    const auto& an = rec.annotations;
    while (f < fr.size() || e < ev.size() || a < an.size()) {
        if (f < fr.size() && (e == ev.size() || !(ev[e].time < fr[f].time)) &&
            (a == an.size() || !(an[a].time < fr[f].time))) {
            on_frame(fr[f++]);
        } else if (e < ev.size() && (a == an.size() || !(an[a].time < ev[e].time))) {
            on_event(ev[e++]);
        } else {
            on_annotation(an[a++]);
        }
    }
}

// ---------------------------------------------------------------------------------------
// Binary form: decoding
// ---------------------------------------------------------------------------------------

constexpr std::size_t kNotFound = std::numeric_limits<std::size_t>::max();

std::size_t find_sync(const unsigned char* p, std::size_t n, std::size_t from)
{
    while (from + 4 <= n) {
        const void* hit = std::memchr(p + from, kSyncFirstByte, n - from - 3);
        if (!hit) return kNotFound;
        std::size_t at = static_cast<std::size_t>(static_cast<const unsigned char*>(hit) - p);
        if (get_u32(p + at) == kSyncMarker) return at;
        from = at + 1;
    }
    return kNotFound;
}

/// Frame records in the undamaged run of records from pos: the capacity to reserve, so the
/// frames are not copied on every growth of the vector.
std::size_t count_frame_records(const unsigned char* p, std::size_t n, std::size_t pos)
{
    std::size_t frames = 0;
    while (n - pos >= kRecordOverhead && get_u32(p + pos) == kSyncMarker && frames < kMaxRecordingFrames) {
        const std::size_t size = get_u32(p + pos + 5);
        if (size > kMaxPayloadBytes || n - pos - kRecordOverhead < size) break;
        if (p[pos + 4] == static_cast<unsigned char>(RecordType::Frame)) ++frames;
        pos += kRecordOverhead + size;
    }
    return frames;
}

/// A prefix of the sync marker at the very end of the data: a record cut before its type.
bool is_sync_prefix(const unsigned char* p, std::size_t n)
{
    const unsigned char sync[4] = {0xFE, 0x4C, 0x52, 0x1E};
    return n < 4 && std::memcmp(p, sync, n) == 0;
}

/// Decodes a frame payload; false when it is too short. Trailing bytes are fields of a
/// newer minor version and are ignored.
bool decode_frame(ByteReader r, HandFrame& f)
{
    if (!r.has(9)) return false;
    f.time = r.f64();
    f.head_valid = (r.u8() & 1u) != 0;
    if (f.head_valid) {
        if (!r.has(kHeadBytes)) return false;
        f.head.position = r.vec3();
        float w = r.f32();
        float x = r.f32();
        float y = r.f32();
        float z = r.f32();
        f.head.orientation = glm::quat(w, x, y, z);
    }
    for (HandState& hand : f.hands) {
        if (!r.has(1)) return false;
        hand.active = (r.u8() & 1u) != 0;
        if (!hand.active) continue;
        if (!r.has(kJointCount * kJointBytes)) return false;
        for (JointState& js : hand.joints) {
            js.pose.position = r.vec3();
            std::array<std::int16_t, 4> q{};
            for (std::int16_t& c : q) c = r.i16();
            js.pose.orientation = dequantise_quat(q);
            js.radius = dequantise_radius(r.u16());
            js.flags = r.u8();
        }
    }
    return true;
}

void decode_record(Collector& c, RecordType type, ByteReader r, Where w)
{
    switch (type) {
    case RecordType::Frame: {
        std::size_t number = c.next_frame_number();
        HandFrame f;
        if (!decode_frame(r, f)) {
            c.drop_frame(w, "frame payload too short (" + std::to_string(r.left()) + " bytes)");
            return;
        }
        c.add_frame(f, w, number);
        return;
    }
    case RecordType::Event: {
        if (!r.has(kEventPayload)) {
            c.drop_event(w, "event payload too short (" + std::to_string(r.left()) + " bytes)");
            return;
        }
        InputEvent e;
        e.time = r.f64();
        std::uint8_t kind = r.u8();
        e.code = r.i32();
        e.value = r.i32();
        e.x = r.f32();
        e.y = r.f32();
        if (!known_event_kind(kind)) {
            c.skip_unknown_event(w, std::to_string(kind));
            return;
        }
        e.kind = static_cast<InputEventKind>(kind);
        if (e.kind == InputEventKind::Setting && !known_setting_id(e.code)) {
            c.skip_unknown_setting(w, e.code);
            return;
        }
        if (e.kind == InputEventKind::Scene && !valid_scene_event(e.code, e.x)) {
            c.drop_event(w, "scene event out of range (component " + std::to_string(e.code) + ")");
            return;
        }
        c.add_event(e, w);
        return;
    }
    case RecordType::Annotation: {
        if (!r.has(10)) {
            c.problem(w.str() + ": annotation payload too short, annotation dropped");
            return;
        }
        Annotation a;
        a.time = r.f64();
        std::size_t size = r.u16();
        if (!r.has(size)) {
            c.problem(w.str() + ": annotation payload too short, annotation dropped");
            return;
        }
        a.text.assign(reinterpret_cast<const char*>(r.data()), size);
        c.add_annotation(std::move(a), w);
        return;
    }
    }
    c.problem(w.str() + ": unknown record type " + std::to_string(static_cast<int>(type)) + " skipped");
}

/// Counts a record that could not be decoded under the type its (untrusted) type byte names.
void drop_record(Collector& c, const unsigned char* p, std::size_t n, std::size_t pos, const std::string& why)
{
    const bool event = n - pos > 4 && p[pos + 4] == static_cast<unsigned char>(RecordType::Event);
    if (event) c.drop_event(Where{false, pos}, why);
    else c.drop_frame(Where{false, pos}, why);
}

Recording parse_binary(std::string_view data, const std::string& name, ReadReport& report)
{
    const auto* p = reinterpret_cast<const unsigned char*>(data.data());
    const std::size_t n = data.size();
    if (n < kFileHeaderBytes)
        throw FileError(name, "truncated file header (" + std::to_string(n) + " bytes)");
    const std::uint16_t major = get_u16(p + 8);
    if (major == 0 || major > kRecordingVersion)
        throw FileError(name, "unsupported recording version " + std::to_string(major) +
                                  " (this build reads versions 1 to " + std::to_string(kRecordingVersion) + ")");

    Collector c(name, report);
    c.rec.header.version = major;
    const std::size_t header_size = get_u32(p + 12);
    std::size_t pos = kFileHeaderBytes;
    if (header_size <= kMaxHeaderBytes && n - kFileHeaderBytes >= header_size + 4) {
        std::string_view js = data.substr(kFileHeaderBytes, header_size);
        if (crc32(p + kFileHeaderBytes, header_size) != get_u32(p + kFileHeaderBytes + header_size))
            c.problem("header: bad checksum, using a default header");
        else
            read_header_json(js, c.rec.header, c, "header");
        pos += header_size + 4;
    } else if (std::size_t first = find_sync(p, n, pos); first != kNotFound) {
        c.problem("header: bad length " + std::to_string(header_size) + ", using a default header");
        pos = first;
    } else {
        throw FileError(name, "truncated or corrupt header (header length " + std::to_string(header_size) +
                                  ", file " + std::to_string(n) + " bytes)");
    }

    if (pos <= n) c.rec.frames.reserve(count_frame_records(p, n, pos));
    while (pos < n && !c.stopped()) {
        if (n - pos < 4 || get_u32(p + pos) != kSyncMarker) {
            if (n - pos < 4 && is_sync_prefix(p + pos, n - pos)) {
                drop_record(c, p, n, pos, "truncated final record");
                break;
            }
            std::size_t next = find_sync(p, n, pos + 1);
            std::size_t skipped = (next == kNotFound ? n : next) - pos;
            c.drop_frame(Where{false, pos}, "no sync marker, skipped " + std::to_string(skipped) + " bytes");
            if (next == kNotFound) break;
            pos = next;
            continue;
        }
        if (n - pos < kRecordPrefixBytes) {
            drop_record(c, p, n, pos, "truncated final record");
            break;
        }
        const auto type = static_cast<RecordType>(p[pos + 4]);
        const std::size_t size = get_u32(p + pos + 5);
        if (size > kMaxPayloadBytes || n - pos < kRecordOverhead || n - pos - kRecordOverhead < size) {
            std::size_t next = find_sync(p, n, pos + 1);
            const bool fits = size <= kMaxPayloadBytes;
            if (next == kNotFound && fits) {
                drop_record(c, p, n, pos, "truncated final record");
                break;
            }
            drop_record(c, p, n, pos, "bad payload length " + std::to_string(size));
            if (next == kNotFound) break;
            pos = next;
            continue;
        }
        const std::size_t end = pos + kRecordOverhead + size;
        if (crc32(p + pos + 4, 5 + size) != get_u32(p + end - 4)) {
            drop_record(c, p, n, pos, "bad checksum");
            // Trust the length only when it lands on the next record; otherwise the length
            // itself may be what was damaged, so scan byte by byte.
            if (end == n || (n - end >= 4 && get_u32(p + end) == kSyncMarker)) {
                pos = end;
            } else {
                std::size_t next = find_sync(p, n, pos + 1);
                pos = next == kNotFound ? n : next;
            }
            continue;
        }
        decode_record(c, type, ByteReader(p + pos + kRecordPrefixBytes, size), Where{false, pos});
        pos = end;
    }
    return c.finish();
}

// ---------------------------------------------------------------------------------------
// Text form: encoding
// ---------------------------------------------------------------------------------------

void append_pose_text(std::string& out, const glm::vec3& p, const glm::quat& q)
{
    for (float v : {p.x, p.y, p.z, q.w, q.x, q.y, q.z}) {
        out += ' ';
        append_number(out, v);
    }
}

void append_frame_line(std::string& out, const HandFrame& f)
{
    out += "frame ";
    append_number(out, f.time);
    out += " head";
    if (f.head_valid) append_pose_text(out, f.head.position, f.head.orientation);
    else out += " -";
    for (int h = 0; h < kHandCount; ++h) {
        out += ' ';
        out += kHandNames[h];
        const HandState& hand = f.hands[h];
        if (!hand.active) {
            out += " -";
            continue;
        }
        for (const JointState& js : hand.joints) {
            append_pose_text(out, js.pose.position, js.pose.orientation);
            out += ' ';
            append_number(out, js.radius);
            out += ' ';
            append_number(out, static_cast<unsigned>(js.flags));
        }
    }
    out += '\n';
}

void append_event_line(std::string& out, const InputEvent& e)
{
    out += "event ";
    append_number(out, e.time);
    out += ' ';
    const char* kind = event_kind_name(e.kind);
    switch (e.kind) {
    case InputEventKind::Key:
    case InputEventKind::MouseButton:
        out += kind;
        out += ' ';
        append_number(out, e.code);
        out += ' ';
        append_number(out, e.value);
        break;
    case InputEventKind::MouseMove:
        out += kind;
        out += ' ';
        append_number(out, e.x);
        out += ' ';
        append_number(out, e.y);
        break;
    case InputEventKind::MouseWheel:
        out += kind;
        out += ' ';
        append_number(out, e.y);
        break;
    case InputEventKind::Setting:
        out += kind;
        out += ' ';
        append_number(out, e.code);
        out += ' ';
        append_number(out, e.value);
        out += ' ';
        append_number(out, e.x);
        break;
    case InputEventKind::ImportMesh:
        out += kind;
        out += ' ';
        append_number(out, e.code);
        break;
    case InputEventKind::Scene:
        out += kind;
        out += ' ';
        append_number(out, e.code);
        out += ' ';
        append_number(out, e.x);
        break;
    default: // a kind this build does not know: written so that readers skip it
        out += "kind_" + std::to_string(static_cast<int>(e.kind));
        break;
    }
    out += '\n';
}

/// Note text on one line: backslash, control characters and DEL are escaped.
void append_escaped(std::string& out, std::string_view s)
{
    static constexpr char kHex[] = "0123456789abcdef";
    for (char ch : s) {
        auto c = static_cast<unsigned char>(ch);
        if (ch == '\\') out += "\\\\";
        else if (ch == '\n') out += "\\n";
        else if (ch == '\r') out += "\\r";
        else if (ch == '\t') out += "\\t";
        else if (c < 0x20 || c == 0x7F) {
            out += "\\x";
            out += kHex[c >> 4];
            out += kHex[c & 0xF];
        } else out += ch;
    }
}

std::string unescape(std::string_view s)
{
    auto hex = [](char c) -> int {
        if (c >= '0' && c <= '9') return c - '0';
        if (c >= 'a' && c <= 'f') return c - 'a' + 10;
        if (c >= 'A' && c <= 'F') return c - 'A' + 10;
        return -1;
    };
    std::string out;
    out.reserve(s.size());
    for (std::size_t i = 0; i < s.size(); ++i) {
        if (s[i] != '\\' || i + 1 == s.size()) {
            out += s[i];
            continue;
        }
        char e = s[i + 1];
        if (e == '\\') out += '\\';
        else if (e == 'n') out += '\n';
        else if (e == 'r') out += '\r';
        else if (e == 't') out += '\t';
        else if (e == 'x' && i + 3 < s.size() && hex(s[i + 2]) >= 0 && hex(s[i + 3]) >= 0) {
            out += static_cast<char>(hex(s[i + 2]) * 16 + hex(s[i + 3]));
            i += 2;
        } else {
            out += '\\'; // unknown escape: kept as written
            continue;
        }
        ++i;
    }
    return out;
}

void append_note_line(std::string& out, const Annotation& a)
{
    out += "note ";
    append_number(out, a.time);
    if (!a.text.empty()) {
        out += ' ';
        append_escaped(out, clip_utf8(a.text, kMaxAnnotationBytes));
    }
    out += '\n';
}

// ---------------------------------------------------------------------------------------
// Text form: decoding
// ---------------------------------------------------------------------------------------

/// Parses `<n> numbers` into out; the error names what was being read.
template <typename T>
bool take_number(Tokens& t, T& out, const char* what, std::string& error)
{
    std::string_view tok = t.next();
    if (parse_number(tok, out)) return true;
    error = tok.empty() ? std::string("missing ") + what : "bad " + std::string(what) + " " + quote_token(tok);
    return false;
}

/// Reads "-" or the numbers of one hand (26 × px py pz qw qx qy qz radius flags).
std::string parse_hand(Tokens& t, HandState& hand, const char* name, std::string_view next_keyword)
{
    if (t.peek() == "-") {
        t.next();
        hand.active = false;
        return {};
    }
    hand.active = true;
    std::array<float, kTextJointNumbers - 1> v{};
    int count = 0;
    for (std::string_view tok = t.peek(); !tok.empty() && tok != next_keyword; tok = t.peek()) {
        t.next();
        if (count < kTextHandNumbers) {
            const int k = count % kTextJointNumbers;
            if (k == kTextJointNumbers - 1) {
                unsigned flags = 0;
                if (!parse_number(tok, flags) || flags > 0xFF)
                    return "bad flags " + quote_token(tok) + " for " + name + " " +
                           joint_name(static_cast<Joint>(count / kTextJointNumbers));
                JointState& js = hand.joints[count / kTextJointNumbers];
                js.pose.position = glm::vec3(v[0], v[1], v[2]);
                js.pose.orientation = glm::quat(v[3], v[4], v[5], v[6]);
                js.radius = v[7];
                js.flags = static_cast<std::uint8_t>(flags);
            } else if (!parse_number(tok, v[k])) {
                return "bad number " + quote_token(tok) + " in the " + name + " hand";
            }
        }
        ++count;
    }
    if (count != kTextHandNumbers)
        return "expected " + std::to_string(kTextHandNumbers) + " numbers for the " + name + " hand, found " +
               std::to_string(count);
    return {};
}

std::string parse_frame_line(Tokens& t, HandFrame& f)
{
    std::string error;
    if (!take_number(t, f.time, "time", error)) return error;
    if (t.next() != "head") return "expected 'head' after the time";
    if (t.peek() == "-") {
        t.next();
        f.head_valid = false;
    } else {
        std::array<float, kTextHeadNumbers> v{};
        for (int i = 0; i < kTextHeadNumbers; ++i) {
            std::string_view tok = t.peek();
            if (tok == "left" || tok.empty())
                return "expected " + std::to_string(kTextHeadNumbers) + " numbers for the head, found " +
                       std::to_string(i);
            t.next();
            if (!parse_number(tok, v[i])) return "bad number " + quote_token(tok) + " in the head";
        }
        f.head_valid = true;
        f.head.position = glm::vec3(v[0], v[1], v[2]);
        f.head.orientation = glm::quat(v[3], v[4], v[5], v[6]);
    }
    if (t.next() != "left") return "expected 'left' after the head";
    error = parse_hand(t, f.hands[0], "left", "right");
    if (!error.empty()) return error;
    if (t.next() != "right") return "expected 'right' after the left hand";
    error = parse_hand(t, f.hands[1], "right", {});
    if (!error.empty()) return error;
    if (!t.peek().empty()) return "unexpected " + quote_token(t.peek()) + " after the right hand";
    return {};
}

struct LineReader {
    std::string_view data;
    std::size_t pos = 0;
    std::size_t number = 0;
    bool last_unterminated = false;

    bool next(std::string_view& line)
    {
        if (pos >= data.size()) return false;
        std::size_t end = data.find('\n', pos);
        last_unterminated = end == std::string_view::npos;
        if (last_unterminated) end = data.size();
        line = data.substr(pos, end - pos);
        if (!line.empty() && line.back() == '\r') line.remove_suffix(1);
        pos = end + 1;
        ++number;
        return true;
    }
};

bool is_blank_or_comment(std::string_view line)
{
    std::size_t i = 0;
    while (i < line.size() && is_space(line[i])) ++i;
    return i == line.size() || line[i] == '#';
}

void parse_text_line(Collector& c, std::string_view line, Where w)
{
    Tokens t(line);
    std::string_view kind = t.next();
    if (kind == "frame") {
        std::size_t number = c.next_frame_number();
        HandFrame f;
        std::string error = parse_frame_line(t, f);
        if (!error.empty()) c.drop_frame(w, error);
        else c.add_frame(f, w, number);
    } else if (kind == "event") {
        InputEvent e;
        std::string error;
        if (!take_number(t, e.time, "time", error)) return c.drop_event(w, error);
        std::string_view ek = t.next();
        bool ok = true;
        if (ek == "key" || ek == "mouse_button") {
            e.kind = ek == "key" ? InputEventKind::Key : InputEventKind::MouseButton;
            ok = take_number(t, e.code, "code", error) && take_number(t, e.value, "value", error);
        } else if (ek == "mouse_move") {
            e.kind = InputEventKind::MouseMove;
            ok = take_number(t, e.x, "x", error) && take_number(t, e.y, "y", error);
        } else if (ek == "wheel") {
            e.kind = InputEventKind::MouseWheel;
            ok = take_number(t, e.y, "wheel delta", error);
        } else if (ek == "setting") {
            e.kind = InputEventKind::Setting;
            ok = take_number(t, e.code, "setting id", error) && take_number(t, e.value, "lobe id", error) &&
                 take_number(t, e.x, "value", error);
            if (ok && t.peek().empty() && !known_setting_id(e.code)) return c.skip_unknown_setting(w, e.code);
        } else if (ek == "import_mesh") {
            e.kind = InputEventKind::ImportMesh;
            ok = take_number(t, e.code, "import number", error);
        } else if (ek == "scene") {
            e.kind = InputEventKind::Scene;
            ok = take_number(t, e.code, "scene component", error) && take_number(t, e.x, "value", error);
            if (ok && !valid_scene_event(e.code, e.x)) {
                ok = false;
                error = "component or value out of range";
            }
        } else if (ek.empty()) {
            return c.drop_event(w, "missing event kind");
        } else {
            return c.skip_unknown_event(w, quote_token(ek));
        }
        if (!ok) return c.drop_event(w, error + " in " + std::string(ek) + " event");
        if (!t.peek().empty()) return c.drop_event(w, "unexpected " + quote_token(t.peek()) + " after " + std::string(ek) + " event");
        c.add_event(e, w);
    } else if (kind == "note") {
        Annotation a;
        std::string error;
        if (!take_number(t, a.time, "time", error)) return c.problem(w.str() + ": " + error + " in note, note dropped");
        a.text = unescape(t.rest());
        c.add_annotation(std::move(a), w);
    } else if (kind == "header") {
        c.problem(w.str() + ": a header must be the second line, skipped");
    } else {
        c.problem(w.str() + ": unknown line kind " + quote_token(kind) + " skipped");
    }
}

Recording parse_text(std::string_view data, const std::string& name, ReadReport& report)
{
    if (data.substr(0, kUtf8Bom.size()) == kUtf8Bom) data.remove_prefix(kUtf8Bom.size());
    LineReader lines{data};
    std::string_view line;
    lines.next(line);
    int major = 0;
    {
        Tokens t(line.substr(0, 256));
        t.next(); // the magic word, checked by the caller
        std::string_view v = t.next();
        std::string_view major_text = v.substr(0, v.find('.'));
        if (!parse_number(major_text, major) || !t.next().empty())
            throw FileError(name, "line 1: bad version line, expected '" + std::string(kTextMagic) + " " +
                                      std::to_string(kRecordingVersion) + "'");
        if (major < 1 || major > kRecordingVersion)
            throw FileError(name, "unsupported recording version " + std::to_string(major) +
                                      " (this build reads versions 1 to " + std::to_string(kRecordingVersion) + ")");
    }
    Collector c(name, report);
    c.rec.header.version = major;
    std::size_t frame_lines = 0;
    for (std::size_t at = data.find("\nframe "); at != std::string_view::npos && frame_lines < kMaxRecordingFrames;
         at = data.find("\nframe ", at + 1))
        ++frame_lines;
    c.rec.frames.reserve(frame_lines);
    bool header_expected = true;
    while (!c.stopped() && lines.next(line)) {
        Where w{true, lines.number};
        if (line.size() > kMaxLineBytes) {
            c.problem(w.str() + ": longer than " + std::to_string(kMaxLineBytes) + " bytes, skipped");
            header_expected = false;
            continue;
        }
        if (is_blank_or_comment(line)) continue;
        if (header_expected) {
            header_expected = false;
            Tokens t(line);
            if (t.next() == "header") {
                read_header_json(t.rest(), c.rec.header, c, w.str());
                continue;
            }
            c.problem(w.str() + ": expected 'header {json}' as the second line, using a default header");
        }
        const std::size_t problems_before = report.problems.size();
        parse_text_line(c, line, w);
        if (lines.last_unterminated && report.problems.size() > problems_before)
            report.problems.back() += " (truncated final line)";
    }
    return c.finish();
}

bool starts_with(std::string_view s, std::string_view prefix) { return s.substr(0, prefix.size()) == prefix; }

} // namespace

// ---------------------------------------------------------------------------------------
// Public interface
// ---------------------------------------------------------------------------------------

Recording parse_recording(const std::string& bytes, const std::string& name, ReadReport* report)
{
    ReadReport local;
    ReadReport& r = report ? *report : local;
    r = ReadReport{};
    std::string_view data(bytes);
    if (data.empty()) throw FileError(name, "empty file");
    const std::string_view magic(reinterpret_cast<const char*>(kMagic.data()), kMagic.size());
    if (starts_with(data, magic)) return parse_binary(data, name, r);
    if (data.size() < magic.size() && starts_with(magic, data))
        throw FileError(name, "truncated file header (" + std::to_string(data.size()) + " bytes)");
    std::string_view text = starts_with(data, kUtf8Bom) ? data.substr(kUtf8Bom.size()) : data;
    if (starts_with(text, kTextMagic) &&
        (text.size() == kTextMagic.size() || is_space(text[kTextMagic.size()]) || text[kTextMagic.size()] == '\n'))
        return parse_text(data, name, r);
    throw FileError(name, "not a Lobesketch recording (wrong magic bytes)");
}

Recording read_recording(const std::string& path, ReadReport* report)
{
    return parse_recording(read_file_limited(path, kMaxFileBytes), path, report);
}

std::string encode_recording_binary(const Recording& rec)
{
    std::string out = binary_file_header(rec.header);
    out.reserve(out.size() + rec.frames.size() * (kRecordOverhead + kMaxFramePayload) +
                rec.events.size() * (kRecordOverhead + kEventPayload) + rec.annotations.size() * 64);
    visit_in_time_order(
        rec, [&](const HandFrame& f) { append_frame_record(out, f); },
        [&](const InputEvent& e) { append_event_record(out, e); },
        [&](const Annotation& a) { append_annotation_record(out, a); });
    return out;
}

std::string encode_recording_text(const Recording& rec)
{
    std::string out;
    out.reserve(rec.frames.size() * 6000 + rec.events.size() * 40 + 4096);
    out += kTextMagic;
    out += ' ';
    out += std::to_string(kRecordingVersion);
    out += "\nheader ";
    out += header_json(rec.header);
    out += '\n';
    visit_in_time_order(
        rec, [&](const HandFrame& f) { append_frame_line(out, f); },
        [&](const InputEvent& e) { append_event_line(out, e); },
        [&](const Annotation& a) { append_note_line(out, a); });
    return out;
}

void write_recording_binary(const std::string& path, const Recording& rec)
{
    write_file_atomic(path, encode_recording_binary(rec));
}

void write_recording_text(const std::string& path, const Recording& rec)
{
    write_file_atomic(path, encode_recording_text(rec));
}

// ---------------------------------------------------------------------------------------
// RecordingWriter
// ---------------------------------------------------------------------------------------

RecordingWriter::RecordingWriter(const std::string& path, const RecordingHeader& header, int flush_every)
    : path_(path), flush_every_(std::max(1, flush_every))
{
    std::string head = binary_file_header(header);
    file_ = std::fopen(path.c_str(), "wb");
    if (!file_) throw FileError(path, std::string("cannot create: ") + std::strerror(errno));
    try {
        write_bytes(head);
        flush();
    } catch (...) {
        std::fclose(file_);
        file_ = nullptr;
        throw;
    }
}

RecordingWriter::~RecordingWriter()
{
    try {
        close();
    } catch (...) {
        // A destructor must not throw; close() explicitly to see write errors.
    }
}

void RecordingWriter::write_bytes(const std::string& bytes)
{
    if (!file_) throw FileError(path_, "recording writer is closed");
    if (std::fwrite(bytes.data(), 1, bytes.size(), file_) != bytes.size())
        throw FileError(path_, std::string("write failed: ") + std::strerror(errno));
}

void RecordingWriter::append(const HandFrame& frame)
{
    std::string bytes;
    append_frame_record(bytes, frame);
    write_bytes(bytes);
    if (++pending_ >= flush_every_) flush();
}

void RecordingWriter::append(const InputEvent& event)
{
    std::string bytes;
    append_event_record(bytes, event);
    write_bytes(bytes);
    flush();
}

void RecordingWriter::append(const Annotation& annotation)
{
    std::string bytes;
    append_annotation_record(bytes, annotation);
    write_bytes(bytes);
    flush();
}

void RecordingWriter::flush()
{
    if (!file_) throw FileError(path_, "recording writer is closed");
    pending_ = 0;
    if (std::fflush(file_) != 0) throw FileError(path_, std::string("flush failed: ") + std::strerror(errno));
}

void RecordingWriter::close()
{
    if (!file_) return;
    std::FILE* f = file_;
    file_ = nullptr;
    bool ok = std::fflush(f) == 0;
    int err = ok ? 0 : errno;
    if (ok && ::fsync(::fileno(f)) != 0 && errno != EINVAL) {
        ok = false;
        err = errno;
    }
    if (std::fclose(f) != 0 && ok) {
        ok = false;
        err = errno;
    }
    if (!ok) throw FileError(path_, std::string("close failed: ") + std::strerror(err));
}

bool valid_scene_event(std::int32_t component, float value)
{
    if (!std::isfinite(value)) return false;
    switch (static_cast<SceneComponent>(component)) {
    case SceneComponent::Scale: return value >= kMinSceneScale && value <= kMaxSceneScale;
    case SceneComponent::Yaw: return std::abs(value) <= 4.0f * 3.14159265f;
    case SceneComponent::TranslationX:
    case SceneComponent::TranslationY:
    case SceneComponent::TranslationZ: return std::abs(value) <= kMaxSceneTranslation;
    }
    return false;
}

std::string import_mesh_path(const std::string& recording_path, int n)
{
    return recording_path + ".import-" + std::to_string(n) + ".ply";
}

const char* event_kind_name(InputEventKind k)
{
    switch (k) {
    case InputEventKind::Key: return "key";
    case InputEventKind::MouseButton: return "mouse_button";
    case InputEventKind::MouseMove: return "mouse_move";
    case InputEventKind::MouseWheel: return "wheel";
    case InputEventKind::Setting: return "setting";
    case InputEventKind::ImportMesh: return "import_mesh";
    case InputEventKind::Scene: return "scene";
    }
    return nullptr;
}

const char* setting_name(SettingId id)
{
    switch (id) {
    case SettingId::SplitAngle: return "split-angle";
    case SettingId::AttractorSpacing: return "attractor-spacing";
    case SettingId::LeafLength: return "leaf-length";
    case SettingId::LeavesPerNode: return "leaves-per-node";
    case SettingId::Species: return "species";
    case SettingId::Seed: return "seed";
    }
    return nullptr;
}

} // namespace lobe
