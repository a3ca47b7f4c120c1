// Commands the tool prints for a person to paste (bless, truth, the run's own command line) hold
// names that come from files: an environment file may be called `x';touch PWNED;'.exr`. Every
// argument is quoted the POSIX way, so that pasting the command runs that command and nothing else;
// a test name given as a --filter glob has its glob characters escaped, so it selects that test only.
#pragma once
#include <string>

namespace iblcheck {

// 'text' with each ' written as '\'' (POSIX sh: nothing inside single quotes is special).
inline std::string shell_quote(const std::string& s) {
    std::string o = "'";
    for (char c : s) o += c == '\'' ? std::string("'\\''") : std::string(1, c);
    return o + "'";
}

// An argument as typed: left bare when it holds only characters no shell treats specially, else
// shell_quote'd (the recorded `iblcheck run --suite ci --out report` stays as readable as typed).
inline std::string shell_arg(const std::string& s) {
    bool plain = !s.empty();
    for (char c : s)
        plain = plain && ((c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') ||
                          std::string("_-./:=,@%+").find(c) != std::string::npos);
    return plain ? s : shell_quote(s);
}

// The word that starts at `pos` in a command written by shell_quote/shell_arg (quoted parts, \x
// escapes and bare characters up to a space), unquoted; `pos` is left after it.
inline std::string shell_word(const std::string& s, size_t& pos) {
    std::string o;
    while (pos < s.size() && s[pos] != ' ') {
        if (s[pos] == '\'') {
            const size_t end = s.find('\'', pos + 1);
            o += s.substr(pos + 1, end == std::string::npos ? std::string::npos : end - pos - 1);
            pos = end == std::string::npos ? s.size() : end + 1;
        } else if (s[pos] == '\\' && pos + 1 < s.size()) {
            o += s[pos + 1];
            pos += 2;
        } else {
            o += s[pos++];
        }
    }
    return o;
}

// A name as a --filter glob that matches it alone: * ? [ \ and | (which separates globs) escaped.
inline std::string glob_escape(const std::string& name) {
    std::string o;
    for (char c : name) {
        if (c == '*' || c == '?' || c == '[' || c == '\\' || c == '|') o += '\\';
        o += c;
    }
    return o;
}

} // namespace iblcheck
