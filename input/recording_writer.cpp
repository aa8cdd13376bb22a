// Writers of both forms: whole recordings (encode_recording_*, write_recording_*) and the
// streaming RecordingWriter of live sessions. Layout: docs/recording-format.md.
#include "input/recording.h"

#include <algorithm>
#include <array>
#include <bit>
#include <cerrno>
#include <cmath>
#include <cstring>
#include <string>
#include <string_view>

#include <unistd.h>

#include <nlohmann/json.hpp>

#include "core/atomic_file.h"
#include "core/errors.h"
#include "input/recording_format.h"

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

} // namespace lobe
