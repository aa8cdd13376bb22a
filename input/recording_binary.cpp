// The binary form's reader: records found by their sync marker, checked by their CRC, and
// decoded into the Collector; damage costs the damaged records only. Layout:
// docs/recording-format.md.
#include <array>
#include <bit>
#include <cstring>
#include <limits>
#include <string>
#include <string_view>

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

} // namespace lobe::recording_format
