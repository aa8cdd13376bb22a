#include "input/recording_format.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <string_view>
#include <utility>

#include <nlohmann/json.hpp>

#include "core/errors.h"

namespace lobe::recording_format {

namespace {

using nlohmann::json;

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

} // namespace

std::uint32_t crc32(const unsigned char* data, std::size_t size)
{
    std::uint32_t crc = 0xFFFFFFFFu;
    for (std::size_t i = 0; i < size; ++i) crc = kCrcTable[(crc ^ data[i]) & 0xFFu] ^ (crc >> 8);
    return ~crc;
}

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

std::string_view clip_utf8(std::string_view s, std::size_t max)
{
    if (s.size() <= max) return s;
    std::size_t n = max;
    while (n > 0 && (static_cast<unsigned char>(s[n]) & 0xC0u) == 0x80u) --n;
    return s.substr(0, n);
}

void Collector::problem(std::string msg)
{
    make_one_line(msg);
    auto& list = report_.problems;
    if (std::find(list.begin(), list.end(), msg) != list.end()) return;
    if (list.size() < kMaxProblems) list.push_back(std::move(msg));
    else ++more_problems_;
}

void Collector::drop_frame(Where w, const std::string& why)
{
    ++report_.frames_dropped;
    problem(w.str() + ": " + why);
}

void Collector::drop_event(Where w, const std::string& why)
{
    ++report_.events_dropped;
    problem(w.str() + ": " + why);
}

void Collector::add_frame(HandFrame& f, Where w, std::size_t number)
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

void Collector::add_event(const InputEvent& e, Where w)
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

void Collector::skip_unknown_event(Where w, const std::string& kind)
{
    ++event_number_;
    drop_event(w, "unknown event kind " + kind + " skipped");
}

void Collector::skip_unknown_setting(Where w, std::int32_t id)
{
    ++event_number_;
    drop_event(w, "unknown setting id " + std::to_string(id) + " skipped");
}

void Collector::add_annotation(Annotation a, Where w)
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

Recording Collector::finish()
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

void Collector::stop(Where w, const std::string& why)
{
    stopped_ = true;
    problem(w.str() + ": " + why);
}

bool Collector::position_ok(const glm::vec3& p)
{
    // NaN fails every comparison, so this also refuses NaN.
    auto ok = [](float v) { return double(std::abs(v)) <= kAbsurdMetres; };
    return ok(p.x) && ok(p.y) && ok(p.z);
}

std::string Collector::position_problem(const glm::vec3& p, const std::string& what)
{
    if (!finite(p)) return "NaN/Inf in " + what + " position";
    float m = std::max({std::abs(p.x), std::abs(p.y), std::abs(p.z)});
    return "absurd coordinate " + number_text(m) + " m (limit " + number_text(kAbsurdMetres) + " m) in " +
           what + " position";
}

std::string Collector::unusable(const HandFrame& f)
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

bool Collector::repair_quat(glm::quat& q, std::size_t number)
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

void Collector::repair(HandFrame& f, std::size_t number)
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

} // namespace lobe::recording_format
