// Recordings: reading either form (told by the first bytes), the binary form's reader, the
// text form's reader. Both forms byte by byte and line by line: docs/recording-format.md.
#include "input/recording.h"

#include <array>
#include <bit>
#include <charconv>
#include <cmath>
#include <cstring>
#include <limits>
#include <string>
#include <string_view>
#include <system_error>
#include <utility>

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
