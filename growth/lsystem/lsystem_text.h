#pragma once
/// \file lsystem_text.h
/// Small text helpers the `.l` reader (lsystem_parse.cpp) and the view-file reader
/// (lsystem_view.cpp) share. Private to growth/lsystem/.

#include <algorithm>
#include <charconv>
#include <cstddef>
#include <string>
#include <string_view>
#include <vector>

#include "core/errors.h"
#include "growth/lsystem/expr.h"

namespace lobe::lsystem::detail {

/// Most warning lines one file gives; past it, one line says how many more there were.
inline constexpr std::size_t kMaxWarnings = 200;

inline bool is_blank(char c) { return c == ' ' || c == '\t' || c == '\r' || c == '\n' || c == '\f' || c == '\v'; }
inline bool is_name_start(char c) { return (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || c == '_'; }
inline bool is_name_char(char c) { return is_name_start(c) || (c >= '0' && c <= '9'); }
inline bool is_letter(char c) { return (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z'); }
inline char lower(char c) { return (c >= 'A' && c <= 'Z') ? static_cast<char>(c - 'A' + 'a') : c; }

/// At most 60 bytes of `s` for a message, "…" when cut.
inline std::string shorten(std::string_view s)
{
    std::string out(s.substr(0, std::min<std::size_t>(s.size(), 60)));
    if (s.size() > 60) out += "…";
    return out;
}

/// `v` in its shortest round-trip form.
inline std::string number_text(double v)
{
    char buf[32];
    const auto r = std::to_chars(buf, buf + sizeof buf, v);
    return std::string(buf, r.ptr);
}

/// Collects warnings, one line each, at most kMaxWarnings.
class Warnings {
public:
    explicit Warnings(std::vector<std::string>* out) : out_(out) {}
    void add(std::string line)
    {
        if (out_ == nullptr) return;
        ++count_;
        if (count_ <= kMaxWarnings) out_->push_back(one_line_message(line));
    }
    /// Adds the line that counts the warnings past the cap, if any.
    void finish(const std::string& name)
    {
        if (out_ != nullptr && count_ > kMaxWarnings)
            out_->push_back(name + ": " + std::to_string(count_ - kMaxWarnings) + " more warnings not shown");
    }

private:
    std::vector<std::string>* out_;
    std::size_t count_ = 0;
};

/// `text` with its comments blanked (newlines kept, so positions stay): `/* … */` anywhere,
/// and `//` to the end of the line where it starts a line or stands between blanks
/// (`F // note`); elsewhere `//` is two turtle rolls (`F//F`, ABOP's `/////`).
/// \throw InvalidInput (src.fail) for an unterminated `/*`.
std::string blank_comments(std::string_view text, const SourceText& src);

} // namespace lobe::lsystem::detail
