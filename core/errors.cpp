#include "core/errors.h"

namespace lobe {

std::string one_line_message(const std::string& what)
{
    constexpr std::size_t kMaxBytes = 1000;
    std::string out;
    out.reserve(what.size() < kMaxBytes ? what.size() : kMaxBytes + 8);
    for (std::size_t i = 0; i < what.size(); ++i) {
        // Cut before a character that would end past the limit (never inside a UTF-8
        // sequence; an escaped control character counts as its 4 bytes).
        const auto c = static_cast<unsigned char>(what[i]);
        if ((c & 0xC0) != 0x80) {
            const std::size_t bytes = c < 0x20 || c == 0x7F ? 4 : c < 0x80 ? 1 : c >= 0xF0 ? 4 : c >= 0xE0 ? 3 : 2;
            if (out.size() + bytes > kMaxBytes) {
                out += "\u2026";
                break;
            }
        }
        if (c == '\n') out += "\\n";
        else if (c == '\r') out += "\\r";
        else if (c == '\t') out += "\\t";
        else if (c < 0x20 || c == 0x7F) {
            static const char* const kHex = "0123456789abcdef";
            out += "\\x";
            out += kHex[c >> 4];
            out += kHex[c & 15];
        } else out += static_cast<char>(c);
    }
    return out;
}

} // namespace lobe
