#include "spec.hpp"

#include <algorithm>
#include <cerrno>

#include <cmath>

namespace orogen::spec {

std::string describe(const Literal& l) {
    switch (l.kind) {
        case Literal::Kind::number: return (l.integer ? "the integer " : "the number ") + l.text;
        case Literal::Kind::string: return "the string \"" + l.text + "\"";
        case Literal::Kind::boolean: return l.boolean ? "true" : "false";
        case Literal::Kind::word: return "the word '" + l.text + "'";
        case Literal::Kind::point: return "a point";
        case Literal::Kind::list: return "a list";
    }
    return "a value";
}

namespace {

class Parser {
public:
    Parser(std::vector<Token> tokens, Diagnostics& diags) : t_(std::move(tokens)), diags_(diags) {}

    Spec parse_spec(const std::shared_ptr<const Source>& source) {
        Spec spec;
        spec.source = source;
        while (peek().kind != Tok::eof) {
            if (peek().kind == Tok::newline) {
                ++p_;
                continue;
            }
            const std::size_t errors_before = std::size_t(diags_.error_count());
            const Token& first = peek();
            const bool header = first.kind == Tok::word && peek(1).kind != Tok::equals && peek(1).kind != Tok::colon;
            statement(spec);
            if (std::size_t(diags_.error_count()) != errors_before) {
                spec.broken = true;
                spec.broken_header |= header;
                recover();
                continue;
            }
            if (peek().kind != Tok::newline && peek().kind != Tok::eof) {
                error(peek(), "expected the end of the line after this statement, found " + what(peek()));
                skip_line();
            }
        }
        return spec;
    }

    std::optional<Override> parse_override() {
        Override o;
        const Token& name = peek();
        if (name.kind != Tok::word) {
            error(name, "expected NAME.PARAM=VALUE, e.g. --set rivers.steps=500");
            return std::nullopt;
        }
        o.target = name.text;
        o.target_where = name.where;
        ++p_;
        // An unnamed node, by its label in the timing table: export:video, export:png#2.
        if (peek().kind == Tok::colon) {
            ++p_;
            if (peek().kind != Tok::word) {
                error(peek(),
                      "expected the node's name after '" + name.text +
                          ":' (an unnamed node is set by its label, e.g. --set export:png#2.bits=8)");
                return std::nullopt;
            }
            o.target += ":" + peek().text;
            ++p_;
            if (!label_number(o.target,
                              "expected the label's number after '#' (kind:node#2 is the second unnamed "
                              "kind:node)"))
                return std::nullopt;
            o.target_where.length = t_[p_ - 1].where.column + t_[p_ - 1].where.length - name.where.column;
        }
        if (!expect(Tok::dot,
                    "'.' between the value name and the parameter (NAME.PARAM=VALUE; an unnamed node by "
                    "its label, e.g. export:png#2.bits=8)"))
            return std::nullopt;
        const Token& param = peek();
        if (param.kind != Tok::word) {
            error(param, "expected a parameter name after '.'");
            return std::nullopt;
        }
        o.param = param.text;
        o.param_where = param.where;
        ++p_;
        if (peek().kind == Tok::hash || peek().kind == Tok::dot) {  // NAME.PROCESS[#N].PARAM
            o.process = o.param;
            o.process_where = o.param_where;
            if (!label_number(o.process,
                              "expected the process's number after '#' (stream-power#2 is the second "
                              "stream-power)"))
                return std::nullopt;
            o.process_where.length = t_[p_ - 1].where.column + t_[p_ - 1].where.length - o.process_where.column;
            if (!expect(Tok::dot, "'.' between the process and its parameter (NAME.PROCESS.PARAM=VALUE)"))
                return std::nullopt;
            const Token& inner = peek();
            if (inner.kind != Tok::word) {
                error(inner, "expected a parameter name after '" + o.process + ".'");
                return std::nullopt;
            }
            o.param = inner.text;
            o.param_where = inner.where;
            ++p_;
        }
        if (!expect(Tok::equals, "'=' and a value (NAME.PARAM=VALUE)")) return std::nullopt;
        auto value = literal();
        if (!value) return std::nullopt;
        o.value = std::move(*value);
        if (peek().kind != Tok::eof && peek().kind != Tok::newline) {
            error(peek(), "unexpected " + what(peek()) + " after the value");
            return std::nullopt;
        }
        return o;
    }

private:
    /// An override's label number, `#N` (N >= 2), appended to `label` if one follows; false (reported with
    /// `message`) if the '#' has no such number after it.
    bool label_number(std::string& label, const std::string& message) {
        if (peek().kind != Tok::hash) return true;
        ++p_;
        const Token& n = peek();
        if (n.kind != Tok::number || !n.integer || n.number < 2 || n.text[0] == '+') {
            error(n, message);
            return false;
        }
        label += "#" + n.text;
        ++p_;
        return true;
    }

