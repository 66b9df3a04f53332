#include "spec.hpp"

#include <cctype>
#include <charconv>
#include <cstdio>
#include <cstdlib>

namespace orogen::spec {

namespace {

bool word_start(char c) { return std::isalpha(static_cast<unsigned char>(c)) || c == '_'; }
bool word_char(char c) { return std::isalnum(static_cast<unsigned char>(c)) || c == '_' || c == '-'; }
bool digit(char c) { return std::isdigit(static_cast<unsigned char>(c)) != 0; }

}  // namespace

std::vector<Token> lex(const std::shared_ptr<const Source>& source, Diagnostics& diags, bool comments) {
    std::vector<Token> out;
    const std::string& s = source->text;
    std::size_t i = 0;
    int line = 1;
    std::size_t line_start = 0;

    auto here = [&](std::size_t begin, std::size_t end) {
        return Location{source, line, int(begin - line_start) + 1, int(std::max<std::size_t>(1, end - begin))};
    };
    auto push = [&](Tok kind, std::size_t begin, std::size_t end, std::string text = {}) {
        Token t;
        t.kind = kind;
        t.text = text.empty() ? s.substr(begin, end - begin) : std::move(text);
        t.where = here(begin, end);
        out.push_back(std::move(t));
    };

    // A binary file (an image, an executable) passed by mistake: one error, not hundreds.
    for (std::size_t k = 0; k < s.size() && k < (1u << 20); ++k) {
        const auto b = static_cast<unsigned char>(s[k]);
        if ((b < 0x20 && b != '\n' && b != '\t' && b != '\r') || b == 0x7f) {
            char hex[8];
            std::snprintf(hex, sizeof hex, "0x%02x", b);
            diags.error(Location{source, 1, 1, 0}, "this is not a text spec: byte " + std::to_string(k) + " is " + hex +
                                                       ", a control character; is it a binary file?");
            Token bad;
            bad.kind = Tok::bad;
            bad.where = Location{source, 1, 1, 1};
            out.push_back(bad);
            Token eof;
            eof.where = bad.where;
            out.push_back(eof);
            return out;
        }
    }
    while (i < s.size()) {
        const char c = s[i];
        if (c == '\n') {
            push(Tok::newline, i, i + 1, "\n");  // the parser skips it inside ( ) and [ ]
            ++i;
            ++line;
            line_start = i;
            continue;
        }
        if (c == ' ' || c == '\t' || c == '\r') {
            ++i;
            continue;
        }
        if (c == '#' && !comments) {  // kind:node#2: the label's number is digits only ("2." is not a number here)
            push(Tok::hash, i, i + 1);
            const std::size_t digits = ++i;
            while (i < s.size() && digit(s[i])) ++i;
            if (i > digits) {
                Token t;
                t.kind = Tok::number;
                t.text = s.substr(digits, i - digits);
                t.integer = true;
                t.number = std::strtod(t.text.c_str(), nullptr);
                t.where = here(digits, i);
                out.push_back(std::move(t));
            }
            continue;
        }
        if (c == '#') {
            while (i < s.size() && s[i] != '\n') ++i;
            continue;
        }
        const std::size_t begin = i;
        if (digit(c) || ((c == '-' || c == '+' || c == '.') && i + 1 < s.size() &&
                         (digit(s[i + 1]) || (s[i + 1] == '.' && i + 2 < s.size() && digit(s[i + 2]))))) {
            if (c == '-' || c == '+') ++i;
            bool integer = true;
            while (i < s.size() && digit(s[i])) ++i;
            if (i < s.size() && s[i] == '.') {
                integer = false;
                ++i;
                while (i < s.size() && digit(s[i])) ++i;
            }
            if (i < s.size() && (s[i] == 'e' || s[i] == 'E') && i + 1 < s.size() &&
                (digit(s[i + 1]) || ((s[i + 1] == '-' || s[i + 1] == '+') && i + 2 < s.size() && digit(s[i + 2])))) {
                integer = false;
                i += 2;
                while (i < s.size() && digit(s[i])) ++i;
            }
            Token t;
            t.kind = Tok::number;
            t.text = s.substr(begin, i - begin);
            t.integer = integer;
            t.number = std::strtod(t.text.c_str(), nullptr);
            t.where = here(begin, i);
            out.push_back(std::move(t));
            continue;
        }
        if (word_start(c)) {
            while (i < s.size() && word_char(s[i])) ++i;
            // A trailing '-' belongs to no word (so "a-" is a word and a stray '-').
            while (i > begin + 1 && s[i - 1] == '-') --i;
            push(Tok::word, begin, i);
            continue;
        }
        if (c == '"') {
            std::string value;
            ++i;
            bool closed = false;
            while (i < s.size() && s[i] != '\n') {
                if (s[i] == '"') {
                    closed = true;
                    ++i;
                    break;
                }
                if (s[i] == '\\' && i + 1 < s.size()) {
                    const char e = s[i + 1];
                    value += e == 'n' ? '\n' : e == 't' ? '\t' : e;
                    i += 2;
                    continue;
                }
                value += s[i++];
            }
            if (!closed) {
                diags.error(here(begin, begin + 1), "unterminated string: add a closing '\"' on this line");
                push(Tok::bad, begin, i);
                continue;
            }
            push(Tok::string, begin, i, value);
            // keep the decoded value even if empty
            out.back().text = value;
            continue;
        }
        Tok kind = Tok::bad;
        switch (c) {
            case '(': kind = Tok::lparen; break;
            case ')': kind = Tok::rparen; break;
            case '[': kind = Tok::lbracket; break;
            case ']': kind = Tok::rbracket; break;
            case ',': kind = Tok::comma; break;
            case '=': kind = Tok::equals; break;
            case ':': kind = Tok::colon; break;
            case '.': kind = Tok::dot; break;
            default: break;
        }
        if (kind == Tok::bad) {
            // One UTF-8 character, whole, for the message.
            std::size_t end = i + 1;
            while (end < s.size() && (static_cast<unsigned char>(s[end]) & 0xC0) == 0x80) ++end;
            diags.error(here(i, end), "unexpected character '" + s.substr(i, end - i) + "'");
            push(Tok::bad, i, end);
            i = end;
            continue;
        }
        push(kind, i, i + 1);
        ++i;
    }
    Token eof;
    eof.kind = Tok::eof;
    eof.where = here(i, i + 1);
    out.push_back(eof);
    return out;
}

}  // namespace orogen::spec
