#include "json.hpp"

#include <cmath>
#include <cstdio>

namespace orogen {

std::string json_escape(std::string_view s) {
    std::string out = "\"";
    for (unsigned char c : s) {
        switch (c) {
            case '"': out += "\\\""; break;
            case '\\': out += "\\\\"; break;
            case '\n': out += "\\n"; break;
            case '\t': out += "\\t"; break;
            case '\r': out += "\\r"; break;
            default:
                if (c < 0x20) {
                    char buf[8];
                    std::snprintf(buf, sizeof buf, "\\u%04x", c);
                    out += buf;
                } else {
                    out += char(c);
                }
        }
    }
    return out + "\"";
}

void JsonWriter::indent() {
    out_ += '\n';
    out_.append(std::size_t(depth_) * 2, ' ');
}

void JsonWriter::comma() {
    if (after_key_) {
        after_key_ = false;
        return;
    }
    if (depth_ > 0) {
        if (!first_) out_ += ',';
        indent();
    }
    first_ = false;
}

JsonWriter& JsonWriter::begin_object() {
    comma();
    out_ += '{';
    ++depth_;
    first_ = true;
    return *this;
}
JsonWriter& JsonWriter::end_object() {
    --depth_;
    if (!first_) indent();
    out_ += '}';
    first_ = false;
    if (depth_ == 0) out_ += '\n';
    return *this;
}
JsonWriter& JsonWriter::begin_array() {
    comma();
    out_ += '[';
    ++depth_;
    first_ = true;
    return *this;
}
JsonWriter& JsonWriter::end_array() {
    --depth_;
    if (!first_) indent();
    out_ += ']';
    first_ = false;
    return *this;
}
JsonWriter& JsonWriter::key(std::string_view k) {
    comma();
    out_ += json_escape(k) + ": ";
    after_key_ = true;
    return *this;
}
JsonWriter& JsonWriter::value(std::string_view v) {
    comma();
    out_ += json_escape(v);
    return *this;
}
JsonWriter& JsonWriter::value(double v) {
    comma();
    if (!std::isfinite(v)) {
        out_ += "null";
        return *this;
    }
    char buf[32];
    std::snprintf(buf, sizeof buf, "%.17g", v);
    out_ += buf;
    return *this;
}
JsonWriter& JsonWriter::value(std::int64_t v) {
    comma();
    out_ += std::to_string(v);
    return *this;
}
JsonWriter& JsonWriter::value(std::uint64_t v) {
    comma();
    out_ += std::to_string(v);
    return *this;
}
JsonWriter& JsonWriter::value(bool v) {
    comma();
    out_ += v ? "true" : "false";
    return *this;
}
JsonWriter& JsonWriter::null() {
    comma();
    out_ += "null";
    return *this;
}

}  // namespace orogen