    const Token& peek(std::size_t ahead = 0) const { return t_[std::min(p_ + ahead, t_.size() - 1)]; }
    const Token& next() { return t_[std::min(p_++, t_.size() - 1)]; }
    void skip_line() {
        while (peek().kind != Tok::newline && peek().kind != Tok::eof) ++p_;
    }
    /// After an error: skip to the next line that starts a statement, so a
    /// broken multi-line call does not produce one error per line.
    void recover() {
        while (peek().kind != Tok::eof) {
            if (peek().kind == Tok::newline && starts_statement(p_ + 1)) {
                ++p_;
                return;
            }
            ++p_;
        }
    }
    /// NAME = kind:node  |  kind:node(  |  orogen/seed/grid at the start of a line.
    bool starts_statement(std::size_t at) const {
        const Token& a = peek(at - p_);
        if (a.kind != Tok::word) return false;
        const Tok b = peek(at - p_ + 1).kind, c = peek(at - p_ + 2).kind, d = peek(at - p_ + 3).kind;
        if (b == Tok::equals && c == Tok::word && d == Tok::colon) return true;
        if (b == Tok::colon && c == Tok::word && d == Tok::lparen) return true;
        return a.where.column == 1 && (a.text == "orogen" || a.text == "seed" || a.text == "grid");
    }
    /// Whether the kind:node(...) call starting at token `at` is followed, after its ')', by ',' or ')': then it
    /// stands where an input goes, else it is a statement of its own.
    bool call_in_place(std::size_t at) const {
        if (peek(at - p_ + 1).kind != Tok::colon || peek(at - p_ + 3).kind != Tok::lparen) return false;
        std::size_t i = at + 3;
        for (int depth = 0; i < t_.size(); ++i) {
            if (t_[i].kind == Tok::lparen) ++depth;
            else if (t_[i].kind == Tok::rparen && --depth == 0) break;
            else if (t_[i].kind == Tok::eof) return false;
        }
        for (++i; i < t_.size() && t_[i].kind == Tok::newline; ++i) {}
        return i < t_.size() && (t_[i].kind == Tok::comma || t_[i].kind == Tok::rparen);
    }
    void skip_newlines() {
        while (peek().kind == Tok::newline) ++p_;
    }
    void error(const Token& at, std::string message) {
        if (at.kind == Tok::bad) return;  // the lexer has said it already
        diags_.error(at.where, std::move(message));
    }
    static std::string what(const Token& t) {
        switch (t.kind) {
            case Tok::word: return "'" + t.text + "'";
            case Tok::number: return "the number " + t.text;
            case Tok::string: return "a string";
            case Tok::newline: return "the end of the line";
            case Tok::eof: return "the end of the file";
            default: return "'" + t.text + "'";
        }
    }
    bool expect(Tok kind, const std::string& wanted) {
        if (peek().kind == kind) {
            ++p_;
            return true;
        }
        error(peek(), "expected " + wanted + ", found " + what(peek()));
        return false;
    }

