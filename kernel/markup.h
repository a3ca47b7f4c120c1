// Escaping for text placed in XML or HTML (JUnit files, the report): the five markup characters
// become entities, and control characters that XML 1.0 forbids become spaces.
#pragma once
#include <string>
#include <string_view>

namespace iblcheck {

inline std::string escape_markup(std::string_view s) {
    std::string o;
    o.reserve(s.size() + 8);
    for (char c : s) {
        switch (c) {
        case '&': o += "&amp;"; break;
        case '<': o += "&lt;"; break;
        case '>': o += "&gt;"; break;
        case '"': o += "&quot;"; break;
        case '\'': o += "&#39;"; break;
        default:
            if (static_cast<unsigned char>(c) < 0x20 && c != '\n' && c != '\t' && c != '\r')
                o += ' ';
            else
                o += c;
        }
    }
    return o;
}

} // namespace iblcheck
