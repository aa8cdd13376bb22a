// The text form's reader: one line per frame, event or note, parsed token by token into the
// Collector; a bad line costs that line only. Line grammar: docs/recording-format.md.
#include <array>
#include <charconv>
#include <string>
#include <string_view>
#include <system_error>
#include <utility>

#include "core/errors.h"
#include "input/recording_format.h"

namespace lobe::recording_format {

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