    void statement(Spec& spec) {
        const Token& first = peek();
        if (first.kind != Tok::word) {
            error(first,
                  "expected a statement (orogen, seed, grid, NAME = kind:node(...), or kind:node(...)), found " +
                      what(first));
            return;
        }
        if (peek(1).kind == Tok::equals) {  // NAME = call
            Statement st;
            st.name = first.text;
            st.name_where = first.where;
            p_ += 2;
            if (auto call = parse_call(spec)) {
                if (peek().kind == Tok::lbrace) parse_body(*call);
                st.call = std::move(*call);
                spec.statements.push_back(std::move(st));
            } else {
                spec.broken_names.push_back(st.name);
            }
            return;
        }
        if (peek(1).kind == Tok::colon) {  // unnamed call
            if (auto call = parse_call(spec)) {
                if (peek().kind == Tok::lbrace) parse_body(*call);
                spec.statements.push_back(Statement{"", {}, std::move(*call)});
            }
            return;
        }
        if (first.text == "orogen") {
            ++p_;
            const Token& v = peek();
            if (v.kind != Tok::number || !v.integer) {
                error(v, "expected the format version after 'orogen' (this orogen reads `orogen 1`)");
                return;
            }
            ++p_;
            if (spec.version) {
                error(first, "the format version is given twice");
                return;
            }
            if (!(v.number >= 0 && v.number <= 1e9)) {  // would not fit an int (found by fuzz_spec)
                error(v, "format version " + v.text + " is not supported; this orogen reads `orogen 1`");
                return;
            }
            spec.version = int(v.number);
            spec.version_where = v.where;
            return;
        }
        if (first.text == "seed") {
            ++p_;
            const Token& v = peek();
            if (v.kind != Tok::number || !v.integer || v.number < 0 || v.number > 18446744073709551615.0) {
                error(v, "expected a whole number from 0 to 2^64-1 after 'seed', found " + what(v));
                return;
            }
            ++p_;
            if (spec.seed) {
                error(first, "the seed is given twice");
                return;
            }
            // 18446744073709551616 rounds to the same double as 2^64-1: strtoull tells them apart.
            const std::string digits = v.text[0] == '+' ? v.text.substr(1) : v.text;
            errno = 0;
            const unsigned long long seed = std::strtoull(digits.c_str(), nullptr, 10);
            if (errno == ERANGE || digits.find_first_not_of("0123456789") != std::string::npos) {
                error(v, "expected a whole number from 0 to 2^64-1 after 'seed', found " + what(v));
                return;
            }
            spec.seed = seed;
            spec.seed_where = v.where;
            return;
        }
        if (first.text == "grid") {
            grid(spec);
            return;
        }
        if (peek(1).kind == Tok::lparen) {
            error(first, "a node is called as kind:node(...), e.g. generate:" + first.text + "(...)");
            return;
        }
        error(first,
              "unknown statement '" + first.text +
                  "'; expected orogen, seed, grid, NAME = kind:node(...), or kind:node(...)");
    }

    void grid(Spec& spec) {
        const Token& kw = next();
        if (spec.has_grid) {
            error(kw, "the grid is given twice");
            return;
        }
        const Token& w = peek();
        if (w.kind != Tok::number || !w.integer) {
            error(w, "expected the grid size in vertices after 'grid', e.g. `grid 513 cell=30` or `grid 513x257`");
            return;
        }
        ++p_;
        double width = w.number, height = w.number;
        // "513x257" lexes as the number 513 and the word x257, written without a space.
        const Token& x = peek();
        if (x.kind == Tok::word && x.where.line == w.where.line && x.where.column == w.where.column + w.where.length &&
            x.text.size() > 1 && x.text[0] == 'x' && x.text.find_first_not_of("0123456789", 1) == std::string::npos) {
            height = std::strtod(x.text.c_str() + 1, nullptr);  // HUGE_VAL for 400 digits, not an exception
            ++p_;
        }
        spec.has_grid = true;
        spec.grid_where = w.where;
        spec.grid_where.length = t_[p_ - 1].where.column + t_[p_ - 1].where.length - w.where.column;
        if (width < 2 || height < 2) {
            // Either side may be any number the lexer accepted (1e27, or HUGE_VAL from 400 digits): clamp before
            // converting, since a double outside long's range is undefined behaviour (found by fuzz_spec).
            const auto side = [](double v) { return std::to_string(long(std::clamp(v, -1e18, 1e18))); };
            diags_.error(spec.grid_where,
                         "the grid needs at least 2 vertices a side, got " + side(width) + "x" + side(height));
            return;
        }
        spec.grid_width = width > 2e9 ? 2000000000 : int(width);
        spec.grid_height = height > 2e9 ? 2000000000 : int(height);
        while (peek().kind == Tok::word) {
            const Token& key = next();
            if (!expect(Tok::equals, "'=' after '" + key.text + "'")) return;
            const Token& value = peek();
            if (key.text != "cell") {
                error(key, "unknown grid option '" + key.text + "'; the grid takes cell=METRES");
                return;
            }
            if (value.kind != Tok::number || !(value.number > 0) || !std::isfinite(value.number)) {
                error(value, "cell must be a positive number of metres, found " + what(value));
                return;
            }
            ++p_;
            spec.grid_cell = value.number;
            spec.has_cell = true;
        }
    }

