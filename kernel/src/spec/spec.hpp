// The pipeline spec language: tokens, syntax tree, lexer and parser.
//
//   spec       := { [statement] [# comment] newline }
//   statement  := "orogen" INT                      format version (1)
//               | "seed" INT
//               | "grid" INT ["x" INT] { key "=" literal }     vertices; grid 513 cell=30
//               | name "=" call                     a named value
//               | call                              (an exporter, usually)
//   call       := kind ":" node "(" [ arg { "," arg } ] ")" [ body ]   newlines allowed inside ( ) and [ ]
//   body       := "{" { [process] [# comment] newline } "}"      a loop node's processes (orogen/process.hpp)
//   process    := name "(" [ key "=" literal { "," key "=" literal } ] ")"   one a line, run in this order
//   arg        := ref                               an input: a value name, or name.side
//               | call                              an input made in place: export:png(render:bloom(x), ...)
//               | key "=" literal                   a parameter
//   literal    := number | "string" | true | false | word | point | list
//   point      := "(" number "," number ")"
//   list       := "[" [ literal { "," literal } ] "]"
//
// Words and names may contain letters, digits, '_' and '-' (von-neumann).
// A call written where an input goes is hoisted into a statement of its own
// just before the one that reads it (Statement::nested): it is an unnamed
// call, labelled kind:node (#2, #3...) like an exporter.
#pragma once

#include "diagnostics.hpp"

#include <optional>
#include <string>
#include <vector>

namespace orogen::spec {

enum class Tok {
    word,
    number,
    string,
    lparen,
    rparen,
    lbracket,
    rbracket,
    lbrace,
    rbrace,
    comma,
    equals,
    colon,
    dot,
    hash,
    newline,
    eof,
    bad
};

struct Token {
    Tok kind = Tok::eof;
    std::string text;  ///< as written (strings: the decoded value)
    double number = 0.0;  ///< for numbers
    bool integer = false;  ///< a number written without '.', exponent
    Location where;
};

/// Split `source` into tokens. Lexical errors (a stray character, an unclosed
/// string) go to `diags` and become Tok::bad tokens. With `comments` false
/// (an override), '#' is a Tok::hash, as in --set export:png#2.bits=8.
std::vector<Token> lex(const std::shared_ptr<const Source>& source, Diagnostics& diags, bool comments = true);

struct Literal {
    enum class Kind { number, string, boolean, word, point, list };
    Kind kind = Kind::number;
    Location where;
    double number = 0.0;
    bool integer = false;
    std::string text;  ///< string/word value; the number as written
    bool boolean = false;
    std::vector<Literal> items;  ///< point: 2 numbers; list: elements
};

/// "a number", "the string \"x\"", "the word nan", ...
std::string describe(const Literal& literal);

struct Input {
    std::string name;  ///< the value name
    std::string side;  ///< "particles" in sim.particles, else ""
    Location where;
    /// A call written in place of a value: the index of its (nested) statement in Spec::statements; name is
    /// then its kind:node, for messages. -1 for a value name.
    int statement = -1;
    std::string full() const { return side.empty() ? name : name + "." + side; }
};

struct Argument {
    std::string key;
    Location key_where;
    Literal value;
};

/// A process in a loop node's body: `stream-power(m=0.5)`.
struct ProcessCallSyntax {
    std::string name;
    Location where;  ///< spans the name
    std::vector<Argument> params;
};

struct Call {
    std::string kind, node;  ///< "generate", "diamond-square"
    Location where;  ///< spans kind:node
    std::vector<Input> inputs;
    std::vector<Argument> params;
    /// The body in braces after the call (a loop node's processes); body_where is its '{'.
    bool has_body = false;
    Location body_where;
    std::vector<ProcessCallSyntax> body;
    /// A line of the body did not parse (reported): the body is incomplete, so what it lacks is not checked.
    bool body_broken = false;
    std::string qualified() const { return kind + ":" + node; }
};

struct Statement {
    std::string name;  ///< "" for an unnamed call
    Location name_where;
    Call call;
    bool nested = false;  ///< a call written where an input goes, hoisted before its reader
};

struct Spec {
    std::shared_ptr<const Source> source;
    std::optional<int> version;
    Location version_where;
    std::optional<std::uint64_t> seed;
    Location seed_where;
    bool has_grid = false;
    int grid_width = 513, grid_height = 513;
    double grid_cell = 1.0;
    bool has_cell = false;  ///< cell= given (else 1 m)
    Location grid_where;
    std::vector<Statement> statements;
    /// After a syntax error the checker still checks the statements that parsed, so every mistake is reported
    /// at once. These say what the broken lines would have made, so it says nothing more about them: the
    /// names of `NAME = ...` lines that did not parse (a read of one is not "undefined"), and whether an
    /// `orogen`, `seed` or `grid` line did not parse (no "add `orogen 1`"; no outputs' warning).
    std::vector<std::string> broken_names;
    bool broken_header = false;
    bool broken = false;  ///< any syntax error
};

/// Parse a whole spec. Syntax errors go to `diags`; the parser recovers at the
/// next line so that every error is reported at once.
Spec parse(const std::shared_ptr<const Source>& source, Diagnostics& diags);

/// Parse a command-line override "NAME.PARAM=VALUE" or "NAME.PROCESS.PARAM=VALUE" (source name "--set").
/// NAME is a value name, or an unnamed node's label as the timing table shows
/// it: kind:node, kind:node#2, ...
struct Override {
    std::string target;  ///< NAME, or the label kind:node[#N]
    std::string param;  ///< PARAM
    /// NAME.PROCESS.PARAM=VALUE: a parameter of a process in a loop node's body, by its label
    /// (stream-power, or stream-power#2 for the second); "" for a node's own parameter.
    std::string process;
    Location target_where, param_where, process_where;
    Literal value;
};
std::optional<Override> parse_override(const std::shared_ptr<const Source>& source, Diagnostics& diags);

}  // namespace orogen::spec
