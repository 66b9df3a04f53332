// orogen/error.hpp — the one exception type that crosses the node boundary.
//
// A node throws orogen::Error (or anything derived from std::exception); the
// runner catches it at the node boundary and reports one error naming the
// node and its spec line. The category decides the exit code:
//   bad_input   — the user's file, value or path is wrong (exit 2)
//   failed_run  — the run itself failed: I/O, non-finite values, ... (exit 1)
#pragma once

#include <stdexcept>
#include <string>

namespace orogen {

class Error : public std::runtime_error {
public:
    enum class Kind { bad_input, failed_run };

    explicit Error(std::string message, Kind kind = Kind::failed_run)
        : std::runtime_error(std::move(message)), kind_(kind) {}
    Kind kind() const { return kind_; }

private:
    Kind kind_;
};

/// A user error: a bad file, value or path. The message says what is wrong and how to fix it.
class BadInput : public Error {
public:
    explicit BadInput(std::string message) : Error(std::move(message), Kind::bad_input) {}
};

/// The user interrupted the run (Ctrl-C): thrown by NodeContext::check_cancelled.
class Cancelled : public Error {
public:
    Cancelled() : Error("cancelled", Kind::failed_run) {}
};

}  // namespace orogen