    /// A call; calls written where an input goes are appended to spec.statements first.
    std::optional<Call> parse_call(Spec& spec) {
        Call call;
        const Token& kind = peek();
        if (kind.kind != Tok::word) {
            error(kind, "expected a node call kind:node(...), found " + what(kind));
            return std::nullopt;
        }
        ++p_;
        if (!expect(Tok::colon, "':' between the node's kind and name (e.g. generate:fault)")) return std::nullopt;
        const Token& node = peek();
        if (node.kind != Tok::word) {
            error(node, "expected the node's name after '" + kind.text + ":'");
            return std::nullopt;
        }
        ++p_;
        call.kind = kind.text;
        call.node = node.text;
        call.where = kind.where;
        call.where.length = node.where.column + node.where.length - kind.where.column;
        const Token& open = peek();
        if (!expect(
                Tok::lparen,
                "'(' after " + call.qualified() + " (a call with no arguments is written " + call.qualified() + "())"))
            return std::nullopt;
        // Inside ( ) newlines do not end a statement, so a missing ')' shows up lines later:
        // then point at the '(' that was never closed.
        // (A kind:node(...) on a later line followed by ',' or ')' is an input made in place, not the next statement.)
        auto unclosed = [&](const Token& at) {
            if (at.kind == Tok::eof ||
                (at.where.line > open.where.line && starts_statement(p_) && !call_in_place(p_))) {
                diags_.error(open.where, "this '(' of the call to " + call.qualified() + " is never closed; add ')'");
                return true;
            }
            return false;
        };
        skip_newlines();
        if (peek().kind == Tok::rparen) {
            ++p_;
            return call;
        }
        bool seen_param = false;
        while (true) {
            skip_newlines();
            const Token& a = peek();
            if (unclosed(a)) return std::nullopt;
            if (a.kind != Tok::word) {
                error(a, "expected an input name or key=value, found " + what(a));
                return std::nullopt;
            }
            if (peek(1).kind == Tok::equals) {
                p_ += 2;
                skip_newlines();
                auto value = literal();
                if (!value) return std::nullopt;
                if (value->kind == Literal::Kind::word && peek().kind == Tok::dot) {
                    diags_.error(value->where,
                                 "a value with a '.' in it is a string: write it in quotes, " + a.text + "=\"" +
                                     value->text + "." + (peek(1).kind == Tok::word ? peek(1).text : "") + "\"");
                    return std::nullopt;
                }
                call.params.push_back(Argument{a.text, a.where, std::move(*value)});
                seen_param = true;
            } else {
                if (seen_param) {
                    error(a, "inputs come first: move input '" + a.text + "' before the key=value parameters");
                    return std::nullopt;
                }
                Input in{a.text, "", a.where};
                if (peek(1).kind == Tok::colon) {  // a call where a value goes: hoisted before this statement
                    if (nesting_ >= kMaxNesting) {  // (a bound on the recursion, whatever the input)
                        error(a,
                              "calls are nested more than " + std::to_string(kMaxNesting) +
                                  " deep here; name some of the values on lines of their own");
                        return std::nullopt;
                    }
                    ++nesting_;
                    auto inner = parse_call(spec);
                    --nesting_;
                    if (!inner) return std::nullopt;
                    if (peek().kind == Tok::dot) {
                        error(peek(),
                              "to use a side value of " + inner->qualified() + ", name the value first: NAME = " +
                                  inner->qualified() + "(...) on a line of its own, then NAME." +
                                  (peek(1).kind == Tok::word ? peek(1).text : "SIDE"));
                        return std::nullopt;
                    }
                    in.name = inner->qualified() + "(...)";
                    in.where = inner->where;
                    spec.statements.push_back(Statement{"", {}, std::move(*inner), true});
                    in.statement = int(spec.statements.size()) - 1;
                } else if (++p_; peek().kind == Tok::dot) {
                    ++p_;
                    const Token& side = peek();
                    if (side.kind != Tok::word) {
                        error(side, "expected a side value's name after '" + a.text + ".'");
                        return std::nullopt;
                    }
                    ++p_;
                    in.side = side.text;
                    in.where.length = side.where.column + side.where.length - a.where.column;
                }
                call.inputs.push_back(std::move(in));
            }
            skip_newlines();
            if (peek().kind == Tok::comma) {
                ++p_;
                continue;
            }
            if (peek().kind == Tok::rparen) {
                ++p_;
                return call;
            }
            if (unclosed(peek())) return std::nullopt;
            error(peek(), "expected ',' or ')' in the call to " + call.qualified() + ", found " + what(peek()));
            return std::nullopt;
        }
    }

