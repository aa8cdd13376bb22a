#include "input/hand_derive.h"

#include "core/errors.h"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <system_error>

#include <glm/geometric.hpp>
#include <glm/mat3x3.hpp>
#include <nlohmann/json.hpp>

namespace lobe {

// ---------------------------------------------------------------------------------------
// Joint geometry
// ---------------------------------------------------------------------------------------

glm::quat bone_orientation(const glm::vec3& along, const glm::vec3& up)
{
    const float len = glm::length(along);
    if (!(len > 1e-9f)) return glm::quat(1.0f, 0.0f, 0.0f, 0.0f);
    const glm::vec3 z = -along / len;
    glm::vec3 y = up - glm::dot(up, z) * z;
    if (!(glm::length(y) > 1e-6f)) {
        // Any perpendicular will do: pick the world axis least aligned with the bone.
        const glm::vec3 helper = std::abs(z.y) < 0.9f ? glm::vec3(0.0f, 1.0f, 0.0f) : glm::vec3(0.0f, 0.0f, -1.0f);
        y = helper - glm::dot(helper, z) * z;
    }
    y = glm::normalize(y);
    const glm::vec3 x = glm::cross(y, z);
    return glm::normalize(glm::quat_cast(glm::mat3(x, y, z)));
}

glm::vec3 finger_bone_up(const glm::vec3& along, const glm::vec3& hand_x, const glm::vec3& hand_up)
{
    const float len = glm::length(along);
    if (!(len > 1e-9f)) return hand_up;
    // cross(X, along) is the bone's +Y for any flexion; the small share of hand_up only
    // matters when the bone points along X (a thumb held sideways).
    return glm::cross(hand_x, along / len) + 0.05f * hand_up;
}

glm::vec3 direction_or(const glm::vec3& from, const glm::vec3& to, const glm::vec3& fallback)
{
    const glm::vec3 d = to - from;
    const float len = glm::length(d);
    return len > 1e-6f ? d / len : fallback;
}

float default_joint_radius(Joint j)
{
    // Meta Quest 3 (WebXR) radii, metres; the palm gets the metacarpal's.
    static constexpr float radii[kJointCount] = {
        0.021f, 0.021f,                          // palm, wrist
        0.019f, 0.012f, 0.010f, 0.009f,          // thumb
        0.021f, 0.010f, 0.009f, 0.008f, 0.007f,  // index
        0.021f, 0.011f, 0.008f, 0.008f, 0.007f,  // middle
        0.019f, 0.010f, 0.008f, 0.007f, 0.006f,  // ring
        0.018f, 0.008f, 0.007f, 0.006f, 0.005f,  // little
    };
    const int i = idx(j);
    return (i >= 0 && i < kJointCount) ? radii[i] : 0.01f;
}

void derive_palm_from_metacarpal(HandState& hand)
{
    const JointState& meta = hand[Joint::MiddleMetacarpal];
    const JointState& prox = hand[Joint::MiddleProximal];
    JointState palm;
    palm.pose.position = 0.5f * (meta.pose.position + prox.pose.position);
    palm.pose.orientation = meta.pose.orientation;
    palm.radius = meta.radius > 0.0f ? meta.radius : default_joint_radius(Joint::Palm);
    palm.flags = kPositionValid;
    if ((meta.flags & kOrientationValid) != 0) palm.flags |= kOrientationValid;
    hand[Joint::Palm] = palm;
}

bool plausible_position(const glm::vec3& p)
{
    for (int i = 0; i < 3; ++i)
        if (!std::isfinite(p[i]) || std::abs(p[i]) > kMaxImportCoordinate) return false;
    return true;
}

const std::vector<std::vector<Joint>>& finger_chains()
{
    static const std::vector<std::vector<Joint>> chains = {
        {Joint::ThumbMetacarpal, Joint::ThumbProximal, Joint::ThumbDistal, Joint::ThumbTip},
        {Joint::IndexMetacarpal, Joint::IndexProximal, Joint::IndexIntermediate, Joint::IndexDistal, Joint::IndexTip},
        {Joint::MiddleMetacarpal, Joint::MiddleProximal, Joint::MiddleIntermediate, Joint::MiddleDistal, Joint::MiddleTip},
        {Joint::RingMetacarpal, Joint::RingProximal, Joint::RingIntermediate, Joint::RingDistal, Joint::RingTip},
        {Joint::LittleMetacarpal, Joint::LittleProximal, Joint::LittleIntermediate, Joint::LittleDistal, Joint::LittleTip},
    };
    return chains;
}

// ---------------------------------------------------------------------------------------
// Literal reader
// ---------------------------------------------------------------------------------------

namespace {

using nlohmann::json;

bool is_ident_char(char c)
{
    return (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') || c == '_' || c == '$';
}

bool is_number_char(char c)
{
    return (c >= '0' && c <= '9') || c == '.' || c == 'e' || c == 'E' || c == '+' || c == '-';
}

void append_utf8(std::string& out, std::uint32_t cp)
{
    if (cp < 0x80) {
        out += static_cast<char>(cp);
    } else if (cp < 0x800) {
        out += static_cast<char>(0xC0 | (cp >> 6));
        out += static_cast<char>(0x80 | (cp & 0x3F));
    } else if (cp < 0x10000) {
        out += static_cast<char>(0xE0 | (cp >> 12));
        out += static_cast<char>(0x80 | ((cp >> 6) & 0x3F));
        out += static_cast<char>(0x80 | (cp & 0x3F));
    } else {
        out += static_cast<char>(0xF0 | (cp >> 18));
        out += static_cast<char>(0x80 | ((cp >> 12) & 0x3F));
        out += static_cast<char>(0x80 | ((cp >> 6) & 0x3F));
        out += static_cast<char>(0x80 | (cp & 0x3F));
    }
}

/// Recursive descent over one value; depth is bounded by max_depth.
class LiteralParser {
public:
    LiteralParser(std::string_view text, std::size_t& pos, int max_depth)
        : s_(text), p_(pos), max_depth_(max_depth)
    {
    }

    [[noreturn]] void fail(const std::string& what) const
    {
        const bool at_end = p_ >= s_.size();
        throw LiteralError(std::min(p_, s_.size()), at_end ? "unexpected end of text" : what, at_end);
    }

    bool at_end() const { return p_ >= s_.size(); }
    char peek() const { return p_ < s_.size() ? s_[p_] : '\0'; }

    void skip_space()
    {
        while (p_ < s_.size()) {
            const char c = s_[p_];
            if (c == ' ' || c == '\t' || c == '\n' || c == '\r' || c == '\f' || c == '\v') {
                ++p_;
            } else if (c == '/' && p_ + 1 < s_.size() && s_[p_ + 1] == '/') {
                while (p_ < s_.size() && s_[p_] != '\n') ++p_;
            } else if (c == '/' && p_ + 1 < s_.size() && s_[p_ + 1] == '*') {
                const std::size_t end = s_.find("*/", p_ + 2);
                if (end == std::string_view::npos) {
                    p_ = s_.size();
                    fail("unterminated comment");
                }
                p_ = end + 2;
            } else {
                break;
            }
        }
    }

    json value(int depth)
    {
        skip_space();
        if (at_end()) fail("unexpected end of text");
        const char c = s_[p_];
        if (c == '{') return object(depth);
        if (c == '[') return array(depth);
        if (c == '"' || c == '\'') return json(string(c));
        if (c == '!') {
            ++p_;
            const char d = peek();
            if (d == '0') { ++p_; return json(true); }
            if (d == '1') { ++p_; return json(false); }
            fail("expected !0 or !1");
        }
        if ((c >= '0' && c <= '9') || c == '-' || c == '+' || c == '.') return json(number());
        if (is_ident_char(c)) {
            const std::string word = identifier();
            if (word == "true") return json(true);
            if (word == "false") return json(false);
            if (word == "null" || word == "undefined") return json(nullptr);
            if (word == "NaN") return json(std::nan(""));
            if (word == "Infinity") return json(HUGE_VAL);
            if (word == "void") {
                skip_space();
                (void)number();
                return json(nullptr);
            }
            fail("unexpected word");
        }
        fail("unexpected character");
    }

    std::string string(char quote)
    {
        ++p_; // opening quote
        std::string out;
        for (;;) {
            if (at_end()) fail("unterminated string");
            const char c = s_[p_++];
            if (c == quote) return out;
            if (c != '\\') {
                out += c;
                continue;
            }
            if (at_end()) fail("unterminated string");
            const char e = s_[p_++];
            switch (e) {
            case 'n': out += '\n'; break;
            case 't': out += '\t'; break;
            case 'r': out += '\r'; break;
            case 'b': out += '\b'; break;
            case 'f': out += '\f'; break;
            case 'v': out += '\v'; break;
            case '0': out += '\0'; break;
            case 'x': append_utf8(out, hex(2)); break;
            case 'u': {
                std::uint32_t cp = hex(4);
                if (cp >= 0xD800 && cp < 0xDC00 && p_ + 1 < s_.size() && s_[p_] == '\\' && s_[p_ + 1] == 'u') {
                    p_ += 2;
                    const std::uint32_t low = hex(4);
                    if (low >= 0xDC00 && low < 0xE000) cp = 0x10000 + ((cp - 0xD800) << 10) + (low - 0xDC00);
                    else cp = 0xFFFD;
                } else if (cp >= 0xD800 && cp < 0xE000) {
                    cp = 0xFFFD;
                }
                append_utf8(out, cp);
                break;
            }
            case '\n': break; // line continuation
            default: out += e; break;
            }
        }
    }

    std::uint32_t hex(int digits)
    {
        std::uint32_t v = 0;
        for (int i = 0; i < digits; ++i) {
            if (at_end()) fail("unterminated string");
            const char c = s_[p_++];
            std::uint32_t d = 0;
            if (c >= '0' && c <= '9') d = static_cast<std::uint32_t>(c - '0');
            else if (c >= 'a' && c <= 'f') d = static_cast<std::uint32_t>(c - 'a' + 10);
            else if (c >= 'A' && c <= 'F') d = static_cast<std::uint32_t>(c - 'A' + 10);
            else fail("bad hex escape");
            v = v * 16 + d;
        }
        return v;
    }

    std::string identifier()
    {
        const std::size_t start = p_;
        while (p_ < s_.size() && is_ident_char(s_[p_])) ++p_;
        return std::string(s_.substr(start, p_ - start));
    }

    double number()
    {
        bool negative = false;
        if (peek() == '+' || peek() == '-') {
            negative = peek() == '-';
            ++p_;
        }
        if (peek() == 'I') {
            if (identifier() != "Infinity") fail("malformed number");
            return negative ? -HUGE_VAL : HUGE_VAL;
        }
        const std::size_t start = p_;
        while (p_ < s_.size() && is_number_char(s_[p_])) ++p_;
        if (p_ == start) fail("malformed number");
        const char* first = s_.data() + start;
        const char* last = s_.data() + p_;
        double v = 0.0;
        const auto [ptr, ec] = std::from_chars(first, last, v);
        if (ptr != last) {
            p_ = start;
            fail("malformed number");
        }
        if (ec == std::errc::result_out_of_range) {
            const std::string_view token(first, static_cast<std::size_t>(last - first));
            const std::size_t e = token.find_first_of("eE");
            const bool tiny = e != std::string_view::npos && e + 1 < token.size() && token[e + 1] == '-';
            v = tiny ? 0.0 : HUGE_VAL;
        } else if (ec != std::errc()) {
            p_ = start;
            fail("malformed number");
        }
        return negative ? -v : v;
    }

    json object(int depth)
    {
        if (depth >= max_depth_) fail("nested deeper than " + std::to_string(max_depth_) + " levels");
        ++p_;
        json out = json::object();
        for (;;) {
            skip_space();
            if (at_end()) fail("unexpected end of text");
            if (s_[p_] == '}') {
                ++p_;
                return out;
            }
            std::string key;
            const char c = s_[p_];
            if (c == '"' || c == '\'') key = string(c);
            else if (is_ident_char(c)) key = identifier();
            else fail("expected a key");
            skip_space();
            if (peek() != ':') fail("expected ':'");
            ++p_;
            out[key] = value(depth + 1);
            skip_space();
            if (peek() == ',') {
                ++p_;
                continue;
            }
            if (peek() == '}') {
                ++p_;
                return out;
            }
            fail("expected ',' or '}'");
        }
    }

    json array(int depth)
    {
        if (depth >= max_depth_) fail("nested deeper than " + std::to_string(max_depth_) + " levels");
        ++p_;
        json out = json::array();
        for (;;) {
            skip_space();
            if (at_end()) fail("unexpected end of text");
            if (s_[p_] == ']') {
                ++p_;
                return out;
            }
            out.push_back(value(depth + 1));
            skip_space();
            if (peek() == ',') {
                ++p_;
                continue;
            }
            if (peek() == ']') {
                ++p_;
                return out;
            }
            fail("expected ',' or ']'");
        }
    }

    /// Iterative bracket matching for skip_literal.
    void skip()
    {
        skip_space();
        if (at_end()) fail("unexpected end of text");
        const char c = s_[p_];
        if (c == '"' || c == '\'') {
            (void)string(c);
            return;
        }
        if (c != '{' && c != '[') {
            (void)value(0);
            return;
        }
        std::vector<char> open;
        while (!at_end()) {
            const char d = s_[p_];
            if (d == '"' || d == '\'') {
                (void)string(d);
                continue;
            }
            if (d == '/' && p_ + 1 < s_.size() && (s_[p_ + 1] == '/' || s_[p_ + 1] == '*')) {
                skip_space();
                continue;
            }
            if (d == '{' || d == '[') {
                if (static_cast<int>(open.size()) >= max_depth_)
                    fail("nested deeper than " + std::to_string(max_depth_) + " levels");
                open.push_back(d);
            } else if (d == '}' || d == ']') {
                if (open.empty() || open.back() != (d == '}' ? '{' : '[')) fail("mismatched bracket");
                open.pop_back();
                if (open.empty()) {
                    ++p_;
                    return;
                }
            }
            ++p_;
        }
        fail("unexpected end of text");
    }

private:
    std::string_view s_;
    std::size_t& p_;
    int max_depth_;
};

} // namespace

nlohmann::json parse_literal(std::string_view text, std::size_t& pos, int max_depth)
{
    LiteralParser parser(text, pos, max_depth);
    return parser.value(0);
}

void skip_literal(std::string_view text, std::size_t& pos, int max_depth)
{
    LiteralParser parser(text, pos, max_depth);
    parser.skip();
}

TopLevelKeys scan_top_level_keys(std::string_view text)
{
    TopLevelKeys out;
    std::size_t p = text.find('{');
    if (p == std::string_view::npos) {
        out.problem = text.empty() ? "empty file" : "no object found";
        return out;
    }
    out.found_object = true;
    LiteralParser parser(text, p, kMaxLiteralDepth);
    ++p;
    try {
        for (;;) {
            parser.skip_space();
            if (parser.at_end()) parser.fail("unexpected end of text");
            const char c = text[p];
            if (c == '}') return out;
            std::string key;
            if (c == '"' || c == '\'') key = parser.string(c);
            else if (is_ident_char(c)) key = parser.identifier();
            else parser.fail("expected a key");
            parser.skip_space();
            if (parser.peek() != ':') parser.fail("expected ':'");
            ++p;
            parser.skip_space();
            out.value_offset.emplace(key, p);
            parser.skip();
            parser.skip_space();
            if (parser.peek() == ',') {
                ++p;
                continue;
            }
            if (parser.peek() == '}') return out;
            parser.fail("expected ',' or '}'");
        }
    } catch (const LiteralError& e) {
        out.problem = e.what();
    }
    return out;
}

std::string for_each_array_element(
    std::string_view text, std::size_t pos,
    const std::function<bool(const nlohmann::json& element, std::size_t index)>& fn,
    const std::function<void(std::size_t index, const std::string& why)>& bad)
{
    std::size_t p = pos;
    LiteralParser parser(text, p, kMaxLiteralDepth);
    parser.skip_space();
    if (parser.peek() != '[') throw LiteralError(p, "not an array", parser.at_end());
    ++p;
    std::size_t index = 0;
    try {
        for (;;) {
            parser.skip_space();
            if (parser.at_end()) parser.fail("unexpected end of text");
            if (text[p] == ']') return {};
            const std::size_t start = p;
            parser.skip();
            const std::size_t end = p;
            if (end - start > kMaxImportFrameBytes) {
                bad(index, "larger than " + std::to_string(kMaxImportFrameBytes >> 20) + " MiB");
            } else {
                std::size_t q = start;
                bool parsed = false;
                json element;
                try {
                    element = parse_literal(text.substr(0, end), q);
                    parsed = true;
                } catch (const LiteralError& e) {
                    bad(index, e.what());
                }
                if (parsed && !fn(element, index)) return {};
            }
            ++index;
            parser.skip_space();
            if (parser.peek() == ',') {
                ++p;
                continue;
            }
            if (parser.peek() == ']') return {};
            parser.fail("expected ',' or ']'");
        }
    } catch (const LiteralError& e) {
        return e.what();
    }
}

// ---------------------------------------------------------------------------------------
// Reporting
// ---------------------------------------------------------------------------------------

void ProblemLog::add(std::string line)
{
    ++count_;
    if (lines_.size() < kMaxReportedProblems) lines_.push_back(std::move(line));
}

void ProblemLog::write_to(ReadReport* report) const
{
    if (report == nullptr) return;
    report->problems.insert(report->problems.end(), lines_.begin(), lines_.end());
    if (count_ > lines_.size())
        report->problems.push_back("... and " + std::to_string(count_ - lines_.size()) + " more problems");
}

} // namespace lobe
