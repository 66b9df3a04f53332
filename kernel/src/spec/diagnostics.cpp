#include "diagnostics.hpp"

#include <algorithm>
#include <sstream>
#include <tuple>

namespace orogen::spec {

Source::Source(std::string n, std::string t, int o) : name(std::move(n)), text(std::move(t)), order(o) {
    line_starts.push_back(0);
    for (std::size_t i = 0; i < text.size(); ++i)
        if (text[i] == '\n') line_starts.push_back(i + 1);
}

std::string_view Source::line(int line_number) const {
    if (line_number < 1 || std::size_t(line_number) > line_starts.size()) return {};
    const std::size_t start = line_starts[std::size_t(line_number - 1)];
    std::size_t end = text.find('\n', start);
    if (end == std::string::npos) end = text.size();
    if (end > start && text[end - 1] == '\r') --end;
    return std::string_view(text).substr(start, end - start);
}

void Diagnostics::error(const Location& where, std::string message) {
    list_.push_back({Diagnostic::Severity::error, where, std::move(message)});
    ++errors_;
}
void Diagnostics::warning(const Location& where, std::string message) {
    list_.push_back({Diagnostic::Severity::warning, where, std::move(message)});
}
void Diagnostics::note(const Location& where, std::string message) {
    list_.push_back({Diagnostic::Severity::note, where, std::move(message)});
}

std::string format(const Diagnostic& d) {
    std::ostringstream out;
    const char* sev = d.severity == Diagnostic::Severity::error ? "error"
        : d.severity == Diagnostic::Severity::warning           ? "warning"
                                                                : "note";
    if (!d.where.source) {
        out << "orogen: " << sev << ": " << d.message << "\n";
        return out.str();
    }
    out << d.where.source->name << ":" << d.where.line << ":" << d.where.column << ": " << sev << ": " << d.message
        << "\n";
    const std::string_view text = d.where.source->line(d.where.line);
    bool printable = d.where.length >
        0;  // length 0: a place with no text worth showing  // a binary file's "line" is noise: say where, do not echo it
    for (unsigned char c : text) printable = printable && (c >= 0x20 || c == '\t') && c != 0x7f;
    if (printable) {
        out << "  " << text << "\n  ";
        // Keep tabs so the caret lines up under tab-indented text.
        for (int i = 1; i < d.where.column; ++i)
            out << (std::size_t(i - 1) < text.size() && text[std::size_t(i - 1)] == '\t' ? '\t' : ' ');
        out << '^';
        for (int i = 1; i < d.where.length; ++i) out << '~';
        out << "\n";
    }
    return out.str();
}

std::string Diagnostics::format() const {
    // In source order, whatever order the checks ran in.
    auto rank = [](const Diagnostic& d) {
        return std::make_tuple(d.where.source ? d.where.source->order : -1, d.where.line, d.where.column);
    };
    std::vector<const Diagnostic*> sorted;
    for (const auto& d : list_) sorted.push_back(&d);
    std::stable_sort(sorted.begin(), sorted.end(), [&](auto* a, auto* b) { return rank(*a) < rank(*b); });
    std::string s;
    for (const auto* d : sorted) s += spec::format(*d);
    return s;
}

namespace {
std::size_t edit_distance(std::string_view a, std::string_view b) {
    // Optimal string alignment distance (Damerau–Levenshtein with adjacent transpositions).
    std::vector<std::vector<std::size_t>> d(a.size() + 1, std::vector<std::size_t>(b.size() + 1));
    for (std::size_t i = 0; i <= a.size(); ++i) d[i][0] = i;
    for (std::size_t j = 0; j <= b.size(); ++j) d[0][j] = j;
    for (std::size_t i = 1; i <= a.size(); ++i)
        for (std::size_t j = 1; j <= b.size(); ++j) {
            const std::size_t cost = a[i - 1] == b[j - 1] ? 0 : 1;
            d[i][j] = std::min({d[i - 1][j] + 1, d[i][j - 1] + 1, d[i - 1][j - 1] + cost});
            if (i > 1 && j > 1 && a[i - 1] == b[j - 2] && a[i - 2] == b[j - 1])
                d[i][j] = std::min(d[i][j], d[i - 2][j - 2] + 1);
        }
    return d[a.size()][b.size()];
}
}  // namespace

std::string closest(std::string_view word, const std::vector<std::string>& candidates) {
    std::string best;
    std::size_t best_distance = std::max<std::size_t>(2, word.size() / 3) + 1;
    for (const auto& c : candidates) {
        const std::size_t dist = edit_distance(word, c);
        if (dist < best_distance) {
            best_distance = dist;
            best = c;
        }
    }
    return best;
}

}  // namespace orogen::spec