    /// A loop node's body: "{", one process a line, "}". A mistake in one process is reported and the
    /// next line is read, so every process's mistakes show at once.
    void parse_body(Call& call) {
        const Token& open = next();
        call.has_body = true;
        call.body_where = open.where;
        while (true) {
            const Token& t = peek();
            if (t.kind == Tok::newline) {
                ++p_;
                continue;
            }
            if (t.kind == Tok::rbrace) {
                ++p_;
                return;
            }
            if (t.kind == Tok::eof ||
                (t.where.line > open.where.line && starts_statement(p_) && !body_closes_before_next_named(p_))) {
                diags_.error(
                    open.where,
                    "this '{' of " + call.qualified() + "'s processes is never closed; add '}' after the last process");
                call.body_broken = true;
                return;
            }
            const int errors_before = diags_.error_count();
            auto process = parse_process();
            const bool at_line_end =
                peek().kind == Tok::newline || peek().kind == Tok::rbrace || peek().kind == Tok::eof;
            if (process && !at_line_end)
                error(peek(),
                      "expected the end of the line after this process (one process a line), found " + what(peek()));
            if (process && at_line_end) call.body.push_back(std::move(*process));
            // After a mistake (reported here, or by the lexer at a bad token: then nothing was counted), go on
            // at the next line, so every process's mistakes show at once and the loop always moves on.
            if (!process || !at_line_end || diags_.error_count() != errors_before) call.body_broken = true;
            if (!process || !at_line_end || diags_.error_count() != errors_before)
                while (peek().kind != Tok::newline && peek().kind != Tok::rbrace && peek().kind != Tok::eof) ++p_;
        }
    }

    /// Whether a '}' comes before the next `NAME = ...` statement (or the end): then a `kind:node(` line at
    /// `at` is a mistake inside a body (a process written with a kind), not the statement after an unclosed one.
    bool body_closes_before_next_named(std::size_t at) const {
        for (std::size_t i = at; i < t_.size(); ++i) {
            if (t_[i].kind == Tok::rbrace) return true;
            if (t_[i].kind == Tok::eof) return false;
            if (t_[i].kind == Tok::newline && i + 2 < t_.size() && t_[i + 1].kind == Tok::word &&
                t_[i + 2].kind == Tok::equals)
                return false;
        }
        return false;
    }

    /// name(key=value, ...) in a body.
    std::optional<ProcessCallSyntax> parse_process() {
        const Token& name = peek();
        if (name.kind != Tok::word) {
            error(name, "expected a process, e.g. stream-power(erodibility=2e-5), found " + what(name));
            return std::nullopt;
        }
        ++p_;
        if (peek().kind == Tok::colon) {
            error(peek(),
                  "a process is called by its name alone, without a kind: write " +
                      (peek(1).kind == Tok::word ? peek(1).text : name.text) + "(...)");
            return std::nullopt;
        }
        ProcessCallSyntax process{name.text, name.where, {}};
        if (!expect(Tok::lparen, "'(' after the process " + name.text + " (with no parameters: " + name.text + "())"))
            return std::nullopt;
        skip_newlines();
        if (peek().kind == Tok::rparen) {
            ++p_;
            return process;
        }
        while (true) {
            skip_newlines();
            const Token& key = peek();
            if (key.kind != Tok::word || peek(1).kind != Tok::equals) {
                error(key,
                      "a process takes key=value parameters only (it reads the loop's fields, not values), found " +
                          what(key));
                return std::nullopt;
            }
            p_ += 2;
            skip_newlines();
            auto value = literal();
            if (!value) return std::nullopt;
            process.params.push_back(Argument{key.text, key.where, std::move(*value)});
            skip_newlines();
            if (peek().kind == Tok::comma) {
                ++p_;
                continue;
            }
            if (peek().kind == Tok::rparen) {
                ++p_;
                return process;
            }
            error(peek(), "expected ',' or ')' in the process " + process.name + ", found " + what(peek()));
            return std::nullopt;
        }
    }

