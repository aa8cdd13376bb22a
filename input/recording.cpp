// Recordings: reading either form (told by the first bytes), the binary form's reader, the
// text form's reader, the writers of both forms and RecordingWriter. Both forms byte by byte
// and line by line: docs/recording-format.md.
#include "input/recording.h"

#include <algorithm>
#include <array>
#include <bit>
#include <cerrno>
#include <charconv>
#include <cmath>
#include <cstring>
#include <limits>
#include <string>
#include <string_view>
#include <system_error>
#include <utility>

#include <unistd.h>

#include <nlohmann/json.hpp>

#include "core/atomic_file.h"
#include "core/errors.h"
#include "input/recording_format.h"

namespace lobe::recording_format {

namespace {

// ---------------------------------------------------------------------------------------
// Little-endian unpacking
// ---------------------------------------------------------------------------------------

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
// Dequantisation (the inverse of recording_writer.cpp's quantisation)
// ---------------------------------------------------------------------------------------

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

float dequantise_radius(std::uint16_t u)
{
    if (u == kNonFiniteRadius) return std::numeric_limits<float>::quiet_NaN();
    return static_cast<float>(double(u) * kRadiusPerUnit);
}

bool known_event_kind(std::uint8_t k) { return k >= 1 && k <= 7; }

// ---------------------------------------------------------------------------------------
// Records
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

} // namespace

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

namespace {

template <typename T>
bool parse_number(std::string_view t, T& v)
{
    if (t.empty()) return false;
    auto r = std::from_chars(t.data(), t.data() + t.size(), v);
    return r.ec == std::errc() && r.ptr == t.data() + t.size();
}

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

/// Note text as append_escaped (recording_writer.cpp) wrote it; an unknown escape is kept as
/// written.
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

} // namespace

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

} // namespace lobe::recording_format

namespace lobe {

using namespace recording_format;

namespace {

using nlohmann::json;

// ---------------------------------------------------------------------------------------
// Little-endian packing and quantisation
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

std::uint16_t quantise_radius(float r)
{
    if (!std::isfinite(r)) return kNonFiniteRadius;
    return static_cast<std::uint16_t>(std::clamp(std::round(double(r) / kRadiusPerUnit), 0.0, kMaxRadiusUnits));
}

// ---------------------------------------------------------------------------------------
// Both forms: the header and the order of records
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
// Binary form
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

// ---------------------------------------------------------------------------------------
// Text form
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

} // namespace

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
