// libFuzzer target: the spec lexer, parser and checker on arbitrary bytes, checked against the real
// plugins' node descriptors (and their check hooks). Any crash, hang or sanitizer report is a bug; a
// diagnostic is the expected outcome for almost every input.
#include "fuzz_support.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    orogen::fuzz::check_spec(std::string(reinterpret_cast<const char*>(data), size), {});
    return 0;
}