    std::optional<Literal> literal() {
        const Token& t = peek();
        Literal l;
        l.where = t.where;
        switch (t.kind) {
            case Tok::number:
                ++p_;
                l.kind = Literal::Kind::number;
                l.number = t.number;
                l.integer = t.integer;
                l.text = t.text;
                return l;
            case Tok::string:
                ++p_;
                l.kind = Literal::Kind::string;
                l.text = t.text;
                return l;
            case Tok::word:
                ++p_;
                if (t.text == "true" || t.text == "false") {
                    l.kind = Literal::Kind::boolean;
                    l.boolean = t.text == "true";
                } else {
                    l.kind = Literal::Kind::word;
                }
                l.text = t.text;
                return l;
            case Tok::lparen: {
                ++p_;
                l.kind = Literal::Kind::point;
                for (int i = 0; i < 2; ++i) {
                    const Token& n = peek();
                    if (n.kind != Tok::number) {
                        error(n, "a point is written (x, y) with two numbers, found " + what(n));
                        return std::nullopt;
                    }
                    ++p_;
                    Literal c;
                    c.kind = Literal::Kind::number;
                    c.where = n.where;
                    c.number = n.number;
                    c.integer = n.integer;
                    c.text = n.text;
                    l.items.push_back(c);
                    if (i == 0 && !expect(Tok::comma, "',' between the point's x and y")) return std::nullopt;
                }
                if (!expect(Tok::rparen, "')' closing the point (x, y)")) return std::nullopt;
                l.where.length = std::max(1, t_[p_ - 1].where.column + 1 - t.where.column);
                return l;
            }
            case Tok::lbracket: {
                ++p_;
                l.kind = Literal::Kind::list;
                skip_newlines();
                if (peek().kind == Tok::rbracket) {
                    ++p_;
                    return l;
                }
                while (true) {
                    skip_newlines();
                    auto item = literal();
                    if (!item) return std::nullopt;
                    l.items.push_back(std::move(*item));
                    skip_newlines();
                    if (peek().kind == Tok::comma) {
                        ++p_;
                        continue;
                    }
                    if (!expect(Tok::rbracket, "',' or ']' in the list")) return std::nullopt;
                    if (t_[p_ - 1].where.line == t.where.line)
                        l.where.length = std::max(1, t_[p_ - 1].where.column + 1 - t.where.column);
                    return l;
                }
            }
            default:
                error(
                    t,
                    "expected a value (a number, \"string\", true/false, a word, (x, y) or [list]), found " + what(t));
                return std::nullopt;
        }
    }

    static constexpr int kMaxNesting = 64;
    std::vector<Token> t_;
    std::size_t p_ = 0;
    int nesting_ = 0;  ///< calls written where inputs go, around the one being parsed
    Diagnostics& diags_;
};

}  // namespace

Spec parse(const std::shared_ptr<const Source>& source, Diagnostics& diags) {
    const int errors_before = diags.error_count();
    std::vector<Token> tokens = lex(source, diags);
    // A file the lexer refused whole (a binary file: one bad token) has no header to look for.
    const bool refused = tokens.size() == 2 && tokens.front().kind == Tok::bad;
    Parser parser(std::move(tokens), diags);
    Spec spec = parser.parse_spec(source);
    spec.broken |= diags.error_count() != errors_before;
    spec.broken_header |= refused;
    return spec;
}

std::optional<Override> parse_override(const std::shared_ptr<const Source>& source, Diagnostics& diags) {
    Parser parser(lex(source, diags, /*comments=*/false), diags);
    if (diags.has_errors()) return std::nullopt;
    return parser.parse_override();
}

}  // namespace orogen::spec
