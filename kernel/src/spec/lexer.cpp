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

/// One pass over a spec's text: each token kind is read by its own step, from `i` onwards.
class Lexer {
public:
    Lexer(const std::shared_ptr<const Source>& source, Diagnostics& diags, bool comments)
        : source_(source), s_(source->text), diags_(diags), comments_(comments) {}

    std::vector<Token> run() {
        if (binary()) return std::move(out_);
        while (i_ < s_.size()) step();
        Token eof;
        eof.kind = Tok::eof;
        eof.where = here(i_, i_ + 1);
        out_.push_back(eof);
        return std::move(out_);
    }

private:
    const std::shared_ptr<const Source>& source_;
    const std::string& s_;
    Diagnostics& diags_;
    const bool comments_;  // '#' starts a comment (true) or is the label's number sign (kind:node#2)
    std::vector<Token> out_;
    std::size_t i_ = 0;
    int line_ = 1;
    std::size_t line_start_ = 0;

    Location here(std::size_t begin, std::size_t end) const {
        return Location{source_, line_, int(begin - line_start_) + 1, int(std::max<std::size_t>(1, end - begin))};
    }
    void push(Tok kind, std::size_t begin, std::size_t end, std::string text = {}) {
        Token t;
        t.kind = kind;
        t.text = text.empty() ? s_.substr(begin, end - begin) : std::move(text);
        t.where = here(begin, end);
        out_.push_back(std::move(t));
    }
    void push_number(std::size_t begin, std::size_t end, bool integer) {
        Token t;
        t.kind = Tok::number;
        t.text = s_.substr(begin, end - begin);
        t.integer = integer;
        t.number = std::strtod(t.text.c_str(), nullptr);
        t.where = here(begin, end);
        out_.push_back(std::move(t));
    }
    bool digit_at(std::size_t k) const { return k < s_.size() && digit(s_[k]); }
    void skip_digits() {
        while (digit_at(i_)) ++i_;
    }

    /// A binary file (an image, an executable) passed by mistake: one error, not hundreds.
    bool binary() {
        for (std::size_t k = 0; k < s_.size() && k < (1u << 20); ++k) {
            const auto b = static_cast<unsigned char>(s_[k]);
            if ((b < 0x20 && b != '\n' && b != '\t' && b != '\r') || b == 0x7f) {
                char hex[8];
                std::snprintf(hex, sizeof hex, "0x%02x", b);
                diags_.error(Location{source_, 1, 1, 0},
                             "this is not a text spec: byte " + std::to_string(k) + " is " + hex +
                                 ", a control character; is it a binary file?");
                Token bad;
                bad.kind = Tok::bad;
                bad.where = Location{source_, 1, 1, 1};
                out_.push_back(bad);
                Token eof;
                eof.where = bad.where;
                out_.push_back(eof);
                return true;
            }
        }
        return false;
    }

    /// The next token (or blank, newline or comment) from i_.
    void step() {
        const char c = s_[i_];
        if (c == '\n') {
            push(Tok::newline, i_, i_ + 1, "\n");  // the parser skips it inside ( ) and [ ]
            ++i_;
            ++line_;
            line_start_ = i_;
        } else if (c == ' ' || c == '\t' || c == '\r') {
            ++i_;
        } else if (c == '#' && !comments_) {
            label_number();
        } else if (c == '#') {
            while (i_ < s_.size() && s_[i_] != '\n') ++i_;
        } else if (starts_number()) {
            number();
        } else if (word_start(c)) {
            word();
        } else if (c == '"') {
            string();
        } else {
            punctuation();
        }
    }

    /// kind:node#2: the label's number is digits only ("2." is not a number here).
    void label_number() {
        push(Tok::hash, i_, i_ + 1);
        const std::size_t digits = ++i_;
        skip_digits();
        if (i_ > digits) push_number(digits, i_, true);
    }

    /// A digit, or a sign or '.' before a digit (".5", "-.5").
    bool starts_number() const {
        const char c = s_[i_];
        if (digit(c)) return true;
        if (c != '-' && c != '+' && c != '.') return false;
        return digit_at(i_ + 1) || (i_ + 1 < s_.size() && s_[i_ + 1] == '.' && digit_at(i_ + 2));
    }

    /// [sign] digits [. digits] [e [sign] digits]; an integer when it has neither '.' nor an exponent.
    void number() {
        const std::size_t begin = i_;
        if (s_[i_] == '-' || s_[i_] == '+') ++i_;
        bool integer = true;
        skip_digits();
        if (i_ < s_.size() && s_[i_] == '.') {
            integer = false;
            ++i_;
            skip_digits();
        }
        if (i_ < s_.size() && (s_[i_] == 'e' || s_[i_] == 'E') &&
            (digit_at(i_ + 1) ||
             (i_ + 1 < s_.size() && (s_[i_ + 1] == '-' || s_[i_ + 1] == '+') && digit_at(i_ + 2)))) {
            integer = false;
            i_ += 2;
            skip_digits();
        }
        push_number(begin, i_, integer);
    }

    void word() {
        const std::size_t begin = i_;
        while (i_ < s_.size() && word_char(s_[i_])) ++i_;
        // A trailing '-' belongs to no word (so "a-" is a word and a stray '-').
        while (i_ > begin + 1 && s_[i_ - 1] == '-') --i_;
        push(Tok::word, begin, i_);
    }

    /// "...", on one line, with \n, \t and \<char> escapes; the token's text is the decoded value.
    void string() {
        const std::size_t begin = i_;
        std::string value;
        ++i_;
        bool closed = false;
        while (i_ < s_.size() && s_[i_] != '\n') {
            if (s_[i_] == '"') {
                closed = true;
                ++i_;
                break;
            }
            if (s_[i_] == '\\' && i_ + 1 < s_.size()) {
                const char e = s_[i_ + 1];
                value += e == 'n' ? '\n' : e == 't' ? '\t' : e;
                i_ += 2;
                continue;
            }
            value += s_[i_++];
        }
        if (!closed) {
            diags_.error(here(begin, begin + 1), "unterminated string: add a closing '\"' on this line");
            push(Tok::bad, begin, i_);
            return;
        }
        push(Tok::string, begin, i_, value);
        out_.back().text = value;  // keep the decoded value even if empty
    }

    void punctuation() {
        Tok kind = Tok::bad;
        switch (s_[i_]) {
            case '(': kind = Tok::lparen; break;
            case ')': kind = Tok::rparen; break;
            case '[': kind = Tok::lbracket; break;
            case ']': kind = Tok::rbracket; break;
            case '{': kind = Tok::lbrace; break;
            case '}': kind = Tok::rbrace; break;
            case ',': kind = Tok::comma; break;
            case '=': kind = Tok::equals; break;
            case ':': kind = Tok::colon; break;
            case '.': kind = Tok::dot; break;
            default: break;
        }
        if (kind == Tok::bad) {
            // One UTF-8 character, whole, for the message.
            std::size_t end = i_ + 1;
            while (end < s_.size() && (static_cast<unsigned char>(s_[end]) & 0xC0) == 0x80) ++end;
            diags_.error(here(i_, end), "unexpected character '" + s_.substr(i_, end - i_) + "'");
            push(Tok::bad, i_, end);
            i_ = end;
            return;
        }
        push(kind, i_, i_ + 1);
        ++i_;
    }
};

}  // namespace

std::vector<Token> lex(const std::shared_ptr<const Source>& source, Diagnostics& diags, bool comments) {
    return Lexer(source, diags, comments).run();
}

}  // namespace orogen::spec
