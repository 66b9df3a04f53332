// Diagnostics: every error names file:line:col, prints the source line and a
// caret under the token (LLVM's SourceMgr format), and all errors of a phase
// are reported together.
#pragma once

#include <memory>
#include <string>
#include <string_view>
#include <vector>

namespace orogen::spec {

/// A spec's text with its name ("alps.orogen", or "--set" for overrides).
struct Source {
    std::string name;
    std::string text;
    std::vector<std::size_t> line_starts;  ///< offset of each line's first character
    int order = 0;  ///< diagnostics are listed by (order, line, column): the spec 0, each --set after it

    Source(std::string name, std::string text, int order = 0);
    std::string_view line(int line_number) const;  ///< 1-based, without the newline
};

/// A place in a source: 1-based line and column (in bytes), and the length to
/// underline (0: print no source line, e.g. for a binary file).
struct Location {
    std::shared_ptr<const Source> source;
    int line = 0;
    int column = 0;
    int length = 1;
};

struct Diagnostic {
    enum class Severity { error, warning, note };
    Severity severity = Severity::error;
    Location where;
    std::string message;
};

class Diagnostics {
public:
    void error(const Location& where, std::string message);
    void warning(const Location& where, std::string message);
    void note(const Location& where, std::string message);
    bool has_errors() const { return errors_ > 0; }
    int error_count() const { return errors_; }
    const std::vector<Diagnostic>& all() const { return list_; }
    /// "file:3:7: error: message\n  line text\n        ^~~~\n" for each, in order.
    std::string format() const;

private:
    std::vector<Diagnostic> list_;
    int errors_ = 0;
};

/// One diagnostic, formatted.
std::string format(const Diagnostic& d);

/// The closest candidate to `word` (Damerau–Levenshtein), or "" if none is close.
std::string closest(std::string_view word, const std::vector<std::string>& candidates);

}  // namespace orogen::spec
